//! Restarts of the robot's nodes and the ground in the virtual-time engine (`--inject reboot-*`):
//! what each keeps (spec/decisions.toml `restart-*`) holds exactly-once and the SDLS counters
//! across them, and the swarm finds a planted restart defect and replays it.

use mmic_host::sim::engine::watch::Invariant;
use mmic_host::sim::engine::{self, PlantedBug};
use mmic_host::sim::inject::Scheduled;
use mmic_host::sim::{LinkLayer, Protocol, SdlsConfig, SdlsKeys, SimConfig};
use mmic_host::swarm::scenario::{Options, RestartDraw};
use mmic_host::swarm::{replay_command, run_one, swarm};
use serde_json::Value;
use std::time::Duration;

fn config(protocol: Protocol, link: LinkLayer, injections: &[&str]) -> SimConfig {
    let mut cfg = SimConfig::demo();
    cfg.progress = false;
    cfg.protocol = protocol;
    cfg.link = link;
    cfg.log_events = true;
    cfg.run_to_end = true;
    cfg.max_sim_ms = 90_000;
    for i in injections {
        cfg.inject(i.parse::<Scheduled>().unwrap()).unwrap();
    }
    cfg
}

/// Board A's restarts over a lossy, duplicating WiFi: every resend after a restart is
/// answered from the log board A kept; none runs twice. (That a lost log shows is the swarm
/// test's below: a restart must fall between a command's execution and its answer.)
#[test]
#[cfg_attr(miri, ignore = "whole simulated runs: minutes under Miri")]
fn board_a_keeps_its_log_across_restarts_and_nothing_runs_twice() {
    for seed in 1..=6u64 {
        for protocol in [Protocol::Legacy, Protocol::Pus] {
            let mut cfg = config(
                protocol,
                LinkLayer::Packets,
                &[
                    "reboot-a@12",
                    "reboot-a@12.65",
                    "reboot-a@25.3",
                    "reboot-a@40",
                ],
            );
            cfg.seed = seed;
            cfg.wifi_loss = 0.3;
            cfg.links.wifi.duplicate = 0.3;
            let s = engine::run(&cfg).unwrap();
            assert_eq!(s.restarts, [4, 0, 0, 0], "seed {seed} {protocol:?}");
            assert_eq!(s.executed_twice, 0, "seed {seed} {protocol:?}");
            // Board A came up with its boot count in heartbeat byte 59 each time.
            let boots: Vec<u64> = s
                .events("boot")
                .filter(|r| r["node"] == "board_a1")
                .map(|r| r["event"]["boot"].as_u64().unwrap())
                .collect();
            assert_eq!(
                boots,
                [0x21, 0x22, 0x23, 0x24],
                "power-on cause, counts 1..=4"
            );
        }
    }
}

/// The server board restarts twice under SDLS with an attacker replaying captured frames: its
/// TM IVs keep rising across the restarts (never one reused), no frame captured before a
/// restart passes after it, and the plan's command in progress ends reported, not lost.
#[test]
#[cfg_attr(miri, ignore = "whole simulated runs: minutes under Miri")]
fn server_restarts_keep_the_sdls_counters_and_refuse_old_frames() {
    let mut cfg = config(
        Protocol::Pus,
        LinkLayer::Frames,
        &["reboot-server@20", "reboot-server@45"],
    );
    cfg.log_packets = true;
    cfg.sdls = Some(SdlsConfig {
        keys: SdlsKeys::Seeded,
        state: None,
        attack: 0.3,
    });
    let s = engine::run(&cfg).unwrap();
    assert_eq!(s.restarts, [0, 0, 2, 0]);
    assert_eq!(s.executed_twice, 0);
    let sdls = s.frames.and_then(|f| f.sdls).expect("SDLS figures");
    assert!(sdls.attack_frames > 0);
    assert_eq!(sdls.attacks_passed, 0, "{sdls:?}");
    // The TM frames' IVs (octets 8..20: after the primary header and the SPI), in the order
    // the server board sent them: strictly rising across both restarts.
    let ivs: Vec<(u64, u128)> = s
        .records
        .iter()
        .filter(|r| r["kind"] == "packet" && r["link"] == "udp_ground" && r["from"] == "server1")
        .filter(|r| r["fate"] != "duplicated")
        .filter_map(|r| {
            let hex = r["hex"].as_str()?;
            let iv = u128::from_str_radix(hex.get(16..40)?, 16).ok()?;
            Some((r["t_ms"].as_u64()?, iv))
        })
        .collect();
    assert!(ivs.iter().any(|(t, _)| *t < 20_000) && ivs.iter().any(|(t, _)| *t > 45_300));
    assert!(ivs.len() > 100, "{} TM frames", ivs.len());
    for w in ivs.windows(2) {
        assert!(
            w[1].1 > w[0].1,
            "TM IV reused or back: {:?} then {:?}",
            w[0],
            w[1]
        );
    }
    // Attack frames after the first restart (replays of frames captured before it, among
    // others) were all refused.
    let late_attacks = s
        .events("tc_frame_refused")
        .filter(|r| r["event"]["attack"] == Value::Bool(true) && r["t_ms"].as_u64() > Some(20_300))
        .count();
    assert!(late_attacks > 0);
    // The command in progress at the first restart ended reported (unacknowledged or a
    // refusal), never silently: the plan stopped with a reason, or went on.
    assert!(s.ends.iter().all(|e| e.is_some()), "{:?}", s.ends);
}

/// The ground's restarts (`--inject reboot-ground@S`), over both protocols and over frames
/// with SDLS: in a wait, the plan goes on at the step it stood at and numbers past every
/// number given out before; with a step open, the plan ends `Restarted` there and nothing is
/// sent again. Either way nothing runs twice and every command sent ends.
#[test]
#[cfg_attr(miri, ignore = "whole simulated runs: minutes under Miri")]
fn the_ground_restarts_from_its_kept_position_and_numbering() {
    let plan = "mode operational\nwait 6s\nbolt 1\nmode standby\n";
    let cases = [
        (Protocol::Legacy, LinkLayer::Packets),
        (Protocol::Pus, LinkLayer::Packets),
        (Protocol::Pus, LinkLayer::Frames),
    ];
    for (protocol, link) in cases {
        // In the wait (Operational is entered within 2 s): the plan completes.
        let mut cfg = config(protocol, link, &["reboot-ground@4"]);
        cfg.steps = mmic_host::sim::steps_of(&mmic_host::plan::parse(plan).unwrap());
        cfg.run_to_end = false;
        if link == LinkLayer::Frames {
            cfg.sdls = Some(SdlsConfig {
                keys: SdlsKeys::Random,
                state: None,
                attack: 0.0,
            });
        }
        let s = engine::run(&cfg).unwrap();
        let what = format!("{protocol:?} {link:?}");
        assert!(
            s.completed(),
            "{what}: {}",
            mmic_host::sim::report::text(&s)
        );
        assert_eq!(s.restarts, [0, 0, 0, 1], "{what}");
        assert_eq!(s.executed_twice, 0, "{what}");
        // Numbers before and after the restart: the later all above the earlier.
        let restart_at = s.events("restart").next().unwrap()["t_ms"]
            .as_u64()
            .unwrap();
        let seqs = |before: bool| -> Vec<u64> {
            s.events("done")
                .filter(|r| (r["t_ms"].as_u64().unwrap() < restart_at) == before)
                .map(|r| r["event"]["seq"].as_u64().unwrap())
                .collect()
        };
        let (old, new) = (seqs(true), seqs(false));
        assert!(
            !old.is_empty() && !new.is_empty(),
            "{what}: {old:?} {new:?}"
        );
        assert!(
            new.iter().all(|n| old.iter().all(|o| n > o)),
            "{what}: {old:?} then {new:?}"
        );
        if link == LinkLayer::Frames {
            let f = s.frames.expect("frames figures");
            let x = f.sdls.expect("SDLS figures");
            // Only the ground's counter ahead of the server board's floor (COP-1 sent it again).
            assert_eq!(
                x.server.refused_total(),
                x.server.refused[6],
                "{what}: {x:?}"
            );
        }
        // During bolt 1 (a motion of many seconds): the plan ends there, unknown.
        let mut cfg = config(protocol, link, &["reboot-ground@9"]);
        cfg.steps = mmic_host::sim::steps_of(&mmic_host::plan::parse(plan).unwrap());
        let s = engine::run(&cfg).unwrap();
        assert_eq!(
            s.ends,
            [Some(mmic::node::ground::plan_runner::PlanEnd::Restarted {
                step: 2
            })],
            "{what}"
        );
        assert_eq!(s.executed_twice, 0, "{what}");
        assert!(
            s.events("done")
                .all(|r| r["t_ms"].as_u64().unwrap() < 9_000),
            "{what}"
        );
    }
}

/// The swarm draws restarts from their own stream, holds its invariants through them, and
/// finds the planted defect (board A's log not restored) and replays it.
#[test]
#[cfg_attr(miri, ignore = "swarm runs: minutes under Miri")]
fn the_swarm_finds_a_log_not_restored_and_replays_it() {
    let clean = Options {
        horizon_ms: 60_000,
        restarts: RestartDraw::On,
        ..Options::default()
    };
    let r = swarm(
        1,
        Duration::from_secs(300),
        Some(30),
        1,
        &clean,
        &mut |_| {},
    );
    assert!(r.failures.is_empty(), "{}", r.text(&clean));
    assert_eq!(r.restart_runs, r.runs);
    assert_eq!(r.checked.executed_twice, 0);
    let opts = Options {
        planted_bug: PlantedBug::LogNotRestored,
        ..clean
    };
    let r = swarm(
        1,
        Duration::from_secs(300),
        Some(200),
        1,
        &opts,
        &mut |_| {},
    );
    let f = r.failures.first().expect("the planted defect is found");
    assert!(
        f.violations
            .iter()
            .all(|v| v.invariant == Invariant::ExecutedTwice),
        "{:?}",
        f.violations
    );
    assert!(r.checked.executed_twice > 0);
    // The same seed without the defect holds; the printed command replays the scenario.
    assert!(run_one(f.seed, &clean).violations.is_empty());
    assert_eq!(
        replay_command(f.seed, &opts),
        format!(
            "mmic swarm --replay {} --sim-seconds 60 --plant-bug log-not-restored --restarts on",
            f.seed
        )
    );
    assert_eq!(
        run_one(f.seed, &opts).violations.len(),
        f.violations.len(),
        "replayed"
    );
}
