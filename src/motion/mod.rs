//! Motion generation (Section 6): shortest routes of primitives between states ([`route`]),
//! the sequencer that runs one primitive ([`sequencer`]) and the runner that chains them
//! ([`runner`]). The states, primitives and the map of Figure 9 they move over are the
//! vocabulary of [`crate::pose`], re-exported here under their old paths.
//!
//! ```
//! use mmic::motion::{State, StateKind, Primitive};
//! assert_eq!(State::A.name(), "Xneg match");
//! assert_eq!(State::from_letter('e'), Some(State::E));
//! assert_eq!(State::E.kind(), StateKind::Turn);
//! assert_eq!(Primitive::from_number(4), Some(Primitive::BackExtend));
//! ```
// req: P6.4, P6.5, P6.11

pub mod estimate;
pub mod figure9;
pub mod route;
pub mod runner;
pub mod sequencer;

pub use crate::pose::{geometry, map, Primitive, State, StateKind};
