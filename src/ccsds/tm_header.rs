//! The PUS-C telemetry secondary header (ECSS-E-ST-70-41C §7.4.3.2), 13 octets here:
//!
//! | octet | bits | field |
//! |---|---|---|
//! | 0 | 0–3 | TM packet PUS version number: 2 (PUS-C) |
//! | 0 | 4–7 | spacecraft time reference status ([`TimeRefStatus`]) |
//! | 1 | | service type ID |
//! | 2 | | message subtype ID |
//! | 3–4 | | message type counter (per APID and message type) |
//! | 5–6 | | destination ID |
//! | 7–12 | | time: CUC, 4 + 2 octets ([`crate::ccsds::cuc`]) |
//!
//! No spare field (this mission has none).
//!
//! ```
//! use mmic::ccsds::cuc::Cuc;
//! use mmic::ccsds::tm_header::{TimeRefStatus, TmSecondaryHeader};
//!
//! // TM(17,2) I-am-alive, third of its kind, to destination 0x0102, at 1.5 s.
//! let h = TmSecondaryHeader {
//!     time_ref_status: TimeRefStatus::default(),
//!     service: 17,
//!     subservice: 2,
//!     counter: 3,
//!     destination_id: 0x0102,
//!     time: Cuc::from_millis(1500),
//! };
//! assert_eq!(h.to_bytes(), [0x20, 17, 2, 0, 3, 1, 2, 0, 0, 0, 1, 0x80, 0]);
//! ```

use super::bit_field::bit_field;
use super::cuc::{Cuc, CucLayout};
use super::PUS_VERSION;
use zerocopy::byteorder::big_endian::U16;
use zerocopy::{FromBytes, Immutable, IntoBytes, KnownLayout, Unaligned};

/// Octets in the TM secondary header, time field included.
pub const TM_SECONDARY_LEN: usize = 13;

/// The TM secondary header, byte for byte.
#[derive(
    Debug, Clone, Copy, PartialEq, Eq, Hash, FromBytes, IntoBytes, KnownLayout, Immutable, Unaligned,
)]
#[repr(C)]
pub struct TmSecondaryLayout {
    /// PUS version (high nibble), spacecraft time reference status (low nibble).
    pub version_time_ref: u8,
    /// Service type ID.
    pub service: u8,
    /// Message subtype ID.
    pub subservice: u8,
    /// Message type counter.
    pub counter: U16,
    /// Destination ID.
    pub destination_id: U16,
    /// Time (CUC).
    pub time: CucLayout,
}

const _: () = assert!(core::mem::size_of::<TmSecondaryLayout>() == TM_SECONDARY_LEN);

bit_field! {
    /// Spacecraft time reference status, 4 bits: the standard leaves the values to the
    /// mission (ECSS-E-ST-70-41C §7.4.3.2); this robot sends 0 (no time reference services).
    TimeRefStatus(u8), max 0xf, "spacecraft time reference status"
}

/// The TM secondary header's fields (the PUS version is not one: it is always 2, and
/// [`crate::ccsds::tm`] refuses any other).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Default)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
#[cfg_attr(feature = "serde", serde(deny_unknown_fields))]
pub struct TmSecondaryHeader {
    /// Spacecraft time reference status.
    pub time_ref_status: TimeRefStatus,
    /// Service type ID.
    pub service: u8,
    /// Message subtype ID.
    pub subservice: u8,
    /// Message type counter.
    pub counter: u16,
    /// Destination ID.
    pub destination_id: u16,
    /// When the packet was made, since its maker's power-on (the gateway's).
    pub time: Cuc,
}

impl TmSecondaryHeader {
    /// The 13 octets, PUS version 2.
    pub fn to_bytes(&self) -> [u8; TM_SECONDARY_LEN] {
        let mut out = [0u8; TM_SECONDARY_LEN];
        out.copy_from_slice(TmSecondaryLayout::from(self).as_bytes());
        out
    }
}

impl TmSecondaryLayout {
    /// The PUS version number (high nibble of octet 0).
    pub const fn pus_version(&self) -> u8 {
        self.version_time_ref >> 4
    }
}

impl From<&TmSecondaryLayout> for TmSecondaryHeader {
    fn from(l: &TmSecondaryLayout) -> TmSecondaryHeader {
        TmSecondaryHeader {
            time_ref_status: TimeRefStatus::masked(l.version_time_ref),
            service: l.service,
            subservice: l.subservice,
            counter: l.counter.get(),
            destination_id: l.destination_id.get(),
            time: Cuc::from(&l.time),
        }
    }
}

impl From<&TmSecondaryHeader> for TmSecondaryLayout {
    fn from(h: &TmSecondaryHeader) -> TmSecondaryLayout {
        TmSecondaryLayout {
            version_time_ref: PUS_VERSION << 4 | h.time_ref_status.get(),
            service: h.service,
            subservice: h.subservice,
            counter: U16::new(h.counter),
            destination_id: U16::new(h.destination_id),
            time: CucLayout::from(h.time),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn header_octets() {
        let h = TmSecondaryHeader {
            time_ref_status: TimeRefStatus::MAX,
            service: 3,
            subservice: 25,
            counter: 0xfffe,
            destination_id: 0x0a0b,
            time: Cuc {
                coarse: 0x0102_0304,
                fine: 0x0506,
            },
        };
        let b = h.to_bytes();
        assert_eq!(b, [0x2f, 3, 25, 0xff, 0xfe, 0x0a, 0x0b, 1, 2, 3, 4, 5, 6]);
        let l = TmSecondaryLayout::ref_from_bytes(&b[..]).ok();
        assert_eq!(l.map(TmSecondaryHeader::from), Some(h));
        assert_eq!(l.map(TmSecondaryLayout::pus_version), Some(2));
    }
}
