//! The fixed PDU header of CCSDS 727.0-B-5 §5.1: four octets, then the source entity ID, the
//! transaction sequence number and the destination entity ID, each 1 to 8 octets long as
//! octet 3 says, all big-endian.
//!
//! | bits | field | here |
//! |---|---|---|
//! | 0–2 | version | `001` emitted; `000` (YAMCS 5.12.8 sends it) and `001` read |
//! | 3 | PDU type | [`PduType`]: 0 file directive, 1 file data |
//! | 4 | direction | [`Direction`]: 0 toward the receiver, 1 toward the sender |
//! | 5 | transmission mode | [`Mode`]: 0 acknowledged (class 2), 1 unacknowledged (class 1) |
//! | 6 | CRC flag | a CRC-16 ends the data field ([`crate::cfdp::pdu_crc`]) |
//! | 7 | large file flag | refused: file sizes and offsets are 32 bits here |
//! | 8–23 | PDU data field length | octets after the header, the CRC included |
//! | 24 | segmentation control | kept as read (record boundaries: no meaning in class 1/2 files) |
//! | 25–27 | length of entity IDs − 1 | [`Lengths::entity`] |
//! | 28 | segment metadata flag | refused: no segment metadata here |
//! | 29–31 | length of the sequence number − 1 | [`Lengths::seq`] |
//!
//! ```
//! use mmic::cfdp::header::{Direction, Lengths, Mode, PduHeader, PduType};
//!
//! // YAMCS's EOF of PacketParseTest: entity 0x18 to 0x15, transaction 1, 10 octets of data.
//! let bytes = [0x00, 0x00, 0x0a, 0x13, 0x00, 0x18, 0x00, 0x00, 0x00, 0x01, 0x00, 0x15];
//! let (h, len) = PduHeader::parse(&bytes).unwrap();
//! assert_eq!((h.pdu_type, h.direction, h.mode), (PduType::Directive, Direction::TowardReceiver, Mode::Acknowledged));
//! assert_eq!((h.lengths, h.source, h.seq, h.dest, h.data_len), (Lengths::MISSION, 0x18, 1, 0x15, 10));
//! assert_eq!(len, 12);
//! let mut out = [0u8; 12];
//! assert_eq!(h.emit(&mut out), Ok(12));
//! assert_eq!(out[0], 0x20); // version 001
//! assert_eq!(out[1..], bytes[1..]);
//! ```

use super::error::PduError;
pub use super::flags::{Direction, Mode, PduType};

/// The version this library emits (`001`, 727.0-B-5 §5.1.1).
pub const VERSION: u8 = 1;
/// The versions it reads: `000` (YAMCS 5.12.8 writes it, 727.0-B-3's) and `001`.
pub const VERSIONS_READ: [u8; 2] = [0, 1];
/// Octets before the variable fields.
pub const FIXED_LEN: usize = 4;

/// The octets of the entity IDs and of the transaction sequence number, 1 to 8 each.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
#[cfg_attr(feature = "serde", derive(serde::Serialize))]
pub struct Lengths {
    /// Octets of each entity ID.
    pub entity: u8,
    /// Octets of the transaction sequence number.
    pub seq: u8,
}

impl Lengths {
    /// The mission's: 2-octet entity IDs, 4-octet sequence numbers (YAMCS's defaults,
    /// `entityIdLength` and `sequenceNrLength`; `spec/ccsds/cfdp.toml`).
    pub const MISSION: Lengths = Lengths { entity: 2, seq: 4 };

    /// Octets of the whole header with these lengths.
    pub fn header_len(self) -> usize {
        let e = usize_of(self.entity);
        FIXED_LEN
            .saturating_add(e)
            .saturating_add(e)
            .saturating_add(usize_of(self.seq))
    }

    /// Whether both lie in 1..=8.
    const fn valid(self) -> bool {
        matches!(self.entity, 1..=8) && matches!(self.seq, 1..=8)
    }
}

/// A PDU's fixed header, every field decoded.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
#[cfg_attr(feature = "serde", derive(serde::Serialize))]
pub struct PduHeader {
    /// Directive or file data.
    pub pdu_type: PduType,
    /// Toward the receiver or the sender.
    pub direction: Direction,
    /// Class 2 or class 1.
    pub mode: TransmissionMode,
    /// A CRC-16 ends the data field.
    pub crc: bool,
    /// Segmentation control: record boundaries preserved (file data only).
    pub segmentation: bool,
    /// Octets of the IDs and the sequence number.
    pub lengths: Lengths,
    /// Octets after the header, the CRC included.
    pub data_len: u16,
    /// Source entity ID.
    pub source: u64,
    /// Transaction sequence number.
    pub seq: u64,
    /// Destination entity ID.
    pub dest: u64,
}

/// The transmission mode (the name the standard gives the field).
pub use Mode as TransmissionMode;

impl PduHeader {
    /// Reads the header at the start of `bytes`: the header and its length. Checks, in this
    /// order: four octets (`truncated`), the version, the large file and segment metadata flags
    /// (not supported here), the lengths' own octets (`truncated`). The data field is the
    /// PDU's ([`crate::cfdp::Pdu`]).
    pub fn parse(bytes: &[u8]) -> Result<(PduHeader, usize), PduError> {
        let Some(&[b0, l0, l1, b3]) = bytes.first_chunk::<FIXED_LEN>() else {
            return Err(PduError::Truncated {
                expected: FIXED_LEN,
                found: bytes.len(),
            });
        };
        let version = b0 >> 5;
        if !(version == VERSIONS_READ[0] || version == VERSIONS_READ[1]) {
            return Err(PduError::Version { found: version });
        }
        if b0 & 0x01 != 0 {
            return Err(PduError::LargeFile);
        }
        if b3 & 0x08 != 0 {
            return Err(PduError::SegmentMetadata);
        }
        // Three bits each, plus one: 1..=8, never out of range.
        let lengths = Lengths {
            entity: ((b3 >> 4) & 0x07).saturating_add(1),
            seq: (b3 & 0x07).saturating_add(1),
        };
        let len = lengths.header_len();
        let var = bytes.get(FIXED_LEN..len).ok_or(PduError::Truncated {
            expected: len,
            found: bytes.len(),
        })?;
        let (source, rest) = var.split_at(usize_of(lengths.entity));
        let (seq, dest) = rest.split_at(usize_of(lengths.seq));
        let h = PduHeader {
            pdu_type: if b0 & 0x10 == 0 {
                PduType::Directive
            } else {
                PduType::FileData
            },
            direction: if b0 & 0x08 == 0 {
                Direction::TowardReceiver
            } else {
                Direction::TowardSender
            },
            mode: if b0 & 0x04 == 0 {
                Mode::Acknowledged
            } else {
                Mode::Unacknowledged
            },
            crc: b0 & 0x02 != 0,
            segmentation: b3 & 0x80 != 0,
            lengths,
            data_len: u16::from_be_bytes([l0, l1]),
            source: be(source),
            seq: be(seq),
            dest: be(dest),
        };
        Ok((h, len))
    }

    /// Octets of this header.
    pub fn len(&self) -> usize {
        self.lengths.header_len()
    }

    /// Always false: a header has its four fixed octets at least (for clippy's
    /// `len_without_is_empty`).
    pub const fn is_empty(&self) -> bool {
        false
    }

    /// Writes the header into `out`: its length. Refused: lengths outside 1..=8, or an ID or
    /// sequence number too large for its length, or an `out` too short.
    pub fn emit(&self, out: &mut [u8]) -> Result<usize, PduError> {
        let l = self.lengths;
        if !l.valid() {
            return Err(PduError::Lengths {
                entity: l.entity,
                seq: l.seq,
            });
        }
        for (value, octets) in [
            (self.source, l.entity),
            (self.seq, l.seq),
            (self.dest, l.entity),
        ] {
            if !fits(value, octets) {
                return Err(PduError::TooLarge { value, octets });
            }
        }
        let len = self.len();
        let found = out.len();
        let head = out
            .get_mut(..len)
            .ok_or(PduError::Buffer { needed: len, found })?;
        let (fixed, var) = head.split_at_mut(FIXED_LEN);
        let bit = |on: bool, b: u8| if on { b } else { 0 };
        let [l0, l1] = self.data_len.to_be_bytes();
        fixed.copy_from_slice(&[
            (VERSION << 5)
                | bit(self.pdu_type == PduType::FileData, 0x10)
                | bit(self.direction == Direction::TowardSender, 0x08)
                | bit(self.mode == Mode::Unacknowledged, 0x04)
                | bit(self.crc, 0x02),
            l0,
            l1,
            bit(self.segmentation, 0x80)
                | (l.entity.saturating_sub(1) << 4)
                | l.seq.saturating_sub(1),
        ]);
        let (source, rest) = var.split_at_mut(usize_of(l.entity));
        let (seq, dest) = rest.split_at_mut(usize_of(l.seq));
        put_be(self.source, source);
        put_be(self.seq, seq);
        put_be(self.dest, dest);
        Ok(len)
    }
}

/// A length octet as a usize.
fn usize_of(b: u8) -> usize {
    usize::from(b)
}

/// Whether `value` fits `octets` octets (8 or more: any u64).
fn fits(value: u64, octets: u8) -> bool {
    // A shift by 64 or more is none: every u64 fits.
    value
        .checked_shr(u32::from(octets).saturating_mul(8))
        .is_none_or(|rest| rest == 0)
}

/// The big-endian unsigned number of up to 8 octets.
fn be(bytes: &[u8]) -> u64 {
    bytes
        .iter()
        .fold(0u64, |v, &b| v.wrapping_shl(8) | u64::from(b))
}

/// `value` big-endian into all of `out` (its low octets; `fits` checked it).
fn put_be(value: u64, out: &mut [u8]) {
    let all = value.to_be_bytes();
    let skip = all.len().saturating_sub(out.len());
    for (o, b) in out.iter_mut().zip(all.iter().skip(skip)) {
        *o = *b;
    }
}
