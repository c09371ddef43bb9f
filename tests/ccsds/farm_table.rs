//! FARM-1 against its state table, cell by cell: `spec/ccsds/farm-1.toml` (232.1-B-2 Table 6-1
//! as transcribed) is the oracle. For each window W in {2, 10, 20, 254}, each V(R) 0..=255, each
//! state with each value of its flags (Retransmit; Wait where the state allows both; FARM-B
//! counter 0 and 3, so its wrap is seen) and each event (an AD frame for every N(S) with and
//! without a buffer, BD, Unlock, Set V(R) to every value, an invalid frame, a buffer release),
//! the verdict and the variables after the step are those the table's cell gives for the event
//! class the oracle computes from (N(S) − V(R)) mod 256 and PW = NW = W/2. The starting states
//! are built with `Farm::restore`; `every_restored_state_is_reachable` shows each of them is
//! reached from `Farm::new` by legal steps.

use mmic::link::clcw::{ClcwVcid, FarmBCounter};
use mmic::link::farm::{
    DiscardReason, EventId, Farm, FarmEvent, FarmState, FarmStatus, FarmWindow, Verdict,
};
use mmic::link::ControlCommand;
use serde::Deserialize;
use std::collections::{BTreeMap, BTreeSet, VecDeque};
use std::path::PathBuf;
use std::time::Instant;

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct Table {
    event: Vec<Event>,
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct Event {
    id: String,
    condition: String,
    #[serde(rename = "S1")]
    s1: Cell,
    #[serde(rename = "S2")]
    s2: Cell,
    #[serde(rename = "S3")]
    s3: Cell,
}

#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
struct Cell {
    actions: Vec<String>,
    verdict: String,
    next: String,
    #[serde(rename = "ref")]
    reference: String,
}

fn table() -> BTreeMap<(String, &'static str), Cell> {
    let p = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("spec/ccsds/farm-1.toml");
    let text = std::fs::read_to_string(&p).unwrap_or_else(|e| panic!("{}: {e}", p.display()));
    let t: Table = toml::from_str(&text).unwrap_or_else(|e| panic!("{}: {e}", p.display()));
    let mut cells = BTreeMap::new();
    for e in t.event {
        assert!(!e.condition.is_empty() && !e.s1.reference.is_empty());
        for (s, c) in [("S1", e.s1), ("S2", e.s2), ("S3", e.s3)] {
            assert!(
                cells.insert((e.id.clone(), s), c).is_none(),
                "{} twice",
                e.id
            );
        }
    }
    let ids: BTreeSet<String> = cells.keys().map(|(id, _)| id.clone()).collect();
    let expected: BTreeSet<String> = EventId::ALL.iter().map(|e| e.name().to_string()).collect();
    assert_eq!(ids, expected, "the table's events are E1..E10");
    cells
}

fn state_name(s: FarmState) -> &'static str {
    match s {
        FarmState::Open => "S1",
        FarmState::Wait => "S2",
        FarmState::Lockout => "S3",
    }
}

fn state_of(name: &str) -> FarmState {
    match name {
        "S1" => FarmState::Open,
        "S2" => FarmState::Wait,
        "S3" => FarmState::Lockout,
        other => panic!("unknown state {other}"),
    }
}

/// The event class, from the definitions of Table 6-1, independent of the library's window
/// code: d = (N(S) − V(R)) mod 256; E3 for 1 ≤ d ≤ PW − 1, E4 for 256 − NW ≤ d ≤ 255.
fn oracle_class(w: u8, vr: u8, ev: FarmEvent) -> &'static str {
    let (pw, nw) = (w as u32 / 2, w as u32 / 2);
    match ev {
        FarmEvent::Ad { ns, buffer_ready } => {
            let d = (ns as u32 + 256 - vr as u32) % 256;
            if d == 0 {
                if buffer_ready {
                    "E1"
                } else {
                    "E2"
                }
            } else if d < pw {
                "E3"
            } else if d >= 256 - nw {
                "E4"
            } else {
                "E5"
            }
        }
        FarmEvent::Bd => "E6",
        FarmEvent::Bc(ControlCommand::Unlock) => "E7",
        FarmEvent::Bc(ControlCommand::SetVr(_)) => "E8",
        FarmEvent::Invalid => "E9",
        FarmEvent::BufferRelease => "E10",
    }
}

/// The variables as the table speaks of them.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
struct Vars {
    state: FarmState,
    vr: u8,
    retransmit: bool,
    wait: bool,
    lockout: bool,
    farm_b: u8,
}

fn apply(cell: &Cell, mut v: Vars, ev: FarmEvent) -> Vars {
    for a in &cell.actions {
        match a.as_str() {
            "vr+1" => v.vr = v.vr.wrapping_add(1),
            "vr=v*" => match ev {
                FarmEvent::Bc(ControlCommand::SetVr(x)) => v.vr = x,
                _ => panic!("vr=v* on {ev:?}"),
            },
            "retransmit=0" => v.retransmit = false,
            "retransmit=1" => v.retransmit = true,
            "wait=0" => v.wait = false,
            "wait=1" => v.wait = true,
            "lockout=0" => v.lockout = false,
            "lockout=1" => v.lockout = true,
            "farm-b+1" => v.farm_b = (v.farm_b + 1) % 4,
            other => panic!("unknown action {other}"),
        }
    }
    v.state = state_of(&cell.next);
    v
}

fn verdict_name(v: Verdict) -> String {
    match v {
        Verdict::Accept => "accept".into(),
        Verdict::Discard(r) => format!("discard:{}", r.name()),
        Verdict::Control { executed: true, .. } => "control".into(),
        Verdict::Control {
            executed: false, ..
        } => "control-not-executed".into(),
        Verdict::Released => "released".into(),
    }
}

/// Every state with every value of its flags the table can reach: Wait 0 in S1, 1 in S2, free
/// in S3; Retransmit free but 1 with Wait; FARM-B counter 0 and 3.
fn starting_statuses(vr: u8) -> Vec<FarmStatus> {
    let mut out = Vec::new();
    for (state, waits) in [
        (FarmState::Open, &[false][..]),
        (FarmState::Wait, &[true][..]),
        (FarmState::Lockout, &[false, true][..]),
    ] {
        for &wait in waits {
            // The Wait flag comes with the Retransmit flag (FarmStatus::is_consistent).
            for retransmit in [false, true].into_iter().filter(|r| *r || !wait) {
                for b in [0u8, 3] {
                    out.push(FarmStatus {
                        state,
                        vr,
                        retransmit,
                        wait,
                        farm_b: FarmBCounter::new(b).unwrap(),
                    });
                }
            }
        }
    }
    out
}

fn events() -> Vec<FarmEvent> {
    let mut out = Vec::new();
    for ns in 0..=255u8 {
        for buffer_ready in [true, false] {
            out.push(FarmEvent::Ad { ns, buffer_ready });
        }
        out.push(FarmEvent::Bc(ControlCommand::SetVr(ns)));
    }
    out.extend([
        FarmEvent::Bd,
        FarmEvent::Bc(ControlCommand::Unlock),
        FarmEvent::Invalid,
        FarmEvent::BufferRelease,
    ]);
    out
}

// req: 232.1-B-2/FARM-1, 232.1-B-2/FARM-2, 232.1-B-2/FARM-3, 232.1-B-2/FARM-5, 232.1-B-2/FARM-6
// req: 232.1-B-2/FARM-7, 232.1-B-2/FARM-8, 232.1-B-2/FARM-9
#[test]
#[cfg_attr(
    miri,
    ignore = "9.5 million cells: days under Miri (the unit tests of link::farm run)"
)]
fn farm_follows_table_6_1_cell_by_cell() {
    let cells = table();
    let events = events();
    let start = Instant::now();
    let mut checked = 0u64;
    let mut seen: BTreeSet<(String, &'static str)> = BTreeSet::new();
    for w in [2u8, 10, 20, 254] {
        let window = FarmWindow::new(w).unwrap();
        for vr in 0..=255u8 {
            for status in starting_statuses(vr) {
                let before = Farm::restore(window, status).expect("consistent");
                for &ev in &events {
                    let class = oracle_class(w, vr, ev);
                    let sname = state_name(status.state);
                    let cell = &cells[&(class.to_string(), sname)];
                    let vars = Vars {
                        state: status.state,
                        vr,
                        retransmit: status.retransmit,
                        wait: status.wait,
                        lockout: status.state == FarmState::Lockout,
                        farm_b: status.farm_b.get(),
                    };
                    let want = apply(cell, vars, ev);
                    let mut farm = before.clone();
                    assert_eq!(farm.classify(ev).name(), class, "W={w} {status:?} {ev:?}");
                    let verdict = farm.step(ev);
                    let ctx = || format!("W={w} {status:?} {ev:?} ({class}/{sname})");
                    assert_eq!(verdict_name(verdict), cell.verdict, "{}", ctx());
                    if let (Verdict::Control { command, .. }, FarmEvent::Bc(c)) = (verdict, ev) {
                        assert_eq!(command, c, "{}", ctx());
                    }
                    let after = farm.status();
                    let clcw = farm.clcw(ClcwVcid::ZERO, false, false);
                    let got = Vars {
                        state: after.state,
                        vr: after.vr,
                        retransmit: after.retransmit,
                        wait: after.wait,
                        lockout: clcw.lockout,
                        farm_b: after.farm_b.get(),
                    };
                    assert_eq!(got, want, "{}", ctx());
                    // The CLCW reports the variables (232.1-B-2 §6.2.4).
                    assert_eq!(
                        (
                            clcw.wait,
                            clcw.retransmit,
                            clcw.report_value,
                            clcw.farm_b_counter
                        ),
                        (after.wait, after.retransmit, after.vr, after.farm_b),
                        "{}",
                        ctx()
                    );
                    // Exactly one counter moved (none for a buffer release).
                    let (c0, c1) = (before.counters(), farm.counters());
                    let total = |c: &mmic::link::farm::FarmCounters| {
                        c.accepted_ad as u64
                            + c.accepted_bd as u64
                            + c.control as u64
                            + c.discarded.iter().map(|&n| n as u64).sum::<u64>()
                    };
                    let moved = total(c1) - total(c0);
                    assert_eq!(moved, (cell.verdict != "released") as u64, "{}", ctx());
                    if let Verdict::Discard(r) = verdict {
                        assert_eq!(c1.discarded(r), 1, "{}", ctx());
                    }
                    seen.insert((class.to_string(), sname));
                    checked += 1;
                }
            }
        }
    }
    // Every cell of the table was exercised.
    assert_eq!(seen.len(), cells.len(), "cells never reached: {:?}", {
        let all: BTreeSet<_> = cells.keys().cloned().collect();
        all.difference(&seen).cloned().collect::<Vec<_>>()
    });
    assert_eq!(checked, 4 * 256 * 12 * (256 * 3 + 4));
    eprintln!(
        "farm table: {checked} cells checked ({} table cells) in {:.2?}",
        cells.len(),
        start.elapsed()
    );
}

/// Every status `farm_follows_table_6_1_cell_by_cell` starts from is reachable from
/// `Farm::new` by legal events (breadth-first over the whole variable space, W = 20), and no
/// inconsistent one is.
#[test]
#[cfg_attr(miri, ignore = "4.7 million FARM-1 steps: hours under Miri")]
fn every_restored_state_is_reachable() {
    let window = FarmWindow::MISSION;
    let mut seen = BTreeSet::new();
    let mut queue = VecDeque::from([Farm::new(window)]);
    seen.insert(Farm::new(window).status());
    let evs = events();
    while let Some(f) = queue.pop_front() {
        for &ev in &evs {
            let mut g = f.clone();
            g.step(ev);
            let s = g.status();
            assert!(s.is_consistent(), "{s:?}");
            if seen.insert(s) {
                queue.push_back(Farm::restore(window, s).unwrap());
            }
        }
    }
    let mut want = BTreeSet::new();
    for vr in 0..=255u8 {
        for s in starting_statuses(vr) {
            for b in 0..4 {
                want.insert(FarmStatus {
                    farm_b: FarmBCounter::new(b).unwrap(),
                    ..s
                });
            }
        }
    }
    assert_eq!(seen, want);
    // A reason for every discard cell; none unused.
    let cells = table();
    let reasons: BTreeSet<&str> = cells
        .values()
        .filter_map(|c| c.verdict.strip_prefix("discard:"))
        .collect();
    let all: BTreeSet<&str> = DiscardReason::ALL.iter().map(|r| r.name()).collect();
    assert_eq!(reasons, all);
}
