//! One side's bolter: executes the step it was last ordered, decides the end of a
//! current-sensed step from the measured bolter current I_bo against the step's threshold,
//! latches it, and times out the steps that never end.
// req: P5.11, P5.12, P5.13, P5.14, D:bolter-current-thresholds

use super::{BolterAux, BolterDirection, BolterOrder, BolterStep, MuxLines};
use crate::units::{Instant, Milliamps};

/// What the side's bolter hardware reads this tick: the raw material of the step decisions,
/// not the decisions themselves, so that the thresholds live in one place ([`SideConfig`]) and
/// the same executor runs on boards A and B.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Default)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Sensed {
    /// The bolter current I_bo, mA, as the sensor front end filtered it (the 50-sample moving
    /// average of ADS7828 CH6; board A's `Inputs.electrical.i_bo`, board B's likewise). Section
    /// 5: the bolters push "until the I_boA and I_boB current threshold is met", and "current
    /// sensing determines if it's locked".
    pub i_bo: Milliamps,
    /// The bolter's home switch: it is in its initial configuration. A digital input, not a
    /// current decision: the steps that end at home carry no asterisk in Figure 8, and the
    /// paper does not say how home is sensed (spec/decisions.toml, `bolter-home`).
    pub at_home: bool,
}

/// What the side's bolter motor must do now.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum Drive {
    /// Nothing: idle, or the current step is finished or timed out.
    Idle,
    /// Translate towards the fastener (push).
    Down,
    /// Translate back to the initial configuration.
    Up,
    /// Rotate the head in the locking direction (unlocking when unbolting).
    Rotate,
    /// Rotate the other way while going back up.
    CounterRotateUp,
}

/// The executor's limits: when a current-sensed step has ended, and how long any step may take.
/// The defaults are spec/control/bolter.toml's (checked by `tests/control/bolter_current.rs`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct SideConfig {
    /// Timeout of the current-sensed steps (the paper's asterisks): Descend, DescendEngage,
    /// Rotate. Default 4000 ms.
    pub sensed_ms: u32,
    /// Timeout of the steps that end at home: Retract, CounterRotate, ReturnHome. Default
    /// 4000 ms.
    pub home_ms: u32,
    /// Descend and DescendEngage end once I_bo ≥ this: the bolter is pushing against the
    /// fastener (it is commanded further down than it can go, so the current rises on contact).
    /// Default 1000 mA: well above a moving bolter's draw and the 200 mA idle limit, well below
    /// the 2000 mA bolter overcurrent limit, so a normal push ends long before that fault.
    pub push_threshold_ma: Milliamps,
    /// Rotate ends once I_bo ≥ this: the fastener locked (released, when unbolting) and the
    /// head stalls. Default 1200 mA: above the push threshold by more than the moving average
    /// can carry over from a push that just ended (the filtered current peaks at most one
    /// sample's share of a current under the 2000 mA limit, 2000 / 50 = 40 mA, past the push
    /// threshold, then falls), so the lag of the filter cannot end Rotate as it starts; below
    /// the 2000 mA limit for the same reason as the push threshold.
    pub lock_threshold_ma: Milliamps,
}

impl Default for SideConfig {
    fn default() -> SideConfig {
        SideConfig {
            sensed_ms: 4000,
            home_ms: 4000,
            push_threshold_ma: 1000,
            lock_threshold_ma: 1200,
        }
    }
}

impl SideConfig {
    /// The current threshold that ends `step`, for the current-sensed steps (Descend,
    /// DescendEngage: the push threshold; Rotate: the lock threshold); `None` for the others,
    /// which no current ends. A step ends when I_bo ≥ the threshold (Section 5: the threshold
    /// "is met", I_bo "hits the threshold"); the overcurrent checks, by contrast, fire strictly
    /// above their limits ("rises above").
    pub const fn threshold(&self, step: BolterStep) -> Option<Milliamps> {
        match step {
            BolterStep::Descend | BolterStep::DescendEngage => Some(self.push_threshold_ma),
            BolterStep::Rotate => Some(self.lock_threshold_ma),
            _ => None,
        }
    }
}

/// A side's bolter executor.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Default)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct BolterSide {
    order: Option<(u8, BolterOrder)>,
    last: Instant,
    waited_ms: u32,
    threshold: bool,
    locked: bool,
    at_home: bool,
    timed_out: bool,
}

/// Whether `step` has ended given the latched flags.
pub(crate) const fn ended(step: BolterStep, threshold: bool, locked: bool, at_home: bool) -> bool {
    match step {
        BolterStep::Descend | BolterStep::DescendEngage => threshold,
        BolterStep::Rotate => locked,
        BolterStep::Retract | BolterStep::CounterRotate | BolterStep::ReturnHome => at_home,
        BolterStep::Done | BolterStep::Failed => true,
    }
}

const fn sensed(step: BolterStep) -> bool {
    matches!(
        step,
        BolterStep::Descend | BolterStep::DescendEngage | BolterStep::Rotate
    )
}

impl BolterSide {
    /// Idle.
    pub const fn new() -> BolterSide {
        BolterSide {
            order: None,
            last: Instant::ZERO,
            waited_ms: 0,
            threshold: false,
            locked: false,
            at_home: false,
            timed_out: false,
        }
    }

    /// An order (from the A→B command, or board A's coordinator for side A) carried by a packet
    /// with sequence number `seq`. An order equal to the current one is a resend or a packet
    /// sent for another reason and changes nothing; a different one starts the ordered step
    /// afresh and records `seq`. (The coordinator never orders the same step twice in a row, and
    /// the serial link is FIFO, so "different" always means "newer".) `None` idles the bolter.
    pub fn order(&mut self, seq: u8, order: Option<BolterOrder>, now: u32) {
        if self.order.map(|(_, o)| o) == order {
            return;
        }
        *self = BolterSide {
            order: order.map(|o| (seq, o)),
            last: Instant::from_millis(now),
            ..BolterSide::new()
        };
    }

    /// One tick: decides and latches the end signal of the current step, or times it out. In
    /// a current-sensed step the current latches that step's flag (threshold reached in the
    /// descents, locked in Rotate) once it reaches the step's threshold; in the other steps, and
    /// when idle, no current latches anything: a spike there ends nothing. The home switch
    /// latches `at_home` in any step.
    pub fn tick(&mut self, cfg: &SideConfig, now: u32, r: Sensed) {
        let Some((_, o)) = self.order else { return };
        let limit = if sensed(o.step) {
            cfg.sensed_ms
        } else {
            cfg.home_ms
        };
        // Clamped just past the limit: the executor has finitely many states.
        self.waited_ms = self
            .waited_ms
            .saturating_add(Instant::from_millis(now).since(self.last).millis())
            .min(limit.saturating_add(1));
        self.last = Instant::from_millis(now);
        if self.finished() {
            return;
        }
        let reached = cfg.threshold(o.step).is_some_and(|t| r.i_bo >= t);
        match o.step {
            BolterStep::Descend | BolterStep::DescendEngage => self.threshold |= reached,
            BolterStep::Rotate => self.locked |= reached,
            _ => {}
        }
        self.at_home |= r.at_home;
        if !ended(o.step, self.threshold, self.locked, self.at_home) && self.waited_ms > limit {
            self.timed_out = true;
        }
    }

    fn finished(&self) -> bool {
        match self.order {
            None => true,
            Some((_, o)) => {
                self.timed_out || ended(o.step, self.threshold, self.locked, self.at_home)
            }
        }
    }

    /// The motor command for now.
    pub fn drive(&self) -> Drive {
        match self.order {
            Some((_, o)) if !self.finished() => match o.step {
                BolterStep::Descend | BolterStep::DescendEngage => Drive::Down,
                BolterStep::Rotate => Drive::Rotate,
                BolterStep::Retract | BolterStep::ReturnHome => Drive::Up,
                BolterStep::CounterRotate => Drive::CounterRotateUp,
                BolterStep::Done | BolterStep::Failed => Drive::Idle,
            },
            _ => Drive::Idle,
        }
    }

    /// The multiplexer lines for the ordered pair (low-low when idle).
    pub fn mux(&self) -> MuxLines {
        self.order
            .map_or(MuxLines::default(), |(_, o)| MuxLines::for_pair(o.pair))
    }

    /// The progress report: Table 4 bytes 26–34 on board B, read directly on board A.
    pub fn aux(&self) -> BolterAux {
        BolterAux {
            step: self.order.map(|(_, o)| o.step),
            seq: self.order.map_or(0, |(s, _)| s),
            pair: self.order.map(|(_, o)| o.pair),
            direction: self.order.map(|(_, o)| o.direction),
            threshold_reached: self.threshold,
            locked: self.locked,
            timed_out: self.timed_out,
            at_home: self.at_home,
            mux: self.mux(),
        }
    }

    /// The direction being run, if any.
    pub fn direction(&self) -> Option<BolterDirection> {
        self.order.map(|(_, o)| o.direction)
    }
}
