//! `mmic swarm`: the fault swarm. Seed after seed, a random scenario ([`scenario`]: the
//! protocol and, with PUS, bare packets or the space data link's frames under COP-1, a plan, the
//! links' loss, duplication, reordering, jitter and cuts, a fault schedule of battery sags,
//! obstacles, jammed fasteners, stuck switches, encoder offsets, silent sensors, a cut A–B line,
//! the operator's Stop and Reset, resent commands) runs in virtual time
//! ([`crate::sim::engine`]) with the invariants watched on every tick
//! ([`crate::sim::engine::watch`]), and each injected fault the firmware must see is checked
//! to have been raised in time ([`expectations`]). A failing seed prints the one command that
//! replays it; the replay runs the same scenario, byte for byte, and writes its whole log.
//!
//! ```
//! use mmic_host::swarm::{run_one, scenario::Options};
//! let opts = Options { horizon_ms: 20_000, ..Options::default() };
//! let r = run_one(3, &opts);
//! assert!(r.violations.is_empty(), "{:?}", r.violations);
//! assert_eq!(r.sim_ms, 20_000);
//! ```

pub mod cli;
pub mod pool;
pub mod scenario;
pub mod shard;

use crate::sim::engine::watch::{Checked, Invariant, Violation, Watch};
use crate::sim::engine::{self, PlantedBug};
use crate::sim::inject::{Device, Injection, Node, BOOT_MS};
use crate::sim::{FrameStats, LinkLayer, Summary};
use mmic::faults::{Fault, Table8};
use scenario::{Options, Scenario};
use serde_json::Value;
use std::time::{Duration, Instant};

/// A fault the firmware must have latched within a window.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Expect {
    /// Why (the injection, or the command that raises it).
    pub why: String,
    /// Any of these faults.
    pub faults: Vec<Fault>,
    /// From, ms.
    pub from: u32,
    /// To, ms (inclusive).
    pub to: u32,
}

/// The injections of `s` that the firmware must see, whatever the robot is doing, and the
/// window it has: a sagging battery (low battery within 1.5 s: the 0.5 s average, then the
/// 0.5 s debounce), an obstacle on arm, gripper or bolter A (its overcurrent within 1 s: the
/// 50-sample average crosses the absolute limit before the 0.5 s pulse ends), a cut A–B line
/// (internal comm loss within 1 s: the 500 ms silence), a silent ADC or encoder on side A
/// (sensor loss within 1 s: one averaging window), a silent ADC on side B (board B falls
/// silent after a window, then internal comm loss: 1.5 s). Side A's currents and battery are
/// judged only while its ADC answers, so an obstacle or a sag is expected only if side A's ADC
/// was not silenced before the window ends. The other injections act only if the robot does
/// something that meets them (a bolting after a jam, an arm contraction after a dead switch,
/// entering Operational after an encoder offset, the next reconfiguration after a misstated
/// one): for them the swarm checks only that, once raised, the fault reaches its mode.
///
/// Two ground commands raise a fault when board A answers them: the System fault command
/// (assembly system) and a reconfiguration refused on arrival, for its initial state (initial
/// state mismatch) or for an arm commanded contracted whose switch is open (arm not fully
/// contracted, refused by the fault's name); each accepted (refused) one is expected to have
/// latched its fault by the time the ground heard of it, unless board A restarted since the
/// command was first sent.
pub fn expectations(s: &Scenario, summary: &Summary) -> Vec<Expect> {
    let cfg = &s.cfg;
    let adc_a_alive_until = |to: u32| cfg.plant.adc_silent_at[0].is_none_or(|t| t > to);
    // Board A down or restarted between `from` and `to`, ms.
    let restarted_a = |from: u32, to: u32| {
        cfg.injections.iter().any(|r| {
            r.injection == Injection::Reboot(Node::A)
                && r.at_ms.saturating_add(BOOT_MS) >= from
                && r.at_ms <= to
        })
    };
    let mut out = Vec::new();
    for inj in &cfg.injections {
        let t = inj.at_ms;
        let (faults, window, needs_adc_a): (Vec<Fault>, u32, bool) = match inj.injection {
            Injection::Fault(Table8::LowBattery) => (vec![Fault::LowBattery], 1_500, true),
            Injection::Fault(Table8::LocomotionOvercurrent) => (
                vec![
                    Fault::LocomotionOvercurrent,
                    Fault::LocomotionOvercurrentIdle,
                ],
                1_000,
                true,
            ),
            Injection::Fault(Table8::GripperOvercurrent) => (
                vec![Fault::GripperOvercurrent, Fault::GripperOvercurrentIdle],
                1_000,
                true,
            ),
            Injection::Fault(Table8::BolterOvercurrent) => (
                vec![Fault::BolterOvercurrent, Fault::BolterOvercurrentIdle],
                1_000,
                true,
            ),
            Injection::Fault(Table8::InternalCommLoss) => {
                (vec![Fault::InternalCommLoss], 1_000, false)
            }
            Injection::Silent(Device::AdcA) | Injection::Silent(Device::Encoder) => {
                (vec![Fault::SensorLoss], 1_000, false)
            }
            Injection::Silent(Device::AdcB) => (vec![Fault::InternalCommLoss], 1_500, false),
            _ => continue,
        };
        let to = t.saturating_add(window);
        if to > cfg.max_sim_ms || (needs_adc_a && !adc_a_alive_until(to)) {
            continue;
        }
        // Board A restarting in the window (or just before it) loses what it had latched and
        // sees nothing while down: a pulse may pass unseen; the restart is the event then.
        if restarted_a(t.saturating_sub(1_000), to) {
            continue;
        }
        out.push(Expect {
            why: format!("{}@{:.3}", inj.injection.name(), t as f64 / 1000.0),
            faults,
            from: t,
            to,
        });
    }
    for r in &summary.records {
        let e = &r["event"];
        if r["kind"] != "event" || e["type"] != "done" {
            continue;
        }
        let t = r["t_ms"].as_u64().unwrap_or(0) as u32;
        let fault = if e["command"] == "system_fault" && e["outcome"] == "accepted" {
            Some(Fault::AssemblySystem)
        } else if e["command"].get("reconfigure").is_some()
            && e["outcome"]["refused"] == "initial_state_mismatch"
        {
            Some(Fault::InitialStateMismatch)
        } else if e["command"].get("reconfigure").is_some()
            && e["outcome"]["refused"] == "arm_not_contracted"
        {
            Some(Fault::ArmNotContracted)
        } else {
            None
        };
        // A restart of board A since the command was first sent (at most its life before the
        // ground heard) may have cleared the fault while its log kept the outcome, which then
        // answers every copy: the report can come long after the fault it raised is gone.
        let sent = t.saturating_sub(cfg.command_life_ms());
        if let (Some(f), false) = (fault, restarted_a(sent, t)) {
            out.push(Expect {
                why: format!("{} {} at {t} ms", e["command"], e["outcome"]),
                faults: vec![f],
                from: t.saturating_sub(2_000),
                to: t,
            });
        }
    }
    out
}

/// What one seed's run gave.
#[derive(Debug, Clone)]
pub struct RunOutcome {
    /// The seed.
    pub seed: u64,
    /// The scenario, in one line.
    pub scenario: String,
    /// Its link layer (packets; frames with PUS over the space data link).
    pub link: LinkLayer,
    /// With SDLS on the frames: the attacker's rate (0: none).
    pub sdls: Option<f64>,
    /// Simulated ms covered.
    pub sim_ms: u32,
    /// Every broken invariant.
    pub violations: Vec<Violation>,
    /// The opportunities each invariant had.
    pub checked: Checked,
    /// Injected faults checked to have been raised.
    pub expected: u64,
    /// Whether the plan completed.
    pub completed: bool,
    /// The run's summary (none if it panicked).
    pub summary: Option<Summary>,
}

/// Runs the scenario of `seed` and judges it.
pub fn run_one(seed: u64, opts: &Options) -> RunOutcome {
    let s = Scenario::from_seed(seed, opts);
    judge(&s)
}

/// Runs scenario `s` (its own configuration: log and all) and judges it.
pub fn judge(s: &Scenario) -> RunOutcome {
    let run = std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| {
        engine::run_watched(&s.cfg, true)
    }));
    let mut out = RunOutcome {
        seed: s.seed,
        scenario: s.describe(),
        link: s.link,
        sdls: s.sdls,
        sim_ms: 0,
        violations: Vec::new(),
        checked: Checked::default(),
        expected: 0,
        completed: false,
        summary: None,
    };
    let (summary, watch) = match run {
        Ok(Ok((summary, Some(watch)))) => (summary, watch),
        Ok(Ok((_, None))) | Ok(Err(_)) => {
            out.violations.push(Violation {
                t_ms: 0,
                robot: 0,
                invariant: Invariant::Panic,
                detail: "the run did not start (configuration refused)".to_string(),
            });
            return out;
        }
        Err(p) => {
            let what = p
                .downcast_ref::<String>()
                .cloned()
                .or_else(|| p.downcast_ref::<&str>().map(|s| s.to_string()))
                .unwrap_or_default();
            out.violations.push(Violation {
                t_ms: 0,
                robot: 0,
                invariant: Invariant::Panic,
                detail: format!("panicked: {what}"),
            });
            return out;
        }
    };
    let mut watch: Watch = watch;
    let ended = summary
        .records
        .iter()
        .filter(|r| r["kind"] == "event" && r["event"]["type"] == "done")
        .count();
    watch.ended(ended as u64);
    let expects = expectations(s, &summary);
    out.expected = expects.len() as u64;
    for e in &expects {
        if !e.faults.iter().any(|f| watch.had(0, *f, e.from, e.to)) {
            let raised: Vec<String> = watch.raised[0]
                .iter()
                .map(|(t, f)| format!("{}@{t}", f.name()))
                .collect();
            watch.violations.push(Violation {
                t_ms: e.to,
                robot: 0,
                invariant: Invariant::InjectedFaultMissed,
                detail: format!(
                    "{}: none of {:?} latched in {}..={} ms (raised: {})",
                    e.why,
                    e.faults.iter().map(|f| f.name()).collect::<Vec<_>>(),
                    e.from,
                    e.to,
                    raised.join(", ")
                ),
            });
        }
    }
    out.sim_ms = summary.sim_ms;
    out.completed = summary.completed();
    out.violations = watch.violations;
    out.checked = watch.checked;
    out.summary = Some(summary);
    out
}

/// The command that replays seed `seed` with these options.
pub fn replay_command(seed: u64, opts: &Options) -> String {
    let mut c = format!("mmic swarm --replay {seed}");
    if opts.horizon_ms != Options::default().horizon_ms {
        c.push_str(&format!(" --sim-seconds {}", opts.horizon_ms / 1000));
    }
    match opts.planted_bug {
        PlantedBug::None => {}
        PlantedBug::DoubleExec => c.push_str(" --plant-bug double-exec"),
        PlantedBug::LogNotRestored => c.push_str(" --plant-bug log-not-restored"),
    }
    if opts.link != Options::default().link {
        c.push_str(&format!(" --link {}", opts.link.name()));
    }
    if opts.sdls != Options::default().sdls {
        c.push_str(&format!(" --sdls {}", opts.sdls.name()));
    }
    if opts.restarts != Options::default().restarts {
        c.push_str(&format!(" --restarts {}", opts.restarts.name()));
    }
    c
}

/// How a swarm went.
#[derive(Debug, Clone, Default)]
pub struct Report {
    /// Runs made.
    pub runs: u64,
    /// Simulated ms covered, all runs.
    pub sim_ms: u64,
    /// Wall time.
    pub wall: Duration,
    /// The failing runs (their first violations).
    pub failures: Vec<RunOutcome>,
    /// The opportunities each invariant had, all runs.
    pub checked: Checked,
    /// Injected faults checked to have been raised, all runs.
    pub expected: u64,
    /// Runs whose plan completed.
    pub completed: u64,
    /// Runs over the space data link (PUS in TC and TM frames, COP-1).
    pub frame_runs: u64,
    /// What the space data link did, those runs together.
    pub frames: FrameStats,
    /// Frames runs secured with SDLS.
    pub sdls_runs: u64,
    /// Of those, runs with an attacker on the uplink.
    pub attacked_runs: u64,
    /// Runs in which some node restarted.
    pub restart_runs: u64,
    /// Restarts of board A, board B and the server board, all runs.
    pub restarts: [u64; 4],
    /// The seeds these runs were (count and digest).
    pub seeds: shard::SeedDigest,
}

/// Adds `b`'s figures to `a`'s.
fn add_frames(a: &mut FrameStats, b: &FrameStats) {
    a.tc_frames += b.tc_frames;
    a.retransmissions += b.retransmissions;
    a.alerts += b.alerts;
    a.clcws += b.clcws;
    a.lockout_reports += b.lockout_reports;
    a.accepted += b.accepted;
    a.discarded += b.discarded;
    a.tm_frames += b.tm_frames;
    a.tm_lost += b.tm_lost;
    a.tm_packets_dropped += b.tm_packets_dropped;
    a.sdls = match (a.sdls, b.sdls) {
        (Some(x), Some(y)) => Some(x.merged(y)),
        (x, y) => x.or(y),
    };
}

impl Report {
    /// Runs per wall second.
    pub fn runs_per_second(&self) -> f64 {
        self.runs as f64 / self.wall.as_secs_f64().max(1e-9)
    }

    /// Simulated hours covered.
    pub fn sim_hours(&self) -> f64 {
        self.sim_ms as f64 / 3_600_000.0
    }

    /// The summary as text (the failures each with their replay command).
    pub fn text(&self, opts: &Options) -> String {
        let c = &self.checked;
        let mut t = format!(
            "swarm: {} runs in {:.1} s wall ({:.1} runs/s), {:.2} simulated hours ({:.0}x real time); \
             {} plans completed, {} ended otherwise (a fault, a refusal, a Stop never reset)\n\
             checked: {} admissions traced to their sender's packet, {} board A ticks in motion \
             (grippers), {} ticks in Standby (drives, motion), {} faults raised (their mode), \
             {} commands ended, {} injected faults expected in time, every run for panics\n",
            self.runs,
            self.wall.as_secs_f64(),
            self.runs_per_second(),
            self.sim_hours(),
            self.sim_ms as f64 / 1000.0 / self.wall.as_secs_f64().max(1e-9),
            self.completed,
            self.runs - self.completed,
            c.admissions,
            c.motion_ticks,
            c.standby_ticks,
            c.faults_raised,
            c.commands_ended,
            self.expected,
        );
        let f = &self.frames;
        t.push_str(&format!(
            "space data link: {} runs over frames: {} TC frames sent ({} retransmitted, {} FOP-1 \
             alerts), {} AD frames accepted and {} discarded by FARM-1; {} TM frames, {} lost, {} \
             TM packets cut by a lost frame\n",
            self.frame_runs,
            f.tc_frames,
            f.retransmissions,
            f.alerts,
            f.accepted,
            f.discarded,
            f.tm_frames,
            f.tm_lost,
            f.tm_packets_dropped,
        ));
        if let Some(x) = &f.sdls {
            t.push_str(&format!(
                "{} of them with SDLS ({} with an attacker, {} attack frames judged): {}\n",
                self.sdls_runs,
                self.attacked_runs,
                c.attack_frames,
                crate::sim::report::sdls_text(x)
            ));
        }
        t.push_str(&format!(
            "restarts: {} runs with a node restarting: board A {} times, board B {}, the server \
             board {}, the ground {}; commands executed twice: {}\n",
            self.restart_runs,
            self.restarts[0],
            self.restarts[1],
            self.restarts[2],
            self.restarts[3],
            c.executed_twice,
        ));
        if self.failures.is_empty() {
            t.push_str("result: no invariant broken\n");
        }
        for f in &self.failures {
            t.push_str(&format!("FAILED {}\n", f.scenario));
            for v in &f.violations {
                t.push_str(&format!(
                    "  {} at {} ms (robot {}): {}\n",
                    v.invariant.name(),
                    v.t_ms,
                    v.robot + 1,
                    v.detail
                ));
            }
            t.push_str(&format!("  replay: {}\n", replay_command(f.seed, opts)));
        }
        t
    }

    /// As JSON.
    pub fn json(&self, opts: &Options) -> Value {
        let c = &self.checked;
        serde_json::json!({
            "runs": self.runs,
            "sim_ms": self.sim_ms,
            "wall_s": self.wall.as_secs_f64(),
            "runs_per_second": self.runs_per_second(),
            "sim_hours": self.sim_hours(),
            "completed": self.completed,
            "frame_runs": self.frame_runs,
            "sdls_runs": self.sdls_runs,
            "attacked_runs": self.attacked_runs,
            "frames": self.frames,
            "checked": {
                "admissions": c.admissions, "motion_ticks": c.motion_ticks,
                "standby_ticks": c.standby_ticks, "faults_raised": c.faults_raised,
                "commands_ended": c.commands_ended, "injected_faults_raised": self.expected,
                "attack_frames": c.attack_frames,
            },
            "executed_twice": c.executed_twice,
            "restart_runs": self.restart_runs,
            "restarts": {
                "board_a": self.restarts[0], "board_b": self.restarts[1], "server": self.restarts[2],
                "ground": self.restarts[3],
            },
            "failures": self.failures.iter().map(|f| serde_json::json!({
                "seed": f.seed,
                "link": f.link.name(),
                "scenario": f.scenario,
                "replay": replay_command(f.seed, opts),
                "violations": f.violations.iter().map(|v| serde_json::json!({
                    "invariant": v.invariant.name(), "t_ms": v.t_ms, "detail": v.detail,
                })).collect::<Vec<_>>(),
            })).collect::<Vec<_>>(),
        })
    }
}

/// Runs seeds from `seed_start` on until `budget` of wall time is spent (or `max_runs` runs,
/// or `stop_at_failures` failures), on every core ([`pool::default_jobs`]); `progress` gets a
/// line every few seconds.
pub fn swarm(
    seed_start: u64,
    budget: Duration,
    max_runs: Option<u64>,
    stop_at_failures: usize,
    opts: &Options,
    progress: &mut dyn FnMut(String),
) -> Report {
    swarm_over(
        &mut seeds_from(seed_start, max_runs),
        budget,
        stop_at_failures,
        pool::default_jobs(),
        opts,
        progress,
    )
}

/// The seeds of [`swarm`]: from `seed_start` on, at most `max_runs` of them (unbounded: none).
pub fn seeds_from(seed_start: u64, max_runs: Option<u64>) -> impl Iterator<Item = u64> {
    let runs = max_runs.map_or(usize::MAX, |m| usize::try_from(m).unwrap_or(usize::MAX));
    (seed_start..=u64::MAX).take(runs)
}

/// Runs the seeds `seeds` gives, on `jobs` threads, until it ends or `budget` of wall time is
/// spent (or `stop_at_failures` failures); `progress` gets a line every few seconds. The report
/// counts the seeds in the order `seeds` gives them, whatever the threads, and says which it
/// counted ([`Report::seeds`]: `mmic swarm --shard` digests them).
pub fn swarm_over(
    seeds: &mut dyn Iterator<Item = u64>,
    budget: Duration,
    stop_at_failures: usize,
    jobs: usize,
    opts: &Options,
    progress: &mut dyn FnMut(String),
) -> Report {
    let start = Instant::now();
    let mut last = start;
    let mut r = Report::default();
    let go_on = || start.elapsed() < budget;
    let run = |seed| run_one(seed, opts);
    pool::in_order(seeds, jobs, &go_on, &run, &mut |seed, o| {
        r.add(seed, o, opts, progress);
        if r.failures.len() >= stop_at_failures {
            return false;
        }
        if last.elapsed() >= Duration::from_secs(10) {
            last = Instant::now();
            // A shard has no budget: it runs its share.
            let left = if budget < Duration::MAX {
                let left = budget.saturating_sub(start.elapsed());
                format!(", {:.0} s left", left.as_secs_f64())
            } else {
                String::new()
            };
            progress(format!(
                "{} runs, {:.1} simulated hours, {} failed{left}",
                r.runs,
                r.sim_ms as f64 / 3_600_000.0,
                r.failures.len(),
            ));
        }
        true
    });
    r.wall = start.elapsed();
    r
}

impl Report {
    /// Counts seed `seed`'s run `o` (a failure with its replay command to `progress`).
    fn add(
        &mut self,
        seed: u64,
        mut o: RunOutcome,
        opts: &Options,
        progress: &mut dyn FnMut(String),
    ) {
        let r = self;
        r.seeds.add(seed);
        r.runs += 1;
        r.sim_ms += o.sim_ms as u64;
        r.expected += o.expected;
        r.completed += o.completed as u64;
        if o.link == LinkLayer::Frames {
            r.frame_runs += 1;
        }
        if let Some(a) = o.sdls {
            r.sdls_runs += 1;
            r.attacked_runs += u64::from(a > 0.0);
        }
        if let Some(f) = o.summary.as_ref().and_then(|s| s.frames.as_ref()) {
            add_frames(&mut r.frames, f);
        }
        let (c, k) = (&mut r.checked, &o.checked);
        c.admissions += k.admissions;
        c.motion_ticks += k.motion_ticks;
        c.standby_ticks += k.standby_ticks;
        c.faults_raised += k.faults_raised;
        c.commands_ended += k.commands_ended;
        c.attack_frames += k.attack_frames;
        c.restarts += k.restarts;
        c.executed_twice += k.executed_twice;
        if let Some(s) = &o.summary {
            for (t, n) in r.restarts.iter_mut().zip(s.restarts) {
                *t += u64::from(n);
            }
            r.restart_runs += u64::from(s.restarts.iter().any(|&n| n > 0));
        }
        if !o.violations.is_empty() {
            o.summary = None;
            progress(format!(
                "seed {seed}: {} -- replay: {}",
                o.violations
                    .iter()
                    .map(|v| format!("{} at {} ms", v.invariant.name(), v.t_ms))
                    .collect::<Vec<_>>()
                    .join(", "),
                replay_command(seed, opts)
            ));
            r.failures.push(o);
        }
    }
}
