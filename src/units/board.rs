//! The number that addresses one robot.
// req: P3.12, D:board-numbering

use super::RangeError;
#[cfg(feature = "serde")]
use super::{Number, NumberRangeError};

/// Number of a robot's WiFi client (board A) on a server, Table 2 byte 4 and Table 3 byte 4.
///
/// 1..=255; 0 is refused so that a zeroed buffer can never address a robot.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
#[cfg_attr(
    feature = "serde",
    derive(serde::Serialize, serde::Deserialize),
    serde(try_from = "Number", into = "u8")
)]
pub struct BoardNumber(core::num::NonZeroU8);

impl BoardNumber {
    /// The first robot.
    pub const ONE: BoardNumber = BoardNumber(core::num::NonZeroU8::MIN);

    /// Board number `n`, refused when 0.
    pub const fn new(n: u8) -> Result<Self, RangeError> {
        match core::num::NonZeroU8::new(n) {
            Some(n) => Ok(BoardNumber(n)),
            None => Err(RangeError {
                quantity: "board number",
                min: 1,
                max: 255,
                found: 0,
            }),
        }
    }

    /// The number as it goes on the wire.
    pub const fn get(self) -> u8 {
        self.0.get()
    }
}

impl TryFrom<u8> for BoardNumber {
    type Error = RangeError;
    fn try_from(n: u8) -> Result<Self, RangeError> {
        BoardNumber::new(n)
    }
}

#[cfg(feature = "serde")]
impl TryFrom<Number> for BoardNumber {
    type Error = NumberRangeError;
    fn try_from(n: Number) -> Result<Self, NumberRangeError> {
        n.narrow("board number", (1, 255), |v: u8| BoardNumber::new(v).ok())
    }
}

impl From<BoardNumber> for u8 {
    fn from(b: BoardNumber) -> u8 {
        b.get()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// `TryFrom<u8>` is `new`: 1..=255, not 0.
    #[test]
    fn try_from_a_byte_is_new() {
        for n in 0..=u8::MAX {
            assert_eq!(BoardNumber::try_from(n), BoardNumber::new(n));
        }
        assert!(BoardNumber::try_from(0).is_err());
        assert_eq!(BoardNumber::try_from(7).map(u8::from), Ok(7));
    }
}
