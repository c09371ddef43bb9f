//! The command packet's byte encoding (Table 2 bytes 5–11): the opcodes, the parameter slots,
//! the slot the exactly-once sequence number takes, and [`encode`]/[`decode`] between a
//! [`Command`] and its opcode and six parameter bytes. The domain (what a command means) is
//! [`crate::command`]; this is layout.
//!
//! ```
//! use mmic::command::{Command, HipTarget};
//! use mmic::wire::opcode;
//! let (id, params) = opcode::encode(&Command::Hip(HipTarget::Straight));
//! assert_eq!(id, opcode::HIP + 1);
//! assert_eq!(opcode::decode(id, params), Ok(Command::Hip(HipTarget::Straight)));
//! ```
// req: T1/*, P3.13, D:opcodes

use crate::command::{
    BolterCommand, BolterPair, Command, CommandKind, Fasteners, HipTarget, PowerTarget,
    PrimitiveMove, Reconfiguration, ServoTarget, Travel,
};
use crate::mode::Mode;
use crate::pose::{Primitive, State};
use crate::units::{HipAngle, Module, PulseWidth, Side};

mod error;
pub use error::CommandError;

/// Index in the command packet of the first parameter byte (Table 2 byte 6).
pub const PARAM_OFFSET: usize = 6;
/// Number of parameter bytes (Table 2 bytes 6–11).
pub const PARAM_LEN: usize = 6;

/// Heartbeat request.
pub const HEARTBEAT: u8 = 0x01;
/// Stop.
pub const STOP: u8 = 0x02;
/// Reset (resume after stop).
pub const RESET: u8 = 0x03;
/// Assembly system operation fault.
pub const SYSTEM_FAULT: u8 = 0x04;
/// Clear latched faults.
pub const CLEAR_FAULTS: u8 = 0x05;
/// Mode: Standby, Operational, Safed = base + 0, 1, 2.
pub const MODE: u8 = 0x10;
/// Arm A: contract, extend, position = base + 0, 1, 2; arm B at base + 4.
pub const ARM: u8 = 0x20;
/// Gripper A: contract, extend, position = base + 0, 1, 2; gripper B at base + 4.
pub const GRIPPER: u8 = 0x28;
/// Hip: home, straight, 90° CW, 90° CCW, angle = base + 0..=4.
pub const HIP: u8 = 0x30;
/// Bolt pair 1..=4 = base + 0..=3; all = base + 4.
pub const BOLT: u8 = 0x40;
/// Unbolt pair 1..=4 = base + 0..=3; all = base + 4.
pub const UNBOLT: u8 = 0x48;
/// Bolters down.
pub const BOLTERS_DOWN: u8 = 0x4f;
/// Primitive n (1..=8) = base + n; its final state in byte 8 (byte 9 stays 0).
pub const PRIMITIVE: u8 = 0x50;
/// Reconfigure: final state in byte 8, initial in byte 9.
pub const RECONFIGURE: u8 = 0x60;
/// Power on module i (Module::ALL order) = base + i; all = base + 7.
pub const POWER_ON: u8 = 0x70;
/// Power off module i = base + i; all = base + 7.
pub const POWER_OFF: u8 = 0x78;

/// A parameter slot of Table 2, as a range of the 6 parameter bytes.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum Slot {
    /// Bytes 6–7: hip target.
    Hip,
    /// Bytes 8–9: arm A target; or a final state in byte 8 (reconfiguration, primitive) and
    /// a reconfiguration's initial state in byte 9.
    ArmA,
    /// Bytes 10–11: arm B target.
    ArmB,
}

impl Slot {
    /// Offset of the slot's low byte among the parameter bytes.
    pub const fn offset(self) -> usize {
        match self {
            Slot::Hip => 0,
            Slot::ArmA => 2,
            Slot::ArmB => 4,
        }
    }

    /// The packet index of the slot's low byte (6, 8 or 10).
    pub const fn index(self) -> usize {
        match self {
            Slot::Hip => PARAM_OFFSET,
            Slot::ArmA => PARAM_OFFSET + 2,
            Slot::ArmB => PARAM_OFFSET + 4,
        }
    }

    /// Slot carrying a servo target for `side`'s arm or gripper.
    pub const fn for_side(side: Side) -> Slot {
        match side {
            Side::A => Slot::ArmA,
            Side::B => Slot::ArmB,
        }
    }
}

/// The parameter slot that carries a command's exactly-once sequence number
/// (spec/protocol/README.md): bytes 10–11 (arm B), unless opcode `id` puts a pulse width there
/// (arm B or gripper B to a position), then bytes 6–7 (hip), which those opcodes leave unused.
/// Every opcode leaves at least one of the two free, so Table 2 keeps its 14 bytes.
pub const fn seq_slot(id: u8) -> Slot {
    const ARM_B_POSITION: u8 = ARM + 4 + 2;
    const GRIPPER_B_POSITION: u8 = GRIPPER + 4 + 2;
    match id {
        ARM_B_POSITION | GRIPPER_B_POSITION => Slot::Hip,
        _ => Slot::ArmB,
    }
}

/// The little-endian word in `slot`.
pub(crate) fn get_u16(p: &[u8; PARAM_LEN], slot: Slot) -> u16 {
    let [h0, h1, a0, a1, b0, b1] = *p;
    u16::from_le_bytes(match slot {
        Slot::Hip => [h0, h1],
        Slot::ArmA => [a0, a1],
        Slot::ArmB => [b0, b1],
    })
}

/// Writes `v` into `slot`, little-endian.
pub(crate) fn put_u16(p: &mut [u8; PARAM_LEN], slot: Slot, v: u16) {
    let [h0, h1, a0, a1, b0, b1] = p;
    let (lo, hi) = match slot {
        Slot::Hip => (h0, h1),
        Slot::ArmA => (a0, a1),
        Slot::ArmB => (b0, b1),
    };
    [*lo, *hi] = v.to_le_bytes();
}

/// The parameter byte of a reconfiguration's and a primitive's target state (packet byte 8),
/// and of a reconfiguration's initial state (byte 9): slot `ArmA`'s two.
const TARGET_STATE: usize = 2;
const INITIAL_STATE: usize = 3;
const _: () = assert!(TARGET_STATE == Slot::ArmA.offset());

/// Which of the six parameter bytes a command uses, as a mask over them read as one
/// little-endian word ([`params_word`]): byte `i` is bits `8 * i..8 * i + 8`.
type Used = u64;

/// No parameter byte used.
const NONE: Used = 0;

/// The two bytes of `slot`.
const fn slot_bytes(slot: Slot) -> Used {
    match slot {
        Slot::Hip => byte(0) | byte(1),
        Slot::ArmA => byte(2) | byte(3),
        Slot::ArmB => byte(4) | byte(5),
    }
}

/// Parameter byte `i` alone (none for an `i` beyond the six).
const fn byte(i: usize) -> Used {
    match i {
        0 => 0xff,
        1 => 0xff << 8,
        2 => 0xff << 16,
        3 => 0xff << 24,
        4 => 0xff << 32,
        5 => 0xff << 40,
        _ => NONE,
    }
}

/// The six parameter bytes as one word, byte `i` in bits `8 * i..8 * i + 8`.
#[inline]
fn params_word(p: &[u8; PARAM_LEN]) -> u64 {
    let mut w = [0u8; 8];
    w[..PARAM_LEN].copy_from_slice(p);
    u64::from_le_bytes(w)
}

/// Parameter bytes a command does not use must be zero. The six are tested as one word, so
/// that a valid packet takes one test and no branch per byte; the error names the first
/// nonzero byte outside `used`, as a test of byte after byte would.
#[inline]
fn unused_zero(id: u8, p: &[u8; PARAM_LEN], used: Used) -> Result<(), CommandError> {
    let stray = params_word(p) & !used;
    if stray == 0 {
        return Ok(());
    }
    // `used` covers whole bytes, so the lowest stray byte is the packet's byte as it is.
    let (i, found) = stray
        .to_le_bytes()
        .into_iter()
        .enumerate()
        .find(|&(_, b)| b != 0)
        .unwrap_or_default(); // never: `stray` is not 0
    Err(CommandError::UnusedNotZero {
        id,
        // i < 6: never saturates.
        index: PARAM_OFFSET.saturating_add(i),
        found,
    })
}

// The last opcode of each block, for [`decode`]'s ranges.
const MODE_LAST: u8 = MODE + 2;
const SERVO_LAST: u8 = GRIPPER + 7;
const HIP_LAST: u8 = HIP + 4;
const BOLT_LAST: u8 = BOLT + 4;
const UNBOLT_LAST: u8 = UNBOLT + 4;
const PRIMITIVE_FIRST: u8 = PRIMITIVE + 1;
const PRIMITIVE_LAST: u8 = PRIMITIVE + 8;
const POWER_LAST: u8 = POWER_OFF + 7;
const _: () = assert!(GRIPPER == ARM + 8 && POWER_OFF == POWER_ON + 8);

// The decoders below take `id - base` only for an `id` that `decode`'s match has placed in
// `base`'s block, so no `saturating_sub` of theirs saturates; the encoder adds to a base an
// offset below 8, and no opcode comes near 255, so no `saturating_add` saturates either.

/// Arm and gripper opcodes (`ARM..=SERVO_LAST`): per module two blocks of four (side A,
/// side B), each contract, extend, position and one unassigned.
const fn is_servo(id: u8) -> bool {
    id.saturating_sub(ARM) % 4 != 3
}

/// An arm or gripper command; a position uses its side's parameter slot.
#[inline(always)] // one caller, `decode`
fn decode_servo(id: u8, p: &[u8; PARAM_LEN]) -> Result<(Command, Used), CommandError> {
    let base = if id < GRIPPER { ARM } else { GRIPPER };
    let side = side_of(id, base);
    let slot = Slot::for_side(side);
    let (target, used) = match id.saturating_sub(base) % 4 {
        0 => (ServoTarget::Contract, NONE),
        1 => (ServoTarget::Extend, NONE),
        _ => {
            let raw = get_u16(p, slot);
            let index = slot.index();
            let pw =
                PulseWidth::new(raw).map_err(|_| CommandError::PulseWidth { index, found: raw })?;
            let (kind, travel) = if base == ARM {
                (CommandKind::Arm, Travel::ARM)
            } else {
                (CommandKind::Gripper, Travel::GRIPPER)
            };
            let target =
                travel
                    .check(ServoTarget::Position(pw))
                    .map_err(|e| CommandError::OutOfTravel {
                        index,
                        kind,
                        found: e.found,
                        min: e.min,
                        max: e.max,
                    })?;
            (target, slot_bytes(slot))
        }
    };
    let cmd = if base == ARM {
        Command::Arm { side, target }
    } else {
        Command::Gripper { side, target }
    };
    Ok((cmd, used))
}

/// A hip command: the four presets, or an angle in the hip slot.
#[inline(always)] // one caller, `decode`
fn decode_hip(id: u8, p: &[u8; PARAM_LEN]) -> Result<(Command, Used), CommandError> {
    Ok(match id.saturating_sub(HIP) {
        0 => (Command::Hip(HipTarget::Home), NONE),
        1 => (Command::Hip(HipTarget::Straight), NONE),
        2 => (Command::Hip(HipTarget::RightAngleCw), NONE),
        3 => (Command::Hip(HipTarget::RightAngleCcw), NONE),
        _ => {
            let raw = get_u16(p, Slot::Hip);
            let a = HipAngle::new(raw).map_err(|_| CommandError::HipAngle {
                index: PARAM_OFFSET,
                found: raw,
            })?;
            (Command::Hip(HipTarget::Angle(a)), slot_bytes(Slot::Hip))
        }
    })
}

/// A bolt or unbolt command: pairs 1..=4, then all four.
#[inline]
fn decode_bolter(id: u8) -> BolterCommand {
    let base = if id < UNBOLT { BOLT } else { UNBOLT };
    let which = match BolterPair::from_number(id.saturating_sub(base).saturating_add(1)) {
        Some(n) => Fasteners::Pair(n),
        None => Fasteners::All,
    };
    if base == BOLT {
        BolterCommand::Bolt(which)
    } else {
        BolterCommand::Unbolt(which)
    }
}

/// The state in parameter byte `I`: missing when 0, invalid when no Table 5 letter.
#[inline]
fn state_at<const I: usize>(p: &[u8; PARAM_LEN]) -> Result<State, CommandError> {
    let index = const { PARAM_OFFSET + I };
    let Some(&b) = p.get(I) else {
        return Err(CommandError::MissingState { index }); // never: I is 2 or 3
    };
    match b {
        0 => Err(CommandError::MissingState { index }),
        b => State::from_wire(b).ok_or(CommandError::State { index, found: b }),
    }
}

/// A reconfiguration: target state in the first parameter byte, initial state in the second
/// (Table 2's "final state / init state").
#[inline(always)] // one caller, `decode`
fn decode_reconfigure(p: &[u8; PARAM_LEN]) -> Result<(Command, Used), CommandError> {
    let target = state_at::<TARGET_STATE>(p)?;
    let initial = state_at::<INITIAL_STATE>(p)?;
    Ok((
        Command::Reconfigure(Reconfiguration::new(initial, target)?),
        slot_bytes(Slot::ArmA),
    ))
}

/// A primitive: its number in the opcode, its final state in byte 8 (Table 2's "final
/// state", as for a reconfiguration). The initial state (byte 9) is not carried: a primitive
/// starts where board A tracks the robot, which checks that the move is the primitive's cell
/// of the map from there (spec/decisions.toml: primitive-final-state).
#[inline(always)] // one caller, `decode`
fn decode_primitive(id: u8, p: &[u8; PARAM_LEN]) -> Result<(Command, Used), CommandError> {
    let Some(primitive) = Primitive::from_number(id.saturating_sub(PRIMITIVE)) else {
        return Err(CommandError::UnknownId { id });
    };
    let target = state_at::<TARGET_STATE>(p)?;
    Ok((
        Command::Primitive(PrimitiveMove::new(primitive, target)?),
        byte(TARGET_STATE),
    ))
}

/// A power command: on or off, one of the seven modules or all.
#[inline]
fn decode_power(id: u8) -> Command {
    let on = id < POWER_OFF;
    let i = id.saturating_sub(POWER_ON) % 8;
    let target = match Module::from_index(i) {
        Some(m) => PowerTarget::Module(m),
        None => PowerTarget::All,
    };
    Command::Power { target, on }
}

fn side_of(id: u8, base: u8) -> Side {
    if id.saturating_sub(base) >= 4 {
        Side::B
    } else {
        Side::A
    }
}

/// Opcode and the six parameter bytes (packet bytes 6..=11).
pub fn encode(c: &Command) -> (u8, [u8; PARAM_LEN]) {
    let mut p = [0u8; PARAM_LEN];
    let servo = |base: u8, side: Side, target: ServoTarget, p: &mut [u8; PARAM_LEN]| {
        let side_off = if side == Side::B { 4 } else { 0 };
        let k = match target {
            ServoTarget::Contract => 0,
            ServoTarget::Extend => 1,
            ServoTarget::Position(pw) => {
                put_u16(p, Slot::for_side(side), pw.micros());
                2
            }
        };
        base.saturating_add(side_off | k)
    };
    let id = match *c {
        Command::Heartbeat => HEARTBEAT,
        Command::Stop => STOP,
        Command::Reset => RESET,
        Command::SystemFault => SYSTEM_FAULT,
        Command::ClearFaults => CLEAR_FAULTS,
        Command::Mode(m) => (MODE - 1).saturating_add(m.to_wire()),
        Command::Arm { side, target } => servo(ARM, side, target, &mut p),
        Command::Gripper { side, target } => servo(GRIPPER, side, target, &mut p),
        Command::Hip(h) => match h {
            HipTarget::Home => HIP,
            HipTarget::Straight => HIP + 1,
            HipTarget::RightAngleCw => HIP + 2,
            HipTarget::RightAngleCcw => HIP + 3,
            HipTarget::Angle(a) => {
                put_u16(&mut p, Slot::Hip, a.centidegrees());
                HIP + 4
            }
        },
        Command::Bolter(b) => match b {
            BolterCommand::Bolt(Fasteners::Pair(n)) => (BOLT - 1).saturating_add(n.number()),
            BolterCommand::Bolt(Fasteners::All) => BOLT + 4,
            BolterCommand::Unbolt(Fasteners::Pair(n)) => (UNBOLT - 1).saturating_add(n.number()),
            BolterCommand::Unbolt(Fasteners::All) => UNBOLT + 4,
            BolterCommand::Down => BOLTERS_DOWN,
        },
        Command::Primitive(m) => {
            p[TARGET_STATE] = m.target().to_wire();
            PRIMITIVE.saturating_add(m.primitive().number())
        }
        Command::Reconfigure(r) => {
            p[TARGET_STATE] = r.target().to_wire();
            p[INITIAL_STATE] = r.initial().to_wire();
            RECONFIGURE
        }
        Command::Power { target, on } => {
            let base = if on { POWER_ON } else { POWER_OFF };
            match target {
                PowerTarget::Module(m) => base.saturating_add(m.index()),
                PowerTarget::All => base.saturating_add(7),
            }
        }
    };
    (id, p)
}

/// The command for opcode `id` and parameter bytes `p` (packet bytes 6..=11). Each block
/// of opcodes is recognised from its opcode constant, in one match over ranges; parameter
/// bytes the command does not use must be zero.
///
/// The decoders of the blocks are always inlined here, their one caller: left out of line
/// (the compiler did so for the servo one), the command and its mask came back through
/// memory written byte by byte and read back a word at a time, and the command packet's
/// parse took longer than before the mask was a word (issue 40, `benches/README.md`).
pub fn decode(id: u8, p: [u8; PARAM_LEN]) -> Result<Command, CommandError> {
    // The command, and which parameter bytes it uses.
    let (cmd, used): (Command, Used) = match id {
        HEARTBEAT => (Command::Heartbeat, NONE),
        STOP => (Command::Stop, NONE),
        RESET => (Command::Reset, NONE),
        SYSTEM_FAULT => (Command::SystemFault, NONE),
        CLEAR_FAULTS => (Command::ClearFaults, NONE),
        MODE..=MODE_LAST => match Mode::from_wire(id.saturating_sub(MODE - 1)) {
            Some(m) => (Command::Mode(m), NONE),
            None => return Err(CommandError::UnknownId { id }),
        },
        ARM..=SERVO_LAST if is_servo(id) => decode_servo(id, &p)?,
        HIP..=HIP_LAST => decode_hip(id, &p)?,
        BOLT..=BOLT_LAST | UNBOLT..=UNBOLT_LAST => (Command::Bolter(decode_bolter(id)), NONE),
        BOLTERS_DOWN => (Command::Bolter(BolterCommand::Down), NONE),
        PRIMITIVE_FIRST..=PRIMITIVE_LAST => decode_primitive(id, &p)?,
        RECONFIGURE => decode_reconfigure(&p)?,
        POWER_ON..=POWER_LAST => (decode_power(id), NONE),
        _ => return Err(CommandError::UnknownId { id }),
    };
    unused_zero(id, &p, used)?;
    Ok(cmd)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The rule as it was written before the word-wide test: the first nonzero byte, in
    /// order, that `used` does not cover.
    fn byte_by_byte(id: u8, p: &[u8; PARAM_LEN], used: Used) -> Result<(), CommandError> {
        for (i, &b) in p.iter().enumerate() {
            if used & byte(i) == 0 && b != 0 {
                return Err(CommandError::UnusedNotZero {
                    id,
                    index: PARAM_OFFSET + i,
                    found: b,
                });
            }
        }
        Ok(())
    }

    // req: P3.13
    #[test]
    fn unused_bytes_are_refused_as_byte_by_byte() {
        // Every mask a decoder returns, over every combination of four values per byte
        // (4^6 blocks): the same result and, on a refusal, the same byte and value.
        let masks = [
            NONE,
            slot_bytes(Slot::Hip),
            slot_bytes(Slot::ArmA),
            slot_bytes(Slot::ArmB),
            byte(Slot::ArmA.offset()),
        ];
        // Under Miri (it looks for undefined behaviour, which no value here changes) two
        // values a byte, 2^6 blocks: the walk over the values runs natively.
        let values: &[u8] = if cfg!(miri) {
            &[0, 0xff]
        } else {
            &[0, 0x01, 0x80, 0xff]
        };
        let n = values.len();
        for used in masks {
            for k in 0..n.pow(PARAM_LEN as u32) {
                let p: [u8; PARAM_LEN] =
                    core::array::from_fn(|i| values[(k / n.pow(i as u32)) % n]);
                assert_eq!(
                    unused_zero(0x26, &p, used),
                    byte_by_byte(0x26, &p, used),
                    "{p:02x?} {used:#x}"
                );
            }
        }
    }
}
