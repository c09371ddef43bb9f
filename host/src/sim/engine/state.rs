//! The engine's state for one run, and what every part of it does alike: schedule an event,
//! write bytes to a hop, log a node's event, append to the replay trace.

use super::agenda::{Agenda, Ev, Hop};
use super::link::Fate;
use super::robot::{Robot, DUPLICATE};
use super::watch::Watch;
use crate::sim::log::Log;
use crate::sim::shell::{Ground, GroundSide};
use crate::sim::{LinkLayer, Protocol, SimConfig};
use mmic_replay::trace::{self, Record};
use serde_json::Value;

/// The engine's state for one run.
pub(super) struct Engine<'c, G: Ground> {
    pub(super) cfg: &'c SimConfig,
    /// The current instant, µs.
    pub(super) now: u64,
    pub(super) agenda: Agenda,
    pub(super) robots: Vec<Robot>,
    pub(super) ground: GroundSide<G>,
    pub(super) log: Option<Log>,
    pub(super) packet_log: bool,
    pub(super) conns: u64,
    pub(super) tokens: u64,
    pub(super) watch: Option<Watch>,
    pub(super) status: Value,
    /// Robot 1's replay trace, when recording.
    pub(super) trace: Option<Vec<u8>>,
    /// Accepted executions of each (robot, sequence number ≠ 0) by board A.
    pub(super) executions: std::collections::HashMap<(usize, u16), u32>,
}

impl<G: Ground> Engine<'_, G> {
    /// Schedules `ev` at `at`, µs.
    pub(super) fn at(&mut self, at: u64, ev: Ev) {
        self.agenda.at(at, ev);
    }

    pub(super) fn now_ms(&self) -> u32 {
        (self.now / 1000) as u32
    }

    /// Appends robot `i`'s call to the replay trace, if recording (robot 1 only).
    pub(super) fn record<'b>(&mut self, i: usize, r: impl FnOnce(u32) -> Record<'b>) {
        if i == 0 {
            let t = self.now_ms();
            if let Some(trace) = &mut self.trace {
                r(t).emit(trace);
            }
        }
    }

    /// Logs robot `i`'s event from its node `node` (0 board A, 1 board B, 2 the server board).
    pub(super) fn node_event(&self, i: usize, node: usize, what: Value) {
        if let (Some(l), true) = (&self.log, self.cfg.log_events) {
            l.event(self.now_ms(), &self.robots[i].names[node], what);
        }
    }

    /// Logs a packet on robot `i`'s `hop` with what became of it, if packets are logged.
    pub(super) fn log_packet(&self, i: usize, hop: Hop, what: &str, bytes: &[u8]) {
        if self.packet_log {
            if let Some(l) = &self.log {
                let (link, from, to) = self.robots[i].ends(hop, self.cfg.protocol);
                l.packet(self.now_ms(), link, from, to, what, bytes);
            }
        }
    }

    /// Writes `bytes` to robot `i`'s `hop` at the current instant: logged with its fate, and
    /// delivered (once or twice) unless lost or cut.
    pub(super) fn send(&mut self, i: usize, hop: Hop, conn: u64, bytes: &[u8]) -> Fate {
        let now = self.now;
        let sent = self.robots[i].links[hop as usize].send(now);
        self.log_packet(i, hop, sent.fate.name(), bytes);
        if sent.at_us.len() > 1 {
            self.log_packet(i, hop, "duplicated", bytes);
        }
        for (k, at) in sent.at_us.iter().enumerate() {
            self.at(
                *at,
                Ev::Deliver {
                    robot: i,
                    hop,
                    conn: if k == 0 { conn } else { conn | DUPLICATE },
                    bytes: bytes.to_vec(),
                },
            );
        }
        sent.fate
    }

    /// Logs a heartbeat board A's WiFi task dropped with no server connected.
    pub(super) fn unconnected(&self, i: usize, hb: &[u8]) {
        if self.packet_log {
            if let Some(l) = &self.log {
                let r = &self.robots[i];
                l.packet(
                    self.now_ms(),
                    "wifi",
                    &r.names[0],
                    &r.names[2],
                    "unconnected",
                    hb,
                );
            }
        }
    }
}

/// The replay trace's header of a run (`mmic sim --record`).
pub(super) fn record_header(cfg: &SimConfig) -> trace::Header {
    let frames = cfg.protocol == Protocol::Pus && cfg.link == LinkLayer::Frames;
    let sdls = cfg
        .sdls
        .as_ref()
        .filter(|_| frames)
        .and_then(|s| s.trace_keys());
    trace::Header {
        sdls,
        protocol: match cfg.protocol {
            Protocol::Legacy => trace::Protocol::Legacy,
            Protocol::Pus if sdls.is_some() => trace::Protocol::PusFramesSdls,
            Protocol::Pus if frames => trace::Protocol::PusFrames,
            Protocol::Pus => trace::Protocol::Pus,
        },
        board: super::robot::board_number(0),
        start: cfg.start_state,
        gateway: cfg.gateway,
    }
}

/// A side's senses as a trace reading.
pub(super) fn reading(s: &crate::sim::plant::Senses) -> trace::Reading {
    trace::Reading {
        raw: s.raw,
        arm_contracted: s.arm_contracted,
        bolter_at_home: s.bolter_at_home,
    }
}
