//! Motion generation (Section 6): the 15 configuration states of Table 5, the 8 motion
//! primitives of Table 6, the reconfiguration map of Figure 9 computed from a geometric model
//! ([`geometry`], [`map`]), and shortest routes of primitives between states ([`route`]).
//!
//! ```
//! use mmic::motion::{State, StateKind, Primitive};
//! assert_eq!(State::A.name(), "Xneg match");
//! assert_eq!(State::from_letter('e'), Some(State::E));
//! assert_eq!(State::E.kind(), StateKind::Turn);
//! assert_eq!(Primitive::from_number(4), Some(Primitive::BackExtend));
//! ```

pub mod estimate;
pub mod figure9;
pub mod geometry;
pub mod map;
mod primitive;
pub mod route;
pub mod runner;
pub mod sequencer;
mod state;

pub use primitive::Primitive;
pub use state::{State, StateKind};
