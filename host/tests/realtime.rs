//! The realtime engine (`mmic sim --realtime`): real threads, OS pipes, TCP and UDP on
//! loopback, on the paced wall clock. Its own tests: the transports carry the demo over both
//! protocols and a lossy WiFi link, and it runs the same node code as the virtual-time engine
//! (`host/tests/sim.rs` and `host/tests/engine.rs` test the behaviour, in virtual time).

use mmic::link::sdls::SdlsRefusal;
use mmic_host::sim::{engine, realtime, report, LinkLayer, Protocol, SimConfig, Summary};
use serde_json::Value;

fn realtime_demo(protocol: Protocol) -> SimConfig {
    let mut cfg = SimConfig::demo();
    cfg.realtime = true;
    cfg.protocol = protocol;
    cfg.scale = 20.0;
    cfg.progress = false;
    cfg
}

/// Board A's accepted commands other than the ground's polls (heartbeat requests, whose
/// number depends on timing), in order.
fn commands_run(s: &Summary) -> Vec<Value> {
    s.records
        .iter()
        .filter(|r| {
            r["kind"] == "event"
                && r["event"]["type"] == "executed"
                && r["event"]["refusal"].is_null()
                && r["event"]["command"] != "heartbeat"
        })
        .map(|r| r["event"]["command"].clone())
        .collect()
}

fn events<'a>(s: &'a Summary, ty: &'a str) -> Vec<&'a Value> {
    s.records
        .iter()
        .filter(|r| r["kind"] == "event" && r["event"]["type"] == ty)
        .map(|r| &r["event"])
        .collect()
}

/// Wall clock: run by `wall_clock::the_wall_clock_tests_side_by_side`.
pub(crate) fn the_demo_completes_over_real_transports_as_in_virtual_time() {
    // Both protocols' realtime runs side by side (they wait on the wall clock, each on its own
    // sockets and pipes), then each checked against its virtual-time run.
    let protocols = [Protocol::Legacy, Protocol::Pus];
    let runs: Vec<_> = std::thread::scope(|scope| {
        let handles: Vec<_> = protocols
            .map(|p| scope.spawn(move || realtime::run(&realtime_demo(p)).unwrap()))
            .into_iter()
            .collect();
        handles.into_iter().map(|h| h.join().unwrap()).collect()
    });
    for (protocol, real) in protocols.into_iter().zip(runs) {
        let cfg = realtime_demo(protocol);
        assert!(real.realtime);
        assert!(real.completed(), "{}", report::text(&real));
        assert!(!real.host_fell_behind());
        let virt = engine::run(&SimConfig {
            realtime: false,
            ..cfg
        })
        .unwrap();
        assert!(virt.completed(), "{}", report::text(&virt));
        // The same node code: the same commands run, in the same order, the same states
        // reached, the same bolting pairs.
        assert_eq!(commands_run(&real), commands_run(&virt), "{protocol:?}");
        let states = |s: &Summary| -> Vec<Value> {
            events(s, "reached")
                .into_iter()
                .map(|e| e["state"].clone())
                .collect()
        };
        assert_eq!(states(&real), states(&virt));
        assert_eq!(events(&real, "pair").len(), events(&virt, "pair").len());
        // Real transports: TCP visits for the WiFi, a pipe or UDP for the ground link.
        let ground_link = match protocol {
            Protocol::Legacy => "serial_ground",
            Protocol::Pus => "udp_ground",
        };
        for link in ["wifi", ground_link, "serial_ab"] {
            assert!(
                real.records.iter().any(|r| r["kind"] == "packet"
                    && r["link"] == link
                    && r["fate"] == "delivered"),
                "{protocol:?}: nothing crossed {link}"
            );
        }
    }
}

/// Wall clock: run by `wall_clock::the_wall_clock_tests_side_by_side`.
pub(crate) fn thirty_percent_wifi_loss_over_tcp_runs_nothing_twice() {
    let mut cfg = realtime_demo(Protocol::Legacy);
    cfg.wifi_loss = 0.3;
    cfg.seed = 7;
    let s = realtime::run(&cfg).unwrap();
    assert!(s.completed(), "{}", report::text(&s));
    let copies = events(&s, "duplicate").len() + events(&s, "stale").len();
    assert!(copies > 0, "resends reached board A and were answered");
    let mut seen = std::collections::BTreeSet::new();
    for e in events(&s, "executed") {
        let seq = e["seq"].as_u64().unwrap();
        assert!(seq == 0 || seen.insert(seq), "{seq} executed twice");
    }
}

/// Wall clock: run by `wall_clock::the_wall_clock_tests_side_by_side`.
pub(crate) fn the_space_data_link_over_lossy_udp_completes_the_demo_and_counts_its_frames() {
    // TC and TM transfer frames, one per datagram, 20 % of them lost each way: FOP-1's
    // retransmissions and the TM frames' CLCWs carry the demo through, and nothing runs twice.
    let mut cfg = realtime_demo(Protocol::Pus);
    cfg.link = LinkLayer::Frames;
    cfg.serial_loss = 0.2;
    cfg.seed = 5;
    // Half the other tests' pace: the frames' threads (FOP-1's ground, the frame gateway)
    // add to the node threads a shared 2-core host must keep within board B's 500 ms.
    cfg.scale = 10.0;
    let s = realtime::run(&cfg).unwrap();
    assert!(s.completed(), "{}", report::text(&s));
    assert!(!s.host_fell_behind());
    let f = s.frames.expect("the summary has the link's figures");
    assert!(
        f.tc_frames > 0 && f.accepted > 0 && f.tm_frames > 0 && f.clcws > 0,
        "{f:?}"
    );
    assert!(
        f.retransmissions > 0,
        "20 % loss and no retransmission: {f:?}"
    );
    assert!(f.tm_lost > 0, "20 % loss and no TM frame missing: {f:?}");
    assert!(f.clcws <= f.tm_frames && f.accepted <= f.tc_frames, "{f:?}");
    assert!(
        report::text(&s).contains("link: frames"),
        "{}",
        report::text(&s)
    );
    let json = report::summary_json(&s, 0);
    assert_eq!(json.link.as_deref(), Some("frames"));
    assert!(json.frames.is_some());
    // Lost frames on the UDP link, logged as such.
    assert!(s
        .records
        .iter()
        .any(|r| r["kind"] == "packet" && r["link"] == "udp_ground" && r["fate"] == "lost"));
    // Every command the plan needed ran once, in the plan's order, as in virtual time.
    let virt = engine::run(&SimConfig {
        realtime: false,
        ..cfg
    })
    .unwrap();
    assert!(virt.completed(), "{}", report::text(&virt));
    assert_eq!(commands_run(&s), commands_run(&virt));
    let mut seen = std::collections::BTreeSet::new();
    for e in events(&s, "executed") {
        let seq = e["seq"].as_u64().unwrap();
        assert!(seq == 0 || seen.insert(seq), "{seq} executed twice");
    }
}

/// Restarts on the wall clock (`--inject reboot-a/-b/-server/-ground@S` with `--realtime`):
/// the threads of board A (both tasks), board B, the server board and the ground go down for
/// 300 ms and boot from what they kept, as in virtual time; nothing runs twice.
/// Wall clock: run by `wall_clock::the_wall_clock_tests_side_by_side`.
pub(crate) fn board_a_board_b_and_the_ground_restart_on_the_wall_clock() {
    for (protocol, inject, node) in [
        (Protocol::Legacy, "reboot-a@8", 0),
        (Protocol::Pus, "reboot-b@8", 1),
    ] {
        let mut cfg = realtime_demo(protocol);
        cfg.inject(inject.parse().unwrap()).unwrap();
        let s = realtime::run(&cfg).unwrap();
        let mut want = [0u32; 4];
        want[node] = 1;
        assert_eq!(s.restarts, want, "{inject}: {}", report::text(&s));
        assert!(report::executed_twice(&s).is_empty(), "{inject}");
        assert_eq!(events(&s, "boot").len(), 1, "{inject}");
        // Board A came up in Standby (boot byte: power-on, once); board B announced its
        // restart and board A went Safed: either way the plan stopped, with a reason.
        assert!(!s.completed() && s.ends[0].is_some(), "{inject}");
        if node == 0 {
            assert_eq!(events(&s, "boot")[0]["boot"], 0x21);
        }
    }
    // The ground in a wait, over frames with SDLS: the plan goes on and completes.
    let mut cfg = realtime_demo(Protocol::Pus);
    cfg.link = LinkLayer::Frames;
    cfg.scale = 10.0;
    cfg.steps = mmic_host::sim::steps_of(
        &mmic_host::plan::parse("mode operational\nwait 6s\nbolt 1\nmode standby\n").unwrap(),
    );
    cfg.sdls = Some(mmic_host::sim::SdlsConfig {
        keys: mmic_host::sim::SdlsKeys::Random,
        state: None,
        attack: 0.0,
    });
    cfg.inject("reboot-ground@4".parse().unwrap()).unwrap();
    let s = realtime::run(&cfg).unwrap();
    assert!(s.completed(), "{}", report::text(&s));
    assert_eq!(s.restarts, [0, 0, 0, 1]);
    assert!(report::executed_twice(&s).is_empty());
    // The server board in the plan's wait, over each protocol and link (over frames with
    // SDLS): its threads drop the visit, the relay or gateway and FARM-1, boot from what
    // they kept, and the plan completes.
    for (protocol, link) in [
        (Protocol::Legacy, LinkLayer::Packets),
        (Protocol::Pus, LinkLayer::Packets),
        (Protocol::Pus, LinkLayer::Frames),
    ] {
        let mut cfg = realtime_demo(protocol);
        cfg.link = link;
        cfg.scale = 10.0;
        cfg.steps = mmic_host::sim::steps_of(
            &mmic_host::plan::parse("mode operational\nwait 6s\nbolt 1\nmode standby\n").unwrap(),
        );
        if link == LinkLayer::Frames {
            cfg.sdls = Some(mmic_host::sim::SdlsConfig {
                keys: mmic_host::sim::SdlsKeys::Random,
                state: None,
                attack: 0.0,
            });
        }
        // Down while the first command may be in flight too: whatever it took, it ends
        // reported and nothing runs twice.
        let mut early = cfg.clone();
        early.inject("reboot-server@0.05".parse().unwrap()).unwrap();
        let s = realtime::run(&early).unwrap();
        let what = format!("early {protocol:?} {link:?}: {}", report::text(&s));
        assert_eq!(s.restarts, [0, 0, 1, 0], "{what}");
        assert!(report::executed_twice(&s).is_empty(), "{what}");
        assert!(s.ends.iter().all(|e| e.is_some()), "{what}");
        cfg.inject("reboot-server@4".parse().unwrap()).unwrap();
        let s = realtime::run(&cfg).unwrap();
        let what = format!("{protocol:?} {link:?}: {}", report::text(&s));
        assert!(s.completed(), "{what}");
        assert_eq!(s.restarts, [0, 0, 1, 0], "{what}");
        assert!(report::executed_twice(&s).is_empty(), "{what}");
        let boots: Vec<&Value> = s
            .records
            .iter()
            .filter(|r| r["kind"] == "event" && r["event"]["type"] == "boot")
            .collect();
        assert_eq!(boots.len(), 1, "{what}");
        assert_eq!(boots[0]["node"], "server1", "{what}");
        assert!(boots[0]["t_ms"].as_u64() >= Some(4_300), "{what}");
        if link == LinkLayer::Frames {
            // The server board's TM counter went on from its store, above every IV used
            // before: the ground refused no TM frame as a replay, only (at most) the first
            // ones beyond its durable floor ("not-reserved": the stored reservation is up to
            // 256 ahead). The server refused replays (FOP-1's retransmissions of frames it
            // had verified) and, after its restart, authentic frames beyond its stored TC
            // floor until the next block was written ("not-reserved", which COP-1 sends
            // again under fresh IVs): at most a block and a half, `TC_RX_BLOCK` × 3/2 = 24
            // (decision `sdls-counters`). Whether any comes depends on how many transmissions
            // the ground made while the server was down, a matter of the wall clock (a CI
            // run saw replay 15, not-reserved 1).
            let f = s.frames.and_then(|f| f.sdls).expect("SDLS figures");
            let only = |e: &mmic_host::sim::SdlsEnd, names: &[&str]| {
                SdlsRefusal::NAMES
                    .iter()
                    .zip(e.refused)
                    .all(|(n, k)| k == 0 || names.contains(n))
            };
            assert!(only(&f.ground, &["not-reserved"]), "{f:?} {what}");
            assert!(only(&f.server, &["replay", "not-reserved"]), "{f:?} {what}");
            let not_reserved = SdlsRefusal::NAMES.iter().position(|n| *n == "not-reserved");
            let bound = u64::from(mmic::link::sdls::mission::TC_RX_BLOCK * 3 / 2);
            assert!(
                f.server.refused[not_reserved.unwrap()] <= bound,
                "{f:?} {what}"
            );
            assert!(f.ground.verified > 0 && f.server.verified > 0, "{f:?}");
        }
    }
}
