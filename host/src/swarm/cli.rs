//! `mmic swarm`: arguments and output around [`super::swarm`] and its replay.

use super::scenario::{LinkDraw, Options, Scenario, SdlsDraw};
use super::{judge, replay_command, swarm};
use crate::error::CliError;
use crate::sim::engine::PlantedBug;
use std::io::Write;
use std::path::PathBuf;
use std::time::Duration;

/// `mmic swarm --help`'s description.
pub const HELP: &str = "\
Run the fault swarm: seed after seed, a random scenario runs in virtual time with its
invariants checked on every tick. A scenario is drawn from its seed alone: the protocol
(legacy or PUS; with PUS, bare packets or the space data link's TC and TM frames under COP-1,
half each, --link; half the frames runs secured with SDLS, most of those with an attacker on
the uplink, --sdls), a plan (the demo, or a random walk of reconfigurations, bolts and waits from
a random state), the links' loss, duplication (resent commands), reordering, latency, jitter
and cuts, board B's clock phase, and up to three faults (battery sag, obstacles on arm,
gripper or bolter, a jammed fastener, a stuck switch, an encoder offset, silent sensors, a cut
A-B line, a misstated reconfiguration, the System fault command) plus the operator's Stop and
Reset. Each run lasts --sim-seconds of simulated time; the robot idles, still watched, after
its plan ends.

Invariants, on every run: no command admitted twice by board A (each traced to the packet its
sender wrote, whatever its sequence number); at least one gripper closed at every board A tick
of a motion; nothing driven by board A in Standby, nothing moving in the plant from 100 ms after
entering it; every fault raised in Operational takes Table 8's mode in the same tick (low
battery and assembly system at the motion's end), and no fault raises power; every command the
ground sent ends (accepted, refused, or reported unacknowledged); every injected fault the
firmware must see whatever it is doing is latched in time (sagging battery, obstacles, cut A-B
line, silent sensors; the System fault command and a misstated reconfiguration when board A
takes them); with SDLS, no attack frame (a replayed or bit-flipped TC frame) reaches FARM-1 and
the server board verifies no more TC frames than the ground protected; no panic.

A failing seed prints the one command that replays it: `mmic swarm --replay SEED` runs the same
scenario, prints it and its violations, and writes the whole log to --out.";

/// `mmic swarm --help`'s examples and exit codes.
pub const AFTER: &str = "\
Examples:
  mmic swarm --seconds 120                    two minutes of seeds from 1 (CI's budget)
  mmic swarm --seconds 60 --seed-start 5000   other seeds
  mmic swarm --runs 200 --json target/swarm.json
  mmic swarm --replay 85 --out target/swarm-85   one seed again, with its whole log
  mmic swarm --seconds 60 --plant-bug double-exec   the swarm's own test: a planted double execution
  mmic swarm --seconds 60 --link frames      every PUS scenario over the space data link
  mmic swarm --seconds 60 --link packets     scenarios as they were before frames were drawn
  mmic swarm --seconds 60 --link frames --sdls on   every PUS run over frames secured, most attacked

Exit codes: 0 no invariant broken; 1 an invariant broke (the replay command is printed);
2 bad arguments; 3 an output could not be written.";

/// Arguments of `mmic swarm`.
#[derive(Debug, clap::Args)]
pub struct SwarmArgs {
    /// Wall-clock budget, seconds.
    #[arg(long, default_value_t = 60.0)]
    pub seconds: f64,
    /// Stop after this many runs (whatever the budget).
    #[arg(long)]
    pub runs: Option<u64>,
    /// The first seed.
    #[arg(long, default_value_t = 1)]
    pub seed_start: u64,
    /// Simulated seconds per run.
    #[arg(long, default_value_t = 200)]
    pub sim_seconds: u32,
    /// Stop after this many failing seeds.
    #[arg(long, default_value_t = 5)]
    pub max_failures: usize,
    /// Plant a bug in the engine's shells (none, double-exec): the swarm must find it.
    #[arg(long, default_value = "none", value_parser = planted)]
    pub plant_bug: PlantedBug,
    /// The link layer of PUS scenarios: any (drawn, packets or frames half each), packets, or
    /// frames (the space data link, COP-1). Part of a seed's scenario: a replay needs the same.
    #[arg(long, default_value = "any", value_parser = link_draw)]
    pub link: LinkDraw,
    /// SDLS on frames scenarios: any (drawn: half of them, most with an attacker on the
    /// uplink replaying and bit-flipping captured TC frames), off, or on. Part of a seed's
    /// scenario: a replay needs the same.
    #[arg(long, default_value = "any", value_parser = sdls_draw)]
    pub sdls: SdlsDraw,
    /// Replay this one seed: print its scenario and violations, write its whole log.
    #[arg(long, value_name = "SEED")]
    pub replay: Option<u64>,
    /// Where --replay writes its log (sim.jsonl) and plan (plan.txt).
    #[arg(long, value_name = "DIR", default_value = "target/swarm")]
    pub out: PathBuf,
    /// Write the report as JSON to this file.
    #[arg(long, value_name = "FILE")]
    pub json: Option<PathBuf>,
}

fn planted(s: &str) -> Result<PlantedBug, String> {
    s.parse()
}

fn link_draw(s: &str) -> Result<LinkDraw, String> {
    s.parse()
}

fn sdls_draw(s: &str) -> Result<SdlsDraw, String> {
    s.parse()
}

/// Runs `mmic swarm`.
pub fn run(a: SwarmArgs, out: &mut dyn Write) -> Result<(), CliError> {
    if !(a.seconds.is_finite() && a.seconds >= 0.0) {
        return Err(CliError::Usage(format!(
            "--seconds {}: expected a number of seconds >= 0",
            a.seconds
        )));
    }
    if a.sim_seconds < 10 {
        return Err(CliError::Usage(format!(
            "--sim-seconds {}: a run needs at least 10 simulated seconds",
            a.sim_seconds
        )));
    }
    let opts = Options {
        horizon_ms: a.sim_seconds.saturating_mul(1000),
        planted_bug: a.plant_bug,
        link: a.link,
        sdls: a.sdls,
    };
    if let Some(seed) = a.replay {
        return replay(seed, &opts, &a.out, out);
    }
    let report = swarm(
        a.seed_start,
        Duration::from_secs_f64(a.seconds),
        a.runs,
        a.max_failures.max(1),
        &opts,
        &mut |line| eprintln!("swarm: {line}"),
    );
    write!(out, "{}", report.text(&opts)).map_err(CliError::Output)?;
    if let Some(path) = &a.json {
        let text = serde_json::to_string_pretty(&report.json(&opts))
            .map_err(|e| CliError::Output(e.into()))?;
        std::fs::write(path, text + "\n").map_err(|source| CliError::Write {
            path: path.clone(),
            source,
        })?;
    }
    match report.failures.first() {
        None => Ok(()),
        Some(f) => Err(CliError::Invariant(format!(
            "seed {} broke {}; replay: {}",
            f.seed,
            f.violations
                .iter()
                .map(|v| v.invariant.name())
                .collect::<Vec<_>>()
                .join(", "),
            replay_command(f.seed, &opts)
        ))),
    }
}

/// `mmic swarm --replay SEED`: the seed's scenario with its whole log.
fn replay(seed: u64, opts: &Options, dir: &PathBuf, out: &mut dyn Write) -> Result<(), CliError> {
    std::fs::create_dir_all(dir).map_err(|source| CliError::Write {
        path: dir.clone(),
        source,
    })?;
    let mut s = Scenario::from_seed(seed, opts);
    s.cfg.log_packets = true;
    s.cfg.log_path = Some(dir.join("sim.jsonl"));
    let plan_path = dir.join("plan.txt");
    std::fs::write(&plan_path, &s.plan).map_err(|source| CliError::Write {
        path: plan_path.clone(),
        source,
    })?;
    let o = judge(&s);
    let w = |out: &mut dyn Write, t: String| writeln!(out, "{t}").map_err(CliError::Output);
    w(out, o.scenario.clone())?;
    if let Some(summary) = &o.summary {
        w(
            out,
            crate::sim::report::text(summary).trim_end().to_string(),
        )?;
    }
    w(out, format!("log: {}", dir.join("sim.jsonl").display()))?;
    w(out, format!("plan: {}", plan_path.display()))?;
    if o.violations.is_empty() {
        w(out, format!("seed {seed}: no invariant broken"))?;
        return Ok(());
    }
    for v in &o.violations {
        w(
            out,
            format!(
                "VIOLATED {} at {} ms (robot {}): {}",
                v.invariant.name(),
                v.t_ms,
                v.robot + 1,
                v.detail
            ),
        )?;
    }
    Err(CliError::Invariant(format!(
        "seed {seed} broke {} invariant(s)",
        o.violations.len()
    )))
}
