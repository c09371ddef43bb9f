//! The 8 motion primitives of Table 6.
// req: T6/*, P6.6, P6.8, D:fwd-back-reading

use crate::wire_enum::wire_enum;

wire_enum! {
    /// A motion primitive, numbered 1..=8 as in Table 6. "fwd" moves side A, "back" side B.
    #[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord)]
    #[cfg_attr(feature = "defmt", derive(defmt::Format))]
    #[cfg_attr(
        feature = "serde",
        derive(serde::Serialize, serde::Deserialize),
        serde(try_from = "crate::units::Number", into = "u8")
    )]
    pub enum Primitive: u8 {
        /// 1: side A contracts along the axis.
        FwdContract = 1 => "fwdContract",
        /// 2: side B contracts along the axis.
        BackContract = 2 => "backContract",
        /// 3: side A extends along the axis.
        FwdExtend = 3 => "fwdExtend",
        /// 4: side B extends along the axis.
        BackExtend = 4 => "backExtend",
        /// 5: side A turns clockwise.
        FwdTurnCw = 5 => "fwdTurnCW",
        /// 6: side A turns counter-clockwise.
        FwdTurnCcw = 6 => "fwdTurnCCW",
        /// 7: side B turns clockwise.
        BackTurnCw = 7 => "backTurnCW",
        /// 8: side B turns counter-clockwise.
        BackTurnCcw = 8 => "backTurnCCW",
    }

    /// All primitives in Table 6 order.
    const ALL;
    /// Table 6 number, 1..=8.
    pub const fn number(self) -> u8;
    /// Position in Table 6 order, 0..=7 (the number less one).
    pub const fn index(self) -> usize;
    /// Primitive with Table 6 number `n`.
    pub const fn from_number(n: u8) -> Option<Self>;
    /// Table 6 name.
    pub const fn name(self) -> &'static str;
    impl Display("{} {}", number, name);

    /// A number that is not a Table 6 primitive.
    #[error("primitive must be 1..=8 (Table 6), found {0}")]
    pub struct PrimitiveNumberError(pub u8);
    impl TryFrom<Number>("primitive (Table 6)");
}
