//! Why a command's parameter block does not decode: [`CommandError`], with the refusal each
//! earns.

use crate::command::{CommandKind, PrimitiveMoveError, ReconfigurationError};
use crate::refusal::Refusal;
use crate::units::PulseWidth;

/// A parameter block that does not decode to a command.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, thiserror::Error)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
#[non_exhaustive]
pub enum CommandError {
    /// Byte 5 holds no assigned opcode.
    #[error("byte 5: unknown command id {id:#04x}")]
    UnknownId {
        /// The refused opcode.
        id: u8,
    },
    /// A parameter byte the command does not use is not zero.
    #[error("byte {index}: unused by command {id:#04x}, must be 0, found {found:#04x}")]
    UnusedNotZero {
        /// Opcode.
        id: u8,
        /// Packet byte index (6..=11).
        index: usize,
        /// Its value.
        found: u8,
    },
    /// A pulse width outside the servo range.
    #[error("bytes {index}-{}: pulse width must be {}..={} us, found {found}", index.saturating_add(1), PulseWidth::MIN_US, PulseWidth::MAX_US)]
    PulseWidth {
        /// Packet index of the low byte.
        index: usize,
        /// Value found.
        found: u16,
    },
    /// An arm or gripper position outside the module's travel (`Travel::ARM`, `Travel::GRIPPER`;
    /// spec/control/servos.toml): it would drive the servo against its end stop.
    #[error("bytes {index}-{}: {} target must be within its travel {min}..={max} us, found {found}", index.saturating_add(1), kind.name())]
    OutOfTravel {
        /// Packet index of the low byte.
        index: usize,
        /// Arm or gripper.
        kind: CommandKind,
        /// Value found, µs.
        found: u16,
        /// The travel's smallest pulse, µs.
        min: u16,
        /// The travel's largest pulse, µs.
        max: u16,
    },
    /// A hip angle at or above 360°.
    #[error("bytes {index}-{}: hip angle must be < 36000 (0.01 deg), found {found}", index.saturating_add(1))]
    HipAngle {
        /// Packet index of the low byte.
        index: usize,
        /// Value found.
        found: u16,
    },
    /// A state byte left 0: the command must name a state there (a primitive built for the
    /// old layout, which carried no final state, lands here).
    #[error("byte {index}: state missing (0x00), must be 'a'..='o' (0x61..=0x6f)")]
    MissingState {
        /// Packet index.
        index: usize,
    },
    /// A state byte that is no Table 5 letter.
    #[error("byte {index}: state must be 'a'..='o' (0x61..=0x6f), found {found:#04x}")]
    State {
        /// Packet index.
        index: usize,
        /// Value found.
        found: u8,
    },
    /// A well-formed but impossible reconfiguration.
    #[error("bytes 8-9: {0}")]
    Reconfiguration(#[from] ReconfigurationError),
    /// A primitive whose final state it reaches from no state.
    #[error("byte 8: {0}")]
    Primitive(#[from] PrimitiveMoveError),
}

impl CommandError {
    /// The refusal a malformed command packet earns: an unknown opcode is an unknown command,
    /// anything else a parameter the command cannot take. The mapping lives with the error,
    /// not with [`Refusal`], because the refusal codes are vocabulary and the error is layout.
    pub const fn refusal(&self) -> Refusal {
        match self {
            CommandError::UnknownId { .. } => Refusal::UnknownCommand,
            _ => Refusal::InvalidParameter,
        }
    }
}
