//! Where the robot stands in the lattice, and how it gets from one stance to the next: the 15
//! configuration states of Table 5, the 8 motion primitives of Table 6, the geometric model
//! behind Figure 9 ([`geometry`]) and the reconfiguration map computed from it ([`map`]).
//!
//! This is vocabulary, not motion: a primitive or reconfiguration command names states, and
//! is only valid if the map has the move, so the command set ([`crate::command`]), the packets
//! and the motion generation ([`crate::motion`], which re-exports this module's items) all
//! speak it. Keeping it below them is what lets the command set be checked without the code
//! that executes it.
//!
//! ```
//! use mmic::pose::{State, StateKind, Primitive};
//! assert_eq!(State::A.name(), "Xneg match");
//! assert_eq!(State::from_letter('e'), Some(State::E));
//! assert_eq!(State::E.kind(), StateKind::Turn);
//! assert_eq!(Primitive::from_number(4), Some(Primitive::BackExtend));
//! ```
// req: P6.1, P6.6, P6.9

pub mod geometry;
pub mod map;
mod primitive;
mod state;

pub use primitive::Primitive;
pub use state::{State, StateKind};
