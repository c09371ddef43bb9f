//! Arm and gripper interpolation: open loop, a fixed step per period towards the target,
//! monotone, ending exactly on the target, never outside the servo range (the type
//! [`PulseWidth`] cannot leave 500..=2500 µs). The heartbeat's "current PWM" is [`Interpolator::now`].

use crate::command::ServoTarget;
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

/// The pulse widths that "totally contract" and "totally extend" mean for one servo: its travel.
/// A partial target from the command set is honoured as given when it lies within them.
///
/// ```
/// use mmic::command::ServoTarget;
/// use mmic::control::interp::Travel;
/// use mmic::units::PulseWidth;
/// let arm = Travel { contracted: PulseWidth::new(900).unwrap(), extended: PulseWidth::new(2100).unwrap() };
/// assert_eq!(arm.resolve(ServoTarget::Extend).micros(), 2100);
/// assert_eq!(arm.resolve(ServoTarget::Position(PulseWidth::new(1300).unwrap())).micros(), 1300);
/// ```
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Travel {
    /// Fully contracted (arm retracted / gripper open).
    pub contracted: PulseWidth,
    /// Fully extended (arm out / gripper closed on the face).
    pub extended: PulseWidth,
}

impl Travel {
    /// The arms' travel: contracted 900 µs, extended 2100 µs (spec/control/servos.toml). No
    /// arm command may leave it.
    pub const ARM: Travel = Travel {
        contracted: PulseWidth::saturating(900),
        extended: PulseWidth::saturating(2100),
    };
    /// The grippers' travel: open 1000 µs, closed on a face 2000 µs (spec/control/servos.toml).
    /// No gripper command may leave it.
    pub const GRIPPER: Travel = Travel {
        contracted: PulseWidth::saturating(1000),
        extended: PulseWidth::saturating(2000),
    };

    /// The pulse a command's target stands for; partial targets are taken as given.
    pub const fn resolve(&self, t: ServoTarget) -> PulseWidth {
        match t {
            ServoTarget::Contract => self.contracted,
            ServoTarget::Extend => self.extended,
            ServoTarget::Position(p) => p,
        }
    }

    /// The smallest pulse of the travel (whichever end it is).
    pub const fn min(&self) -> PulseWidth {
        if self.contracted.micros() <= self.extended.micros() {
            self.contracted
        } else {
            self.extended
        }
    }

    /// The largest pulse of the travel.
    pub const fn max(&self) -> PulseWidth {
        if self.contracted.micros() <= self.extended.micros() {
            self.extended
        } else {
            self.contracted
        }
    }

    /// `target` when the pulse it stands for lies within the travel (its two ends included);
    /// otherwise the error, with the range. A partial target outside the travel would drive
    /// the servo against its end stop (issue 24): the commands refuse it at decoding
    /// (`CommandError::OutOfTravel`), board A against its configured travel.
    ///
    /// ```
    /// use mmic::command::ServoTarget;
    /// use mmic::control::interp::{OutOfTravel, Travel};
    /// use mmic::units::PulseWidth;
    /// let at = |us| ServoTarget::Position(PulseWidth::new(us).unwrap());
    /// assert_eq!(Travel::ARM.check(at(2100)), Ok(at(2100)));
    /// assert_eq!(Travel::ARM.check(at(2101)), Err(OutOfTravel { found: 2101, min: 900, max: 2100 }));
    /// assert_eq!(Travel::ARM.check(ServoTarget::Extend), Ok(ServoTarget::Extend));
    /// ```
    pub const fn check(&self, target: ServoTarget) -> Result<ServoTarget, OutOfTravel> {
        let p = self.resolve(target).micros();
        let (min, max) = (self.min().micros(), self.max().micros());
        if p < min || p > max {
            Err(OutOfTravel { found: p, min, max })
        } else {
            Ok(target)
        }
    }
}

/// A servo target outside the module's travel.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, thiserror::Error)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
#[error("pulse width {found} us is outside the travel {min}..={max} us")]
pub struct OutOfTravel {
    /// The pulse width asked for, µs.
    pub found: u16,
    /// The travel's smallest pulse, µs.
    pub min: u16,
    /// The travel's largest pulse, µs.
    pub max: u16,
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
        let period = self.rate.period_ms.max(1);
        let t = Instant::from_millis(t);
        self.banked_ms = self.banked_ms.saturating_add(t.since(self.last).millis());
        self.last = t;
        let periods = self.banked_ms / period;
        self.banked_ms %= period;
        let max_move = (periods as u64).saturating_mul(self.rate.step_us.max(1) as u64);
        let (now, target) = (self.now.micros() as u64, self.target.micros() as u64);
        let next = if target >= now {
            now + max_move.min(target - now)
        } else {
            now - max_move.min(now - target)
        };
        // `next` lies between `now` and `target`, both in range.
        self.now = PulseWidth::saturating(next as u16);
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
