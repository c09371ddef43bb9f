//! Boards A and B of each robot: their control ticks, and board A's WiFi task (its session
//! with the server board and the hand-off queues to the control task).

use super::agenda::{Ev, Hop};
use super::planted::PlantedBug;
use super::robot::DUPLICATE;
use super::state::{reading, Engine};
use super::watch;
use crate::sim::inject::Node;
use crate::sim::log;
use crate::sim::shell::{event_json, Ground};
use mmic::node::robot::board_a::{self, BoardA};
use mmic::node::robot::wifi_session::Outgoing;
use mmic::wire::command::{CommandRepr, COMMAND_LEN};
use mmic_replay::trace::Record;
use serde_json::json;

/// How soon board A's WiFi task writes a heartbeat the control task queued, µs: the firmware's
/// WiFi task polls its connection with a 2 ms read timeout and then drains the queue, 1 ms
/// later on average.
pub const WIFI_TASK_US: u64 = 1_000;

impl<G: Ground> Engine<'_, G> {
    /// Board A's control task: one tick (while board A is down, the plant alone moves on).
    pub(super) fn tick_a(&mut self, i: usize) {
        let now = self.now_ms();
        let r = &mut self.robots[i];
        if r.down[Node::A as usize] {
            r.plant.advance(now);
            return;
        }
        let command = r.commands.split().1.pop();
        // Board A's flash: the record written before a tick that may run a new sequenced
        // command, then after the tick (decision `restart-board-a`).
        if let Some(d) = r.a.board.ahead(command.as_ref()) {
            r.kept_a = Some(d);
        }
        let from_b = r.a_from_b.pop_front();
        let out = r.a.tick(&mut r.plant, now, command, from_b);
        r.kept_a = Some(r.a.board.durable());
        self.count_executions(i, &out);
        if let (Some(s), true) = (self.robots[i].a.sensed, self.trace.is_some()) {
            self.record(i, |t| Record::TickA {
                t,
                reading: reading(&s),
            });
        }
        let r = &mut self.robots[i];
        if let Some(w) = &mut self.watch {
            w.tick_a(
                i,
                now,
                &watch::TickA::of(command, &r.a.board, &r.plant, &out),
            );
        }
        if self.cfg.log_events {
            for e in &out.events {
                self.node_event(i, 0, event_json(e));
            }
        }
        self.a_outputs(i, &out);
    }

    /// Counts board A's accepted executions of each sequenced command (nothing but a
    /// Heartbeat poll may run twice: `BoardA::may_run_again`).
    fn count_executions(&mut self, i: usize, out: &board_a::Outputs) {
        for e in &out.events {
            if let board_a::Event::Executed {
                seq,
                refusal: None,
                command,
            } = e
            {
                if *seq != 0 && !BoardA::may_run_again(*command) {
                    *self.executions.entry((i, *seq)).or_default() += 1;
                }
            }
        }
    }

    /// Board A's tick's outputs to its links: the command to board B, the heartbeat to the
    /// WiFi task's queue.
    fn a_outputs(&mut self, i: usize, out: &board_a::Outputs) {
        if let Some(b) = out.to_b {
            self.send(i, Hop::AToB, 0, &b);
        }
        if let Some(hb) = out.heartbeat {
            let r = &mut self.robots[i];
            if let Err(full) = r.heartbeats.split().0.push(hb) {
                self.node_event(
                    i,
                    0,
                    json!({"type": "handoff_full", "hex": log::hex(&full.0)}),
                );
            }
            self.at(self.now + WIFI_TASK_US, Ev::Wifi(i));
        }
    }

    /// Board B: one tick (none while it is down).
    pub(super) fn tick_b(&mut self, i: usize) {
        let now = self.now_ms();
        let r = &mut self.robots[i];
        if r.down[Node::B as usize] {
            return;
        }
        let command = r.b_from_a.pop_front();
        let out = r.b.tick(&mut r.plant, now, command);
        if let Some(s) = r.b.sensed {
            self.record(i, |t| Record::TickB {
                t,
                reading: reading(&s),
            });
        }
        let r = &mut self.robots[i];
        if let Some(w) = &mut self.watch {
            w.tick_b(i, now, &watch::SideMotion::of(&r.plant, 1));
        }
        if out.link_lost != r.b_lost {
            r.b_lost = out.link_lost;
            let holding = r.b_lost;
            self.node_event(i, 1, json!({"type": "link_lost", "holding": holding}));
        }
        if let Some(hb) = out.heartbeat {
            self.send(i, Hop::BToA, 0, &hb);
        }
    }

    /// Board A's WiFi task takes a connection: heartbeats made while nobody was connected
    /// are discarded (the library's session says so), then it serves this one.
    pub(super) fn wifi_opened(&mut self, i: usize, conn: u64) {
        self.record(i, |t| Record::WifiOpen { t });
        let now = self.now_ms();
        let r = &mut self.robots[i];
        r.wifi_conn = conn;
        let (_, mut queued) = r.heartbeats.split();
        let mut stale = Vec::new();
        r.wifi.open(now, std::iter::from_fn(|| queued.pop()), |hb| {
            stale.push(hb)
        });
        for hb in stale {
            self.unconnected(i, &hb);
        }
    }

    /// The server board's disconnection reaches board A's WiFi task.
    pub(super) fn wifi_closed(&mut self, i: usize, conn: u64) {
        let r = &mut self.robots[i];
        if r.wifi_conn == conn && r.wifi.close() {
            self.record(i, |t| Record::WifiClose { t });
        }
    }

    /// Board A's WiFi task writes the queued heartbeats to the open connection (or drops
    /// them, unconnected).
    pub(super) fn wifi_drain(&mut self, i: usize) {
        self.record(i, |t| Record::WifiDrain { t });
        while let Some(hb) = self.robots[i].heartbeats.split().1.pop() {
            let r = &mut self.robots[i];
            match r.wifi.heartbeat(hb) {
                Outgoing::Send(hb) => {
                    let conn = r.wifi_conn;
                    self.send(i, Hop::AToServer, conn, &hb);
                }
                Outgoing::Drop(hb) => self.unconnected(i, &hb),
            }
        }
    }

    /// Command bytes reach board A's WiFi task on connection `conn`.
    pub(super) fn wifi_bytes(&mut self, i: usize, conn: u64, bytes: &[u8]) {
        let copy = conn & DUPLICATE != 0;
        let r = &mut self.robots[i];
        if !r.wifi.is_open() || r.wifi_conn != conn & !DUPLICATE {
            self.node_event(i, 0, json!({"type": "wifi_closed", "hex": log::hex(bytes)}));
            return;
        }
        self.record(i, |t| Record::WifiBytes { t, bytes });
        let now = self.now_ms();
        let r = &mut self.robots[i];
        let mut packets: Vec<[u8; COMMAND_LEN]> = Vec::new();
        r.wifi.received(now, bytes, |c| packets.push(c));
        if copy && self.cfg.planted_bug == PlantedBug::DoubleExec {
            self.plant_double_exec(i, &mut packets);
        }
        for p in packets {
            let r = &mut self.robots[i];
            if let Err(full) = r.commands.split().0.push(p) {
                self.node_event(
                    i,
                    0,
                    json!({"type": "handoff_full", "hex": log::hex(&full.0)}),
                );
            }
        }
    }

    /// The planted double execution: a duplicated packet's copy handed on unsequenced.
    fn plant_double_exec(&mut self, i: usize, packets: &mut [[u8; COMMAND_LEN]]) {
        for p in packets.iter_mut() {
            if let Ok(mut c) = CommandRepr::parse(p) {
                let origin = *p;
                c.seq = 0;
                *p = c.to_bytes();
                if let Some(w) = &mut self.watch {
                    w.same_origin(i, &origin, p);
                }
            }
        }
    }
}
