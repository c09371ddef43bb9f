//! The library's integration tests, one binary: a module per area, each a directory of files.
//!
//! - `wire`: Tables 2–4, the packets: golden bytes, corruption, round trips, and the
//!   property-test configuration;
//! - `ccsds`: CCSDS space packets, PUS-C headers, transfer frames, SDLS and CFDP, against the
//!   standards, spec/ccsds/ and the `spacepackets` crate, and the conformance statements (PICS);
//! - `pus`: the PUS-C services and the PUS gateway, the ground's data link and COP-1;
//! - `control`: Sections 2 and 5, the hip controller, the sensor front end and the bolter;
//! - `motion`: Section 6, the map, plans, estimation and the sequencer;
//! - `node`: Sections 3 and 4, boards A and B as nodes, and the two-core hand-off;
//! - `safety`: Section 7, the supervisor, exhaustively and against an oracle.
//!
//! One binary rather than one per area (issue 40): the seven compiled the same generic code
//! (proptest's runner, std's collections, the library's generics) seven times, at the opt-level
//! the exhaustive walks need. One build took 84.6 CPU-s against 97.9 for the seven, and the run,
//! its long checks spread over libtest's two threads, 27.6 s against 30.4 s. Run one area with
//! its module's name: `cargo test -p mmic --test library wire::`.
//!
//! The checks of the code against spec/'s tables (Tables 1–8, the hardware, the boards, the
//! servos, the PUS services) are the package `mmic-spec-check` (spec/check/): built at opt-level
//! 0 beside this binary rather than inside it (issue 40).

mod common;

mod ccsds;
mod control;
mod motion;
mod node;
mod pus;
mod safety;
mod wire;
