//! `mmic opsui`: the opsUI on a real serial device — the paper's path opsUI → USB serial →
//! server board → WiFi → board A (Section 3) from the host's end. It opens the device with
//! spec/boards.toml `[ops_line]` ([`crate::serial`]), runs a plan (the format and files of
//! `mmic sim --plan`; the built-in demo by default) through the library's plan runner and
//! uplink on the wall clock — a command every 1.2 s, an attempt failed when no heartbeat came
//! within 0.7 s, the efficiency over the last 100 attempts (Section 8) — with live progress on
//! stderr, and prints the simulator's summary of the ground at the end ([`summary`]).
//!
//! At the other end: a server board running the relay image (firmware/server-paper), or the
//! simulator's server board and robot on a serial device of their own (`mmic sim --realtime
//! --opsui-serial DEV`, [`crate::sim::opsline`]); host/tests/opsui_serial.rs joins the two over
//! pseudo-terminals.

pub mod server;
pub mod session;
pub mod summary;

use crate::error::CliError;
use crate::exit::EXIT_OK;
use crate::serial::LineSettings;
use crate::sim::clock::Clock;
use crate::sim::log::Log;
use crate::sim::shell::{GroundSide, LegacyGround};
use crate::sim::{SimConfig, SimStep, Summary};
use mmic::node::exactly_once::uplink;
use mmic::node::ground::plan_runner::{PlanEnd, PlanRunner};
use session::{Ending, Outcome, Session};
use std::io::Write;
use std::path::{Path, PathBuf};

/// `mmic opsui --help`'s description.
pub const HELP: &str = "\
The opsUI on a real serial device: the paper's path opsUI -> USB serial -> server board -> WiFi
-> board A (Section 3). Opens DEV with the line settings of spec/boards.toml [ops_line]
(115200 baud, 8N1, no flow control: decision opsui-serial-line), then runs a plan -- the
format and files of `mmic sim --plan`, the built-in demo by default -- through the library's
plan runner and uplink on the wall clock, as in Section 8: a command packet every 1.2 s, an
attempt failed when its heartbeat has not come back within 0.7 s, resent until acknowledged
(--max-attempts), the efficiency counted over the last 100 attempts.

Live progress goes to stderr; at the end the summary `mmic sim` prints of the ground: how the
plan ended, the attempts answered and made, the efficiency over the last 100, the longest
answer; then the commands done, what crossed the line (bytes the deframer dropped included:
nothing read is dropped uncounted) and the robot as its last heartbeat showed it.

When the line is lost (end of file, hang-up, an unplugged adapter, an I/O error) the opsUI
stops at once: a command then open ran at most once and is reported as ended unknown (decision
opsui-line-lost). At its own end it closes the device.

--scale X is only for a simulator at the other end that runs at the same scale (`mmic sim
--realtime --scale X --opsui-serial DEV`: the CI test's set-up): the paper's timing divided by
X on the wall clock. A real server board and robot run at 1, the default.";

/// `mmic opsui --help`'s examples and exit codes.
pub const AFTER: &str = "\
Examples:
  mmic opsui --serial /dev/ttyUSB0                 the demo plan through the server board on ttyUSB0
  mmic opsui --serial /dev/ttyACM0 --plan my.plan --summary-json out.json
  mmic opsui --serial /dev/pts/4 --scale 5         against `mmic sim --realtime --scale 5
                                                   --opsui-serial /dev/pts/3`, the two pseudo-
                                                   terminals joined

Exit codes: 0 the plan completed; 1 it stopped (a step refused, the robot interrupted, the time
limit); 2 bad arguments, a malformed plan file or a step that does not fit the robot's state;
3 a file could not be written; 5 the serial device cannot be opened (nothing was sent); 6 the
line was lost before the plan ended; 7 the plan ended at a step the robot never acknowledged.";

/// Arguments of `mmic opsui`.
#[derive(Debug, clap::Args)]
pub struct OpsuiArgs {
    /// The server board's serial device (e.g. /dev/ttyUSB0, /dev/ttyACM0, a /dev/pts/N).
    #[arg(long, value_name = "DEV")]
    pub serial: String,
    /// The plan file (format: host/plans/demo.plan), or `demo` for the built-in demo plan.
    #[arg(long, value_name = "FILE|demo", default_value = "demo")]
    pub plan: PathBuf,
    /// Time between transmissions, ms (Section 8: 1.2 s).
    #[arg(long, value_name = "MS", default_value_t = uplink::Config::default().period_ms)]
    pub period_ms: u32,
    /// An attempt whose heartbeat has not come within this is failed, ms (Section 8: 0.7 s).
    #[arg(long, value_name = "MS", default_value_t = uplink::Config::default().timeout_ms)]
    pub timeout_ms: u32,
    /// Attempts before a command is reported unacknowledged (spec/boards.toml `[ground]`).
    #[arg(long, value_name = "N", default_value_t = uplink::Config::default().max_attempts)]
    pub max_attempts: u8,
    /// Give up after this many seconds on the plan's clock.
    #[arg(long, value_name = "S", default_value_t = 900.0)]
    pub max_seconds: f64,
    /// Only against a simulator running at the same --scale: the paper's timing divided by X on
    /// the wall clock.
    #[arg(long, value_name = "X", default_value_t = 1.0)]
    pub scale: f64,
    /// No live progress.
    #[arg(long)]
    pub quiet: bool,
    /// Write the opsUI's log here (JSON lines: the packets on the line, attempts, commands
    /// done, steps, the plan's end).
    #[arg(long, value_name = "FILE")]
    pub log: Option<PathBuf>,
    /// Write the summary as one JSON object here.
    #[arg(long, value_name = "FILE")]
    pub summary_json: Option<PathBuf>,
}

/// The plan to run: its steps, checked against the robot's state from its `start` line.
struct Planned {
    robot: mmic::units::BoardNumber,
    start: mmic::motion::State,
    steps: Vec<SimStep>,
}

fn planned(plan: &Path) -> Result<Planned, CliError> {
    let file = (plan != Path::new("demo")).then_some(plan);
    let (path, plan) = crate::simcli::load_plan(file)?;
    let start = plan.start.unwrap_or(SimConfig::DEFAULT_START);
    plan.trace(start)
        .map_err(|error| CliError::Plan { path, error })?;
    Ok(Planned {
        robot: plan.robot,
        start,
        steps: crate::sim::steps_of(&plan),
    })
}

/// The uplink's timing from the arguments; what the uplink cannot run is refused.
fn uplink_config(a: &OpsuiArgs) -> Result<uplink::Config, CliError> {
    let usage = |m: String| Err(CliError::Usage(m));
    if a.max_attempts == 0 {
        return usage("--max-attempts: at least 1".into());
    }
    if a.period_ms == 0 || a.timeout_ms == 0 || a.timeout_ms > a.period_ms {
        return usage(format!(
            "--timeout-ms {} and --period-ms {}: both above 0, the answer window no longer \
             than the period",
            a.timeout_ms, a.period_ms
        ));
    }
    let finite_positive = |x: f64| x.is_finite() && x > 0.0;
    if !finite_positive(a.scale) || a.max_seconds.is_nan() || a.max_seconds < 0.0 {
        return usage("--scale above 0, --max-seconds not negative".into());
    }
    Ok(uplink::Config {
        period_ms: a.period_ms,
        timeout_ms: a.timeout_ms,
        max_attempts: a.max_attempts,
    })
}

/// Runs `mmic opsui`: the summary on `out`, progress on stderr.
pub fn run(a: OpsuiArgs, out: &mut dyn Write) -> Result<(), CliError> {
    let p = planned(&a.plan)?;
    let up = uplink_config(&a)?;
    let (port, settings) = crate::serial::open(&a.serial)?;
    let head = head(&a, &settings, &p, up);
    if !a.quiet {
        eprintln!("{head}");
    }
    let log = Log::memory();
    let runner = LegacyGround {
        run: PlanRunner::new(up, p.robot),
        last: None,
    };
    let ground = GroundSide::new(
        &p.steps,
        p.start,
        &[],
        vec![runner],
        !a.quiet,
        Some(log.clone()),
    );
    let clock = Clock::start(a.scale);
    let max_ms = (a.max_seconds * 1000.0).min(u32::MAX as f64) as u32;
    let o = Session::new(port, ground, clock, log, max_ms).run();
    let s = summary_of(&p, up, &o, clock.wall_elapsed());
    let verdict = verdict(&a.serial, &s, &o);
    let exit = verdict.as_ref().err().map_or(EXIT_OK, CliError::exit_code);
    write!(out, "{}", summary::text(&s, &o, &head)).map_err(CliError::Output)?;
    write_files(&a, &s, &o, exit)?;
    verdict
}

/// The run's first line: the device and its settings, the robot, the uplink's timing.
fn head(a: &OpsuiArgs, settings: &LineSettings, p: &Planned, up: uplink::Config) -> String {
    let scale = if a.scale == 1.0 {
        String::new()
    } else {
        format!(
            "; the paper's timing / {} on the wall clock (--scale)",
            a.scale
        )
    };
    format!(
        "opsui: {} ({}), robot {}: a command every {} ms, answered within {} ms, {} attempts \
         (Section 8: 1200, 700){scale}",
        a.serial,
        settings.describe(),
        p.robot.get(),
        up.period_ms,
        up.timeout_ms,
        up.max_attempts,
    )
}

/// The run as a simulator summary, for the lines the two share.
fn summary_of(p: &Planned, up: uplink::Config, o: &Outcome, wall: std::time::Duration) -> Summary {
    let mut cfg = SimConfig::with_steps(p.steps.clone());
    cfg.start_state = p.start;
    cfg.ground = up;
    let s = Summary::of_run(
        &cfg,
        vec![o.end],
        o.stats.clone(),
        o.records.clone(),
        serde_json::Value::Null,
        wall,
    );
    Summary {
        realtime: true,
        ..s
    }
}

/// How the run ends for the process: completed, or why not.
fn verdict(device: &str, s: &Summary, o: &Outcome) -> Result<(), CliError> {
    if let Ending::Lost { at_ms, why, open } = &o.ending {
        return Err(CliError::LineLost {
            device: device.to_string(),
            at_s: *at_ms as f64 / 1000.0,
            why: why.clone(),
            outstanding: summary::open_text(open),
        });
    }
    let line = crate::sim::report::plan_line(s);
    match o.end {
        Some(PlanEnd::Completed) => Ok(()),
        Some(PlanEnd::Unacknowledged { .. }) => Err(CliError::Unacknowledged(line)),
        _ => Err(CliError::Incomplete(line)),
    }
}

/// `--log` and `--summary-json`.
fn write_files(a: &OpsuiArgs, s: &Summary, o: &Outcome, exit: u8) -> Result<(), CliError> {
    let write = |path: &PathBuf, text: String| {
        std::fs::write(path, text).map_err(|source| CliError::Write {
            path: path.clone(),
            source,
        })
    };
    if let Some(path) = &a.log {
        let mut text = Vec::new();
        crate::sim::log::write_lines(&o.records, &mut text).map_err(CliError::Output)?;
        write(path, String::from_utf8_lossy(&text).into_owned())?;
    }
    if let Some(path) = &a.summary_json {
        let json = serde_json::to_string_pretty(&summary::json(s, o, exit))
            .map_err(|e| CliError::Output(e.into()))?;
        write(path, json + "\n")?;
    }
    Ok(())
}
