//! Motion generation (Section 6): the 15 configuration states of Table 5 and the 8 motion
//! primitives of Table 6.
//!
//! ```
//! use mmic::motion::{State, StateKind, Primitive};
//! assert_eq!(State::A.name(), "Xneg match");
//! assert_eq!(State::from_letter('e'), Some(State::E));
//! assert_eq!(State::E.kind(), StateKind::Turn);
//! assert_eq!(Primitive::from_number(4), Some(Primitive::BackExtend));
//! ```

mod primitive;
mod state;

pub use primitive::Primitive;
pub use state::{State, StateKind};
