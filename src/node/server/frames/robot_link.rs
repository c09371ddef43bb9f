//! One robot's end of the link on the server board: its FARM-1, its TM framer, its SDLS
//! associations and their refusals waiting for a report, and what of it the shell has kept
//! durable. The steps of a TC frame that concern one robot only are here.

use super::{FrameRefusal, LinkCounters, Origin, KEPT_SOURCES, SECURITY_EVENT_PERIOD_MS};
use crate::link::clcw::ClcwVcid;
use crate::link::farm::{Farm, Verdict};
use crate::link::sdls::{frames as secured, SaTable, SdlsRefusal};
use crate::link::tc_frame::{self, TcFrame};
use crate::link::tm_framer::TmFramer;
use crate::link::FrameKind;
use crate::node::server::store::queue::QUEUE_SLOTS;
use crate::node::server::store::{Entry, Progress};
use crate::units::BoardNumber;

/// One reason's refusals waiting to be reported.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Default)]
pub(super) struct Alarm {
    /// Frames refused since the last report.
    pub(super) pending: u16,
    /// The last one's SPI.
    pub(super) spi: u16,
    /// When the last report went.
    pub(super) last: Option<u32>,
}

impl Alarm {
    /// Whether a report waits and may go at `now`.
    pub(super) fn ready(&self, now: u32) -> bool {
        self.pending > 0
            && self
                .last
                .is_none_or(|t| now.wrapping_sub(t) >= SECURITY_EVENT_PERIOD_MS)
    }

    /// How long from `now` until the waiting report may go, if one waits.
    pub(super) fn wait(&self, now: u32) -> Option<u32> {
        (self.pending > 0).then(|| {
            self.last.map_or(0, |t| {
                SECURITY_EVENT_PERIOD_MS.saturating_sub(now.wrapping_sub(t))
            })
        })
    }
}

/// One robot's end of the link.
#[derive(Debug, Clone)]
pub(super) struct RobotLink<const N: usize> {
    pub(super) board: BoardNumber,
    pub(super) farm: Farm,
    pub(super) framer: TmFramer<N>,
    /// When the oldest report still waiting in the framer was written.
    pub(super) oldest: Option<u32>,
    /// The CLCW of the last frame sent.
    pub(super) clcw_sent: Option<[u8; 4]>,
    pub(super) counters: LinkCounters,
    /// SDLS, when the robot's link is secured: its TC (receiving) and TM (sending)
    /// associations.
    pub(super) sdls: Option<SaTable<2>>,
    /// SDLS refusals waiting for their ST\[5\] report, by reason.
    pub(super) alarms: [Alarm; SdlsRefusal::NAMES.len()],
    /// Where FARM-1 and the TC window stand now, and what the shell last confirmed durable
    /// (no TM frame and no visit leaves while they differ: `durable`).
    pub(super) progress: Progress,
    pub(super) progress_kept: Progress,
    /// The kept-key entries the shell last confirmed, by slot.
    pub(super) kept_written: [Option<Entry>; KEPT_SOURCES],
    /// The gateway's queue in the store's ring (write-ahead): which telecommand each slot
    /// holds, the next slot a new one takes, and what the shell last confirmed per slot.
    pub(super) ring: [Option<(u16, u16)>; QUEUE_SLOTS],
    pub(super) ring_next: u8,
    pub(super) ring_written: [Option<Entry>; QUEUE_SLOTS],
}

impl<const N: usize> RobotLink<N> {
    /// A checked TC frame from `origin` before FARM-1: a BC frame only from the ground's
    /// address; a data frame through SDLS when the link is secured (its plaintext into `plain`,
    /// its range and IV returned), a refusal counted (and waiting for its ST\[5\] report).
    pub(super) fn unwrap_tc(
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
                        .get(6..)
                        .and_then(<[u8]>::first_chunk::<2>)
                        .map_or(0, |b| u16::from_be_bytes(*b));
                }
                Err(e.into())
            }
        }
    }

    pub(super) fn clcw(&self) -> [u8; 4] {
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
    pub(super) fn due(&self, now: u32, gather_ms: u32) -> bool {
        self.framer.frame_due(now)
            || self
                .oldest
                .is_some_and(|t| now.wrapping_sub(t) >= gather_ms)
            || self.clcw_sent != Some(self.clcw())
    }

    /// FARM-1's verdict on a checked frame that came through SDLS (`iv`: the IV it verified
    /// with), counted; then what a restart must resume from: V(R) (a BC frame may have moved
    /// it) and the IV of a frame SDLS verified (the window moved to it whatever FARM-1 did
    /// with the frame).
    #[inline]
    pub(super) fn take_tc(
        &mut self,
        frame: &TcFrame<&[u8]>,
        buffer_ready: bool,
        iv: Option<u128>,
    ) -> Verdict {
        self.counters.tc_frames = self.counters.tc_frames.wrapping_add(1);
        let verdict = self.farm.frame(
            frame.kind(),
            frame.seq(),
            frame.control_command(),
            buffer_ready,
        );
        if let Verdict::Discard(_) = verdict {
            self.counters.tc_discarded = self.counters.tc_discarded.wrapping_add(1);
        }
        self.progress.vr = self.farm.vr();
        if iv.is_some() {
            self.progress.tc_iv = iv;
        }
        verdict
    }
}
