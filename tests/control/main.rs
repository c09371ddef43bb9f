//! Sections 2 and 5, Figures 8 and 10: the hip controller, the sensor front end and the bolter.
//!
//! One test binary per area, each file a module: fewer binaries to link than one per file.

#[path = "../common/mod.rs"]
mod common;

mod bolter_handshake;
mod bolter_statistics;
mod control_hip;
mod sensors;
