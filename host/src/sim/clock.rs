//! Simulated time: wall time since the start, multiplied by the time scale, and — when paced —
//! held back so that it never runs ahead of the slowest node.
//!
//! # Why pacing
//!
//! The firmware's timeouts (500 ms of board B silence, the 0.7 s answer window) are simulated
//! milliseconds. A host that deschedules a board's thread for 30 ms of wall time at 10× makes
//! that board tick 300 simulated ms late, and a timeout that the robot would never see fires:
//! the verdict of a run would depend on how busy the machine was. A paced clock gives every
//! node a slot saying up to when it has done its work ([`Clock::ready`]); simulated time never
//! passes the earliest slot by more than [`Pace::slack_ms`]. A slow host then slows the run
//! down instead of stretching the firmware's timers, and a tick is at most the slack late by
//! construction. The time the clock was held is reported ([`Clock::held_ms`]).
//!
//! ```
//! use mmic_host::sim::clock::{Clock, Pace};
//! let pace = Pace::new(2, 20);
//! let clock = Clock::paced(1000.0, &pace);
//! let (a, b) = (clock.node(), clock.node());
//! std::thread::sleep(std::time::Duration::from_millis(5)); // 5 s simulated at 1000x
//! // Neither node has done anything yet: time waits for them at the slack.
//! assert!(a.now_ms() <= 20);
//! a.ready(1_000);
//! b.ready(1_000);
//! assert!(b.now_ms() <= 1_020);
//! drop((a, b));
//! ```

use std::sync::atomic::{AtomicU32, AtomicU64, AtomicUsize, Ordering};
use std::time::{Duration, Instant};

/// The shared state of a paced clock: one slot per node, the time withheld so far.
#[derive(Debug)]
pub struct Pace {
    slack_ms: u32,
    /// Per node: simulated ms up to which it has done its work; `u32::MAX` when free.
    slots: Box<[AtomicU32]>,
    taken: AtomicUsize,
    /// Simulated µs the clock has been held back in total.
    held_us: AtomicU64,
    /// The latest time handed out, so that time never runs backwards between threads.
    last_ms: AtomicU32,
}

impl Pace {
    /// Room for `nodes` nodes; time runs at most `slack_ms` ahead of the slowest.
    pub fn new(nodes: usize, slack_ms: u32) -> Pace {
        Pace {
            slack_ms,
            slots: (0..nodes).map(|_| AtomicU32::new(u32::MAX)).collect(),
            taken: AtomicUsize::new(0),
            held_us: AtomicU64::new(0),
            last_ms: AtomicU32::new(0),
        }
    }

    /// How far (simulated ms) time may run ahead of the slowest node.
    pub fn slack_ms(&self) -> u32 {
        self.slack_ms
    }

    fn earliest(&self) -> u32 {
        self.slots
            .iter()
            .map(|s| s.load(Ordering::Acquire))
            .min()
            .unwrap_or(u32::MAX)
    }
}

/// The simulation's clock, shared by every node (a copy per node; see [`Clock::node`]).
#[derive(Debug, Clone, Copy)]
pub struct Clock<'p> {
    start: Instant,
    scale: f64,
    pace: Option<&'p Pace>,
    /// This copy's slot in the pace, if it is a node's.
    slot: Option<usize>,
}

impl Clock<'static> {
    /// Starts now, unpaced; `scale` simulated seconds pass per wall second.
    pub fn start(scale: f64) -> Clock<'static> {
        Clock {
            start: Instant::now(),
            scale: scale.max(0.01),
            pace: None,
            slot: None,
        }
    }
}

impl<'p> Clock<'p> {
    /// Starts now, paced by `pace`.
    pub fn paced(scale: f64, pace: &'p Pace) -> Clock<'p> {
        Clock {
            start: Instant::now(),
            scale: scale.max(0.01),
            pace: Some(pace),
            slot: None,
        }
    }

    /// A copy of the clock for one node, holding a slot of the pace (time waits for it from
    /// 0 on). The slot is freed when the returned [`NodeClock`] is dropped. Without a pace, or
    /// when every slot is taken, the node does not hold time back.
    pub fn node(&self) -> NodeClock<'p> {
        let slot = self.pace.and_then(|p| {
            let i = p.taken.fetch_add(1, Ordering::AcqRel);
            let s = p.slots.get(i)?;
            s.store(0, Ordering::Release);
            Some(i)
        });
        NodeClock(Clock { slot, ..*self })
    }

    /// Simulated milliseconds since the start (wrapping like the boards' clocks).
    pub fn now_ms(&self) -> u32 {
        let raw_us = (self.start.elapsed().as_secs_f64() * self.scale * 1e6) as u64;
        let Some(p) = self.pace else {
            return (raw_us / 1000) as u32;
        };
        let bound_us = (p.earliest() as u64)
            .saturating_add(p.slack_ms as u64)
            .saturating_mul(1000);
        let mut t_us = raw_us.saturating_sub(p.held_us.load(Ordering::Acquire));
        if t_us > bound_us {
            p.held_us
                .fetch_max(raw_us.saturating_sub(bound_us), Ordering::AcqRel);
            t_us = bound_us;
        }
        let t = (t_us / 1000).min(u32::MAX as u64) as u32;
        p.last_ms.fetch_max(t, Ordering::AcqRel).max(t)
    }

    /// This node has done everything due up to simulated time `t` (ms): time may now run to
    /// `t` plus the slack. A no-op for an unpaced clock or a copy without a slot.
    pub fn ready(&self, t: u32) {
        if let (Some(p), Some(i)) = (self.pace, self.slot) {
            if let Some(s) = p.slots.get(i) {
                s.store(t, Ordering::Release);
            }
        }
    }

    /// Wall time for `ms` simulated milliseconds.
    pub fn wall(&self, ms: f64) -> Duration {
        Duration::from_secs_f64((ms / 1000.0 / self.scale).max(0.0))
    }

    /// Wall seconds since the start.
    pub fn wall_elapsed(&self) -> Duration {
        self.start.elapsed()
    }

    /// The time scale.
    pub fn scale(&self) -> f64 {
        self.scale
    }

    /// Simulated ms the clock has been held back for slow nodes so far (0 when unpaced).
    pub fn held_ms(&self) -> u64 {
        self.pace
            .map_or(0, |p| p.held_us.load(Ordering::Acquire) / 1000)
    }

    /// The pace's slack, if paced.
    pub fn slack_ms(&self) -> Option<u32> {
        self.pace.map(|p| p.slack_ms)
    }
}

/// A node's copy of the clock: frees its slot when dropped, so that a node that has ended
/// (or panicked) never holds time back.
#[derive(Debug)]
pub struct NodeClock<'p>(Clock<'p>);

impl<'p> std::ops::Deref for NodeClock<'p> {
    type Target = Clock<'p>;
    fn deref(&self) -> &Clock<'p> {
        &self.0
    }
}

impl Drop for NodeClock<'_> {
    fn drop(&mut self) {
        self.0.ready(u32::MAX);
    }
}
