//! The fault swarm (issue 16): scenarios drawn from their seed alone, invariants that hold on
//! the real firmware, a planted double execution found and replayed from its seed.

use mmic_host::sim::engine::watch::Invariant;
use mmic_host::sim::engine::PlantedBug;
use mmic_host::sim::{LinkLayer, Protocol};
use mmic_host::swarm::scenario::{LinkDraw, Options, Scenario};
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
    // Every injection the simulator has, restarts included, is drawn by some seed.
    assert_eq!(
        injected.len(),
        mmic_host::sim::inject::Injection::ALL.len()
            + mmic_host::sim::inject::Injection::REBOOTS.len(),
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
        ..Options::default()
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

/// The part of a scenario the main stream draws and the link stream leaves alone: everything
/// but the link layer and the ground link's loss, duplication and reordering.
fn main_stream(s: &Scenario) -> String {
    let c = &s.cfg;
    format!(
        "{:?} {} {:?} {} {:?} {:?} {} {} {} {:?} {:?} {:?} {:?}",
        s.protocol,
        s.plan,
        c.start_state,
        c.b_phase_us,
        c.links.wifi,
        c.links.ab,
        c.wifi_loss,
        c.ab_loss,
        c.links.ground.latency_us,
        c.links.ground.jitter_us,
        c.links.ground.cuts,
        c.injections,
        c.max_sim_ms,
    )
}

#[test]
fn pus_scenarios_draw_packets_or_frames_from_a_stream_of_their_own() {
    let (mut frames, mut pus, mut heavier) = (0, 0, 0);
    for seed in 0..2_000 {
        let any = Scenario::from_seed(seed, &Options::default());
        let packets = Scenario::from_seed(
            seed,
            &Options {
                link: LinkDraw::Packets,
                ..Options::default()
            },
        );
        let all_frames = Scenario::from_seed(
            seed,
            &Options {
                link: LinkDraw::Frames,
                ..Options::default()
            },
        );
        // The main stream's draws are the same whatever the link: a seed keeps its protocol,
        // plan, links, phase and faults.
        assert_eq!(main_stream(&any), main_stream(&packets), "seed {seed}");
        assert_eq!(main_stream(&any), main_stream(&all_frames), "seed {seed}");
        assert_eq!(packets.link, LinkLayer::Packets);
        assert_eq!(packets.cfg.link, LinkLayer::Packets);
        if any.protocol == Protocol::Legacy {
            // Legacy has no frames: its scenario is the packets one, whatever --link says.
            assert_eq!(any.link, LinkLayer::Packets);
            assert_eq!(all_frames.link, LinkLayer::Packets);
            assert_eq!(any.describe(), packets.describe());
            continue;
        }
        pus += 1;
        assert_eq!(all_frames.link, LinkLayer::Frames, "seed {seed}");
        assert_eq!(all_frames.cfg.link, LinkLayer::Frames);
        assert!(all_frames.describe().contains(" pus over frames from "));
        match any.link {
            LinkLayer::Packets => assert_eq!(any.describe(), packets.describe()),
            LinkLayer::Frames => {
                frames += 1;
                assert_eq!(any.cfg.link, LinkLayer::Frames);
                // The drawn frames scenario is --link frames' for that seed.
                assert_eq!(any.describe(), all_frames.describe());
                let g = &any.cfg.links.ground;
                assert!(any.cfg.serial_loss < 0.3 && g.duplicate < 0.3 && g.reorder < 0.2);
                // Heavier than the packet link's draws (loss up to 0.1): COP-1's business.
                heavier += (any.cfg.serial_loss > 0.1) as u32;
            }
        }
        assert_eq!(
            Scenario::from_seed(seed, &Options::default()).describe(),
            any.describe()
        );
    }
    assert!(
        (0.4..0.6).contains(&(frames as f64 / pus as f64)),
        "{frames} of {pus} PUS scenarios over frames"
    );
    assert!(heavier > frames / 4, "{heavier} of {frames}");
}

#[test]
fn the_invariants_hold_over_the_space_data_link() {
    let opts = Options {
        horizon_ms: 60_000,
        link: LinkDraw::Frames,
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
    // About half the seeds are PUS, all of them over frames; the frame link's faults happened
    // and COP-1 dealt with them.
    assert!(r.frame_runs >= 10, "{}", r.frame_runs);
    let f = r.frames;
    assert!(
        f.retransmissions > 0 && f.discarded > 0 && f.tm_lost > 0 && f.accepted > 100,
        "{f:?}"
    );
    assert!(r.checked.commands_ended > 300, "{:?}", r.checked);
    let text = r.text(&opts);
    assert!(
        text.contains(&format!(
            "space data link: {} runs over frames",
            r.frame_runs
        )),
        "{text}"
    );
    assert_eq!(r.json(&opts)["frame_runs"], r.frame_runs);
    assert_eq!(
        replay_command(85, &opts),
        "mmic swarm --replay 85 --sim-seconds 60 --link frames"
    );
}

#[test]
fn a_frames_seed_replays_its_scenario_from_the_command_line() {
    // The first PUS seed drawn over frames, replayed with the default --link (any): the line the
    // replay prints is its scenario's, frames and all.
    let opts = Options {
        horizon_ms: 20_000,
        ..Options::default()
    };
    let s = (1..)
        .map(|seed| Scenario::from_seed(seed, &opts))
        .find(|s| s.link == LinkLayer::Frames)
        .unwrap();
    let dir = std::path::PathBuf::from(env!("CARGO_TARGET_TMPDIR")).join("swarm-replay-frames");
    let seed = s.seed.to_string();
    let out = Command::new(env!("CARGO_BIN_EXE_mmic"))
        .args(["swarm", "--replay", &seed, "--sim-seconds", "20", "--out"])
        .arg(&dir)
        .output()
        .unwrap();
    assert_eq!(out.status.code(), Some(0), "{out:?}");
    let text = String::from_utf8_lossy(&out.stdout);
    assert_eq!(text.lines().next(), Some(s.describe().as_str()), "{text}");
    assert!(text.contains("link: frames -- "), "{text}");
    let log = std::fs::read_to_string(dir.join("sim.jsonl")).unwrap();
    assert!(log.contains("tc_frame"), "the log has the frames");
    let bad = Command::new(env!("CARGO_BIN_EXE_mmic"))
        .args(["swarm", "--link", "cells"])
        .output()
        .unwrap();
    assert_eq!(bad.status.code(), Some(2), "{bad:?}");
}
