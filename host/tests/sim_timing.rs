//! Section 8's timing decides (issue 39, item 3; decision `relay-visit-window`): the opsUI
//! sends every 1.2 s and counts an attempt failed when no heartbeat comes within 0.7 s, and
//! the paper's server board waits for the heartbeat as long as that window allows
//! (`relay::VISIT_MS`), so the 0.7 s is what decides, not the server's visit. Virtual time,
//! the demo plan, the legacy protocol (the paper's), the WiFi link's latency fixed each way.
//!
//! Until issue 39 the simulator's server waited 250 ms: a WiFi latency of 120 ms each way
//! answered 0 of 20 attempts, though each answer would have reached the opsUI in time.

use mmic::node::exactly_once::uplink::Efficiency;
use mmic::node::server::relay;
use mmic_host::sim::engine::{self, link::LinkModel};
use mmic_host::sim::{report, SimConfig, Summary};

/// The demo with `latency_ms` each way on the WiFi, and `jitter_ms` more at most.
fn demo_at(latency_ms: u64, jitter_ms: u64) -> Summary {
    let mut cfg = SimConfig::demo();
    cfg.progress = false;
    cfg.links.wifi = LinkModel {
        latency_us: latency_ms * 1000,
        jitter_us: jitter_ms * 1000,
        ..LinkModel::default()
    };
    engine::run(&cfg).unwrap()
}

// req: P3.7, D:relay-visit-window
#[test]
fn the_server_visits_as_long_as_the_opsui_window_allows() {
    assert_eq!(SimConfig::demo().visit_ms, relay::VISIT_MS);
    assert_eq!(
        relay::VISIT_MS + relay::SERIAL_RESERVE_MS,
        mmic::node::exactly_once::uplink::Config::default().timeout_ms
    );
}

/// Round trips as the opsUI measures them (command written to heartbeat read) from 250 ms to
/// 650 ms: every attempt answered, the demo completes.
// req: P8.3, P8.4
#[test]
fn every_attempt_is_answered_at_round_trips_from_250_to_650_ms() {
    let mut longest = Vec::new();
    for latency_ms in [120, 200, 260, 318] {
        let s = demo_at(latency_ms, 0);
        let text = report::text(&s);
        assert!(s.completed(), "{latency_ms} ms each way:\n{text}");
        assert_eq!(s.attempts.0, s.attempts.1, "{latency_ms} ms:\n{text}");
        assert!(s.attempts.1 > 100, "{latency_ms} ms: {:?}", s.attempts);
        // Two crossings of the WiFi at least, and within the opsUI's window.
        assert!(
            (2 * latency_ms as u32..=650).contains(&s.max_latency_ms),
            "{latency_ms} ms each way: longest answer {} ms",
            s.max_latency_ms
        );
        longest.push(s.max_latency_ms);
    }
    // The runs span the range the issue asks for.
    assert!(longest[0] <= 260 && longest[0] >= 250, "{longest:?}");
    assert!(*longest.last().unwrap() >= 640, "{longest:?}");
}

/// A WiFi round trip above 0.7 s: no heartbeat reaches the opsUI in time, and it counts every
/// attempt failed, resends until its limit and reports the command unacknowledged.
// req: P3.10, P8.4
#[test]
fn above_the_window_every_attempt_fails_as_section_8_counts_it() {
    for latency_ms in [360, 500] {
        let s = demo_at(latency_ms, 0);
        let text = report::text(&s);
        assert!(!s.completed(), "{latency_ms} ms:\n{text}");
        assert_eq!(s.attempts.0, 0, "{latency_ms} ms:\n{text}");
        assert_eq!(s.attempts.1, 20, "the simulator's 20 attempts:\n{text}");
        assert!(text.contains("unacknowledged"), "{text}");
        assert!(
            s.efficiency.iter().all(|&(_, e)| e == 0.0),
            "{:?}",
            s.efficiency
        );
    }
}

/// Figure 11's analogue is the opsUI's own count: with jitter that sends some answers past
/// 0.7 s, the efficiency after each attempt equals the share of answered attempts among the
/// last 100 in the log, and both kinds of attempt occur.
// req: P8.5
#[test]
fn the_efficiency_curve_is_the_moving_window_of_the_logged_attempts() {
    let s = demo_at(250, 220);
    let oks: Vec<bool> = s
        .records
        .iter()
        .filter(|r| r["event"]["type"] == "attempt" && r["event"]["robot"] == 1)
        .map(|r| r["event"]["ok"].as_bool().unwrap())
        .collect();
    assert_eq!(oks.len(), s.efficiency.len());
    assert!(
        oks.iter().any(|&ok| ok) && oks.iter().any(|&ok| !ok),
        "{oks:?}"
    );
    let window = Efficiency::WINDOW as usize;
    for (k, &(_, e)) in s.efficiency.iter().enumerate() {
        let last = &oks[(k + 1).saturating_sub(window)..=k];
        let ok = last.iter().filter(|&&o| o).count();
        let expected = ((ok * 100 + last.len() / 2) / last.len()) as f64;
        assert_eq!(e, expected, "after attempt {}", k + 1);
    }
}
