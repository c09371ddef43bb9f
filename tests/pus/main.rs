//! PUS-C services (src/pus/) and the PUS gateway (src/node/server/gateway/): the code equals
//! spec/ccsds/, every command round-trips as a function, every bad input is refused by name.
//!
//! One test binary per area, each file a module.

#[path = "../common/mod.rs"]
mod common;

mod cop1_attack;
mod durable;
mod event;
mod frames;
mod function;
mod gateway;
mod housekeeping;
mod spec;
