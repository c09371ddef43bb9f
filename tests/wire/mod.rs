//! Tables 2–4: the packets, their golden bytes, corruption, round trips, and the property-test
//! configuration (the code against spec/'s tables: spec/check/tests/wire/spec.rs).

mod corruption;
mod golden;
mod opcode;
mod proptest_config;
mod round_trip;
mod trait_emit;
