//! Section 7, Tables 7 and 8: the supervisor, exhaustively and against an oracle, and equal to spec/modes.toml.

mod safety_exhaustive;
mod safety_oracle;
