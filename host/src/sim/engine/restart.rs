//! A node's restart (a power cycle): down at once, losing what it held in RAM, and up again
//! [`BOOT_MS`] later from what it kept (decisions `restart-*`).

use super::agenda::Ev;
use super::planted::PlantedBug;
use super::robot::{board_a_config, server_board, SimGroundLink};
use super::state::Engine;
use crate::sim::durable;
use crate::sim::inject::{Node, BOOT_MS};
use crate::sim::plant::Drives;
use crate::sim::shell::{Ground, SideA, SideB};
use crate::sim::{LinkLayer, Protocol};
use mmic::node::robot::board_a::BoardA;
use mmic::node::robot::board_b::{self, BoardB};
use mmic::node::robot::handoff::PacketQueue;
use mmic::node::robot::wifi_session::{WifiConfig, WifiSession};
use mmic::restart::ResetCause;
use mmic::wire::deframer::Deframer;
use serde_json::{json, Value};

impl<G: Ground> Engine<'_, G> {
    /// Robot `i`'s `node` goes down (a power cycle): what it held in RAM is gone, its
    /// connections drop, its outputs are unpowered; it comes up [`BOOT_MS`] later.
    pub(super) fn down(&mut self, i: usize, node: Node) {
        let now = self.now_ms();
        let r = &mut self.robots[i];
        let k = node as usize;
        if r.down[k] {
            return; // already restarting: one boot
        }
        r.down[k] = true;
        r.restarts[k] += 1;
        match node {
            Node::A => {
                r.commands = PacketQueue::new();
                r.heartbeats = PacketQueue::new();
                r.a_reader = Deframer::new();
                r.a_from_b.clear();
                r.wifi = WifiSession::new(WifiConfig::default());
                r.wifi_conn = 0;
                r.plant.advance(now);
                r.plant.drive_a(Drives::off(), None);
                if let Some(w) = &mut self.watch {
                    w.restarted_a(i, now);
                }
            }
            Node::B => {
                r.b_reader = Deframer::new();
                r.b_from_a.clear();
                r.plant.advance(now);
                r.plant.drive_b(Drives::off());
            }
            Node::Server => {
                r.visit = None;
                r.inbox.clear();
                r.server_reader = Deframer::new();
                r.server_wake = None;
                if let Some(a) = &mut r.attacker {
                    a.waiting.clear();
                }
                r.keep_server_figures();
            }
            Node::Ground => {
                r.ground_reader = Deframer::new();
                if let Some(gl) = r.ground_link.take() {
                    r.past_frames.add_ground(&gl);
                }
            }
        }
        self.node_event(i, k, json!({"type": "restart", "down_ms": BOOT_MS}));
        self.at(
            self.now + u64::from(BOOT_MS) * 1000,
            Ev::Up { robot: i, node },
        );
    }

    /// Robot `i`'s `node` boots from what it kept (decisions `restart-*`).
    pub(super) fn up(&mut self, i: usize, node: Node) {
        let cfg = self.cfg;
        let r = &mut self.robots[i];
        r.down[node as usize] = false;
        let booted = match node {
            Node::A => {
                let kept = match cfg.planted_bug {
                    PlantedBug::LogNotRestored => None,
                    _ => r.kept_a,
                };
                let board = BoardA::restarted(board_a_config(r.number), kept, ResetCause::PowerOn);
                r.kept_a = Some(board.durable());
                r.a = SideA::new(board);
                true
            }
            Node::B => {
                r.b = SideB::new(BoardB::restarted(board_b::Config::default()));
                true
            }
            Node::Server => self.server_up(i),
            Node::Ground => self.ground_up(i),
        };
        if !booted {
            return;
        }
        let boot = match node {
            Node::A => json!(self.robots[i].a.board.boot().to_wire()),
            _ => Value::Null,
        };
        self.node_event(i, node as usize, json!({"type": "boot", "boot": boot}));
    }

    /// The server board boots; false if its store refused it (its link stopped).
    fn server_up(&mut self, i: usize) -> bool {
        let r = &mut self.robots[i];
        // A store the run provisioned itself boots: a refusal here would be the simulator's
        // fault, and the server board then stays down (its link stopped).
        let kept = Some(r.kept_server.clone());
        match server_board(self.cfg, r.number, kept, &r.store, r.keys.clone()) {
            Ok(b) => r.set_board(b),
            Err(e) => {
                // Nothing reaches a stopped link: it stays down.
                r.down[Node::Server as usize] = true;
                let why = e.to_string();
                self.node_event(i, 2, json!({"type": "link_stopped", "why": why}));
                return false;
            }
        }
        self.wake_server(i, self.now);
        true
    }

    /// The ground restarts its side of robot `i`; false if the link's store refused it.
    fn ground_up(&mut self, i: usize) -> bool {
        let cfg = self.cfg;
        let now = self.now_ms();
        self.ground.restart(i, now);
        let r = &mut self.robots[i];
        if cfg.protocol == Protocol::Pus && cfg.link == LinkLayer::Frames {
            // FOP-1 starts afresh (its AD service initiated again with a CLCW check);
            // SDLS continues from the stored counters (decision `sdls-counters`).
            let mut gl = Box::new(SimGroundLink::new(r.number));
            if let Some(keys) = r.keys.clone() {
                if let Err(e) = durable::boot_ground(&mut gl, r.number, &r.store, keys) {
                    // The link stopped: the ground's end of it is gone with its RAM.
                    r.ground_link = None;
                    let why = e.to_string();
                    self.node_event(i, 3, json!({"type": "link_stopped", "why": why}));
                    return false;
                }
            }
            gl.start(now, &mut |_: &[u8]| {});
            r.ground_link = Some(gl);
            r.persist();
        }
        true
    }
}
