//! One side's sensor front end: raw readings in, the filtered values the board node takes out.
//!
//! Section 2: "All the raw sensor data is sent to a moving average calculator, with a window
//! size of 50 samples." Here that means the ADS7828's eight codes and the IMU's three
//! accelerations, one sample per control tick. The hip encoder is not averaged: an average of
//! angles across the 0°/360° seam is wrong (359° and 1° would give 180°), and the hip
//! controller smooths its own velocity estimate (spec/decisions.toml, `sensor-filtering`).
//!
//! ```
//! use mmic::sensors::frontend::{Frontend, Raw};
//! use mmic::units::{Axis, Sign};
//!
//! let mut f = Frontend::<50>::new(Default::default());
//! // 10.0 V battery (code 2730 of 15 V full scale), gravity along −Y.
//! let raw = Raw { adc: [2730, 0, 0, 0, 0, 0, 0, 0], accel: Some([10, -16384, 0]), encoder: 2048 };
//! let out = f.push(&raw);
//! assert_eq!(out.electrical.v_bat, 10_000);
//! assert_eq!(out.gravity.map(|g| (g.axis, g.sign)), Some((Axis::Y, Sign::Negative)));
//! assert_eq!(out.hip.centidegrees(), 18000);
//! ```

use super::adc::{self, Scaling};
use super::{encoder, imu, MovingAverage};
use crate::units::{Electrical, Gravity, HipAngle};

/// The paper's window: 50 samples (Section 2).
pub const WINDOW: usize = 50;

/// Front-end configuration.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Default)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Config {
    /// ADS7828 channel scaling.
    pub scaling: Scaling,
    /// Raw encoder reading at hip 0° (board A only; board B has no encoder).
    pub encoder_zero: u16,
}

/// One tick's raw readings of a side.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Raw {
    /// ADS7828 codes, CH0..CH7 (12-bit; larger values are clamped by the scaling).
    pub adc: [u16; 8],
    /// IMU accelerations (X, Y, Z); `None` when the IMU did not answer this tick.
    pub accel: Option<[i16; 3]>,
    /// Raw hip encoder reading (board A; ignored on board B).
    pub encoder: u16,
}

/// The filtered readings a board node takes as input.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Filtered {
    /// Voltages and currents from the averaged codes.
    pub electrical: Electrical,
    /// Gravity direction from the averaged accelerations; `None` before any IMU sample, or
    /// while they average to zero.
    pub gravity: Option<Gravity>,
    /// Hip angle from this tick's encoder reading.
    pub hip: HipAngle,
}

/// A side's `N`-sample moving averages (the paper's `N` is 50).
#[derive(Debug, Clone, PartialEq, Eq, Hash)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Frontend<const N: usize> {
    cfg: Config,
    adc: [MovingAverage<N>; 8],
    /// Accelerations offset by 32768 so that the unsigned filter averages them exactly.
    accel: [MovingAverage<N>; 3],
}

/// Offsets an i16 into u16 order-preservingly (−32768 → 0).
const fn unsign(a: i16) -> u16 {
    (a as u16) ^ 0x8000
}

/// Inverse of [`unsign`].
const fn resign(u: u16) -> i16 {
    (u ^ 0x8000) as i16
}

impl<const N: usize> Frontend<N> {
    /// Empty filters.
    pub const fn new(cfg: Config) -> Self {
        Frontend {
            cfg,
            adc: [const { MovingAverage::new() }; 8],
            accel: [const { MovingAverage::new() }; 3],
        }
    }

    /// Feeds one tick's raw readings and returns the filtered values. A tick without an IMU
    /// sample leaves the acceleration averages as they were.
    pub fn push(&mut self, raw: &Raw) -> Filtered {
        for (f, &code) in self.adc.iter_mut().zip(raw.adc.iter()) {
            f.push(code);
        }
        if let Some(accel) = raw.accel {
            for (f, &a) in self.accel.iter_mut().zip(accel.iter()) {
                f.push(unsign(a));
            }
        }
        self.filtered(raw.encoder)
    }

    /// The filtered values now, with `encoder` as the hip reading.
    pub fn filtered(&self, encoder: u16) -> Filtered {
        let codes = self.adc.each_ref().map(|f| f.mean().unwrap_or(0));
        let accel = if self.accel[0].is_empty() {
            None
        } else {
            Some(
                self.accel
                    .each_ref()
                    .map(|f| resign(f.mean().unwrap_or(0x8000))),
            )
        };
        Filtered {
            electrical: adc::electrical(&self.cfg.scaling, codes),
            gravity: accel.and_then(imu::gravity),
            hip: encoder::hip_angle(encoder, self.cfg.encoder_zero),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn raw(code: u16) -> Raw {
        Raw {
            adc: [code; 8],
            accel: Some([0, 0, 16384]),
            encoder: 0,
        }
    }

    #[test]
    fn a_step_reaches_the_output_after_exactly_the_window() {
        let mut f = Frontend::<50>::new(Config::default());
        for _ in 0..50 {
            f.push(&raw(0));
        }
        let full = adc::electrical(&Scaling::default(), [4000; 8]);
        for k in 1..=50u32 {
            let out = f.push(&raw(4000));
            let mean = (4000 * k / 50) as u16;
            assert_eq!(
                out.electrical,
                adc::electrical(&Scaling::default(), [mean; 8])
            );
            assert_eq!(out.electrical == full, k == 50, "k = {k}");
        }
    }

    #[test]
    fn accelerations_average_with_their_sign() {
        assert_eq!(resign(unsign(-32768)), -32768);
        assert!(unsign(-1) < unsign(0) && unsign(0) < unsign(1));
        let mut f = Frontend::<4>::new(Config::default());
        let g = |f: &mut Frontend<4>, a| {
            f.push(&Raw {
                adc: [0; 8],
                accel: Some(a),
                encoder: 0,
            })
            .gravity
        };
        assert_eq!(
            g(&mut f, [-16000, 0, 0]).map(|g| g.axis),
            Some(crate::units::Axis::X)
        );
        // A single opposite sample does not flip the averaged direction.
        let out = g(&mut f, [0, 0, 9000]);
        assert_eq!(out.map(|g| g.axis), Some(crate::units::Axis::X));
    }

    #[test]
    fn no_imu_sample_no_gravity_and_a_gap_keeps_the_average() {
        let mut f = Frontend::<50>::new(Config::default());
        let mut r = raw(0);
        r.accel = None;
        assert_eq!(f.push(&r).gravity, None);
        f.push(&raw(0));
        let before = f.filtered(0);
        assert!(before.gravity.is_some());
        assert_eq!(f.push(&r).gravity, before.gravity);
    }
}
