//! `mmic sim` and `mmic bench`: argument handling around [`crate::sim`].

use crate::cli::{CliError, SimArgs};
use crate::sim::{self, report, SimConfig};
use std::io::Write;
use std::path::PathBuf;

fn ms(s: Option<f64>) -> Option<u32> {
    s.map(|s| (s.max(0.0) * 1000.0) as u32)
}

/// The plan `mmic sim` runs (the built-in demo without `--plan`), with its name for errors.
fn load_plan(a: &SimArgs) -> Result<(PathBuf, crate::plan::Plan), CliError> {
    let (path, text) = match &a.plan {
        None => (
            PathBuf::from("host/plans/demo.plan (built in)"),
            report::DEMO_PLAN.to_string(),
        ),
        Some(path) => {
            let text = std::fs::read_to_string(path).map_err(|source| CliError::Read {
                path: path.clone(),
                source,
            })?;
            (path.clone(), text)
        }
    };
    let plan = crate::plan::parse(&text).map_err(|error| CliError::Plan {
        path: path.clone(),
        error,
    })?;
    Ok((path, plan))
}

/// Runs `mmic sim`.
pub fn sim(a: SimArgs, out: &mut dyn Write) -> Result<(), CliError> {
    let (path, plan) = load_plan(&a)?;
    // Every step must fit the state the robot will be in: refused here, with its line and
    // column, before anything is sent.
    let start = plan.start.unwrap_or(SimConfig::DEFAULT_START);
    let states = plan
        .trace(start)
        .map_err(|error| CliError::Plan { path, error })?;
    if a.check_plan {
        let mut path_of_states = vec![start.letter().to_string()];
        for s in states.iter().flatten() {
            if path_of_states.last().map(String::as_str) != Some(&s.letter().to_string()) {
                path_of_states.push(s.letter().to_string());
            }
        }
        writeln!(
            out,
            "plan OK: {} steps for robot {}, states {}",
            plan.steps.len(),
            plan.robot.get(),
            path_of_states.join(" -> ")
        )
        .map_err(CliError::Output)?;
        return Ok(());
    }
    let steps = report::steps_of(&plan);
    std::fs::create_dir_all(&a.out).map_err(|source| CliError::Write {
        path: a.out.clone(),
        source,
    })?;
    let mut cfg = SimConfig::with_steps(steps);
    cfg.start_state = start;
    cfg.scale = a.scale;
    cfg.seed = a.seed;
    cfg.wifi_loss = a.wifi_loss;
    cfg.serial_loss = a.serial_loss;
    cfg.ab_loss = a.ab_loss;
    cfg.cut_b_at = ms(a.cut_b_at);
    cfg.plant.low_battery_at = ms(a.low_battery_at);
    cfg.plant.overcurrent_at = ms(a.overcurrent_at);
    cfg.max_sim_ms = ms(Some(a.max_seconds)).unwrap_or(u32::MAX);
    cfg.log_path = Some(a.out.join("sim.jsonl"));
    cfg.progress = !a.quiet;
    let summary = sim::run(&cfg).map_err(CliError::Sim)?;
    let plots = report::plots(&summary, &a.out).map_err(|source| CliError::Write {
        path: a.out.clone(),
        source,
    })?;
    write!(out, "{}", report::text(&summary)).map_err(CliError::Output)?;
    writeln!(out, "log: {}", a.out.join("sim.jsonl").display()).map_err(CliError::Output)?;
    for p in plots {
        writeln!(out, "plot: {}", p.display()).map_err(CliError::Output)?;
    }
    if summary.host_fell_behind() {
        // Only an unpaced run can get here; say so rather than report the host's timeouts as
        // the robot's.
        return Err(CliError::HostBehind {
            late_ms: summary.max_tick_lateness_ms,
        });
    }
    if summary.completed() {
        Ok(())
    } else {
        Err(CliError::Incomplete(
            report::text(&summary)
                .lines()
                .next()
                .unwrap_or_default()
                .to_string(),
        ))
    }
}

/// Runs `mmic bench`.
pub fn bench(max: u8, seconds: u32, out: &mut dyn Write) -> Result<(), CliError> {
    let result = crate::sim::bench::largest(max, seconds, &mut |line| {
        eprintln!("{line}");
    })
    .map_err(CliError::Sim)?;
    writeln!(out, "{result}").map_err(CliError::Output)?;
    Ok(())
}
