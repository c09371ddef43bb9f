//! The rows of Table 1: what the mode rules (Table 7) and spec/ speak of, where a [`Command`]
//! carries its parameters too.
//!
//! [`Command`]: super::Command
// req: T1/*

use crate::wire_enum::wire_enum;

wire_enum! {
    /// The rows of Table 1 (plus the `ClearFaults` extension): what mode rules and spec/ talk about.
    #[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
    #[cfg_attr(feature = "defmt", derive(defmt::Format))]
    #[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
    #[cfg_attr(feature = "serde", serde(rename_all = "snake_case"))]
    pub enum CommandKind {
        /// Single module: arm.
        Arm => "arm",
        /// Single module: gripper.
        Gripper => "gripper",
        /// Single module: hip.
        Hip => "hip",
        /// Single module: bolter.
        Bolter => "bolter",
        /// Primitive motion.
        Primitive => "primitive",
        /// Stop.
        Stop => "stop",
        /// Reset.
        Reset => "reset",
        /// Power control.
        PowerControl => "power_control",
        /// Reconfiguration.
        Reconfiguration => "reconfiguration",
        /// Mode.
        Mode => "mode",
        /// System fault.
        SystemFault => "system_fault",
        /// Heartbeat.
        Heartbeat => "heartbeat",
        /// Clear latched faults (extension, not in Table 1).
        ClearFaults => "clear_faults",
    }

    /// Table 1 order, then the extension.
    const ALL;
    /// snake_case name, as in spec/ and JSON.
    pub const fn name(self) -> &'static str;
    impl Display("{}", name);
}

impl CommandKind {
    /// Whether commands of this kind move an actuator (an arm, a gripper, the hip, a bolter,
    /// or several through a primitive or a reconfiguration): the commands a Stop blocks until
    /// Reset (Table 1), that Table 7 refuses outside Operational (arm and hip excepted in Safed),
    /// and that board A runs one at a time. A mode change is not one: it powers modules, and
    /// entering Operational homes the servos as part of the mode. spec/modes.toml lists them
    /// (`moving`), and a test holds this to it.
    pub const fn moves(self) -> bool {
        matches!(
            self,
            CommandKind::Arm
                | CommandKind::Gripper
                | CommandKind::Hip
                | CommandKind::Bolter
                | CommandKind::Primitive
                | CommandKind::Reconfiguration
        )
    }
}
