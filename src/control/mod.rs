//! Controllers (Section 5): open-loop interpolation for the arms and grippers, the hip's PI
//! controller, and the time budget of a single-module motion ([`deadline`]).
//!
//! ```
//! use mmic::control::interp::{Interpolator, Rate};
//! use mmic::units::PulseWidth;
//! let mut i = Interpolator::new(PulseWidth::new(1000).unwrap(), Rate::default());
//! i.set_target(PulseWidth::new(1050).unwrap(), 0);
//! assert_eq!(i.tick(20).micros(), 1010); // 10 µs per 20 ms period
//! assert_eq!(i.tick(200).micros(), 1050); // never past the target
//! assert!(i.done());
//! ```
// req: P5.1, P5.5

pub mod deadline;
pub mod hip;
pub mod interp;
