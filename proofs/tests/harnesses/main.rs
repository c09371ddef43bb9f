//! Every bolero harness of the workspace: unit tests here, fuzz targets under `cargo bolero test`, proofs under `cargo kani --tests` (see proofs/README.md).
//!
//! One test binary per area, each file a module: fewer binaries to link than one per file.

mod bolter_executor;
mod ccsds;
mod control_hip;
mod control_interp;
mod deframer;
mod ledger;
mod motion_sequencer;
mod node;
mod packets;
mod pus;
mod safety_timers;
mod sensors_frontend;
mod sensors_moving_average;
