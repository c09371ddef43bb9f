//! The fault swarm (issue 16): scenarios drawn from their seed alone, invariants that hold on
//! the real firmware, a planted double execution found and replayed from its seed.

use mmic_host::sim::engine::watch::Invariant;
use mmic_host::sim::engine::PlantedBug;
use mmic_host::swarm::scenario::{Options, Scenario};
use mmic_host::swarm::{replay_command, run_one, swarm};
use std::process::Command;
use std::time::Duration;

#[test]
fn every_drawn_plan_fits_the_robot_and_a_seed_always_draws_the_same_scenario() {
    let opts = Options::default();
    let mut protocols = std::collections::BTreeSet::new();
    let mut starts = std::collections::BTreeSet::new();
    let mut injected = std::collections::BTreeSet::new();
    for seed in 0..2_000 {
        let s = Scenario::from_seed(seed, &opts);
        let p = mmic_host::plan::parse(&s.plan).unwrap_or_else(|e| panic!("seed {seed}: {e}"));
        let start = p.start.unwrap_or(mmic::motion::State::A);
        p.trace(start)
            .unwrap_or_else(|e| panic!("seed {seed}: {e}\n{}", s.plan));
        assert_eq!(s.cfg.steps.len(), p.steps.len());
        assert_eq!(Scenario::from_seed(seed, &opts).describe(), s.describe());
        protocols.insert(s.protocol.name());
        starts.insert(start.letter());
        for i in &s.cfg.injections {
            injected.insert(i.injection.name());
            assert!(
                i.at_ms + 2_000 <= s.cfg.max_sim_ms,
                "seed {seed}: {i:?} too late"
            );
        }
    }
    assert_eq!(protocols.len(), 2);
    assert_eq!(starts.len(), 15, "plans start in every state");
    // Every injection the simulator has is drawn by some seed.
    assert_eq!(
        injected.len(),
        mmic_host::sim::inject::Injection::ALL.len(),
        "{injected:?}"
    );
}

#[test]
fn the_invariants_hold_on_the_firmware_for_a_batch_of_seeds() {
    let opts = Options {
        horizon_ms: 60_000,
        ..Options::default()
    };
    let r = swarm(
        1,
        Duration::from_secs(600),
        Some(40),
        40,
        &opts,
        &mut |_| {},
    );
    assert_eq!(r.runs, 40);
    assert!(r.failures.is_empty(), "{}", r.text(&opts));
    // Every invariant had opportunities.
    let c = r.checked;
    assert!(c.admissions > 1_000 && c.motion_ticks > 10_000 && c.standby_ticks > 10_000);
    assert!(
        c.faults_raised > 10 && c.commands_ended > 300 && r.expected > 5,
        "{c:?}, {} expected",
        r.expected
    );
    assert!(
        (40 * 60_000..=40 * 60_010).contains(&r.sim_ms),
        "each run covers its horizon: {}",
        r.sim_ms
    );
}

#[test]
fn a_planted_double_execution_is_found_and_its_seed_replays_it() {
    let opts = Options {
        horizon_ms: 60_000,
        planted_bug: PlantedBug::DoubleExec,
    };
    let r = swarm(
        1,
        Duration::from_secs(300),
        Some(200),
        1,
        &opts,
        &mut |_| {},
    );
    let f = r.failures.first().expect("the planted bug is found");
    assert!(
        f.violations
            .iter()
            .all(|v| v.invariant == Invariant::ExecutedTwice),
        "{:?}",
        f.violations
    );
    // The same seed without the bug holds: the bug, not the scenario, broke it.
    let clean = run_one(
        f.seed,
        &Options {
            planted_bug: PlantedBug::None,
            ..opts
        },
    );
    assert!(clean.violations.is_empty(), "{:?}", clean.violations);
    // The printed command replays it, byte for byte of the verdict.
    let cmd = replay_command(f.seed, &opts);
    assert_eq!(
        cmd,
        format!(
            "mmic swarm --replay {} --sim-seconds 60 --plant-bug double-exec",
            f.seed
        )
    );
    let dir = std::path::PathBuf::from(env!("CARGO_TARGET_TMPDIR")).join("swarm-replay");
    let mut args: Vec<&str> = cmd.split(' ').skip(1).collect();
    let d = dir.to_string_lossy().to_string();
    args.extend(["--out", &d]);
    let out = Command::new(env!("CARGO_BIN_EXE_mmic"))
        .args(&args)
        .output()
        .unwrap();
    assert_eq!(out.status.code(), Some(1), "{out:?}");
    let text = String::from_utf8_lossy(&out.stdout);
    for v in &f.violations {
        let line = format!(
            "VIOLATED {} at {} ms (robot 1): {}",
            v.invariant.name(),
            v.t_ms,
            v.detail
        );
        assert!(text.contains(&line), "{line}\nnot in\n{text}");
    }
    // The replay wrote the whole log, packets included.
    let log = std::fs::read_to_string(dir.join("sim.jsonl")).unwrap();
    assert!(log.lines().any(|l| l.contains("\"fate\":\"duplicated\"")));
}

#[test]
fn mmic_swarm_reports_and_exits_by_its_verdict() {
    let bin = env!("CARGO_BIN_EXE_mmic");
    let json = std::path::PathBuf::from(env!("CARGO_TARGET_TMPDIR")).join("swarm.json");
    let ok = Command::new(bin)
        .args(["swarm", "--runs", "3", "--sim-seconds", "30", "--json"])
        .arg(&json)
        .output()
        .unwrap();
    assert_eq!(ok.status.code(), Some(0), "{ok:?}");
    let text = String::from_utf8_lossy(&ok.stdout);
    assert!(text.starts_with("swarm: 3 runs in "), "{text}");
    assert!(text.contains("result: no invariant broken"), "{text}");
    let v: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&json).unwrap()).unwrap();
    assert_eq!(v["runs"], 3);
    assert!(v["sim_hours"].as_f64().unwrap() > 0.02);
    let bad = Command::new(bin)
        .args(["swarm", "--sim-seconds", "3"])
        .output()
        .unwrap();
    assert_eq!(bad.status.code(), Some(2), "{bad:?}");
    let bad = Command::new(bin)
        .args(["swarm", "--plant-bug", "typo"])
        .output()
        .unwrap();
    assert_eq!(bad.status.code(), Some(2), "{bad:?}");
}
