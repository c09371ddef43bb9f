//! How long a single-module motion may take: its size over the actuator's speed, plus a margin
//! (spec/control/servos.toml, `[deadline]`). Arm, gripper and hip commands, and the move home on
//! entering Operational, end when their feedback says done; a hip that cannot reach its target
//! (switched off by Power Control, stalled under the overcurrent limit) or a side-B servo that
//! never reports arrival would keep the robot "in motion" for ever: every motion command refused
//! as busy, a deferred Standby (low battery) never taken. Board A gives each such motion this
//! budget and raises the motion-timeout fault when it runs out (spec/decisions.toml,
//! `module-motion-deadline`). A primitive's steps and a bolting job's steps have timeouts of
//! their own (spec/motion/sequencer.md, spec/control/bolter.md).
//!
//! ```
//! use mmic::control::deadline::{budget_ms, hip_ms, servo_ms, Config};
//! use mmic::control::interp::Rate;
//! use mmic::units::{HipAngle, PulseWidth};
//! let us = |v| PulseWidth::new(v).unwrap();
//! // A full arm stroke, 900 -> 2100 µs at 10 µs per 20 ms: 2.4 s.
//! assert_eq!(servo_ms(us(900), us(2100), Rate::default()), 2_400);
//! // A quarter turn of the hip at 10°/s: 9 s; the short way round 0°/360°.
//! let deg = |d: u16| HipAngle::new(d * 100).unwrap();
//! assert_eq!(hip_ms(deg(180), deg(90), 1_000), 9_000);
//! assert_eq!(hip_ms(deg(350), deg(10), 1_000), 2_000);
//! // The motion's budget: the slowest module's time plus that module kind's margin.
//! let cfg = Config::default();
//! assert_eq!(budget_ms(&cfg, 2_400, 0), 2_400 + cfg.servo_margin_ms);
//! assert_eq!(budget_ms(&cfg, 2_400, 9_000), 9_000 + cfg.hip_margin_ms);
//! ```
// req: D:module-motion-deadline, D:motion-timeout

use super::interp::Rate;
use crate::units::widen::to_u32;
use crate::units::{HipAngle, PulseWidth};

/// The margins added to a motion's nominal time.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Config {
    /// Added to an arm or gripper move, ms. Default 1000: side B's servos are judged from board
    /// B's reports, which come every 50 ms and follow A's commands, sent every 50 ms, by up to a
    /// heartbeat period each; the rest is room for a tick late on a loaded board.
    pub servo_margin_ms: u32,
    /// Added to a hip move, ms. Default 5000: the hip ends in position mode (Section 5), which
    /// took up to 0.94 s beyond the nominal time on the plant of tests/control/control_hip.rs
    /// (18.94 s for 180°, spec/control/hip.md), and accelerates from rest at the start.
    pub hip_margin_ms: u32,
}

impl Default for Config {
    fn default() -> Config {
        Config {
            servo_margin_ms: 1_000,
            hip_margin_ms: 5_000,
        }
    }
}

/// The time the interpolator takes from `from` to `to`: one `rate.step_us` per
/// `rate.period_ms`, the last step partial (as [`super::interp::Interpolator`] moves).
pub const fn servo_ms(from: PulseWidth, to: PulseWidth, rate: Rate) -> u32 {
    let d = to_u32(from.micros().abs_diff(to.micros()).to_le_bytes());
    let step = to_u32(if rate.step_us == 0 { 1 } else { rate.step_us }.to_le_bytes());
    let periods = d.div_ceil(step);
    periods.saturating_mul(if rate.period_ms == 0 {
        1
    } else {
        rate.period_ms
    })
}

/// The time the hip takes from `from` to `to` the short way round at `speed` (0.01°/s, the hip
/// controller's velocity-mode speed; at least 1).
pub const fn hip_ms(from: HipAngle, to: HipAngle, speed: i32) -> u32 {
    let d = to_u32(from.distance(to).to_le_bytes());
    let speed = if speed < 1 { 1 } else { speed.unsigned_abs() };
    // `d` ≤ 18000: the product stays far below the saturation.
    d.saturating_mul(1000).div_ceil(speed)
}

/// A motion's budget from the slowest servo's nominal time and the hip's (0 where that kind of
/// module does not move): each kind's time plus its margin, the larger of the two. A motion
/// where nothing moves gets the servo margin: its feedback (side B's report) may still be on
/// its way.
pub const fn budget_ms(cfg: &Config, servos_ms: u32, hip_ms: u32) -> u32 {
    let servo = servos_ms.saturating_add(cfg.servo_margin_ms);
    if hip_ms == 0 {
        return servo;
    }
    let hip = hip_ms.saturating_add(cfg.hip_margin_ms);
    if hip > servo {
        hip
    } else {
        servo
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    // req: D:module-motion-deadline
    #[test]
    fn servo_time_rounds_the_last_partial_step_up_and_never_divides_by_zero() {
        let us = |v| PulseWidth::new(v).unwrap();
        let r = Rate::default();
        assert_eq!(servo_ms(us(1000), us(1000), r), 0);
        assert_eq!(servo_ms(us(1000), us(1001), r), 20);
        assert_eq!(servo_ms(us(1010), us(1000), r), 20);
        assert_eq!(servo_ms(us(1000), us(1011), r), 40);
        let zero = Rate {
            step_us: 0,
            period_ms: 0,
        };
        assert_eq!(servo_ms(us(500), us(2500), zero), 2000);
        let slow = Rate {
            step_us: 1,
            period_ms: u32::MAX,
        };
        assert_eq!(servo_ms(us(500), us(2500), slow), u32::MAX);
    }

    // req: D:module-motion-deadline
    #[test]
    fn hip_time_goes_the_short_way_and_survives_any_speed() {
        let a = HipAngle::wrapping;
        assert_eq!(hip_ms(a(0), a(18000), 1000), 18_000);
        assert_eq!(hip_ms(a(100), a(35900), 1000), 200);
        assert_eq!(hip_ms(a(0), a(1), 1000), 1);
        assert_eq!(hip_ms(a(0), a(1), 3), 334);
        assert_eq!(hip_ms(a(0), a(18000), 0), 18_000_000);
        assert_eq!(hip_ms(a(0), a(18000), -5), 18_000_000);
        assert_eq!(hip_ms(a(0), a(18000), i32::MAX), 1);
    }

    // req: D:module-motion-deadline
    #[test]
    fn the_budget_is_the_slower_kind_with_its_margin() {
        let c = Config::default();
        assert_eq!(budget_ms(&c, 0, 0), 1_000);
        assert_eq!(budget_ms(&c, 9_000, 100), 10_000);
        assert_eq!(budget_ms(&c, 100, 9_000), 14_000);
        assert_eq!(budget_ms(&c, u32::MAX, u32::MAX), u32::MAX);
    }
}
