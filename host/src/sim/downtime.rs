//! A node's restarts on the realtime engine's wall clock: the times `--inject reboot-*@S`
//! asked for, and where the node stands at each of its ticks (running, just gone down, down
//! for [`BOOT_MS`], just come up). The virtual-time engine schedules the same two events
//! (down, up) in its queue; a thread asks this at every tick instead.
//!
//! ```
//! use mmic_host::sim::downtime::{Downtime, Phase};
//! let mut d = Downtime::new(vec![1_000, 1_100]); // the second falls while it is down
//! assert_eq!(d.step(990), Phase::Running);
//! assert!(d.due(1_005));
//! assert_eq!(d.step(1_005), Phase::WentDown);
//! assert!(!d.due(1_200));
//! assert_eq!(d.step(1_200), Phase::Down);
//! assert_eq!(d.step(1_305), Phase::CameUp);
//! assert_eq!(d.step(5_000), Phase::Running); // 1_100 was that same boot
//! ```

use super::inject::{Injection, Node, BOOT_MS};
use super::SimConfig;

/// Where a node stands at one of its ticks.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Phase {
    /// Up as before.
    Running,
    /// A restart begins now: what it held in RAM is gone, its outputs unpowered.
    WentDown,
    /// Still down: what reaches it is lost.
    Down,
    /// Up again now: it boots from what it kept, and runs this tick.
    CameUp,
}

/// One node's restart times and its state.
#[derive(Debug, Clone, Default)]
pub struct Downtime {
    at: Vec<u32>,
    next: usize,
    until: Option<u32>,
}

impl Downtime {
    /// Restarts at these simulated times, ms (in any order).
    pub fn new(mut at: Vec<u32>) -> Downtime {
        at.sort_unstable();
        Downtime {
            at,
            ..Downtime::default()
        }
    }

    /// `node`'s restarts in `cfg`'s injections.
    pub fn of(cfg: &SimConfig, node: Node) -> Downtime {
        Downtime::new(
            cfg.injections
                .iter()
                .filter(|s| s.injection == Injection::Reboot(node))
                .map(|s| s.at_ms)
                .collect(),
        )
    }

    /// Whether a restart falls due at `now` while the node is up: the next [`Downtime::step`]
    /// would say [`Phase::WentDown`]. A node busy in a blocking wait (the server board's
    /// visit of board A) asks this to break off, then steps.
    pub fn due(&self, now: u32) -> bool {
        self.until.is_none() && self.at.get(self.next).is_some_and(|&t| t <= now)
    }

    /// At a tick at `now`. A restart asked for while the node is down is the same boot, as
    /// in the virtual-time engine.
    pub fn step(&mut self, now: u32) -> Phase {
        if let Some(u) = self.until {
            if now < u {
                return Phase::Down;
            }
            self.until = None;
            // Restarts asked for while it was down were that boot.
            while self.at.get(self.next).is_some_and(|&t| t < u) {
                self.next += 1;
            }
            return Phase::CameUp;
        }
        match self.at.get(self.next) {
            Some(&t) if t <= now => {
                self.next += 1;
                self.until = Some(now.saturating_add(BOOT_MS));
                Phase::WentDown
            }
            _ => Phase::Running,
        }
    }
}
