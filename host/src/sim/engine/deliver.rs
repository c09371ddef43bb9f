//! Bytes arriving at the end of a hop: handed to the node there, unless it is down.

use super::agenda::Hop;
use super::robot::Board;
use super::state::Engine;
use crate::sim::inject::Node;
use crate::sim::shell::Ground;
use crate::sim::{LinkLayer, Protocol};
use mmic::wire::deframer::{Deframed, Deframer};
use mmic_replay::trace::Record;

/// Each packet a stream's deframer finds in `bytes` (its next read), as it finds it.
fn each_packet(d: &mut Deframer<256>, bytes: &[u8], mut f: impl FnMut(&[u8])) {
    d.feed(bytes, |e| {
        if let Deframed::Frame(p) = e {
            f(p.as_bytes());
        }
    });
}

/// The node at the end of `hop`.
fn receiver(hop: Hop) -> Node {
    match hop {
        Hop::GroundToServer | Hop::AToServer => Node::Server,
        Hop::ServerToA | Hop::BToA => Node::A,
        Hop::AToB => Node::B,
        Hop::ServerToGround => Node::Ground,
    }
}

impl<G: Ground> Engine<'_, G> {
    /// `bytes` arrive at the end of robot `i`'s `hop` (on WiFi connection `conn`).
    pub(super) fn deliver(&mut self, i: usize, hop: Hop, conn: u64, bytes: Vec<u8>) {
        // A node that is down (restarting) hears nothing.
        if self.robots[i].down[receiver(hop) as usize] {
            self.log_packet(i, hop, "node_down", &bytes);
            return;
        }
        match hop {
            Hop::GroundToServer => self.at_server(i, bytes),
            Hop::ServerToGround => self.at_ground(i, bytes),
            Hop::ServerToA => self.wifi_bytes(i, conn, &bytes),
            Hop::AToServer => self.heartbeat_at_server(i, conn, &bytes),
            Hop::AToB => {
                self.record(i, |t| Record::ToB { t, bytes: &bytes });
                let r = &mut self.robots[i];
                let queue = &mut r.b_from_a;
                each_packet(&mut r.b_reader, &bytes, |p| {
                    if let Ok(p) = p.try_into() {
                        queue.push_back(p);
                    }
                });
            }
            Hop::BToA => {
                self.record(i, |t| Record::ToA { t, bytes: &bytes });
                let r = &mut self.robots[i];
                let queue = &mut r.a_from_b;
                each_packet(&mut r.a_reader, &bytes, |p| {
                    if let Ok(p) = p.try_into() {
                        queue.push_back(p);
                    }
                });
            }
        }
    }

    /// The ground's bytes reach robot `i`'s server board: into its inbox, then its loop.
    fn at_server(&mut self, i: usize, bytes: Vec<u8>) {
        self.record(i, |t| Record::ServerIn { t, bytes: &bytes });
        let r = &mut self.robots[i];
        match r.board() {
            Board::Relay(_) => {
                let inbox = &mut r.inbox;
                each_packet(&mut r.server_reader, &bytes, |p| {
                    inbox.push_back(p.to_vec())
                });
            }
            Board::Gateway(_) => r.inbox.push_back(bytes),
            Board::Frames(_) => {
                if let Some(a) = &mut r.attacker {
                    a.delivered(&bytes);
                }
                r.inbox.push_back(bytes);
            }
        }
        self.server_loop(i);
    }

    /// Robot `i`'s server board's bytes reach the ground: its packets to the plan runner,
    /// and what it answers back.
    fn at_ground(&mut self, i: usize, bytes: Vec<u8>) {
        let now = self.now_ms();
        let packets = match self.cfg.protocol {
            Protocol::Legacy => {
                let mut packets = Vec::new();
                let reader = &mut self.robots[i].ground_reader;
                each_packet(reader, &bytes, |p| packets.push(p.to_vec()));
                packets
            }
            Protocol::Pus if self.cfg.link == LinkLayer::Frames => {
                self.tm_frame_at_ground(i, &bytes)
            }
            Protocol::Pus => vec![bytes],
        };
        for p in packets {
            if let Some(out) = self.ground.receive(i, now, &p) {
                self.ground_sends(i, &out);
            }
        }
    }
}
