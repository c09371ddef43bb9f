//! Live progress, the end-of-run summary and the plots (Figure 10 and 11 analogues).

use super::{SimStep, Summary};
use crate::plot::{bar_chart, line_chart, Series};
use mmic::node::ground::Efficiency;
use mmic::node::plan::PlanEnd;
use mmic::wire::heartbeat::HeartbeatRepr;
use serde_json::Value;
use std::fmt::Write as _;
use std::path::Path;
use std::sync::{Arc, Mutex};

/// The built-in demo plan's text (host/plans/demo.plan).
pub const DEMO_PLAN: &str = include_str!("../../plans/demo.plan");

/// The demo plan's steps.
pub fn demo_steps() -> Vec<SimStep> {
    match crate::plan::parse(DEMO_PLAN) {
        Ok(p) => steps_of(&p),
        // The demo is checked by a test; an empty plan here would show up at once.
        Err(_) => Vec::new(),
    }
}

/// A parsed plan's steps for the simulator.
pub fn steps_of(p: &crate::plan::Plan) -> Vec<SimStep> {
    p.steps
        .iter()
        .map(|s| SimStep {
            line: s.line,
            text: s.text.clone(),
            step: match s.action {
                crate::plan::Action::Command(c) => mmic::node::plan::PlanStep::Command(c),
                crate::plan::Action::Wait { ms } => mmic::node::plan::PlanStep::Wait { ms },
            },
        })
        .collect()
}

/// Live progress on stderr: a line when a step starts or the robot's mode, state or faults
/// change (as the ground sees them, from heartbeats), and every 10 simulated seconds.
pub struct Progress {
    on: bool,
    steps: Vec<SimStep>,
    last_key: String,
    last_print: u32,
}

impl Progress {
    /// Printing or not.
    pub fn new(on: bool, steps: Vec<SimStep>) -> Progress {
        Progress {
            on,
            steps,
            last_key: String::new(),
            last_print: 0,
        }
    }

    /// Step `k` (0-based) started.
    pub fn step(&mut self, now: u32, k: usize) {
        if self.on {
            if let Some(s) = self.steps.get(k) {
                eprintln!(
                    "[{:>6.1} s] step {}/{} (line {}): {}",
                    now as f64 / 1000.0,
                    k + 1,
                    self.steps.len(),
                    s.line,
                    s.text
                );
            }
        }
    }

    /// The latest heartbeat.
    pub fn status(
        &mut self,
        now: u32,
        step: usize,
        hb: &HeartbeatRepr,
        eff: Efficiency,
        _board: &Arc<Mutex<Value>>,
    ) {
        if !self.on {
            return;
        }
        let faults: Vec<String> = hb.faults.iter().map(|f| f.to_string()).collect();
        let state = match (hb.target_state, hb.command_complete) {
            (Some(s), true) => format!("{s}"),
            (Some(s), false) => format!("-> {s}"),
            (None, _) => "start".to_string(),
        };
        let key = format!("{} {state} {faults:?}", hb.mode);
        if key != self.last_key || now.saturating_sub(self.last_print) >= 10_000 {
            let (ok, n) = eff.counts();
            eprintln!(
                "[{:>6.1} s]   step {}/{} | {} | state {state} | faults: {} | wifi {}% ({ok}/{n})",
                now as f64 / 1000.0,
                (step + 1).min(self.steps.len()),
                self.steps.len(),
                hb.mode,
                if faults.is_empty() {
                    "none".to_string()
                } else {
                    faults.join(", ")
                },
                eff.percent().unwrap_or(100),
            );
            self.last_key = key;
            self.last_print = now;
        }
    }

    /// The run ended.
    pub fn finish(&mut self) {}
}

/// Pairs bolted at the 1st, 2nd and 3rd attempt, and failed (from board A's events).
pub fn bolting(s: &Summary) -> [u64; 4] {
    let mut bins = [0u64; 4];
    for e in s.events("pair") {
        let ok = e["event"]["ok"].as_bool().unwrap_or(false);
        let a = e["event"]["attempts"].as_u64().unwrap_or(0);
        let i = if ok { (a.clamp(1, 3) - 1) as usize } else { 3 };
        bins[i] += 1;
    }
    bins
}

/// Sequence numbers board A executed more than once (counted from its events).
pub fn executed_twice(s: &Summary) -> Vec<u64> {
    let mut count = std::collections::BTreeMap::new();
    for e in s.events("executed") {
        let seq = e["event"]["seq"].as_u64().unwrap_or(0);
        if seq != 0 {
            *count.entry((e["node"].to_string(), seq)).or_insert(0u32) += 1;
        }
    }
    count
        .into_iter()
        .filter(|(_, n)| *n > 1)
        .map(|((_, s), _)| s)
        .collect()
}

/// The summary as text.
pub fn text(s: &Summary) -> String {
    let mut t = String::new();
    let end = match s.ends.first().copied().flatten() {
        Some(PlanEnd::Completed) => "completed".to_string(),
        Some(PlanEnd::Refused {
            step,
            refusal,
            robot,
        }) => {
            let mut t = format!("stopped: step {} refused ({refusal})", step + 1);
            if let Some((mode, faults)) = robot {
                let f: Vec<String> = faults.iter().map(|f| f.to_string()).collect();
                let f = if f.is_empty() {
                    "none".to_string()
                } else {
                    f.join(", ")
                };
                let _ = write!(t, ", robot in {mode} (faults: {f})");
            }
            t
        }
        Some(PlanEnd::Unacknowledged { step }) => {
            format!("stopped: step {} unacknowledged", step + 1)
        }
        Some(PlanEnd::Interrupted { step, mode, faults }) => {
            let f: Vec<String> = faults.iter().map(|f| f.to_string()).collect();
            format!(
                "stopped: step {} interrupted, robot in {mode} (faults: {})",
                step + 1,
                f.join(", ")
            )
        }
        None => "time limit reached".to_string(),
    };
    let _ = writeln!(t, "plan: {end} ({} steps)", s.steps);
    let _ = writeln!(
        t,
        "time: {:.1} s simulated in {:.1} s wall ({:.1}x)",
        s.sim_ms as f64 / 1000.0,
        s.wall.as_secs_f64(),
        s.sim_ms as f64 / 1000.0 / s.wall.as_secs_f64().max(1e-9)
    );
    let (ok, n) = s.attempts;
    let _ = writeln!(
        t,
        "wifi: {ok}/{n} attempts answered within the timeout ({:.1}%), longest answer {} ms",
        if n == 0 {
            100.0
        } else {
            ok as f64 * 100.0 / n as f64
        },
        s.max_latency_ms
    );
    let _ = writeln!(
        t,
        "host: board ticks started at most {} ms (simulated) late{}",
        s.max_tick_lateness_ms,
        if s.max_tick_lateness_ms >= super::nodes::OVERRUN_MS {
            " -- the host fell behind the simulated clock, so timeouts and faults in this run \
             may come from the host, not the robot: rerun with a smaller --scale"
        } else {
            ""
        }
    );
    let executed = s.events("executed").count();
    let dups = s.events("duplicate").count() + s.events("stale").count();
    let twice = executed_twice(s);
    let _ = writeln!(
        t,
        "commands: {executed} executed by board A, {dups} copies answered without running, {} executed twice",
        twice.len()
    );
    let b = bolting(s);
    let _ = writeln!(
        t,
        "bolting: {} pairs; first attempt {}, second {}, third {}, failed {}",
        b.iter().sum::<u64>(),
        b[0],
        b[1],
        b[2],
        b[3]
    );
    let _ = writeln!(
        t,
        "robot: mode {}, state {}, faults {}",
        s.status["mode"], s.status["state"], s.status["faults"]
    );
    t
}

/// Writes wifi-efficiency.svg and bolting-attempts.svg into `dir`; returns their paths.
pub fn plots(s: &Summary, dir: &Path) -> std::io::Result<Vec<std::path::PathBuf>> {
    std::fs::create_dir_all(dir)?;
    let eff = line_chart(
        "WiFi efficiency over the last 100 attempts (Figure 11 analogue)",
        "simulated time (s)",
        "efficiency (%)",
        Some((0.0, 100.0)),
        &[Series {
            name: "robot 1",
            points: &s.efficiency,
        }],
    );
    let b = bolting(s);
    let bars = bar_chart(
        "Bolting attempts per fastener pair (Figure 10 analogue)",
        "pairs",
        &[
            ("1st attempt", b[0] as f64),
            ("2nd attempt", b[1] as f64),
            ("3rd attempt", b[2] as f64),
            ("failed", b[3] as f64),
        ],
    );
    let p1 = dir.join("wifi-efficiency.svg");
    let p2 = dir.join("bolting-attempts.svg");
    std::fs::write(&p1, eff)?;
    std::fs::write(&p2, bars)?;
    Ok(vec![p1, p2])
}
