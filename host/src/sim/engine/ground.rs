//! The ground's side of the run: its loop ticking every plan runner, what it writes to each
//! server board (through FOP-1 with `--link frames`), and the TM frames it takes back.

use super::agenda::{Ev, Hop};
use super::state::Engine;
use crate::sim::inject::Node;
use crate::sim::shell::Ground;
use crate::sim::Protocol;
use serde_json::json;

/// How often the ground's loop ticks its plan runners, ms (packets from the server boards are
/// taken as they arrive; this is the resolution of the runners' own timers: the 1.2 s slots
/// and 0.7 s answer windows).
pub const GROUND_TICK_MS: u32 = 10;

impl<G: Ground> Engine<'_, G> {
    /// The ground's loop: every plan runner ticks; false when the run is over.
    pub(super) fn ground_tick(&mut self) -> bool {
        let now = self.now_ms();
        let over = self.ground.all_done() && !self.cfg.run_to_end;
        if now > self.cfg.max_sim_ms || over {
            return false;
        }
        self.ground_links_tick();
        for i in 0..self.robots.len() {
            if self.robots[i].down[Node::Ground as usize] {
                continue;
            }
            if let Some(p) = self.ground.tick(i, now) {
                self.ground_sends(i, &p);
            }
        }
        self.ground.progress(now);
        if self.ground.all_done() && !self.cfg.run_to_end {
            return false;
        }
        self.at(self.now + GROUND_TICK_MS as u64 * 1000, Ev::GroundTick);
        true
    }

    /// The ground writes `p` to robot `i`'s server board (through FOP-1 with `--link frames`:
    /// the frames due go out).
    pub(super) fn ground_sends(&mut self, i: usize, p: &[u8]) {
        if self.cfg.protocol == Protocol::Legacy {
            if let Some(w) = &mut self.watch {
                w.commanded(i, p);
            }
        }
        let now = self.now_ms();
        self.robots[i].persist();
        if let Some(gl) = self.robots[i].ground_link.as_mut() {
            let mut frames = Vec::new();
            if gl
                .send(p, now, &mut |f: &[u8]| frames.push(f.to_vec()))
                .is_err()
            {
                self.node_event(i, 2, json!({"type": "ground_outbox_full"}));
            }
            for f in frames {
                self.send(i, Hop::GroundToServer, 0, &f);
            }
            return;
        }
        self.send(i, Hop::GroundToServer, 0, p);
    }

    /// A TM frame reaches the ground's end of robot `i`'s link: its CLCW to FOP-1 (frames
    /// it sends again go out), its packets returned.
    pub(super) fn tm_frame_at_ground(&mut self, i: usize, bytes: &[u8]) -> Vec<Vec<u8>> {
        let now = self.now_ms();
        let (mut frames, mut packets) = (Vec::new(), Vec::new());
        self.robots[i].persist();
        if let Some(gl) = self.robots[i].ground_link.as_mut() {
            let refused = gl.tm_frame(
                now,
                bytes,
                &mut |f: &[u8]| frames.push(f.to_vec()),
                &mut |p: &[u8]| packets.push(p.to_vec()),
            );
            if let Err(e) = refused {
                self.node_event(i, 2, json!({"type": "tm_frame_refused", "check": e.name()}));
            }
        }
        for f in frames {
            self.send(i, Hop::GroundToServer, 0, &f);
        }
        packets
    }

    /// The ground's end of every link: timer T1.
    fn ground_links_tick(&mut self) {
        let now = self.now_ms();
        for i in 0..self.robots.len() {
            let mut frames = Vec::new();
            self.robots[i].persist();
            if let Some(gl) = self.robots[i].ground_link.as_mut() {
                gl.tick(now, &mut |f: &[u8]| frames.push(f.to_vec()));
            }
            for f in frames {
                self.send(i, Hop::GroundToServer, 0, &f);
            }
        }
    }
}
