//! The server board's end of the space data link: the PUS [`Gateway`] behind TC transfer
//! frames under COP-1 and fixed-length TM transfer frames, one spacecraft per robot
//! (`spec/ccsds/link.toml`; spec/decisions.toml `link-spacecraft-id`).
//!
//! A TC frame is checked ([`TcFrame::new_checked`], the robot's spacecraft ID from the frame's
//! header); FARM-1 decides (the robot's telecommand queue is its buffer: an AD frame whose
//! packets the queue cannot take now is refused with Wait, and the queue's draining is the
//! buffer release); the packets of an accepted frame go to the gateway as
//! [`Gateway::tc_packet`] takes them, each required to carry the frame's robot's APID. Every
//! report the gateway makes is written as a PUS packet into that robot's [`TmFramer`], and
//! [`FrameGateway::frame`] hands out the TM frames due, each with the robot's CLCW. The
//! PUS layer's exactly-once (request keys) stays underneath: COP-1 makes the frames arrive
//! once and in order, the key log still refuses a telecommand the ground sends again in a new
//! frame.
//!
//! ```
//! use mmic::link::tc_frame::{self, SpacecraftId, TcContent, TcFrameRepr, Vcid, MapId};
//! use mmic::link::tm_frame::{TmFrameParams, TmFrameRepr, TM_FRAME_LEN};
//! use mmic::link::clcw::Clcw;
//! use mmic::node::server::frames::{FrameGateway, FrameConfig};
//! use mmic::units::BoardNumber;
//!
//! let mut g: FrameGateway<1, 4, 8, 1024> = FrameGateway::new(FrameConfig::default());
//! g.add(BoardNumber::ONE);
//! // TC(17,1) are-you-alive to robot 1 (APID 0x101), in AD frame N(S) = 0.
//! # use mmic::ccsds::{primary::{Apid, SeqCount}, tc::TcRepr, tc_header::{AckFlags, TcSecondaryHeader}};
//! let mut ping = [0u8; 13];
//! TcRepr { apid: Apid::new(0x101).unwrap(), seq_count: SeqCount::new(0).unwrap(),
//!          header: TcSecondaryHeader { ack: AckFlags::ALL, service: 17, subservice: 1, source_id: 0 },
//!          app_data: &[] }.emit(&mut ping).unwrap();
//! let frame = TcFrameRepr {
//!     spacecraft_id: SpacecraftId::new(0x101).unwrap(),
//!     vcid: Vcid::new(0).unwrap(),
//!     seq: 0,
//!     content: TcContent::Ad { map_id: Some(MapId::new(0).unwrap()), data: &ping },
//! };
//! let mut buf = [0u8; 64];
//! let n = frame.emit(&mut buf).unwrap();
//! let verdict = g.tc_frame(0, &buf[..n]);
//! assert_eq!(verdict.accepted, 1);
//! // What a restart must resume from (FARM-1's V(R) = 1) is written durably by the shell
//! // first: until it confirms, no TM frame leaves.
//! let mut tm = [0u8; TM_FRAME_LEN];
//! assert!(g.frame(0, &mut tm).is_none());
//! for e in g.durable_due::<8>() {
//!     // ... the shell writes `e` to flash here ...
//!     assert!(g.durable_written(&e));
//! }
//! // The TM frame due now carries the acceptance report and the CLCW: V(R) = 1.
//! let (board, len) = g.frame(0, &mut tm).unwrap();
//! assert_eq!(board, BoardNumber::ONE);
//! let params = TmFrameParams::mission(0x101).unwrap();
//! let f = TmFrameRepr::parse(&tm[..len], &params).unwrap();
//! assert_eq!(Clcw::parse(&f.ocf.unwrap()).unwrap().report_value, 1);
//! ```

use super::gateway::{
    Config as GatewayConfig, Gateway, Kept, Out, TmOut, KEPT_SOURCES, MAX_TM_DATA,
};
use super::store::queue::QUEUE_SLOTS;
use super::store::{Entry, Progress};
use crate::ccsds::primary::PrimaryHeader;
use crate::ccsds::tm::TM_MIN_LEN;
use crate::link::clcw::ClcwVcid;
use crate::link::farm::{Farm, FarmState, FarmWindow, Verdict};
use crate::link::sdls::{self, frames as secured, SaTable, SdlsRefusal};
use crate::link::tc_frame::Packets;
use crate::link::tc_frame::{self, SpacecraftId, TcFrame, TcFrameError, TcPrimaryHeader};
use crate::link::tm_frame::{TmFrameParams, TM_FRAME_LEN};
use crate::link::tm_framer::{TmFramer, IDLE_PERIOD_MS};
use crate::link::FrameKind;
use crate::pus::robot_apid;
use crate::units::BoardNumber;
use crate::wire::command::CommandRepr;
use crate::wire::heartbeat::HeartbeatRepr;
use heapless::Vec;

mod durable;
mod secure;
pub use durable::DUE_PER_ROBOT;

/// The largest telemetry packet the gateway writes.
const MAX_TM_LEN: usize = TM_MIN_LEN + MAX_TM_DATA;

/// Packets in one TC frame at most: a 256-octet frame of 13-octet telecommands (the shortest
/// PUS TC) holds 19.
pub const MAX_PACKETS_PER_FRAME: usize = 19;

/// The link's timing and FARM-1's window (`spec/ccsds/link.toml`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub struct FrameConfig {
    /// The gateway behind the link.
    pub gateway: GatewayConfig,
    /// FARM-1's sliding window.
    pub farm_window: FarmWindow,
    /// A TM frame goes out at least this often, idle or not (the CLCW), ms.
    pub idle_period_ms: u32,
    /// A report waits at most this long for others to share its frame, ms; a frame also goes
    /// at once when the CLCW changed (the ground's FOP-1 learns of accepted frames only
    /// through it).
    pub gather_ms: u32,
}

impl Default for FrameConfig {
    /// The gateway's defaults; W = 20, a frame at least every 500 ms, reports gathered for 20 ms.
    fn default() -> FrameConfig {
        FrameConfig {
            gateway: GatewayConfig::default(),
            farm_window: FarmWindow::MISSION,
            idle_period_ms: IDLE_PERIOD_MS,
            gather_ms: GATHER_MS,
        }
    }
}

/// How long a report waits for others to share its TM frame, ms (`spec/ccsds/link.toml`).
pub const GATHER_MS: u32 = 20;

/// SDLS refusals are reported in ST\[5\] at most once per reason per robot in this period,
/// ms (`spec/ccsds/sdls.toml`): each report counts the frames refused since the last one, so
/// none goes unreported, and a flood of bad frames makes at most seven reports a second.
pub const SECURITY_EVENT_PERIOD_MS: u32 = 1000;

/// One reason's refusals waiting to be reported.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Default)]
struct Alarm {
    /// Frames refused since the last report.
    pending: u16,
    /// The last one's SPI.
    spi: u16,
    /// When the last report went.
    last: Option<u32>,
}

impl Alarm {
    /// Whether a report waits and may go at `now`.
    fn ready(&self, now: u32) -> bool {
        self.pending > 0
            && self
                .last
                .is_none_or(|t| now.wrapping_sub(t) >= SECURITY_EVENT_PERIOD_MS)
    }

    /// How long from `now` until the waiting report may go, if one waits.
    fn wait(&self, now: u32) -> Option<u32> {
        (self.pending > 0).then(|| {
            self.last.map_or(0, |t| {
                SECURITY_EVENT_PERIOD_MS.saturating_sub(now.wrapping_sub(t))
            })
        })
    }
}

/// What the link did, per robot. Each counter wraps at `u32::MAX`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Default)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub struct LinkCounters {
    /// TC frames that passed the frame checks.
    pub tc_frames: u32,
    /// Of those, refused by FARM-1 (any discard reason: FARM-1's own counters say which).
    pub tc_discarded: u32,
    /// Packets of accepted frames handed to the gateway.
    pub tc_packets: u32,
    /// Packets of accepted frames the gateway refused (PUS checks), or carrying another
    /// robot's APID.
    pub tc_packets_refused: u32,
    /// TM frames sent.
    pub tm_frames: u32,
    /// Reports the framer could not take (it was full): lost, and counted here.
    pub tm_overflow: u32,
    /// TM frames SDLS could not protect (none expected: a frame waits until its association's
    /// counter is reserved).
    pub tm_unprotected: u32,
    /// BC frames refused because they came from elsewhere than the ground's address.
    pub bc_origin: u32,
}

/// Why a TC frame went no further than the link.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, thiserror::Error)]
pub enum FrameRefusal {
    /// A frame check ([`TcFrameError`]).
    #[error(transparent)]
    Frame(#[from] TcFrameError),
    /// SDLS ([`SdlsRefusal`]): nothing of the frame reached FARM-1.
    #[error(transparent)]
    Security(#[from] SdlsRefusal),
    /// A BC frame not from the ground's address ([`Origin`]): FARM-1 never saw it.
    #[error("a BC frame from elsewhere than the ground's address: not obeyed")]
    Origin,
}

impl FrameRefusal {
    /// The check's name ([`TcFrameError::NAMES`], [`SdlsRefusal::NAMES`], or `bc-origin`).
    pub const fn name(&self) -> &'static str {
        match self {
            FrameRefusal::Frame(e) => e.name(),
            FrameRefusal::Security(e) => e.name(),
            FrameRefusal::Origin => "bc-origin",
        }
    }

    /// `frame`, `sdls` or `cop`.
    pub const fn layer(&self) -> &'static str {
        match self {
            FrameRefusal::Frame(_) => "frame",
            FrameRefusal::Security(_) => "sdls",
            FrameRefusal::Origin => "cop",
        }
    }
}

/// What the shell kept in durable storage, per robot ([`super::store`]): where the TC
/// window's floor and the TM counter's reservation stood (`None`: a new association), and
/// where FARM-1 and the TC window stood after the last accepted frame.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Default)]
pub struct Stored {
    /// The TC floor.
    pub tc: Option<u128>,
    /// The TM reservation.
    pub tm: Option<u128>,
    /// FARM-1's V(R) and the last TC IV accepted (`None`: FARM-1 starts at V(R) = 0).
    pub progress: Option<Progress>,
}

/// Where a TC frame came from, as the shell's transport tells it: FARM-1 obeys a BC frame
/// (Unlock, Set V(R), which go in clear) only from the ground's configured address (decision
/// `sdls-bc-origin`); data frames are judged by SDLS wherever they come from.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Origin {
    /// The configured ground address.
    Ground,
    /// Anywhere else.
    Elsewhere,
}

/// Why [`FrameGateway::secure`] could not secure a robot's link: the shell must not run it
/// in clear instead.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, thiserror::Error)]
pub enum SecureError {
    /// The robot is not served ([`FrameGateway::add`] first).
    #[error("robot {board} is not served: add it before securing its link")]
    NotServed {
        /// The robot.
        board: u8,
    },
    /// The TM frame has no room for the security header and MAC.
    #[error("robot {board}'s TM frames have no room for SDLS's header and MAC")]
    Layout {
        /// The robot.
        board: u8,
    },
}

/// What became of one TC frame.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub struct FrameIn {
    /// The robot the frame was for, when it is one of ours.
    pub robot: Option<BoardNumber>,
    /// The check that refused it (the frame's or SDLS's), or FARM-1's verdict.
    pub verdict: Result<Verdict, FrameRefusal>,
    /// Packets handed to the gateway.
    pub accepted: u8,
    /// Packets refused at the PUS layer (or for another robot's APID).
    pub refused: u8,
}

/// One robot's end of the link.
#[derive(Debug, Clone)]
struct RobotLink<const N: usize> {
    board: BoardNumber,
    farm: Farm,
    framer: TmFramer<N>,
    /// When the oldest report still waiting in the framer was written.
    oldest: Option<u32>,
    /// The CLCW of the last frame sent.
    clcw_sent: Option<[u8; 4]>,
    counters: LinkCounters,
    /// SDLS, when the robot's link is secured: its TC (receiving) and TM (sending)
    /// associations.
    sdls: Option<SaTable<2>>,
    /// SDLS refusals waiting for their ST\[5\] report, by reason.
    alarms: [Alarm; SdlsRefusal::NAMES.len()],
    /// Where FARM-1 and the TC window stand now, and what the shell last confirmed durable
    /// (no TM frame and no visit leaves while they differ: `durable`).
    progress: Progress,
    progress_kept: Progress,
    /// The kept-key entries the shell last confirmed, by slot.
    kept_written: [Option<Entry>; KEPT_SOURCES],
    /// The gateway's queue in the store's ring (write-ahead): which telecommand each slot
    /// holds, the next slot a new one takes, and what the shell last confirmed per slot.
    ring: [Option<(u16, u16)>; QUEUE_SLOTS],
    ring_next: u8,
    ring_written: [Option<Entry>; QUEUE_SLOTS],
}

impl<const N: usize> RobotLink<N> {
    /// A checked TC frame from `origin` before FARM-1: a BC frame only from the ground's
    /// address; a data frame through SDLS when the link is secured (its plaintext into `plain`,
    /// its range and IV returned), a refusal counted (and waiting for its ST\[5\] report).
    fn unwrap_tc(
        &mut self,
        frame: &TcFrame<&[u8]>,
        origin: Origin,
        plain: &mut [u8; tc_frame::MAX_FRAME_LEN],
    ) -> Result<(Option<core::ops::Range<usize>>, Option<u128>), FrameRefusal> {
        let bc = frame.kind() == FrameKind::Bc;
        if bc && origin != Origin::Ground {
            self.counters.bc_origin = self.counters.bc_origin.wrapping_add(1);
            return Err(FrameRefusal::Origin);
        }
        let Some(table) = self.sdls.as_mut().filter(|_| !bc) else {
            return Ok((None, None));
        };
        match secured::verify_tc(table, frame, plain) {
            Ok((v, range)) => Ok((Some(range), Some(v.iv.get()))),
            Err(e) => {
                if let Some(a) = self.alarms.get_mut(e.position()) {
                    a.pending = a.pending.saturating_add(1);
                    a.spi = frame
                        .as_bytes()
                        .get(6..8)
                        .map_or(0, |b| u16::from_be_bytes([b[0], b[1]]));
                }
                Err(e.into())
            }
        }
    }

    fn clcw(&self) -> [u8; 4] {
        self.farm
            .clcw(
                ClcwVcid::new(tc_frame::MISSION_VCID).unwrap_or(ClcwVcid::ZERO),
                false,
                false,
            )
            .emit()
    }

    /// Whether a frame should go now: the framer's own rule (a full data field, the idle
    /// period), a report that waited `gather_ms`, or a CLCW the ground has not seen.
    fn due(&self, now: u32, gather_ms: u32) -> bool {
        self.framer.frame_due(now)
            || self
                .oldest
                .is_some_and(|t| now.wrapping_sub(t) >= gather_ms)
            || self.clcw_sent != Some(self.clcw())
    }
}

/// The PUS gateway for up to `R` robots (`Q` waiting telecommands and `K` remembered keys
/// each) behind the space data link, with `N` octets of TM packets waiting per robot.
#[derive(Debug, Clone)]
pub struct FrameGateway<const R: usize, const Q: usize, const K: usize, const N: usize> {
    cfg: FrameConfig,
    gateway: Gateway<R, Q, K>,
    links: Vec<RobotLink<N>, R>,
    /// TC frames refused by a frame check before any robot could be told (no robot of ours,
    /// or a corrupted frame), by check in the order of [`TcFrameError::NAMES`].
    refused: [u32; TcFrameError::NAMES.len()],
}

impl<const R: usize, const Q: usize, const K: usize, const N: usize> FrameGateway<R, Q, K, N> {
    /// No robots yet.
    pub fn new(cfg: FrameConfig) -> Self {
        FrameGateway {
            cfg,
            gateway: Gateway::new(cfg.gateway),
            links: Vec::new(),
            refused: [0; TcFrameError::NAMES.len()],
        }
    }

    /// Serves robot `board` (its spacecraft ID `0x100 + n`); false when all `R` places are
    /// taken or it is served already.
    pub fn add(&mut self, board: BoardNumber) -> bool {
        self.add_link(board, None)
    }

    /// Serves robot `board` after the server board restarted, with what its gateway kept
    /// ([`Gateway::add_restarted`]): a telecommand it may have taken before is answered, never
    /// run twice. Then [`FrameGateway::secure`] with the stored SDLS counters and progress (or,
    /// without SDLS, [`FrameGateway::resume`]): FARM-1 resumes at the V(R) it had, so the
    /// ground's FOP-1 finds the N(R) it expects and retransmits what is unconfirmed.
    pub fn add_restarted(&mut self, board: BoardNumber, kept: Kept) -> bool {
        self.add_link(board, Some(kept))
    }

    /// What to keep of robot `board`'s gateway across a restart ([`Gateway::kept`]).
    pub fn kept(&self, board: BoardNumber) -> Option<Kept> {
        self.gateway.kept(board)
    }

    fn add_link(&mut self, board: BoardNumber, kept: Option<Kept>) -> bool {
        let restarted = kept.is_some();
        let added = self.push_link(board, kept);
        if added && restarted {
            self.kept_restored(board);
        }
        added
    }

    fn push_link(&mut self, board: BoardNumber, kept: Option<Kept>) -> bool {
        let scid = SpacecraftId::of_board(board).get();
        let Some(params) = TmFrameParams::mission(scid) else {
            return false;
        };
        let added = match kept {
            Some(k) => self.gateway.add_restarted(board, k),
            None => self.gateway.add(board),
        };
        if !added {
            return false;
        }
        // Every shell of the frame gateway keeps the queue (`durable_due`).
        self.gateway.write_ahead(board, true);
        self.links
            .push(RobotLink {
                board,
                farm: Farm::new(self.cfg.farm_window),
                framer: TmFramer::new(params, self.cfg.idle_period_ms),
                oldest: None,
                clcw_sent: None,
                counters: LinkCounters::default(),
                sdls: None,
                alarms: [Alarm::default(); SdlsRefusal::NAMES.len()],
                progress: Progress::default(),
                progress_kept: Progress::default(),
                kept_written: [None; KEPT_SOURCES],
                ring: [None; QUEUE_SLOTS],
                ring_next: 0,
                ring_written: [None; QUEUE_SLOTS],
            })
            .is_ok()
    }

    /// The gateway behind the link.
    pub const fn gateway(&self) -> &Gateway<R, Q, K> {
        &self.gateway
    }

    /// FARM-1 of robot `board`.
    pub fn farm(&self, board: BoardNumber) -> Option<&Farm> {
        self.links
            .iter()
            .find(|l| l.board == board)
            .map(|l| &l.farm)
    }

    /// The link counters of robot `board`.
    pub fn counters(&self, board: BoardNumber) -> Option<&LinkCounters> {
        self.links
            .iter()
            .find(|l| l.board == board)
            .map(|l| &l.counters)
    }

    /// TC frames refused before reaching a robot's FARM-1, by check
    /// ([`TcFrameError::NAMES`] order).
    pub const fn refused(&self) -> &[u32; TcFrameError::NAMES.len()] {
        &self.refused
    }

    /// A TC frame from the ground's address, at `now` ([`FrameGateway::tc_frame_from`]).
    pub fn tc_frame(&mut self, now: u32, bytes: &[u8]) -> FrameIn {
        self.tc_frame_from(now, bytes, Origin::Ground)
    }

    /// A TC frame from `origin`, at `now`.
    pub fn tc_frame_from(&mut self, now: u32, bytes: &[u8], origin: Origin) -> FrameIn {
        // The robot by the header's spacecraft ID (before any check: it only picks the
        // configuration; the checks then say whether the frame is sound and whether it is
        // really for that robot).
        let scid = TcPrimaryHeader::read(bytes).map(|h| h.spacecraft_id);
        let at = self
            .links
            .iter()
            .position(|l| Some(SpacecraftId::of_board(l.board).get()) == scid)
            .unwrap_or(0);
        let board = self.links.get(at).map(|l| l.board);
        let config =
            tc_frame::mission(board.map_or(SpacecraftId::default(), SpacecraftId::of_board));
        let frame = match TcFrame::new_checked(bytes, &config) {
            Ok(f) => f,
            Err(e) => {
                if let Some(c) = self.refused.get_mut(e.position()) {
                    *c = c.wrapping_add(1);
                }
                return FrameIn {
                    robot: None,
                    verdict: Err(e.into()),
                    accepted: 0,
                    refused: 0,
                };
            }
        };
        let Some(board) = board else {
            // Unreachable: with no robot the spacecraft ID check refuses every frame.
            return FrameIn {
                robot: None,
                verdict: Ok(Verdict::Discard(crate::link::farm::DiscardReason::Invalid)),
                accepted: 0,
                refused: 0,
            };
        };
        let mut result = FrameIn {
            robot: Some(board),
            verdict: Ok(Verdict::Released),
            accepted: 0,
            refused: 0,
        };
        let Some(link) = self.links.get_mut(at) else {
            return result;
        };
        // SDLS before FARM-1 (355.0-B-2 §2.3.3): a data frame that does not verify changes
        // nothing but SDLS's counter of its reason; the packets come from the plaintext.
        let mut plain = [0u8; tc_frame::MAX_FRAME_LEN];
        let (data, iv) = match link.unwrap_tc(&frame, origin, &mut plain) {
            Ok((Some(range), iv)) => (plain.get(range).unwrap_or(&[]), iv),
            Ok((None, iv)) if frame.kind() == FrameKind::Bc => (&[][..], iv),
            Ok((None, iv)) => (frame.data(), iv),
            Err(e) => {
                result.verdict = Err(e);
                if let FrameRefusal::Security(_) = e {
                    self.security_reports(now);
                }
                return result;
            }
        };
        let packets = Packets::new(data).count();
        let room = self.gateway.queue_room(board).unwrap_or(0);
        link.counters.tc_frames = link.counters.tc_frames.wrapping_add(1);
        let verdict = link.farm.frame(
            frame.kind(),
            frame.seq(),
            frame.control_command(),
            room >= packets,
        );
        result.verdict = Ok(verdict);
        if let Verdict::Discard(_) = verdict {
            link.counters.tc_discarded = link.counters.tc_discarded.wrapping_add(1);
        }
        // What a restart must resume from: V(R) (a BC frame may have moved it) and the IV of
        // a frame SDLS verified (the window moved to it whatever FARM-1 did with the frame).
        link.progress.vr = link.farm.vr();
        if iv.is_some() {
            link.progress.tc_iv = iv;
        }
        if verdict != Verdict::Accept || frame.kind() == FrameKind::Bc {
            return result;
        }
        let apid = robot_apid(board);
        for packet in Packets::new(data) {
            let out = match packet {
                Ok(p) if PrimaryHeader::read(p).is_some_and(|h| h.apid == apid) => {
                    self.gateway.tc_packet(p).ok()
                }
                _ => None,
            };
            match out {
                Some(out) => {
                    result.accepted = result.accepted.saturating_add(1);
                    self.downlink(now, out);
                }
                None => result.refused = result.refused.saturating_add(1),
            }
        }
        if let Some(link) = self.links.get_mut(at) {
            link.counters.tc_packets = link
                .counters
                .tc_packets
                .wrapping_add(u32::from(result.accepted));
            link.counters.tc_packets_refused = link
                .counters
                .tc_packets_refused
                .wrapping_add(u32::from(result.refused));
        }
        self.sync_rings();
        result
    }

    /// Time passes: the gateway's resends, polls and housekeeping (their reports go into the
    /// TM framers); the legacy commands due now, at most one per robot. A robot whose queue
    /// has room again releases FARM-1's buffer.
    ///
    /// Nothing is done while the shell has not confirmed a durable entry that gates
    /// ([`FrameGateway::durable_due`]): a telecommand must not reach board A before what a
    /// restart needs to answer it again is kept.
    pub fn tick(&mut self, now: u32) -> Vec<(BoardNumber, CommandRepr), R> {
        if self.gated() {
            self.security_reports(now);
            return Vec::new();
        }
        let out = self.gateway.tick(now);
        self.sync_rings();
        let mut to_robots = Vec::new();
        for c in &out.to_robots {
            let _ = to_robots.push(*c);
        }
        self.downlink(now, out);
        self.release_buffers();
        self.security_reports(now);
        to_robots
    }

    /// A heartbeat from board A of `hb.board`; the reports go into the TM framer.
    pub fn heartbeat(&mut self, now: u32, hb: &HeartbeatRepr) {
        let out = self.gateway.heartbeat(now, hb);
        self.downlink(now, out);
        self.release_buffers();
    }

    /// The next TM frame due at `now` of any robot, written into `out` (at least
    /// [`TM_FRAME_LEN`] octets): the robot and the frame's length. Call until `None`.
    pub fn frame(&mut self, now: u32, out: &mut [u8]) -> Option<(BoardNumber, usize)> {
        let gather = self.cfg.gather_ms;
        let link = self.links.iter_mut().find(|l| {
            l.due(now, gather)
                // The CLCW would report a V(R) a restart could not resume from.
                && l.progress == l.progress_kept
                && l.sdls
                    .as_ref()
                    .is_none_or(|t| t.ready(sdls::mission::tm_spi(l.board)))
        })?;
        let clcw = link.clcw();
        let n = link.framer.next_frame(now, clcw, out).ok()?;
        if let Some(table) = link.sdls.as_mut() {
            let params = *link.framer.params();
            let spi = sdls::mission::tm_spi(link.board);
            // Unreachable (the association is ready, the layout the framer's): counted.
            if secured::protect_tm(table, spi, &params, out).is_err() {
                link.counters.tm_unprotected = link.counters.tm_unprotected.wrapping_add(1);
                return None;
            }
        }
        link.clcw_sent = Some(clcw);
        link.counters.tm_frames = link.counters.tm_frames.wrapping_add(1);
        link.oldest = (link.framer.waiting() > 0).then_some(now);
        Some((link.board, n))
    }

    /// The earliest time from `now` on when something is due: the gateway's next deadline, a
    /// TM frame (the idle period, a gathered report). `now` when something is due already.
    pub fn next_deadline(&self, now: u32) -> Option<u32> {
        let wait = |t: u32| {
            let d = t.wrapping_sub(now);
            if d > i32::MAX as u32 {
                0
            } else {
                d
            }
        };
        let mut best = self.gateway.next_deadline(now).map(wait);
        for l in &self.links {
            let d = if l.due(now, self.cfg.gather_ms) {
                0
            } else {
                let idle = self.cfg.idle_period_ms;
                let gathered = l.oldest.map(|t| wait(t.wrapping_add(self.cfg.gather_ms)));
                let idle_at = l
                    .framer
                    .last_frame_ms()
                    .map_or(0, |t| wait(t.wrapping_add(idle)));
                gathered.map_or(idle_at, |g| g.min(idle_at))
            };
            let alarm = l.alarms.iter().filter_map(|a| a.wait(now)).min();
            let d = alarm.map_or(d, |a| a.min(d));
            best = Some(best.map_or(d, |b| b.min(d)));
        }
        best.map(|d| now.wrapping_add(d))
    }

    /// Writes the reports of `out` into their robots' framers.
    fn downlink<const M: usize>(&mut self, now: u32, out: Out<M>) {
        for tm in &out.reports {
            self.report(now, tm);
        }
        if out.overflow > 0 {
            if let Some(l) = self.links.first_mut() {
                l.counters.tm_overflow =
                    l.counters.tm_overflow.wrapping_add(u32::from(out.overflow));
            }
        }
    }

    fn report(&mut self, now: u32, tm: &TmOut) {
        let mut buf = [0u8; MAX_TM_LEN];
        let Ok(n) = self.gateway.encode(tm, now, &mut buf) else {
            return;
        };
        let Some(link) = self
            .links
            .iter_mut()
            .find(|l| robot_apid(l.board) == tm.apid)
        else {
            return;
        };
        match link.framer.push(buf.get(..n).unwrap_or(&[])) {
            Ok(()) => {
                link.oldest.get_or_insert(now);
            }
            Err(_) => link.counters.tm_overflow = link.counters.tm_overflow.wrapping_add(1),
        }
    }

    /// FARM-1's buffer release for each robot waiting on a queue that has room again.
    fn release_buffers(&mut self) {
        for l in self.links.iter_mut() {
            let waiting = l.farm.state() == FarmState::Wait || l.farm.status().wait;
            if waiting && self.gateway.queue_room(l.board).unwrap_or(0) > 0 {
                l.farm.buffer_released();
            }
        }
    }
}

/// The frame length every robot's TM frames have (`spec/ccsds/link.toml`).
pub const FRAME_LEN: usize = TM_FRAME_LEN;
