//! The server board as a PUS gateway: PUS-C telecommands from the ground in, the legacy
//! 14-byte commands to board A out, and the ST\[1\], ST\[3\], ST\[5\] and ST\[17\] telemetry back.
//!
//! Board A and its link stay as the paper has them. For each robot the gateway does what the
//! opsUI did — the legacy [`Uplink`] numbers each command, resends it until board A
//! acknowledges it and polls for heartbeats — and turns the outcomes into reports: ST\[1\] from
//! the uplink's outcome and the heartbeat's "command complete", ST\[3\] from the latest
//! heartbeat every collection interval, ST\[5\] from what changed between two heartbeats
//! ([`crate::pus::event`]). No robot behaviour is decided here (spec/decisions.toml,
//! `pus-gateway`).
//!
//! Exactly once: a telecommand is keyed on (APID, source ID, sequence count). A copy of a
//! telecommand still in the key log is never run again; its latest report is sent again. The
//! same key with other content is refused (`KEY_REUSED`). The legacy numbering below it keeps
//! board A's guarantee (one sequence number, one execution).
//!
//! ```
//! use mmic::command::Command;
//! use mmic::node::server::gateway::{Gateway, Tc};
//! use mmic::pus::request::Request;
//! use mmic::pus::verification::{RequestId, Stage};
//! use mmic::units::BoardNumber;
//! use mmic::wire::heartbeat::HeartbeatRepr;
//!
//! let mut g: Gateway<2, 4, 8> = Gateway::new(Default::default());
//! g.add(BoardNumber::ONE);
//! let tc = Tc { request: RequestId { apid: 0x101, seq_count: 1 }, source_id: 7, ack: 0b1001,
//!               request_of: Ok(Request::Function(Command::Stop)) };
//! let out = g.tc(&tc);
//! assert_eq!(out.reports[0].stage(), Some((Stage::Acceptance, true)));
//! // Until board A was heard from, the gateway polls and holds the telecommand back.
//! let poll = g.tick(0).to_robots[0].1;
//! assert_eq!(poll.command, Command::Heartbeat);
//! g.heartbeat(3, &HeartbeatRepr { last_seq: poll.seq, ..HeartbeatRepr::default() });
//! let out = g.tick(250); // the uplink's period: one command per 250 ms
//! let sent = out.to_robots[0].1;
//! assert_eq!(sent.command, Command::Stop);
//! // Board A answers: accepted, so started and (Stop being instantaneous) completed.
//! let hb = HeartbeatRepr { last_seq: sent.seq, ..HeartbeatRepr::default() };
//! let out = g.heartbeat(255, &hb);
//! let stages: Vec<_> = out.reports.iter().filter_map(|r| r.stage()).collect();
//! assert_eq!(stages, [(Stage::Completion, true)]); // start success not asked (ack 0b1001)
//! ```
// req: D:pus-gateway

mod robot;

pub use robot::{Job, Kept, KEPT_SOURCES};

mod ahead;

use crate::ccsds::cuc::Cuc;
use crate::ccsds::primary::{Apid, SeqCount};
use crate::ccsds::tc::TcRepr;
use crate::ccsds::tm::TmRepr;
use crate::ccsds::tm_header::TmSecondaryHeader;
use crate::ccsds::{EmitError, PacketError};
use crate::node::exactly_once::uplink::{self, Uplink};
use crate::pus::event;
use crate::pus::housekeeping::{DEFAULT_INTERVAL_MS, REPORT_LEN};
use crate::pus::request::{Request, RequestError, ST_VERIFICATION};
use crate::pus::verification::{Failure, Report, RequestId, Stage};
use crate::pus::{robot_apid, robot_of_apid};
use crate::units::{BoardNumber, Instant};
use crate::wire::command::CommandRepr;
use crate::wire::heartbeat::HeartbeatRepr;
use heapless::Vec;
use robot::Robot;

/// A telecommand the CCSDS layer accepted (header, CRC and APID checked), with its request
/// already read ([`Request::parse`]) or refused.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub struct Tc {
    /// Its request ID (APID and sequence count).
    pub request: RequestId,
    /// Its source ID (PUS-C TC secondary header).
    pub source_id: u16,
    /// Acknowledgement flags: bit 0 acceptance, 1 start, 2 progress, 3 completion (success
    /// reports are sent only when asked; failure reports always).
    pub ack: u8,
    /// The request, or why it is none.
    pub request_of: Result<Request, RequestError>,
}

/// Largest source data of a report the gateway makes.
pub const MAX_TM_DATA: usize = REPORT_LEN;

/// A report to send to the ground: service, subservice, source data, on the robot's APID.
#[derive(Debug, Clone, PartialEq, Eq, Hash)]
pub struct TmOut {
    /// APID (the robot's).
    pub apid: u16,
    /// Service type.
    pub service: u8,
    /// Subservice type.
    pub subservice: u8,
    /// Destination ID: the source ID of the TC it answers, 0 for unsolicited reports.
    pub destination: u16,
    /// Source data.
    pub data: Vec<u8, MAX_TM_DATA>,
}

impl TmOut {
    pub(crate) fn new(
        apid: u16,
        service: u8,
        subservice: u8,
        destination: u16,
        data: &[u8],
    ) -> TmOut {
        let mut v = Vec::new();
        // Every report the gateway builds fits (MAX_TM_DATA is the longest).
        let _ = v.extend_from_slice(data.get(..data.len().min(MAX_TM_DATA)).unwrap_or(&[]));
        TmOut {
            apid,
            service,
            subservice,
            destination,
            data: v,
        }
    }

    /// The index of its message type among the robot's counters.
    fn type_index(&self) -> usize {
        // The subservices' ranges keep both sums in 0..=12.
        match (self.service, self.subservice) {
            (1, s @ 1..=8) => usize::from(s).saturating_sub(1),
            (3, _) => 8,
            (5, s @ 1..=4) => usize::from(s).saturating_add(8),
            (17, _) => 13,
            _ => 15,
        }
    }

    /// For an ST\[1\] report: its stage and whether it reports success.
    pub fn stage(&self) -> Option<(Stage, bool)> {
        if self.service != ST_VERIFICATION {
            return None;
        }
        Report::parse(self.subservice, &self.data)
            .ok()
            .map(|r| (r.stage, r.failure.is_none()))
    }
}

/// Timing and sizes.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub struct Config {
    /// The legacy uplink's resend timing towards board A.
    pub uplink: uplink::Config,
    /// A heartbeat is asked for this often while nothing else is sent, ms; 0: never (then
    /// motions are not seen to complete: for models of the command path alone).
    pub poll_ms: u32,
    /// Initial housekeeping collection interval, ms.
    pub hk_interval_ms: u32,
    /// Periodic housekeeping on at start.
    pub hk_enabled: bool,
}

impl Default for Config {
    /// Resend every 250 ms with a 200 ms timeout, up to 10 attempts; poll every 250 ms;
    /// housekeeping every second, on.
    fn default() -> Config {
        Config {
            uplink: uplink::Config {
                period_ms: 250,
                timeout_ms: 200,
                max_attempts: 10,
            },
            poll_ms: 250,
            hk_interval_ms: DEFAULT_INTERVAL_MS,
            hk_enabled: true,
        }
    }
}

/// What a call asks the shell to do.
#[derive(Debug, Clone, Default, PartialEq, Eq)]
pub struct Out<const M: usize> {
    /// Send these legacy commands, each to its robot's board A (one per robot at most).
    pub to_robots: Vec<(BoardNumber, CommandRepr), M>,
    /// Send these reports to the ground, in order.
    pub reports: Vec<TmOut, M>,
    /// Reports or commands that did not fit (none while robots ≤ 16; counted, not silent).
    pub overflow: u16,
}

impl<const M: usize> Out<M> {
    fn push(&mut self, tm: TmOut) {
        if self.reports.push(tm).is_err() {
            self.overflow = self.overflow.saturating_add(1);
        }
    }
}

/// The gateway for up to `R` robots, `Q` waiting telecommands and `K` remembered keys each.
#[derive(Debug, Clone, PartialEq, Eq, Hash)]
pub struct Gateway<const R: usize, const Q: usize, const K: usize> {
    cfg: Config,
    robots: Vec<Robot<Q, K>, R>,
}

/// Reports per call.
const M: usize = 16;

fn report(stage: Stage, request: RequestId, failure: Option<Failure>) -> Report {
    Report {
        stage,
        request,
        failure,
    }
}

impl<const R: usize, const Q: usize, const K: usize> Gateway<R, Q, K> {
    /// No robots yet.
    pub const fn new(cfg: Config) -> Self {
        Gateway {
            cfg,
            robots: Vec::new(),
        }
    }

    /// Serves robot `board`; false when all `R` places are taken (or it is served already).
    pub fn add(&mut self, board: BoardNumber) -> bool {
        self.add_robot(board, Uplink::new(self.cfg.uplink, board), Kept::new())
    }

    /// Serves robot `board` after the server board restarted, with what it kept of it
    /// ([`Gateway::kept`], from flash): a copy of a telecommand taken before the restart (its
    /// sequence count not newer than the source's kept one) is never run again, and is
    /// reported failed with [`crate::pus::verification::RESTARTED`]; the legacy uplink first
    /// learns which numbers board A has taken ([`Uplink::after_restart`]). False as [`Gateway::add`].
    ///
    /// ```
    /// use mmic::command::Command;
    /// use mmic::node::server::gateway::{Gateway, Kept, Tc};
    /// use mmic::pus::request::Request;
    /// use mmic::pus::verification::{RequestId, Stage, RESTARTED};
    /// use mmic::units::BoardNumber;
    ///
    /// let tc = |seq_count| Tc { request: RequestId { apid: 0x101, seq_count }, source_id: 7,
    ///                           ack: 0b1001, request_of: Ok(Request::Function(Command::Stop)) };
    /// let mut g: Gateway<1, 4, 8> = Gateway::new(Default::default());
    /// g.add(BoardNumber::ONE);
    /// g.tc(&tc(41));
    /// let kept = g.kept(BoardNumber::ONE).unwrap(); // written to flash before any tick
    /// // The server board restarts; the ground sends telecommand 41 again, then 42.
    /// let mut g: Gateway<1, 4, 8> = Gateway::new(Default::default());
    /// g.add_restarted(BoardNumber::ONE, kept);
    /// let out = g.tc(&tc(41));
    /// assert_eq!(out.reports[0].stage(), Some((Stage::Start, false))); // 0x0202: not run again
    /// let out = g.tc(&tc(42));
    /// assert_eq!(out.reports[0].stage(), Some((Stage::Acceptance, true)));
    /// ```
    pub fn add_restarted(&mut self, board: BoardNumber, kept: Kept) -> bool {
        let uplink = Uplink::after_restart(self.cfg.uplink, board);
        self.add_robot(board, uplink, kept)
    }

    /// What to keep of robot `board` across a restart; write it whenever it changed, before
    /// the next [`Gateway::tick`].
    pub fn kept(&self, board: BoardNumber) -> Option<Kept> {
        self.robots
            .iter()
            .find(|r| r.board == board)
            .map(|r| r.marks.clone())
    }

    fn add_robot(&mut self, board: BoardNumber, uplink: Uplink, kept: Kept) -> bool {
        if self.robots.iter().any(|r| r.board == board) {
            return false;
        }
        self.robots
            .push(Robot {
                board,
                uplink,
                queue: Vec::new(),
                sent: None,
                running: Vec::new(),
                log: Vec::new(),
                last: None,
                stopped: false,
                hk_enabled: self.cfg.hk_enabled,
                hk_interval_ms: self.cfg.hk_interval_ms,
                hk_next: None,
                next_poll: None,
                tm_seq: SeqCount::default(),
                counters: [0; 16],
                marks: kept.clone(),
                restored: kept,
                write_ahead: false,
                cleared: None,
                wants_out: None,
            })
            .is_ok()
    }

    /// The earliest time from `now` on when something is due: a queued telecommand, a resend
    /// or its timeout, a poll, a housekeeping report (for a caller that sleeps until then, and
    /// for models that jump time). `now` itself when something is due already.
    pub fn next_deadline(&self, now: u32) -> Option<u32> {
        let wait = |t: u32| {
            let d = t.wrapping_sub(now);
            if d > i32::MAX.unsigned_abs() {
                0
            } else {
                d
            }
        };
        let mut best: Option<u32> = None;
        for r in &self.robots {
            let idle = r.uplink.is_idle();
            let times = [
                (idle && !r.queue.is_empty()).then_some(now),
                r.uplink.next_deadline(),
                (idle && self.cfg.poll_ms > 0).then(|| r.next_poll.map_or(now, Instant::millis)),
                (r.hk_enabled && r.last.is_some()).then(|| r.hk_next.map_or(now, Instant::millis)),
            ];
            for d in times.into_iter().flatten().map(wait) {
                best = Some(best.map_or(d, |b| b.min(d)));
            }
        }
        best.map(|d| now.wrapping_add(d))
    }

    /// How many more telecommands robot `board`'s queue can take now (`None`: not served).
    /// The space data link's FARM-1 takes an AD frame only when its packets fit
    /// ([`crate::node::server::frames`]).
    pub fn queue_room(&self, board: BoardNumber) -> Option<usize> {
        self.robots
            .iter()
            .find(|r| r.board == board)
            // A queue holds at most Q.
            .map(|r| Q.saturating_sub(r.queue.len()))
    }

    /// A telecommand packet from the ground: checked (CCSDS and PUS headers, CRC, one of the
    /// served robots' APIDs; a packet that fails is refused whole, as its request ID cannot be
    /// trusted, and the caller counts it), then its request read and served as [`Gateway::tc`].
    pub fn tc_packet(&mut self, bytes: &[u8]) -> Result<Out<M>, PacketError> {
        let apids: Vec<u16, R> = self.robots.iter().map(|r| robot_apid(r.board)).collect();
        let p = TcRepr::parse(bytes, &apids)?;
        let h = p.header;
        Ok(self.tc(&Tc {
            request: RequestId {
                apid: p.apid.get(),
                seq_count: p.seq_count.get(),
            },
            source_id: h.source_id,
            ack: h.ack.bits(),
            request_of: Request::parse(h.service, h.subservice, p.app_data),
        }))
    }

    /// Writes a report as a PUS-C telemetry packet stamped `now` (ms since the gateway's
    /// power-on: spec/decisions.toml, `ccsds-time`), numbering it in its APID's sequence and
    /// its message type's counter; returns its length.
    pub fn encode(&mut self, tm: &TmOut, now: u32, out: &mut [u8]) -> Result<usize, EmitError> {
        let r = robot_of_apid(tm.apid).and_then(|b| self.robots.iter_mut().find(|r| r.board == b));
        let (seq, counter) = match r {
            Some(r) => {
                let seq = r.tm_seq;
                let c = r.counters.get_mut(tm.type_index());
                let counter = c.as_deref().copied().unwrap_or(0);
                if let Some(c) = c {
                    *c = c.wrapping_add(1);
                }
                r.tm_seq = seq.wrapping_next();
                (seq, counter)
            }
            None => (SeqCount::default(), 0),
        };
        TmRepr {
            apid: Apid::new(tm.apid).unwrap_or_default(),
            seq_count: seq,
            header: TmSecondaryHeader {
                time_ref_status: Default::default(),
                service: tm.service,
                subservice: tm.subservice,
                counter,
                destination_id: tm.destination,
                time: Cuc::from_instant(Instant::from_millis(now)),
            },
            source_data: &tm.data,
        }
        .emit(out)
    }

    /// A telecommand from the ground.
    pub fn tc(&mut self, tc: &Tc) -> Out<M> {
        let mut out = Out::default();
        let robot = robot_of_apid(tc.request.apid)
            .and_then(|b| self.robots.iter_mut().find(|r| r.board == b));
        // The CCSDS layer admits only the APIDs of robots served; nothing to answer otherwise.
        if let Some(r) = robot
            && let Some(request) = r.admit(tc, &mut out)
        {
            r.run(tc, request, &mut out);
        }
        out
    }

    /// Time passes: resends and their timeouts, polls, housekeeping reports; the legacy
    /// commands due now, at most one per robot (the server board visits them in turn,
    /// Figure 4).
    pub fn tick(&mut self, now: u32) -> Out<M> {
        let mut out = Out::default();
        let cfg = self.cfg;
        for r in self.robots.iter_mut() {
            if r.uplink.is_idle() {
                r.submit_next(now, &cfg);
            }
            let t = r.uplink.tick(now);
            if let Some(d) = t.done {
                r.finished(&mut out, d);
            }
            if let Some(send) = t.send
                && out.to_robots.push((r.board, send)).is_err()
            {
                out.overflow = out.overflow.saturating_add(1);
            }
            r.housekeeping(now, &mut out);
        }
        out
    }

    /// A heartbeat from board A of `hb.board`.
    pub fn heartbeat(&mut self, now: u32, hb: &HeartbeatRepr) -> Out<M> {
        let mut out = Out::default();
        let Some(r) = self.robots.iter_mut().find(|r| r.board == hb.board) else {
            return out;
        };
        let t = r.uplink.heartbeat(now, hb);
        if let Some(prev) = r.last {
            let apid = robot_apid(r.board);
            for e in event::between(&prev, hb, r.stopped) {
                out.push(TmOut::new(apid, 5, e.severity(), 0, &e.to_bytes()));
            }
            r.progress(&mut out, &prev, hb);
        }
        r.stopped = false;
        r.last = Some(*hb);
        if let Some(d) = t.done {
            r.finished(&mut out, d);
        }
        out
    }
}
