//! Section 7, Tables 7 and 8: the supervisor, exhaustively and against an oracle, and equal to spec/modes.toml.
//!
//! One test binary per area, each file a module: fewer binaries to link than one per file.

#[path = "../common/mod.rs"]
mod common;

mod safety_exhaustive;
mod safety_oracle;
mod safety_spec;
