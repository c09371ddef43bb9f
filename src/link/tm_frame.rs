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

mod error;
mod repr;
mod view;

pub use error::{TmEmitError, TmFrameError};
pub use repr::TmFrameRepr;
pub use view::TmFrame;

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
        let overhead = overhead(ocf, fecf);
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
    pub fn with_security(self, header: u8, trailer: u8) -> Option<TmFrameParams> {
        if self.data_len() <= usize::from(header).saturating_add(usize::from(trailer)) {
            return None;
        }
        Some(TmFrameParams {
            security: (header, trailer),
            ..self
        })
    }

    /// Octets of the security header and trailer ((0, 0) without SDLS).
    pub fn security(&self) -> (usize, usize) {
        (usize::from(self.security.0), usize::from(self.security.1))
    }

    /// Where the packet zone starts: after the primary header and the security header. The
    /// first header pointer counts from here (as YAMCS reads it).
    pub fn data_start(&self) -> usize {
        PRIMARY_HEADER_LEN.saturating_add(usize::from(self.security.0))
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
    pub fn data_len(&self) -> usize {
        // `new` and `with_security` refuse parameters that leave no data octet: no step
        // saturates.
        self.frame_len
            .saturating_sub(overhead(self.ocf, self.fecf))
            .saturating_sub(usize::from(self.security.0))
            .saturating_sub(usize::from(self.security.1))
    }
    /// Where the packet zone lies in a frame: `data_start()` and `data_len()` octets on.
    pub fn data_range(&self) -> core::ops::Range<usize> {
        let start = self.data_start();
        // Within the frame (a few hundred octets): the sum cannot saturate.
        start..start.saturating_add(self.data_len())
    }
    /// Where the OCF starts (if there is one): right after the data field (the MAC's end).
    pub fn ocf_start(&self) -> usize {
        // At most the frame's length (the parts of a frame, a few hundred octets).
        self.data_start()
            .saturating_add(self.data_len())
            .saturating_add(usize::from(self.security.1))
    }
}

/// The octets of a frame outside its data field and SDLS: primary header, OCF, FECF.
const fn overhead(ocf: bool, fecf: bool) -> usize {
    match (ocf, fecf) {
        (false, false) => PRIMARY_HEADER_LEN,
        (true, false) => PRIMARY_HEADER_LEN + OCF_LEN,
        (false, true) => PRIMARY_HEADER_LEN + FECF_LEN,
        (true, true) => PRIMARY_HEADER_LEN + OCF_LEN + FECF_LEN,
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

    /// Room for SDLS: a security header and trailer that leave no packet octet are refused;
    /// otherwise the packet zone shrinks by both and `security` gives them back.
    #[test]
    fn security_leaves_a_packet_octet_or_is_refused() {
        let p = TmFrameParams::new(64, 1, 0, true, true).unwrap();
        let n = p.data_len();
        assert_eq!(p.security(), (0, 0));
        let s = p.with_security(14, 16).unwrap();
        assert_eq!((s.security(), s.data_len()), ((14, 16), n - 30));
        let whole = u8::try_from(n).unwrap();
        assert!(p.with_security(whole - 16, 16).is_none());
        assert!(p.with_security(whole - 17, 16).is_some());
    }
}
