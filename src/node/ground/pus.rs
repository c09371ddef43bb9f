//! The ground's telecommand link over PUS: the plan runner's commands as PUS-C telecommands
//! to the server board acting as gateway ([`gateway`](crate::node::server::gateway)), and its telemetry read back
//! into what the runner waits for — the start of each command, the completion of each
//! motion, the robot's status. The PUS counterpart of the legacy [`Uplink`](crate::node::exactly_once::uplink::Uplink);
//! [`super::plan_runner::PlanRunner`] drives either ([`super::plan_runner::Link`]).
//!
//! Each command becomes a TC(8,1) function (TC(17,1) are-you-alive for a heartbeat request)
//! on the robot's APID ([`crate::pus::robot_apid`]), numbered in the APID's sequence count,
//! with this ground's source ID and every acknowledgement flag. A command is *started* when
//! its TM(1,3) arrives (TM(1,4) with a refusal code: refused; with `UNACKNOWLEDGED`: board A
//! never answered the gateway), and a motion *completes* with its TM(1,7) (TM(1,8): a fault,
//! or the robot left the mode, cut it short).
//!
//! Resends: the gateway resends to board A by itself; the link resends a telecommand (same
//! key, same bytes) only when a transmission got no report at all within
//! [`Config::timeout_ms`] (UDP can lose it or its answer), and, once the gateway accepted it,
//! asks again every [`Config::query_ms`] for a start or completion report it may have lost.
//! The gateway answers a copy with its latest report and never runs it twice
//! (spec/decisions.toml, `pus-gateway`). After [`Config::max_attempts`] unanswered
//! transmissions in a row the command is given up as unacknowledged.
//!
//! ```
//! use mmic::command::Command;
//! use mmic::node::exactly_once::uplink::Outcome;
//! use mmic::node::ground::plan_runner::Link;
//! use mmic::node::ground::pus::{Config, TcLink};
//! use mmic::pus::verification::{Report, Stage};
//! use mmic::units::BoardNumber;
//!
//! let mut link = TcLink::new(Config::default(), BoardNumber::ONE);
//! let seq = link.submit(Command::Stop).unwrap();
//! let tc = link.tick(0).send.unwrap();
//! assert_eq!((tc.request.apid, tc.request.seq_count, tc.command), (0x101, seq, Command::Stop));
//! let mut bytes = [0u8; mmic::node::ground::pus::MAX_TC_LEN];
//! let n = tc.emit(&mut bytes).unwrap();
//! assert_eq!(mmic::pus::read_tc(&bytes[..n], &[0x101]).unwrap().0.header.service, 8);
//! let start = Report { stage: Stage::Start, request: tc.request, failure: None };
//! let r = link.report(&start);
//! assert_eq!(r.done.map(|d| d.outcome), Some(Outcome::Accepted));
//! assert!(link.is_idle());
//! ```
// req: D:pus-ground-resend

use super::link::{Link, LinkTick, MotionEnd};

mod pending;
mod tc_out;

use crate::ccsds::primary::SeqCount;
use crate::ccsds::tc::TC_MIN_LEN;
use crate::command::Command;
use crate::faults::Faults;
use crate::link::fop::FopConfig;
use crate::link::low;
use crate::mode::Mode;
use crate::node::exactly_once::uplink::{Done, Efficiency, Outcome};
use crate::pus::function;
use crate::pus::housekeeping;
use crate::pus::request::{ST_EVENT, ST_HOUSEKEEPING, ST_VERIFICATION};
use crate::pus::robot_apid;
use crate::pus::verification::{
    Failure, Report, RequestId, Stage, ABANDONED, RESTARTED, UNACKNOWLEDGED,
};
use crate::refusal::Refusal;
use crate::units::{BoardNumber, Instant};
use crate::wire::heartbeat::HeartbeatRepr;
use pending::{Due, Pending};
pub use tc_out::{TcOut, TcOutError};

/// The longest telecommand the link sends, bytes: headers, the longest function, CRC.
pub const MAX_TC_LEN: usize = TC_MIN_LEN + function::MAX_LEN;

/// Timing and identity.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Config {
    /// The source ID in every telecommand's secondary header (the key is source ID and
    /// sequence count).
    pub source_id: u16,
    /// A transmission with no report within this is unanswered, and the telecommand is sent
    /// again, ms. Above the gateway's longest visit of board A (it reads no telecommand while
    /// it waits for a heartbeat).
    pub timeout_ms: u32,
    /// Once accepted, the telecommand is sent again (a query: the gateway answers a copy with
    /// its latest report) when no start report, or for a motion no completion report, came
    /// within this, ms.
    pub query_ms: u32,
    /// Unanswered transmissions in a row before the command is given up (≥ 1).
    pub max_attempts: u8,
}

impl Default for Config {
    /// Source ID 1; a second to answer; ask again after five seconds; ten attempts.
    fn default() -> Config {
        Config {
            source_id: 1,
            timeout_ms: 1000,
            query_ms: 5000,
            max_attempts: 10,
        }
    }
}

impl Config {
    /// The same link with its telecommands carried in TC frames under COP-1 (`fop`): as many
    /// attempts as it takes for the ground to give a telecommand up no sooner than FOP-1
    /// gives its frame up (`tx_limit` transmissions, `t1_ms` apart), and never fewer than
    /// before. A frame FARM-1 did not take holds every later one back, so the link's resends
    /// cannot get past the gap: only FOP-1's retransmissions can (spec/decisions.toml,
    /// `pus-ground-under-cop1`). The timeout stays, so a lost report is asked for as soon.
    ///
    /// ```
    /// use mmic::link::fop::FopConfig;
    /// use mmic::node::ground::pus::Config;
    ///
    /// let c = Config::default().under_cop1(&FopConfig::MISSION);
    /// assert_eq!((c.timeout_ms, c.max_attempts), (1000, 30)); // 10 × 3 s
    /// ```
    pub fn under_cop1(self, fop: &FopConfig) -> Config {
        // Two 32-bit values at most: their product fits a u64 (no saturation).
        let horizon = u64::from(fop.tx_limit).saturating_mul(u64::from(fop.t1_ms));
        let needed = horizon.div_ceil(u64::from(self.timeout_ms.max(1)));
        let max_attempts = u8::try_from(needed)
            .unwrap_or(u8::MAX)
            .max(self.max_attempts);
        Config {
            max_attempts,
            ..self
        }
    }
}

/// What a report told the link.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Default)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Heard {
    /// A transmission was answered (Figure 11's attempt).
    pub attempt: Option<bool>,
    /// A command started, was refused, or went unacknowledged.
    pub done: Option<Done>,
    /// A started motion ended: its sequence count and how.
    pub ended: Option<(u16, MotionEnd)>,
    /// The gateway refused a telecommand at acceptance, or failed its start with a code that
    /// is no refusal of board A's: its sequence count and the failure notice.
    pub rejected: Option<(u16, Failure)>,
    /// A housekeeping report: the robot's status now.
    pub status: Option<HeartbeatRepr>,
}

/// One robot's telecommand link at the ground.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct TcLink {
    cfg: Config,
    apid: u16,
    next: SeqCount,
    /// The command submitted last, until its start report.
    current: Option<Pending>,
    /// A started motion, until its completion report.
    running: Option<Pending>,
    efficiency: Efficiency,
    /// The latest housekeeping report.
    status: Option<HeartbeatRepr>,
    /// The mode last reported (housekeeping or event).
    mode: Option<Mode>,
}

impl TcLink {
    /// For robot `board` (its APID), numbering from sequence count 0.
    pub fn new(cfg: Config, board: BoardNumber) -> TcLink {
        TcLink {
            cfg,
            apid: robot_apid(board),
            next: SeqCount::default(),
            current: None,
            running: None,
            efficiency: Efficiency::default(),
            status: None,
            mode: None,
        }
    }

    /// For robot `board`, numbering from sequence count `next` (its low 14 bits): a restarted ground's link,
    /// from the count it kept ([`TcLink::next_count`]; decision `restart-ground`). A ground
    /// that numbered from 0 again would have its new telecommands answered as copies of old
    /// ones by a gateway that kept a newer key.
    pub fn starting_at(cfg: Config, board: BoardNumber, next: u16) -> TcLink {
        TcLink {
            next: SeqCount::masked(next),
            ..TcLink::new(cfg, board)
        }
    }

    /// The sequence count the next submitted command gets.
    pub const fn next_count(&self) -> u16 {
        self.next.get()
    }

    /// This link after its ground restarted, keeping only the sequence count (decision
    /// `restart-ground`): nothing outstanding or followed, no status, nothing measured.
    pub fn restarted(&self) -> TcLink {
        TcLink {
            cfg: self.cfg,
            apid: self.apid,
            next: self.next,
            ..TcLink::new(self.cfg, BoardNumber::ONE)
        }
    }

    /// The APID of its telecommands.
    pub const fn apid(&self) -> u16 {
        self.apid
    }

    /// The transmissions answered over the last 100 (Figure 11).
    pub const fn efficiency(&self) -> Efficiency {
        self.efficiency
    }

    /// The sequence count of the command awaiting its start report, if any.
    pub fn outstanding(&self) -> Option<u16> {
        self.current.map(|p| p.tc.request.seq_count)
    }

    /// The robot's status as last reported: the latest housekeeping report, with the mode
    /// of any mode-change or fault event since.
    pub fn status(&self) -> Option<HeartbeatRepr> {
        self.status.map(|s| HeartbeatRepr {
            mode: self.mode.unwrap_or(s.mode),
            ..s
        })
    }

    /// A telemetry packet's service, subservice and source data (its CCSDS headers checked by
    /// the caller): ST\[1\] reports ([`TcLink::report`]), ST\[3\] housekeeping (the status),
    /// ST\[5\] events (the mode they name); anything else, or source data that does not read,
    /// tells nothing.
    pub fn telemetry(&mut self, service: u8, subservice: u8, data: &[u8]) -> Heard {
        match service {
            ST_VERIFICATION => match Report::parse(subservice, data) {
                Ok(r) => self.report(&r),
                Err(_) => Heard::default(),
            },
            ST_HOUSEKEEPING if subservice == 25 => match housekeeping::parse(data) {
                Ok(hb) => {
                    self.status = Some(hb);
                    self.mode = Some(hb.mode);
                    Heard {
                        status: Some(hb),
                        ..Heard::default()
                    }
                }
                Err(_) => Heard::default(),
            },
            ST_EVENT => {
                // Mode changes (ID 1: from, to) and faults (ID 0x01xx: the mode after it);
                // spec/ccsds/services.toml.
                let mode = match data {
                    [0x00, 0x01, _, to, _, _] => Mode::from_wire(*to),
                    [0x01, _, m, _, _, _] => Mode::from_wire(*m),
                    _ => None,
                };
                self.mode = mode.or(self.mode);
                Heard::default()
            }
            _ => Heard::default(),
        }
    }

    /// How a motion ended, from its completion report.
    fn motion_end(&self, failure: Option<Failure>) -> MotionEnd {
        let Some(f) = failure else {
            return MotionEnd::Completed;
        };
        let known = self.status();
        let mode = self.mode.unwrap_or(Mode::Operational);
        let faults = known.map_or(Faults::EMPTY, |s| s.faults);
        match f.code {
            c if (0x0100..0x0100 + 16).contains(&c) => MotionEnd::Interrupted {
                mode,
                faults: Faults::from_wire([low::u8_of_u32(f.data), low::u8_of_u32(f.data >> 8)])
                    .unwrap_or(faults),
            },
            ABANDONED => MotionEnd::Interrupted {
                mode: Mode::from_wire(low::u8_of_u32(f.data)).unwrap_or(mode),
                faults,
            },
            _ => MotionEnd::Unacknowledged,
        }
    }

    /// An ST\[1\] report.
    pub fn report(&mut self, r: &Report) -> Heard {
        let mut heard = Heard::default();
        if r.request.apid != self.apid {
            return heard;
        }
        let seq = r.request.seq_count;
        if let Some(mut p) = self.current.filter(|p| p.tc.request.seq_count == seq) {
            heard.attempt = p.answered();
            self.current = None;
            match (r.stage, r.failure) {
                (Stage::Acceptance, None) => {
                    p.accepted = true;
                    self.current = Some(p);
                }
                (Stage::Acceptance, Some(f)) => heard.rejected = Some((seq, f)),
                (Stage::Start, None) => {
                    heard.done = Some(p.done(Outcome::Accepted));
                    if p.tc.command.kind().moves() {
                        // Its completion is asked for from the next tick on.
                        self.running = Some(Pending { sent: None, ..p });
                    }
                }
                (Stage::Start, Some(f)) => {
                    let refusal = u8::try_from(f.code).ok().and_then(Refusal::from_wire);
                    match (f.code, refusal) {
                        (_, Some(r)) => heard.done = Some(p.done(Outcome::Refused(r))),
                        // Board A never answered, or the gateway restarted after taking it
                        // (it ran at most once): either way the outcome is not known.
                        (UNACKNOWLEDGED | RESTARTED, _) => {
                            heard.done = Some(p.done(Outcome::Unacknowledged))
                        }
                        _ => heard.rejected = Some((seq, f)),
                    }
                }
                (Stage::Completion, failure) => {
                    // Its start report was lost: started, and ended already.
                    heard.done = Some(p.done(Outcome::Accepted));
                    if p.tc.command.kind().moves() {
                        heard.ended = Some((seq, self.motion_end(failure)));
                    }
                }
            }
        } else if let Some(mut p) = self.running.filter(|p| p.tc.request.seq_count == seq) {
            heard.attempt = p.answered();
            self.running = Some(p);
            let restarted =
                r.stage == Stage::Start && r.failure.is_some_and(|f| f.code == RESTARTED);
            if r.stage == Stage::Completion || restarted {
                // A motion whose gateway restarted under it is not followed any more: its
                // end is not known (the robot may have finished it or stopped).
                self.running = None;
                heard.ended = Some((seq, self.motion_end(r.failure)));
            }
        }
        if let Some(ok) = heard.attempt {
            self.efficiency.push(ok);
        }
        heard
    }
}

impl Link for TcLink {
    type Packet = TcOut;
    const POLLS: bool = false;

    fn is_idle(&self) -> bool {
        self.current.is_none()
    }

    /// Numbers `command` with the next sequence count; none while another awaits its start.
    fn submit(&mut self, command: Command) -> Option<u16> {
        if self.current.is_some() {
            return None;
        }
        let seq = self.next;
        self.next = seq.wrapping_next();
        self.current = Some(Pending::new(TcOut {
            request: RequestId {
                apid: self.apid,
                seq_count: seq.get(),
            },
            source_id: self.cfg.source_id,
            command,
        }));
        Some(seq.get())
    }

    /// The transmission due now, if any (the submitted command first, then a query for a
    /// running motion's completion); a failed attempt; a command given up.
    fn tick(&mut self, now: u32) -> LinkTick<TcOut> {
        let t = Instant::from_millis(now);
        let mut out = LinkTick::default();
        let cfg = self.cfg;
        if let Some(mut p) = self.current.take() {
            let limit = if p.accepted {
                cfg.query_ms
            } else {
                cfg.timeout_ms
            };
            match p.due(t, limit, cfg.max_attempts) {
                Due::Wait => self.current = Some(p),
                Due::Send { failed } => {
                    out.attempt = failed.then_some(false);
                    out.send = Some(p.transmit(t));
                    self.current = Some(p);
                }
                Due::GiveUp => {
                    out.attempt = Some(false);
                    out.done = Some(p.done(Outcome::Unacknowledged));
                }
            }
        }
        if out.send.is_none()
            && out.done.is_none()
            && let Some(mut p) = self.running.take()
        {
            match p.sent {
                // The query timer starts now.
                None => {
                    p.sent = Some(t);
                    p.open = false;
                    self.running = Some(p);
                }
                Some(_) => match p.due(t, cfg.query_ms, cfg.max_attempts) {
                    Due::Wait => self.running = Some(p),
                    Due::Send { failed } => {
                        out.attempt = failed.then_some(false);
                        out.send = Some(p.transmit(t));
                        self.running = Some(p);
                    }
                    Due::GiveUp => {
                        out.attempt = Some(false);
                        out.ended = Some((p.tc.request.seq_count, MotionEnd::Unacknowledged));
                    }
                },
            }
        }
        if let Some(ok) = out.attempt {
            self.efficiency.push(ok);
        }
        out
    }
}
