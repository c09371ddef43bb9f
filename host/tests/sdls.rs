//! SDLS in the simulator's own grounds (`mmic sim --protocol pus --link frames --sdls`) and in
//! the fault swarm: both ends secured with keys derived from the seed (deterministic runs), the
//! summary's SDLS figures, the log's protected frames by their headers only, and the attacker on
//! the uplink whose replays and bit flips are all refused before FARM-1.

use mmic_host::sim::engine::watch::Invariant;
use mmic_host::sim::engine::{self, watch::Watch};
use mmic_host::sim::{LinkLayer, Protocol, SdlsConfig, SdlsKeys, SdlsStats, SimConfig, Summary};
use mmic_host::swarm::scenario::{LinkDraw, Options, Scenario, SdlsDraw};
use mmic_host::swarm::{run_one, swarm};
use serde_json::Value;
use std::collections::BTreeMap;
use std::time::Duration;

/// The demo over the space data link with SDLS, an attacker at `attack`, the ground link
/// losing `loss` each way.
fn secured(seed: u64, attack: f64, loss: f64) -> SimConfig {
    let mut cfg = SimConfig::demo();
    cfg.protocol = Protocol::Pus;
    cfg.link = LinkLayer::Frames;
    cfg.seed = seed;
    cfg.serial_loss = loss;
    cfg.progress = false;
    cfg.sdls = Some(SdlsConfig {
        keys: SdlsKeys::Seeded,
        state: None,
        attack,
    });
    cfg
}

fn run(cfg: &SimConfig) -> (Summary, Watch) {
    let (s, w) = engine::run_watched(cfg, true).expect("the run starts");
    (s, w.expect("watched"))
}

fn sdls(s: &Summary) -> SdlsStats {
    s.frames
        .as_ref()
        .and_then(|f| f.sdls)
        .expect("SDLS figures in the summary")
}

/// Board A's executions of each command (heartbeats aside) by sequence number.
fn executions(records: &[Value]) -> BTreeMap<u64, u32> {
    let mut m = BTreeMap::new();
    for r in records {
        let e = &r["event"];
        if r["kind"] == "event" && e["type"] == "executed" && e["command"] != "heartbeat" {
            *m.entry(e["seq"].as_u64().unwrap()).or_insert(0) += 1;
        }
    }
    m
}

#[test]
fn a_seeded_sdls_run_completes_the_demo_with_no_refusal_and_is_deterministic() {
    let cfg = secured(1, 0.0, 0.0);
    let (a, w) = run(&cfg);
    assert!(a.completed(), "{:?}", a.ends);
    assert!(w.violations.is_empty(), "{:?}", w.violations);
    let x = sdls(&a);
    assert_eq!(x.server.refused_total(), 0, "{x:?}");
    assert_eq!(x.ground.refused_total(), 0, "{x:?}");
    let f = a.frames.unwrap();
    // Every TC frame the ground sent is a protected data frame (the engine's initiation needs
    // no BC frame on a clean link), verified once; every TM frame protected and verified.
    assert!(
        x.server.verified > 0 && x.server.verified == x.ground.protected,
        "{x:?}"
    );
    assert_eq!(x.server.verified, f.tc_frames);
    assert_eq!(x.server.protected, f.tm_frames);
    assert_eq!(x.ground.verified, f.tm_frames);
    assert_eq!(x.attack_frames, 0);
    // The same seed, the same keys: the same log, byte for byte.
    let (b, _) = run(&cfg);
    assert_eq!(a.records, b.records);
    // Another seed's keys protect the same plaintexts differently.
    let (c, _) = run(&secured(2, 0.0, 0.0));
    let first_tc = |s: &Summary| {
        s.records
            .iter()
            .find(|r| r["kind"] == "packet" && r["packet_kind"] == "tc_frame")
            .map(|r| r["hex"].clone())
    };
    assert_ne!(first_tc(&a), first_tc(&c));
}

#[test]
fn the_log_shows_a_protected_frame_by_its_headers_never_its_packets() {
    let (s, _) = run(&secured(1, 0.0, 0.0));
    let frames: Vec<&Value> = s
        .records
        .iter()
        .filter(|r| r["kind"] == "packet" && r["link"] == "udp_ground")
        .collect();
    assert!(frames.len() > 100);
    for r in &frames {
        let p = &r["packet"];
        let kind = r["packet_kind"].as_str().unwrap();
        assert!(kind == "tc_frame" || kind == "tm_frame", "{r}");
        let sec = &p["sdls"];
        let spi = sec["spi"].as_u64().unwrap();
        assert_eq!(spi, if kind == "tc_frame" { 257 } else { 513 }, "{r}");
        assert_eq!(sec["iv"].as_str().unwrap().len(), 24);
        // The ciphertext is not read as packets or shown as data.
        assert!(p["data"].is_null(), "{r}");
        assert!(p.get("packets").is_none_or(Value::is_null), "{r}");
    }
    // The IVs count up from 0 each way.
    let ivs = |kind: &str| -> Vec<u128> {
        frames
            .iter()
            .filter(|r| r["packet_kind"] == kind)
            .map(|r| u128::from_str_radix(r["packet"]["sdls"]["iv"].as_str().unwrap(), 16).unwrap())
            .collect()
    };
    for kind in ["tc_frame", "tm_frame"] {
        let v = ivs(kind);
        assert_eq!(v, (0..v.len() as u128).collect::<Vec<_>>(), "{kind}");
    }
    // The server board's verdict on each TC frame names its SPI and IV.
    let verdicts = s
        .records
        .iter()
        .filter(|r| r["kind"] == "event" && r["event"]["type"] == "tc_frame")
        .count();
    assert!(verdicts > 0);
    let text = mmic_host::sim::report::text(&s);
    assert!(
        text.contains("sdls: AES-256-GCM both ways -- server verified"),
        "{text}"
    );
}

#[test]
fn an_attacker_on_the_uplink_is_refused_every_time_and_nothing_runs_twice() {
    let (mut attacks, mut refused) = (0, 0);
    for seed in 1..=4 {
        let (s, w) = run(&secured(seed, 0.5, 0.1));
        assert!(w.violations.is_empty(), "seed {seed}: {:?}", w.violations);
        let x = sdls(&s);
        assert!(x.attack_frames > 0, "seed {seed}: {x:?}");
        assert_eq!(
            x.attacks_refused_sdls + x.attacks_refused_frame,
            x.attack_frames,
            "seed {seed}: {x:?}"
        );
        assert_eq!(x.attacks_passed, 0);
        assert!(x.server.refused_total() >= x.attacks_refused_sdls);
        assert!(
            x.server.verified <= x.ground.protected,
            "seed {seed}: {x:?}"
        );
        assert_eq!(w.checked.attack_frames, x.attack_frames);
        let twice: Vec<_> = executions(&s.records)
            .into_iter()
            .filter(|(_, n)| *n > 1)
            .collect();
        assert!(twice.is_empty(), "seed {seed}: {twice:?}");
        // Refused attack frames are logged with their check and layer.
        let logged = s
            .records
            .iter()
            .filter(|r| r["event"]["type"] == "tc_frame_refused" && r["event"]["attack"] == true)
            .count() as u64;
        assert_eq!(logged, x.attack_frames);
        attacks += x.attack_frames;
        refused += x.server.refused_total();
    }
    assert!(attacks > 20, "{attacks}");
    println!("4 attacked runs: {attacks} attack frames, SDLS refused {refused} TC frames");
}

#[test]
fn the_cli_runs_sdls_and_refuses_what_it_cannot_do() {
    let dir = std::path::PathBuf::from(env!("CARGO_TARGET_TMPDIR")).join("sdls-cli");
    let mmic = |args: &[&str]| {
        let o = std::process::Command::new(env!("CARGO_BIN_EXE_mmic"))
            .args(args)
            .output()
            .unwrap();
        (
            o.status.code().unwrap_or(-1),
            String::from_utf8_lossy(&o.stdout).into_owned(),
            String::from_utf8_lossy(&o.stderr).into_owned(),
        )
    };
    let json = dir.join("summary.json");
    let (code, out, err) = mmic(&[
        "sim",
        "--protocol",
        "pus",
        "--link",
        "frames",
        "--sdls",
        "--sdls-attack",
        "0.3",
        "--quiet",
        "--out",
        dir.to_str().unwrap(),
        "--summary-json",
        json.to_str().unwrap(),
    ]);
    assert_eq!(code, 0, "{out}{err}");
    assert!(out.contains("attacker sent"), "{out}");
    let v: Value = serde_json::from_str(&std::fs::read_to_string(&json).unwrap()).unwrap();
    let x = &v["frames"]["sdls"];
    assert!(x["attack_frames"].as_u64().unwrap() > 0, "{x}");
    assert_eq!(x["attacks_passed"], 0);
    for name in mmic::link::sdls::SdlsRefusal::NAMES {
        assert!(x["server"]["refused"][name].is_u64(), "{name}: {x}");
    }
    for (args, why) in [
        (&["sim", "--protocol", "pus", "--sdls"][..], "--link frames"),
        (
            &[
                "sim",
                "--protocol",
                "pus",
                "--link",
                "frames",
                "--sdls-attack",
                "0.1",
            ][..],
            "--sdls",
        ),
        (
            &[
                "sim",
                "--protocol",
                "pus",
                "--link",
                "frames",
                "--sdls",
                "--sdls-attack",
                "2",
            ][..],
            "0..1",
        ),
        (
            &[
                "sim",
                "--protocol",
                "pus",
                "--link",
                "frames",
                "--sdls",
                "--realtime",
                "--sdls-attack",
                "0.1",
            ][..],
            "virtual time",
        ),
    ] {
        let (code, _, err) = mmic(args);
        assert_eq!(code, 2, "{args:?}: {err}");
        assert!(err.contains(why), "{args:?}: {err}");
    }
}

#[test]
fn the_swarm_draws_sdls_for_half_the_frames_runs_and_leaves_other_scenarios_alone() {
    let any = Options::default();
    let off = Options {
        sdls: SdlsDraw::Off,
        ..Options::default()
    };
    let packets = Options {
        link: LinkDraw::Packets,
        ..Options::default()
    };
    let (mut frames, mut secured, mut attacked) = (0, 0, 0);
    for seed in 0..400 {
        let s = Scenario::from_seed(seed, &any);
        let o = Scenario::from_seed(seed, &off);
        // SDLS is drawn after every other draw: without it a seed's scenario is what it was.
        assert_eq!(o.sdls, None);
        let without = match s.sdls {
            Some(a) => s
                .describe()
                .replace(&format!("; SDLS, attacker rate {a:.2}"), ""),
            None => s.describe(),
        };
        assert_eq!(o.describe(), without, "seed {seed}");
        assert_eq!(o.cfg.serial_loss, s.cfg.serial_loss, "seed {seed}");
        assert_eq!(o.cfg.links, s.cfg.links, "seed {seed}");
        assert_eq!(o.plan, s.plan);
        let p = Scenario::from_seed(seed, &packets);
        assert!(p.cfg.sdls.is_none() && p.sdls.is_none());
        if s.link == LinkLayer::Frames {
            frames += 1;
            if let Some(a) = s.sdls {
                secured += 1;
                attacked += usize::from(a > 0.0);
                assert!(matches!(
                    s.cfg.sdls.as_ref().map(|c| &c.keys),
                    Some(SdlsKeys::Seeded)
                ));
            }
        } else {
            assert!(s.sdls.is_none() && s.cfg.sdls.is_none());
        }
    }
    assert!(frames > 50, "{frames}");
    let share = secured as f64 / frames as f64;
    assert!((0.35..0.65).contains(&share), "{secured} of {frames}");
    assert!(attacked > secured / 2, "{attacked} of {secured}");
}

#[test]
fn swarm_runs_with_sdls_and_attacks_break_no_invariant() {
    let opts = Options {
        horizon_ms: 60_000,
        link: LinkDraw::Frames,
        sdls: SdlsDraw::On,
        ..Options::default()
    };
    let r = swarm(1, Duration::from_secs(600), Some(24), 1, &opts, &mut |_| {});
    assert!(r.failures.is_empty(), "{}", r.text(&opts));
    let x = r.frames.sdls.expect("SDLS figures");
    assert!(r.sdls_runs > 5 && r.attacked_runs > 2, "{}", r.text(&opts));
    assert!(x.attack_frames > 10, "{x:?}");
    assert_eq!(x.attacks_passed, 0);
    assert_eq!(r.checked.attack_frames, x.attack_frames);
    let text = r.text(&opts);
    assert!(text.contains("with SDLS"), "{text}");
    let json = r.json(&opts);
    assert_eq!(json["sdls_runs"], r.sdls_runs);
    assert!(json["frames"]["sdls"]["attack_frames"].as_u64().unwrap() > 0);
    // A seed replays the same: its outcome again.
    let seed = 3;
    let a = run_one(seed, &opts);
    let b = run_one(seed, &opts);
    assert_eq!(a.scenario, b.scenario);
    assert_eq!(
        a.summary.as_ref().map(|s| &s.records),
        b.summary.as_ref().map(|s| &s.records)
    );
}

#[test]
fn the_watch_flags_more_frames_verified_than_protected() {
    let cfg = secured(1, 0.0, 0.0);
    let mut w = Watch::new(&cfg, 1);
    w.sdls_checked(0, 10, 5, 5);
    assert!(w.violations.is_empty());
    w.sdls_checked(0, 20, 6, 5);
    w.forged(0, 30, "an attack frame reached FARM-1".into());
    let names: Vec<_> = w.violations.iter().map(|v| v.invariant).collect();
    assert_eq!(names, vec![Invariant::ForgedFrame, Invariant::ForgedFrame]);
    assert_eq!(Invariant::ForgedFrame.name(), "forged-frame");
}

/// Wall clock: run by `wall_clock::the_wall_clock_tests_side_by_side`.
pub(crate) fn the_realtime_engine_secures_its_own_ground_with_keys_made_at_run_time() {
    let mut cfg = secured(1, 0.0, 0.0);
    cfg.realtime = true;
    cfg.scale = 10.0;
    cfg.sdls = Some(SdlsConfig {
        keys: SdlsKeys::Random,
        state: None,
        attack: 0.0,
    });
    let s = mmic_host::sim::run(&cfg).expect("the run");
    assert!(s.completed(), "{:?}", s.ends);
    let x = sdls(&s);
    assert_eq!(x.server.refused_total(), 0, "{x:?}");
    assert!(
        x.server.verified > 0 && x.server.verified <= x.ground.protected,
        "{x:?}"
    );
    assert!(
        x.ground.verified > 0 && x.ground.verified <= x.server.protected,
        "{x:?}"
    );
    assert!(mmic_host::sim::report::executed_twice(&s).is_empty());
}
