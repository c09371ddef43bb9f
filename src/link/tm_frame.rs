//! The TM transfer frame (CCSDS 132.0-B-3 §4.1): a fixed-length frame, six octets of primary
//! header, the data field (space packets laid end to end, §4.1.4), the operational control
//! field (the CLCW, §4.1.5) and the frame error control field (§4.1.6):
//!
//! | bits | field | here |
//! |---|---|---|
//! | 0–1 | transfer frame version number | always `00` (version 1) |
//! | 2–11 | spacecraft ID | 10 bits, the robot's (`spec/ccsds/link.toml`: `0x100 + n`) |
//! | 12–14 | virtual channel ID | 3 bits, [`TM_VCID`] |
//! | 15 | OCF flag | set when the frame carries an OCF ([`TmFrameParams::ocf`]) |
//! | 16–23 | master channel frame count | mod 256 |
//! | 24–31 | virtual channel frame count | mod 256 |
//! | 32 | secondary header flag | always 0: no secondary header (decision `link-tm-frame`) |
//! | 33 | synchronisation flag | always 0: octet-synchronised packets |
//! | 34 | packet order flag | always 0 (reserved when the synch flag is 0) |
//! | 35–36 | segment length ID | always `11` (required when the synch flag is 0) |
//! | 37–47 | first header pointer | [`FirstHeaderPointer`] |
//!
//! The frame length, the presence of the OCF and of the FECF are managed parameters (§5): the
//! parser takes them, with the spacecraft ID and VCID it expects, as [`TmFrameParams`]. The
//! mission's are [`TmFrameParams::mission`]: [`TM_FRAME_LEN`] = 256 octets, OCF and FECF
//! present, VC [`TM_VCID`].
//!
//! ```
//! use mmic::link::tm_frame::{FirstHeaderPointer, TmFrameParams, TmFrameRepr, TM_FRAME_LEN};
//!
//! // Robot 0x42 (spacecraft 0x142), VC 0, frame counts 5 and 5, one packet starting at octet 0.
//! let params = TmFrameParams::mission(0x142).unwrap();
//! let data = [0x55u8; 244];
//! let repr = TmFrameRepr {
//!     spacecraft_id: 0x142,
//!     vcid: 0,
//!     mc_frame_count: 5,
//!     vc_frame_count: 5,
//!     first_header_pointer: FirstHeaderPointer::Packet(0),
//!     data: &data,
//!     ocf: Some([0x01, 0x00, 0x00, 0x00]),
//! };
//! let mut frame = [0u8; TM_FRAME_LEN];
//! assert_eq!(repr.emit(&params, &mut frame), Ok(256));
//! // 00 0101000010 000 1: version 0, spacecraft 0x142, VC 0, OCF flag; counts; status 0x1800.
//! assert_eq!(frame[..6], [0x14, 0x21, 0x05, 0x05, 0x18, 0x00]);
//! assert_eq!(TmFrameRepr::parse(&frame, &params), Ok(repr));
//!
//! // Strict: a flipped bit is refused by name (here by the FECF).
//! frame[10] ^= 0x04;
//! assert_eq!(TmFrameRepr::parse(&frame, &params).unwrap_err().name(), "fecf");
//! ```
//!
//! Every check, its order and its error are listed on [`TmFrameError`];
//! `spec/ccsds/bad-inputs.toml` holds one refused frame per check (parser `tm-frame`).

use crate::ccsds::pec;

/// Octets of the primary header (132.0-B-3 §4.1.2).
pub const PRIMARY_HEADER_LEN: usize = 6;
/// Octets of the operational control field (132.0-B-3 §4.1.5).
pub const OCF_LEN: usize = 4;
/// Octets of the frame error control field (132.0-B-3 §4.1.6).
pub const FECF_LEN: usize = 2;
/// The mission's TM frame length, headers and trailer included (`spec/ccsds/link.toml`
/// `[tm] frame_len`).
pub const TM_FRAME_LEN: usize = 256;
/// The mission's one TM virtual channel (`[tm] vcid`).
pub const TM_VCID: u8 = 0;
/// Whether the mission's TM frames carry an OCF (`[tm] ocf`: the CLCW in every frame).
pub const TM_OCF: bool = true;
/// Whether the mission's TM frames end with a FECF (`[tm] fecf`).
pub const TM_FECF: bool = true;
/// Whether the mission's TM frames have a secondary header (`[tm] secondary_header`): no, and
/// the parser refuses the flag ([`TmFrameError::SecondaryHeaderFlag`]).
pub const TM_SECONDARY_HEADER: bool = false;
/// The mission's data field length: 256 - 6 - 4 - 2.
pub const TM_DATA_LEN: usize = TM_FRAME_LEN - PRIMARY_HEADER_LEN - OCF_LEN - FECF_LEN;
/// The longest TM transfer frame 132.0-B-3 allows (§4.1.1; `spacepackets` 0.32 takes
/// only shorter ones).
pub const MAX_FRAME_LEN: usize = 2048;
/// The only transfer frame version number of TM frames (`00`, version 1).
pub const VERSION: u8 = 0;
/// The segment length ID required when the synchronisation flag is 0 (132.0-B-3 §4.1.2.7.5).
pub const SEGMENT_LENGTH_ID: u8 = 0b11;
/// First header pointer value: no packet starts in this frame (132.0-B-3 §4.1.2.7.6).
pub const FHP_NO_PACKET_START: u16 = 0x7ff;
/// First header pointer value: the data field holds only idle data (132.0-B-3 §4.1.2.7.6).
pub const FHP_ONLY_IDLE_DATA: u16 = 0x7fe;
/// Largest spacecraft ID (10 bits).
pub const MAX_SPACECRAFT_ID: u16 = 0x3ff;
/// Largest VCID (3 bits).
pub const MAX_VCID: u8 = 7;

/// Byte ranges of the primary header.
pub mod field {
    use core::ops::Range;
    /// Version, spacecraft ID, VCID, OCF flag.
    pub const ID: Range<usize> = 0..2;
    /// Master channel frame count.
    pub const MC_FRAME_COUNT: usize = 2;
    /// Virtual channel frame count.
    pub const VC_FRAME_COUNT: usize = 3;
    /// Data field status: flags, segment length ID, first header pointer.
    pub const DATA_FIELD_STATUS: Range<usize> = 4..6;
    /// First octet of the data field.
    pub const DATA_START: usize = 6;
}

/// The managed parameters of one TM physical channel and VC (132.0-B-3 §5) as the parser and
/// the framer take them: frame length, OCF and FECF presence, and the spacecraft ID and VCID
/// the receiver accepts. Built by [`TmFrameParams::new`], which refuses what no frame can
/// have, so that every frame under them has at least one data octet.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
#[cfg_attr(feature = "serde", derive(serde::Serialize))]
pub struct TmFrameParams {
    frame_len: usize,
    spacecraft_id: u16,
    vcid: u8,
    ocf: bool,
    fecf: bool,
    /// Octets of a security header before the packet zone and of a security trailer after it
    /// (SDLS, `crate::link::sdls`; 0 without).
    security: (u8, u8),
}

impl TmFrameParams {
    /// The parameters, or `None` when the spacecraft ID needs more than 10 bits, the VCID more
    /// than 3, or the frame length leaves no data octet after header, OCF and FECF or exceeds
    /// [`MAX_FRAME_LEN`].
    pub const fn new(
        frame_len: usize,
        spacecraft_id: u16,
        vcid: u8,
        ocf: bool,
        fecf: bool,
    ) -> Option<TmFrameParams> {
        let overhead =
            PRIMARY_HEADER_LEN + if ocf { OCF_LEN } else { 0 } + if fecf { FECF_LEN } else { 0 };
        if spacecraft_id > MAX_SPACECRAFT_ID
            || vcid > MAX_VCID
            || frame_len <= overhead
            || frame_len > MAX_FRAME_LEN
        {
            return None;
        }
        Some(TmFrameParams {
            frame_len,
            spacecraft_id,
            vcid,
            ocf,
            fecf,
            security: (0, 0),
        })
    }

    /// The same channel with a security header of `header` octets and a trailer of
    /// `trailer` around the packet zone (SDLS, 355.0-B-2 §4.1: `crate::link::sdls` gives the
    /// lengths). `None` when no packet octet would be left.
    pub const fn with_security(self, header: u8, trailer: u8) -> Option<TmFrameParams> {
        if self.data_len() <= header as usize + trailer as usize {
            return None;
        }
        Some(TmFrameParams {
            security: (header, trailer),
            ..self
        })
    }

    /// Octets of the security header and trailer ((0, 0) without SDLS).
    pub const fn security(&self) -> (usize, usize) {
        (self.security.0 as usize, self.security.1 as usize)
    }

    /// Where the packet zone starts: after the primary header and the security header. The
    /// first header pointer counts from here (as YAMCS reads it).
    pub const fn data_start(&self) -> usize {
        PRIMARY_HEADER_LEN + self.security.0 as usize
    }

    /// The mission's (`spec/ccsds/link.toml` `[tm]`) for spacecraft `spacecraft_id`: 256
    /// octets, VC 0, OCF and FECF present; `None` if the ID needs more than 10 bits.
    pub const fn mission(spacecraft_id: u16) -> Option<TmFrameParams> {
        TmFrameParams::new(TM_FRAME_LEN, spacecraft_id, TM_VCID, TM_OCF, TM_FECF)
    }

    /// Octets of every frame.
    pub const fn frame_len(&self) -> usize {
        self.frame_len
    }
    /// The spacecraft ID.
    pub const fn spacecraft_id(&self) -> u16 {
        self.spacecraft_id
    }
    /// The VCID.
    pub const fn vcid(&self) -> u8 {
        self.vcid
    }
    /// Whether frames carry an OCF.
    pub const fn ocf(&self) -> bool {
        self.ocf
    }
    /// Whether frames end with a FECF.
    pub const fn fecf(&self) -> bool {
        self.fecf
    }
    /// Octets of the packet zone: the frame less header, OCF, FECF and SDLS's security header
    /// and MAC (at least 1).
    pub const fn data_len(&self) -> usize {
        self.frame_len
            - PRIMARY_HEADER_LEN
            - if self.ocf { OCF_LEN } else { 0 }
            - if self.fecf { FECF_LEN } else { 0 }
            - self.security.0 as usize
            - self.security.1 as usize
    }
    /// Where the OCF starts (if there is one): right after the data field (the MAC's end).
    pub const fn ocf_start(&self) -> usize {
        self.data_start() + self.data_len() + self.security.1 as usize
    }
}

/// The first header pointer (132.0-B-3 §4.1.2.7.6): where the first packet that starts in
/// this frame's data field starts, or one of the two reserved values.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
#[cfg_attr(feature = "serde", serde(rename_all = "kebab-case"))]
pub enum FirstHeaderPointer {
    /// The first packet header starts at this octet of the data field (0-based).
    Packet(u16),
    /// `0x7FF`: no packet starts in this frame (the data field continues an earlier packet).
    NoPacketStart,
    /// `0x7FE`: the data field holds only idle data.
    OnlyIdleData,
}

impl FirstHeaderPointer {
    /// The 11-bit field's meaning (only its low 11 bits count).
    pub const fn from_field(v: u16) -> FirstHeaderPointer {
        match v & 0x7ff {
            FHP_NO_PACKET_START => FirstHeaderPointer::NoPacketStart,
            FHP_ONLY_IDLE_DATA => FirstHeaderPointer::OnlyIdleData,
            p => FirstHeaderPointer::Packet(p),
        }
    }

    /// The 11-bit field (a `Packet` offset masked to 11 bits).
    pub const fn field(self) -> u16 {
        match self {
            FirstHeaderPointer::Packet(p) => p & 0x7ff,
            FirstHeaderPointer::NoPacketStart => FHP_NO_PACKET_START,
            FirstHeaderPointer::OnlyIdleData => FHP_ONLY_IDLE_DATA,
        }
    }
}

/// Why octets are not a TM transfer frame under the given [`TmFrameParams`]. Each variant
/// names one check; [`TmFrameRepr::parse`] runs them in the order of [`TmFrameError::NAMES`]
/// (the order of the variants) and reports the first that fails:
///
/// 1. `length`: the octets against the fixed frame length;
/// 2. `version` … `ocf-flag`: the header's fields fixed for every frame of the mission;
/// 3. `fecf`: the CRC-16 over the frame (when the FECF is present);
/// 4. `spacecraft-id`, `vcid`: the frame's addressee, against the caller's;
/// 5. `synch-flag` … `segment-length-id`: the data field status says "packets";
/// 6. `first-header-pointer`: inside the data field, or one of its two reserved values.
///
/// As for [`crate::ccsds::PacketError`]: fixed fields before the CRC, so that a frame of
/// another version or layout is refused for what it is; the addressee after the CRC, so that a
/// corrupted ID is reported as corruption and a foreign one only when the frame is intact. The
/// synchronisation flag and its companions come before the first header pointer because they
/// say whether the pointer means anything (with the synch flag set it is undefined, §4.1.2.7.6).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, thiserror::Error)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
#[non_exhaustive]
pub enum TmFrameError {
    /// Not exactly the frame length of the physical channel.
    #[error("TM frame: {found} octets, the frame length is {expected}")]
    Length {
        /// The managed frame length.
        expected: usize,
        /// Octets given.
        found: usize,
    },
    /// Transfer frame version number other than `00`.
    #[error("TM frame: version number must be {expected}, found {found}")]
    Version {
        /// 0.
        expected: u8,
        /// Bits 0–1.
        found: u8,
    },
    /// The secondary header flag is set: the mission's frames have none (decision
    /// `link-tm-frame`), so the data field would start elsewhere.
    #[error("TM frame: secondary header flag set, the mission's frames have no secondary header")]
    SecondaryHeaderFlag,
    /// The OCF flag disagrees with the managed parameter.
    #[error("TM frame: OCF flag must be {expected}, found {found}")]
    OcfFlag {
        /// Whether the channel carries an OCF.
        expected: bool,
        /// Bit 15.
        found: bool,
    },
    /// The FECF disagrees with the CRC of the other octets.
    #[error("TM frame: FECF carried {carried:#06x}, computed {computed:#06x}")]
    Fecf {
        /// The last two octets, big-endian.
        carried: u16,
        /// CRC-16/CCITT-FALSE of the others.
        computed: u16,
    },
    /// Another spacecraft's frame.
    #[error("TM frame: spacecraft ID must be {expected:#05x}, found {found:#05x}")]
    SpacecraftId {
        /// The receiver's spacecraft ID.
        expected: u16,
        /// Bits 2–11.
        found: u16,
    },
    /// Another virtual channel's frame.
    #[error("TM frame: VCID must be {expected}, found {found}")]
    Vcid {
        /// The receiver's VCID.
        expected: u8,
        /// Bits 12–14.
        found: u8,
    },
    /// The synchronisation flag is set: the data field would not be octet-synchronised packets
    /// (VCA service, which the mission does not use).
    #[error("TM frame: synchronisation flag set, the mission's data fields hold packets")]
    SynchFlag,
    /// The packet order flag is set, reserved (0) when the synch flag is 0 (§4.1.2.7.4).
    #[error("TM frame: packet order flag set, reserved when the synchronisation flag is 0")]
    PacketOrderFlag,
    /// Segment length ID other than `11`, required when the synch flag is 0 (§4.1.2.7.5).
    #[error("TM frame: segment length ID must be {expected:#04b}, found {found:#04b}")]
    SegmentLengthId {
        /// `0b11`.
        expected: u8,
        /// Bits 35–36.
        found: u8,
    },
    /// The first header pointer is neither inside the data field nor `0x7FF`/`0x7FE`.
    #[error(
        "TM frame: first header pointer {found:#05x} lies outside the {data_len}-octet data field"
    )]
    FirstHeaderPointer {
        /// Octets of the data field.
        data_len: usize,
        /// Bits 37–47.
        found: u16,
    },
}

impl TmFrameError {
    /// Every check's name, in the order the parser runs them.
    pub const NAMES: [&'static str; 11] = [
        "length",
        "version",
        "secondary-header-flag",
        "ocf-flag",
        "fecf",
        "spacecraft-id",
        "vcid",
        "synch-flag",
        "packet-order-flag",
        "segment-length-id",
        "first-header-pointer",
    ];

    /// The failed check's name (`spec/ccsds/bad-inputs.toml`).
    pub const fn name(&self) -> &'static str {
        Self::NAMES[self.position()]
    }

    /// The failed check's place in the check order (0 = first).
    pub const fn position(&self) -> usize {
        match self {
            TmFrameError::Length { .. } => 0,
            TmFrameError::Version { .. } => 1,
            TmFrameError::SecondaryHeaderFlag => 2,
            TmFrameError::OcfFlag { .. } => 3,
            TmFrameError::Fecf { .. } => 4,
            TmFrameError::SpacecraftId { .. } => 5,
            TmFrameError::Vcid { .. } => 6,
            TmFrameError::SynchFlag => 7,
            TmFrameError::PacketOrderFlag => 8,
            TmFrameError::SegmentLengthId { .. } => 9,
            TmFrameError::FirstHeaderPointer { .. } => 10,
        }
    }
}

/// Why a frame could not be written.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, thiserror::Error)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
#[non_exhaustive]
pub enum TmEmitError {
    /// The caller's buffer is shorter than the frame.
    #[error("the frame needs {expected} octets, the buffer has {found}")]
    BufferTooSmall {
        /// The frame length.
        expected: usize,
        /// The buffer's length.
        found: usize,
    },
    /// The data field is not exactly as long as the parameters make it.
    #[error("the data field must be {expected} octets, found {found}")]
    DataLength {
        /// [`TmFrameParams::data_len`].
        expected: usize,
        /// Octets given.
        found: usize,
    },
    /// An OCF given on a channel without one, or none on a channel with one.
    #[error("the channel's OCF flag is {expected}, the frame has an OCF: {found}")]
    Ocf {
        /// [`TmFrameParams::ocf`].
        expected: bool,
        /// Whether the repr holds an OCF.
        found: bool,
    },
    /// A field whose value its bits cannot carry, or a first header pointer outside the data
    /// field.
    #[error("{field} {found} does not fit (at most {max})")]
    Field {
        /// The field.
        field: &'static str,
        /// Largest value.
        max: u32,
        /// Value given.
        found: u32,
    },
}

/// A frame whose every [`TmFrameError`] check has passed, over its octets.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct TmFrame<'a> {
    bytes: &'a [u8],
    params: TmFrameParams,
}

/// Octet `i` of `b`, 0 past its end (only read after the length check).
fn octet(b: &[u8], i: usize) -> u8 {
    b.get(i).copied().unwrap_or(0)
}

impl<'a> TmFrame<'a> {
    /// Checks `bytes` as one TM frame under `params` (see [`TmFrameError`] for the checks and
    /// their order).
    pub fn new_checked(
        bytes: &'a [u8],
        params: &TmFrameParams,
    ) -> Result<TmFrame<'a>, TmFrameError> {
        let p = *params;
        if bytes.len() != p.frame_len {
            return Err(TmFrameError::Length {
                expected: p.frame_len,
                found: bytes.len(),
            });
        }
        let id = u16::from_be_bytes([octet(bytes, 0), octet(bytes, 1)]);
        let version = (id >> 14) as u8;
        if version != VERSION {
            return Err(TmFrameError::Version {
                expected: VERSION,
                found: version,
            });
        }
        let status = u16::from_be_bytes([octet(bytes, 4), octet(bytes, 5)]);
        if status & 0x8000 != 0 {
            return Err(TmFrameError::SecondaryHeaderFlag);
        }
        let ocf_flag = id & 1 != 0;
        if ocf_flag != p.ocf {
            return Err(TmFrameError::OcfFlag {
                expected: p.ocf,
                found: ocf_flag,
            });
        }
        if p.fecf {
            let (body, fecf) = bytes.split_at(bytes.len().saturating_sub(FECF_LEN));
            let carried = u16::from_be_bytes([octet(fecf, 0), octet(fecf, 1)]);
            let computed = pec(body);
            if carried != computed {
                return Err(TmFrameError::Fecf { carried, computed });
            }
        }
        let spacecraft_id = (id >> 4) & MAX_SPACECRAFT_ID;
        if spacecraft_id != p.spacecraft_id {
            return Err(TmFrameError::SpacecraftId {
                expected: p.spacecraft_id,
                found: spacecraft_id,
            });
        }
        let vcid = ((id >> 1) & 0x7) as u8;
        if vcid != p.vcid {
            return Err(TmFrameError::Vcid {
                expected: p.vcid,
                found: vcid,
            });
        }
        if status & 0x4000 != 0 {
            return Err(TmFrameError::SynchFlag);
        }
        if status & 0x2000 != 0 {
            return Err(TmFrameError::PacketOrderFlag);
        }
        let segment = ((status >> 11) & 0b11) as u8;
        if segment != SEGMENT_LENGTH_ID {
            return Err(TmFrameError::SegmentLengthId {
                expected: SEGMENT_LENGTH_ID,
                found: segment,
            });
        }
        let fhp = status & 0x7ff;
        if fhp as usize >= p.data_len() && fhp != FHP_NO_PACKET_START && fhp != FHP_ONLY_IDLE_DATA {
            return Err(TmFrameError::FirstHeaderPointer {
                data_len: p.data_len(),
                found: fhp,
            });
        }
        Ok(TmFrame { bytes, params: p })
    }

    /// The frame's octets.
    pub fn as_bytes(&self) -> &'a [u8] {
        self.bytes
    }
    fn id(&self) -> u16 {
        u16::from_be_bytes([octet(self.bytes, 0), octet(self.bytes, 1)])
    }
    /// Spacecraft ID (the parameters').
    pub fn spacecraft_id(&self) -> u16 {
        (self.id() >> 4) & MAX_SPACECRAFT_ID
    }
    /// VCID (the parameters').
    pub fn vcid(&self) -> u8 {
        ((self.id() >> 1) & 0x7) as u8
    }
    /// Master channel frame count.
    pub fn mc_frame_count(&self) -> u8 {
        octet(self.bytes, field::MC_FRAME_COUNT)
    }
    /// Virtual channel frame count.
    pub fn vc_frame_count(&self) -> u8 {
        octet(self.bytes, field::VC_FRAME_COUNT)
    }
    /// The first header pointer.
    pub fn first_header_pointer(&self) -> FirstHeaderPointer {
        FirstHeaderPointer::from_field(u16::from_be_bytes([
            octet(self.bytes, 4),
            octet(self.bytes, 5),
        ]))
    }
    /// The data field.
    pub fn data(&self) -> &'a [u8] {
        self.bytes
            .get(self.params.data_start()..self.params.data_start() + self.params.data_len())
            .unwrap_or(&[])
    }
    /// The OCF, when the channel carries one.
    pub fn ocf(&self) -> Option<[u8; OCF_LEN]> {
        if !self.params.ocf {
            return None;
        }
        let s = self.params.ocf_start();
        self.bytes
            .get(s..s + OCF_LEN)
            .and_then(|o| <[u8; OCF_LEN]>::try_from(o).ok())
    }
    /// The frame's fields.
    pub fn repr(&self) -> TmFrameRepr<'a> {
        TmFrameRepr {
            spacecraft_id: self.spacecraft_id(),
            vcid: self.vcid(),
            mc_frame_count: self.mc_frame_count(),
            vc_frame_count: self.vc_frame_count(),
            first_header_pointer: self.first_header_pointer(),
            data: self.data(),
            ocf: self.ocf(),
        }
    }
}

/// A TM frame's fields (the fixed ones, version, flags and segment length ID, are implied).
/// The data field borrows the octets it was parsed from, or the caller's to emit.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
#[cfg_attr(feature = "serde", derive(serde::Serialize))]
pub struct TmFrameRepr<'a> {
    /// Spacecraft ID (10 bits).
    pub spacecraft_id: u16,
    /// Virtual channel ID (3 bits).
    pub vcid: u8,
    /// Master channel frame count.
    pub mc_frame_count: u8,
    /// Virtual channel frame count.
    pub vc_frame_count: u8,
    /// The first header pointer.
    pub first_header_pointer: FirstHeaderPointer,
    /// The data field, exactly [`TmFrameParams::data_len`] octets.
    pub data: &'a [u8],
    /// The OCF (the CLCW), present exactly when the channel carries one.
    pub ocf: Option<[u8; OCF_LEN]>,
}

impl<'a> TmFrameRepr<'a> {
    /// Checks `bytes` (see [`TmFrame::new_checked`]) and returns the fields.
    pub fn parse(bytes: &'a [u8], params: &TmFrameParams) -> Result<TmFrameRepr<'a>, TmFrameError> {
        TmFrame::new_checked(bytes, params).map(|f| f.repr())
    }

    /// Writes the frame into the front of `out`, FECF included (when the channel has one); the
    /// number of octets written, [`TmFrameParams::frame_len`]. The spacecraft ID and VCID are
    /// the repr's (a frame for another receiver can be built; its parser refuses it). Refused
    /// when a field does not fit its bits, the first header pointer lies outside the data
    /// field, the data field's length or the OCF's presence disagree with `params`, or `out`
    /// is too short.
    pub fn emit(&self, params: &TmFrameParams, out: &mut [u8]) -> Result<usize, TmEmitError> {
        let p = params;
        let field = |field, max: u32, found: u32| {
            if found > max {
                Err(TmEmitError::Field { field, max, found })
            } else {
                Ok(())
            }
        };
        field(
            "spacecraft ID",
            MAX_SPACECRAFT_ID as u32,
            self.spacecraft_id as u32,
        )?;
        field("VCID", MAX_VCID as u32, self.vcid as u32)?;
        if let FirstHeaderPointer::Packet(at) = self.first_header_pointer {
            field(
                "first header pointer",
                p.data_len().saturating_sub(1).min(0x7fd) as u32,
                at as u32,
            )?;
        }
        if self.data.len() != p.data_len() {
            return Err(TmEmitError::DataLength {
                expected: p.data_len(),
                found: self.data.len(),
            });
        }
        if self.ocf.is_some() != p.ocf {
            return Err(TmEmitError::Ocf {
                expected: p.ocf,
                found: self.ocf.is_some(),
            });
        }
        let too_small = TmEmitError::BufferTooSmall {
            expected: p.frame_len,
            found: out.len(),
        };
        let frame = out.get_mut(..p.frame_len).ok_or(too_small)?;
        if let Some(d) = frame.get_mut(p.data_start()..p.data_start() + p.data_len()) {
            d.copy_from_slice(self.data);
        }
        self.seal(p, frame);
        Ok(p.frame_len)
    }

    /// Writes header, OCF and FECF around the data field already in `frame` (exactly
    /// `p.frame_len` octets; the fields already checked): what [`TmFrameRepr::emit`] and the
    /// framer, which builds the data field in place, share. `self.data` is not read.
    pub(crate) fn seal(&self, p: &TmFrameParams, frame: &mut [u8]) {
        let id = ((VERSION as u16) << 14)
            | ((self.spacecraft_id & MAX_SPACECRAFT_ID) << 4)
            | (((self.vcid & MAX_VCID) as u16) << 1)
            | p.ocf as u16;
        let status = ((SEGMENT_LENGTH_ID as u16) << 11) | self.first_header_pointer.field();
        let [i0, i1] = id.to_be_bytes();
        let [s0, s1] = status.to_be_bytes();
        let header = [i0, i1, self.mc_frame_count, self.vc_frame_count, s0, s1];
        if let Some(h) = frame.get_mut(..PRIMARY_HEADER_LEN) {
            h.copy_from_slice(&header);
        }
        if let Some(ocf) = self.ocf {
            let s = p.ocf_start();
            if let Some(o) = frame.get_mut(s..s + OCF_LEN) {
                o.copy_from_slice(&ocf);
            }
        }
        if p.fecf {
            let body_len = p.frame_len - FECF_LEN;
            let crc = pec(frame.get(..body_len).unwrap_or(&[]));
            if let Some(f) = frame.get_mut(body_len..p.frame_len) {
                f.copy_from_slice(&crc.to_be_bytes());
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn params_refuse_what_no_frame_has() {
        assert!(TmFrameParams::new(13, 1, 0, true, true).is_some());
        assert!(TmFrameParams::new(12, 1, 0, true, true).is_none());
        assert!(TmFrameParams::new(7, 1, 0, false, false).is_some());
        assert!(TmFrameParams::new(6, 1, 0, false, false).is_none());
        assert!(TmFrameParams::new(2049, 1, 0, false, false).is_none());
        assert!(TmFrameParams::new(256, 0x400, 0, false, false).is_none());
        assert!(TmFrameParams::new(256, 1, 8, false, false).is_none());
        assert_eq!(
            TmFrameParams::mission(0x142).map(|p| p.data_len()),
            Some(244)
        );
    }

    #[test]
    fn fhp_field_round_trips() {
        for v in 0..=0x7ffu16 {
            assert_eq!(FirstHeaderPointer::from_field(v).field(), v);
        }
    }
}
