//! Each robot's server board: its loop between visits (the ground's packets, then the next
//! visit), the visit itself (a connection to board A, its command, the wait for the heartbeat),
//! and the PUS gateway's reports to the ground.

use super::agenda::{Ev, Hop};
use super::robot::{Board, DUPLICATE};
use super::state::Engine;
use crate::sim::inject::Node;
use crate::sim::log;
use crate::sim::shell::Ground;
use crate::sim::Protocol;
use mmic::node::server::gateway::Out;
use mmic::node::server::relay::Accepted;
use mmic::node::server::visit::Visit;
use mmic::wire::command::COMMAND_LEN;
use mmic::wire::heartbeat::HeartbeatRepr;
use mmic_replay::trace::Record;
use serde_json::json;

/// The largest telemetry packet the gateway writes, bytes.
const MAX_TM_LEN: usize = mmic::ccsds::tm::TM_MIN_LEN + mmic::node::server::gateway::MAX_TM_DATA;

impl<G: Ground> Engine<'_, G> {
    /// A heartbeat reaches the server board on connection `conn`.
    pub(super) fn heartbeat_at_server(&mut self, i: usize, conn: u64, bytes: &[u8]) {
        let now = self.now_ms();
        let r = &mut self.robots[i];
        let current = r
            .visit
            .as_ref()
            .is_some_and(|(c, _)| *c == conn & !DUPLICATE);
        if !current {
            self.node_event(
                i,
                2,
                json!({"type": "heartbeat_after_visit", "hex": log::hex(bytes)}),
            );
            return;
        }
        self.record(i, |t| Record::ServerHeartbeat { t, bytes });
        let r = &mut self.robots[i];
        let Some((_, v)) = r.visit.as_mut() else {
            return;
        };
        let Some(hb) = v.received(bytes) else {
            return;
        };
        match r.board_mut() {
            Board::Relay(_) => {
                self.end_visit(i);
                self.send(i, Hop::ServerToGround, 0, &hb);
            }
            Board::Gateway(g) => {
                let out = HeartbeatRepr::parse(&hb).map(|h| g.heartbeat(now, &h));
                self.end_visit(i);
                if let Ok(out) = out {
                    self.reports(i, out);
                }
            }
            Board::Frames(g) => {
                if let Ok(h) = HeartbeatRepr::parse(&hb) {
                    g.heartbeat(now, &h);
                }
                self.end_visit(i);
                self.tm_frames(i);
            }
        }
        self.server_loop(i);
    }

    /// The server board stops waiting for the visit's heartbeat on connection `conn`.
    pub(super) fn visit_timeout(&mut self, i: usize, conn: u64) {
        let now = self.now_ms();
        let due = |(c, v): &(u64, Visit)| *c == conn && v.left_ms(now).is_none();
        if self.robots[i].visit.as_ref().is_some_and(due) {
            self.end_visit(i);
            self.server_loop(i);
        }
    }

    /// The server board closes the visit's connection.
    pub(super) fn end_visit(&mut self, i: usize) {
        if let Some((conn, _)) = self.robots[i].visit.take() {
            let latency = self.robots[i].links[Hop::ServerToA as usize]
                .model()
                .latency_us;
            self.at(self.now + latency, Ev::Close { robot: i, conn });
        }
    }

    /// The server board opens a connection to board A and writes the visit's packet to it.
    pub(super) fn start_visit(&mut self, i: usize, visit: Visit) {
        let packet = *visit.packet();
        let wait_ms = visit.deadline().wrapping_sub(self.now_ms());
        self.conns += 1;
        let conn = self.conns;
        let latency = self.robots[i].links[Hop::ServerToA as usize]
            .model()
            .latency_us;
        self.at(self.now + latency, Ev::Open { robot: i, conn });
        self.robots[i].visit = Some((conn, visit));
        if self.cfg.protocol == Protocol::Pus {
            if let Some(w) = &mut self.watch {
                w.commanded(i, &packet);
            }
        }
        self.send(i, Hop::ServerToA, conn, &packet);
        self.at(
            self.now + wait_ms as u64 * 1000,
            Ev::VisitTimeout { robot: i, conn },
        );
    }

    /// The server board's loop, between visits: the ground's packets, then the next visit.
    pub(super) fn server_loop(&mut self, i: usize) {
        if self.robots[i].visit.is_some() || self.robots[i].down[Node::Server as usize] {
            return;
        }
        self.record(i, |t| Record::ServerLoop { t });
        let inbox: Vec<Vec<u8>> = self.robots[i].inbox.drain(..).collect();
        match self.robots[i].board() {
            Board::Relay(_) => self.relay_loop(i, inbox),
            Board::Frames(_) => self.frames_loop(i, inbox),
            Board::Gateway(_) => self.gateway_loop(i, inbox),
        }
    }

    /// The legacy relay's loop: the ground's packets queued, then the next visit.
    fn relay_loop(&mut self, i: usize, inbox: Vec<Vec<u8>>) {
        let now = self.now_ms();
        let number = self.robots[i].number;
        for p in inbox {
            let Board::Relay(srv) = self.robots[i].board_mut() else {
                return;
            };
            let Ok(packet) = <[u8; COMMAND_LEN]>::try_from(p.as_slice()) else {
                continue;
            };
            let what = match srv.accept(&packet) {
                Ok(Accepted::Queued) => json!({"type": "queued"}),
                Ok(Accepted::Resend) => json!({"type": "resend"}),
                Ok(Accepted::Superseded(old)) => {
                    json!({"type": "superseded", "old": log::hex(&old)})
                }
                Err(e) => json!({"type": "refused", "error": e.to_string()}),
            };
            self.node_event(i, 2, what);
        }
        let Board::Relay(srv) = self.robots[i].board_mut() else {
            return;
        };
        if let Some(visit) = Visit::next(srv, now, self.cfg.visit_ms) {
            // The engine's write to the link cannot fail (the link may lose it).
            visit.written(srv);
            if visit.board() == number {
                self.start_visit(i, visit);
            } else {
                let board = visit.board().get();
                self.node_event(i, 2, json!({"type": "no_such_robot", "board": board}));
            }
        }
    }

    /// The PUS gateway's loop: the ground's telecommands, its tick, the next visit or wake.
    fn gateway_loop(&mut self, i: usize, inbox: Vec<Vec<u8>>) {
        let now = self.now_ms();
        let number = self.robots[i].number;
        for p in inbox {
            let Board::Gateway(g) = self.robots[i].board_mut() else {
                return;
            };
            match g.tc_packet(&p) {
                Ok(out) => self.reports(i, out),
                Err(e) => self.node_event(
                    i,
                    2,
                    json!({"type": "tc_refused", "error": e.to_string(), "hex": log::hex(&p)}),
                ),
            }
        }
        let Board::Gateway(g) = self.robots[i].board_mut() else {
            return;
        };
        let out = g.tick(now);
        let visit = out
            .to_robots
            .iter()
            .find(|(b, _)| *b == number)
            .map(|(_, c)| c.to_bytes());
        self.reports(i, out);
        if let Some(packet) = visit {
            let wait = self.cfg.gateway.uplink.timeout_ms;
            self.start_visit(i, Visit::new(now, number, packet, wait));
            return;
        }
        let Board::Gateway(g) = self.robots[i].board() else {
            return;
        };
        if let Some(t) = g.next_deadline(now) {
            let at = (t.max(now.saturating_add(1)) as u64) * 1000;
            self.wake_server(i, at);
        }
    }

    /// The gateway's wake (its next deadline) with token `token`, unless a later one replaced
    /// it.
    pub(super) fn server_woken(&mut self, i: usize, token: u64) {
        if self.robots[i].server_wake.map(|(_, t)| t) == Some(token) {
            self.robots[i].server_wake = None;
            self.server_loop(i);
        }
    }

    /// Schedules the gateway's loop at `at` (µs) unless it runs sooner already.
    pub(super) fn wake_server(&mut self, i: usize, at: u64) {
        if self.robots[i].server_wake.is_some_and(|(t, _)| t <= at) {
            return;
        }
        self.tokens += 1;
        let token = self.tokens;
        self.robots[i].server_wake = Some((at, token));
        self.at(at, Ev::Server { robot: i, token });
    }

    /// The gateway's reports, written to the ground.
    fn reports<const M: usize>(&mut self, i: usize, out: Out<M>) {
        let now = self.now_ms();
        if out.overflow > 0 {
            self.node_event(i, 2, json!({"type": "overflow", "count": out.overflow}));
        }
        for tm in &out.reports {
            let Board::Gateway(g) = self.robots[i].board_mut() else {
                return;
            };
            let mut b = [0u8; MAX_TM_LEN];
            match g.encode(tm, now, &mut b) {
                Ok(n) => {
                    let p = b.get(..n).unwrap_or(&[]).to_vec();
                    self.send(i, Hop::ServerToGround, 0, &p);
                }
                Err(e) => {
                    self.node_event(
                        i,
                        2,
                        json!({"type": "tm_unwritten", "error": e.to_string()}),
                    );
                }
            }
        }
    }
}
