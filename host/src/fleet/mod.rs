//! `mmic fleet`: N robots, each with its own server board and links, against one ground
//! process — the scale question of the paper's Section 3 (one opsUI keeping "multiple persistent
//! WiFi connections with many robots", a server board each), at Section 8's 1.2 s cadence with
//! every answer due within 0.7 s.
//!
//! Two ways to run the same fleet:
//!
//! * **virtual time** ([`run_virtual`]): the discrete-event engine ([`crate::sim::engine`]) runs
//!   every robot's nodes on one virtual clock; the figure of merit is simulated robot-seconds
//!   per wall second;
//! * **realtime** ([`realtime::run`]): the same nodes on the wall clock, every robot's boards,
//!   server board and links as tasks of one async runtime with a few threads (no thread per
//!   robot), the ground polling over real sockets; the figure of merit is whether every answer
//!   came within 0.7 s.
//!
//! ```
//! use mmic_host::fleet::{run_virtual, FleetConfig};
//! let r = run_virtual(&FleetConfig { robots: 3, seconds: 5, ..FleetConfig::default() }).unwrap();
//! assert_eq!(r.robots, 3);
//! assert_eq!(r.attempts.0, r.attempts.1); // every poll answered
//! assert!(r.robot_seconds_per_wall_second() > 100.0);
//! ```

pub mod cli;
pub mod realtime;

use crate::sim::{self, engine, Protocol, SimConfig, SimStep};
use mmic::node::ground::plan_runner::{PlanEnd, PlanStep};
use std::time::Duration;

/// What fleet to run.
#[derive(Debug, Clone)]
pub struct FleetConfig {
    /// Robots.
    pub robots: u32,
    /// Simulated seconds (virtual time) or wall seconds (realtime) to run.
    pub seconds: u32,
    /// The plan every robot runs; none: wait `seconds` while the ground polls every robot at
    /// its 1.2 s cadence (the paper's scale scenario; the legacy protocol's: over PUS the
    /// gateway polls board A itself and the ground sends nothing while it waits, so a PUS
    /// fleet needs a plan).
    pub plan: Option<Vec<SimStep>>,
    /// Between the ground and each server board.
    pub protocol: Protocol,
    /// Seed of every random choice.
    pub seed: u64,
    /// WiFi loss each way, 0..1.
    pub wifi_loss: f64,
}

impl Default for FleetConfig {
    fn default() -> FleetConfig {
        FleetConfig {
            robots: 1,
            seconds: 60,
            plan: None,
            protocol: Protocol::Legacy,
            seed: 1,
            wifi_loss: 0.0,
        }
    }
}

impl FleetConfig {
    /// The plan: the configured one, or a wait of `seconds` (polling).
    pub fn steps(&self) -> Vec<SimStep> {
        self.plan.clone().unwrap_or_else(|| {
            vec![SimStep {
                line: 1,
                text: format!("wait {}s", self.seconds),
                step: PlanStep::Wait {
                    ms: self.seconds.saturating_mul(1000),
                },
            }]
        })
    }

    /// The simulator's configuration of this fleet: no log, no progress (the summary's
    /// figures are all a fleet keeps).
    pub fn sim_config(&self) -> SimConfig {
        let mut cfg = SimConfig::with_steps(self.steps());
        cfg.robots = self.robots.max(1);
        cfg.protocol = self.protocol;
        cfg.seed = self.seed;
        cfg.wifi_loss = self.wifi_loss;
        // A polling wait ends when the poll in flight at its end is answered: that poll goes
        // out in the uplink's next 1.2 s slot, so leave a slot and an answer window of room.
        let room = if self.plan.is_none() { 2_000 } else { 0 };
        cfg.max_sim_ms = self.seconds.saturating_mul(1000) + room;
        cfg.log_packets = false;
        cfg.log_events = false;
        cfg.log_path = None;
        cfg.progress = false;
        cfg
    }
}

/// What a fleet run measured.
#[derive(Debug, Clone, PartialEq)]
pub struct FleetResult {
    /// Robots.
    pub robots: u32,
    /// Simulated (virtual) or wall (realtime) seconds covered.
    pub sim_seconds: f64,
    /// Wall time.
    pub wall: Duration,
    /// Attempts answered within the 0.7 s window, attempts made (all robots).
    pub attempts: (u64, u64),
    /// Longest command-to-answer time, ms.
    pub max_latency_ms: u32,
    /// Robots whose plan completed, robots whose plan ended otherwise.
    pub ends: (u32, u32),
    /// Realtime: OS threads the run used (the runtime's workers and the ground).
    pub threads: Option<usize>,
    /// Realtime: the latest any robot's board tick ran after it was due, ms.
    pub max_tick_lateness_ms: Option<u32>,
}

impl FleetResult {
    /// Simulated robot-seconds per wall second.
    pub fn robot_seconds_per_wall_second(&self) -> f64 {
        self.robots as f64 * self.sim_seconds / self.wall.as_secs_f64().max(1e-9)
    }

    /// Every attempt was answered, within 0.7 s (the paper's window).
    pub fn all_answered_in_time(&self) -> bool {
        self.attempts.1 > 0 && self.attempts.0 == self.attempts.1 && self.max_latency_ms <= 700
    }

    /// One line for the terminal.
    pub fn line(&self) -> String {
        let mut s = format!(
            "{:>6} robots, {:.0} s {}: {}/{} polls answered within 0.7 s, longest {} ms; \
             {:.1} s wall, {:.0} robot-s per wall s",
            self.robots,
            self.sim_seconds,
            if self.threads.is_some() {
                "realtime"
            } else {
                "virtual"
            },
            self.attempts.0,
            self.attempts.1,
            self.max_latency_ms,
            self.wall.as_secs_f64(),
            self.robot_seconds_per_wall_second(),
        );
        if let (Some(t), Some(l)) = (self.threads, self.max_tick_lateness_ms) {
            s.push_str(&format!("; {t} threads, ticks at most {l} ms late"));
        }
        s.push_str(if self.all_answered_in_time() {
            ": pass"
        } else {
            ": FAIL"
        });
        s
    }

    /// As JSON.
    pub fn json(&self) -> serde_json::Value {
        serde_json::json!({
            "robots": self.robots,
            "engine": if self.threads.is_some() { "realtime" } else { "virtual" },
            "seconds": self.sim_seconds,
            "wall_s": self.wall.as_secs_f64(),
            "robot_seconds_per_wall_second": self.robot_seconds_per_wall_second(),
            "answered": self.attempts.0,
            "attempts": self.attempts.1,
            "max_latency_ms": self.max_latency_ms,
            "completed": self.ends.0,
            "ended_otherwise": self.ends.1,
            "threads": self.threads,
            "max_tick_lateness_ms": self.max_tick_lateness_ms,
            "pass": self.all_answered_in_time(),
        })
    }
}

/// Runs the fleet in virtual time.
pub fn run_virtual(cfg: &FleetConfig) -> std::io::Result<FleetResult> {
    let s = engine::run(&cfg.sim_config())?;
    Ok(result_of(cfg, &s, None, None))
}

/// The result of a simulator run of the fleet.
fn result_of(
    cfg: &FleetConfig,
    s: &sim::Summary,
    threads: Option<usize>,
    late: Option<u32>,
) -> FleetResult {
    let completed = s
        .ends
        .iter()
        .filter(|e| **e == Some(PlanEnd::Completed))
        .count() as u32;
    let ended = s.ends.iter().filter(|e| e.is_some()).count() as u32;
    FleetResult {
        robots: cfg.robots.max(1),
        sim_seconds: s.sim_ms as f64 / 1000.0,
        wall: s.wall,
        attempts: s.attempts,
        max_latency_ms: s.max_latency_ms,
        ends: (completed, ended - completed),
        threads,
        max_tick_lateness_ms: late,
    }
}
