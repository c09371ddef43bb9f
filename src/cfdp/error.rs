//! Why bytes are not a CFDP PDU this library takes, and why a PDU does not fit a buffer: one
//! variant per check, named ([`PduError::name`]) as `spec/ccsds/bad-inputs.toml` names them.

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
    pub const NAMES: [&'static str; 9] = [
        "truncated",
        "version",
        "large-file",
        "segment-metadata",
        "length",
        "crc",
        "lengths",
        "too-large",
        "buffer",
    ];

    /// How many of [`PduError::NAMES`] are the parser's checks.
    pub const PARSE: usize = 6;

    /// The check's place in [`PduError::NAMES`].
    pub const fn position(&self) -> usize {
        match self {
            PduError::Truncated { .. } => 0,
            PduError::Version { .. } => 1,
            PduError::LargeFile => 2,
            PduError::SegmentMetadata => 3,
            PduError::Length { .. } => 4,
            PduError::Crc { .. } => 5,
            PduError::Lengths { .. } => 6,
            PduError::TooLarge { .. } => 7,
            PduError::Buffer { .. } => 8,
        }
    }

    /// The check's name.
    pub fn name(&self) -> &'static str {
        Self::NAMES.get(self.position()).copied().unwrap_or("")
    }
}
