//! The TC transfer frame (CCSDS 232.0-B-4 §4.1): a five-octet primary header, an optional
//! one-octet segment header, the data field, and the frame error control field (FECF).
//!
//! ```
//! use mmic::ccsds::primary::{Apid, SeqCount};
//! use mmic::ccsds::tc::TcRepr;
//! use mmic::ccsds::tc_header::{AckFlags, TcSecondaryHeader};
//! use mmic::link::tc_frame::{mission, MapId, SpacecraftId, TcContent, TcFrameRepr, Vcid};
//!
//! // The TC(17,1) ping of the packet layer's example (13 octets) ...
//! let ping = TcRepr {
//!     apid: Apid::new(0x42).unwrap(),
//!     seq_count: SeqCount::new(7).unwrap(),
//!     header: TcSecondaryHeader { ack: AckFlags::ALL, service: 17, subservice: 1, source_id: 0 },
//!     app_data: &[],
//! };
//! let mut packet = [0u8; 13];
//! ping.emit(&mut packet).unwrap();
//!
//! // ... in an AD frame of spacecraft 0x101, VC 0, MAP 0, N(S) 0: 5 + 1 + 13 + 2 octets.
//! let frame = TcFrameRepr {
//!     spacecraft_id: SpacecraftId::new(0x101).unwrap(),
//!     vcid: Vcid::new(0).unwrap(),
//!     seq: 0,
//!     content: TcContent::Ad { map_id: Some(MapId::new(0).unwrap()), data: &packet },
//! };
//! let mut buf = [0u8; 64];
//! let n = frame.emit(&mut buf).unwrap();
//! assert_eq!(n, 21);
//! assert_eq!(buf[..6], [0x01, 0x01, 0x00, 0x14, 0x00, 0xc0]);
//!
//! let config = mission(SpacecraftId::new(0x101).unwrap());
//! assert_eq!(TcFrameRepr::parse(&buf[..n], &config), Ok(frame));
//!
//! // Strict: any flipped bit is refused by name (here, one in the packet: the FECF's check).
//! buf[10] ^= 0x04;
//! assert_eq!(TcFrameRepr::parse(&buf[..n], &config).unwrap_err().name(), "fecf");
//! ```
//!
//! The primary header, bit by bit (232.0-B-4 §4.1.2):
//!
//! | bits | field | here |
//! |---|---|---|
//! | 0–1 | transfer frame version number | always `00` ([`TC_VERSION`]) |
//! | 2 | bypass flag | 0 type-A, 1 type-B |
//! | 3 | control command flag | 0 data, 1 control command |
//! | 4–5 | reserved spare | always `00` |
//! | 6–15 | spacecraft ID | [`SpacecraftId`], 10 bits |
//! | 16–21 | virtual channel ID | [`Vcid`], 6 bits |
//! | 22–31 | frame length | octets in the whole frame minus 1, 10 bits |
//! | 32–39 | frame sequence number N(S) | 8 bits |
//!
//! The two flags give the [`FrameKind`]: AD `(0, 0)`, BD `(1, 0)`, BC `(1, 1)`; `(0, 1)` is
//! refused. Whether a virtual channel's AD and BD frames carry the segment header (sequence
//! flags, 2 bits, and MAP ID, 6 bits; 232.0-B-4 §4.1.3.2) and whether the channel's frames
//! carry the FECF are managed parameters (232.0-B-4 §5), handed to the parser as a
//! [`TcFrameConfig`]; a BC frame never has a segment header (§4.1.3.2.1.3), its data field
//! is the control command (§4.1.3.3). The mission's parameters (`spec/ccsds/link.toml`) are
//! [`mission`]'s: one VC (0), every frame with the segment header for MAP 0 and the FECF, at
//! most [`MAX_FRAME_LEN`] octets.
//!
//! We carry whole packets only: the segment header's sequence flags must say `0b11`
//! (unsegmented), and an AD or BD frame's data holds one or more whole space packets back to
//! back ([`TcFrame::packets`]); a packet never spans frames (decision `link-tc-frame`).
//!
//! Every check, its order and its error are listed on [`TcFrameError`]; exactly one error
//! comes out for a given input.

use super::{ControlCommand, FrameKind};
use crate::units::{ranged, BoardNumber};

mod error;
mod header;
mod repr;
mod view;

pub use error::{TcEmitError, TcFrameError};
pub use header::TcPrimaryHeader;
pub use repr::{TcContent, TcFrameRepr};
pub use view::{Packets, TcFrame};

/// Octets of the TC primary header (232.0-B-4 §4.1.2).
pub const TC_PRIMARY_HEADER_LEN: usize = 5;
/// Octets of the segment header (232.0-B-4 §4.1.3.2).
pub const SEGMENT_HEADER_LEN: usize = 1;
/// Octets of the frame error control field (232.0-B-4 §4.1.4).
pub const FECF_LEN: usize = 2;
/// The longest TC transfer frame the standard allows: the 10-bit frame length field's
/// 1023 + 1 (232.0-B-4 §4.1.2.7).
pub const TC_MAX_FRAME_LEN: usize = 1024;
/// The mission's longest TC frame, headers and FECF included (`spec/ccsds/link.toml`,
/// `[tc] max_frame_len`): a frame the server board's radio buffer holds whole.
pub const MAX_FRAME_LEN: usize = 256;
/// The transfer frame version number of TC frames: `00` (232.0-B-4 §4.1.2.2).
pub const TC_VERSION: u8 = 0;
/// Sequence flags of a segment header holding whole packets: `0b11`, "no segmentation"
/// (232.0-B-4 §4.1.3.2.2).
pub const UNSEGMENTED: u8 = 0b11;
/// The mission's one TC virtual channel (`[tc] vcid`).
pub const MISSION_VCID: u8 = 0;
/// The mission's one MAP (`[tc] map_id`).
pub const MISSION_MAP_ID: u8 = 0;
/// Whether the mission's AD and BD frames carry the segment header (`[tc] segment_header`).
pub const MISSION_SEGMENT_HEADER: bool = true;
/// Whether the mission's TC frames carry the FECF (`[tc] fecf`).
pub const MISSION_FECF: bool = true;
/// The spacecraft ID of board `n`'s robot is `0x100 + n` (`[spacecraft] id`).
pub const SPACECRAFT_ID_BASE: u16 = 0x100;

/// Octets of Unlock (`0x00`) and of Set V(R) (`0x82 0x00 V(R)`), 232.1-B-2 §4.1.3.3.
const UNLOCK: [u8; 1] = [0x00];
const SET_VR_HEAD: [u8; 2] = [0x82, 0x00];

ranged! {
    /// Spacecraft ID, 10 bits (0..=1023), in both the TC and the TM frame header
    /// (232.0-B-4 §4.1.2.5). The mission gives robot `n` the ID `0x100 + n`
    /// ([`SpacecraftId::of_board`]).
    #[derive(Default)]
    pub struct SpacecraftId(u16), min 0, max 0x3ff, "spacecraft ID";
}

ranged! {
    /// Virtual channel ID of a TC frame, 6 bits (0..=63), 232.0-B-4 §4.1.2.6.
    #[derive(Default)]
    pub struct Vcid(u8), min 0, max 0x3f, "virtual channel ID";
}

ranged! {
    /// Multiplexer access point ID, 6 bits (0..=63), in the segment header
    /// (232.0-B-4 §4.1.3.2.3).
    #[derive(Default)]
    pub struct MapId(u8), min 0, max 0x3f, "MAP ID";
}

impl SpacecraftId {
    /// The spacecraft ID of board `board`'s robot: `0x100 + n` (`spec/ccsds/link.toml`).
    pub const fn of_board(board: BoardNumber) -> SpacecraftId {
        // A board number is at most 255 (its octet widened through from_be_bytes, which a
        // const fn may call): the sum stays below 0x200.
        SpacecraftId(SPACECRAFT_ID_BASE.saturating_add(u16::from_be_bytes([0, board.get()])))
    }

    /// The 10 bits of `v` (the others dropped): for decoding, where the bits hold no more.
    const fn masked(v: u16) -> SpacecraftId {
        SpacecraftId(v & 0x3ff)
    }
}

impl Vcid {
    const fn masked(v: u8) -> Vcid {
        Vcid(v & 0x3f)
    }
}

impl MapId {
    const fn masked(v: u8) -> MapId {
        MapId(v & 0x3f)
    }
}

/// A virtual channel the receiver accepts, with its managed parameters (232.0-B-4 §5.4).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct VcConfig {
    /// The channel's ID.
    pub vcid: Vcid,
    /// Whether its AD and BD frames carry the segment header (the MAP service is used).
    pub segment_header: bool,
    /// The MAP IDs accepted on it, one bit each: bit `m` set accepts MAP `m` (64 MAPs, 64
    /// bits). Ignored without the segment header.
    pub map_ids: u64,
}

/// What the receiver expects of the TC frames of one physical channel: the managed
/// parameters of 232.0-B-4 §5 the parser needs.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct TcFrameConfig<'a> {
    /// The one spacecraft whose frames are accepted (one robot, one spacecraft).
    pub spacecraft_id: SpacecraftId,
    /// The virtual channels accepted, each with its parameters.
    pub vcs: &'a [VcConfig],
    /// Whether the frames carry the FECF ("presence of frame error control", a physical
    /// channel parameter).
    pub fecf: bool,
    /// The longest frame accepted, in octets, headers and FECF included (at most
    /// [`TC_MAX_FRAME_LEN`]).
    pub max_frame_len: usize,
}

/// The mission's one TC virtual channel: VC 0, segment header, MAP 0 only.
pub const MISSION_VCS: [VcConfig; 1] = [VcConfig {
    vcid: Vcid(MISSION_VCID),
    segment_header: MISSION_SEGMENT_HEADER,
    map_ids: 1 << MISSION_MAP_ID,
}];

/// The mission's TC frame parameters (`spec/ccsds/link.toml` `[tc]`) for the robot whose
/// spacecraft ID is `spacecraft_id`.
pub const fn mission(spacecraft_id: SpacecraftId) -> TcFrameConfig<'static> {
    TcFrameConfig {
        spacecraft_id,
        vcs: &MISSION_VCS,
        fecf: MISSION_FECF,
        max_frame_len: MAX_FRAME_LEN,
    }
}

impl TcFrameConfig<'_> {
    /// Octets of the FECF in this channel's frames: 2 or 0.
    pub const fn fecf_len(&self) -> usize {
        if self.fecf {
            FECF_LEN
        } else {
            0
        }
    }

    /// The shortest frame: the primary header, one data field octet (232.0-B-4 §4.1.3.1: the
    /// data field holds at least one; Unlock is one), and the FECF.
    pub const fn min_frame_len(&self) -> usize {
        (TC_PRIMARY_HEADER_LEN + 1).saturating_add(self.fecf_len())
    }

    fn vc(&self, vcid: u8) -> Option<&VcConfig> {
        self.vcs.iter().find(|vc| vc.vcid.get() == vcid)
    }
}

impl FrameKind {
    /// The kind the bypass and control command flags name; `None` for `(0, 1)`, which is
    /// none (232.0-B-4 §4.1.2.3).
    pub const fn from_flags(bypass: bool, control: bool) -> Option<FrameKind> {
        match (bypass, control) {
            (false, false) => Some(FrameKind::Ad),
            (true, false) => Some(FrameKind::Bd),
            (true, true) => Some(FrameKind::Bc),
            (false, true) => None,
        }
    }

    /// The bypass and control command flags of this kind.
    pub const fn flags(self) -> (bool, bool) {
        match self {
            FrameKind::Ad => (false, false),
            FrameKind::Bd => (true, false),
            FrameKind::Bc => (true, true),
        }
    }
}

impl ControlCommand {
    /// Longest control command: Set V(R), three octets.
    pub const MAX_LEN: usize = 3;

    /// Octets of the command: 1 (Unlock) or 3 (Set V(R)).
    #[expect(
        clippy::len_without_is_empty,
        reason = "a length of this type is never zero"
    )]
    pub const fn len(&self) -> usize {
        match self {
            ControlCommand::Unlock => UNLOCK.len(),
            ControlCommand::SetVr(_) => Self::MAX_LEN,
        }
    }

    /// The command's octets, in the front of a three-octet array (`len` of them count).
    pub const fn to_bytes(&self) -> ([u8; 3], usize) {
        match self {
            ControlCommand::Unlock => ([0x00, 0, 0], 1),
            ControlCommand::SetVr(v) => ([SET_VR_HEAD[0], SET_VR_HEAD[1], *v], 3),
        }
    }

    /// The command a BC frame's data field holds: exactly `0x00`, or exactly
    /// `0x82 0x00 V(R)` (232.1-B-2 §4.1.3.3); anything else is refused.
    pub fn parse(field: &[u8]) -> Result<ControlCommand, TcFrameError> {
        match field {
            [0x00] => Ok(ControlCommand::Unlock),
            [0x82, 0x00, v] => Ok(ControlCommand::SetVr(*v)),
            _ => {
                let mut head = [0u8; 3];
                for (h, b) in head.iter_mut().zip(field) {
                    *h = *b;
                }
                Err(TcFrameError::ControlCommand {
                    len: field.len(),
                    head,
                })
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_header_field_lands_on_its_bits() {
        let zero = TcPrimaryHeader {
            version: 0,
            bypass: false,
            control: false,
            spare: 0,
            spacecraft_id: 0,
            vcid: 0,
            frame_length: 0,
            seq: 0,
        };
        let cases: [(TcPrimaryHeader, [u8; 5]); 8] = [
            (TcPrimaryHeader { version: 3, ..zero }, [0xc0, 0, 0, 0, 0]),
            (
                TcPrimaryHeader {
                    bypass: true,
                    ..zero
                },
                [0x20, 0, 0, 0, 0],
            ),
            (
                TcPrimaryHeader {
                    control: true,
                    ..zero
                },
                [0x10, 0, 0, 0, 0],
            ),
            (TcPrimaryHeader { spare: 3, ..zero }, [0x0c, 0, 0, 0, 0]),
            (
                TcPrimaryHeader {
                    spacecraft_id: 0x3ff,
                    ..zero
                },
                [0x03, 0xff, 0, 0, 0],
            ),
            (TcPrimaryHeader { vcid: 0x3f, ..zero }, [0, 0, 0xfc, 0, 0]),
            (
                TcPrimaryHeader {
                    frame_length: 0x3ff,
                    ..zero
                },
                [0, 0, 0x03, 0xff, 0],
            ),
            (TcPrimaryHeader { seq: 0xff, ..zero }, [0, 0, 0, 0, 0xff]),
        ];
        for (h, bytes) in cases {
            assert_eq!(h.to_bytes(), bytes, "{h:?}");
            assert_eq!(TcPrimaryHeader::read(&bytes), Some(h));
        }
        assert_eq!(TcPrimaryHeader::read(&[0; 4]), None);
    }

    #[test]
    fn names_follow_the_variants() {
        let e = TcFrameError::PacketBoundary {
            at: 0,
            needed: 6,
            left: 1,
        };
        assert_eq!(e.name(), "packet-boundary");
        assert_eq!(
            TcFrameError::Truncated {
                expected: 8,
                found: 0
            }
            .name(),
            "truncated"
        );
    }
}
