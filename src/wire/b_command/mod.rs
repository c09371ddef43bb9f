//! The 15-byte A→B command, which the paper does not lay out.
//!
//! Design: every A→B command is a complete *snapshot* of what side B must do (power switches,
//! arm and gripper targets, bolter order), not a delta. A duplicate or a resend is therefore
//! harmless, and B needs no command history. Byte 4 is a wrapping sequence number that B
//! echoes in Table 4's "command received" byte: that echo is the acknowledgement A counts for
//! the internal-communication-loss fault.
//!
//! ```
//! use mmic::wire::b_command::{BCommandRepr, BPower};
//! use mmic::units::PulseWidth;
//! let cmd = BCommandRepr {
//!     seq: 7,
//!     power: BPower { regulator: true, arm: true, gripper: true, bolter: false },
//!     stop: false,
//!     arm_target: PulseWidth::new(1000).unwrap(),
//!     gripper_target: PulseWidth::new(2000).unwrap(),
//!     bolter: None,
//! };
//! let bytes = cmd.to_bytes();
//! assert_eq!(&bytes[..6], b"MIbc\x07\x07");
//! assert_eq!(BCommandRepr::parse(&bytes), Ok(cmd));
//! ```
// req: D:b-command

use super::layout::fields;
use super::pulse;
use super::{check, field_err, seal, Packet, PacketKind, WireError};
/// The order is the bolter's vocabulary; re-exported at its old path.
pub use crate::bolter::BolterOrder;
use crate::bolter::{BolterDirection, BolterPair, BolterStep};
use crate::units::PulseWidth;
use zerocopy::byteorder::little_endian::U16;
use zerocopy::{FromBytes, Immutable, IntoBytes, KnownLayout, Unaligned};

/// Length of the A→B command.
pub const B_COMMAND_LEN: usize = 15;
const KIND: PacketKind = PacketKind::BCommand;

/// The A→B command, byte for byte.
#[derive(
    Debug, Clone, Copy, PartialEq, Eq, Hash, FromBytes, IntoBytes, KnownLayout, Immutable, Unaligned,
)]
#[repr(C)]
#[expect(
    missing_docs,
    reason = "each field is described in FIELDS and spec/packets/b-command.toml"
)]
pub struct BCommandPacket {
    pub header: [u8; 4],
    pub seq: u8,
    pub flags: u8,
    pub arm_target: U16,
    pub gripper_target: U16,
    pub bolter_pair: u8,
    pub bolter_direction: u8,
    pub bolter_step: u8,
    pub checksum: U16,
}

impl Packet for BCommandPacket {
    const KIND: PacketKind = KIND;
}

const _: () = assert!(core::mem::size_of::<BCommandPacket>() == B_COMMAND_LEN);

macro_rules! at {
    ($f:ident) => {
        core::mem::offset_of!(BCommandPacket, $f)
    };
}

// The fields, from the layout (spec/packets/b-command.toml is checked against it). The
// "paper" labels are this project's, written in the paper's style.
fields! {
    BCommandPacket;
    // CONST: (name, field, type, unit, the paper's label)
    HEADER: ("header", header, [u8; 4], Header, "header"),
    SEQ: ("seq", seq, u8, Sequence, "sequence number"),
    FLAGS: ("flags", flags, u8, Bits, "power/stop flags"),
    ARM_TARGET: ("arm_target", arm_target, U16, Micros, "arm B-target"),
    GRIPPER_TARGET: ("gripper_target", gripper_target, U16, Micros, "gripper B-target"),
    BOLTER_PAIR: ("bolter.pair", bolter_pair, u8, Enum, "bolter pair"),
    BOLTER_DIRECTION: ("bolter.direction", bolter_direction, u8, Enum, "bolter direction"),
    BOLTER_STEP: ("bolter.step", bolter_step, u8, Enum, "bolter step"),
    CHECKSUM: ("checksum", checksum, U16, Crc16, "checksum"),
}

/// Flag bits of byte 5.
pub mod flags {
    /// Side B's voltage regulator.
    pub const REGULATOR: u8 = 1 << 0;
    /// Arm B powered.
    pub const ARM: u8 = 1 << 1;
    /// Gripper B powered.
    pub const GRIPPER: u8 = 1 << 2;
    /// Bolter B powered.
    pub const BOLTER: u8 = 1 << 3;
    /// Stop: hold every module where it is, ignoring the targets.
    pub const STOP: u8 = 1 << 4;
    /// Every defined bit.
    pub const DEFINED: u8 = 0b1_1111;
}

/// Side B's power switches.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Default)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
#[cfg_attr(feature = "serde", serde(deny_unknown_fields))]
pub struct BPower {
    /// Voltage regulator (7.4 V to the servos).
    pub regulator: bool,
    /// Arm B servo.
    pub arm: bool,
    /// Gripper B servo.
    pub gripper: bool,
    /// Bolter B.
    pub bolter: bool,
}

/// What board A orders board B to do.
///
/// JSON (feature `serde`) follows [`FIELDS`]: byte 5 is one object, `flags`, holding the
/// power switches and the stop bit:
/// `{"seq":7,"flags":{"regulator":true,"arm":true,"gripper":true,"bolter":false,"stop":false},
/// "arm_target":1000,"gripper_target":2000,"bolter":null}`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct BCommandRepr {
    /// Wrapping sequence number, echoed by B as the acknowledgement.
    pub seq: u8,
    /// Power switches.
    pub power: BPower,
    /// Hold everything where it is.
    pub stop: bool,
    /// Arm B target.
    pub arm_target: PulseWidth,
    /// Gripper B target.
    pub gripper_target: PulseWidth,
    /// Bolter order; none leaves the bolter idle (bytes 10–12 all zero).
    pub bolter: Option<BolterOrder>,
}

/// The JSON form (feature `serde`).
#[cfg(feature = "serde")]
mod ser;

impl BCommandRepr {
    /// Checks length, header, checksum and every field.
    pub fn parse(bytes: &[u8]) -> Result<BCommandRepr, WireError> {
        let p: &BCommandPacket = check(bytes)?;
        if p.flags & !flags::DEFINED != 0 {
            return Err(field_err(
                KIND,
                at!(flags),
                "flags",
                "bits 0..=4 only",
                u32::from(p.flags),
            ));
        }
        let bolter = bolter_order(p)?;
        Ok(BCommandRepr {
            seq: p.seq,
            power: BPower {
                regulator: p.flags & flags::REGULATOR != 0,
                arm: p.flags & flags::ARM != 0,
                gripper: p.flags & flags::GRIPPER != 0,
                bolter: p.flags & flags::BOLTER != 0,
            },
            stop: p.flags & flags::STOP != 0,
            arm_target: pulse(KIND, "arm_target", at!(arm_target), p.arm_target)?,
            gripper_target: pulse(
                KIND,
                "gripper_target",
                at!(gripper_target),
                p.gripper_target,
            )?,
            bolter,
        })
    }

    /// Writes the packet, header and checksum included.
    pub fn emit(&self, out: &mut [u8; B_COMMAND_LEN]) {
        let pw = self.power;
        let bit = |on: bool, b: u8| if on { b } else { 0 };
        let p = BCommandPacket {
            header: KIND.header(),
            seq: self.seq,
            flags: bit(pw.regulator, flags::REGULATOR)
                | bit(pw.arm, flags::ARM)
                | bit(pw.gripper, flags::GRIPPER)
                | bit(pw.bolter, flags::BOLTER)
                | bit(self.stop, flags::STOP),
            arm_target: U16::new(self.arm_target.micros()),
            gripper_target: U16::new(self.gripper_target.micros()),
            bolter_pair: self.bolter.map_or(0, |b| b.pair.number()),
            bolter_direction: self.bolter.map_or(0, |b| b.direction.to_wire()),
            bolter_step: self.bolter.map_or(0, |b| b.step.to_wire()),
            checksum: U16::ZERO,
        };
        out.copy_from_slice(p.as_bytes());
        seal(KIND, out);
    }

    /// The packet as a new array.
    pub fn to_bytes(&self) -> [u8; B_COMMAND_LEN] {
        let mut out = [0u8; B_COMMAND_LEN];
        self.emit(&mut out);
        out
    }
}

/// Bytes 10–12: no order when all three are zero, else a whole, valid one.
#[inline]
fn bolter_order(p: &BCommandPacket) -> Result<Option<BolterOrder>, WireError> {
    Ok(match (p.bolter_pair, p.bolter_direction, p.bolter_step) {
        (0, 0, 0) => None,
        (pair, dir, step) => Some(BolterOrder {
            pair: BolterPair::from_number(pair).ok_or_else(|| {
                field_err(
                    KIND,
                    at!(bolter_pair),
                    "bolter.pair",
                    "1..=4 (or bytes 10-12 all 0)",
                    u32::from(pair),
                )
            })?,
            direction: BolterDirection::from_wire(dir).ok_or_else(|| {
                field_err(
                    KIND,
                    at!(bolter_direction),
                    "bolter.direction",
                    "1 (bolt) or 2 (unbolt)",
                    u32::from(dir),
                )
            })?,
            step: BolterStep::from_wire(step).ok_or_else(|| {
                field_err(
                    KIND,
                    at!(bolter_step),
                    "bolter.step",
                    "1..=8",
                    u32::from(step),
                )
            })?,
        }),
    })
}
