//! `mmic sim` and `mmic bench`: argument handling around [`crate::sim`].

use crate::cli::{CliError, SimArgs};
use crate::sim::{self, report, SimConfig};
use std::io::Write;

fn ms(s: Option<f64>) -> Option<u32> {
    s.map(|s| (s.max(0.0) * 1000.0) as u32)
}

/// Runs `mmic sim`.
pub fn sim(a: SimArgs, out: &mut dyn Write) -> Result<(), CliError> {
    let steps = match &a.plan {
        None => report::demo_steps(),
        Some(path) => {
            let text = std::fs::read_to_string(path).map_err(|source| CliError::Read {
                path: path.clone(),
                source,
            })?;
            let plan = crate::plan::parse(&text).map_err(|error| CliError::Plan {
                path: path.clone(),
                error,
            })?;
            report::steps_of(&plan)
        }
    };
    std::fs::create_dir_all(&a.out).map_err(|source| CliError::Write {
        path: a.out.clone(),
        source,
    })?;
    let mut cfg = SimConfig::with_steps(steps);
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
