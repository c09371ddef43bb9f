//! One side's bolter: executes the step it was last ordered, latches the step's end signal from
//! the current sensing, and times out the current-sensed steps.

use super::{BolterDirection, BolterStep, MuxLines};
use crate::units::Instant;
use crate::wire::b_command::BolterOrder;
use crate::wire::internal_heartbeat::BolterAux;

/// What the side's bolter hardware reports this tick (from the filtered I_bo and the position).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Default)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Signals {
    /// The bolter current passed its push threshold.
    pub threshold: bool,
    /// The current says the fastener is locked (released, when unbolting).
    pub locked: bool,
    /// The bolter is in its initial configuration.
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

/// Step timeouts, ms.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct SideConfig {
    /// Current-sensed steps (the paper's asterisks): Descend, DescendEngage, Rotate.
    pub sensed_ms: u32,
    /// Steps that end at home: Retract, CounterRotate, ReturnHome.
    pub home_ms: u32,
}

impl Default for SideConfig {
    fn default() -> SideConfig {
        SideConfig {
            sensed_ms: 4000,
            home_ms: 4000,
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

    /// One tick: latches the end signal of the current step, or times it out.
    pub fn tick(&mut self, cfg: &SideConfig, now: u32, s: Signals) {
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
        self.threshold |= s.threshold;
        self.locked |= s.locked;
        self.at_home |= s.at_home;
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
