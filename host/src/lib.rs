//! Host side of mmic: the `mmic` command-line tool's logic (arguments and errors in [`cli`],
//! packets as JSON and hex in [`codec`], motion plans in [`motion`], and the generated review
//! pages of spec/ in [`pages`]), kept out of `main.rs` so tests can call it.

pub mod cfdp;
pub mod cli;
pub mod codec;
pub mod error;
pub mod exit;
pub mod fleet;
pub mod ground;
pub mod link;
pub mod motion;
pub mod opsui;
pub mod pages;
pub mod plan;
pub mod plot;
pub mod pus;
pub mod replay;
pub mod sdlscli;
pub mod serial;
pub mod sim;
pub mod simcli;
pub mod spec;
pub mod swarm;
pub mod xtce;
