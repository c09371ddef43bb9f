//! Host side of mmic: the `mmic` command-line tool's logic (packet codec as JSON and hex, and
//! the generated review pages of spec/), kept out of `main.rs` so tests can call it.

pub mod codec;
pub mod motion;
pub mod pages;
