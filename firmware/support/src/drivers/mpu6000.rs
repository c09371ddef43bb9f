//! InvenSense MPU-6000 6-axis IMU, over I2C: only the accelerometer is read (the gravity
//! direction, `mmic::sensors::imu::gravity`).
//!
//! It powers up asleep. [`Mpu6000::init`] checks WHO_AM_I, wakes it on the X-gyro PLL clock
//! and sets the accelerometer to ±2 g (AFS_SEL = 0: 16384 per g, the 1 g of the simulator's
//! plant and the front end's examples; `gravity` itself only compares the axes' magnitudes).
//! [`Mpu6000::accel`] reads ACCEL_XOUT_H..ACCEL_ZOUT_L in one burst.

use super::Error;
use embedded_hal::i2c::I2c;

/// Address with AD0 low; 0x69 with AD0 high.
pub const ADDRESS: u8 = 0x68;
/// WHO_AM_I's value whatever AD0 is.
pub const WHO_AM_I_VALUE: u8 = 0x68;

const ACCEL_CONFIG: u8 = 0x1C;
const ACCEL_XOUT_H: u8 = 0x3B;
const PWR_MGMT_1: u8 = 0x6B;
const WHO_AM_I: u8 = 0x75;
/// SLEEP = 0, CLKSEL = 1 (PLL on the X gyro, the datasheet's recommended clock).
const WAKE_PLL_X: u8 = 0x01;
/// AFS_SEL = 0 (±2 g), no self-test.
const RANGE_2G: u8 = 0x00;

/// An MPU-6000 at one bus address.
#[derive(Debug)]
pub struct Mpu6000<I> {
    i2c: I,
    address: u8,
}

impl<I: I2c> Mpu6000<I> {
    /// The IMU at `address` (see [`ADDRESS`]). Nothing is sent until [`Mpu6000::init`].
    pub fn new(i2c: I, address: u8) -> Self {
        Mpu6000 { i2c, address }
    }

    /// Checks WHO_AM_I (before writing anything), wakes the part and selects ±2 g.
    pub fn init(&mut self) -> Result<(), Error<I::Error>> {
        let mut who = [0u8; 1];
        self.i2c.write_read(self.address, &[WHO_AM_I], &mut who)?;
        if who[0] != WHO_AM_I_VALUE {
            return Err(Error::WhoAmI(who[0]));
        }
        self.i2c.write(self.address, &[PWR_MGMT_1, WAKE_PLL_X])?;
        self.i2c.write(self.address, &[ACCEL_CONFIG, RANGE_2G])?;
        Ok(())
    }

    /// Accelerations X, Y, Z (two's complement, big-endian registers), 16384 per g.
    pub fn accel(&mut self) -> Result<[i16; 3], Error<I::Error>> {
        let mut b = [0u8; 6];
        self.i2c.write_read(self.address, &[ACCEL_XOUT_H], &mut b)?;
        Ok([
            i16::from_be_bytes([b[0], b[1]]),
            i16::from_be_bytes([b[2], b[3]]),
            i16::from_be_bytes([b[4], b[5]]),
        ])
    }

    /// Gives the bus back.
    pub fn release(self) -> I {
        self.i2c
    }
}
