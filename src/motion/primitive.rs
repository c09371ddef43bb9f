//! The 8 motion primitives of Table 6.

use core::fmt;

/// A motion primitive, numbered 1..=8 as in Table 6. "fwd" moves side A, "back" side B.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord)]
#[cfg_attr(
    feature = "serde",
    derive(serde::Serialize, serde::Deserialize),
    serde(try_from = "crate::units::Number", into = "u8")
)]
#[repr(u8)]
pub enum Primitive {
    /// 1: side A contracts along the axis.
    FwdContract = 1,
    /// 2: side B contracts along the axis.
    BackContract = 2,
    /// 3: side A extends along the axis.
    FwdExtend = 3,
    /// 4: side B extends along the axis.
    BackExtend = 4,
    /// 5: side A turns clockwise.
    FwdTurnCw = 5,
    /// 6: side A turns counter-clockwise.
    FwdTurnCcw = 6,
    /// 7: side B turns clockwise.
    BackTurnCw = 7,
    /// 8: side B turns counter-clockwise.
    BackTurnCcw = 8,
}

impl Primitive {
    /// All primitives in Table 6 order.
    pub const ALL: [Primitive; 8] = [
        Primitive::FwdContract,
        Primitive::BackContract,
        Primitive::FwdExtend,
        Primitive::BackExtend,
        Primitive::FwdTurnCw,
        Primitive::FwdTurnCcw,
        Primitive::BackTurnCw,
        Primitive::BackTurnCcw,
    ];

    /// Table 6 number, 1..=8.
    pub const fn number(self) -> u8 {
        self as u8
    }

    /// Primitive with Table 6 number `n`.
    pub const fn from_number(n: u8) -> Option<Primitive> {
        if n >= 1 && n <= 8 {
            Some(Self::ALL[(n - 1) as usize])
        } else {
            None
        }
    }

    /// Table 6 name.
    pub const fn name(self) -> &'static str {
        match self {
            Primitive::FwdContract => "fwdContract",
            Primitive::BackContract => "backContract",
            Primitive::FwdExtend => "fwdExtend",
            Primitive::BackExtend => "backExtend",
            Primitive::FwdTurnCw => "fwdTurnCW",
            Primitive::FwdTurnCcw => "fwdTurnCCW",
            Primitive::BackTurnCw => "backTurnCW",
            Primitive::BackTurnCcw => "backTurnCCW",
        }
    }
}

impl fmt::Display for Primitive {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{} {}", self.number(), self.name())
    }
}

/// A number that is not a Table 6 primitive.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, thiserror::Error)]
#[error("primitive must be 1..=8 (Table 6), found {0}")]
pub struct PrimitiveNumberError(pub u8);

impl TryFrom<u8> for Primitive {
    type Error = PrimitiveNumberError;
    fn try_from(n: u8) -> Result<Primitive, PrimitiveNumberError> {
        Primitive::from_number(n).ok_or(PrimitiveNumberError(n))
    }
}

#[cfg(feature = "serde")]
impl TryFrom<crate::units::Number> for Primitive {
    type Error = crate::units::NumberRangeError;
    fn try_from(n: crate::units::Number) -> Result<Self, Self::Error> {
        n.narrow("primitive (Table 6)", (1, 8), Primitive::from_number)
    }
}

impl From<Primitive> for u8 {
    fn from(p: Primitive) -> u8 {
        p.number()
    }
}
