//! The `mmic` tool: the packet codec, JSON shapes, review pages, plan files and plots.
//!
//! One test binary per area, each file a module: fewer binaries to link than one per file.

mod cli;
mod json_shape;
mod link;
mod pages;
mod plan;
mod plot;
mod pus;
mod xtce;
