//! The replay (`mmic replay`, `benches/rv32`) against the simulation it was recorded from: for
//! every scenario CI runs on RV32, replaying the trace on this host must send exactly the
//! packets the virtual-time engine sent (every link, in order, at the same milliseconds), and
//! end with board A where the engine's ended. So the RV32 comparison checks the simulator's own
//! ticks, not a look-alike. Also: a changed trace or output is found and named.

use mmic_host::replay::{compare, run, scenarios, tag_name, FAULTS};
use mmic_replay::out::{fields, records, Field};
use mmic_replay::trace::{Protocol, Record, Trace, TraceError};
use serde_json::Value;

type Streams = std::collections::BTreeMap<&'static str, Vec<(u32, String)>>;

fn hex(b: &[u8]) -> String {
    b.iter().map(|x| format!("{x:02x}")).collect()
}

/// Every packet the engine's log shows written, by stream (copies of duplicated packets and
/// heartbeats discarded while unconnected are not writes).
fn engine_streams(log: &[Value], pus: bool) -> Streams {
    let mut s = Streams::new();
    for r in log {
        if r["kind"] != "packet" || r["fate"] == "duplicated" || r["fate"] == "unconnected" {
            continue;
        }
        let stream = match (r["from"].as_str(), r["to"].as_str()) {
            (Some("board_a1"), Some("board_b1")) => "A to B",
            (Some("board_b1"), Some("board_a1")) => "B to A",
            (Some("board_a1"), Some("server1")) => "A to server",
            (Some("server1"), Some("board_a1")) => "server to A",
            (Some("server1"), Some("ground")) => "server to ground",
            _ => continue,
        };
        let _ = pus;
        let t = r["t_ms"].as_u64().unwrap_or(u64::MAX) as u32;
        let h = r["hex"].as_str().unwrap_or("").to_string();
        s.entry(stream).or_default().push((t, h));
    }
    s
}

/// The same streams from the replay's output records.
fn replay_streams(out: &[u8]) -> Streams {
    let mut s = Streams::new();
    for r in records(out) {
        let mut visit_board = false;
        for (id, v) in fields(r.fields) {
            let stream = match (r.tag, Field::from_id(id)) {
                (1, Some(Field::ToB)) => "A to B",
                (2, Some(Field::InternalHeartbeat)) => "B to A",
                (8, Some(Field::Sent)) => "A to server",
                (11, Some(Field::Sent)) | (_, Some(Field::Report)) | (_, Some(Field::TmFrame)) => {
                    "server to ground"
                }
                (_, Some(Field::Visit)) => {
                    // The board number, then the command.
                    visit_board = !visit_board;
                    if visit_board {
                        continue;
                    }
                    "server to A"
                }
                _ => continue,
            };
            s.entry(stream).or_default().push((r.t, hex(v)));
        }
    }
    s
}

#[test]
fn replay_sends_what_the_engine_sent_in_every_scenario() {
    let dir = std::env::temp_dir().join(format!("mmic-replay-test-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let all = scenarios();
    assert_eq!(all.len(), 5 + FAULTS.len());
    for (name, mut cfg) in all {
        let path = dir.join(format!("{name}.trace"));
        cfg.record = Some(path.clone());
        cfg.log_packets = true;
        let pus = cfg.protocol == mmic_host::sim::Protocol::Pus;
        let summary = mmic_host::sim::run(&cfg).unwrap();
        let trace = std::fs::read(&path).unwrap();
        let (out, n) = run(&trace).unwrap();
        let (want, got) = (engine_streams(&summary.records, pus), replay_streams(&out));
        assert_eq!(
            want.keys().copied().collect::<Vec<_>>(),
            [
                "A to B",
                "A to server",
                "B to A",
                "server to A",
                "server to ground"
            ],
            "{name}"
        );
        for (stream, w) in &want {
            let g = got.get(stream).map(Vec::as_slice).unwrap_or(&[]);
            let first = w.iter().zip(g).position(|(a, b)| a != b);
            assert!(
                first.is_none() && w.len() == g.len(),
                "{name}: {stream}: engine {} packets, replay {}; first difference at {first:?}: {:?} vs {:?}",
                w.len(),
                g.len(),
                first.and_then(|i| w.get(i)),
                first.and_then(|i| g.get(i)),
            );
        }
        // Board A ends where the engine's did.
        let t = Trace::parse(&trace).unwrap();
        let mut r = mmic_replay::Replay::new(&t.header);
        for rec in t.records() {
            r.step(&rec.unwrap(), &mut Vec::new(), &mut ());
        }
        let status = &summary.status;
        assert_eq!(
            serde_json::to_value(r.board_a().mode()).unwrap(),
            status["mode"],
            "{name}"
        );
        assert_eq!(
            serde_json::to_value(r.board_a().state()).unwrap(),
            status["state"],
            "{name}"
        );
        if cfg.link == mmic_host::sim::LinkLayer::Frames {
            // The frame gateway ran: TC frames in (some retransmitted after the ground link
            // lost them), every TM frame out in the streams compared above.
            let secured = cfg.sdls.is_some();
            let protocol = if secured {
                Protocol::PusFramesSdls
            } else {
                Protocol::PusFrames
            };
            assert_eq!(t.header.protocol, protocol, "{name}");
            assert_eq!(t.header.sdls.is_some(), secured, "{name}");
            assert!(summary.completed(), "{name}");
            let f = summary.frames.expect("the link's figures");
            assert!(f.retransmissions > 0 && f.tm_lost > 0, "{name}: {f:?}");
            let count = |field: Field| {
                records(&out)
                    .flat_map(|r| fields(r.fields))
                    .filter(|(id, _)| *id == field as u8)
                    .count() as u64
            };
            assert_eq!(count(Field::TmFrame), f.tm_frames, "{name}");
            assert!(count(Field::TcFrame) > 0, "{name}");
            assert_eq!(count(Field::Report), 0, "{name}: no bare packets");
            if secured {
                // The server board verified the ground's TC frames and protected every TM
                // frame it sent, the replay's the same (compared above, byte for byte).
                let s = f.sdls.expect("SDLS's figures");
                assert!(s.server.verified > 0, "{name}: {s:?}");
                assert_eq!(s.server.protected, f.tm_frames, "{name}: {s:?}");
            }
        }
        if let Some(f) = name.strip_prefix("fault-") {
            let raised = mmic_host::sim::report::faults_raised(&summary);
            assert!(raised.iter().any(|x| x == f), "{name}: raised {raised:?}");
        }
        assert!(n > 100, "{name}: {n} records");
        std::fs::remove_file(&path).unwrap();
    }
    let _ = std::fs::remove_dir(&dir);
}

#[test]
fn a_changed_output_is_named_by_record_and_field() {
    let (name, cfg) = scenarios().swap_remove(0);
    let mut cfg = cfg;
    let path =
        std::env::temp_dir().join(format!("mmic-replay-{name}-{}.trace", std::process::id()));
    cfg.record = Some(path.clone());
    cfg.log_packets = false;
    mmic_host::sim::run(&cfg).unwrap();
    let trace = std::fs::read(&path).unwrap();
    std::fs::remove_file(&path).unwrap();
    let (out, _) = run(&trace).unwrap();
    assert_eq!(compare(&out, &out, ("a", "b")), None);
    // Flip one bit of the 500th record's arm pulse.
    let r = records(&out).nth(500).unwrap();
    assert_eq!(r.tag, 1, "the 500th record is a board A tick");
    let offset = r.fields.as_ptr() as usize - out.as_ptr() as usize;
    let (id, v) = fields(r.fields)
        .find(|(id, _)| *id == Field::Arm as u8)
        .unwrap();
    assert_eq!(id, Field::Arm as u8);
    let at = offset + (v.as_ptr() as usize - r.fields.as_ptr() as usize);
    let mut bad = out.clone();
    bad[at] ^= 1;
    let d = compare(&out, &bad, ("host", "rv32")).unwrap();
    assert!(
        d.starts_with(&format!(
            "first difference at output record 500 ({}, t={} ms), field arm pulse",
            tag_name(1),
            r.t
        )),
        "{d}"
    );
    // A missing tail is named too.
    let cut = &out[..offset - 7];
    let d = compare(&out, cut, ("host", "rv32")).unwrap();
    assert!(d.contains("output record 500"), "{d}");
    // A trace cut short is an error, not a shorter replay.
    let err = run(&trace[..trace.len() - 3]).unwrap_err();
    assert!(matches!(err, TraceError::Truncated { .. }), "{err}");
    assert_eq!(run(b"not a trace at all!").unwrap_err(), TraceError::Magic);
    // Every record parses back to what it was.
    let t = Trace::parse(&trace).unwrap();
    let mut again = Vec::new();
    t.header.emit(&mut again);
    for rec in t.records() {
        let rec: Record<'_> = rec.unwrap();
        rec.emit(&mut again);
    }
    assert_eq!(again, trace);
}

/// `mmic rv32-costs`'s budgets: the robot's boards are held to --robot-budget, the server board
/// to --budget (and the robot's boards too when no --robot-budget is given); a call over its
/// node's budget fails the run, naming the node.
#[test]
fn each_node_is_held_to_its_own_budget() {
    use mmic_replay::cost::{Cost, COST_LEN};
    use mmic_replay::trace::Node;
    let call = |node: Node, glue: u32| {
        let mut b = [0u8; COST_LEN];
        let node = node as u8;
        let c = Cost {
            tag: 1,
            node,
            t: 10,
            phases: [glue, 0, 0, 7],
            stack_node: 0,
            stack_all: 0,
        };
        c.emit(&mut b);
        b
    };
    let f = std::env::temp_dir().join(format!("mmic-costs-{}.cost", std::process::id()));
    let mut bytes = call(Node::AControl, 12_000).to_vec();
    bytes.extend(call(Node::B, 2_000));
    bytes.extend(call(Node::Server, 40_000));
    std::fs::write(&f, bytes).unwrap();
    let costs = |all, robot| {
        let mut out = Vec::new();
        let r = mmic_host::replay::cli_costs(std::slice::from_ref(&f), (all, robot), &mut out);
        (
            r.map_err(|e| e.to_string()),
            String::from_utf8(out).unwrap(),
        )
    };
    let (r, out) = costs(Some(60_000), Some(16_000));
    assert!(r.is_ok(), "{r:?}");
    assert!(
        out.contains(
            "worst call of board A control: 12000 instructions, within its budget of 16000"
        ),
        "{out}"
    );
    assert!(
        out.contains("worst call of server board: 40000 instructions, within its budget of 60000"),
        "{out}"
    );
    let (r, _) = costs(Some(60_000), Some(11_999));
    let e = r.unwrap_err();
    assert!(
        e.contains("board A control (12000 > 11999)") && !e.contains("server"),
        "{e}"
    );
    let (r, _) = costs(Some(39_999), None);
    let e = r.unwrap_err();
    assert!(
        e.contains("server board (40000 > 39999)") && !e.contains("board A"),
        "{e}"
    );
    let (r, _) = costs(Some(11_999), None);
    assert!(r.unwrap_err().contains("board A control (12000 > 11999)"));
    assert!(costs(None, None).0.is_ok());
    let _ = std::fs::remove_file(&f);
}

#[test]
fn a_trace_holds_only_test_keys_made_for_its_run() {
    use mmic_host::sim::{SdlsConfig, SdlsKeys};
    let (_, frames) = scenarios()
        .into_iter()
        .find(|(n, _)| n == "frames-sdls")
        .unwrap();
    let path = std::env::temp_dir().join(format!("mmic-replay-keys-{}.trace", std::process::id()));
    // Keys given from files, or a run with an attacker, are never recorded.
    let given = SdlsConfig {
        keys: SdlsKeys::Seeded,
        ..SdlsConfig::recorded()
    };
    let attacked = SdlsConfig {
        attack: 0.1,
        ..SdlsConfig::recorded()
    };
    for sdls in [given, attacked] {
        let mut cfg = frames.clone();
        cfg.max_sim_ms = 1_000;
        cfg.record = Some(path.clone());
        cfg.sdls = Some(sdls);
        let e = mmic_host::sim::run(&cfg).unwrap_err();
        assert!(e.to_string().contains("only test keys"), "{e}");
        assert!(!path.exists());
    }
    // Two recordings, two sets of keys; never shown.
    let (a, b) = (SdlsConfig::recorded(), SdlsConfig::recorded());
    let (ka, kb) = (a.trace_keys().unwrap(), b.trace_keys().unwrap());
    assert_ne!(ka, kb);
    assert_eq!(format!("{ka:?}"), "TestKeys(..)");
    assert_eq!(
        format!("{a:?}"),
        r#"SdlsConfig { keys: "recorded", attack: 0.0 }"#
    );
    // A trace whose key is weak (here all zeros) is refused, not replayed.
    let mut h = mmic_replay::trace::Header::demo(Protocol::PusFramesSdls);
    h.sdls = Some(mmic_replay::trace::TestKeys::new([0; 32], [7; 32]));
    let mut bytes = Vec::new();
    h.emit(&mut bytes);
    assert!(matches!(
        Trace::parse(&bytes).map(|_| ()),
        Err(TraceError::Header { .. })
    ));
}
