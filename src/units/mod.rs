//! Physical quantities and identifiers carried in packets, each with the unit and range that
//! `spec/decisions.toml` fixes (the paper names the fields but gives no unit or scale).
//!
//! ```
//! use mmic::units::{PulseWidth, HipAngle};
//! let pw = PulseWidth::new(1500).unwrap();
//! assert_eq!(pw.micros(), 1500);
//! assert!(PulseWidth::new(2501).is_err());
//! assert_eq!(HipAngle::new(18000).unwrap().centidegrees(), 18000); // 180.00°
//! ```
//!
//! One file per kind of quantity; each bounded integer is a `ranged!` newtype, so a
//! value outside its range cannot be built and is refused by name.
// req: D:hip-unit, D:servo-unit, D:electrical-units

mod board;
mod electrical;
mod lattice;
#[cfg(feature = "serde")]
mod number;
pub(crate) mod range;
mod servo;
mod side;
pub(crate) mod slice;
mod time;
pub mod widen;

pub use board::BoardNumber;
pub use electrical::{Electrical, Milliamps, Millivolts};
pub use lattice::{Axis, Gravity, Module, Sign};
#[cfg(feature = "serde")]
pub(crate) use number::de;
#[cfg(feature = "serde")]
pub use number::{Number, NumberRangeError};
pub(crate) use range::ranged;
pub use range::RangeError;
pub use servo::{HipAngle, PulseWidth};
pub use side::{PerSide, Side};
pub use time::{Duration, Instant};
