//! The PUS-C telecommand secondary header (ECSS-E-ST-70-41C §7.4.3.1), five octets:
//!
//! | octet | bits | field |
//! |---|---|---|
//! | 0 | 0–3 | TC packet PUS version number: 2 (PUS-C) |
//! | 0 | 4–7 | acknowledgement flags ([`AckFlags`]) |
//! | 1 | | service type ID |
//! | 2 | | message subtype ID |
//! | 3–4 | | source ID (the ground application that sent it) |
//!
//! No spare field: the standard leaves its length to the mission, and this mission has none.
//!
//! ```
//! use mmic::ccsds::tc_header::{AckFlags, TcSecondaryHeader};
//!
//! // TC(17,1) are-you-alive, every report requested, from source 0x0102.
//! let h = TcSecondaryHeader { ack: AckFlags::ALL, service: 17, subservice: 1, source_id: 0x0102 };
//! assert_eq!(h.to_bytes(), [0x2f, 17, 1, 0x01, 0x02]);
//! ```

use super::PUS_VERSION;
use zerocopy::byteorder::big_endian::U16;
use zerocopy::{FromBytes, Immutable, IntoBytes, KnownLayout, Unaligned};

/// Octets in the TC secondary header.
pub const TC_SECONDARY_LEN: usize = 5;

/// The TC secondary header, byte for byte.
#[derive(
    Debug, Clone, Copy, PartialEq, Eq, Hash, FromBytes, IntoBytes, KnownLayout, Immutable, Unaligned,
)]
#[repr(C)]
pub struct TcSecondaryLayout {
    /// PUS version (high nibble), acknowledgement flags (low nibble).
    pub version_ack: u8,
    /// Service type ID.
    pub service: u8,
    /// Message subtype ID.
    pub subservice: u8,
    /// Source ID.
    pub source_id: U16,
}

const _: () = assert!(core::mem::size_of::<TcSecondaryLayout>() == TC_SECONDARY_LEN);

/// Which ST\[1\] verification reports the sender asks for. The low nibble of octet 0, with the
/// standard's bit numbering (bit 0 = most significant): bit 3, the least significant, asks for
/// the acceptance report, bit 0 for the completion report, so acceptance alone is `0b0001`.
/// The Python `spacepackets` package and the Flight Software Framework use the same values;
/// the Rust `spacepackets` 0.19 names the bits the other way round (its `acceptance` is
/// `0b1000`), which `tests/ccsds/interop_spacepackets.rs` measures.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Default)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
#[cfg_attr(feature = "serde", serde(deny_unknown_fields))]
pub struct AckFlags {
    /// Successful acceptance must be reported (`0b0001`).
    pub acceptance: bool,
    /// Successful start of execution must be reported (`0b0010`).
    pub start: bool,
    /// Successful progress of execution must be reported (`0b0100`).
    pub progress: bool,
    /// Successful completion of execution must be reported (`0b1000`).
    pub completion: bool,
}

impl AckFlags {
    /// No success reports (failures are always reported).
    pub const NONE: AckFlags = AckFlags::from_bits(0);
    /// Every success report.
    pub const ALL: AckFlags = AckFlags::from_bits(0b1111);

    /// The flags of the low nibble of `bits` (the high nibble is ignored).
    pub const fn from_bits(bits: u8) -> AckFlags {
        AckFlags {
            acceptance: bits & 0b0001 != 0,
            start: bits & 0b0010 != 0,
            progress: bits & 0b0100 != 0,
            completion: bits & 0b1000 != 0,
        }
    }

    /// The nibble.
    pub const fn bits(self) -> u8 {
        // `if`, not `u8::from(bool)`: that is not `const`.
        const fn bit(set: bool, value: u8) -> u8 {
            if set {
                value
            } else {
                0
            }
        }
        bit(self.acceptance, 0b0001)
            | bit(self.start, 0b0010)
            | bit(self.progress, 0b0100)
            | bit(self.completion, 0b1000)
    }
}

/// The TC secondary header's fields (the PUS version is not one: it is always 2, and
/// [`crate::ccsds::tc`] refuses any other).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Default)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
#[cfg_attr(feature = "serde", serde(deny_unknown_fields))]
pub struct TcSecondaryHeader {
    /// Verification reports requested.
    pub ack: AckFlags,
    /// Service type ID.
    pub service: u8,
    /// Message subtype ID.
    pub subservice: u8,
    /// Source ID.
    pub source_id: u16,
}

impl TcSecondaryHeader {
    /// The five octets, PUS version 2.
    pub fn to_bytes(&self) -> [u8; TC_SECONDARY_LEN] {
        let mut out = [0u8; TC_SECONDARY_LEN];
        out.copy_from_slice(TcSecondaryLayout::from(self).as_bytes());
        out
    }
}

impl TcSecondaryLayout {
    /// The PUS version number (high nibble of octet 0).
    pub const fn pus_version(&self) -> u8 {
        self.version_ack >> 4
    }
}

impl From<&TcSecondaryLayout> for TcSecondaryHeader {
    #[inline]
    fn from(l: &TcSecondaryLayout) -> TcSecondaryHeader {
        TcSecondaryHeader {
            ack: AckFlags::from_bits(l.version_ack),
            service: l.service,
            subservice: l.subservice,
            source_id: l.source_id.get(),
        }
    }
}

impl From<&TcSecondaryHeader> for TcSecondaryLayout {
    fn from(h: &TcSecondaryHeader) -> TcSecondaryLayout {
        TcSecondaryLayout {
            version_ack: PUS_VERSION << 4 | h.ack.bits(),
            service: h.service,
            subservice: h.subservice,
            source_id: U16::new(h.source_id),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    // req: PUS/tc-ack-flags
    #[test]
    fn ack_flags_take_the_standards_bit_order() {
        for bits in 0..16u8 {
            assert_eq!(AckFlags::from_bits(bits).bits(), bits);
        }
        let acceptance_only = AckFlags {
            acceptance: true,
            ..AckFlags::NONE
        };
        assert_eq!(acceptance_only.bits(), 0b0001);
        let completion_only = AckFlags {
            completion: true,
            ..AckFlags::NONE
        };
        assert_eq!(completion_only.bits(), 0b1000);
    }

    #[test]
    fn header_octets() {
        let h = TcSecondaryHeader {
            ack: AckFlags::from_bits(0b1001),
            service: 8,
            subservice: 1,
            source_id: 0xbeef,
        };
        let b = h.to_bytes();
        assert_eq!(b, [0x29, 8, 1, 0xbe, 0xef]);
        let l = TcSecondaryLayout::ref_from_bytes(&b[..]).ok();
        assert_eq!(l.map(TcSecondaryHeader::from), Some(h));
        assert_eq!(l.map(TcSecondaryLayout::pus_version), Some(2));
    }
}
