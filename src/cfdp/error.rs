//! Why bytes are not a CFDP PDU this library takes, and why a PDU does not fit a buffer: one
//! variant per check, named ([`PduError::name`]) as `spec/ccsds/bad-inputs.toml` names them.

use super::flags::Direction;

/// Why bytes are not a PDU this library takes, or why one cannot be written.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, thiserror::Error)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
#[non_exhaustive]
pub enum PduError {
    /// Fewer octets than the part being read needs.
    #[error("PDU: {found} octets, fewer than the {expected} its header or field needs")]
    Truncated {
        /// Octets needed.
        expected: usize,
        /// Octets given.
        found: usize,
    },
    /// A version other than `000` or `001` (bits 0–2 of octet 0).
    #[error("PDU: version must be 0 or 1, found {found}")]
    Version {
        /// Bits 0–2.
        found: u8,
    },
    /// The large file flag is set: file sizes and offsets are 32 bits here.
    #[error("PDU: large file flag set; files here are under 4 GiB (32-bit sizes)")]
    LargeFile,
    /// The segment metadata flag is set: no segment metadata here.
    #[error("PDU: segment metadata flag set; no segment metadata is taken")]
    SegmentMetadata,
    /// The data field length disagrees with the octets after the header.
    #[error("PDU: data field length says {declared} octets, {found} follow the header")]
    Length {
        /// The header's data field length.
        declared: usize,
        /// Octets after the header.
        found: usize,
    },
    /// The CRC-16 at the end of the data field is not that of the octets before it.
    #[error("PDU: CRC {found:#06x}, the octets before it give {expected:#06x}")]
    Crc {
        /// The CRC of the PDU's octets before it.
        expected: u16,
        /// The CRC carried.
        found: u16,
    },
    /// A directive code 727.0-B-5 does not define.
    #[error("PDU: directive code {found:#04x} is none of 727.0-B-5's")]
    Directive {
        /// The code.
        found: u8,
    },
    /// Octets after a directive's last field.
    #[error("PDU: the directive ends after {expected} octets of its data field, {found} given")]
    Trailing {
        /// Octets the directive's fields take.
        expected: usize,
        /// Octets of the data field.
        found: usize,
    },
    /// The direction bit is not the directive's way.
    #[error("PDU: this directive travels {expected:?}, the direction bit says {found:?}")]
    Direction {
        /// The directive's way.
        expected: Direction,
        /// The header's.
        found: Direction,
    },
    /// A reserved condition code (12, 13).
    #[error("PDU: condition code {found} is reserved")]
    Condition {
        /// The code.
        found: u8,
    },
    /// An ACK of a directive other than EOF and Finished.
    #[error("PDU: an ACK acknowledges EOF (4) or Finished (5), not directive {found}")]
    AckOf {
        /// The acknowledged directive's code.
        found: u8,
    },
    /// An LV (a file name) longer than the octets left.
    #[error("PDU: a name of {declared} octets, {found} left in the data field")]
    Lv {
        /// The length octet.
        declared: usize,
        /// Octets after it.
        found: usize,
    },
    /// A TLV longer than the octets left.
    #[error("PDU: a TLV of {declared} octets, {found} left in the data field")]
    Tlv {
        /// Octets the TLV takes, its type and length octets included.
        declared: usize,
        /// Octets left.
        found: usize,
    },
    /// A TLV of a type this directive does not carry there.
    #[error("PDU: a TLV of type {found:#04x} where this directive carries none")]
    TlvType {
        /// The type.
        found: u8,
    },
    /// An entity ID TLV (the fault location) whose value is not as long as the header's
    /// entity IDs.
    #[error("PDU: an entity ID of {found} octets in a PDU of {expected}-octet entity IDs")]
    EntityId {
        /// Octets of the header's entity IDs.
        expected: u8,
        /// Octets of the value.
        found: usize,
    },
    /// A NAK's segment requests that are not a whole number of 8-octet pairs.
    #[error("PDU: {found} octets of NAK segment requests, not a multiple of 8")]
    NakSegments {
        /// Octets after the scope.
        found: usize,
    },
    /// A NAK's scope or segment request whose end is before its start.
    #[error("PDU: a NAK range from {start} to {end}, which ends before it starts")]
    NakRange {
        /// Its start offset.
        start: u32,
        /// Its end offset.
        end: u32,
    },
    /// Lengths outside 1..=8 octets, on emit.
    #[error(
        "PDU: entity IDs of {entity} and sequence numbers of {seq} octets; each must be 1 to 8"
    )]
    Lengths {
        /// Octets of the entity IDs.
        entity: u8,
        /// Octets of the sequence number.
        seq: u8,
    },
    /// A value too large for its field's octets, on emit.
    #[error("PDU: {value} does not fit {octets} octets")]
    TooLarge {
        /// The value.
        value: u64,
        /// The field's octets.
        octets: u8,
    },
    /// An output buffer too short, on emit.
    #[error("PDU: {needed} octets to write, {found} in the buffer")]
    Buffer {
        /// Octets the PDU needs.
        needed: usize,
        /// Octets in the buffer.
        found: usize,
    },
}

impl PduError {
    /// Every check's name, in the order the parsers run them (the first [`PduError::PARSE`]),
    /// then emit's.
    pub const NAMES: [&'static str; 20] = [
        "truncated",
        "version",
        "large-file",
        "segment-metadata",
        "length",
        "crc",
        "directive",
        "trailing",
        "direction",
        "condition",
        "ack-of",
        "lv",
        "tlv",
        "tlv-type",
        "entity-id",
        "nak-segments",
        "nak-range",
        "lengths",
        "too-large",
        "buffer",
    ];

    /// How many of [`PduError::NAMES`] are the parser's checks.
    pub const PARSE: usize = 17;

    /// The check's place in [`PduError::NAMES`].
    pub const fn position(&self) -> usize {
        match self {
            PduError::Truncated { .. } => 0,
            PduError::Version { .. } => 1,
            PduError::LargeFile => 2,
            PduError::SegmentMetadata => 3,
            PduError::Length { .. } => 4,
            PduError::Crc { .. } => 5,
            PduError::Directive { .. } => 6,
            PduError::Trailing { .. } => 7,
            PduError::Direction { .. } => 8,
            PduError::Condition { .. } => 9,
            PduError::AckOf { .. } => 10,
            PduError::Lv { .. } => 11,
            PduError::Tlv { .. } => 12,
            PduError::TlvType { .. } => 13,
            PduError::EntityId { .. } => 14,
            PduError::NakSegments { .. } => 15,
            PduError::NakRange { .. } => 16,
            PduError::Lengths { .. } => 17,
            PduError::TooLarge { .. } => 18,
            PduError::Buffer { .. } => 19,
        }
    }

    /// The check's name.
    pub fn name(&self) -> &'static str {
        Self::NAMES.get(self.position()).copied().unwrap_or("")
    }
}
