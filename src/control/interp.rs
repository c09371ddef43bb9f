//! Arm and gripper interpolation: open loop, a fixed step per period towards the target,
//! monotone, ending exactly on the target, never outside the servo range (the type
//! [`PulseWidth`] cannot leave 500..=2500 µs). The heartbeat's "current PWM" is [`Interpolator::now`].
// req: P5.1

/// The servos' travel is command vocabulary (what a target means); re-exported at its old path.
pub use crate::command::{OutOfTravel, Travel};
use core::num::NonZeroU32;

use crate::units::Instant;
use crate::units::PulseWidth;

/// Interpolation rate: `step_us` every `period_ms`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Rate {
    /// Pulse change per period, µs (≥ 1). Default 10 µs.
    pub step_us: u16,
    /// Period, ms (≥ 1). Default 20 ms (the servo frame), i.e. 500 µs/s.
    pub period_ms: u32,
}

impl Default for Rate {
    fn default() -> Rate {
        Rate {
            step_us: 10,
            period_ms: 20,
        }
    }
}

/// One servo's interpolator.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Interpolator {
    now: PulseWidth,
    target: PulseWidth,
    rate: Rate,
    last: Instant,
    banked_ms: u32,
}

impl Interpolator {
    /// At rest at `now`.
    pub const fn new(now: PulseWidth, rate: Rate) -> Interpolator {
        Interpolator {
            now,
            target: now,
            rate,
            last: Instant::ZERO,
            banked_ms: 0,
        }
    }

    /// New target from time `t` (ms) on.
    pub fn set_target(&mut self, target: PulseWidth, t: u32) {
        self.target = target;
        self.last = Instant::from_millis(t);
        self.banked_ms = 0;
    }

    /// Advances to time `t` (ms, wrapping): one step per whole period elapsed, stopping on the
    /// target. Returns the pulse to send.
    pub fn tick(&mut self, t: u32) -> PulseWidth {
        // A zero period counts as 1 ms; as a `NonZeroU32` its division cannot panic.
        let period = NonZeroU32::new(self.rate.period_ms).unwrap_or(NonZeroU32::MIN);
        let t = Instant::from_millis(t);
        self.banked_ms = self.banked_ms.saturating_add(t.since(self.last).millis());
        self.last = t;
        let periods = self.banked_ms / period;
        self.banked_ms %= period;
        let max_move = u64::from(periods).saturating_mul(u64::from(self.rate.step_us.max(1)));
        let (now, target) = (self.now.micros(), self.target.micros());
        let gap = now.abs_diff(target);
        // At most `gap`, so `next` lies between `now` and `target`, both in range: the
        // wrapping operations (free on the control tick) are exact.
        let step = u16::try_from(max_move.min(u64::from(gap))).unwrap_or(gap);
        let next = if target >= now {
            now.wrapping_add(step)
        } else {
            now.wrapping_sub(step)
        };
        self.now = PulseWidth::saturating(next);
        self.now
    }

    /// The last interpolated pulse ("current PWM").
    pub const fn now(&self) -> PulseWidth {
        self.now
    }

    /// The target.
    pub const fn target(&self) -> PulseWidth {
        self.target
    }

    /// Interpolation finished.
    pub fn done(&self) -> bool {
        self.now == self.target
    }
}
