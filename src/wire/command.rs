//! The 14-byte command packet of Table 2 (opsUI → server → board A).
//!
//! ```
//! use mmic::command::Command;
//! use mmic::pose::State;
//! use mmic::units::BoardNumber;
//! use mmic::wire::command::CommandRepr;
//!
//! let repr = CommandRepr { board: BoardNumber::ONE, command: Command::reconfigure(State::A, State::M).unwrap(), seq: 7 };
//! let bytes = repr.to_bytes();
//! assert_eq!(&bytes[..4], b"MICM");
//! assert_eq!(bytes[5], 0x60);            // reconfigure opcode
//! assert_eq!((bytes[8], bytes[9]), (b'm', b'a')); // final, initial state
//! assert_eq!((bytes[10], bytes[11]), (7, 0));     // exactly-once sequence number
//! assert_eq!(CommandRepr::parse(&bytes), Ok(repr));
//! ```
// req: T2/*, P3.12

use super::layout::{span, FieldSpec, Unit};
use super::opcode::{get_u16, put_u16, seq_slot, Slot, PARAM_LEN, PARAM_OFFSET};
use super::{check_inline, field_err, seal, Packet, PacketKind, WireError};
use crate::command::Command;
use crate::units::BoardNumber;
use zerocopy::byteorder::little_endian::U16;
use zerocopy::{FromBytes, Immutable, IntoBytes, KnownLayout, Unaligned};

/// Length of the command packet.
pub const COMMAND_LEN: usize = 14;

/// Table 2, byte for byte.
#[derive(
    Debug, Clone, Copy, PartialEq, Eq, Hash, FromBytes, IntoBytes, KnownLayout, Immutable, Unaligned,
)]
#[repr(C)]
pub struct CommandPacket {
    /// Bytes 0–3: `MICM`.
    pub header: [u8; 4],
    /// Byte 4: robot number.
    pub board: u8,
    /// Byte 5: opcode.
    pub command: u8,
    /// Bytes 6–7: hip target (0.01°).
    pub hip: U16,
    /// Bytes 8–9: arm A target (µs); or a final state (8: reconfiguration, primitive) and a
    /// reconfiguration's initial state (9).
    pub arm_a: U16,
    /// Bytes 10–11: arm B target (µs).
    pub arm_b: U16,
    /// Bytes 12–13: CRC-16 of bytes 0–11.
    pub checksum: U16,
}

impl Packet for CommandPacket {
    const KIND: PacketKind = PacketKind::Command;
}

const _: () = assert!(core::mem::size_of::<CommandPacket>() == COMMAND_LEN);

/// Read-only accessors, for a packet whose length, header and checksum [`check`](super::check)
/// has passed but whose opcode or parameters may not decode: board A still answers such a
/// packet, with its sequence number, so the ground stops resending it.
///
/// ```
/// use mmic::wire::{check, command::{CommandPacket, CommandRepr}};
/// use mmic::command::Command;
/// use mmic::units::BoardNumber;
/// let bytes = CommandRepr { board: BoardNumber::ONE, command: Command::Stop, seq: 258 }.to_bytes();
/// let p: &CommandPacket = check(&bytes).unwrap();
/// assert_eq!((p.board_number(), p.opcode(), p.seq()), (1, 0x02, 258));
/// ```
impl CommandPacket {
    /// Byte 4: the robot the packet addresses (0 refused by [`CommandRepr::parse`]).
    pub fn board_number(&self) -> u8 {
        self.board
    }

    /// Byte 5: the opcode.
    pub fn opcode(&self) -> u8 {
        self.command
    }

    /// The exactly-once sequence number, in the parameter slot the opcode leaves free
    /// ([`seq_slot`]).
    pub fn seq(&self) -> u16 {
        match seq_slot(self.command) {
            Slot::Hip => self.hip.get(),
            Slot::ArmA => self.arm_a.get(),
            Slot::ArmB => self.arm_b.get(),
        }
    }
}

/// Byte ranges, from the layout.
pub mod field {
    use super::*;
    use core::ops::Range;
    /// Header.
    pub const HEADER: Range<usize> = span!(CommandPacket, header, [u8; 4]);
    /// Board number.
    pub const BOARD: Range<usize> = span!(CommandPacket, board, u8);
    /// Opcode.
    pub const COMMAND: Range<usize> = span!(CommandPacket, command, u8);
    /// Hip target.
    pub const HIP: Range<usize> = span!(CommandPacket, hip, U16);
    /// Arm A target / final+initial state.
    pub const ARM_A: Range<usize> = span!(CommandPacket, arm_a, U16);
    /// Arm B target.
    pub const ARM_B: Range<usize> = span!(CommandPacket, arm_b, U16);
    /// Checksum.
    pub const CHECKSUM: Range<usize> = span!(CommandPacket, checksum, U16);
}

/// Field table (spec/packets/command.toml is checked against it).
pub const FIELDS: &[FieldSpec] = &[
    FieldSpec {
        name: "header",
        range: field::HEADER,
        unit: Unit::Header,
        paper: "header",
        cells: &[],
    },
    FieldSpec {
        name: "board",
        range: field::BOARD,
        unit: Unit::Board,
        paper: "board number",
        cells: &[],
    },
    FieldSpec {
        name: "command",
        range: field::COMMAND,
        unit: Unit::Opcode,
        paper: "command",
        cells: &[],
    },
    FieldSpec {
        name: "hip",
        range: field::HIP,
        unit: Unit::Parameter,
        paper: "hip PWM",
        cells: &[],
    },
    FieldSpec {
        name: "arm_a",
        range: field::ARM_A,
        unit: Unit::Parameter,
        paper: "arm A PWM/ final state",
        cells: &[
            "lowByte arm A PWM/ final state",
            "highByte arm A PWM/ init state",
        ],
    },
    FieldSpec {
        name: "arm_b",
        range: field::ARM_B,
        unit: Unit::Parameter,
        paper: "arm B PWM",
        cells: &[],
    },
    FieldSpec {
        name: "checksum",
        range: field::CHECKSUM,
        unit: Unit::Crc16,
        paper: "checksum",
        cells: &[],
    },
];

const _: () =
    assert!(field::HIP.start == PARAM_OFFSET && field::ARM_B.end == PARAM_OFFSET + PARAM_LEN);

/// A command addressed to one robot.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
#[cfg_attr(feature = "serde", serde(deny_unknown_fields))]
pub struct CommandRepr {
    /// Robot (board A) the command is for.
    pub board: BoardNumber,
    /// The command.
    pub command: Command,
    /// Exactly-once sequence number, 1..=65535, carried in the parameter slot
    /// [`crate::wire::opcode::seq_slot`] leaves free; 0 = unsequenced, the paper's
    /// behaviour (board A executes every copy). See spec/protocol/README.md.
    #[cfg_attr(feature = "serde", serde(default))]
    #[cfg_attr(feature = "serde", serde(deserialize_with = "crate::units::de::seq16"))]
    pub seq: u16,
}

impl CommandRepr {
    /// Checks length, header, checksum, board number, opcode and parameters.
    pub fn parse(bytes: &[u8]) -> Result<CommandRepr, WireError> {
        let p: &CommandPacket = check_inline(bytes)?;
        let board = BoardNumber::new(p.board).map_err(|_| {
            field_err(
                PacketKind::Command,
                field::BOARD.start,
                "board",
                "1..=255",
                0,
            )
        })?;
        // Never short: `check_inline` checked the length.
        let Some(&params) = bytes.get(PARAM_OFFSET..).and_then(<[u8]>::first_chunk) else {
            return Err(WireError::Length {
                kind: PacketKind::Command,
                expected: COMMAND_LEN,
                found: bytes.len(),
            });
        };
        let mut params: [u8; PARAM_LEN] = params;
        let slot = seq_slot(p.command);
        let seq = get_u16(&params, slot);
        put_u16(&mut params, slot, 0);
        let command = super::opcode::decode(p.command, params)?;
        Ok(CommandRepr {
            board,
            command,
            seq,
        })
    }

    /// Writes the packet, header and checksum included.
    pub fn emit(&self, out: &mut [u8; COMMAND_LEN]) {
        let (id, mut params) = super::opcode::encode(&self.command);
        put_u16(&mut params, seq_slot(id), self.seq);
        out[field::BOARD.start] = self.board.get();
        out[field::COMMAND.start] = id;
        out[PARAM_OFFSET..PARAM_OFFSET + PARAM_LEN].copy_from_slice(&params);
        seal(PacketKind::Command, out);
    }

    /// The packet as a new array.
    pub fn to_bytes(&self) -> [u8; COMMAND_LEN] {
        let mut out = [0u8; COMMAND_LEN];
        self.emit(&mut out);
        out
    }
}
