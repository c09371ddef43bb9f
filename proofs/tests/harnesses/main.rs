//! Every bolero harness of the workspace: unit tests here, fuzz targets under `cargo bolero test`, proofs under `cargo kani --tests` (see proofs/README.md).
//!
//! One test binary per area, each file a module: fewer binaries to link than one per file.

mod bolter_executor;
mod ccsds;
mod cfdp;
mod control_hip;
mod control_interp;
mod deframer;
#[cfg(not(any(kani, fuzzing)))]
mod ledger;
mod link_cop;
mod link_tc;
mod link_tm;
mod motion_sequencer;
mod node;
mod packets;
mod pus;
mod safety_timers;
mod sdls;
mod sensors_frontend;
mod sensors_moving_average;
mod store;
mod transport;

/// Every harness lands with its ledger row: each `#[test]` function of the harness files (the
/// packet harnesses as `<packet>::<name>`, one per `packet_harnesses!` instance) has a row in
/// proofs/README.md whose harness cell is its name in backticks, and every row names a harness.
#[test]
fn ledger_has_a_row_for_every_harness() {
    use std::collections::BTreeSet;
    let dir = concat!(env!("CARGO_MANIFEST_DIR"), "/tests/harnesses");
    let mut harnesses = BTreeSet::new();
    for entry in std::fs::read_dir(dir).expect("tests/harnesses") {
        let path = entry.expect("entry").path();
        let file = path.file_name().and_then(|n| n.to_str()).unwrap_or("");
        if !file.ends_with(".rs") || file == "main.rs" {
            continue;
        }
        let text = std::fs::read_to_string(&path).expect("harness file");
        let lines: Vec<&str> = text.lines().collect();
        // The test functions: `fn name(` within the attribute lines after a `#[test]`.
        let mut tests = Vec::new();
        for (i, l) in lines.iter().enumerate() {
            if l.trim() != "#[test]" {
                continue;
            }
            let f = lines[i + 1..]
                .iter()
                .map(|l| l.trim())
                .find(|l| !l.starts_with("#["))
                .expect("a function after #[test]");
            let name = f
                .strip_prefix("fn ")
                .and_then(|f| f.split('(').next())
                .unwrap_or_else(|| panic!("{file}: #[test] on `{f}`, not a fn"));
            tests.push(name.to_string());
        }
        // A macro instantiated per packet: `<module>: <type>, …` inside `packet_harnesses! {`.
        let instances: Vec<String> = lines
            .windows(3)
            .filter(|w| w[0].starts_with("packet_harnesses! {"))
            .filter_map(|w| {
                let l = if w[1].trim_start().starts_with("///") {
                    w[2]
                } else {
                    w[1]
                };
                l.trim().split(':').next().map(str::to_string)
            })
            .collect();
        if instances.is_empty() {
            harnesses.extend(tests);
        } else {
            for m in &instances {
                harnesses.extend(tests.iter().map(|t| format!("{m}::{t}")));
            }
        }
    }
    assert!(harnesses.len() >= 41, "found only {harnesses:?}");
    let readme = std::fs::read_to_string(concat!(env!("CARGO_MANIFEST_DIR"), "/README.md"))
        .expect("proofs/README.md");
    let start = readme
        .find("## The ledger")
        .expect("proofs/README.md has no ledger section");
    let rows: BTreeSet<String> = readme[start..]
        .lines()
        .skip_while(|l| !l.starts_with("| file | harness |"))
        .skip(2)
        .take_while(|l| l.starts_with('|'))
        .map(|l| {
            let cell = l.split('|').nth(2).expect("a harness cell").trim();
            cell.trim_matches('`').to_string()
        })
        .collect();
    let missing: Vec<_> = harnesses.difference(&rows).collect();
    let stale: Vec<_> = rows.difference(&harnesses).collect();
    assert!(
        missing.is_empty(),
        "harnesses without a ledger row in proofs/README.md: {missing:?}"
    );
    assert!(stale.is_empty(), "ledger rows naming no harness: {stale:?}");
}
