//! Blocking drivers for the controller board's I2C sensors, on `embedded_hal::i2c::I2c` 1.0:
//! no_std, no allocation, no panics. Each returns the raw value the library's sensor front end
//! (`mmic::sensors`) takes, or an [`Error`], never a stale or made-up reading.
//!
//! - [`ads7828::Ads7828`]: the eight single-ended 12-bit codes, CH0..CH7 (`Raw::adc`).
//! - [`mpu6000::Mpu6000`]: accelerations X, Y, Z at ±2 g, 16384 per g (`Raw::accel`).
//! - [`encoder::HipEncoder`]: the hip's AS5600-style 12-bit raw angle, 4096 per turn
//!   (`Raw::encoder`), only while the magnet is detected.
//!
//! All three share one bus: Section 2 of the paper reads every sensor "through the i2c
//! protocol", so the MPU-6000 is driven over I2C too, not over its SPI port.
//!
//! # The crates.io drivers, judged (and not used)
//! - `ads7828` 0.1.1 (Feb 2023, two releases the same day, undocumented): embedded-hal 0.2;
//!   a fixed 100 ms delay per channel, and it returns `f32` volts, not the raw code. Its
//!   command bytes are right (PD0 = 1, the internal reference bit ORed in), but the bus
//!   error is the bare `E` and there is no all-channel read. Rejected.
//! - `mpu6000` 0.3.0: embedded-hal 0.2 and built around SPI; `verify()` returns `bool`, not
//!   an error, and `read_temperature` reads the accelerometer registers. Rejected.
//! - `as5600` 0.8.0: embedded-hal 1.0, no_std, no alloc, typed `Error<E>`, mock-tested;
//!   `raw_angle()` masks to 12 bits. It fits, but a status without MD (magnet too weak or
//!   too strong, not detected) comes back as `Ok`, and no magnet at all as a parse error,
//!   so the check below would be rewritten on top of it anyway, while it brings
//!   num-derive (a proc macro, syn) and a second error type for two register reads. The
//!   driver here does the same traffic (0x0B, then 0x0C..0x0D) and is a drop-in swap if
//!   the encoder part gets a maintained crate of its own.

pub mod ads7828;
pub mod encoder;
pub mod mpu6000;

/// A driver's failure. `E` is the bus's error.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Error<E> {
    /// The I2C transfer failed (no acknowledge, arbitration loss, ...).
    Bus(E),
    /// ADS7828: no such channel (0..=7).
    Channel(usize),
    /// ADS7828: a result with a non-zero upper nibble, which the part never sends.
    Frame(u16),
    /// MPU-6000: WHO_AM_I read this instead of 0x68.
    WhoAmI(u8),
    /// Hip encoder: STATUS (its MD, ML, MH bits) says no magnet is detected.
    NoMagnet(u8),
}

impl<E> From<E> for Error<E> {
    fn from(e: E) -> Self {
        Error::Bus(e)
    }
}
