//! TI ADS7828: 8-channel, 12-bit SAR ADC on I2C (datasheet SBAS181C).
//!
//! A conversion is one write-then-read: the command byte `SD C2 C1 C0 PD1 PD0 X X`, then two
//! bytes back, MSB first, `0000 D11..D8` `D7..D0`. Single-ended (SD = 1) channel `n` is
//! selected by C2 = the low bit of `n` and C1 C0 = `n >> 1` (CH0 000, CH1 100, CH2 001, ...).
//! The board measures against the internal 2.5 V reference (`mmic::sensors::adc`), so
//! PD1 PD0 = 11: reference and converter stay on between conversions.

use super::Error;
use embedded_hal::i2c::I2c;

/// Address with A1 = A0 = 0 (`1001 0 A1 A0`); 0x49..=0x4B for the other strappings.
pub const ADDRESS: u8 = 0x48;
/// SD = 1 (single-ended), PD1 PD0 = 11 (internal reference on, converter on).
const BASE: u8 = 0b1000_1100;

/// The command byte that converts single-ended channel `ch` (0..=7, taken modulo 8).
pub const fn command(ch: u8) -> u8 {
    BASE | ((ch & 1) << 6) | (((ch >> 1) & 3) << 4)
}

/// An ADS7828 at one bus address.
#[derive(Debug)]
pub struct Ads7828<I> {
    i2c: I,
    address: u8,
}

impl<I: I2c> Ads7828<I> {
    /// The converter at `address` (see [`ADDRESS`]). Nothing is sent: it needs no setup.
    pub fn new(i2c: I, address: u8) -> Self {
        Ads7828 { i2c, address }
    }

    /// Converts channel `ch` (0..=7) and returns its 12-bit code.
    pub fn read(&mut self, ch: usize) -> Result<u16, Error<I::Error>> {
        if ch > 7 {
            return Err(Error::Channel(ch));
        }
        let mut buf = [0u8; 2];
        self.i2c
            .write_read(self.address, &[command(ch as u8)], &mut buf)?;
        match u16::from_be_bytes(buf) {
            code @ 0..=0x0FFF => Ok(code),
            bad => Err(Error::Frame(bad)),
        }
    }

    /// The codes of CH0..CH7, in the order of `mmic::sensors::adc::Channel::ALL`; the first
    /// failing channel's error otherwise.
    pub fn read_all(&mut self) -> Result<[u16; 8], Error<I::Error>> {
        let mut codes = [0u16; 8];
        for (ch, code) in codes.iter_mut().enumerate() {
            *code = self.read(ch)?;
        }
        Ok(codes)
    }

    /// Gives the bus back.
    pub fn release(self) -> I {
        self.i2c
    }
}
