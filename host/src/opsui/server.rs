//! `mmic sim --realtime --opsui-serial DEV`: the simulator's robot and the paper's server board
//! (the legacy relay) with the server board's opsUI line on a serial device, for an opsUI at the
//! other end (`mmic opsui --serial`). The command-line side: the options it refuses (they make
//! no sense without the simulator's own ground, or on another protocol), the run
//! ([`crate::sim::opsline`] is the engine's side), and its own summary: what the server board
//! did with the opsUI's packets, and what board A executed.

use crate::error::CliError;
use crate::sim::inject::{Injection, Node, Scheduled};
use crate::sim::opsline::{LineStats, OpsLine};
use crate::sim::{self, report, SimConfig, Summary};
use crate::simcli::SimArgs;
use mmic::faults::Table8;
use std::fmt::Write as _;
use std::io::Write;

/// What `--opsui-serial` cannot go with (with the run's `injections`), each refused (exit 2)
/// rather than ignored, before anything is opened or written.
pub fn refuse(a: &SimArgs, injections: &[Scheduled]) -> Result<(), CliError> {
    let usage = |what: &str| {
        Err(CliError::Usage(format!(
            "--opsui-serial: {what}; refusing rather than running something else"
        )))
    };
    if a.protocol != sim::Protocol::Legacy || a.link != sim::LinkLayer::Packets {
        return usage(
            "the opsUI line carries the paper's packets (--protocol legacy, no --link frames)",
        );
    }
    if a.sdls || a.sdls_keys.is_some() || a.sdls_state.is_some() || a.sdls_attack != 0.0 {
        return usage("SDLS protects the space data link, which this line is not (--sdls...)");
    }
    if a.ground_tm_to.is_some() || a.record.is_some() {
        return usage(
            "the opsUI is at the other end of the device (no --ground-tm-to, no --record)",
        );
    }
    if a.serial_loss > 0.0 {
        return usage("the line is a real one: --serial-loss does not apply");
    }
    if a.summary_json.is_some() {
        return usage(
            "--summary-json reports a plan, and the plan is the opsUI's (its --summary-json)",
        );
    }
    let ground_side = |i: Injection| {
        i.command().is_some()
            || i == Injection::Fault(Table8::InitialStateMismatch)
            || i == Injection::Reboot(Node::Ground)
    };
    if let Some(s) = injections.iter().find(|s| ground_side(s.injection)) {
        return usage(&format!(
            "--inject {}: the ground's part of a run, and the ground is the opsUI's",
            s.injection.name()
        ));
    }
    Ok(())
}

/// Runs the robot and its server board on DEV; the summary on `out`.
pub fn sim(
    a: &SimArgs,
    mut cfg: SimConfig,
    device: &str,
    out: &mut dyn Write,
) -> Result<(), CliError> {
    refuse(a, &cfg.injections)?;
    let line = OpsLine::open(device)?;
    cfg.ops_line = Some(line.clone());
    cfg.robots = 1;
    cfg.log_packets = true;
    eprintln!(
        "opsui line: {device} open ({}): robot 1 and its server board run at scale {}, for the \
         opsUI at the other end (until the line closes, or {:.0} s)",
        line.settings,
        cfg.scale,
        cfg.max_sim_ms as f64 / 1000.0
    );
    let summary = sim::run(&cfg).map_err(CliError::Sim)?;
    write!(out, "{}", text(&summary, &line)).map_err(CliError::Output)?;
    writeln!(out, "log: {}", a.out.join("sim.jsonl").display()).map_err(CliError::Output)?;
    verdict(&summary)
}

/// The server board's events of this type.
fn server_events(s: &Summary, ty: &str) -> usize {
    s.events(ty)
        .filter(|e| e["node"].as_str().is_some_and(|n| n.starts_with("server")))
        .count()
}

/// The summary: the line, the server board, then board A's lines of `mmic sim`'s summary.
pub fn text(s: &Summary, line: &OpsLine) -> String {
    let mut t = String::new();
    line_lines(&mut t, s, line);
    let forwarded = |fate: &str| {
        s.records
            .iter()
            .filter(|r| r["kind"] == "packet" && r["link"] == "serial_ground")
            .filter(|r| r["from"].as_str().is_some_and(|f| f.starts_with("server")))
            .filter(|r| r["fate"] == fate)
            .count()
    };
    let _ = writeln!(
        t,
        "server board: {} commands queued, {} resent, {} superseded, {} refused; {} heartbeats \
         forwarded to the opsUI ({} not written: the line was closed)",
        server_events(s, "queued"),
        server_events(s, "resend"),
        server_events(s, "superseded"),
        server_events(s, "refused"),
        forwarded("delivered"),
        forwarded("closed")
    );
    board_lines(&mut t, s);
    t
}

/// The line: how it ended, and what came over it.
fn line_lines(t: &mut String, s: &Summary, line: &OpsLine) {
    let l = &line.stats;
    let at = s.sim_ms as f64 / 1000.0;
    let closed = match l.closed_why() {
        Some(why) => format!("closed at {at:.1} s ({why})"),
        None => format!("still open at the time limit, {at:.1} s"),
    };
    let _ = writeln!(
        t,
        "opsui line: {} ({}): {closed}",
        line.device, line.settings
    );
    let _ = writeln!(
        t,
        "line: {} bytes in: {} command packets, {} other packets; {} bytes dropped by the \
         deframer, {} left incomplete",
        LineStats::get(&l.bytes_in),
        LineStats::get(&l.commands),
        LineStats::get(&l.other_packets),
        LineStats::get(&l.discarded),
        LineStats::get(&l.left_incomplete)
    );
}

/// Board A's lines of `mmic sim`'s summary: the host's clock, the commands executed (and
/// executed twice), the bolting, the robot at the end.
fn board_lines(t: &mut String, s: &Summary) {
    report::clock_line(t, s);
    report::commands_line(t, s);
    report::robot_lines(t, s);
}

/// 0, unless the host fell behind (4) or a command ran twice (1).
fn verdict(s: &Summary) -> Result<(), CliError> {
    if s.host_fell_behind() {
        return Err(CliError::HostBehind {
            late_ms: s.max_tick_lateness_ms,
        });
    }
    let twice = report::executed_twice(s);
    if !twice.is_empty() {
        return Err(CliError::Invariant(format!(
            "board A executed sequenced commands {twice:?} more than once"
        )));
    }
    Ok(())
}
