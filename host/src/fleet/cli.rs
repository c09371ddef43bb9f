//! `mmic fleet`: arguments and output around [`super::run_virtual`] and
//! [`super::realtime::run`], and the sweep over fleet sizes with its plot.

use super::{realtime, run_virtual, FleetConfig, FleetResult};
use crate::error::CliError;
use crate::sim::Protocol;
use std::io::Write;
use std::path::PathBuf;

/// `mmic fleet --help`'s description.
pub const HELP: &str = "\
Run a fleet: N robots, each with its own server board and links, against one ground that polls
every robot at the paper's 1.2 s cadence (or runs --plan on each), and report whether every
answer came within the paper's 0.7 s window.

In virtual time (the default) the discrete-event engine runs every robot's nodes on one virtual
clock: the figure is simulated robot-seconds per wall second. With --realtime the same nodes run
on the wall clock as tasks of one async runtime with two worker threads (no thread per robot):
board A's WiFi task on its own TCP port on loopback, visited by its server board over a new
connection per command, the ground and the server boards over UDP; the figure is whether every
poll was answered within 0.7 s.

--sweep 1,10,100,1000 runs one fleet per size (in virtual time, and with --realtime on the wall
clock too, up to --realtime-max robots) and writes a plot of both against N (--plot FILE.svg).";

/// `mmic fleet --help`'s examples and exit codes.
pub const AFTER: &str = "\
Examples:
  mmic fleet --robots 1000 --seconds 60               virtual time
  mmic fleet --robots 1000 --seconds 30 --realtime    wall clock: every answer within 0.7 s?
  mmic fleet --robots 10 --plan host/plans/demo.plan --seconds 200
  mmic fleet --sweep 1,10,100,1000,10000 --seconds 10 --realtime --realtime-max 2000 \\
             --plot target/fleet.svg --json target/fleet.json

Exit codes: 0 every poll answered within 0.7 s; 1 not (the line says which figure missed);
2 bad arguments; 3 an output could not be written or a socket opened.";

/// Arguments of `mmic fleet`.
#[derive(Debug, clap::Args)]
pub struct FleetArgs {
    /// Robots.
    #[arg(long, default_value_t = 100)]
    pub robots: u32,
    /// Simulated (virtual) or wall (--realtime) seconds.
    #[arg(long, default_value_t = 60)]
    pub seconds: u32,
    /// A plan every robot runs (format: host/plans/demo.plan); without it, the ground polls.
    #[arg(long, value_name = "FILE")]
    pub plan: Option<PathBuf>,
    /// legacy or pus, between the ground and each server board.
    #[arg(long, default_value = "legacy", value_parser = protocol)]
    pub protocol: Protocol,
    /// Seed of every random choice.
    #[arg(long, default_value_t = 1)]
    pub seed: u64,
    /// On the wall clock (async tasks, real sockets) instead of in virtual time.
    #[arg(long)]
    pub realtime: bool,
    /// Fleet sizes to run one after the other (comma-separated), instead of --robots.
    #[arg(long, value_delimiter = ',', value_name = "N,N,..")]
    pub sweep: Vec<u32>,
    /// With --sweep --realtime: the largest fleet run on the wall clock.
    #[arg(long, default_value_t = 2000)]
    pub realtime_max: u32,
    /// With --sweep: the plot of both figures against N.
    #[arg(long, value_name = "FILE")]
    pub plot: Option<PathBuf>,
    /// Write the results as JSON (one object, or an array for --sweep).
    #[arg(long, value_name = "FILE")]
    pub json: Option<PathBuf>,
}

fn protocol(s: &str) -> Result<Protocol, String> {
    s.parse()
}

fn io(e: std::io::Error) -> CliError {
    CliError::Sim(e)
}

/// Runs `mmic fleet`.
pub fn run(a: FleetArgs, out: &mut dyn Write) -> Result<(), CliError> {
    let plan = match &a.plan {
        None => None,
        Some(path) => {
            let text = std::fs::read_to_string(path).map_err(|source| CliError::Read {
                path: path.clone(),
                source,
            })?;
            let p = crate::plan::parse(&text).map_err(|error| CliError::Plan {
                path: path.clone(),
                error,
            })?;
            Some(crate::sim::steps_of(&p))
        }
    };
    if a.protocol == Protocol::Pus && plan.is_none() {
        return Err(CliError::Usage(
            "--protocol pus needs --plan: over PUS the gateway polls board A itself, so a \
             waiting ground sends nothing to answer"
                .into(),
        ));
    }
    if a.robots == 0 || a.sweep.contains(&0) {
        return Err(CliError::Usage("a fleet has at least one robot".into()));
    }
    let cfg = |robots: u32| FleetConfig {
        robots,
        seconds: a.seconds,
        plan: plan.clone(),
        protocol: a.protocol,
        seed: a.seed,
        wifi_loss: 0.0,
    };
    let line = |out: &mut dyn Write, r: &FleetResult| {
        writeln!(out, "{}", r.line()).map_err(CliError::Output)
    };
    if a.sweep.is_empty() {
        let c = cfg(a.robots);
        let r = if a.realtime {
            realtime::run(&c)
        } else {
            run_virtual(&c)
        }
        .map_err(io)?;
        line(out, &r)?;
        write_json(&a.json, &r.json())?;
        return verdict(&[r]);
    }
    let mut all = Vec::new();
    for &n in &a.sweep {
        let r = run_virtual(&cfg(n)).map_err(io)?;
        line(out, &r)?;
        all.push(r);
        if a.realtime && n <= a.realtime_max {
            let r = realtime::run(&cfg(n)).map_err(io)?;
            line(out, &r)?;
            all.push(r);
        }
    }
    write_json(
        &a.json,
        &serde_json::Value::Array(all.iter().map(FleetResult::json).collect()),
    )?;
    if let Some(path) = &a.plot {
        std::fs::write(path, plot(&all)).map_err(|source| CliError::Write {
            path: path.clone(),
            source,
        })?;
        writeln!(out, "plot: {}", path.display()).map_err(CliError::Output)?;
    }
    verdict(&all)
}

fn write_json(path: &Option<PathBuf>, v: &serde_json::Value) -> Result<(), CliError> {
    if let Some(path) = path {
        let text = serde_json::to_string_pretty(v).map_err(|e| CliError::Output(e.into()))?;
        std::fs::write(path, text + "\n").map_err(|source| CliError::Write {
            path: path.clone(),
            source,
        })?;
    }
    Ok(())
}

fn verdict(all: &[FleetResult]) -> Result<(), CliError> {
    match all.iter().find(|r| !r.all_answered_in_time()) {
        None => Ok(()),
        Some(r) => Err(CliError::Fleet(format!(
            "not every poll answered within 0.7 s: {}",
            r.line()
        ))),
    }
}

/// The sweep's plot: simulated robot-seconds per wall second (virtual time) and the longest
/// answer (realtime, with the 0.7 s line), against log10 of the fleet size.
pub fn plot(all: &[FleetResult]) -> String {
    let x = |r: &FleetResult| (r.robots as f64).log10();
    let virt: Vec<(f64, f64)> = all
        .iter()
        .filter(|r| r.threads.is_none())
        .map(|r| (x(r), r.robot_seconds_per_wall_second().log10()))
        .collect();
    let real: Vec<(f64, f64)> = all
        .iter()
        .filter(|r| r.threads.is_some())
        .map(|r| (x(r), r.max_latency_ms as f64))
        .collect();
    let window: Vec<(f64, f64)> = real.iter().map(|(x, _)| (*x, 700.0)).collect();
    let a = crate::plot::line_chart_with(
        "Virtual time: simulated robot-seconds per wall second",
        "log10(robots)",
        "log10(robot-s per wall s)",
        crate::plot::LineOptions {
            legend: true,
            ..Default::default()
        },
        &[crate::plot::Series {
            name: "virtual time",
            points: &virt,
        }],
    );
    let b = crate::plot::line_chart_with(
        "Realtime: longest answer to a poll (the paper's window: 700 ms)",
        "log10(robots)",
        "longest answer, ms",
        crate::plot::LineOptions {
            legend: true,
            y_range: Some((0.0, 800.0)),
            ..Default::default()
        },
        &[
            crate::plot::Series {
                name: "realtime",
                points: &real,
            },
            crate::plot::Series {
                name: "0.7 s window",
                points: &window,
            },
        ],
    );
    stack(&a, &b)
}

/// Two SVG charts one above the other in one SVG.
fn stack(a: &str, b: &str) -> String {
    let size = |s: &str| -> (f64, f64) {
        let attr = |name: &str| {
            s.split(&format!("{name}=\""))
                .nth(1)
                .and_then(|r| r.split('"').next())
                .and_then(|v| v.parse::<f64>().ok())
                .unwrap_or(0.0)
        };
        (attr("width"), attr("height"))
    };
    let ((wa, ha), (wb, hb)) = (size(a), size(b));
    format!(
        "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"{w}\" height=\"{h}\">\n\
         <g>{a}</g>\n<g transform=\"translate(0,{ha})\">{b}</g>\n</svg>\n",
        w = wa.max(wb),
        h = ha + hb
    )
}
