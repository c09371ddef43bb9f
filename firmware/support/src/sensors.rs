//! A side's sensors through the drivers: the ADS7828, the MPU-6000 and (board A) the hip
//! encoder on one shared I2C bus, and the two switches. A device that does not answer gives
//! "no reading" (`None`), counted per device; the library decides what follows
//! (`mmic::sensors::frontend`, spec/decisions.toml `sensor-loss`).

use crate::control::{Reading, Sensors};
use crate::drivers::{ads7828::Ads7828, encoder::HipEncoder, mpu6000::Mpu6000};
use core::cell::RefCell;
use core::convert::Infallible;
use embedded_hal::digital::InputPin;
use embedded_hal::i2c::I2c;
use embedded_hal_bus::i2c::RefCellDevice;
use mmic::sensors::frontend::Raw;

/// A side's sensors on bus `I` with switches `P` (closed: low).
pub struct Side<'b, I, P> {
    adc: Ads7828<RefCellDevice<'b, I>>,
    imu: Mpu6000<RefCellDevice<'b, I>>,
    imu_ready: bool,
    encoder: Option<HipEncoder<RefCellDevice<'b, I>>>,
    switches: [P; 2],
    /// Failed reads: ADC, IMU, encoder.
    pub errors: [u32; 3],
}

impl<'b, I: I2c, P: InputPin<Error = Infallible>> Side<'b, I, P> {
    /// The devices at their fixed addresses; `hip`: the encoder is fitted (board A).
    pub fn new(bus: &'b RefCell<I>, switches: [P; 2], hip: bool) -> Self {
        use crate::drivers::{ads7828, encoder, mpu6000};
        Side {
            adc: Ads7828::new(RefCellDevice::new(bus), ads7828::ADDRESS),
            imu: Mpu6000::new(RefCellDevice::new(bus), mpu6000::ADDRESS),
            imu_ready: false,
            encoder: hip.then(|| HipEncoder::new(RefCellDevice::new(bus), encoder::ADDRESS)),
            switches,
            errors: [0; 3],
        }
    }
}

fn count<T, E>(r: Result<T, E>, errors: &mut u32) -> Option<T> {
    *errors = errors.saturating_add(r.is_err().into());
    r.ok()
}

/// A closed switch reads low (the pins cannot fail: `Infallible`).
fn closed(p: &mut impl InputPin<Error = Infallible>) -> bool {
    matches!(p.is_low(), Ok(true))
}

impl<I: I2c, P: InputPin<Error = Infallible>> Sensors for Side<'_, I, P> {
    fn read(&mut self) -> Reading {
        let [e_adc, e_imu, e_enc] = &mut self.errors;
        if !self.imu_ready {
            self.imu_ready = count(self.imu.init(), e_imu).is_some();
        }
        let accel = if self.imu_ready {
            count(self.imu.accel(), e_imu)
        } else {
            None
        };
        Reading {
            raw: Raw {
                adc: count(self.adc.read_all(), e_adc),
                accel,
                encoder: self.encoder.as_mut().and_then(|e| count(e.angle(), e_enc)),
            },
            arm_contracted: closed(&mut self.switches[0]),
            bolter_at_home: closed(&mut self.switches[1]),
        }
    }
}
