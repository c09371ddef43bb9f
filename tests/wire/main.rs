//! Tables 2–4: the packets, their golden bytes, corruption, round trips, spec/ tables, and the property-test configuration.
//!
//! One test binary per area, each file a module: fewer binaries to link than one per file.

#[path = "../common/mod.rs"]
mod common;

mod corruption;
mod golden;
mod opcode;
mod proptest_config;
mod round_trip;
mod spec;
mod trait_emit;
