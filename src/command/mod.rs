//! The command set of Table 1 as one enum: what the operator can ask of the robot.
//!
//! Its byte encoding in the 14-byte command packet is [`crate::wire::opcode`]'s (the vocabulary
//! stands below the packets that carry it). Byte 5 of the packet (Table 2) is an *opcode*: one
//! value per command variant class, so the discrete choices (side, module, pair, primitive,
//! mode, on/off) live in the opcode and the parameter bytes 6–11 carry only the quantities
//! Table 2 names for them: the hip target in bytes 6–7, arm A's in 8–9, arm B's in 10–11,
//! and, for a reconfiguration, the final state in byte 8 and the initial state in byte 9; a
//! primitive names its final state in byte 8 too, because from a turn state one primitive can
//! reach two states. Every parameter byte a
//! command does not use must be zero, so a corrupted or mis-built packet is refused instead of
//! guessed at.
//!
//! ```
//! use mmic::command::{Command, ServoTarget};
//! use mmic::units::{PulseWidth, Side};
//! use mmic::pose::{Primitive, State};
//! use mmic::wire::opcode::{decode, encode};
//!
//! let c = Command::Arm { side: Side::B, target: ServoTarget::Position(PulseWidth::new(1200).unwrap()) };
//! let (opcode, params) = encode(&c);
//! assert_eq!(opcode, 0x26);
//! assert_eq!(params, [0, 0, 0, 0, 0xb0, 0x04]); // 1200 µs, low byte first, in bytes 10–11
//! assert_eq!(decode(opcode, params), Ok(c));
//!
//! let r = Command::reconfigure(State::A, State::M).unwrap();
//! assert_eq!(encode(&r), (0x60, [0, 0, b'm', b'a', 0, 0]));
//! assert!(Command::reconfigure(State::A, State::D).is_err()); // d is not a final state
//!
//! // Primitive 7 (backTurnCW) from e reaches a or d: the packet says which.
//! let p = Command::primitive(Primitive::BackTurnCw, State::D).unwrap();
//! assert_eq!(encode(&p), (0x57, [0, 0, b'd', 0, 0, 0]));
//! assert!(decode(0x57, [0; 6]).is_err()); // no final state: refused
//! ```
// req: T1/*

use crate::mode::Mode;
use crate::pose::{Primitive, State};
use crate::units::{Module, Side};

mod kind;
mod moves;
#[cfg(feature = "serde")]
mod ser;
mod servo;

/// The bolter's vocabulary ([`crate::bolter`]); commands name its pairs and fasteners.
pub use crate::bolter::{BolterPair, BolterPairError, Fasteners};
pub use kind::CommandKind;
pub use moves::{PrimitiveMove, PrimitiveMoveError, Reconfiguration, ReconfigurationError};
#[cfg(feature = "serde")]
use ser::{arm_target, gripper_target};
pub use servo::{preset_angle, HipTarget, OutOfTravel, ServoTarget, Travel};

/// A bolter command (Table 1, "Bolter").
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
#[cfg_attr(feature = "serde", serde(rename_all = "snake_case"))]
pub enum BolterCommand {
    /// Bolt a pair of fasteners, or all four.
    Bolt(Fasteners),
    /// Unbolt a pair of fasteners, or all four.
    Unbolt(Fasteners),
    /// Move both bolters down.
    Down,
}

/// What a power command switches.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
#[cfg_attr(feature = "serde", serde(rename_all = "snake_case"))]
pub enum PowerTarget {
    /// One module.
    Module(Module),
    /// Every module.
    All,
}

/// A command to the robot (Table 1, plus `ClearFaults`, which the fault latching of Section 7
/// needs and the paper does not list).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
#[cfg_attr(
    feature = "serde",
    serde(rename_all = "snake_case", deny_unknown_fields)
)]
pub enum Command {
    /// Request a heartbeat packet.
    Heartbeat,
    /// Emergency stop of the current motion.
    Stop,
    /// After a stop, resume the motion.
    Reset,
    /// Trigger the assembly system operation fault.
    SystemFault,
    /// Clear the latched faults whose conditions no longer hold (extension).
    ClearFaults,
    /// Change operating mode.
    Mode(Mode),
    /// Move one arm. A position must lie within the arms' travel (`Travel::ARM`, 900..=2100 µs):
    /// decoding and JSON refuse one outside it.
    Arm {
        /// Which arm.
        side: Side,
        /// Where to.
        #[cfg_attr(feature = "serde", serde(deserialize_with = "arm_target"))]
        target: ServoTarget,
    },
    /// Move one gripper. A position must lie within the grippers' travel (`Travel::GRIPPER`,
    /// 1000..=2000 µs): decoding and JSON refuse one outside it.
    Gripper {
        /// Which gripper.
        side: Side,
        /// Where to.
        #[cfg_attr(feature = "serde", serde(deserialize_with = "gripper_target"))]
        target: ServoTarget,
    },
    /// Rotate the hip.
    Hip(HipTarget),
    /// Bolt, unbolt or lower the bolters.
    Bolter(BolterCommand),
    /// Execute one motion primitive, ending in the final state it names.
    Primitive(PrimitiveMove),
    /// Reconfigure from an initial to a target state.
    Reconfigure(Reconfiguration),
    /// Switch power to one or all modules.
    Power {
        /// What to switch.
        target: PowerTarget,
        /// On or off.
        on: bool,
    },
}

impl Command {
    /// A reconfiguration command; see [`Reconfiguration::new`].
    pub const fn reconfigure(
        initial: State,
        target: State,
    ) -> Result<Command, ReconfigurationError> {
        match Reconfiguration::new(initial, target) {
            Ok(r) => Ok(Command::Reconfigure(r)),
            Err(e) => Err(e),
        }
    }

    /// A primitive command; see [`PrimitiveMove::new`].
    pub const fn primitive(
        primitive: Primitive,
        target: State,
    ) -> Result<Command, PrimitiveMoveError> {
        match PrimitiveMove::new(primitive, target) {
            Ok(m) => Ok(Command::Primitive(m)),
            Err(e) => Err(e),
        }
    }

    /// Table 1 row this command belongs to.
    pub const fn kind(&self) -> CommandKind {
        match self {
            Command::Heartbeat => CommandKind::Heartbeat,
            Command::Stop => CommandKind::Stop,
            Command::Reset => CommandKind::Reset,
            Command::SystemFault => CommandKind::SystemFault,
            Command::ClearFaults => CommandKind::ClearFaults,
            Command::Mode(_) => CommandKind::Mode,
            Command::Arm { .. } => CommandKind::Arm,
            Command::Gripper { .. } => CommandKind::Gripper,
            Command::Hip(_) => CommandKind::Hip,
            Command::Bolter(_) => CommandKind::Bolter,
            Command::Primitive(_) => CommandKind::Primitive,
            Command::Reconfigure(_) => CommandKind::Reconfiguration,
            Command::Power { .. } => CommandKind::PowerControl,
        }
    }
}
