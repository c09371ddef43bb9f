//! Why bytes are not a valid PUS packet, and why a packet does not fit a buffer.
//!
//! [`PacketError`] covers everything the wire layer checks, one variant per check, in the
//! order the parsers run them ([`PacketError::NAMES`]); the first failure is the error, so a
//! given input has exactly one. The error of a whole telecommand, from the first octet to
//! the last argument, is the services layer's ([`crate::pus::PusError`]): it wraps this one.

use super::primary::PacketType;

/// Why bytes are not a valid PUS-C space packet. Each variant names one check; the parsers
/// run them in the order of [`PacketError::NAMES`] (the order of the variants here) and report
/// the first that fails:
///
/// 1. `truncated`: fewer octets than the headers and the packet error control;
/// 2. `version` … `sequence-flags`: the primary header's fixed fields, in bit order;
/// 3. `length`: the data length field against the buffer (both ways);
/// 4. `pus-version`: the secondary header's version nibble;
/// 5. `checksum`: the CRC-16 over the whole packet;
/// 6. `apid`: the APID against the caller's set.
///
/// The fields whose value is fixed for every PUS packet come first (a packet of another
/// protocol or of the other direction is refused for what it is, not as a corrupted one); the
/// length before the CRC, because the length says where the CRC is; the APID last, after the
/// CRC, so that a corrupted APID is reported as corruption and a foreign APID only when the
/// packet is intact.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, thiserror::Error)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
#[non_exhaustive]
pub enum PacketError {
    /// Fewer octets than the primary and secondary headers and the CRC.
    #[error("{kind} packet: {found} octets, fewer than its headers and CRC ({expected})")]
    Truncated {
        /// The parser's packet type.
        kind: PacketType,
        /// The shortest such packet (no user data).
        expected: usize,
        /// Octets given.
        found: usize,
    },
    /// Packet version number (bits 0–2) other than 0.
    #[error("{kind} packet: packet version number must be {expected}, found {found}")]
    Version {
        /// The parser's packet type.
        kind: PacketType,
        /// 0.
        expected: u8,
        /// Bits 0–2.
        found: u8,
    },
    /// The type bit says telemetry to the TC parser, or telecommand to the TM parser.
    #[error("packet type bit must say {expected}, found {found}")]
    PacketType {
        /// The parser's packet type.
        expected: PacketType,
        /// The type bit's.
        found: PacketType,
    },
    /// The secondary header flag is clear: no PUS secondary header.
    #[error("{kind} packet: secondary header flag must be {expected}, found {found}")]
    SecondaryHeaderFlag {
        /// The parser's packet type.
        kind: PacketType,
        /// 1.
        expected: u8,
        /// 0.
        found: u8,
    },
    /// Sequence flags other than `0b11` (unsegmented).
    #[error(
        "{kind} packet: sequence flags must be {expected:#04b} (unsegmented), found {found:#04b}"
    )]
    SequenceFlags {
        /// The parser's packet type.
        kind: PacketType,
        /// `0b11`.
        expected: u8,
        /// Bits 16–17.
        found: u8,
    },
    /// The data length field disagrees with the number of octets given.
    #[error("{kind} packet: the data length field says {expected} octets in all, found {found}")]
    Length {
        /// The parser's packet type.
        kind: PacketType,
        /// Total length the field declares (field + 7).
        expected: usize,
        /// Octets given.
        found: usize,
    },
    /// The secondary header's PUS version number is not 2 (PUS-C).
    #[error("{kind} packet: PUS version number must be {expected}, found {found}")]
    PusVersion {
        /// The parser's packet type.
        kind: PacketType,
        /// 2.
        expected: u8,
        /// High nibble of octet 6.
        found: u8,
    },
    /// The packet error control disagrees with the CRC of the other octets.
    #[error(
        "{kind} packet: packet error control carried {carried:#06x}, computed {computed:#06x}"
    )]
    Checksum {
        /// The parser's packet type.
        kind: PacketType,
        /// The last two octets, big-endian.
        carried: u16,
        /// CRC-16/CCITT-FALSE of the others.
        computed: u16,
    },
    /// The APID is not one the caller accepts.
    #[error("{kind} packet: APID {found:#05x} is not one this receiver accepts")]
    Apid {
        /// The parser's packet type.
        kind: PacketType,
        /// The packet's APID.
        found: u16,
    },
}

impl PacketError {
    /// Every check's name, in the order the parsers run them.
    pub const NAMES: [&'static str; 9] = [
        "truncated",
        "version",
        "packet-type",
        "secondary-header-flag",
        "sequence-flags",
        "length",
        "pus-version",
        "checksum",
        "apid",
    ];

    /// The failed check's name (`spec/ccsds/bad-inputs.toml`, CLI output).
    pub const fn name(&self) -> &'static str {
        // Constant indices, checked by the compiler; the order is `position`'s.
        match self {
            PacketError::Truncated { .. } => Self::NAMES[0],
            PacketError::Version { .. } => Self::NAMES[1],
            PacketError::PacketType { .. } => Self::NAMES[2],
            PacketError::SecondaryHeaderFlag { .. } => Self::NAMES[3],
            PacketError::SequenceFlags { .. } => Self::NAMES[4],
            PacketError::Length { .. } => Self::NAMES[5],
            PacketError::PusVersion { .. } => Self::NAMES[6],
            PacketError::Checksum { .. } => Self::NAMES[7],
            PacketError::Apid { .. } => Self::NAMES[8],
        }
    }

    /// The failed check's place in the check order (0 = first).
    pub const fn position(&self) -> usize {
        match self {
            PacketError::Truncated { .. } => 0,
            PacketError::Version { .. } => 1,
            PacketError::PacketType { .. } => 2,
            PacketError::SecondaryHeaderFlag { .. } => 3,
            PacketError::SequenceFlags { .. } => 4,
            PacketError::Length { .. } => 5,
            PacketError::PusVersion { .. } => 6,
            PacketError::Checksum { .. } => 7,
            PacketError::Apid { .. } => 8,
        }
    }
}

/// Why a packet could not be written.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, thiserror::Error)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
#[non_exhaustive]
pub enum EmitError {
    /// The caller's buffer is shorter than the packet.
    #[error("the packet needs {expected} octets, the buffer has {found}")]
    BufferTooSmall {
        /// The packet's length.
        expected: usize,
        /// The buffer's length.
        found: usize,
    },
    /// More user data than a space packet's data field holds (65,536 octets with the
    /// secondary header and CRC).
    #[error("{found} octets of user data, at most {max} fit one packet")]
    DataTooLong {
        /// Most user data octets of this packet type.
        max: usize,
        /// Octets given.
        found: usize,
    },
}
