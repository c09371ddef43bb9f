//! A TC frame's way in on the server board: checked against the robot its header names,
//! through SDLS (data frames) or the ground's address (BC frames), judged by that robot's
//! FARM-1, and its packets handed to the gateway; and what became of it ([`FrameIn`]) or why
//! it went no further ([`FrameRefusal`]).

use super::FrameGateway;
use crate::ccsds::primary::PrimaryHeader;
use crate::link::farm::{DiscardReason, Verdict};
use crate::link::sdls::SdlsRefusal;
use crate::link::tc_frame::{self, Packets, SpacecraftId, TcFrame, TcFrameError, TcPrimaryHeader};
use crate::link::FrameKind;
use crate::pus::robot_apid;
use crate::units::BoardNumber;

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

impl<const R: usize, const Q: usize, const K: usize, const N: usize> FrameGateway<R, Q, K, N> {
    /// A TC frame from the ground's address, at `now` ([`FrameGateway::tc_frame_from`]).
    pub fn tc_frame(&mut self, now: u32, bytes: &[u8]) -> FrameIn {
        self.tc_frame_from(now, bytes, Origin::Ground)
    }

    /// A TC frame from `origin`, at `now`.
    pub fn tc_frame_from(&mut self, now: u32, bytes: &[u8], origin: Origin) -> FrameIn {
        let (at, board, frame) = match self.check_tc(bytes) {
            Ok(checked) => checked,
            Err(refused) => return refused,
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
        let verdict = link.take_tc(&frame, room >= packets, iv);
        result.verdict = Ok(verdict);
        if verdict != Verdict::Accept || frame.kind() == FrameKind::Bc {
            return result;
        }
        self.accept_packets(now, at, data, &mut result);
        self.sync_rings();
        result
    }

    /// The frame checked against the configuration of the robot its header's spacecraft ID
    /// names (read before any check: it only picks the configuration; the checks then say
    /// whether the frame is sound and whether it is really for that robot): the robot's place
    /// in `links`, the robot and the frame; a refusal counted, as the answer.
    #[inline]
    fn check_tc<'b>(
        &mut self,
        bytes: &'b [u8],
    ) -> Result<(usize, BoardNumber, TcFrame<&'b [u8]>), FrameIn> {
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
                return Err(FrameIn {
                    robot: None,
                    verdict: Err(e.into()),
                    accepted: 0,
                    refused: 0,
                });
            }
        };
        let Some(board) = board else {
            // Unreachable: with no robot the spacecraft ID check refuses every frame.
            return Err(FrameIn {
                robot: None,
                verdict: Ok(Verdict::Discard(DiscardReason::Invalid)),
                accepted: 0,
                refused: 0,
            });
        };
        Ok((at, board, frame))
    }

    /// The packets of an accepted data frame (`data`) to the gateway, each required to carry
    /// the robot's APID; their reports into the TM framer, the count into `result` and into
    /// the counters of the robot at `at`.
    #[inline]
    fn accept_packets(&mut self, now: u32, at: usize, data: &[u8], result: &mut FrameIn) {
        let Some(board) = result.robot else { return };
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
    }
}
