//! The shells: each node's thread moves bytes between its transport and the library's pure
//! node, and does nothing else. Board A runs two threads, as on the ESP32's two cores: the
//! WiFi task (TCP) and the control loop, joined by the library's SPSC hand-off queues.

use super::clock::{Clock, NodeClock};
use super::log::Log;
use super::plant::{Drives, Plant};
use mmic::node::board_a::{self, BoardA, Event};
use mmic::node::board_b::{self, BoardB};
use mmic::node::handoff::{Consumer, Producer};
use mmic::node::server::{Accepted, Server};
use mmic::sensors::frontend::{self, Frontend, WINDOW};
use mmic::units::BoardNumber;
use mmic::wire::command::COMMAND_LEN;
use mmic::wire::deframer::{Deframed, Deframer};
use mmic::wire::heartbeat::HEARTBEAT_LEN;
use mmic::wire::PacketKind;
use serde_json::{json, Value};
use std::io::{ErrorKind, Read, Write};
use std::net::{SocketAddr, TcpListener, TcpStream};
use std::sync::atomic::{AtomicBool, AtomicU32, Ordering};
use std::sync::mpsc::{Receiver, Sender};
use std::sync::{Arc, Mutex};
use std::time::Duration;

/// Board A's control period, ms.
pub const TICK_MS: u32 = 10;

/// A packet writer that can lose packets (injected loss) or be cut at a time, and logs each
/// packet's fate.
pub struct Lossy<W: Write> {
    pub out: W,
    pub link: &'static str,
    pub from: String,
    pub to: String,
    pub loss: f64,
    pub cut_at: Option<u32>,
    pub rng: fastrand::Rng,
    pub log: Option<Log>,
}

impl<W: Write> Lossy<W> {
    /// Sends one packet at `now`; returns whether it went out.
    pub fn send(&mut self, now: u32, bytes: &[u8]) -> bool {
        let fate = if self.cut_at.is_some_and(|t| now >= t) {
            "cut"
        } else if self.loss > 0.0 && self.rng.f64() < self.loss {
            "lost"
        } else if self
            .out
            .write_all(bytes)
            .and_then(|_| self.out.flush())
            .is_ok()
        {
            "delivered"
        } else {
            "closed"
        };
        if let Some(l) = &self.log {
            l.packet(now, self.link, &self.from, &self.to, fate, bytes);
        }
        fate == "delivered"
    }
}

/// Reads a byte stream until EOF and sends every packet the deframer finds.
pub fn reader(mut input: impl Read, tx: Sender<Vec<u8>>) {
    let mut d = Deframer::<256>::new();
    let mut buf = [0u8; 256];
    loop {
        match input.read(&mut buf) {
            Ok(0) | Err(_) => return,
            Ok(n) => {
                let mut frames = Vec::new();
                d.feed(&buf[..n], |e| {
                    if let Deframed::Frame(f) = e {
                        frames.push(f.as_bytes().to_vec());
                    }
                });
                for f in frames {
                    if tx.send(f).is_err() {
                        return;
                    }
                }
            }
        }
    }
}

/// A tick started this late (simulated ms) is logged as an overrun: a fifth of the 500 ms
/// communication timeout, beyond which the host's lag starts to matter to the firmware's timers.
pub const OVERRUN_MS: u32 = 100;

/// Records a tick's lateness in the run's maximum, and logs an overrun.
fn note_lateness(late: &AtomicU32, by: u32, log: &Option<Log>, now: u32, name: &str) {
    late.fetch_max(by, Ordering::Relaxed);
    if by >= OVERRUN_MS {
        if let Some(l) = log {
            l.event(now, name, json!({"type": "overrun", "late_ms": by}));
        }
    }
}

/// Sleeps until simulated time `t`.
pub fn sleep_until(clock: &Clock, t: u32) {
    let now = clock.now_ms();
    if t > now {
        std::thread::sleep(clock.wall((t - now) as f64).min(Duration::from_millis(5)));
    } else {
        std::thread::yield_now();
    }
}

/// Board A's event as JSON.
pub fn event_json(e: &Event) -> Value {
    match e {
        Event::Executed {
            seq,
            command,
            refusal,
        } => json!({"type": "executed", "seq": seq, "command": command, "refusal": refusal}),
        Event::Duplicate { seq } => json!({"type": "duplicate", "seq": seq}),
        Event::Stale { seq } => json!({"type": "stale", "seq": seq}),
        Event::Rejected(w) => json!({"type": "rejected", "error": w.to_string()}),
        Event::OtherRobot { board } => json!({"type": "other_robot", "board": board.get()}),
        Event::Faults(f) => json!({"type": "faults", "faults": f}),
        Event::Mode { from, to } => json!({"type": "mode", "from": from, "to": to}),
        Event::Reached(s) => json!({"type": "reached", "state": s}),
        Event::Bolting(f) => json!({"type": "bolting", "fault": f}),
        Event::Pair { pair, attempts, ok } => {
            json!({"type": "pair", "pair": pair.number(), "attempts": attempts, "ok": ok})
        }
    }
}

/// Board A's WiFi task (core 0): accepts the server's connections, deframes command packets
/// into the hand-off queue, writes heartbeats from the other queue back.
#[allow(clippy::too_many_arguments)]
pub fn board_a_wifi(
    listener: TcpListener,
    mut commands: Producer<'_, COMMAND_LEN, 8>,
    mut heartbeats: Consumer<'_, HEARTBEAT_LEN, 8>,
    loss: f64,
    seed: u64,
    clock: NodeClock<'_>,
    log: Option<Log>,
    stop: &AtomicBool,
    name: String,
) {
    let mut rng = fastrand::Rng::with_seed(seed);
    let lost = |rng: &mut fastrand::Rng| loss > 0.0 && rng.f64() < loss;
    let _ = listener.set_nonblocking(true);
    while !stop.load(Ordering::Relaxed) {
        clock.ready(clock.now_ms());
        let sock = match listener.accept() {
            Ok((s, _)) => s,
            Err(_) => {
                while let Some(hb) = heartbeats.pop() {
                    if let Some(l) = &log {
                        l.packet(clock.now_ms(), "wifi", &name, "server", "unconnected", &hb);
                    }
                }
                std::thread::sleep(Duration::from_micros(300));
                continue;
            }
        };
        let mut sock = sock;
        let _ = sock.set_nonblocking(true);
        let _ = sock.set_nodelay(true);
        let mut d = Deframer::<256>::new();
        let mut buf = [0u8; 256];
        'conn: while !stop.load(Ordering::Relaxed) {
            clock.ready(clock.now_ms());
            match sock.read(&mut buf) {
                Ok(0) => break 'conn,
                Ok(n) => {
                    let mut frames = Vec::new();
                    d.feed(&buf[..n], |e| {
                        if let Deframed::Frame(f) = e {
                            frames.push(f);
                        }
                    });
                    for f in frames {
                        if f.kind() != PacketKind::Command {
                            continue;
                        }
                        let now = clock.now_ms();
                        let bytes = f.as_bytes();
                        let fate = if lost(&mut rng) { "lost" } else { "delivered" };
                        if let Some(l) = &log {
                            l.packet(now, "wifi", "server", &name, fate, bytes);
                        }
                        if fate == "delivered" {
                            let mut p = [0u8; COMMAND_LEN];
                            p.copy_from_slice(bytes);
                            if let Err(full) = commands.push(p) {
                                if let Some(l) = &log {
                                    l.event(now, &name, json!({"type": "handoff_full", "hex": super::log::hex(&full.0)}));
                                }
                                commands.give_up(full);
                            }
                        }
                    }
                }
                Err(e) if e.kind() == ErrorKind::WouldBlock => {}
                Err(_) => break 'conn,
            }
            while let Some(hb) = heartbeats.pop() {
                let now = clock.now_ms();
                let fate = if lost(&mut rng) {
                    "lost"
                } else if sock.write_all(&hb).is_ok() {
                    "delivered"
                } else {
                    "closed"
                };
                if let Some(l) = &log {
                    l.packet(now, "wifi", &name, "server", fate, &hb);
                }
            }
            std::thread::sleep(Duration::from_micros(200));
        }
    }
}

/// Board A's control loop (core 1): one library tick every 10 ms.
#[allow(clippy::too_many_arguments)]
pub fn board_a_control(
    mut a: BoardA,
    mut commands: Consumer<'_, COMMAND_LEN, 8>,
    mut heartbeats: Producer<'_, HEARTBEAT_LEN, 8>,
    from_b: Receiver<Vec<u8>>,
    mut to_b: Lossy<std::io::PipeWriter>,
    plant: Arc<Mutex<Plant>>,
    clock: NodeClock<'_>,
    log: Option<Log>,
    stop: &AtomicBool,
    name: String,
    status: Arc<Mutex<Value>>,
    late: &AtomicU32,
) {
    let mut next = 0;
    let mut sensors = Frontend::<WINDOW>::new(frontend::Config::default());
    while !stop.load(Ordering::Relaxed) {
        sleep_until(&clock, next);
        let now = clock.now_ms();
        if now < next {
            continue;
        }
        if next > 0 {
            note_lateness(late, now - next, &log, now, &name);
        }
        next = now - now % TICK_MS + TICK_MS;
        // Everything due before this tick is done: time may run on to the pace's slack.
        clock.ready(now);
        let command = commands.pop();
        let from_b = from_b.try_recv().ok().and_then(|v| v.try_into().ok());
        let s = {
            let mut p = plant.lock().unwrap_or_else(|e| e.into_inner());
            p.advance(now);
            p.sense(0, now)
        };
        let f = sensors.push(&s.raw);
        let out = a.tick(
            now,
            &board_a::Inputs {
                command,
                from_b,
                electrical: f.electrical,
                hip: f.hip,
                gravity: f.gravity,
                arm_contracted: s.arm_contracted,
                bolter: s.bolter,
            },
        );
        {
            let mut p = plant.lock().unwrap_or_else(|e| e.into_inner());
            p.drive_a(
                Drives {
                    arm: out.arm,
                    gripper: out.gripper,
                    regulator: out.regulator,
                    bolter: out.bolter,
                    mux: out.mux,
                },
                out.hip,
            );
            for e in &out.events {
                if let Event::Reached(st) = e {
                    p.set_state(*st);
                }
            }
        }
        for e in &out.events {
            if let Some(l) = &log {
                l.event(now, &name, event_json(e));
            }
        }
        if let Some(b) = out.to_b {
            to_b.send(now, &b);
        }
        if let Some(hb) = out.heartbeat {
            if let Err(full) = heartbeats.push(hb) {
                if let Some(l) = &log {
                    l.event(
                        now,
                        &name,
                        json!({"type": "handoff_full", "hex": super::log::hex(&full.0)}),
                    );
                }
                heartbeats.give_up(full);
            }
        }
        if let Ok(mut st) = status.lock() {
            *st = json!({
                "mode": a.mode(), "faults": a.faults(), "state": a.state(),
                "in_motion": a.in_motion(), "t_ms": now,
            });
        }
    }
}

/// Board B: one library tick every 10 ms.
#[allow(clippy::too_many_arguments)]
pub fn board_b(
    mut b: BoardB,
    from_a: Receiver<Vec<u8>>,
    mut to_a: Lossy<std::io::PipeWriter>,
    plant: Arc<Mutex<Plant>>,
    clock: NodeClock<'_>,
    log: Option<Log>,
    stop: &AtomicBool,
    name: String,
    late: &AtomicU32,
) {
    let mut next = 0;
    let mut was_lost = false;
    let mut sensors = Frontend::<WINDOW>::new(frontend::Config::default());
    while !stop.load(Ordering::Relaxed) {
        sleep_until(&clock, next);
        let now = clock.now_ms();
        if now < next {
            continue;
        }
        if next > 0 {
            note_lateness(late, now - next, &log, now, &name);
        }
        next = now - now % TICK_MS + TICK_MS;
        // Everything due before this tick is done: time may run on to the pace's slack.
        clock.ready(now);
        let command = from_a.try_recv().ok().and_then(|v| v.try_into().ok());
        let s = plant
            .lock()
            .unwrap_or_else(|e| e.into_inner())
            .sense(1, now);
        let f = sensors.push(&s.raw);
        let out = b.tick(
            now,
            &board_b::Inputs {
                command,
                electrical: f.electrical,
                gravity: f.gravity,
                arm_contracted: s.arm_contracted,
                bolter: s.bolter,
            },
        );
        plant
            .lock()
            .unwrap_or_else(|e| e.into_inner())
            .drive_b(Drives {
                arm: out.arm,
                gripper: out.gripper,
                regulator: out.regulator,
                bolter: out.bolter,
                mux: out.mux,
            });
        if out.link_lost != was_lost {
            was_lost = out.link_lost;
            if let Some(l) = &log {
                l.event(
                    now,
                    &name,
                    json!({"type": "link_lost", "holding": was_lost}),
                );
            }
        }
        if let Some(hb) = out.heartbeat {
            to_a.send(now, &hb);
        }
    }
}

/// The server board: takes commands from the ground's serial line, visits robots with a
/// pending command (connect, send, wait for the heartbeat, forward it, disconnect).
#[allow(clippy::too_many_arguments)]
pub fn server(
    from_ground: Receiver<Vec<u8>>,
    mut to_ground: Lossy<std::io::PipeWriter>,
    robots: Vec<(BoardNumber, SocketAddr)>,
    visit_ms: u32,
    clock: NodeClock<'_>,
    log: Option<Log>,
    stop: &AtomicBool,
    name: String,
) {
    let mut srv: Server<4> = Server::new();
    while !stop.load(Ordering::Relaxed) {
        clock.ready(clock.now_ms());
        while let Ok(bytes) = from_ground.try_recv() {
            let now = clock.now_ms();
            let Ok(packet) = <[u8; COMMAND_LEN]>::try_from(bytes.as_slice()) else {
                continue;
            };
            let what = match srv.accept(&packet) {
                Ok(Accepted::Queued) => json!({"type": "queued"}),
                Ok(Accepted::Resend) => json!({"type": "resend"}),
                Ok(Accepted::Superseded(old)) => {
                    json!({"type": "superseded", "old": super::log::hex(&old)})
                }
                Err(e) => json!({"type": "refused", "error": e.to_string()}),
            };
            if let Some(l) = &log {
                l.event(now, &name, what);
            }
        }
        let Some((robot, packet)) = srv.next_visit() else {
            std::thread::sleep(Duration::from_micros(300));
            continue;
        };
        let Some(addr) = robots.iter().find(|(b, _)| *b == robot).map(|(_, a)| *a) else {
            continue;
        };
        let Ok(mut sock) = TcpStream::connect_timeout(&addr, Duration::from_millis(200)) else {
            std::thread::sleep(Duration::from_millis(1));
            continue;
        };
        let _ = sock.set_nodelay(true);
        if sock.write_all(&packet).is_err() {
            continue;
        }
        srv.delivered(robot, &packet);
        // Wait for the heartbeat, then disconnect (one robot per loop). Polled without blocking:
        // a socket read timeout is rounded up to the kernel's tick (4–8 ms here), and a blocked
        // server would hold the paced clock back.
        let _ = sock.set_nonblocking(true);
        let until = clock.now_ms().saturating_add(visit_ms);
        let mut d = Deframer::<256>::new();
        let mut buf = [0u8; 256];
        let mut got = false;
        while !got && clock.now_ms() < until && !stop.load(Ordering::Relaxed) {
            clock.ready(clock.now_ms());
            match sock.read(&mut buf) {
                Ok(0) => break,
                Ok(n) => {
                    let mut frames = Vec::new();
                    d.feed(&buf[..n], |e| {
                        if let Deframed::Frame(f) = e {
                            frames.push(f);
                        }
                    });
                    for f in frames {
                        if f.kind() == PacketKind::Heartbeat {
                            to_ground.send(clock.now_ms(), f.as_bytes());
                            got = true;
                        }
                    }
                }
                Err(e) if matches!(e.kind(), ErrorKind::WouldBlock | ErrorKind::TimedOut) => {
                    std::thread::sleep(Duration::from_micros(200));
                }
                Err(_) => break,
            }
        }
    }
}
