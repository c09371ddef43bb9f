//! The library held to spec/'s tables, one binary: a module per area, as in the library's own
//! tests (tests/library.rs), whose areas these checks were part of until issue 40.
//!
//! - `wire`: Tables 2–4, the packets and the command set, field by field and cell by cell
//!   (spec/packets/, spec/commands.toml, spec/faults.toml);
//! - `pus`: the PUS-C services, functions and housekeeping (spec/ccsds/);
//! - `control`: the paper's hardware facts (spec/hardware.toml) and the servos'
//!   (spec/control/servos.toml);
//! - `motion`: Tables 5 and 6, the states, primitives and reconfigurations (spec/motion/);
//! - `node`: the boards' defaults (spec/boards.toml);
//! - `safety`: Tables 7 and 8, the modes (spec/modes.toml).
//!
//! Run one area with its module's name: `cargo test -p mmic-spec-check wire::`. Files are read
//! from the repository's root, two levels above this package (`ROOT`).

/// The repository's root: this package is spec/check/.
pub const ROOT: &str = concat!(env!("CARGO_MANIFEST_DIR"), "/../..");

mod wire {
    mod spec;
}
mod pus {
    mod spec;
}
mod control {
    mod hardware;
    mod servos_spec;
}
mod motion {
    mod motion_tables;
}
mod node {
    mod node_spec;
}
mod safety {
    mod safety_spec;
}
