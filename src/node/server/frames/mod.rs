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
//!
//! [`TcFrame::new_checked`]: crate::link::tc_frame::TcFrame::new_checked
// req: D:link-cop1, D:restart-server

use super::gateway::{Config as GatewayConfig, Gateway, Kept, KEPT_SOURCES};
use super::store::queue::QUEUE_SLOTS;
use super::store::Progress;
use crate::link::farm::{Farm, FarmState, FarmWindow};
use crate::link::sdls::SdlsRefusal;
use crate::link::tc_frame::{SpacecraftId, TcFrameError};
use crate::link::tm_frame::{TmFrameParams, TM_FRAME_LEN};
use crate::link::tm_framer::{TmFramer, IDLE_PERIOD_MS};
use crate::units::BoardNumber;
use crate::wire::command::CommandRepr;
use crate::wire::heartbeat::HeartbeatRepr;
use heapless::Vec;

mod durable;
mod robot_link;
mod secure;
mod tc_in;
mod tm_out;

pub use super::store::Stored;
pub use durable::DUE_PER_ROBOT;
use robot_link::{Alarm, RobotLink};
pub use tc_in::{FrameIn, FrameRefusal, Origin};

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
