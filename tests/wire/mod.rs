//! Tables 2–4: the packets, their golden bytes, corruption, round trips, spec/ tables, and the property-test configuration.

mod corruption;
mod golden;
mod opcode;
mod proptest_config;
mod round_trip;
mod spec;
mod trait_emit;
