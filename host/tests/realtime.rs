//! The realtime engine (`mmic sim --realtime`): real threads, OS pipes, TCP and UDP on
//! loopback, on the paced wall clock. Its own tests: the transports carry the demo over both
//! protocols and a lossy WiFi link, and it runs the same node code as the virtual-time engine
//! (`host/tests/sim.rs` and `host/tests/engine.rs` test the behaviour, in virtual time).

use mmic_host::sim::{engine, realtime, report, Protocol, SimConfig, Summary};
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

#[test]
fn the_demo_completes_over_real_transports_as_in_virtual_time() {
    for protocol in [Protocol::Legacy, Protocol::Pus] {
        let cfg = realtime_demo(protocol);
        let real = realtime::run(&cfg).unwrap();
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

#[test]
fn thirty_percent_wifi_loss_over_tcp_runs_nothing_twice() {
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
