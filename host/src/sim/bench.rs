//! The scale benchmark: N robots, each with its own server board and serial line, against
//! one ground process (one thread running N plan runners), at time scale 1 (real time).
//! Each robot is polled with a heartbeat request every 1.2 s; a trial passes when every
//! attempt of every robot was answered within the 0.7 s timeout.

use super::{run, SimConfig, SimStep};
use mmic::node::ground::plan_runner::PlanStep;

/// One trial's result.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Trial {
    /// Robots.
    pub robots: u8,
    /// Attempts answered within the timeout, attempts made.
    pub attempts: (u64, u64),
    /// Longest command-to-heartbeat time, ms.
    pub max_latency_ms: u32,
}

impl Trial {
    /// Every heartbeat arrived within the timeout.
    pub fn passed(&self) -> bool {
        self.attempts.1 > 0 && self.attempts.0 == self.attempts.1 && self.max_latency_ms <= 700
    }
}

impl std::fmt::Display for Trial {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(
            f,
            "{:>3} robots: {}/{} attempts answered within 0.7 s, longest {} ms: {}",
            self.robots,
            self.attempts.0,
            self.attempts.1,
            self.max_latency_ms,
            if self.passed() { "pass" } else { "FAIL" }
        )
    }
}

/// Runs one trial of `robots` robots for `seconds`.
pub fn trial(robots: u8, seconds: u32) -> std::io::Result<Trial> {
    let mut cfg = SimConfig::with_steps(vec![SimStep {
        line: 1,
        text: format!("wait {seconds}s"),
        step: PlanStep::Wait { ms: seconds * 1000 },
    }]);
    cfg.robots = robots.into();
    cfg.realtime = true;
    cfg.scale = 1.0;
    cfg.paced = false; // real time: the benchmark measures what the host keeps up with
    cfg.log_packets = false;
    cfg.max_sim_ms = seconds * 1000 + 5000;
    let s = run(&cfg)?;
    Ok(Trial {
        robots,
        attempts: s.attempts,
        max_latency_ms: s.max_latency_ms,
    })
}

/// The largest N ≤ `max` that passes: doubling from 1, then bisecting. Progress lines go to
/// `note`; returns the summary line.
pub fn largest(max: u8, seconds: u32, note: &mut dyn FnMut(String)) -> std::io::Result<String> {
    let mut good = 0u8;
    let mut bad: Option<u8> = None;
    let mut n = 1u8;
    loop {
        let t = trial(n, seconds)?;
        note(t.to_string());
        if t.passed() {
            good = n;
            if n >= max {
                break;
            }
            n = n.saturating_mul(2).min(max);
        } else {
            bad = Some(n);
            break;
        }
    }
    while let Some(b) = bad {
        if b - good <= 1 {
            break;
        }
        let mid = good + (b - good) / 2;
        let t = trial(mid, seconds)?;
        note(t.to_string());
        if t.passed() {
            good = mid;
        } else {
            bad = Some(mid);
        }
    }
    Ok(match bad {
        Some(b) => format!(
            "largest N with every heartbeat within 0.7 s: {good} (fails at {b}); {seconds} s per trial"
        ),
        None => format!(
            "largest N with every heartbeat within 0.7 s: at least {good} (the --max tried); {seconds} s per trial"
        ),
    })
}
