//! The shells: each node's thread moves bytes between its transport and the library's pure
//! node, and does nothing else. Board A runs two threads, as on the ESP32's two cores: the
//! WiFi task (TCP) and the control loop, joined by the library's SPSC hand-off queues. The
//! server board runs the legacy relay ([`ServerTask`]) or, with `--protocol pus`, the PUS
//! gateway ([`GatewayTask`]: telecommands in and telemetry out over UDP), or with `--link
//! frames` the gateway behind the space data link ([`FrameGatewayTask`]: TC transfer frames in,
//! TM transfer frames out, one per datagram).

use super::clock::{Clock, NodeClock};
use super::downtime::{Downtime, Phase};
use super::inject::BOOT_MS;
use super::log::Log;
use super::plant::{Drives, Plant};
use super::serial_line::SerialRx;
use super::shell::{SideA, SideB};
use super::FrameStats;
use mmic::link::farm::Verdict;
use mmic::link::sdls::Key256;
use mmic::link::tc_frame::{self, SpacecraftId, TcFrame};
use mmic::link::tm_frame::TM_FRAME_LEN;
use mmic::link::ControlCommand;
use mmic::node::robot::board_a::{BoardA, Durable};
use mmic::node::robot::board_b::{self, BoardB};
use mmic::node::robot::handoff::{Consumer, Producer};
use mmic::node::robot::wifi_session::{Outgoing, WifiConfig, WifiSession};
use mmic::node::server::frames::Origin;
use mmic::node::server::gateway::{self, Gateway, Kept, Out};
use mmic::node::server::relay::{Accepted, Server};
use mmic::node::server::visit::Visit;
use mmic::restart::ResetCause;
use mmic::units::BoardNumber;
use mmic::wire::command::COMMAND_LEN;
use mmic::wire::deframer::{Deframed, Deframer};
use mmic::wire::heartbeat::HEARTBEAT_LEN;
use serde_json::{json, Value};
use std::io::{ErrorKind, Read, Write};
use std::net::{SocketAddr, TcpListener, TcpStream, UdpSocket};
use std::os::unix::net::UnixStream;
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

impl<W: Write + Send + 'static> Lossy<W> {
    /// The same writer behind a box, for links of either kind.
    pub fn boxed(self) -> Lossy<Box<dyn Write + Send>> {
        Lossy {
            out: Box::new(self.out),
            link: self.link,
            from: self.from,
            to: self.to,
            loss: self.loss,
            cut_at: self.cut_at,
            rng: self.rng,
            log: self.log,
        }
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

/// Sleeps until simulated time `t`.
pub fn sleep_until(clock: &Clock, t: u32) {
    let now = clock.now_ms();
    if t > now {
        std::thread::sleep(clock.wall((t - now) as f64).min(Duration::from_millis(5)));
    } else {
        std::thread::yield_now();
    }
}

/// What every node loop shares: its name in the log, its copy of the (paced) clock, the log,
/// the run's stop flag and the run's worst tick lateness.
pub struct Node<'a> {
    /// Name in the log, e.g. `board_a1`.
    pub name: String,
    /// This node's copy of the clock (it holds the node's pace slot).
    pub clock: NodeClock<'a>,
    /// Where events go (none: not logged).
    pub log: Option<Log>,
    /// Set when the run ends.
    pub stop: &'a AtomicBool,
    /// The latest any tick started after it was due, simulated ms.
    pub late: &'a AtomicU32,
}

impl Node<'_> {
    fn running(&self) -> bool {
        !self.stop.load(Ordering::Relaxed)
    }

    fn event(&self, now: u32, what: Value) {
        if let Some(l) = &self.log {
            l.event(now, &self.name, what);
        }
    }

    /// Tells the paced clock this node has done everything due up to now; returns now.
    fn poll(&self) -> u32 {
        let now = self.clock.now_ms();
        self.clock.ready(now);
        now
    }

    /// Runs `tick(now)` every [`TICK_MS`] until the run stops: records how late each tick
    /// started (an overrun past [`OVERRUN_MS`] is logged) and tells the paced clock when the
    /// node is ready, at the start of each tick, so time may run on to the pace's slack.
    fn every_tick(&self, mut tick: impl FnMut(u32)) {
        let mut next = 0;
        while self.running() {
            sleep_until(&self.clock, next);
            let now = self.clock.now_ms();
            if now < next {
                continue;
            }
            if next > 0 {
                let by = now - next;
                self.late.fetch_max(by, Ordering::Relaxed);
                if by >= OVERRUN_MS {
                    self.event(now, json!({"type": "overrun", "late_ms": by}));
                }
            }
            next = now - now % TICK_MS + TICK_MS;
            self.clock.ready(now);
            tick(now);
        }
    }
}

pub use super::shell::event_json;

/// Board A's WiFi task (core 0): accepts the server's connections, deframes command packets
/// into the hand-off queue, writes heartbeats from the other queue back, as the library's
/// [`WifiSession`] says.
pub struct WifiTask<'q> {
    /// Where the server board connects.
    pub listener: TcpListener,
    /// Commands to the control task (the rx queue).
    pub commands: Producer<'q, COMMAND_LEN, 8>,
    /// Heartbeats from the control task (the tx queue).
    pub heartbeats: Consumer<'q, HEARTBEAT_LEN, 8>,
    /// Injected loss, each direction.
    pub loss: f64,
    /// Seed of the loss draws.
    pub seed: u64,
    /// Board A is restarting (set by its control task): the WiFi task takes no connection and
    /// drops what it holds, and starts a new session once it is up again.
    pub down: Arc<AtomicBool>,
    /// The server board's address: a connection from anywhere else is closed at once, never
    /// holds the slot, and is logged (decision `sdls-scope`; on loopback every local process
    /// shares 127.0.0.1, so here it keeps out only other hosts).
    pub server: std::net::IpAddr,
}

/// Whether board A takes a connection from `peer`: only from its server board's address.
pub fn from_server(peer: &SocketAddr, server: std::net::IpAddr) -> bool {
    peer.ip() == server
}

impl WifiTask<'_> {
    /// Runs until the run stops.
    pub fn run(mut self, node: Node<'_>) {
        let mut rng = fastrand::Rng::with_seed(self.seed);
        let mut session = WifiSession::new(WifiConfig::default());
        let _ = self.listener.set_nonblocking(true);
        while node.running() {
            let now = node.poll();
            if self.down.load(Ordering::Relaxed) {
                // Restarting: connections refused (accepted and dropped), RAM lost.
                while self.heartbeats.pop().is_some() {}
                let _ = self.listener.accept();
                session = WifiSession::new(WifiConfig::default());
                std::thread::sleep(Duration::from_micros(300));
                continue;
            }
            match self.listener.accept() {
                Ok((sock, peer)) if !from_server(&peer, self.server) => {
                    let _ = sock.shutdown(std::net::Shutdown::Both);
                    node.event(
                        now,
                        json!({"type": "wifi_refused", "peer": peer.to_string()}),
                    );
                }
                Ok((sock, _)) => {
                    let queued = std::iter::from_fn(|| self.heartbeats.pop());
                    session.open(now, queued, |hb| unconnected(&node, &hb));
                    self.serve(&node, sock, &mut rng, &mut session);
                    session.close();
                }
                Err(_) => {
                    while let Some(hb) = self.heartbeats.pop() {
                        if let Outgoing::Drop(hb) = session.heartbeat(hb) {
                            unconnected(&node, &hb);
                        }
                    }
                    std::thread::sleep(Duration::from_micros(300));
                }
            }
        }
    }

    fn lost(&self, rng: &mut fastrand::Rng) -> bool {
        self.loss > 0.0 && rng.f64() < self.loss
    }

    /// One connection of the server board, until it disconnects (or idles out).
    fn serve(
        &mut self,
        node: &Node<'_>,
        mut sock: TcpStream,
        rng: &mut fastrand::Rng,
        session: &mut WifiSession,
    ) {
        let _ = sock.set_nonblocking(true);
        let _ = sock.set_nodelay(true);
        let mut buf = [0u8; 256];
        while node.running() {
            let now = node.poll();
            if self.down.load(Ordering::Relaxed) {
                return; // board A restarts: the connection drops
            }
            match sock.read(&mut buf) {
                Ok(0) => return,
                Ok(n) => {
                    let mut commands = Vec::new();
                    session.received(now, &buf[..n], |c| commands.push(c));
                    for c in commands {
                        self.take_command(node, c, rng);
                    }
                }
                Err(e) if e.kind() == ErrorKind::WouldBlock => {}
                Err(_) => return,
            }
            if session.expired(now) {
                return;
            }
            while let Some(hb) = self.heartbeats.pop() {
                let fate = match session.heartbeat(hb) {
                    Outgoing::Drop(_) => "unconnected",
                    Outgoing::Send(_) if self.lost(rng) => "lost",
                    Outgoing::Send(hb) if sock.write_all(&hb).is_ok() => "delivered",
                    Outgoing::Send(_) => "closed",
                };
                if let Some(l) = &node.log {
                    l.packet(node.clock.now_ms(), "wifi", &node.name, "server", fate, &hb);
                }
            }
            std::thread::sleep(Duration::from_micros(200));
        }
    }

    /// A command packet off the link: lost, or handed to the control task (a full queue hands
    /// it back, and that is logged).
    fn take_command(&mut self, node: &Node<'_>, p: [u8; COMMAND_LEN], rng: &mut fastrand::Rng) {
        let now = node.clock.now_ms();
        let fate = if self.lost(rng) { "lost" } else { "delivered" };
        if let Some(l) = &node.log {
            l.packet(now, "wifi", "server", &node.name, fate, &p);
        }
        if fate == "delivered" {
            if let Err(full) = self.commands.push(p) {
                node.event(
                    now,
                    json!({"type": "handoff_full", "hex": super::log::hex(&full.0)}),
                );
                self.commands.give_up(full);
            }
        }
    }
}

/// Logs a heartbeat board A's WiFi task dropped with no server connected.
fn unconnected(node: &Node<'_>, hb: &[u8]) {
    if let Some(l) = &node.log {
        l.packet(
            node.clock.now_ms(),
            "wifi",
            &node.name,
            "server",
            "unconnected",
            hb,
        );
    }
}

/// Board A's control loop (core 1): one library tick every 10 ms.
pub struct ControlTask<'q> {
    /// The library's board A and side A's sensor front end.
    pub a: SideA,
    /// Commands from the WiFi task (the rx queue).
    pub commands: Consumer<'q, COMMAND_LEN, 8>,
    /// Heartbeats to the WiFi task (the tx queue).
    pub heartbeats: Producer<'q, HEARTBEAT_LEN, 8>,
    /// Packets from board B's serial line.
    pub from_b: SerialRx,
    /// Board B's serial line.
    pub to_b: Lossy<UnixStream>,
    /// The robot's body.
    pub plant: Arc<Mutex<Plant>>,
    /// Board A's mode, faults and state for the run's summary.
    pub status: Arc<Mutex<Value>>,
    /// Board A's restarts (`--inject reboot-a@S`), and the flag its WiFi task reads.
    pub restarts: Downtime,
    /// Set while board A is down.
    pub down: Arc<AtomicBool>,
    /// Board A's flash: its exactly-once log's last entry and boot count (decision
    /// `restart-board-a`).
    pub kept: Option<Durable>,
}

impl ControlTask<'_> {
    /// Runs until the run stops.
    pub fn run(mut self, node: Node<'_>) {
        node.every_tick(|now| self.tick(&node, now));
    }

    /// A restart going on: true while board A is down (this tick does nothing).
    fn restarting(&mut self, node: &Node<'_>, now: u32) -> bool {
        match self.restarts.step(now) {
            Phase::Running => return false,
            Phase::WentDown => {
                self.down.store(true, Ordering::Relaxed);
                let mut p = self.plant.lock().unwrap_or_else(|e| e.into_inner());
                p.advance(now);
                p.drive_a(Drives::off(), None);
                node.event(now, json!({"type": "restart", "down_ms": BOOT_MS}));
            }
            Phase::Down => {}
            Phase::CameUp => {
                let board =
                    BoardA::restarted(self.a.board.config(), self.kept, ResetCause::PowerOn);
                self.kept = Some(board.durable());
                self.a = SideA::new(board);
                self.down.store(false, Ordering::Relaxed);
                let boot = self.a.board.boot().to_wire();
                node.event(now, json!({"type": "boot", "boot": boot}));
                return false;
            }
        }
        // Down: what reaches it is lost.
        while self.commands.pop().is_some() {}
        while self.from_b.try_recv().is_some() {}
        true
    }

    fn tick(&mut self, node: &Node<'_>, now: u32) {
        if self.restarting(node, now) {
            return;
        }
        let command = self.commands.pop();
        let from_b = self.from_b.try_recv().and_then(|v| v.try_into().ok());
        // Board A's flash: the record written ahead of a tick that may run a new command,
        // then after it.
        if let Some(d) = self.a.board.ahead(command.as_ref()) {
            self.kept = Some(d);
        }
        let out = {
            let mut p = self.plant.lock().unwrap_or_else(|e| e.into_inner());
            self.a.tick(&mut p, now, command, from_b)
        };
        self.kept = Some(self.a.board.durable());
        for e in &out.events {
            node.event(now, event_json(e));
        }
        if let Some(b) = out.to_b {
            self.to_b.send(now, &b);
        }
        if let Some(hb) = out.heartbeat {
            if let Err(full) = self.heartbeats.push(hb) {
                node.event(
                    now,
                    json!({"type": "handoff_full", "hex": super::log::hex(&full.0)}),
                );
                self.heartbeats.give_up(full);
            }
        }
        if let Ok(mut st) = self.status.lock() {
            *st = self.a.status(now);
        }
    }
}

/// Board B: one library tick every 10 ms.
pub struct BoardBTask {
    /// The library's board B and side B's sensor front end.
    pub b: SideB,
    /// Packets from board A's serial line.
    pub from_a: SerialRx,
    /// Board A's serial line.
    pub to_a: Lossy<UnixStream>,
    /// The robot's body.
    pub plant: Arc<Mutex<Plant>>,
    /// Board B's restarts (`--inject reboot-b@S`): it keeps nothing (decision
    /// `restart-board-b`).
    pub restarts: Downtime,
}

impl BoardBTask {
    /// Runs until the run stops.
    pub fn run(mut self, node: Node<'_>) {
        let mut was_lost = false;
        node.every_tick(|now| {
            let phase = restart_phase(&node, &mut self.restarts, now);
            match phase {
                Phase::Running | Phase::Down => {}
                Phase::WentDown => {
                    let mut p = self.plant.lock().unwrap_or_else(|e| e.into_inner());
                    p.advance(now);
                    p.drive_b(Drives::off());
                }
                Phase::CameUp => {
                    self.b = SideB::new(BoardB::restarted(board_b::Config::default()));
                }
            }
            if matches!(phase, Phase::WentDown | Phase::Down) {
                while self.from_a.try_recv().is_some() {}
                return;
            }
            let command = self.from_a.try_recv().and_then(|v| v.try_into().ok());
            let out = {
                let mut p = self.plant.lock().unwrap_or_else(|e| e.into_inner());
                self.b.tick(&mut p, now, command)
            };
            if out.link_lost != was_lost {
                was_lost = out.link_lost;
                node.event(now, json!({"type": "link_lost", "holding": was_lost}));
            }
            if let Some(hb) = out.heartbeat {
                self.to_a.send(now, &hb);
            }
        });
    }
}

/// A node's restart phase at `now` (board B, the server board), its `restart` and `boot`
/// events logged as the virtual-time engine logs them.
fn restart_phase(node: &Node<'_>, restarts: &mut Downtime, now: u32) -> Phase {
    let phase = restarts.step(now);
    match phase {
        Phase::WentDown => node.event(now, json!({"type": "restart", "down_ms": BOOT_MS})),
        Phase::CameUp => node.event(now, json!({"type": "boot", "boot": null})),
        Phase::Running | Phase::Down => {}
    }
    phase
}

/// How long a server task waits when it has nothing to do (or is down).
const SERVER_IDLE: Duration = Duration::from_micros(300);

/// Everything waiting on a UDP socket, read and dropped: what reaches a node that is down is
/// lost.
fn lose_datagrams(sock: &UdpSocket) {
    let mut buf = [0u8; 2048];
    while sock.recv(&mut buf).is_ok() {}
}

/// The server board: takes commands from the ground's serial line, visits robots with a
/// pending command (connect, send, wait for the heartbeat, forward it, disconnect).
pub struct ServerTask {
    /// Packets from the ground's serial line.
    pub from_ground: Receiver<Vec<u8>>,
    /// The ground's serial line (an OS pipe, or with `--opsui-serial` a serial device).
    pub to_ground: Lossy<Box<dyn Write + Send>>,
    /// Each robot's board A and where it listens.
    pub robots: Vec<(BoardNumber, SocketAddr)>,
    /// How long to wait for a heartbeat, simulated ms.
    pub visit_ms: u32,
    /// The server board's restarts (`--inject reboot-server@S`): the relay keeps nothing
    /// (decision `restart-server`); a visit going on is broken off.
    pub restarts: Downtime,
}

impl ServerTask {
    /// Runs until the run stops.
    pub fn run(mut self, node: Node<'_>) {
        let mut srv: Server<4> = Server::new();
        while node.running() {
            let now = node.poll();
            match restart_phase(&node, &mut self.restarts, now) {
                Phase::WentDown | Phase::Down => {
                    srv = Server::new();
                    while self.from_ground.try_recv().is_ok() {}
                    std::thread::sleep(SERVER_IDLE);
                    continue;
                }
                Phase::CameUp | Phase::Running => {}
            }
            self.take_from_ground(&node, &mut srv);
            let now = node.clock.now_ms();
            let Some(mut visit) = Visit::next(&mut srv, now, self.visit_ms) else {
                std::thread::sleep(SERVER_IDLE);
                continue;
            };
            let Some(addr) = self
                .robots
                .iter()
                .find(|(b, _)| *b == visit.board())
                .map(|(_, a)| *a)
            else {
                continue;
            };
            let Some(sock) = connect(&addr, visit.packet()) else {
                continue;
            };
            visit.written(&mut srv);
            let restarts = &self.restarts;
            let up = || !restarts.due(node.clock.now_ms());
            if let Some(hb) = await_heartbeat_with(&node, sock, &mut visit, up) {
                self.to_ground.send(node.clock.now_ms(), &hb);
            }
        }
    }

    fn take_from_ground(&mut self, node: &Node<'_>, srv: &mut Server<4>) {
        while let Ok(bytes) = self.from_ground.try_recv() {
            let now = node.clock.now_ms();
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
            node.event(now, what);
        }
    }
}

/// Connects to board A at `addr` and writes the visit's packet; `None` if either failed.
fn connect(addr: &SocketAddr, packet: &[u8]) -> Option<TcpStream> {
    let Ok(mut sock) = TcpStream::connect_timeout(addr, Duration::from_millis(200)) else {
        std::thread::sleep(Duration::from_millis(1));
        return None;
    };
    let _ = sock.set_nodelay(true);
    sock.write_all(packet).ok().map(|_| sock)
}

/// Waits on a visit's connection for board A's heartbeat until the visit's deadline (the
/// library's [`Visit`] decides). Polled without blocking: a socket read timeout is rounded up
/// to the kernel's tick (4–8 ms here), and a blocked server would hold the paced clock back.
/// Between polls of the socket it calls `meanwhile`, and breaks the visit off when that says
/// false (the server board restarts); the frame gateway keeps its link going there too (TC
/// frames in, a TM frame at least every idle period).
fn await_heartbeat_with(
    node: &Node<'_>,
    mut sock: TcpStream,
    visit: &mut Visit,
    mut meanwhile: impl FnMut() -> bool,
) -> Option<[u8; HEARTBEAT_LEN]> {
    let _ = sock.set_nonblocking(true);
    let mut buf = [0u8; 256];
    while node.running() && visit.left_ms(node.poll()).is_some() {
        if !meanwhile() {
            return None;
        }
        match sock.read(&mut buf) {
            Ok(0) => return None,
            Ok(n) => {
                if let Some(hb) = visit.received(&buf[..n]) {
                    return Some(hb);
                }
            }
            Err(e) if matches!(e.kind(), ErrorKind::WouldBlock | ErrorKind::TimedOut) => {
                std::thread::sleep(Duration::from_micros(200));
            }
            Err(_) => return None,
        }
    }
    None
}

/// One end of a UDP link as a packet writer: each write is one datagram to `peer`.
pub struct UdpOut {
    /// The socket sent from.
    pub sock: UdpSocket,
    /// Where to.
    pub peer: SocketAddr,
}

impl Write for UdpOut {
    fn write(&mut self, buf: &[u8]) -> std::io::Result<usize> {
        self.sock.send_to(buf, self.peer)
    }

    fn flush(&mut self) -> std::io::Result<()> {
        Ok(())
    }
}

/// Receives datagrams until the run stops and sends each to `tx` (the ground's end of the UDP
/// link, read as the serial lines' readers are).
pub fn udp_reader(sock: UdpSocket, tx: Sender<Vec<u8>>, stop: &AtomicBool) {
    let _ = sock.set_read_timeout(Some(Duration::from_millis(5)));
    let mut buf = [0u8; 2048];
    while !stop.load(Ordering::Relaxed) {
        match sock.recv(&mut buf) {
            Ok(n) => {
                if tx.send(buf[..n].to_vec()).is_err() {
                    return;
                }
            }
            Err(e) if matches!(e.kind(), ErrorKind::WouldBlock | ErrorKind::TimedOut) => {}
            Err(_) => return,
        }
    }
}

/// The largest telemetry packet the gateway writes, bytes.
const MAX_TM_LEN: usize = mmic::ccsds::tm::TM_MIN_LEN + gateway::MAX_TM_DATA;

/// The server board as the PUS gateway (`--protocol pus`): telecommand packets from the
/// ground's UDP socket into [`Gateway::tc_packet`], the legacy commands of
/// [`Gateway::tick`] to board A over the same visits as [`ServerTask`]'s (connect, send, wait
/// for the heartbeat, disconnect), the heartbeat into [`Gateway::heartbeat`], and every
/// report written by [`Gateway::encode`] to the ground over UDP.
pub struct GatewayTask {
    /// Where the ground's telecommands arrive (non-blocking).
    pub from_ground: UdpSocket,
    /// The ground's UDP socket.
    pub to_ground: Lossy<UdpOut>,
    /// The robot's board A and where it listens.
    pub robot: (BoardNumber, SocketAddr),
    /// The gateway's timing: its uplink's timeout is how long a visit waits for the heartbeat.
    pub config: gateway::Config,
    /// With an external ground (`mmic sim --ground-tm-to`): one JSON line per packet
    /// crossing the ground link.
    pub wire: Option<WireLog>,
    /// The server board's restarts (`--inject reboot-server@S`): it keeps the newest
    /// telecommand key per source (decision `restart-server`); a visit going on is broken off.
    pub restarts: Downtime,
}

/// The packets between an external ground and the gateway, one JSON line each, as
/// `mmic ground robot` prints them (ground/README.md): `{"dir":"tc","hex":..,"refused":null|check}`
/// per telecommand datagram, `{"dir":"tm","hex":..}` per telemetry packet sent. Behind the space
/// data link ([`FrameGatewayTask`]) one line per frame instead:
/// `{"dir":"tc-frame","hex":..,"refused":null|check,"farm":verdict|null,"packets":[hex,..]}` per TC
/// frame received (the frame check that refused it, or FARM-1's verdict as [`verdict_name`] writes
/// it; the packets it carries), `{"dir":"tm-frame","hex":..}` per TM frame sent.
#[derive(Clone)]
pub struct WireLog(pub Arc<Mutex<Box<dyn Write + Send>>>);

impl WireLog {
    /// Writes one line and flushes it (the reader waits on it).
    pub fn line(&self, v: Value) {
        if let Ok(mut w) = self.0.lock() {
            let _ = writeln!(w, "{v}").and_then(|_| w.flush());
        }
    }
}

/// One robot, eight waiting telecommands, 64 remembered keys.
type SimGateway = Gateway<1, 8, 64>;

impl GatewayTask {
    /// Runs until the run stops.
    pub fn run(mut self, node: Node<'_>) {
        let board = self.robot.0;
        let mut g = SimGateway::new(self.config);
        g.add(board);
        // Its flash: the telecommand keys it took, written before the tick may send one on.
        let mut kept = Kept::new();
        let mut buf = [0u8; 2048];
        while node.running() {
            let now = node.poll();
            match restart_phase(&node, &mut self.restarts, now) {
                Phase::WentDown | Phase::Down => {
                    lose_datagrams(&self.from_ground);
                    std::thread::sleep(SERVER_IDLE);
                    continue;
                }
                Phase::CameUp => {
                    g = SimGateway::new(self.config);
                    g.add_restarted(board, kept.clone());
                }
                Phase::Running => {}
            }
            let mut busy = false;
            // Until board A's first heartbeat the gateway holds telecommands back itself.
            while let Ok(n) = self.from_ground.recv(&mut buf) {
                busy = true;
                let bytes = buf.get(..n).unwrap_or(&[]);
                let refused = g.tc_packet(bytes);
                if let Some(w) = &self.wire {
                    w.line(json!({"dir": "tc", "hex": super::log::hex(bytes),
                                  "refused": refused.as_ref().err().map(|e| e.name())}));
                }
                match refused {
                    Ok(out) => self.reports(&node, &mut g, out),
                    Err(e) => node.event(
                        now,
                        json!({"type": "tc_refused", "error": e.to_string(),
                               "hex": super::log::hex(bytes)}),
                    ),
                }
            }
            if let Some(k) = g.kept(board) {
                kept = k;
            }
            let out = g.tick(node.clock.now_ms());
            let visits = out.to_robots.clone();
            self.reports(&node, &mut g, out);
            for (board, command) in visits {
                busy = true;
                if board == self.robot.0 {
                    self.visit(&node, &mut g, command.to_bytes());
                }
            }
            if !busy {
                std::thread::sleep(SERVER_IDLE);
            }
        }
    }

    /// Writes the reports of `out` to the ground.
    fn reports<const M: usize>(&mut self, node: &Node<'_>, g: &mut SimGateway, out: Out<M>) {
        if out.overflow > 0 {
            node.event(
                node.clock.now_ms(),
                json!({"type": "overflow", "count": out.overflow}),
            );
        }
        for tm in &out.reports {
            let now = node.clock.now_ms();
            let mut b = [0u8; MAX_TM_LEN];
            match g.encode(tm, now, &mut b) {
                Ok(n) => {
                    let p = b.get(..n).unwrap_or(&[]);
                    self.to_ground.send(now, p);
                    if let Some(w) = &self.wire {
                        w.line(json!({"dir": "tm", "hex": super::log::hex(p)}));
                    }
                }
                Err(e) => node.event(now, json!({"type": "tm_unwritten", "error": e.to_string()})),
            }
        }
    }

    /// One visit of board A: connect, send the command, wait up to the gateway's uplink
    /// timeout for the heartbeat and hand it to the gateway, disconnect.
    fn visit(&mut self, node: &Node<'_>, g: &mut SimGateway, packet: [u8; COMMAND_LEN]) {
        let (now, wait) = (node.clock.now_ms(), self.config.uplink.timeout_ms);
        let mut visit = Visit::new(now, self.robot.0, packet, wait);
        let Some(sock) = connect(&self.robot.1, visit.packet()) else {
            return;
        };
        let restarts = &self.restarts;
        let up = || !restarts.due(node.clock.now_ms());
        let hb = await_heartbeat_with(node, sock, &mut visit, up)
            .and_then(|b| mmic::wire::heartbeat::HeartbeatRepr::parse(&b).ok());
        if let Some(hb) = hb {
            let out = g.heartbeat(node.clock.now_ms(), &hb);
            self.reports(node, g, out);
        }
    }
}

/// The server board as the PUS gateway behind the space data link (`--protocol pus --link
/// frames`): one TC transfer frame per datagram from the ground into
/// [`FrameGateway::tc_frame`] (FARM-1, then the packets into the gateway), the visits of board
/// A as [`GatewayTask`]'s, and every TM transfer frame [`FrameGateway::frame`] says is due —
/// a gathered report, a changed CLCW, and at least one every idle period — to the ground, one
/// per datagram. The link keeps going during a visit.
///
/// [`FrameGateway::tc_frame`]: mmic::node::server::frames::FrameGateway::tc_frame
/// [`FrameGateway::frame`]: mmic::node::server::frames::FrameGateway::frame
pub struct FrameGatewayTask {
    /// Where the ground's TC frames arrive (non-blocking).
    pub from_ground: UdpSocket,
    /// The ground's UDP socket.
    pub to_ground: Lossy<UdpOut>,
    /// The robot's board A and where it listens.
    pub robot: (BoardNumber, SocketAddr),
    /// The gateway's timing: its uplink's timeout is how long a visit waits for the heartbeat.
    pub config: gateway::Config,
    /// With an external ground: one JSON line per frame crossing the ground link
    /// ([`WireLog`]: `tc-frame` and `tm-frame` lines).
    pub wire: Option<WireLog>,
    /// Where the server board's figures of the link (FARM-1, TM frames) go when the run ends.
    pub stats: Arc<Mutex<FrameStats>>,
    /// SDLS on the link: the robot's TC and TM keys.
    pub sdls: Option<(Key256, Key256)>,
    /// Its flash ([`super::durable`]): the SDLS counters, FARM-1's progress and the kept
    /// telecommand keys (memory for the run, or the state file of given keys).
    pub store: super::durable::Durable,
    /// The ground's address: FARM-1 obeys BC frames only from it (decision `sdls-bc-origin`;
    /// on loopback every local process shares it).
    pub ground: std::net::IpAddr,
    /// The server board's restarts (`--inject reboot-server@S`): it boots from its store
    /// (decisions `restart-server`, `sdls-counters`); a visit going on is broken off.
    pub restarts: Downtime,
}

/// One robot, eight waiting telecommands, 64 remembered keys, 4 KiB of TM packets waiting for
/// frames (the virtual-time engine's type).
type SimFrameGateway = super::durable::FrameGateway;

/// FARM-1's verdict on a frame, for the wire log: `accept`, `discard:<reason>` (the reason's
/// name), `unlock`, `set-vr:<V(R)>` (with ` (not executed)` when Lockout kept it from acting),
/// `released`.
pub fn verdict_name(v: &Verdict) -> String {
    match v {
        Verdict::Accept => "accept".into(),
        Verdict::Discard(r) => format!("discard:{}", r.name()),
        Verdict::Control { command, executed } => {
            let c = match command {
                ControlCommand::Unlock => "unlock".to_string(),
                ControlCommand::SetVr(v) => format!("set-vr:{v}"),
            };
            if *executed {
                c
            } else {
                c + " (not executed)"
            }
        }
        Verdict::Released => "released".into(),
    }
}

impl FrameGatewayTask {
    /// Runs until the run stops; then adds the server board's figures to [`Self::stats`]. A
    /// store that does not boot (not provisioned for the keys) stops the link: nothing is
    /// taken or sent, and the log says why.
    pub fn run(mut self, node: Node<'_>) {
        let board = self.robot.0;
        let mut g = self.boot(&node);
        // Whether this life's figures are in `stats` already (it went down).
        let mut counted = false;
        while node.running() {
            let now = node.poll();
            match restart_phase(&node, &mut self.restarts, now) {
                Phase::WentDown | Phase::Down => {
                    if let (false, Some(g)) = (counted, &g) {
                        if let Ok(mut s) = self.stats.lock() {
                            s.add_server(g, board);
                        }
                    }
                    counted = true;
                    lose_datagrams(&self.from_ground);
                    std::thread::sleep(SERVER_IDLE);
                    continue;
                }
                Phase::CameUp => {
                    g = self.boot(&node);
                    counted = false;
                }
                Phase::Running => {}
            }
            let Some(gw) = g.as_deref_mut() else {
                // The link stopped: what arrives is not taken.
                lose_datagrams(&self.from_ground);
                std::thread::sleep(SERVER_IDLE);
                continue;
            };
            super::durable::persist_gateway(gw, &self.store);
            let mut busy = self.link(&node, gw);
            let visits = super::durable::tick_gateway(gw, &self.store, node.clock.now_ms());
            for (board, command) in visits {
                busy = true;
                if board == self.robot.0 {
                    self.visit(&node, gw, command.to_bytes());
                }
            }
            self.tm_frames(&node, gw);
            if !busy {
                std::thread::sleep(SERVER_IDLE);
            }
        }
        if let (false, Some(g)) = (counted, &g) {
            if let Ok(mut s) = self.stats.lock() {
                s.add_server(g, board);
            }
        }
    }

    /// The gateway as it starts, from its store ([`super::durable::boot_gateway`]); `None`
    /// (logged) when the store refuses it.
    fn boot(&self, node: &Node<'_>) -> Option<Box<SimFrameGateway>> {
        let board = self.robot.0;
        match super::durable::boot_gateway(self.config, board, &self.store, self.sdls.clone()) {
            Ok(g) => Some(g),
            Err(e) => {
                node.event(
                    node.clock.now_ms(),
                    json!({"type": "link_stopped", "why": e.to_string()}),
                );
                None
            }
        }
    }

    /// The link's own work: every TC frame waiting taken, the TM frames due sent. Whether a TC
    /// frame came.
    fn link(&mut self, node: &Node<'_>, g: &mut SimFrameGateway) -> bool {
        let mut buf = [0u8; 2048];
        let mut busy = false;
        while let Ok((n, from)) = self.from_ground.recv_from(&mut buf) {
            busy = true;
            let now = node.clock.now_ms();
            let bytes = buf.get(..n).unwrap_or(&[]);
            let origin = if from.ip() == self.ground {
                Origin::Ground
            } else {
                Origin::Elsewhere
            };
            let got = g.tc_frame_from(now, bytes, origin);
            // What a restart resumes from, before anything of the frame leaves the board.
            super::durable::persist_gateway(g, &self.store);
            // With SDLS a data frame's packets are ciphertext: its security header instead.
            let secured = self.sdls.is_some();
            let sec = if secured {
                super::log::sdls_header(bytes)
            } else {
                Value::Null
            };
            if let Err(e) = &got.verdict {
                let mut ev = json!({"type": "tc_frame_refused", "check": e.name(),
                                    "layer": e.layer(), "hex": super::log::hex(bytes)});
                if secured {
                    ev["sdls"] = sec.clone();
                }
                node.event(now, ev);
            }
            if let Some(w) = &self.wire {
                let config = tc_frame::mission(SpacecraftId::of_board(self.robot.0));
                let packets: Vec<String> = TcFrame::new_checked(bytes, &config)
                    .map(|f| {
                        f.packets()
                            .filter_map(Result::ok)
                            .map(super::log::hex)
                            .collect()
                    })
                    .unwrap_or_default();
                let mut line = json!({"dir": "tc-frame", "hex": super::log::hex(bytes),
                              "refused": got.verdict.as_ref().err().map(|e| e.name()),
                              "farm": got.verdict.as_ref().ok().map(verdict_name),
                              "packets": packets});
                if secured && !sec.is_null() {
                    line["packets"] = Value::Null;
                    line["sdls"] = sec;
                }
                w.line(line);
            }
        }
        self.tm_frames(node, g);
        busy
    }

    /// Every TM frame due now, to the ground.
    fn tm_frames(&mut self, node: &Node<'_>, g: &mut SimFrameGateway) {
        let mut buf = [0u8; TM_FRAME_LEN];
        let now = node.clock.now_ms();
        while let Some((_, n)) = g.frame(now, &mut buf) {
            let f = buf.get(..n).unwrap_or(&[]);
            self.to_ground.send(now, f);
            if let Some(w) = &self.wire {
                w.line(json!({"dir": "tm-frame", "hex": super::log::hex(f)}));
            }
        }
    }

    /// One visit of board A, as [`GatewayTask`]'s, the link served while it waits.
    fn visit(&mut self, node: &Node<'_>, g: &mut SimFrameGateway, packet: [u8; COMMAND_LEN]) {
        let (now, wait) = (node.clock.now_ms(), self.config.uplink.timeout_ms);
        let mut visit = Visit::new(now, self.robot.0, packet, wait);
        let Some(sock) = connect(&self.robot.1, visit.packet()) else {
            return;
        };
        let hb = await_heartbeat_with(node, sock, &mut visit, || {
            self.link(node, g);
            !self.restarts.due(node.clock.now_ms())
        })
        .and_then(|b| mmic::wire::heartbeat::HeartbeatRepr::parse(&b).ok());
        if let Some(hb) = hb {
            g.heartbeat(node.clock.now_ms(), &hb);
            self.tm_frames(node, g);
        }
    }
}
