//! The server board behind the space data link (`--link frames`): the ground's TC frames (and
//! the attacker's) through FARM-1 into the gateway, the TM frames due back to the ground, and
//! the link's figures of the run.

use super::agenda::Hop;
use super::robot::Board;
use super::state::Engine;
use crate::sim::log;
use crate::sim::shell::Ground;
use crate::sim::{FrameStats, LinkLayer, Protocol};
use mmic::link::farm::Verdict;
use mmic::node::server::frames::{FrameRefusal, Origin};
use mmic::node::server::visit::Visit;
use serde_json::{json, Value};

impl<G: Ground> Engine<'_, G> {
    /// The server board's loop behind the space data link: the ground's TC frames through
    /// FARM-1 into the gateway, the gateway's tick, the TM frames due, the next visit.
    pub(super) fn frames_loop(&mut self, i: usize, inbox: Vec<Vec<u8>>) {
        let now = self.now_ms();
        let number = self.robots[i].number;
        self.robots[i].persist();
        let attacks: Vec<Vec<u8>> = self.robots[i]
            .attacker
            .as_mut()
            .map(|a| a.waiting.drain(..).collect())
            .unwrap_or_default();
        let frames = inbox
            .into_iter()
            .map(|f| (f, false))
            .chain(attacks.into_iter().map(|f| (f, true)));
        for (f, attack) in frames {
            if !self.tc_frame(i, now, &f, attack) {
                return;
            }
        }
        let Some(visits) = self.robots[i].tick_frames(now) else {
            return;
        };
        let visit = visits
            .iter()
            .find(|(b, _)| *b == number)
            .map(|(_, c)| c.to_bytes());
        self.tm_frames(i);
        if let Some(packet) = visit {
            let wait = self.cfg.gateway.uplink.timeout_ms;
            self.start_visit(i, Visit::new(now, number, packet, wait));
            return;
        }
        let Board::Frames(g) = self.robots[i].board() else {
            return;
        };
        if let Some(t) = g.next_deadline(now) {
            let at = (t.max(now.saturating_add(1)) as u64) * 1000;
            self.wake_server(i, at);
        }
    }

    /// One TC frame `f` (the attacker's if `attack`) into robot `i`'s gateway, its verdict
    /// logged; false if the server board is no gateway behind frames.
    fn tc_frame(&mut self, i: usize, now: u32, f: &[u8], attack: bool) -> bool {
        let secured = self.cfg.sdls.is_some();
        let Board::Frames(g) = self.robots[i].board_mut() else {
            return false;
        };
        // The attacker sends from its own address (decision sdls-bc-origin).
        let origin = if attack {
            Origin::Elsewhere
        } else {
            Origin::Ground
        };
        let got = g.tc_frame_from(now, f, origin);
        // The security header as sent (never the key; the data stays ciphertext).
        let sec = if secured {
            log::sdls_header(f)
        } else {
            Value::Null
        };
        if attack {
            self.attack_outcome(i, now, f, &got.verdict);
        }
        match got.verdict {
            Err(e) => {
                let mut ev = json!({"type": "tc_frame_refused", "check": e.name(),
                                    "layer": e.layer(), "hex": log::hex(f)});
                if secured {
                    ev["sdls"] = sec;
                    ev["attack"] = json!(attack);
                }
                self.node_event(i, 2, ev);
            }
            Ok(v) if self.packet_log => {
                let mut ev = json!({"type": "tc_frame", "farm": format!("{v:?}"),
                                    "packets": got.accepted, "refused": got.refused});
                if secured {
                    ev["sdls"] = sec;
                }
                self.node_event(i, 2, ev);
            }
            Ok(_) => {}
        }
        true
    }

    /// What became of an attack frame: counted, and none may reach FARM-1 (the watch's
    /// `forged-frame`).
    fn attack_outcome(
        &mut self,
        i: usize,
        now: u32,
        f: &[u8],
        verdict: &Result<Verdict, FrameRefusal>,
    ) {
        let Some(a) = self.robots[i].attacker.as_mut() else {
            return;
        };
        if let Some(w) = &mut self.watch {
            w.attack_judged();
        }
        match verdict {
            Err(e) if e.layer() == "sdls" => a.refused_sdls += 1,
            Err(_) => a.refused_frame += 1,
            Ok(v) => {
                a.passed += 1;
                let detail = format!(
                    "an attack frame reached FARM-1 ({v:?}): {}",
                    log::hex(f.get(..24).unwrap_or(f))
                );
                if let Some(w) = &mut self.watch {
                    w.forged(i, now, detail);
                }
            }
        }
    }

    /// The TM frames due at robot `i`'s server board, sent to the ground.
    pub(super) fn tm_frames(&mut self, i: usize) {
        let now = self.now_ms();
        self.robots[i].persist();
        let mut out = Vec::new();
        if let Board::Frames(g) = self.robots[i].board_mut() {
            let mut buf = [0u8; mmic::link::tm_frame::TM_FRAME_LEN];
            while let Some((_, n)) = g.frame(now, &mut buf) {
                out.push(buf.get(..n).unwrap_or(&[]).to_vec());
            }
        }
        for f in out {
            self.send(i, Hop::ServerToGround, 0, &f);
        }
    }

    /// The space data link's figures of the run, all robots.
    pub(super) fn frame_stats(&self) -> Option<FrameStats> {
        if self.cfg.link != LinkLayer::Frames || self.cfg.protocol != Protocol::Pus {
            return None;
        }
        let mut s = FrameStats::default();
        for r in &self.robots {
            s = s.merged(r.frames());
            if let (Some(a), Some(sdls)) = (&r.attacker, s.sdls.as_mut()) {
                sdls.attack_frames += a.sent;
                sdls.attacks_refused_sdls += a.refused_sdls;
                sdls.attacks_refused_frame += a.refused_frame;
                sdls.attacks_passed += a.passed;
            }
        }
        Some(s)
    }
}
