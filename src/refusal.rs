//! Why the robot refused a command: every refusal reaches the operator in the heartbeat that
//! answers the command (Table 3 byte 62, "fault byte2"), never a silent drop.
//!
//! ```
//! use mmic::refusal::Refusal;
//! assert_eq!(Refusal::from_wire(Refusal::NotAllowedInMode.to_wire()), Some(Refusal::NotAllowedInMode));
//! assert_eq!(Refusal::from_wire(0), None); // 0 = the command was accepted
//! ```

use core::fmt;

/// A refused command's reason. Wire value 1..=7; 0 means accepted.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
#[cfg_attr(feature = "serde", serde(rename_all = "snake_case"))]
pub enum Refusal {
    /// Table 7: the current mode does not accept this kind of command.
    NotAllowedInMode,
    /// Operational refused: a fault condition still holds (see the fault bytes).
    FaultConditionHolds,
    /// Reconfiguration refused: its initial state is not the detected state (Table 8).
    InitialStateMismatch,
    /// Opcode unknown (includes an unknown mode value).
    UnknownCommand,
    /// Opcode known, parameters invalid (range, unused byte not zero, impossible state pair).
    InvalidParameter,
    /// A motion is running; a new motion command must wait for command complete.
    Busy,
    /// Motion is stopped; send Reset first.
    Stopped,
}

impl Refusal {
    /// All reasons, in wire order.
    pub const ALL: [Refusal; 7] = [
        Refusal::NotAllowedInMode,
        Refusal::FaultConditionHolds,
        Refusal::InitialStateMismatch,
        Refusal::UnknownCommand,
        Refusal::InvalidParameter,
        Refusal::Busy,
        Refusal::Stopped,
    ];

    /// Wire value 1..=7.
    pub const fn to_wire(self) -> u8 {
        self as u8 + 1
    }

    /// Reason from its wire value; `None` for 0 (accepted) and unknown values.
    pub const fn from_wire(b: u8) -> Option<Refusal> {
        if b >= 1 && b <= 7 {
            Some(Self::ALL[(b - 1) as usize])
        } else {
            None
        }
    }

    /// snake_case name (spec/ and JSON).
    pub const fn name(self) -> &'static str {
        match self {
            Refusal::NotAllowedInMode => "not_allowed_in_mode",
            Refusal::FaultConditionHolds => "fault_condition_holds",
            Refusal::InitialStateMismatch => "initial_state_mismatch",
            Refusal::UnknownCommand => "unknown_command",
            Refusal::InvalidParameter => "invalid_parameter",
            Refusal::Busy => "busy",
            Refusal::Stopped => "stopped",
        }
    }

    /// The refusal a malformed command packet earns.
    pub const fn for_command_error(e: &crate::command::CommandError) -> Refusal {
        match e {
            crate::command::CommandError::UnknownId { .. } => Refusal::UnknownCommand,
            _ => Refusal::InvalidParameter,
        }
    }
}

impl fmt::Display for Refusal {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}
