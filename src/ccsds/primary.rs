//! The space packet primary header (CCSDS 133.0-B-2 §4.1.3), six octets, big-endian:
//!
//! | bits | field | here |
//! |---|---|---|
//! | 0–2 | packet version number | always 0 (version 1 packets) |
//! | 3 | packet type | 0 telemetry, 1 telecommand |
//! | 4 | secondary header flag | always 1 (every PUS packet has one) |
//! | 5–15 | APID | [`Apid`], 11 bits |
//! | 16–17 | sequence flags | always `0b11`, unsegmented |
//! | 18–31 | packet sequence count | [`SeqCount`], 14 bits |
//! | 32–47 | packet data length | octets after the primary header, minus 1 |
//!
//! [`PrimaryHeader`] is the header as it lies in the bytes, every field decoded but none
//! judged, so that the checks in [`crate::ccsds`] can report what they found.
//!
//! ```
//! use mmic::ccsds::primary::{PrimaryHeader, PacketType, PRIMARY_LEN};
//!
//! // TC, APID 0x042, unsegmented, count 7, 13 octets in all (data length 13 - 7 = 6).
//! let h = PrimaryHeader::read(&[0x18, 0x42, 0xc0, 0x07, 0x00, 0x06]).unwrap();
//! assert_eq!((h.packet_type, h.apid, h.seq_count, h.total_len()), (PacketType::Tc, 0x42, 7, 13));
//! assert_eq!(h.to_bytes(), [0x18, 0x42, 0xc0, 0x07, 0x00, 0x06]);
//! # assert_eq!(PRIMARY_LEN, 6);
//! ```

use super::bit_field::bit_field;
use crate::wire_enum::wire_enum;
use core::fmt;
use zerocopy::byteorder::big_endian::U16;
use zerocopy::{FromBytes, Immutable, IntoBytes, KnownLayout, Unaligned};

/// Octets in the primary header.
pub const PRIMARY_LEN: usize = 6;
/// The only packet version number CCSDS 133.0-B-2 defines (`000`, "version 1").
pub const VERSION: u8 = 0;
/// Sequence flags of an unsegmented user data packet: the only kind PUS uses.
pub const UNSEGMENTED: u8 = 0b11;

/// The primary header, byte for byte (big-endian).
#[derive(
    Debug, Clone, Copy, PartialEq, Eq, Hash, FromBytes, IntoBytes, KnownLayout, Immutable, Unaligned,
)]
#[repr(C)]
pub struct PrimaryLayout {
    /// Octets 0–1: version (3 bits), type, secondary header flag, APID (11 bits).
    pub packet_id: U16,
    /// Octets 2–3: sequence flags (2 bits), sequence count (14 bits).
    pub sequence: U16,
    /// Octets 4–5: octets in the packet data field minus 1.
    pub data_length: U16,
}

const _: () = assert!(core::mem::size_of::<PrimaryLayout>() == PRIMARY_LEN);

/// Byte ranges of the primary header, from the layout.
pub mod field {
    use super::*;
    use crate::wire::layout::span;
    use core::ops::Range;
    /// Version, type, secondary header flag, APID.
    pub const PACKET_ID: Range<usize> = span!(PrimaryLayout, packet_id, U16);
    /// Sequence flags and count.
    pub const SEQUENCE: Range<usize> = span!(PrimaryLayout, sequence, U16);
    /// Packet data length.
    pub const DATA_LENGTH: Range<usize> = span!(PrimaryLayout, data_length, U16);
}

wire_enum! {
    /// Telemetry (0) or telecommand (1): bit 3 of the header.
    #[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord)]
    #[cfg_attr(feature = "defmt", derive(defmt::Format))]
    #[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
    #[cfg_attr(feature = "serde", serde(rename_all = "lowercase"))]
    pub enum PacketType: u8 {
        /// Telemetry: robot → ground.
        Tm = 0,
        /// Telecommand: ground → robot.
        Tc = 1,
    }

    /// The type's bit: 0 or 1.
    pub const fn bit(self) -> u8;
}

impl PacketType {
    /// The type whose bit is `bit` (only its lowest bit counts).
    pub const fn from_bit(bit: u8) -> PacketType {
        if bit & 1 == 0 {
            PacketType::Tm
        } else {
            PacketType::Tc
        }
    }
}

impl fmt::Display for PacketType {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(match self {
            PacketType::Tm => "TM",
            PacketType::Tc => "TC",
        })
    }
}

bit_field! {
    /// Application process identifier, 11 bits (0..=2047). 2047 (`0x7ff`) is the idle packets'
    /// APID; which APIDs the robot uses is the services layer's plan, handed to the parsers as
    /// the set they accept.
    Apid(u16), max 0x7ff, "APID"
}

bit_field! {
    /// Packet sequence count, 14 bits (0..=16383), counted per APID and wrapping.
    SeqCount(u16), max 0x3fff, "packet sequence count"
}

impl SeqCount {
    /// The next count, wrapping from 16383 to 0 as CCSDS 133.0-B-2 §4.1.3.4.2.3 says.
    pub const fn wrapping_next(self) -> SeqCount {
        // Modulo 2¹⁴, the standard's count: the wrap is meant.
        SeqCount(self.0.wrapping_add(1) & 0x3fff)
    }
}

/// The primary header's fields as they lie in the bytes, decoded but not judged.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct PrimaryHeader {
    /// Packet version number (3 bits).
    pub version: u8,
    /// Type bit.
    pub packet_type: PacketType,
    /// Secondary header flag.
    pub secondary_header: bool,
    /// APID (11 bits).
    pub apid: u16,
    /// Sequence flags (2 bits).
    pub seq_flags: u8,
    /// Sequence count (14 bits).
    pub seq_count: u16,
    /// Packet data length field: octets after the primary header minus 1.
    pub data_length: u16,
}

impl PrimaryHeader {
    /// The header of a PUS packet: version 0, secondary header, unsegmented, `total_len`
    /// octets in all (`total_len` must lie in `7..=65542`; the packet builders check that).
    pub(crate) const fn pus(
        packet_type: PacketType,
        apid: Apid,
        seq_count: SeqCount,
        total_len: usize,
    ) -> PrimaryHeader {
        PrimaryHeader {
            version: VERSION,
            packet_type,
            secondary_header: true,
            apid: apid.get(),
            seq_flags: UNSEGMENTED,
            seq_count: seq_count.get(),
            data_length: data_length_of(total_len),
        }
    }

    /// The packet's total length in octets as the data length field says:
    /// `data_length + 7` (the field counts the data field's octets minus one).
    pub fn total_len(&self) -> usize {
        // At most 65,542: never saturates.
        usize::from(self.data_length).saturating_add(PRIMARY_LEN + 1)
    }

    /// Decodes the first six octets of `bytes`; `None` if there are fewer.
    #[inline]
    pub fn read(bytes: &[u8]) -> Option<PrimaryHeader> {
        let (l, _) = PrimaryLayout::ref_from_prefix(bytes).ok()?;
        Some(PrimaryHeader::from(l))
    }

    /// The six octets (fields wider than their bits are masked).
    pub fn to_bytes(&self) -> [u8; PRIMARY_LEN] {
        let mut out = [0u8; PRIMARY_LEN];
        self.write(&mut out);
        out
    }

    /// Writes the six octets into `out`.
    pub fn write(&self, out: &mut [u8; PRIMARY_LEN]) {
        let l = PrimaryLayout::from(self);
        out.copy_from_slice(l.as_bytes());
    }
}

/// The data length field of a packet of `total_len` octets: its low 16 bits, `total_len`
/// lying in `7..=65542` (the packet builders check that; `From` and `TryFrom` are not `const`).
const fn data_length_of(total_len: usize) -> u16 {
    let [lo, hi, ..] = total_len.saturating_sub(PRIMARY_LEN + 1).to_le_bytes();
    u16::from_le_bytes([lo, hi])
}

impl From<&PrimaryLayout> for PrimaryHeader {
    #[inline]
    fn from(l: &PrimaryLayout) -> PrimaryHeader {
        let id = l.packet_id.get();
        let seq = l.sequence.get();
        let [id_hi, _] = id.to_be_bytes();
        let [seq_hi, _] = seq.to_be_bytes();
        PrimaryHeader {
            version: id_hi >> 5,
            packet_type: PacketType::from_bit(id_hi >> 4),
            secondary_header: id & 0x0800 != 0,
            apid: id & 0x07ff,
            seq_flags: seq_hi >> 6,
            seq_count: seq & 0x3fff,
            data_length: l.data_length.get(),
        }
    }
}

impl From<&PrimaryHeader> for PrimaryLayout {
    fn from(h: &PrimaryHeader) -> PrimaryLayout {
        let id = ((u16::from(h.version) & 0b111) << 13)
            | (u16::from(h.packet_type.bit()) << 12)
            | (u16::from(h.secondary_header) << 11)
            | (h.apid & 0x07ff);
        let seq = ((u16::from(h.seq_flags) & 0b11) << 14) | (h.seq_count & 0x3fff);
        PrimaryLayout {
            packet_id: U16::new(id),
            sequence: U16::new(seq),
            data_length: U16::new(h.data_length),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    // req: 133.0-B-2/SPP-3, 133.0-B-2/SPP-15
    #[test]
    fn every_field_lands_on_its_bits() {
        // All ones in each field in turn, against the bit positions of 133.0-B-2 §4.1.3.
        let zero = PrimaryHeader {
            version: 0,
            packet_type: PacketType::Tm,
            secondary_header: false,
            apid: 0,
            seq_flags: 0,
            seq_count: 0,
            data_length: 0,
        };
        let cases: [(PrimaryHeader, [u8; 6]); 7] = [
            (PrimaryHeader { version: 7, ..zero }, [0xe0, 0, 0, 0, 0, 0]),
            (
                PrimaryHeader {
                    packet_type: PacketType::Tc,
                    ..zero
                },
                [0x10, 0, 0, 0, 0, 0],
            ),
            (
                PrimaryHeader {
                    secondary_header: true,
                    ..zero
                },
                [0x08, 0, 0, 0, 0, 0],
            ),
            (
                PrimaryHeader {
                    apid: 0x7ff,
                    ..zero
                },
                [0x07, 0xff, 0, 0, 0, 0],
            ),
            (
                PrimaryHeader {
                    seq_flags: 3,
                    ..zero
                },
                [0, 0, 0xc0, 0, 0, 0],
            ),
            (
                PrimaryHeader {
                    seq_count: 0x3fff,
                    ..zero
                },
                [0, 0, 0x3f, 0xff, 0, 0],
            ),
            (
                PrimaryHeader {
                    data_length: 0xfffe,
                    ..zero
                },
                [0, 0, 0, 0, 0xff, 0xfe],
            ),
        ];
        for (h, bytes) in cases {
            assert_eq!(h.to_bytes(), bytes, "{h:?}");
            assert_eq!(PrimaryHeader::read(&bytes), Some(h));
        }
        assert_eq!(PrimaryHeader::read(&[0; 5]), None);
    }

    #[test]
    fn ranged_fields_refuse_what_their_bits_cannot_carry() {
        assert_eq!(Apid::new(0x7ff).map(Apid::get), Ok(0x7ff));
        assert_eq!(Apid::new(0x800).map_err(|e| e.found), Err(0x800));
        assert_eq!(SeqCount::new(0x4000).map_err(|e| e.max), Err(0x3fff));
        assert_eq!(SeqCount::MAX.wrapping_next(), SeqCount::default());
        assert_eq!(
            SeqCount::new(5).map(SeqCount::wrapping_next),
            SeqCount::new(6)
        );
    }
}
