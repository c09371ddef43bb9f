//! The three operating modes of Table 7.
//!
//! ```
//! use mmic::mode::Mode;
//! assert_eq!(Mode::from_wire(Mode::Safed.to_wire()), Some(Mode::Safed));
//! assert_eq!(Mode::default(), Mode::Standby); // the startup mode
//! ```

use core::fmt;

/// Operating mode (Table 7). On the wire: Standby 1, Operational 2, Safed 3; 0 is never a mode.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord, Default)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
#[cfg_attr(feature = "serde", serde(rename_all = "snake_case"))]
pub enum Mode {
    /// Regulator off, no module powered; accepts mode changes only. Entered on startup.
    #[default]
    Standby,
    /// All modules powered; accepts every command.
    Operational,
    /// Hip and arms hold position; accepts hip/arm commands and mode changes.
    Safed,
}

impl Mode {
    /// All modes.
    pub const ALL: [Mode; 3] = [Mode::Standby, Mode::Operational, Mode::Safed];

    /// Wire value (heartbeat byte 63).
    pub const fn to_wire(self) -> u8 {
        match self {
            Mode::Standby => 1,
            Mode::Operational => 2,
            Mode::Safed => 3,
        }
    }

    /// Mode from its wire value.
    pub const fn from_wire(b: u8) -> Option<Mode> {
        match b {
            1 => Some(Mode::Standby),
            2 => Some(Mode::Operational),
            3 => Some(Mode::Safed),
            _ => None,
        }
    }

    /// Name as in Table 7.
    pub const fn name(self) -> &'static str {
        match self {
            Mode::Standby => "standby",
            Mode::Operational => "operational",
            Mode::Safed => "safed",
        }
    }
}

impl fmt::Display for Mode {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}
