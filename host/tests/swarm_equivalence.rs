//! The swarm's shortcuts (issue: the swarm's rate) change nothing: a batch of seeds, run with
//! [`SimConfig::shortcuts`](mmic_host::sim::SimConfig::shortcuts) on and off, gives the same
//! runs, byte for byte: every logged event and packet, robot 1's replay trace (every tick's
//! readings and every byte its nodes took) where the run can record one, and the same
//! verdicts (violations, invariants' opportunities, faults expected in time).

use mmic_host::sim::inject::{Injection, Node};
use mmic_host::sim::{LinkLayer, Protocol};
use mmic_host::swarm::judge;
use mmic_host::swarm::scenario::{Options, RestartDraw, Scenario};
use std::collections::BTreeSet;

/// One run of `s` with the shortcuts `on`: its log and trace and verdicts as one text.
fn run(s: &Scenario, on: bool, dir: &std::path::Path) -> String {
    let mut s = s.clone();
    s.cfg.shortcuts = on;
    s.cfg.log_packets = true;
    // The trace holds only test keys: runs secured with other keys record none.
    let trace = dir.join(format!("{}-{on}.trace", s.seed));
    let traced = s.cfg.sdls.as_ref().is_none_or(|x| x.trace_keys().is_some());
    if traced {
        s.cfg.record = Some(trace.clone());
    }
    let o = judge(&s);
    let summary = o.summary.as_ref().expect("the run started");
    let mut text = format!(
        "sim_ms {} completed {} expected {}\nchecked {:?}\nviolations {:?}\nframes {:?}\n",
        o.sim_ms, o.completed, o.expected, o.checked, o.violations, summary.frames
    );
    for r in &summary.records {
        text.push_str(&r.to_string());
        text.push('\n');
    }
    if traced {
        let bytes = std::fs::read(&trace).expect("the trace was written");
        text.push_str(&format!("trace {:?}\n", bytes));
    }
    text
}

#[test]
fn the_shortcuts_change_no_run_of_a_batch_of_seeds() {
    let opts = Options {
        horizon_ms: 40_000,
        restarts: RestartDraw::Any,
        ..Options::default()
    };
    let dir = std::env::temp_dir().join(format!("mmic-swarm-equivalence-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let mut kinds = BTreeSet::new();
    for seed in 1..=24 {
        let s = Scenario::from_seed(seed, &opts);
        kinds.insert(match (s.protocol, s.link, s.sdls) {
            (Protocol::Legacy, _, _) => "legacy",
            (Protocol::Pus, LinkLayer::Packets, _) => "pus packets",
            (Protocol::Pus, LinkLayer::Frames, None) => "frames",
            (Protocol::Pus, LinkLayer::Frames, Some(_)) => "frames with SDLS",
        });
        for i in &s.cfg.injections {
            kinds.insert(match i.injection {
                Injection::Reboot(Node::A) => "board A restarts",
                Injection::Reboot(_) => "another node restarts",
                Injection::Fault(_) | Injection::Silent(_) => "plant fault",
                _ => "other injection",
            });
        }
        let (on, off) = (run(&s, true, &dir), run(&s, false, &dir));
        assert!(on == off, "seed {seed}: the shortcuts changed the run");
    }
    let _ = std::fs::remove_dir_all(&dir);
    for k in [
        "legacy",
        "pus packets",
        "frames",
        "frames with SDLS",
        "board A restarts",
        "another node restarts",
        "plant fault",
    ] {
        assert!(kinds.contains(k), "no seed of the batch has {k}: {kinds:?}");
    }
}
