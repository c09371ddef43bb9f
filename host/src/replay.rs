//! `mmic replay`: runs a recorded scenario (`mmic sim --record`) through one robot's nodes on
//! this host ([`mmic_replay`]) and compares the output with another run's, such as the
//! bare-metal RV32 runner's under QEMU (benches/rv32/README.md): any difference is named by
//! its record, time and field.

use crate::sim::{Protocol, SimConfig};
use mmic_replay::out::{first_difference, Difference, Field};
use mmic_replay::trace::{Trace, TraceError};
use mmic_replay::Replay;

/// Table 8's ten faults, each injected into its own run of the demo plan at a time it is
/// detected (the run stops with the plan); the last two over PUS.
pub const FAULTS: &[(&str, Protocol)] = &[
    ("bolting-failure@5", Protocol::Legacy),
    ("arm-not-contracted@28", Protocol::Legacy),
    ("bolter-overcurrent@12", Protocol::Legacy),
    ("gripper-overcurrent@15", Protocol::Legacy),
    ("locomotion-overcurrent@3", Protocol::Legacy),
    ("hip-mismatch@0", Protocol::Legacy),
    ("initial-state-mismatch@5", Protocol::Legacy),
    ("internal-comm-loss@5", Protocol::Legacy),
    ("low-battery@5", Protocol::Pus),
    ("assembly-system@5", Protocol::Pus),
];

/// The scenarios CI replays on RV32 (benches/rv32/README.md), by name: the demo plan over
/// both protocols, the demo over lossy, duplicating and reordering links, the demo over the
/// space data link with loss on the ground link (`frames`: TC frames under COP-1, TM frames;
/// `frames-sdls`: the same secured with SDLS), and one run per Table 8 fault (`fault-NAME`). Each runs in virtual time, deterministically.
pub fn scenarios() -> Vec<(String, SimConfig)> {
    let demo = |protocol| {
        let mut c = SimConfig::demo();
        c.progress = false;
        c.protocol = protocol;
        c
    };
    let mut lossy = demo(Protocol::Pus);
    lossy.seed = 7;
    lossy.max_sim_ms = 400_000;
    lossy.wifi_loss = 0.1;
    lossy.serial_loss = 0.05;
    lossy.ab_loss = 0.05;
    lossy.links.wifi.duplicate = 0.05;
    lossy.links.wifi.reorder = 0.05;
    lossy.links.wifi.reorder_us = 50_000;
    // The acceptance run, shorter: the demo behind the space data link, 10 % of the
    // TC and TM frames lost on the ground link (FOP-1 retransmits, TM frames go missing) and
    // 10 % of the WiFi packets.
    let mut frames = demo(Protocol::Pus);
    frames.link = crate::sim::LinkLayer::Frames;
    frames.seed = 1;
    frames.max_sim_ms = 400_000;
    frames.wifi_loss = 0.1;
    frames.serial_loss = 0.1;
    // The same run with the link secured by SDLS: every TC frame verified and decrypted,
    // every TM frame protected, under test keys made for this recording (in the trace).
    let mut frames_sdls = frames.clone();
    frames_sdls.sdls = Some(crate::sim::SdlsConfig::recorded());
    let mut all = vec![
        ("demo-legacy".to_string(), demo(Protocol::Legacy)),
        ("demo-pus".to_string(), demo(Protocol::Pus)),
        ("lossy".to_string(), lossy),
        ("frames".to_string(), frames),
        ("frames-sdls".to_string(), frames_sdls),
    ];
    for (f, protocol) in FAULTS {
        let mut c = demo(*protocol);
        c.max_sim_ms = 60_000;
        // The names and times above are fixed: the test of this list checks each is taken
        // and raises its fault.
        if let Ok(s) = f.parse() {
            let _ = c.inject(s);
        }
        let name = f.split('@').next().unwrap_or(f);
        all.push((format!("fault-{name}"), c));
    }
    all
}

/// Runs every scenario with its trace written to `dir`/NAME.trace; returns each path with the
/// run's summary.
pub fn record_scenarios(
    dir: &std::path::Path,
) -> Result<Vec<(std::path::PathBuf, crate::sim::Summary)>, CliError> {
    std::fs::create_dir_all(dir).map_err(|source| CliError::Write {
        path: dir.to_path_buf(),
        source,
    })?;
    let mut paths = Vec::new();
    for (name, mut cfg) in scenarios() {
        let p = dir.join(format!("{name}.trace"));
        cfg.record = Some(p.clone());
        let summary = crate::sim::run(&cfg).map_err(CliError::Sim)?;
        paths.push((p, summary));
    }
    Ok(paths)
}

/// Runs `trace` on this host; returns the output stream and the number of records.
pub fn run(trace: &[u8]) -> Result<(Vec<u8>, usize), TraceError> {
    let t = Trace::parse(trace)?;
    let mut r = Replay::new(&t.header);
    let mut out = Vec::new();
    let mut n = 0;
    for rec in t.records() {
        r.step(&rec?, &mut out, &mut ());
        n += 1;
    }
    Ok((out, n))
}

/// The name of a trace record's tag.
pub fn tag_name(tag: u8) -> &'static str {
    match tag {
        1 => "board A tick",
        2 => "board B tick",
        3 => "bytes to board A (serial)",
        4 => "bytes to board B (serial)",
        5 => "WiFi task: connection opened",
        6 => "WiFi task: connection closed",
        7 => "WiFi task: command bytes",
        8 => "WiFi task: heartbeats drained",
        9 => "server board: bytes from the ground",
        10 => "server board: loop",
        11 => "server board: heartbeat",
        _ => "unknown record",
    }
}

fn hex(b: &[u8]) -> String {
    b.iter().map(|x| format!("{x:02x}")).collect()
}

/// A difference as one line: which record (index, kind, time), which field, both values.
pub fn describe(d: &Difference<'_>, left: &str, right: &str) -> String {
    let field = d.field.map_or("the record's shape or length", Field::name);
    format!(
        "first difference at output record {} ({}, t={} ms), field {field}: {left} {} | {right} {}",
        d.index,
        tag_name(d.tag),
        d.t,
        hex(d.left),
        hex(d.right)
    )
}

/// Compares two output streams: `None` when identical, else the description.
pub fn compare(left: &[u8], right: &[u8], names: (&str, &str)) -> Option<String> {
    first_difference(left, right).map(|d| describe(&d, names.0, names.1))
}

fn read(path: &std::path::Path) -> Result<Vec<u8>, CliError> {
    std::fs::read(path).map_err(|source| CliError::Read {
        path: path.to_path_buf(),
        source,
    })
}

/// `mmic replay --record-scenarios DIR`.
pub fn cli_record(dir: &std::path::Path, out: &mut dyn std::io::Write) -> Result<(), CliError> {
    for (p, summary) in record_scenarios(dir)? {
        let n = std::fs::metadata(&p).map(|m| m.len()).unwrap_or(0);
        writeln!(out, "recorded {} ({n} bytes)", p.display()).map_err(CliError::Output)?;
        for line in crate::sim::report::text(&summary).lines() {
            if line.starts_with("injected:") || line.starts_with("robot:") {
                writeln!(out, "  {line}").map_err(CliError::Output)?;
            }
        }
    }
    Ok(())
}

/// `mmic replay TRACE [--against FILE] [--out FILE]`.
pub fn cli(
    trace: &std::path::Path,
    against: Option<&std::path::Path>,
    to: Option<&std::path::Path>,
    out: &mut dyn std::io::Write,
) -> Result<(), CliError> {
    let bytes = read(trace)?;
    let (host, n) =
        run(&bytes).map_err(|e| CliError::Usage(format!("{}: {e}", trace.display())))?;
    if let Some(p) = to {
        std::fs::write(p, &host).map_err(|source| CliError::Write {
            path: p.to_path_buf(),
            source,
        })?;
    }
    writeln!(
        out,
        "replayed {n} records of {} on this host: {} output bytes",
        trace.display(),
        host.len()
    )
    .map_err(CliError::Output)?;
    if let Some(p) = against {
        let other = read(p)?;
        let name = p.display().to_string();
        if let Some(d) = compare(&host, &other, ("host", &name)) {
            return Err(CliError::Replay(d));
        }
        writeln!(out, "identical to {name}: {} bytes", other.len()).map_err(CliError::Output)?;
    }
    Ok(())
}

use crate::error::CliError;

/// One node's figures over the cost files.
#[derive(Debug, Clone, Default)]
pub struct NodeCost {
    /// Calls measured.
    pub calls: usize,
    /// Instructions of each call (sorted by [`cost_table`]).
    pub instructions: Vec<u32>,
    /// The most expensive call: instructions, scenario, record tag, time.
    pub worst: (u32, String, u8, u32),
    /// The deepest stack before the output record, and with it, bytes.
    pub stack: (u32, u32),
    /// Per phase (glue, front end, node): the median and the largest, instructions.
    pub phases: [Vec<u32>; 3],
}

/// The per-node figures of cost files, given as (scenario, bytes).
pub fn node_costs(files: &[(String, Vec<u8>)]) -> Result<Vec<NodeCost>, CliError> {
    use mmic_replay::cost::{Cost, COST_LEN};
    let mut nodes = vec![NodeCost::default(); mmic_replay::trace::Node::ALL.len()];
    for (name, b) in files {
        if b.len() % COST_LEN != 0 {
            return Err(CliError::Usage(format!(
                "{name}: {} bytes is not a whole number of {COST_LEN}-byte cost records",
                b.len()
            )));
        }
        for c in b.chunks_exact(COST_LEN).filter_map(Cost::parse) {
            let Some(n) = nodes.get_mut(usize::from(c.node)) else {
                return Err(CliError::Usage(format!(
                    "{name}: node {} in a cost record",
                    c.node
                )));
            };
            let i = c.instructions();
            n.calls += 1;
            n.instructions.push(i);
            if i > n.worst.0 {
                n.worst = (i, name.clone(), c.tag, c.t);
            }
            n.stack = (n.stack.0.max(c.stack_node), n.stack.1.max(c.stack_all));
            for (p, v) in n.phases.iter_mut().zip(c.phases) {
                p.push(v);
            }
        }
    }
    for n in &mut nodes {
        n.instructions.sort_unstable();
        for p in &mut n.phases {
            p.sort_unstable();
        }
    }
    Ok(nodes)
}

/// The value at quantile `q` (0..=1) of sorted `v` (nearest rank).
pub fn quantile(v: &[u32], q: f64) -> u32 {
    if v.is_empty() {
        return 0;
    }
    let rank = ((q * v.len() as f64).ceil() as usize).clamp(1, v.len());
    v[rank - 1]
}

/// The ESP32-C3's clock, Hz.
pub const CLOCK_HZ: f64 = 160e6;
/// The boards' tick, s.
pub const TICK_S: f64 = 0.010;

/// The cost table (Markdown).
pub fn cost_table(nodes: &[NodeCost]) -> String {
    let mut s = String::from(
        "| node | calls | instructions min / median / p99 / max | worst call | µs at 160 MHz, CPI 1 | share of the 10 ms tick | stack, bytes (node / with output record) |\n|---|---|---|---|---|---|---|\n",
    );
    for (n, node) in nodes.iter().zip(mmic_replay::trace::Node::ALL) {
        let v = &n.instructions;
        let max = v.last().copied().unwrap_or(0);
        let us = f64::from(max) / CLOCK_HZ * 1e6;
        s.push_str(&format!(
            "| {} | {} | {} / {} / {} / {} | {}, {} at {:.2} s | {us:.1} | {:.2} % | {} / {} |\n",
            node.name(),
            n.calls,
            v.first().copied().unwrap_or(0),
            quantile(v, 0.5),
            quantile(v, 0.99),
            max,
            n.worst.1,
            tag_name(n.worst.2),
            f64::from(n.worst.3) / 1000.0,
            us / (TICK_S * 1e6) * 100.0,
            n.stack.0,
            n.stack.1,
        ));
    }
    s.push_str("\n| node | phase | median | max |\n|---|---|---|---|\n");
    for (n, node) in nodes.iter().zip(mmic_replay::trace::Node::ALL) {
        for (p, phase) in n.phases.iter().zip(mmic_replay::Phase::ALL) {
            if p.last().copied().unwrap_or(0) == 0 {
                continue;
            }
            s.push_str(&format!(
                "| {} | {} | {} | {} |\n",
                node.name(),
                phase.name(),
                quantile(p, 0.5),
                p.last().copied().unwrap_or(0)
            ));
        }
    }
    s
}

/// The most instructions one call of `node` may take: `robot` for the robot's boards (board
/// A's control and WiFi tasks, board B) when given, `all` otherwise. The robot's boards have a
/// budget of their own because their worst calls are far below the server board's (whose loop
/// carries the PUS gateway and the space data link): the server's budget would let a board A
/// tick grow threefold unnoticed (issue 40).
pub fn budget(node: mmic_replay::trace::Node, all: Option<u32>, robot: Option<u32>) -> Option<u32> {
    match node {
        mmic_replay::trace::Node::Server => all,
        _ => robot.or(all),
    }
}

/// `mmic rv32-costs [--budget N] [--robot-budget N] COST...`.
pub fn cli_costs(
    files: &[std::path::PathBuf],
    budgets: (Option<u32>, Option<u32>),
    out: &mut dyn std::io::Write,
) -> Result<(), CliError> {
    let mut all = Vec::new();
    for f in files {
        let name = f.file_stem().map_or_else(
            || f.display().to_string(),
            |s| s.to_string_lossy().into_owned(),
        );
        all.push((name, read(f)?));
    }
    let nodes = node_costs(&all)?;
    writeln!(out, "{}", cost_table(&nodes)).map_err(CliError::Output)?;
    let mut over = Vec::new();
    for (n, node) in nodes.iter().zip(mmic_replay::trace::Node::ALL) {
        let Some(b) = budget(node, budgets.0, budgets.1) else {
            continue;
        };
        let worst = n.instructions.last().copied().unwrap_or(0);
        let verdict = if worst > b { "OVER" } else { "within" };
        writeln!(
            out,
            "worst call of {}: {worst} instructions, {verdict} its budget of {b}",
            node.name()
        )
        .map_err(CliError::Output)?;
        if worst > b {
            over.push(format!("{} ({worst} > {b})", node.name()));
        }
    }
    if !over.is_empty() {
        return Err(CliError::Replay(format!(
            "over the instruction budget: {}",
            over.join(", ")
        )));
    }
    Ok(())
}
