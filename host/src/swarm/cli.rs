//! `mmic swarm`: arguments and output around [`super::swarm`] and its replay.

use super::scenario::{LinkDraw, Options, RestartDraw, Scenario, SdlsDraw};
use super::shard::{self, SeedRange, Shard};
use super::{judge, replay_command, swarm_over};
use crate::error::CliError;
use crate::sim::engine::PlantedBug;
use serde_json::Value;
use std::io::Write;
use std::path::{Path, PathBuf};
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
Reset, and restarts of board A, board B or the server board (0.4 of the runs, --restarts). Each run lasts --sim-seconds of simulated time; the robot idles, still watched, after
its plan ends.

Invariants, on every run: no command admitted twice by board A (each traced to the packet its
sender wrote, whatever its sequence number; a Heartbeat poll, which does nothing, may run again
after a restart); at least one gripper closed at every board A tick
of a motion; nothing driven by board A in Standby, nothing moving in the plant from 100 ms after
entering it; every fault raised in Operational takes Table 8's mode in the same tick (low
battery and assembly system at the motion's end), and no fault raises power; every command the
ground sent ends (accepted, refused, or reported unacknowledged); every injected fault the
firmware must see whatever it is doing is latched in time (sagging battery, obstacles, cut A-B
line, silent sensors; the System fault command and a misstated reconfiguration when board A
takes them); with SDLS, no attack frame (a replayed or bit-flipped TC frame) reaches FARM-1 and
the server board verifies no more TC frames than the ground protected; no panic.

A failing seed prints the one command that replays it: `mmic swarm --replay SEED` runs the same
scenario, prints it and its violations, and writes the whole log to --out.

A campaign over N machines: `--shard K/N --runs R` runs the seeds of --seed-start..+R whose
offset is K-1 modulo N (its whole share: no wall-clock budget, so --seconds is refused), and its
--json says which shard it is and which seeds it ran (count and digest). `--merge` adds the N
shards' reports up into the report the single `--runs R` run writes (its wall-clock fields
aside), refusing a shard missing or given twice, or shards whose options differ.";

/// `mmic swarm --help`'s examples and exit codes.
pub const AFTER: &str = "\
Examples:
  mmic swarm --seconds 60                     a minute of seeds from 1 (CI's budget)
  mmic swarm --seconds 60 --seed-start 5000   other seeds
  mmic swarm --runs 200 --json target/swarm.json
  mmic swarm --replay 85 --out target/swarm-85   one seed again, with its whole log
  mmic swarm --seconds 60 --plant-bug double-exec   the swarm's own test: a planted double execution
  mmic swarm --seconds 60 --restarts on --plant-bug log-not-restored   board A boots without its log
  mmic swarm --seconds 60 --link frames      every PUS scenario over the space data link
  mmic swarm --seconds 60 --link packets     scenarios as they were before frames were drawn
  mmic swarm --seconds 60 --link frames --sdls on   every PUS run over frames secured, most attacked
  mmic swarm --runs 100000 --shard 3/8 --json shard-3.json   machine 3 of 8's share of seeds 1..=100000
  mmic swarm --merge shard-*.json --json swarm.json   the 8 shards' reports as the single run's
    (array jobs: K8s Indexed Job K=$((JOB_COMPLETION_INDEX+1)), Slurm K=$SLURM_ARRAY_TASK_ID;
     docs/swarm-and-fleets.md, \"Sharding a campaign\")

Exit codes: 0 no invariant broken; 1 an invariant broke (the replay command is printed; with
--merge, in any shard); 2 bad arguments, or shard reports that do not merge (the message says
which shard is missing or twice, or which option differs); 3 a file could not be read or
written.";

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
    /// Plant a bug in the engine's shells (none, double-exec, log-not-restored): the swarm
    /// must find it.
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
    /// Node restarts: any (drawn: 0.4 of the runs restart board A, board B or the server board
    /// one to three times), off, or on (every run). Part of a seed's scenario: a replay needs
    /// the same.
    #[arg(long, default_value = "any", value_parser = restart_draw)]
    pub restarts: RestartDraw,
    /// Seeds run at once, each on a thread of its own (default: the cores this process may
    /// use). The report is the same for any number: the runs are counted in seed order.
    #[arg(long, value_name = "N")]
    pub jobs: Option<usize>,
    /// Replay this one seed: print its scenario and violations, write its whole log.
    #[arg(long, value_name = "SEED")]
    pub replay: Option<u64>,
    /// Where --replay writes its log (sim.jsonl) and plan (plan.txt).
    #[arg(long, value_name = "DIR", default_value = "target/swarm")]
    pub out: PathBuf,
    /// Write the report as JSON to this file.
    #[arg(long, value_name = "FILE")]
    pub json: Option<PathBuf>,
    /// Run shard K of N of the campaign --seed-start S --runs R: the seeds S+K-1, S+K-1+N, ...
    /// below S+R, all of them (needs --runs; --seconds is refused: a budget would make the
    /// shards' union depend on each machine's speed).
    #[arg(long, value_name = "K/N", value_parser = shard_arg,
          conflicts_with_all = ["seconds", "replay"])]
    pub shard: Option<Shard>,
    /// Merge the --json reports of a sharded campaign's N shards into the single run's report
    /// (printed; --json writes it): every shard once, all with the same options.
    #[arg(long, value_name = "FILE", num_args = 1..,
          conflicts_with_all = ["seconds", "runs", "seed_start", "sim_seconds", "max_failures",
                                "plant_bug", "link", "sdls", "restarts", "replay", "out",
                                "shard"])]
    pub merge: Vec<PathBuf>,
}

fn shard_arg(s: &str) -> Result<Shard, shard::ShardError> {
    s.parse()
}

fn planted(s: &str) -> Result<PlantedBug, String> {
    s.parse()
}

fn link_draw(s: &str) -> Result<LinkDraw, String> {
    s.parse()
}

fn sdls_draw(s: &str) -> Result<SdlsDraw, String> {
    s.parse().map_err(|e| format!("--sdls: {e}"))
}

fn restart_draw(s: &str) -> Result<RestartDraw, String> {
    s.parse().map_err(|e| format!("--restarts: {e}"))
}

/// The seeds of a run, in the order they run.
type Seeds = Box<dyn Iterator<Item = u64>>;

/// The seeds a run takes, its wall-clock budget and, for a shard, the campaign's range: a
/// shard's seeds are a fixed share of a fixed range; a single run's, the range (or every seed
/// from --seed-start) cut by the budget.
fn seeds_of(a: &SwarmArgs) -> Result<(Seeds, Duration, Option<SeedRange>), CliError> {
    Ok(match a.shard {
        Some(s) => {
            let runs = a.runs.ok_or_else(|| {
                CliError::Usage(format!(
                    "--shard {s} needs --runs R: the shards split the seeds --seed-start .. \
                     --seed-start + R between them, and a wall-clock budget (--seconds) would \
                     make their union depend on each machine's speed"
                ))
            })?;
            let range =
                SeedRange::new(a.seed_start, runs).map_err(|e| CliError::Usage(e.to_string()))?;
            eprintln!(
                "swarm: shard {s}: {} of the {runs} seeds from {} (offset {} modulo {})",
                s.share(range),
                a.seed_start,
                s.k() - 1,
                s.n(),
            );
            (Box::new(s.seeds(range)), Duration::MAX, Some(range))
        }
        None => {
            let runs = a
                .runs
                .map_or(usize::MAX, |r| usize::try_from(r).unwrap_or(usize::MAX));
            let seeds = Box::new((a.seed_start..=u64::MAX).take(runs));
            (seeds, Duration::from_secs_f64(a.seconds), None)
        }
    })
}

/// Runs `mmic swarm`.
pub fn run(a: SwarmArgs, out: &mut dyn Write) -> Result<(), CliError> {
    if !a.merge.is_empty() {
        return merge(&a.merge, a.json.as_deref(), out);
    }
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
        restarts: a.restarts,
    };
    if let Some(seed) = a.replay {
        return replay(seed, &opts, &a.out, out);
    }
    let (seeds, budget, range) = seeds_of(&a)?;
    let mut seeds = seeds;
    let report = swarm_over(
        &mut seeds,
        budget,
        a.max_failures.max(1),
        a.jobs.unwrap_or_else(super::pool::default_jobs).max(1),
        &opts,
        &mut |line| eprintln!("swarm: {line}"),
    );
    let digest = report.seeds;
    let mut text = report.text(&opts);
    let mut json = report.json(&opts);
    json["options"] = serde_json::json!({
        "seed_start": a.seed_start,
        "runs": a.runs,
        "sim_seconds": a.sim_seconds,
        "link": opts.link.name(),
        "sdls": opts.sdls.name(),
        "restarts": opts.restarts.name(),
        "plant_bug": match opts.planted_bug {
            PlantedBug::None => "none",
            PlantedBug::DoubleExec => "double-exec",
            PlantedBug::LogNotRestored => "log-not-restored",
        },
    });
    json["seeds"] = digest.json();
    if let (Some(s), Some(range)) = (a.shard, range) {
        let share = s.share(range);
        json["shard"] = serde_json::json!({
            "k": s.k(), "n": s.n(), "share": share, "complete": digest.count() == share,
        });
        text.push_str(&format!(
            "shard {s}: {} of its {share} seeds run{}\n",
            digest.count(),
            if digest.count() == share {
                ""
            } else {
                " (stopped at --max-failures)"
            }
        ));
    }
    write!(out, "{text}").map_err(CliError::Output)?;
    if let Some(path) = &a.json {
        write_json(path, &json)?;
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

/// Writes `v` to `path`, pretty, with a final newline.
fn write_json(path: &Path, v: &Value) -> Result<(), CliError> {
    let text = serde_json::to_string_pretty(v).map_err(|e| CliError::Output(e.into()))?;
    std::fs::write(path, text + "\n").map_err(|source| CliError::Write {
        path: path.to_path_buf(),
        source,
    })
}

/// `mmic swarm --merge FILE...`: the shards' reports as the single run's.
fn merge(files: &[PathBuf], json: Option<&Path>, out: &mut dyn Write) -> Result<(), CliError> {
    let mut reports = Vec::new();
    for f in files {
        let text = std::fs::read_to_string(f).map_err(|source| CliError::Read {
            path: f.clone(),
            source,
        })?;
        let v: Value = serde_json::from_str(&text)
            .map_err(|e| CliError::Usage(format!("{}: not JSON: {e}", f.display())))?;
        reports.push((f.display().to_string(), v));
    }
    let merged = shard::merge(&reports).map_err(|e| CliError::Usage(e.to_string()))?;
    write!(out, "{}", shard::merged_text(&merged)).map_err(CliError::Output)?;
    if let Some(path) = json {
        write_json(path, &merged)?;
    }
    match merged["failures"].as_array().and_then(|f| f.first()) {
        None => Ok(()),
        Some(f) => Err(CliError::Invariant(format!(
            "seed {} broke {}; replay: {}",
            f["seed"],
            f["violations"]
                .as_array()
                .map(Vec::as_slice)
                .unwrap_or(&[])
                .iter()
                .filter_map(|v| v["invariant"].as_str())
                .collect::<Vec<_>>()
                .join(", "),
            f["replay"].as_str().unwrap_or("?")
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
