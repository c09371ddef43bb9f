//! The hip's absolute magnetic encoder: an AS5600-style part on I2C, 12 bits, 4096 counts per
//! turn (`mmic::sensors::encoder`).
//!
//! STATUS (0x0B) holds MD (bit 5, magnet detected), ML (bit 4, too weak) and MH (bit 3, too
//! strong); RAW ANGLE is 0x0C (bits 11..8, upper nibble unused) and 0x0D (bits 7..0).
//! [`HipEncoder::angle`] reads STATUS first and fails without MD, so the shell passes "no
//! reading" rather than the last angle the chip latched.

use super::Error;
use embedded_hal::i2c::I2c;

/// The AS5600's fixed address.
pub const ADDRESS: u8 = 0x36;
/// STATUS bit: magnet detected.
pub const MD: u8 = 1 << 5;
/// STATUS bit: magnet too weak (AGC at maximum gain).
pub const ML: u8 = 1 << 4;
/// STATUS bit: magnet too strong (AGC at minimum gain).
pub const MH: u8 = 1 << 3;

const STATUS: u8 = 0x0B;
const RAW_ANGLE: u8 = 0x0C;

/// The hip encoder at one bus address.
#[derive(Debug)]
pub struct HipEncoder<I> {
    i2c: I,
    address: u8,
}

impl<I: I2c> HipEncoder<I> {
    /// The encoder at `address` (see [`ADDRESS`]). Nothing is sent: it needs no setup.
    pub fn new(i2c: I, address: u8) -> Self {
        HipEncoder { i2c, address }
    }

    /// STATUS's MD, ML and MH bits (the others masked off).
    pub fn status(&mut self) -> Result<u8, Error<I::Error>> {
        let mut s = [0u8; 1];
        self.i2c.write_read(self.address, &[STATUS], &mut s)?;
        Ok(s[0] & (MD | ML | MH))
    }

    /// The raw angle, 0..=4095, if STATUS has MD set (ML or MH alone is no magnet; with MD
    /// they only warn, and the angle is still returned); [`Error::NoMagnet`] otherwise.
    pub fn angle(&mut self) -> Result<u16, Error<I::Error>> {
        let status = self.status()?;
        if status & MD == 0 {
            return Err(Error::NoMagnet(status));
        }
        let mut b = [0u8; 2];
        self.i2c.write_read(self.address, &[RAW_ANGLE], &mut b)?;
        Ok(u16::from_be_bytes(b) & 0x0FFF)
    }

    /// Gives the bus back.
    pub fn release(self) -> I {
        self.i2c
    }
}
