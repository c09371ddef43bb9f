//! Property harnesses for `mmic`, in the bolero pattern of the project's DEVELOPERS brief:
//! each `#[test]` is a randomised unit test under `cargo test`, a coverage-guided fuzz target
//! under `cargo bolero test`, and a bounded proof under `cargo kani --tests` (where Kani is
//! installed; it is not on the development machines, so no Kani result is claimed here).
//!
//! The harnesses live in `tests/`, one file per area, each named after the property it checks.
#![no_std]
#![forbid(unsafe_code)]
