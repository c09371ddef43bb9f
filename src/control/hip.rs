//! The hip's PI controller (Section 5): velocity mode at 10°/s while the hip is more than 3°
//! from its target, position mode within 3°, velocity estimated from successive encoder
//! readings with exponential smoothing. The estimate runs in both modes, but only the velocity
//! law uses it: the position law is a PI on the angle error, which meets the settling and
//! overshoot bounds of spec/control/hip.md without a velocity term (the paper's "again
//! estimating velocity" read in spec/decisions.toml, `hip-position-law`). Beyond the paper, which
//! names a PI velocity controller only, the velocity law adds a feed-forward term, the pulse
//! offset the servo needs for 10°/s (`Config::servo_gain`; spec/decisions.toml,
//! `hip-velocity-feed-forward`). Fixed-point integers throughout (the ESP32-C3 has no FPU);
//! the output is saturated to the configured pulse range and the integrator is clamped and
//! frozen while the output saturates (anti-windup).
//!
//! Units: angles and angle errors in 0.01°, velocities in 0.01°/s, the output a pulse width in
//! µs for the continuous-rotation hip servo (1500 µs = stop).
//!
//! ```
//! use mmic::control::hip::{Config, HipController, Mode};
//! use mmic::units::HipAngle;
//! let mut c = HipController::new(Config::default());
//! let target = HipAngle::new(9000).unwrap();
//! let out = c.step(target, HipAngle::new(0).unwrap(), 0);
//! assert_eq!(c.mode(), Mode::Velocity); // 90° away: turn at 10°/s
//! assert!(out.micros() > 1500);
//! ```
// req: P5.5, P5.6, P5.7, P5.8, D:hip-position-law, D:hip-velocity-feed-forward

use crate::units::widen::to_u32;
use crate::units::Instant;
use crate::units::{HipAngle, PulseWidth};

/// Controller settings.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Config {
    /// Switch to position mode within this error, 0.01°. Paper: 3°.
    pub position_band: i32,
    /// Velocity-mode speed, 0.01°/s. Paper: 10°/s.
    pub speed: i32,
    /// Servo speed per µs away from the stop pulse, 0.01°/s per µs, for the velocity law's
    /// feed-forward (the project's, not the paper's: spec/decisions.toml,
    /// `hip-velocity-feed-forward`); 0 switches it off. Default 10.
    pub servo_gain: i32,
    /// Velocity mode: proportional gain, µs per (0.01°/s), Q8. Default 13/256 ≈ 0.05.
    pub kp_velocity_q8: i32,
    /// Velocity mode: integral gain, µs per (0.01°/s · s), Q8. Default 51/256 ≈ 0.2.
    pub ki_velocity_q8: i32,
    /// Position mode: proportional gain, µs per 0.01°, Q8. Default 85/256 ≈ 0.33.
    pub kp_position_q8: i32,
    /// Position mode: integral gain, µs per (0.01° · s), Q8. Default 128/256 = 0.5.
    pub ki_position_q8: i32,
    /// Largest pulse offset from the stop pulse, µs (≤ 1000). Default 300.
    pub max_offset_us: i32,
    /// Velocity smoothing: each reading moves the estimate by 1/2^shift of the difference. Default 2.
    pub smoothing_shift: u32,
}

impl Default for Config {
    fn default() -> Config {
        Config {
            position_band: 300,
            speed: 1000,
            servo_gain: 10,
            kp_velocity_q8: 13,
            ki_velocity_q8: 51,
            kp_position_q8: 85,
            ki_position_q8: 128,
            max_offset_us: 300,
            smoothing_shift: 2,
        }
    }
}

/// Which law is active.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum Mode {
    /// |error| > band: track ±speed.
    Velocity,
    /// |error| ≤ band: track the angle.
    Position,
}

/// The controller's state.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct HipController {
    cfg: Config,
    last: Option<(Instant, HipAngle)>,
    velocity: i32,
    integral_q8: i32,
    mode: Mode,
}

/// Signed shortest difference `to − from`, in (−18000, 18000].
pub const fn angle_error(from: HipAngle, to: HipAngle) -> i32 {
    // Exact, so the wrapping operations (which cost nothing on the board's control tick)
    // never wrap: both angles are in 0..36000 (their type's range), `d` in (−36000, 36000) and
    // the results in (−18000, 18000].
    let d = centidegrees(to).wrapping_sub(centidegrees(from));
    if d > 18000 {
        d.wrapping_sub(36000)
    } else if d <= -18000 {
        d.wrapping_add(36000)
    } else {
        d
    }
}

/// The angle as a signed number of centidegrees, for differences.
const fn centidegrees(a: HipAngle) -> i32 {
    to_u32(a.centidegrees().to_le_bytes()).cast_signed()
}

const STOP_US: u16 = 1500;

impl HipController {
    /// At rest, no history.
    pub const fn new(cfg: Config) -> HipController {
        HipController {
            cfg,
            last: None,
            velocity: 0,
            integral_q8: 0,
            mode: Mode::Position,
        }
    }

    /// Current law.
    pub const fn mode(&self) -> Mode {
        self.mode
    }

    /// Smoothed velocity estimate, 0.01°/s.
    pub const fn velocity(&self) -> i32 {
        self.velocity
    }

    /// Updates the velocity estimate from the reading `measured` at `now` (ms) and the one
    /// before; returns the ms between them (0 on the first, at most 1000).
    fn estimate_velocity(&mut self, measured: HipAngle, now: u32) -> u32 {
        let mut dt_ms = 0u32;
        if let Some((t0, a0)) = self.last {
            dt_ms = Instant::from_millis(now).since(t0).millis().min(1000);
            // In 1..=1000 here, so `checked_div` never fails, and `raw` is exact in i32:
            // |raw| ≤ 18000 × 1000. The estimate stays within the same bound, so the update's
            // wrapping operations (free on the control tick) are exact.
            if let Ok(dt @ 1..) = i32::try_from(dt_ms) {
                let raw = angle_error(a0, measured)
                    .wrapping_mul(1000)
                    .checked_div(dt)
                    .unwrap_or(0);
                let shift = self.cfg.smoothing_shift.min(8);
                self.velocity = self
                    .velocity
                    .wrapping_add(raw.wrapping_sub(self.velocity) >> shift);
            }
        }
        self.last = Some((Instant::from_millis(now), measured));
        dt_ms
    }

    /// One control tick at time `now` (ms): the pulse to send to the hip servo.
    pub fn step(&mut self, target: HipAngle, measured: HipAngle, now: u32) -> PulseWidth {
        let dt_ms = self.estimate_velocity(measured, now);
        let c = &self.cfg;
        let max = c.max_offset_us.clamp(0, 1000);
        let e = angle_error(measured, target);
        let band = c.position_band.max(0);
        let mode = if e.abs() > band {
            Mode::Velocity
        } else {
            Mode::Position
        };
        if mode != self.mode {
            self.integral_q8 = 0;
            self.mode = mode;
        }
        // Error and gains of the active law; velocity mode adds the servo feed-forward.
        let (err, kp, ki, ff) = match mode {
            Mode::Velocity => {
                let v_ref = if e > 0 {
                    c.speed
                } else {
                    c.speed.saturating_neg()
                };
                let ff = if c.servo_gain > 0 {
                    // A positive divisor: `checked_div` never fails.
                    v_ref.checked_div(c.servo_gain).unwrap_or(0)
                } else {
                    0
                };
                (
                    v_ref.saturating_sub(self.velocity),
                    c.kp_velocity_q8,
                    c.ki_velocity_q8,
                    ff,
                )
            }
            Mode::Position => (e, c.kp_position_q8, c.ki_position_q8, 0),
        };
        // Exact: the product of two i32 is below 2⁶² in magnitude.
        let p = i64::from(err).wrapping_mul(i64::from(kp)) >> 8;
        let unsat = i64::from(ff)
            .saturating_add(p)
            .saturating_add(i64::from(self.integral_q8) >> 8);
        let max = i64::from(max);
        // 0..=1000: the negation is exact.
        let out = unsat.clamp(max.wrapping_neg(), max);
        // Anti-windup: integrate only when not saturated, or when the error pulls back inward.
        let saturated = unsat != out;
        if !saturated || (unsat > 0) != (err > 0) {
            self.integrate(err, ki, dt_ms, max);
        }
        // |out| ≤ 1000: an i16, so the fallback never applies, and the pulse is in 500..=2500
        // (exact: the wrapping addition never wraps).
        let out = i16::try_from(out).unwrap_or(0);
        PulseWidth::saturating(STOP_US.wrapping_add_signed(out))
    }

    /// Adds `err × ki` over `dt_ms` to the integral, clamped to the output's range `max`
    /// (0..=1000 µs) in Q8.
    fn integrate(&mut self, err: i32, ki: i32, dt_ms: u32, max: i64) {
        let di = i64::from(err)
            .saturating_mul(i64::from(ki))
            .saturating_mul(i64::from(dt_ms))
            / 1000;
        let lim = max << 8;
        // Clamped to ±256,000: an i32, so the fallback never applies.
        self.integral_q8 = i32::try_from(
            i64::from(self.integral_q8)
                .saturating_add(di)
                .clamp(lim.wrapping_neg(), lim),
        )
        .unwrap_or(0);
    }

    /// A tick without an angle reading: the stop pulse, and the controller starts afresh
    /// (no velocity history across the gap, no integral), as a hip driven from a guessed
    /// angle could turn on unchecked (spec/decisions.toml, `sensor-loss`).
    ///
    /// ```
    /// use mmic::control::hip::HipController;
    /// use mmic::units::HipAngle;
    /// let mut c = HipController::new(Default::default());
    /// let far = HipAngle::wrapping(9000);
    /// assert_ne!(c.step(far, HipAngle::STRAIGHT, 0).micros(), 1500);
    /// assert_eq!(c.blind().micros(), 1500);
    /// assert_eq!(c.velocity(), 0);
    /// ```
    pub fn blind(&mut self) -> PulseWidth {
        *self = HipController::new(self.cfg);
        PulseWidth::saturating(STOP_US)
    }
}
