//! Packets: a fixed-size [`zerocopy`] layout per packet (the one place its field ranges are
//! defined), a typed `Repr` with `parse`/`emit`, and a deframer for byte streams.
//!
//! Every packet is `header (4) | body | checksum (2)`. The header differs per packet type so a
//! packet sent to the wrong parser is refused at byte 0; the checksum is CRC-16/CCITT-FALSE
//! over all preceding bytes, low byte first like every u16 of the paper's tables.
//!
//! ```
//! use mmic::wire::{PacketKind, WireError};
//! use mmic::wire::command::CommandRepr;
//!
//! // A heartbeat header in front of a command parser is refused at the header check.
//! let mut bytes = [0u8; 14];
//! bytes[..4].copy_from_slice(&PacketKind::Heartbeat.header());
//! assert!(matches!(CommandRepr::parse(&bytes), Err(WireError::Header { .. })));
//! ```
// req: T2/*, T3/*, T4/*

use core::fmt;
use zerocopy::{FromBytes, Immutable, KnownLayout, Unaligned};

pub mod b_command;
pub mod checksum;
pub mod command;
pub mod deframer;
pub mod heartbeat;
pub mod internal_heartbeat;
pub(crate) mod layout;
pub mod opcode;

pub use layout::{ElectricalLayout, FieldSpec, Unit};

use opcode::CommandError;

/// Length of every header.
pub const HEADER_LEN: usize = 4;
/// Length of every checksum.
pub const CHECKSUM_LEN: usize = 2;
/// Length of the longest packet (the WiFi heartbeat).
pub const MAX_PACKET_LEN: usize = 66;

/// The four packet types.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
#[cfg_attr(feature = "serde", serde(rename_all = "kebab-case"))]
pub enum PacketKind {
    /// opsUI → server → board A, 14 bytes (Table 2).
    Command,
    /// Board A → server → opsUI, 66 bytes (Table 3).
    Heartbeat,
    /// Board B → board A over the internal serial line, 47 bytes (Table 4).
    InternalHeartbeat,
    /// Board A → board B over the internal serial line, 15 bytes (not in the paper).
    BCommand,
}

impl PacketKind {
    /// All kinds.
    pub const ALL: [PacketKind; 4] = [
        PacketKind::Command,
        PacketKind::Heartbeat,
        PacketKind::InternalHeartbeat,
        PacketKind::BCommand,
    ];

    /// The four header bytes: "MI" (MMIC-I) and two letters naming the type, readable in a
    /// capture; any two headers differ in at least 5 bits.
    pub const fn header(self) -> [u8; HEADER_LEN] {
        match self {
            PacketKind::Command => *b"MICM",
            PacketKind::Heartbeat => *b"MIHB",
            PacketKind::InternalHeartbeat => *b"MIih",
            PacketKind::BCommand => *b"MIbc",
        }
    }

    /// Total length in bytes, header and checksum included.
    #[expect(
        clippy::len_without_is_empty,
        reason = "a length of this type is never zero"
    )]
    pub const fn len(self) -> usize {
        match self {
            PacketKind::Command => command::COMMAND_LEN,
            PacketKind::Heartbeat => heartbeat::HEARTBEAT_LEN,
            PacketKind::InternalHeartbeat => internal_heartbeat::INTERNAL_HEARTBEAT_LEN,
            PacketKind::BCommand => b_command::B_COMMAND_LEN,
        }
    }

    /// Kind whose header is `h`.
    pub fn from_header(h: &[u8]) -> Option<PacketKind> {
        Self::ALL.into_iter().find(|k| k.header() == h)
    }

    /// The CLI / spec name.
    pub const fn name(self) -> &'static str {
        match self {
            PacketKind::Command => "command",
            PacketKind::Heartbeat => "heartbeat",
            PacketKind::InternalHeartbeat => "internal-heartbeat",
            PacketKind::BCommand => "b-command",
        }
    }

    /// Kind with CLI / spec name `s`.
    pub fn from_name(s: &str) -> Option<PacketKind> {
        Self::ALL.into_iter().find(|k| k.name() == s)
    }

    /// Field table of this packet, byte order.
    pub const fn fields(self) -> &'static [FieldSpec] {
        match self {
            PacketKind::Command => command::FIELDS,
            PacketKind::Heartbeat => heartbeat::FIELDS,
            PacketKind::InternalHeartbeat => internal_heartbeat::FIELDS,
            PacketKind::BCommand => b_command::FIELDS,
        }
    }
}

impl fmt::Display for PacketKind {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}

/// Why bytes are not a valid packet. Checks run in this order: length, header, checksum,
/// fields; the first failure is reported with the numbers that explain it.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, thiserror::Error)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
#[non_exhaustive]
pub enum WireError {
    /// Wrong number of bytes.
    #[error("{kind} packet: length must be {expected} bytes, found {found}")]
    Length {
        /// Packet type being parsed.
        kind: PacketKind,
        /// Its fixed length.
        expected: usize,
        /// Bytes given.
        found: usize,
    },
    /// Bytes 0–3 are not this packet's header.
    #[error("{kind} packet: header must be {expected:02x?}, found {found:02x?}")]
    Header {
        /// Packet type being parsed.
        kind: PacketKind,
        /// Its header.
        expected: [u8; HEADER_LEN],
        /// Bytes 0–3 found.
        found: [u8; HEADER_LEN],
    },
    /// The checksum bytes disagree with the CRC of the preceding bytes.
    // The values, and the two bytes as they stand at the packet's end in a hex dump (low
    // byte first), so that either can be found in what the user pasted.
    #[error(
        "{kind} packet: checksum carried {carried:#06x} (bytes {:02x} {:02x}), computed {computed:#06x} (bytes {:02x} {:02x})",
        carried.to_le_bytes()[0],
        carried.to_le_bytes()[1],
        computed.to_le_bytes()[0],
        computed.to_le_bytes()[1]
    )]
    Checksum {
        /// Packet type being parsed.
        kind: PacketKind,
        /// The last two bytes, little-endian.
        carried: u16,
        /// CRC-16/CCITT-FALSE of the other bytes.
        computed: u16,
    },
    /// A field holds a value outside its domain.
    #[error("{kind} packet: byte {index} ({field}): expected {expected}, found {found:#x}")]
    Field {
        /// Packet type being parsed.
        kind: PacketKind,
        /// Index of the (first) offending byte.
        index: usize,
        /// Field name, as in spec/.
        field: &'static str,
        /// What the field may hold.
        expected: &'static str,
        /// What it held.
        found: u32,
    },
    /// The command packet's opcode and parameters are no command.
    #[error("command packet: {0}")]
    Command(#[from] CommandError),
}

impl WireError {
    /// Short machine name of the failed check: `length`, `header`, `checksum`, `field`, `command`.
    pub const fn check(&self) -> &'static str {
        match self {
            WireError::Length { .. } => "length",
            WireError::Header { .. } => "header",
            WireError::Checksum { .. } => "checksum",
            WireError::Field { .. } => "field",
            WireError::Command(_) => "command",
        }
    }
}

/// What every packet's typed form offers, so that code written once serves all four (and any
/// later) packets: tools that encode or decode by kind, fuzz targets, and the property
/// harnesses in `proofs/`. The kind gives the name, header and length
/// ([`PacketKind::name`], [`PacketKind::header`], [`PacketKind::len`]).
///
/// ```
/// use mmic::wire::{command::CommandRepr, Repr};
/// use mmic::command::Command;
/// use mmic::units::BoardNumber;
///
/// fn round_trip<R: Repr>(r: R) -> bool {
///     R::parse(r.to_bytes().as_ref()) == Ok(r)
/// }
/// let stop = CommandRepr { board: BoardNumber::ONE, command: Command::Stop, seq: 0 };
/// assert!(round_trip(stop));
/// assert_eq!(<CommandRepr as Repr>::KIND.name(), "command");
/// ```
pub trait Repr: Sized + Copy + PartialEq + fmt::Debug {
    /// Which packet this is.
    const KIND: PacketKind;
    /// Its fixed length in bytes (`KIND.len()`).
    const LEN: usize;
    /// The packet's bytes: `[u8; LEN]`.
    type Bytes: AsRef<[u8]> + AsMut<[u8]> + Copy + fmt::Debug;
    /// Checks length, header, checksum and every field, in that order; the first failure is
    /// the error.
    fn parse(bytes: &[u8]) -> Result<Self, WireError>;
    /// Writes the whole packet into `out`: header, fields, checksum.
    fn emit(&self, out: &mut Self::Bytes);
    /// The packet as new bytes.
    fn to_bytes(&self) -> Self::Bytes;
}

macro_rules! impl_repr {
    ($($t:ty => $kind:ident, $len:expr;)*) => {$(
        impl Repr for $t {
            const KIND: PacketKind = PacketKind::$kind;
            const LEN: usize = $len;
            type Bytes = [u8; $len];
            fn parse(bytes: &[u8]) -> Result<Self, WireError> {
                <$t>::parse(bytes)
            }
            fn emit(&self, out: &mut [u8; $len]) {
                <$t>::emit(self, out)
            }
            fn to_bytes(&self) -> [u8; $len] {
                <$t>::to_bytes(self)
            }
        }
        const _: () = assert!(<$t as Repr>::LEN == PacketKind::$kind.len());
    )*};
}

impl_repr! {
    command::CommandRepr => Command, command::COMMAND_LEN;
    heartbeat::HeartbeatRepr => Heartbeat, heartbeat::HEARTBEAT_LEN;
    internal_heartbeat::InternalHeartbeatRepr => InternalHeartbeat, internal_heartbeat::INTERNAL_HEARTBEAT_LEN;
    b_command::BCommandRepr => BCommand, b_command::B_COMMAND_LEN;
}

/// A packet layout: fixed size, no padding, byte-aligned, readable from any bytes.
pub trait Packet: FromBytes + KnownLayout + Immutable + Unaligned + Sized {
    /// Which packet this is.
    const KIND: PacketKind;
}

/// Length, header and checksum checks; on success a view of the bytes as `P`.
///
/// Left to the compiler's choice, as before issue 40: with `#[inline]` here (for the command
/// parse, `check_inline`) every packet's check went in line, and on RV32 board A's and board
/// B's ticks then copied their packets through `memcpy` byte by byte on every tick, about 200
/// instructions more in each board's median tick (`benches/rv32/README.md`, "The medians
/// rose").
pub fn check<P: Packet>(bytes: &[u8]) -> Result<&P, WireError> {
    check_inline(bytes)
}

/// [`check`], always inlined: for the command's parse, where `P`'s length is a constant
/// that the checksum's step depends on (`checksum::checked_packet_crc`).
#[inline(always)]
pub(crate) fn check_inline<P: Packet>(bytes: &[u8]) -> Result<&P, WireError> {
    let kind = P::KIND;
    let expected = kind.len();
    if bytes.len() != expected {
        return Err(WireError::Length {
            kind,
            expected,
            found: bytes.len(),
        });
    }
    // Never short after the length check (every packet is longer than its header and
    // checksum); refused as its length were it so.
    let split = bytes
        .first_chunk::<HEADER_LEN>()
        .zip(bytes.split_last_chunk::<CHECKSUM_LEN>());
    let Some((&found, (body, crc))) = split else {
        return Err(WireError::Length {
            kind,
            expected,
            found: bytes.len(),
        });
    };
    if found != kind.header() {
        return Err(WireError::Header {
            kind,
            expected: kind.header(),
            found,
        });
    }
    let carried = u16::from_le_bytes(*crc);
    let computed = checksum::checked_packet_crc(kind, body);
    if carried != computed {
        return Err(WireError::Checksum {
            kind,
            carried,
            computed,
        });
    }
    P::ref_from_bytes(bytes).map_err(|_| WireError::Length {
        kind,
        expected,
        found: bytes.len(),
    })
}

/// Writes header and checksum around a body already written into `out`.
pub(crate) fn seal(kind: PacketKind, out: &mut [u8]) {
    // `out` is a whole packet (the callers' arrays), so neither `if let` fails.
    if let Some(header) = out.first_chunk_mut::<HEADER_LEN>() {
        *header = kind.header();
    }
    if let Some((body, crc)) = out.split_last_chunk_mut::<CHECKSUM_LEN>() {
        *crc = checksum::crc16(body).to_le_bytes();
    }
}

/// A field check failure, for the parsers.
pub(crate) const fn field_err(
    kind: PacketKind,
    index: usize,
    field: &'static str,
    expected: &'static str,
    found: u32,
) -> WireError {
    WireError::Field {
        kind,
        index,
        field,
        expected,
        found,
    }
}

/// Reads a boolean byte: exactly 0 or 1.
/// A servo pulse field (µs, little-endian u16), refused outside 500..=2500 µs.
pub(crate) fn pulse(
    kind: PacketKind,
    name: &'static str,
    at: usize,
    v: zerocopy::little_endian::U16,
) -> Result<crate::units::PulseWidth, WireError> {
    crate::units::PulseWidth::new(v.get())
        .map_err(|_| field_err(kind, at, name, "500..=2500 us", u32::from(v.get())))
}

/// An optional byte field: `None` for 0 (the field is empty), else the value `from_wire`
/// gives, or the field error naming what is `expected`.
pub(crate) fn optional<T>(
    kind: PacketKind,
    index: usize,
    field: &'static str,
    expected: &'static str,
    b: u8,
    from_wire: impl FnOnce(u8) -> Option<T>,
) -> Result<Option<T>, WireError> {
    match b {
        0 => Ok(None),
        v => from_wire(v)
            .map(Some)
            .ok_or_else(|| field_err(kind, index, field, expected, u32::from(v))),
    }
}

pub(crate) fn get_bool(
    kind: PacketKind,
    index: usize,
    field: &'static str,
    b: u8,
) -> Result<bool, WireError> {
    match b {
        0 => Ok(false),
        1 => Ok(true),
        _ => Err(field_err(kind, index, field, "0 or 1", u32::from(b))),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    // req: D:headers
    #[test]
    fn headers_are_far_apart() {
        for a in PacketKind::ALL {
            for b in PacketKind::ALL {
                if a != b {
                    let d: u32 = a
                        .header()
                        .iter()
                        .zip(b.header())
                        .map(|(x, y)| (x ^ y).count_ones())
                        .sum();
                    assert!(d >= 5, "{a} vs {b}: {d} bits");
                }
            }
        }
    }
}
