//! The MMIC-I firmware's shared glue: moves bytes and readings between the ESP32's peripherals
//! and the `mmic` library's pure nodes, and decides nothing (every decision is in `mmic`).
//!
//! Hardware-free parts build on the host and are tested there with mocked peripherals
//! (`tests/`); the esp-hal parts are behind `cfg(target_arch = "riscv32")`.
#![no_std]

pub mod control;
pub mod counters;
pub mod drivers;
pub mod durable;
pub mod link;
pub mod net;
pub mod relay;
pub mod restart;
pub mod sensors;
pub mod server;

#[cfg(target_arch = "riscv32")]
pub mod chip;
#[cfg(target_arch = "riscv32")]
pub mod hw;
#[cfg(target_arch = "riscv32")]
pub mod wdt;

/// The A–B serial line's rate, baud.
pub const BAUD: u32 = 115_200;
