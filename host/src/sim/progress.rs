//! Live progress of a simulation on stderr.

use super::steps::SimStep;
use mmic::motion::State;
use mmic::node::exactly_once::uplink::Efficiency;
use mmic::wire::heartbeat::HeartbeatRepr;

/// Live progress on stderr: a line when a step starts or the robot's mode, state or faults
/// change (as the ground sees them, from heartbeats), and every 10 simulated seconds.
///
/// Status lines name the step that last *started*, so a status line never runs ahead of its
/// step's header; before any reconfiguration the state shown is the plan's start state (the
/// heartbeat's state byte is the last commanded target, none at power-up).
pub struct Progress {
    on: bool,
    steps: Vec<SimStep>,
    start: State,
    current: Option<usize>,
    last_key: String,
    last_print: u32,
}

impl Progress {
    /// Printing or not; the plan's steps and the state the robot starts in.
    pub fn new(on: bool, steps: Vec<SimStep>, start: State) -> Progress {
        Progress {
            on,
            steps,
            start,
            current: None,
            last_key: String::new(),
            last_print: 0,
        }
    }

    /// Step `k` (0-based) started.
    pub fn step(&mut self, now: u32, k: usize) {
        self.current = Some(k);
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

    /// An injection's time came.
    pub fn inject(&mut self, now: u32, injection: super::inject::Injection) {
        if self.on {
            eprintln!(
                "[{:>6.1} s] inject {injection}: {}",
                now as f64 / 1000.0,
                injection.effect()
            );
        }
    }

    /// The latest heartbeat.
    pub fn status(&mut self, now: u32, hb: &HeartbeatRepr, eff: Efficiency) {
        if !self.on {
            return;
        }
        let faults: Vec<String> = hb.faults.iter().map(|f| f.to_string()).collect();
        let state = match (hb.target_state, hb.command_complete) {
            (Some(s), true) => format!("{s}"),
            (Some(s), false) => format!("-> {s}"),
            (None, _) => format!("{} (start)", self.start),
        };
        let key = format!("{} {state} {faults:?}", hb.mode);
        if key != self.last_key || now.saturating_sub(self.last_print) >= 10_000 {
            let (ok, n) = eff.counts();
            let step = match self.current {
                Some(k) => format!("step {}/{}", k + 1, self.steps.len()),
                None => format!("step -/{}", self.steps.len()),
            };
            eprintln!(
                "[{:>6.1} s]   {step} | {} | state {state} | faults: {} | wifi {}% ({ok}/{n})",
                now as f64 / 1000.0,
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
