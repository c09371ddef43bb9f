//! ST\[8\] function management: every Table 1 command as a function with typed arguments, the
//! application data of TC(8,1) "perform a function".
//!
//! The application data is the function ID (one byte) and then that function's arguments,
//! big-endian, fixed length per function (spec/ccsds/functions.toml lists them with their
//! ranges; a test holds this module to it). Decoding builds the library's [`Command`] through
//! its own constructors, so a PUS function is exactly the legacy command it names — the
//! legacy ⇄ PUS mapping is this one table, with no second meaning of any command. Table 1's
//! Heartbeat request is no function: ST\[17\] are-you-alive replaces it.
//!
//! ```
//! use mmic::command::Command;
//! use mmic::pose::State;
//! use mmic::pus::function::{self, FunctionError};
//!
//! let c = Command::reconfigure(State::A, State::M).unwrap();
//! let mut buf = [0u8; function::MAX_LEN];
//! let n = function::encode(&c, &mut buf).unwrap();
//! assert_eq!(&buf[..n], &[9, b'a', b'm']); // function 9, initial a, target m
//! assert_eq!(function::decode(&buf[..n]), Ok(c));
//! // Each bad input is refused by name, with the numbers.
//! assert_eq!(
//!     function::decode(&[9, b'a']),
//!     Err(FunctionError::Length { function: 9, expected: 3, found: 2 })
//! );
//! ```

use crate::bolter::BolterPair;
use crate::command::Travel;
use crate::command::{
    BolterCommand, Command, Fasteners, HipTarget, PowerTarget, PrimitiveMove, PrimitiveMoveError,
    Reconfiguration, ReconfigurationError, ServoTarget,
};
use crate::mode::Mode;
use crate::pose::{Primitive, State};
use crate::units::{HipAngle, Module, PulseWidth, Side};

/// The longest application data of a function: ID and arguments.
pub const MAX_LEN: usize = 5;

crate::wire_enum::wire_enum! {
    /// A function of ST\[8\], in Table 1's order; the value is its function ID.
    #[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord)]
    #[cfg_attr(feature = "defmt", derive(defmt::Format))]
    pub enum FunctionId: u8 {
        /// Move one arm: side, target kind, pulse.
        Arm = 1 => "arm",
        /// Move one gripper: side, target kind, pulse.
        Gripper = 2 => "gripper",
        /// Rotate the hip: target kind, angle.
        Hip = 3 => "hip",
        /// Bolt, unbolt, or lower the bolters: operation, pair.
        Bolter = 4 => "bolter",
        /// One motion primitive: primitive, final state.
        Primitive = 5 => "primitive",
        /// Emergency stop of the current motion.
        Stop = 6 => "stop",
        /// Resume the motion a stop interrupted.
        Reset = 7 => "reset",
        /// Power one or all modules: target, on.
        Power = 8 => "power_control",
        /// Reconfigure: initial state, target state.
        Reconfiguration = 9 => "reconfiguration",
        /// Change operating mode: mode.
        Mode = 10 => "mode",
        /// Trigger the assembly system operation fault.
        SystemFault = 11 => "system_fault",
        /// Clear the latched faults whose conditions no longer hold (extension).
        ClearFaults = 12 => "clear_faults",
    }

    /// Every function, in ID order.
    const ALL;
    /// The function ID.
    pub const fn id(self) -> u8;
    /// The ID's function.
    pub const fn from_id(b: u8) -> Option<Self>;
    /// Its name: Table 1's kind, as in spec/commands.toml.
    pub const fn name(self) -> &'static str;
}

impl FunctionId {
    /// Length of its arguments, bytes.
    pub const fn args_len(self) -> usize {
        match self {
            FunctionId::Arm | FunctionId::Gripper => 4,
            FunctionId::Hip => 3,
            FunctionId::Bolter
            | FunctionId::Primitive
            | FunctionId::Power
            | FunctionId::Reconfiguration => 2,
            FunctionId::Mode => 1,
            FunctionId::Stop
            | FunctionId::Reset
            | FunctionId::SystemFault
            | FunctionId::ClearFaults => 0,
        }
    }

    /// The function of a command; none for the Heartbeat request (ST\[17\] instead).
    pub const fn of(c: &Command) -> Option<FunctionId> {
        Some(match c {
            Command::Heartbeat => return None,
            Command::Arm { .. } => FunctionId::Arm,
            Command::Gripper { .. } => FunctionId::Gripper,
            Command::Hip(_) => FunctionId::Hip,
            Command::Bolter(_) => FunctionId::Bolter,
            Command::Primitive(_) => FunctionId::Primitive,
            Command::Stop => FunctionId::Stop,
            Command::Reset => FunctionId::Reset,
            Command::Power { .. } => FunctionId::Power,
            Command::Reconfigure(_) => FunctionId::Reconfiguration,
            Command::Mode(_) => FunctionId::Mode,
            Command::SystemFault => FunctionId::SystemFault,
            Command::ClearFaults => FunctionId::ClearFaults,
        })
    }
}

/// Why application data is no function.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, thiserror::Error)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
#[non_exhaustive]
pub enum FunctionError {
    /// No application data at all: not even a function ID.
    #[error("no function ID: the application data is empty")]
    Empty,
    /// The function ID names no function.
    #[error("unknown function ID {id} (valid: 1..=12)")]
    UnknownFunction {
        /// The ID found.
        id: u8,
    },
    /// The application data is not the function's length.
    #[error("function {function}: application data of {found} bytes, expected {expected}")]
    Length {
        /// The function ID.
        function: u8,
        /// ID and arguments.
        expected: usize,
        /// Bytes found.
        found: usize,
    },
    /// An argument outside its range (spec/ccsds/functions.toml).
    #[error("function {function}: argument {argument} = {value} out of range {min}..={max}")]
    OutOfRange {
        /// The function ID.
        function: u8,
        /// The argument's name.
        argument: &'static str,
        /// The value found.
        value: u16,
        /// Its smallest valid value.
        min: u16,
        /// Its largest valid value.
        max: u16,
    },
    /// Each argument in range, together no reconfiguration (Section 6).
    #[error("function 9: {0}")]
    Reconfiguration(ReconfigurationError),
    /// Each argument in range, together no primitive command (Figure 9).
    #[error("function 5: {0}")]
    Primitive(PrimitiveMoveError),
    /// The Heartbeat request has no function: ST\[17\] are-you-alive replaces it.
    #[error("the heartbeat request is no ST[8] function: use TC(17,1)")]
    NoFunction,
    /// The caller's buffer is shorter than the application data.
    #[error("buffer of {found} bytes, need {needed}")]
    Buffer {
        /// Bytes needed.
        needed: usize,
        /// Bytes given.
        found: usize,
    },
}

/// An argument `value` checked against `min..=max`.
const fn arg(
    f: FunctionId,
    argument: &'static str,
    value: u16,
    min: u16,
    max: u16,
) -> Result<u16, FunctionError> {
    if value >= min && value <= max {
        Ok(value)
    } else {
        Err(FunctionError::OutOfRange {
            function: f.id(),
            argument,
            value,
            min,
            max,
        })
    }
}

/// Servo target kinds: contract, extend, position (pulse given).
const SERVO_KINDS: u16 = 2;
/// Hip target kinds: home, straight, right angle CW, right angle CCW, angle (given).
const HIP_KINDS: u16 = 4;
/// Bolter operations: bolt, unbolt, down.
const BOLTER_OPS: u16 = 2;

fn side(f: FunctionId, b: u8) -> Result<Side, FunctionError> {
    Ok(if arg(f, "side", b.into(), 0, 1)? == 0 {
        Side::A
    } else {
        Side::B
    })
}

/// A servo target; a position within `travel` (the arms' or the grippers', which the command
/// layer refuses to leave: spec/control/servos.toml).
fn servo(
    f: FunctionId,
    kind: u8,
    pulse: u16,
    travel: Travel,
) -> Result<ServoTarget, FunctionError> {
    Ok(match arg(f, "target", kind.into(), 0, SERVO_KINDS)? {
        0 | 1 => {
            arg(f, "pulse", pulse, 0, 0)?;
            if kind == 0 {
                ServoTarget::Contract
            } else {
                ServoTarget::Extend
            }
        }
        _ => {
            let (min, max) = (travel.min().micros(), travel.max().micros());
            match PulseWidth::new(arg(f, "pulse", pulse, min, max)?) {
                Ok(p) => ServoTarget::Position(p),
                Err(_) => return Err(range_err(f, "pulse", pulse, min, max)),
            }
        }
    })
}

const fn range_err(
    f: FunctionId,
    argument: &'static str,
    value: u16,
    min: u16,
    max: u16,
) -> FunctionError {
    FunctionError::OutOfRange {
        function: f.id(),
        argument,
        value,
        min,
        max,
    }
}

fn state(f: FunctionId, argument: &'static str, b: u8) -> Result<State, FunctionError> {
    State::from_wire(b).ok_or(range_err(f, argument, b.into(), b'a'.into(), b'o'.into()))
}

/// Power targets: 0 all, then the modules in `Module::ALL` order (1 hip … 7 bolter B).
const fn power_target(t: PowerTarget) -> u8 {
    match t {
        PowerTarget::All => 0,
        // At most 7 (seven modules): never saturates.
        PowerTarget::Module(m) => m.index().saturating_add(1),
    }
}

/// Decodes TC(8,1) application data into the command it names; refuses, by name, anything
/// else: no ID, an unknown ID, a wrong length, an argument out of range, a combination of
/// arguments that is no command.
pub fn decode(data: &[u8]) -> Result<Command, FunctionError> {
    let (&id, a) = data.split_first().ok_or(FunctionError::Empty)?;
    let f = FunctionId::from_id(id).ok_or(FunctionError::UnknownFunction { id })?;
    if a.len() != f.args_len() {
        return Err(FunctionError::Length {
            function: id,
            // At most 5: never saturates.
            expected: f.args_len().saturating_add(1),
            found: data.len(),
        });
    }
    let b = |i: usize| a.get(i).copied().unwrap_or(0);
    let w = |i: usize| {
        a.get(i..)
            .and_then(<[u8]>::first_chunk::<2>)
            .map_or(0, |&s| u16::from_be_bytes(s))
    };
    Ok(match f {
        FunctionId::Arm => Command::Arm {
            side: side(f, b(0))?,
            target: servo(f, b(1), w(2), Travel::ARM)?,
        },
        FunctionId::Gripper => Command::Gripper {
            side: side(f, b(0))?,
            target: servo(f, b(1), w(2), Travel::GRIPPER)?,
        },
        FunctionId::Hip => Command::Hip(hip(f, b(0), w(1))?),
        FunctionId::Bolter => Command::Bolter(bolter(f, b(0), b(1))?),
        FunctionId::Primitive => {
            let p =
                Primitive::from_number(b(0)).ok_or(range_err(f, "primitive", b(0).into(), 1, 8))?;
            let s = state(f, "final_state", b(1))?;
            Command::Primitive(PrimitiveMove::new(p, s).map_err(FunctionError::Primitive)?)
        }
        FunctionId::Stop => Command::Stop,
        FunctionId::Reset => Command::Reset,
        FunctionId::Power => power(f, b(0), b(1))?,
        FunctionId::Reconfiguration => {
            let (i, t) = (state(f, "initial", b(0))?, state(f, "target", b(1))?);
            Command::Reconfigure(
                Reconfiguration::new(i, t).map_err(FunctionError::Reconfiguration)?,
            )
        }
        FunctionId::Mode => {
            Command::Mode(Mode::from_wire(b(0)).ok_or(range_err(f, "mode", b(0).into(), 1, 3))?)
        }
        FunctionId::SystemFault => Command::SystemFault,
        FunctionId::ClearFaults => Command::ClearFaults,
    })
}

/// A hip function's target: `kind` 0..=3 a preset (angle 0), 4 the angle given.
fn hip(f: FunctionId, kind: u8, angle: u16) -> Result<HipTarget, FunctionError> {
    let kind = arg(f, "target", kind.into(), 0, HIP_KINDS)?;
    if kind < HIP_KINDS {
        arg(f, "angle", angle, 0, 0)?;
    }
    Ok(match kind {
        0 => HipTarget::Home,
        1 => HipTarget::Straight,
        2 => HipTarget::RightAngleCw,
        3 => HipTarget::RightAngleCcw,
        _ => HipTarget::Angle(match HipAngle::new(angle) {
            Ok(h) => h,
            Err(_) => return Err(range_err(f, "angle", angle, 0, HipAngle::TURN - 1)),
        }),
    })
}

/// A bolter function: `op` 0 bolt, 1 unbolt (pair 1..=4, or 0 for all), 2 down (pair 0).
fn bolter(f: FunctionId, op: u8, pair: u8) -> Result<BolterCommand, FunctionError> {
    let op = arg(f, "operation", op.into(), 0, BOLTER_OPS)?;
    let pair = arg(f, "pair", pair.into(), 0, if op == 2 { 0 } else { 4 })?;
    let fasteners = match u8::try_from(pair).ok().and_then(BolterPair::from_number) {
        Some(p) => Fasteners::Pair(p),
        None => Fasteners::All,
    };
    Ok(match op {
        0 => BolterCommand::Bolt(fasteners),
        1 => BolterCommand::Unbolt(fasteners),
        _ => BolterCommand::Down,
    })
}

/// A power function: `target` 0 for every module, else module `target - 1`; `on` 0 or 1.
fn power(f: FunctionId, target: u8, on: u8) -> Result<Command, FunctionError> {
    let modules = u16::try_from(Module::ALL.len()).unwrap_or(u16::MAX); // 7
    let t = arg(f, "target", target.into(), 0, modules)?;
    let on = arg(f, "on", on.into(), 0, 1)? == 1;
    let target = match t
        .checked_sub(1)
        .and_then(|i| Module::ALL.get(usize::from(i)))
    {
        Some(&m) => PowerTarget::Module(m),
        None => PowerTarget::All,
    };
    Ok(Command::Power { target, on })
}

/// Writes a command's TC(8,1) application data into `out`; returns its length.
pub fn encode(c: &Command, out: &mut [u8]) -> Result<usize, FunctionError> {
    let f = FunctionId::of(c).ok_or(FunctionError::NoFunction)?;
    let mut a = [0u8; MAX_LEN];
    a[0] = f.id();
    let servo = |t: &ServoTarget| match t {
        ServoTarget::Contract => (0u8, 0u16),
        ServoTarget::Extend => (1, 0),
        ServoTarget::Position(p) => (2, p.micros()),
    };
    let args: [u8; 4] = match c {
        Command::Arm { side, target } | Command::Gripper { side, target } => {
            let (k, p) = servo(target);
            let [hi, lo] = p.to_be_bytes();
            [u8::from(*side == Side::B), k, hi, lo]
        }
        Command::Hip(h) => {
            let (k, v) = match h {
                HipTarget::Home => (0u8, 0u16),
                HipTarget::Straight => (1, 0),
                HipTarget::RightAngleCw => (2, 0),
                HipTarget::RightAngleCcw => (3, 0),
                HipTarget::Angle(a) => (4, a.centidegrees()),
            };
            let [hi, lo] = v.to_be_bytes();
            [k, hi, lo, 0]
        }
        Command::Bolter(b) => {
            let pair = |f: &Fasteners| match f {
                Fasteners::All => 0,
                Fasteners::Pair(p) => p.number(),
            };
            match b {
                BolterCommand::Bolt(x) => [0, pair(x), 0, 0],
                BolterCommand::Unbolt(x) => [1, pair(x), 0, 0],
                BolterCommand::Down => [2, 0, 0, 0],
            }
        }
        Command::Primitive(m) => [m.primitive().number(), m.target().to_wire(), 0, 0],
        Command::Power { target, on } => [power_target(*target), u8::from(*on), 0, 0],
        Command::Reconfigure(r) => [r.initial().to_wire(), r.target().to_wire(), 0, 0],
        Command::Mode(m) => [m.to_wire(), 0, 0, 0],
        _ => [0; 4],
    };
    // At most 5: never saturates.
    let n = f.args_len().saturating_add(1);
    for (d, s) in a.iter_mut().skip(1).zip(args.iter()) {
        *d = *s;
    }
    let found = out.len();
    let dst = out
        .get_mut(..n)
        .ok_or(FunctionError::Buffer { needed: n, found })?;
    dst.copy_from_slice(a.get(..n).unwrap_or(&[]));
    Ok(n)
}
