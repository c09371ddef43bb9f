//! Why the robot refused a command: every refusal reaches the operator in the heartbeat that
//! answers the command (Table 3 byte 62, "fault byte2"), never a silent drop.
//!
//! ```
//! use mmic::refusal::Refusal;
//! assert_eq!(Refusal::from_wire(Refusal::NotAllowedInMode.to_wire()), Some(Refusal::NotAllowedInMode));
//! assert_eq!(Refusal::from_wire(0), None); // 0 = the command was accepted
//! ```
// req: D:heartbeat-byte-62, D:commands-in-every-mode

use crate::wire_enum::wire_enum;

wire_enum! {
    /// A refused command's reason. Wire value 1..=11; 0 means accepted. None of these is the
    /// paper's: it has no refusal codes (spec/decisions.toml, `heartbeat-byte-62`).
    #[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord)]
    #[cfg_attr(feature = "defmt", derive(defmt::Format))]
    #[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
    #[cfg_attr(feature = "serde", serde(rename_all = "snake_case"))]
    pub enum Refusal {
        /// Table 7: the current mode does not accept this kind of command.
        NotAllowedInMode = 1 => "not_allowed_in_mode",
        /// Operational refused: a fault condition still holds (see the fault bytes).
        FaultConditionHolds = 2 => "fault_condition_holds",
        /// Reconfiguration refused: its initial state is not the detected state (Table 8).
        /// Primitive refused: the robot's tracked state is none the primitive takes to the
        /// final state the command names (Figure 9), so the ground's belief of where the
        /// robot is does not hold either; no fault is latched (Table 8 names reconfigurations).
        InitialStateMismatch = 3 => "initial_state_mismatch",
        /// Opcode unknown (includes an unknown mode value).
        UnknownCommand = 4 => "unknown_command",
        /// Opcode known, parameters invalid (range, unused byte not zero, impossible state pair).
        InvalidParameter = 5 => "invalid_parameter",
        /// A motion is running; a new motion command must wait for command complete.
        Busy = 6 => "busy",
        /// A Stop interrupted a motion; send Reset to resume it (or change mode to drop it).
        Stopped = 7 => "stopped",
        /// Reset with nothing to resume: no motion was interrupted by a Stop, or the mode
        /// changed since (which drops it).
        NothingToResume = 8 => "nothing_to_resume",
        /// Primitive refused: from the robot's tracked state, the move to the final state named
        /// is a turn between two right-angle states, which would swing the moving arm about the
        /// holding arm's axis: the geometric model has it, the robot's joints do not (the hip's
        /// axis is perpendicular to both arms; spec/decisions.toml, `turn-to-turn-moves`).
        TurnWithoutHip = 9 => "turn_without_hip",
        /// No refusal of the command itself: board A restarted while taking it, and its flash
        /// holds only the record written ahead of that tick (spec/decisions.toml,
        /// `restart-board-a`), so it ran at most once and whether it ran is not known. A copy
        /// after the restart is answered with this; the uplink reports the command
        /// unacknowledged (its outcome unknown), never accepted.
        Restarted = 10 => "restarted",
        /// Reconfiguration refused: an arm board A commands contracted does not sense its
        /// contraction (Table 8's arm not fully contracted, latched, Safed). Receiving the
        /// reconfiguration starts a motion, and a motion must not start on an arm not known to
        /// be contracted; the ground's belief of where the robot is may well hold
        /// (spec/decisions.toml, `initial-state-sensors`).
        ArmNotContracted = 11 => "arm_not_contracted",
    }

    /// All reasons, in wire order.
    const ALL;
    /// Wire value 1..=11.
    pub const fn to_wire(self) -> u8;
    /// Reason from its wire value; `None` for 0 (accepted) and unknown values.
    pub const fn from_wire(b: u8) -> Option<Self>;
    /// snake_case name (spec/ and JSON).
    pub const fn name(self) -> &'static str;
    impl Display("{}", name);
}
