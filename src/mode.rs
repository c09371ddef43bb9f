//! The three operating modes of Table 7.
//!
//! ```
//! use mmic::mode::Mode;
//! assert_eq!(Mode::from_wire(Mode::Safed.to_wire()), Some(Mode::Safed));
//! assert_eq!(Mode::default(), Mode::Standby); // the startup mode
//! ```
// req: P7.1, T7/*, D:mode-codes

use crate::wire_enum::wire_enum;

wire_enum! {
    /// Operating mode (Table 7). On the wire: Standby 1, Operational 2, Safed 3; 0 is never a mode.
    #[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord, Default)]
    #[cfg_attr(feature = "defmt", derive(defmt::Format))]
    #[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
    #[cfg_attr(feature = "serde", serde(rename_all = "snake_case"))]
    pub enum Mode {
        /// Regulator off, no module powered; accepts mode changes only. Entered on startup.
        #[default]
        Standby = 1 => "standby",
        /// All modules powered; accepts every command.
        Operational = 2 => "operational",
        /// Hip and arms hold position; accepts hip/arm commands and mode changes.
        Safed = 3 => "safed",
    }

    /// All modes.
    const ALL;
    /// Wire value (heartbeat byte 63).
    pub const fn to_wire(self) -> u8;
    /// Mode from its wire value.
    pub const fn from_wire(b: u8) -> Option<Self>;
    /// Name as in Table 7.
    pub const fn name(self) -> &'static str;
    impl Display("{}", name);
}
