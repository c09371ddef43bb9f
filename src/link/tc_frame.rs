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
use crate::ccsds::pec;
use crate::ccsds::primary::{PrimaryHeader, PRIMARY_LEN};
use crate::units::{ranged, BoardNumber};

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
        SpacecraftId(SPACECRAFT_ID_BASE + board.get() as u16)
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
        TC_PRIMARY_HEADER_LEN + 1 + self.fecf_len()
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
    #[allow(clippy::len_without_is_empty)] // never empty
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

/// Why bytes are not a TC transfer frame this receiver accepts. Each variant names one check;
/// [`TcFrame::new_checked`] runs them in the order of [`TcFrameError::NAMES`] (the order of the
/// variants here) and reports the first that fails:
///
/// 1. `truncated`: fewer octets than the shortest frame (header, one data octet, FECF);
/// 2. `version`, `flags`, `spare`: the primary header's fixed fields, in bit order (the
///    version `00`; the flags not `(0, 1)`; the reserved spare `00`);
/// 3. `length`: the frame length field against the octets given (both ways);
/// 4. `too-long`: the frame against the channel's longest;
/// 5. `fecf`: the CRC-16 over the whole frame before it (skipped without an FECF);
/// 6. `spacecraft-id`, `vcid`: the addressing, against the channel's configuration;
/// 7. `sequence-flags`, `map-id`: the segment header of an AD or BD frame on a VC that has
///    one (whole packets only; an accepted MAP);
/// 8. `control-command`: a BC frame's data field is Unlock or Set V(R);
/// 9. `packet-boundary`: not a check of the frame but of its data, run by
///    [`TcFrame::packets`]: the data is whole space packets, back to back.
///
/// The rationale is that of [`crate::ccsds::PacketError`]: the fields fixed for every TC
/// frame first (a frame of another protocol is refused for what it is), the length before the
/// FECF (the length says where the FECF is), the addressing after the FECF (a corrupted
/// spacecraft ID or VCID is reported as corruption, a foreign one only when the frame is
/// intact), and the content last.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, thiserror::Error)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
#[non_exhaustive]
pub enum TcFrameError {
    /// Fewer octets than the shortest frame.
    #[error("TC frame: {found} octets, fewer than the shortest frame ({expected})")]
    Truncated {
        /// Header, one data octet, and the FECF if the channel has one.
        expected: usize,
        /// Octets given.
        found: usize,
    },
    /// Transfer frame version number other than `00`.
    #[error("TC frame: transfer frame version number must be {expected}, found {found}")]
    Version {
        /// 0.
        expected: u8,
        /// Bits 0–1.
        found: u8,
    },
    /// Bypass flag 0 with control command flag 1: no frame type.
    #[error("TC frame: bypass flag {bypass} with control command flag {control} is no frame type")]
    Flags {
        /// Bit 2.
        bypass: u8,
        /// Bit 3.
        control: u8,
    },
    /// The reserved spare bits are not `00`.
    #[error("TC frame: reserved spare must be {expected}, found {found:#04b}")]
    Spare {
        /// 0.
        expected: u8,
        /// Bits 4–5.
        found: u8,
    },
    /// The frame length field disagrees with the number of octets given.
    #[error("TC frame: the frame length field says {expected} octets, found {found}")]
    Length {
        /// Total length the field declares (field + 1).
        expected: usize,
        /// Octets given.
        found: usize,
    },
    /// Longer than the channel's longest frame.
    #[error("TC frame: {found} octets, longer than this channel's {max}")]
    TooLong {
        /// The channel's longest frame.
        max: usize,
        /// The frame's length.
        found: usize,
    },
    /// The FECF disagrees with the CRC of the other octets.
    #[error("TC frame: FECF carried {carried:#06x}, computed {computed:#06x}")]
    Fecf {
        /// The last two octets, big-endian.
        carried: u16,
        /// CRC-16/CCITT-FALSE of the others.
        computed: u16,
    },
    /// Another spacecraft's frame.
    #[error("TC frame: spacecraft ID {found:#05x}, this receiver is {expected:#05x}")]
    SpacecraftId {
        /// The receiver's.
        expected: u16,
        /// The frame's.
        found: u16,
    },
    /// A virtual channel the receiver does not have.
    #[error("TC frame: virtual channel {found} is not one this receiver accepts")]
    Vcid {
        /// The frame's VCID.
        found: u8,
    },
    /// Segment header sequence flags other than `0b11`: a segment of a packet, which we do
    /// not reassemble.
    #[error("TC frame: sequence flags must be {expected:#04b} (unsegmented), found {found:#04b}")]
    SequenceFlags {
        /// `0b11`.
        expected: u8,
        /// The segment header's bits 0–1.
        found: u8,
    },
    /// A MAP the virtual channel does not accept.
    #[error("TC frame: MAP {found} is not one virtual channel {vcid} accepts")]
    MapId {
        /// The frame's VCID.
        vcid: u8,
        /// The segment header's MAP ID.
        found: u8,
    },
    /// A BC frame whose data field is neither Unlock nor Set V(R).
    #[error("TC frame: a control command of {len} octets starting {head:02x?} is neither Unlock nor Set V(R)")]
    ControlCommand {
        /// Octets in the data field.
        len: usize,
        /// Its first three octets (zeros past its end).
        head: [u8; 3],
    },
    /// The data of an AD or BD frame does not end on a packet boundary: the packet at `at`
    /// needs `needed` octets (its primary header's, or the length its header declares),
    /// only `left` remain.
    #[error("TC frame: the packet at octet {at} of the data needs {needed} octets, {left} left")]
    PacketBoundary {
        /// Offset of the packet in the frame's data.
        at: usize,
        /// Octets the packet needs: 6 for its header, or its declared total length.
        needed: usize,
        /// Octets left in the data from `at`.
        left: usize,
    },
}

impl TcFrameError {
    /// Every check's name, in the order they run.
    pub const NAMES: [&'static str; 13] = [
        "truncated",
        "version",
        "flags",
        "spare",
        "length",
        "too-long",
        "fecf",
        "spacecraft-id",
        "vcid",
        "sequence-flags",
        "map-id",
        "control-command",
        "packet-boundary",
    ];

    /// The failed check's name (`spec/ccsds/bad-inputs.toml`, CLI output).
    pub const fn name(&self) -> &'static str {
        Self::NAMES[self.position()]
    }

    /// The failed check's place in the check order (0 = first).
    pub const fn position(&self) -> usize {
        match self {
            TcFrameError::Truncated { .. } => 0,
            TcFrameError::Version { .. } => 1,
            TcFrameError::Flags { .. } => 2,
            TcFrameError::Spare { .. } => 3,
            TcFrameError::Length { .. } => 4,
            TcFrameError::TooLong { .. } => 5,
            TcFrameError::Fecf { .. } => 6,
            TcFrameError::SpacecraftId { .. } => 7,
            TcFrameError::Vcid { .. } => 8,
            TcFrameError::SequenceFlags { .. } => 9,
            TcFrameError::MapId { .. } => 10,
            TcFrameError::ControlCommand { .. } => 11,
            TcFrameError::PacketBoundary { .. } => 12,
        }
    }
}

/// Why a frame could not be written.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, thiserror::Error)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
#[non_exhaustive]
pub enum TcEmitError {
    /// The caller's buffer is shorter than the frame.
    #[error("the frame needs {expected} octets, the buffer has {found}")]
    BufferTooSmall {
        /// The frame's length.
        expected: usize,
        /// The buffer's length.
        found: usize,
    },
    /// More data than one TC frame holds (1024 octets in all).
    #[error("a frame of {found} octets, at most {max} fit the frame length field")]
    FrameTooLong {
        /// [`TC_MAX_FRAME_LEN`].
        max: usize,
        /// The frame's length with this data.
        found: usize,
    },
}

/// The primary header's fields as they lie in the octets, decoded but not judged.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct TcPrimaryHeader {
    /// Transfer frame version number (2 bits).
    pub version: u8,
    /// Bypass flag.
    pub bypass: bool,
    /// Control command flag.
    pub control: bool,
    /// Reserved spare (2 bits).
    pub spare: u8,
    /// Spacecraft ID (10 bits).
    pub spacecraft_id: u16,
    /// Virtual channel ID (6 bits).
    pub vcid: u8,
    /// Frame length field: octets in the frame minus 1 (10 bits).
    pub frame_length: u16,
    /// Frame sequence number N(S).
    pub seq: u8,
}

impl TcPrimaryHeader {
    /// Decodes the first five octets of `bytes`; `None` if there are fewer.
    pub fn read(bytes: &[u8]) -> Option<TcPrimaryHeader> {
        let h: &[u8; TC_PRIMARY_HEADER_LEN] = bytes.first_chunk()?;
        let [b0, b1, b2, b3, seq] = *h;
        Some(TcPrimaryHeader {
            version: b0 >> 6,
            bypass: b0 & 0x20 != 0,
            control: b0 & 0x10 != 0,
            spare: (b0 >> 2) & 0b11,
            spacecraft_id: ((b0 & 0b11) as u16) << 8 | b1 as u16,
            vcid: b2 >> 2,
            frame_length: ((b2 & 0b11) as u16) << 8 | b3 as u16,
            seq,
        })
    }

    /// The frame's total length in octets as the frame length field says: field + 1.
    pub const fn total_len(&self) -> usize {
        self.frame_length as usize + 1
    }

    /// The five octets (fields wider than their bits are masked).
    pub const fn to_bytes(&self) -> [u8; TC_PRIMARY_HEADER_LEN] {
        [
            (self.version & 0b11) << 6
                | (self.bypass as u8) << 5
                | (self.control as u8) << 4
                | (self.spare & 0b11) << 2
                | ((self.spacecraft_id >> 8) & 0b11) as u8,
            self.spacecraft_id as u8,
            (self.vcid & 0x3f) << 2 | ((self.frame_length >> 8) & 0b11) as u8,
            self.frame_length as u8,
            self.seq,
        ]
    }
}

/// A TC frame whose every [`TcFrameError`] check (but `packet-boundary`) has passed, over its
/// octets: `T` is the buffer (`&[u8]`, an array, a `heapless::Vec`, ...).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct TcFrame<T: AsRef<[u8]>> {
    buffer: T,
    header: TcPrimaryHeader,
    kind: FrameKind,
    segment_header: bool,
    fecf: bool,
}

impl<T: AsRef<[u8]>> TcFrame<T> {
    /// Checks `buffer` as one whole TC frame of the channel `config` describes (see
    /// [`TcFrameError`] for the checks and their order).
    pub fn new_checked(buffer: T, config: &TcFrameConfig<'_>) -> Result<TcFrame<T>, TcFrameError> {
        let bytes = buffer.as_ref();
        let n = bytes.len();
        let truncated = TcFrameError::Truncated {
            expected: config.min_frame_len(),
            found: n,
        };
        if n < config.min_frame_len() {
            return Err(truncated);
        }
        let header = TcPrimaryHeader::read(bytes).ok_or(truncated)?;
        if header.version != TC_VERSION {
            return Err(TcFrameError::Version {
                expected: TC_VERSION,
                found: header.version,
            });
        }
        let kind =
            FrameKind::from_flags(header.bypass, header.control).ok_or(TcFrameError::Flags {
                bypass: header.bypass as u8,
                control: header.control as u8,
            })?;
        if header.spare != 0 {
            return Err(TcFrameError::Spare {
                expected: 0,
                found: header.spare,
            });
        }
        if header.total_len() != n {
            return Err(TcFrameError::Length {
                expected: header.total_len(),
                found: n,
            });
        }
        let max = config.max_frame_len.min(TC_MAX_FRAME_LEN);
        if n > max {
            return Err(TcFrameError::TooLong { max, found: n });
        }
        if config.fecf {
            let (body, carried) = bytes.split_last_chunk::<FECF_LEN>().ok_or(truncated)?;
            let carried = u16::from_be_bytes(*carried);
            let computed = pec(body);
            if carried != computed {
                return Err(TcFrameError::Fecf { carried, computed });
            }
        }
        if header.spacecraft_id != config.spacecraft_id.get() {
            return Err(TcFrameError::SpacecraftId {
                expected: config.spacecraft_id.get(),
                found: header.spacecraft_id,
            });
        }
        let vc = config
            .vc(header.vcid)
            .ok_or(TcFrameError::Vcid { found: header.vcid })?;
        let segment_header = vc.segment_header && kind != FrameKind::Bc;
        let frame = TcFrame {
            buffer,
            header,
            kind,
            segment_header,
            fecf: config.fecf,
        };
        if let Some((flags, map_id)) = frame.segment() {
            if flags != UNSEGMENTED {
                return Err(TcFrameError::SequenceFlags {
                    expected: UNSEGMENTED,
                    found: flags,
                });
            }
            if vc.map_ids >> map_id.get() & 1 == 0 {
                return Err(TcFrameError::MapId {
                    vcid: header.vcid,
                    found: map_id.get(),
                });
            }
        }
        if kind == FrameKind::Bc {
            ControlCommand::parse(frame.data_field())?;
        }
        Ok(frame)
    }

    /// The buffer back.
    pub fn into_inner(self) -> T {
        self.buffer
    }

    /// The whole frame.
    pub fn as_bytes(&self) -> &[u8] {
        self.buffer.as_ref()
    }

    /// The primary header.
    pub fn header(&self) -> TcPrimaryHeader {
        self.header
    }

    /// AD, BD or BC.
    pub fn kind(&self) -> FrameKind {
        self.kind
    }

    /// The spacecraft ID (the receiver's).
    pub fn spacecraft_id(&self) -> SpacecraftId {
        SpacecraftId::masked(self.header.spacecraft_id)
    }

    /// The virtual channel (one the receiver accepts).
    pub fn vcid(&self) -> Vcid {
        Vcid::masked(self.header.vcid)
    }

    /// The frame sequence number N(S).
    pub fn seq(&self) -> u8 {
        self.header.seq
    }

    /// The frame data field: everything between the primary header and the FECF (the
    /// segment header included, when there is one).
    pub fn data_field(&self) -> &[u8] {
        let bytes = self.buffer.as_ref();
        let end = bytes
            .len()
            .saturating_sub(if self.fecf { FECF_LEN } else { 0 });
        bytes.get(TC_PRIMARY_HEADER_LEN..end).unwrap_or(&[])
    }

    /// The segment header's sequence flags and MAP ID, if the frame has one.
    pub fn segment(&self) -> Option<(u8, MapId)> {
        if !self.segment_header {
            return None;
        }
        let b = *self.data_field().first()?;
        Some((b >> 6, MapId::masked(b)))
    }

    /// The MAP ID, if the frame has a segment header.
    pub fn map_id(&self) -> Option<MapId> {
        self.segment().map(|(_, m)| m)
    }

    /// The data an AD or BD frame carries (after the segment header), or a BC frame's
    /// control command octets.
    pub fn data(&self) -> &[u8] {
        let field = self.data_field();
        if self.segment_header {
            field.get(SEGMENT_HEADER_LEN..).unwrap_or(&[])
        } else {
            field
        }
    }

    /// The control command of a BC frame; `None` for AD and BD frames.
    pub fn control_command(&self) -> Option<ControlCommand> {
        match self.kind {
            FrameKind::Bc => ControlCommand::parse(self.data_field()).ok(),
            FrameKind::Ad | FrameKind::Bd => None,
        }
    }

    /// The FECF as carried (and checked), if the channel has one.
    pub fn fecf(&self) -> Option<u16> {
        let bytes = self.buffer.as_ref();
        match (self.fecf, bytes.last_chunk::<FECF_LEN>()) {
            (true, Some(f)) => Some(u16::from_be_bytes(*f)),
            _ => None,
        }
    }

    /// The whole space packets of an AD or BD frame's data, in order (none for a BC frame):
    /// see [`Packets`].
    pub fn packets(&self) -> Packets<'_> {
        match self.kind {
            FrameKind::Ad | FrameKind::Bd => Packets::new(self.data()),
            FrameKind::Bc => Packets::new(&[]),
        }
    }

    /// The frame's fields.
    pub fn repr(&self) -> TcFrameRepr<'_> {
        let content = match self.kind {
            FrameKind::Ad => TcContent::Ad {
                map_id: self.map_id(),
                data: self.data(),
            },
            FrameKind::Bd => TcContent::Bd {
                map_id: self.map_id(),
                data: self.data(),
            },
            FrameKind::Bc => {
                TcContent::Bc(self.control_command().unwrap_or(ControlCommand::Unlock))
            }
        };
        TcFrameRepr {
            spacecraft_id: self.spacecraft_id(),
            vcid: self.vcid(),
            seq: self.header.seq,
            content,
        }
    }
}

/// The whole space packets in a frame's data, each by its primary header's packet data length
/// (CCSDS 133.0-B-2 §4.1.3.5; several may be blocked in one frame, none spans two). An item is
/// a packet's octets, not judged (the packet layer's parsers do that); the data must end on a
/// packet boundary, or the last item is [`TcFrameError::PacketBoundary`] and the iteration
/// ends.
#[derive(Debug, Clone)]
pub struct Packets<'a> {
    data: &'a [u8],
    at: usize,
    failed: bool,
}

impl<'a> Packets<'a> {
    /// The packets of `data` (an AD or BD frame's data, after the segment header).
    pub const fn new(data: &'a [u8]) -> Packets<'a> {
        Packets {
            data,
            at: 0,
            failed: false,
        }
    }
}

impl<'a> Iterator for Packets<'a> {
    type Item = Result<&'a [u8], TcFrameError>;

    fn next(&mut self) -> Option<Self::Item> {
        if self.failed {
            return None;
        }
        let rest = self.data.get(self.at..).filter(|r| !r.is_empty())?;
        let needed = PrimaryHeader::read(rest).map_or(PRIMARY_LEN, |h| h.total_len());
        match rest.get(..needed) {
            Some(packet) if PrimaryHeader::read(rest).is_some() => {
                self.at += needed;
                Some(Ok(packet))
            }
            _ => {
                self.failed = true;
                Some(Err(TcFrameError::PacketBoundary {
                    at: self.at,
                    needed,
                    left: rest.len(),
                }))
            }
        }
    }
}

/// What an AD, BD or BC frame carries.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
#[cfg_attr(feature = "serde", derive(serde::Serialize))]
#[cfg_attr(feature = "serde", serde(rename_all = "kebab-case"))]
pub enum TcContent<'a> {
    /// Type-AD: data under COP-1's sequence control.
    Ad {
        /// The MAP of the segment header (unsegmented), if the VC has one.
        map_id: Option<MapId>,
        /// The data after the segment header: whole space packets.
        data: &'a [u8],
    },
    /// Type-BD: data bypassing FARM-1's sequence checks.
    Bd {
        /// The MAP of the segment header (unsegmented), if the VC has one.
        map_id: Option<MapId>,
        /// The data after the segment header: whole space packets.
        data: &'a [u8],
    },
    /// Type-BC: a control command to FARM-1.
    Bc(ControlCommand),
}

impl TcContent<'_> {
    /// AD, BD or BC.
    pub const fn kind(&self) -> FrameKind {
        match self {
            TcContent::Ad { .. } => FrameKind::Ad,
            TcContent::Bd { .. } => FrameKind::Bd,
            TcContent::Bc(_) => FrameKind::Bc,
        }
    }

    /// Octets of the data field: segment header, data, or the control command.
    const fn data_field_len(&self) -> usize {
        match self {
            TcContent::Ad { map_id, data } | TcContent::Bd { map_id, data } => {
                let seg = if map_id.is_some() {
                    SEGMENT_HEADER_LEN
                } else {
                    0
                };
                seg.saturating_add(data.len())
            }
            TcContent::Bc(c) => c.len(),
        }
    }
}

/// A TC frame's fields. The data is borrowed, as in [`crate::ccsds::tc::TcRepr`].
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
#[cfg_attr(feature = "serde", derive(serde::Serialize))]
pub struct TcFrameRepr<'a> {
    /// The spacecraft (robot) the frame is for.
    pub spacecraft_id: SpacecraftId,
    /// Its virtual channel.
    pub vcid: Vcid,
    /// Frame sequence number N(S): COP-1's for AD frames; carried as is in BD and BC frames,
    /// whose sequence FARM-1 does not check (FOP-1 sends 0 there).
    pub seq: u8,
    /// What it carries, and so its kind.
    pub content: TcContent<'a>,
}

impl<'a> TcFrameRepr<'a> {
    /// Checks `bytes` (see [`TcFrame::new_checked`]) and returns the fields.
    pub fn parse(
        bytes: &'a [u8],
        config: &TcFrameConfig<'_>,
    ) -> Result<TcFrameRepr<'a>, TcFrameError> {
        let frame = TcFrame::new_checked(bytes, config)?;
        let header = frame.header;
        let segment_header = frame.segment_header;
        // Rebuilt from `bytes` (not `frame`) so the data borrows the caller's octets.
        let field = bytes
            .get(TC_PRIMARY_HEADER_LEN..bytes.len().saturating_sub(config.fecf_len()))
            .unwrap_or(&[]);
        let map_id = frame.map_id();
        let data = if segment_header {
            field.get(SEGMENT_HEADER_LEN..).unwrap_or(&[])
        } else {
            field
        };
        let content = match frame.kind {
            FrameKind::Ad => TcContent::Ad { map_id, data },
            FrameKind::Bd => TcContent::Bd { map_id, data },
            FrameKind::Bc => TcContent::Bc(ControlCommand::parse(field)?),
        };
        Ok(TcFrameRepr {
            spacecraft_id: SpacecraftId::masked(header.spacecraft_id),
            vcid: Vcid::masked(header.vcid),
            seq: header.seq,
            content,
        })
    }

    /// AD, BD or BC.
    pub const fn kind(&self) -> FrameKind {
        self.content.kind()
    }

    /// Octets of the frame with an FECF (saturating for data no frame holds, which
    /// [`TcFrameRepr::emit`] refuses).
    #[allow(clippy::len_without_is_empty)] // never empty
    pub const fn len(&self) -> usize {
        self.len_with(true)
    }

    /// Octets of the frame, with or without the FECF.
    pub const fn len_with(&self, fecf: bool) -> usize {
        let f = if fecf { FECF_LEN } else { 0 };
        (TC_PRIMARY_HEADER_LEN + f).saturating_add(self.content.data_field_len())
    }

    /// Writes the frame, FECF included, into the front of `out`; the number of octets
    /// written. Refused when `out` is too short or the frame longer than
    /// [`TC_MAX_FRAME_LEN`]. Whether the result suits a channel (its longest frame, its
    /// segment header) is the caller's: the same frame parses back with a [`TcFrameConfig`]
    /// that agrees.
    pub fn emit(&self, out: &mut [u8]) -> Result<usize, TcEmitError> {
        self.emit_with(true, out)
    }

    /// [`TcFrameRepr::emit`], with or without the FECF (for channels without one).
    pub fn emit_with(&self, fecf: bool, out: &mut [u8]) -> Result<usize, TcEmitError> {
        let len = self.len_with(fecf);
        if len > TC_MAX_FRAME_LEN {
            return Err(TcEmitError::FrameTooLong {
                max: TC_MAX_FRAME_LEN,
                found: len,
            });
        }
        let too_small = TcEmitError::BufferTooSmall {
            expected: len,
            found: out.len(),
        };
        let frame = out.get_mut(..len).ok_or(too_small)?;
        let (bypass, control) = self.kind().flags();
        let header = TcPrimaryHeader {
            version: TC_VERSION,
            bypass,
            control,
            spare: 0,
            spacecraft_id: self.spacecraft_id.get(),
            vcid: self.vcid.get(),
            frame_length: (len - 1) as u16,
            seq: self.seq,
        };
        let (head, rest) = frame.split_at_mut(TC_PRIMARY_HEADER_LEN);
        head.copy_from_slice(&header.to_bytes());
        let f = if fecf { FECF_LEN } else { 0 };
        let field_len = rest.len() - f;
        let field = rest.get_mut(..field_len).ok_or(too_small)?;
        match self.content {
            TcContent::Ad { map_id, data } | TcContent::Bd { map_id, data } => {
                let data_out = match map_id {
                    Some(m) => {
                        let (seg, d) = field.split_at_mut(SEGMENT_HEADER_LEN);
                        seg.fill(UNSEGMENTED << 6 | m.get());
                        d
                    }
                    None => field,
                };
                data_out.copy_from_slice(data);
            }
            TcContent::Bc(c) => {
                let (bytes, n) = c.to_bytes();
                field.copy_from_slice(bytes.get(..n).unwrap_or(&[]));
            }
        }
        if fecf {
            let (body, fecf_out) = frame.split_last_chunk_mut::<FECF_LEN>().ok_or(too_small)?;
            *fecf_out = pec(body).to_be_bytes();
        }
        Ok(len)
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
