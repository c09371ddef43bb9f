//! `mmic fleet`: arguments and output around [`super::run_virtual`] and
//! [`super::realtime::run`], and the sweep over fleet sizes with its plot.

use super::{realtime, run_virtual, FleetConfig, FleetResult};
use crate::error::CliError;
use crate::sim::nodes::OVERRUN_MS;
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
2 bad arguments; 3 an output could not be written or a socket opened; 4 (--realtime) a poll was
missed while the boards' ticks ran 100 ms or more late: the host fell behind, so the run measured
the host, not the protocol.";

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

/// Every run answered every poll in time; or which did not. A realtime run whose board ticks
/// started [`OVERRUN_MS`] or more late measured the host, not the robots' protocol: it is
/// reported as the host falling behind (exit 4, as `mmic sim`), not as a missed window.
fn verdict(all: &[FleetResult]) -> Result<(), CliError> {
    match all.iter().find(|r| !r.all_answered_in_time()) {
        None => Ok(()),
        Some(r) => match r.max_tick_lateness_ms {
            Some(late_ms) if late_ms >= OVERRUN_MS => Err(CliError::HostBehind { late_ms }),
            _ => Err(CliError::Fleet(format!(
                "not every poll answered within 0.7 s: {}",
                r.line()
            ))),
        },
    }
}

/// The sweep's plot, three charts against log10 of the fleet size: simulated robot-seconds
/// per wall second (virtual time), the longest answer to a poll with the paper's 0.7 s window,
/// and the share of polls answered within it (realtime).
pub fn plot(all: &[FleetResult]) -> String {
    use crate::plot::{line_chart_with, LineOptions, Series};
    let x = |r: &FleetResult| (r.robots as f64).log10();
    let virt: Vec<(f64, f64)> = all
        .iter()
        .filter(|r| r.threads.is_none())
        .map(|r| (x(r), r.robot_seconds_per_wall_second() / 1000.0))
        .collect();
    let real: Vec<&FleetResult> = all.iter().filter(|r| r.threads.is_some()).collect();
    let longest: Vec<(f64, f64)> = real
        .iter()
        .map(|r| (x(r), r.max_latency_ms as f64))
        .collect();
    let window: Vec<(f64, f64)> = real.iter().map(|r| (x(r), 700.0)).collect();
    let share: Vec<(f64, f64)> = real
        .iter()
        .map(|r| {
            let (ok, n) = r.attempts;
            (x(r), ok as f64 * 100.0 / n.max(1) as f64)
        })
        .collect();
    let legend = LineOptions {
        legend: true,
        ..Default::default()
    };
    let a = line_chart_with(
        "Virtual time: simulated robot-seconds per wall second",
        "log10(robots)",
        "thousand robot-s per wall s",
        legend,
        &[Series {
            name: "virtual time",
            points: &virt,
        }],
    );
    let b = line_chart_with(
        "Realtime: longest answer to a poll (the paper's window: 700 ms)",
        "log10(robots)",
        "longest answer, ms",
        LineOptions {
            y_range: Some((0.0, 800.0)),
            ..legend
        },
        &[
            Series {
                name: "realtime",
                points: &longest,
            },
            Series {
                name: "0.7 s window",
                points: &window,
            },
        ],
    );
    let c = line_chart_with(
        "Realtime: polls answered within 0.7 s",
        "log10(robots)",
        "% of polls",
        LineOptions {
            y_range: Some((98.0, 100.2)),
            ..legend
        },
        &[Series {
            name: "realtime",
            points: &share,
        }],
    );
    stack(&[&a, &b, &c])
}

/// SVG charts one above the other in one SVG.
fn stack(charts: &[&str]) -> String {
    let attr = |s: &str, name: &str| {
        s.split(&format!("{name}=\""))
            .nth(1)
            .and_then(|r| r.split('"').next())
            .and_then(|v| v.parse::<f64>().ok())
            .unwrap_or(0.0)
    };
    let mut body = String::new();
    let (mut width, mut y) = (0.0f64, 0.0);
    for c in charts {
        body.push_str(&format!("<g transform=\"translate(0,{y})\">{c}</g>\n"));
        width = width.max(attr(c, "width"));
        y += attr(c, "height");
    }
    format!(
        "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"{width}\" height=\"{y}\">\n{body}</svg>\n"
    )
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::error::CliError;
    use std::time::Duration;

    fn run(answered: u64, late: Option<u32>) -> FleetResult {
        FleetResult {
            robots: 2,
            sim_seconds: 10.0,
            wall: Duration::from_secs(10),
            attempts: (answered, 16),
            max_latency_ms: 300,
            ends: (0, 2),
            threads: late.map(|_| 3),
            max_tick_lateness_ms: late,
        }
    }

    #[test]
    fn a_missed_window_is_the_hosts_only_when_ticks_ran_late() {
        assert!(verdict(&[run(16, Some(500))]).is_ok());
        assert!(matches!(verdict(&[run(15, None)]), Err(CliError::Fleet(_))));
        assert!(matches!(
            verdict(&[run(15, Some(OVERRUN_MS - 1))]),
            Err(CliError::Fleet(_))
        ));
        let e = verdict(&[run(15, Some(OVERRUN_MS))]).unwrap_err();
        assert!(matches!(e, CliError::HostBehind { late_ms } if late_ms == OVERRUN_MS));
        assert_eq!(e.exit_code(), crate::exit::EXIT_HOST);
    }
}
