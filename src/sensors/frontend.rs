//! One side's sensor front end: raw readings in, the filtered values the board node takes out.
//!
//! Section 2: "All the raw sensor data is sent to a moving average calculator, with a window
//! size of 50 samples." Here that means the ADS7828's eight codes and the IMU's three
//! accelerations, one sample per control tick. The hip encoder is not averaged: an average of
//! angles across the 0°/360° seam is wrong (359° and 1° would give 180°), and the hip
//! controller smooths its own velocity estimate. Nor are the arms' contraction switches and the
//! bolters' home switches, digital inputs that do not pass through this front end at all (the
//! boards take them as `arm_contracted` and `bolter_at_home`; spec/decisions.toml,
//! `sensor-filtering`).
//!
//! A device that does not answer gives no reading (`None`), never a made-up one. What follows
//! is decided here, in one place (spec/decisions.toml, `sensor-loss`): a missing ADC or IMU
//! sample leaves its averages as they were, for at most [`Config::loss_ticks`] ticks in a row
//! (one window); past that the ADC is reported [`Lost`] (the board raises
//! `Fault::SensorLoss`) and the IMU's stale average is dropped (gravity unknown). A missing
//! hip reading is `hip: None` at once — the hip is not steered blind — and [`Lost`] after as
//! many ticks. Before its first sample a device counts as lost.
//!
//! ```
//! use mmic::sensors::frontend::{Frontend, Raw};
//! use mmic::units::{Axis, Sign};
//!
//! let mut f = Frontend::<50>::new(Default::default());
//! // 10.0 V battery (code 2730 of 15 V full scale), gravity along −Y.
//! let raw = Raw {
//!     adc: Some([2730, 0, 0, 0, 0, 0, 0, 0]),
//!     accel: Some([10, -16384, 0]),
//!     encoder: Some(2048),
//! };
//! let out = f.push(&raw);
//! assert_eq!(out.electrical.v_bat, 10_000);
//! assert_eq!(out.gravity.map(|g| (g.axis, g.sign)), Some((Axis::Y, Sign::Negative)));
//! assert_eq!(out.hip.map(|h| h.centidegrees()), Some(18000));
//! assert!(!out.lost.any());
//!
//! // The ADC and the encoder stop answering: the averages stand, the hip is unknown at once…
//! let silent = Raw { adc: None, accel: None, encoder: None };
//! let out = f.push(&silent);
//! assert_eq!((out.electrical.v_bat, out.hip, out.lost.any()), (10_000, None, false));
//! // …and after a whole window of silence both are lost.
//! for _ in 1..50 {
//!     f.push(&silent);
//! }
//! assert!(f.push(&silent).lost.adc && f.lost().encoder);
//! ```
// req: P2.10, D:sensor-loss

use super::adc::{self, Scaling};
use super::{encoder, imu, Averages};
use crate::units::{Electrical, Gravity, HipAngle};

/// The paper's window: 50 samples (Section 2).
pub const WINDOW: usize = 50;

/// Front-end configuration.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Config {
    /// ADS7828 channel scaling.
    pub scaling: Scaling,
    /// Raw encoder reading at hip 0° (board A only; board B has no encoder).
    pub encoder_zero: u16,
    /// The side has a hip encoder (board A): its silence counts as a loss. Board B: `false`.
    pub hip_encoder: bool,
    /// Ticks in a row without a reading after which a device is lost. Default 50: one
    /// window of the moving average, 500 ms at the 10 ms tick — an average older than its
    /// own window no longer describes the present.
    pub loss_ticks: u16,
}

impl Default for Config {
    /// Board A's: default scaling, encoder zero 0, with the hip encoder, 50 ticks.
    fn default() -> Config {
        Config {
            scaling: Scaling::default(),
            encoder_zero: 0,
            hip_encoder: true,
            loss_ticks: u16::try_from(WINDOW).unwrap_or(u16::MAX),
        }
    }
}

/// One tick's raw readings of a side; `None` where the device did not answer.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Raw {
    /// ADS7828 codes, CH0..CH7 (12-bit; larger values are clamped by the scaling).
    pub adc: Option<[u16; 8]>,
    /// IMU accelerations (X, Y, Z).
    pub accel: Option<[i16; 3]>,
    /// Raw hip encoder reading (board A; ignored on board B).
    pub encoder: Option<u16>,
}

/// Devices that gave no reading for [`Config::loss_ticks`] ticks in a row (or none yet).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Default)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub struct Lost {
    /// The ADS7828: every voltage and current of the side is stale.
    pub adc: bool,
    /// The hip encoder (board A).
    pub encoder: bool,
}

impl Lost {
    /// Nothing lost.
    pub const NONE: Lost = Lost {
        adc: false,
        encoder: false,
    };

    /// Some device is lost.
    pub const fn any(self) -> bool {
        self.adc || self.encoder
    }
}

/// The filtered readings a board node takes as input.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Filtered {
    /// Voltages and currents from the averaged codes: the last samples received, at most
    /// `loss_ticks` old unless `lost.adc` (all zero before the first sample).
    pub electrical: Electrical,
    /// Gravity direction from the averaged accelerations; `None` before any IMU sample, after
    /// `loss_ticks` ticks without one, or while they average to zero.
    pub gravity: Option<Gravity>,
    /// Hip angle from this tick's encoder reading; `None` when there was none.
    pub hip: Option<HipAngle>,
    /// Devices silent for too long.
    pub lost: Lost,
}

/// A side's `N`-sample moving averages (the paper's `N` is 50), and how long each device has
/// been silent.
#[derive(Debug, Clone, PartialEq, Eq, Hash)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Frontend<const N: usize> {
    cfg: Config,
    /// The eight ADC channels, sampled together (one slot index for all: issue 40).
    adc: Averages<N, 8>,
    /// Accelerations offset by 32768 so that the unsigned filter averages them exactly.
    accel: Averages<N, 3>,
    /// Ticks in a row without a reading (saturating), per device: ADC, IMU, encoder.
    silent: Silence,
}

#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
struct Silence {
    adc: u16,
    imu: u16,
    encoder: u16,
}

/// Offsets an i16 into u16 order-preservingly (−32768 → 0).
const fn unsign(a: i16) -> u16 {
    a.cast_unsigned() ^ 0x8000
}

/// Inverse of [`unsign`].
const fn resign(u: u16) -> i16 {
    (u ^ 0x8000).cast_signed()
}

/// One more tick of silence, or none when the device answered.
const fn count(silent: u16, answered: bool) -> u16 {
    if answered {
        0
    } else {
        silent.saturating_add(1)
    }
}

impl<const N: usize> Frontend<N> {
    /// Empty filters; every device lost until its first reading.
    pub const fn new(cfg: Config) -> Self {
        Frontend {
            cfg,
            adc: Averages::new(),
            accel: Averages::new(),
            silent: Silence {
                adc: u16::MAX,
                imu: u16::MAX,
                encoder: u16::MAX,
            },
        }
    }

    /// Feeds one tick's raw readings and returns the filtered values. A missing ADC or IMU
    /// sample leaves its averages as they were; after `loss_ticks` missing samples in a row
    /// the IMU's averages are dropped and the ADC is reported lost.
    pub fn push(&mut self, raw: &Raw) -> Filtered {
        self.silent = Silence {
            adc: count(self.silent.adc, raw.adc.is_some()),
            imu: count(self.silent.imu, raw.accel.is_some()),
            encoder: count(self.silent.encoder, raw.encoder.is_some()),
        };
        if let Some(codes) = raw.adc {
            self.adc.push(codes);
        }
        if let Some(accel) = raw.accel {
            self.accel.push(accel.map(unsign));
        } else if self.silent.imu >= self.cfg.loss_ticks {
            self.accel = Averages::new();
        }
        self.filtered(raw.encoder)
    }

    /// The devices silent for `loss_ticks` ticks in a row (or not heard yet).
    pub const fn lost(&self) -> Lost {
        Lost {
            adc: self.silent.adc >= self.cfg.loss_ticks,
            encoder: self.cfg.hip_encoder && self.silent.encoder >= self.cfg.loss_ticks,
        }
    }

    /// The filtered values now, with `encoder` as the hip reading.
    pub fn filtered(&self, encoder: Option<u16>) -> Filtered {
        // All zero before the first ADC sample; the IMU's channels are empty together.
        let codes = self.adc.means_or([0; 8]);
        let accel = self.accel.means().map(|m| m.map(resign));
        Filtered {
            electrical: adc::electrical(&self.cfg.scaling, codes),
            gravity: accel.and_then(imu::gravity),
            hip: encoder.map(|e| encoder::hip_angle(e, self.cfg.encoder_zero)),
            lost: self.lost(),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn raw(code: u16) -> Raw {
        Raw {
            adc: Some([code; 8]),
            accel: Some([0, 0, 16384]),
            encoder: Some(0),
        }
    }

    // req: P2.10
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

    // req: P2.5
    #[test]
    fn accelerations_average_with_their_sign() {
        assert_eq!(resign(unsign(-32768)), -32768);
        assert!(unsign(-1) < unsign(0) && unsign(0) < unsign(1));
        let mut f = Frontend::<4>::new(Config::default());
        let g = |f: &mut Frontend<4>, a| {
            f.push(&Raw {
                adc: Some([0; 8]),
                accel: Some(a),
                encoder: Some(0),
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

    // req: P2.5
    #[test]
    fn no_imu_sample_no_gravity_and_a_gap_keeps_the_average() {
        let mut f = Frontend::<50>::new(Config::default());
        let mut r = raw(0);
        r.accel = None;
        assert_eq!(f.push(&r).gravity, None);
        f.push(&raw(0));
        let before = f.filtered(Some(0));
        assert!(before.gravity.is_some());
        assert_eq!(f.push(&r).gravity, before.gravity);
    }

    // req: D:sensor-loss
    #[test]
    fn a_device_is_lost_after_exactly_loss_ticks_silent_ticks_and_found_at_its_next_reading() {
        let cfg = Config {
            loss_ticks: 5,
            ..Config::default()
        };
        let mut f = Frontend::<50>::new(cfg);
        assert_eq!(
            f.lost(),
            Lost {
                adc: true,
                encoder: true
            },
            "not heard yet"
        );
        let out = f.push(&raw(1000));
        assert_eq!(out.lost, Lost::NONE);
        let full = out.electrical;
        for k in 1..=6u16 {
            let out = f.push(&Raw {
                adc: None,
                accel: None,
                encoder: None,
            });
            assert_eq!(out.lost.adc, k >= 5, "k = {k}");
            assert_eq!(out.lost.encoder, k >= 5, "k = {k}");
            assert_eq!(out.hip, None);
            // The stale average stands (it is never replaced by an invented value)…
            assert_eq!(out.electrical, full);
            // …the IMU's is dropped once lost.
            assert_eq!(out.gravity.is_some(), k < 5, "k = {k}");
        }
        let out = f.push(&Raw {
            encoder: None,
            ..raw(1000)
        });
        assert_eq!(
            out.lost,
            Lost {
                adc: false,
                encoder: true
            }
        );
        assert!(
            out.gravity.is_some(),
            "a new IMU sample gives gravity again"
        );
        assert_eq!(f.push(&raw(1000)).lost, Lost::NONE);
    }

    // req: P4.2
    #[test]
    fn a_side_without_a_hip_encoder_never_loses_it() {
        let cfg = Config {
            hip_encoder: false,
            ..Config::default()
        };
        let mut f = Frontend::<50>::new(cfg);
        for _ in 0..200 {
            let out = f.push(&Raw {
                encoder: None,
                ..raw(7)
            });
            assert_eq!(out.lost, Lost::NONE);
        }
    }
}
