//! Simulated time: wall time since the start, multiplied by the time scale.

use std::time::{Duration, Instant};

/// The simulation's clock, shared by every node.
#[derive(Debug, Clone, Copy)]
pub struct Clock {
    start: Instant,
    scale: f64,
}

impl Clock {
    /// Starts now; `scale` simulated seconds pass per wall second.
    pub fn start(scale: f64) -> Clock {
        Clock {
            start: Instant::now(),
            scale: scale.max(0.01),
        }
    }

    /// Simulated milliseconds since the start (wrapping like the boards' clocks).
    pub fn now_ms(&self) -> u32 {
        (self.start.elapsed().as_secs_f64() * self.scale * 1000.0) as u64 as u32
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
}
