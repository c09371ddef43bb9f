//! COP-1 (CCSDS 232.1-B-2), model-checked with stateright over the library's FOP-1
//! ([`Fop`], the ground) and FARM-1 ([`Farm`], the robot): three packets sent as AD frames
//! over a TC link that loses, duplicates and reorders frames, FARM-1's CLCWs back over a TM link
//! that loses and duplicates them (in order: CLCWs ride in TM frames, which a physical channel
//! does not reorder; FOP-1 alerts "NN(R)" on a CLCW older than one it has seen, by design), the
//! FARM's buffer busy once (Wait, then a buffer release), and T1's expiry as a step of its own.
//!
//! Timing is abstracted to two assumptions, both true of the mission's parameters (T1 = 3 s,
//! a CLCW in every TM frame, at least one every 500 ms): T1 expires only when nothing is in
//! flight (T1 exceeds the round trip), and FARM-1 reports its CLCW after every frame and
//! buffer release, and once more on its own when the ground waits with T1 stopped (FOP-1 in
//! Retransmit with Wait ignores T1; only a CLCW brings it out). Two starts: FOP-1 initiated
//! without CLCW against a fresh FARM-1, and FOP-1 initiating with Unlock against a FARM-1 in
//! Lockout (the BC frame lost, duplicated and reordered like the others).
//!
//! Checked, breadth-first and exhaustive within the bounds:
//! - always: the data FARM-1 accepts is a prefix of the data sent, in order, no duplicate;
//! - always: FOP-1 raises no alert, with the smallest transmission limit for which that holds
//!   (searched from 2 up; the one below alerts);
//! - eventually: every packet accepted by FARM-1 and confirmed to the ground. Stateright checks
//!   an `eventually` property on every path to a terminal state (no action enabled); the model
//!   has no cycle (`assert_acyclic` walks the whole graph depth-first to show it: every step
//!   consumes a fault or report budget, a packet, a transmission count, or moves V(R), NN(R)
//!   or a frame along), so every maximal path ends in a terminal state and the property covers
//!   them all;
//! - with the BC frame duplicated as well, a late Unlock clears FARM-1's flags and FOP-1
//!   alerts "SYNCH" (the data stream stays safe);
//! - with FOP-1 as Table 5-1 is written (`restart_t1_after_wait` false), the eventually
//!   property fails: a frame FARM-1 discarded ahead of a gap is never sent again.
//!
//! The counts are written to spec/protocol/cop1.txt (checked fresh).

use mmic::link::clcw::{Clcw, ClcwVcid};
use mmic::link::farm::{Farm, FarmEvent, FarmState, FarmStatus, FarmWindow, Verdict};
use mmic::link::fop::{Directive, Fop, FopConfig, FopOutput, FopState, FrameData, TimeoutType};
use mmic::link::{ControlCommand, FrameKind};
use stateright::{Checker, Model, Property};

/// Packets the ground sends.
const N: u8 = 3;
/// FOP-1's window K and sent queue.
const K: usize = 2;
/// Frames in flight on the TC link at most; CLCWs on the TM link at most.
const MAX_UP: usize = 3;
const MAX_DOWN: usize = 2;
/// Fault budgets over a whole run.
const MAX_LOSSES: u8 = 3;
const MAX_DUPLICATES: u8 = 1;
const MAX_BUSY: u8 = 1;
/// FARM-1's own reports while the ground waits with T1 stopped: one more than the losses,
/// so that one gets through (a CLCW in every TM frame, for ever, in the real link).
const MAX_REPORTS: u8 = MAX_LOSSES + 1;
/// FARM-1's window (the mission's, W = 20).
const WINDOW: FarmWindow = FarmWindow::MISSION;

#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
enum Up {
    Ad(u8, u8),
    Bc(ControlCommand),
}

#[derive(Clone, Debug, PartialEq, Eq, Hash)]
struct State {
    fop: Fop<u8, K>,
    farm: FarmStatus,
    submitted: u8,
    up: Vec<Up>,
    down: Vec<Clcw>,
    losses: u8,
    duplicates: u8,
    busy: u8,
    reports: u8,
    delivered: Vec<u8>,
    confirmed: u8,
    alerts: u8,
    initiated: bool,
}

#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
enum Action {
    Submit,
    Deliver(Up),
    DeliverBusy(Up),
    Drop(Up),
    Duplicate(Up),
    DeliverClcw,
    DropClcw,
    DuplicateClcw,
    Expire,
    Release,
    Report,
}

struct Cop1 {
    tx_limit: u8,
    /// Whether the TC link may duplicate the BC frame too (a late Unlock clears FARM-1's
    /// flags: FOP-1 then alerts "SYNCH").
    duplicate_bc: bool,
    /// FOP-1's `restart_t1_after_wait` (false: Table 5-1 as written).
    restart_t1_after_wait: bool,
}

fn put(v: &mut Vec<Up>, f: Up) {
    let i = v.partition_point(|x| *x <= f);
    v.insert(i, f);
}

impl State {
    /// FOP-1's outputs: frames onto the TC link (the transition is cut, as beyond the
    /// bounds, if the link is full), confirmations and alerts counted.
    fn fop_out(&mut self, outs: Vec<FopOutput<u8>>) -> Option<()> {
        for o in outs {
            match o {
                FopOutput::Transmit(f) => {
                    let up = match (f.kind, f.data) {
                        (FrameKind::Ad, FrameData::Fdu(p)) => Up::Ad(f.ns, p),
                        (FrameKind::Bc, FrameData::Control(c)) => Up::Bc(c),
                        _ => return None,
                    };
                    if self.up.len() >= MAX_UP {
                        return None;
                    }
                    put(&mut self.up, up);
                }
                FopOutput::Confirmed { .. } => self.confirmed += 1,
                FopOutput::Alert(_) => self.alerts += 1,
                FopOutput::InitiateConfirmed => self.initiated = true,
                _ => {}
            }
        }
        Some(())
    }

    /// FARM-1 reports: its CLCW onto the TM link. With the link full the newest CLCW takes
    /// the last one's place (a TM frame carries the CLCW of the moment it is sent, and YAMCS
    /// processes only the latest CLCW it holds), so a full link loses no news.
    fn report(&mut self) {
        let farm = Farm::restore(WINDOW, self.farm).expect("consistent");
        let clcw = farm.clcw(ClcwVcid::ZERO, false, false);
        if self.down.len() < MAX_DOWN {
            self.down.push(clcw);
        } else if let Some(last) = self.down.last_mut() {
            *last = clcw;
        }
    }

    /// FARM-1 takes `ev`; `carrying` is the packet of an AD frame.
    fn farm_step(&mut self, ev: FarmEvent, carrying: Option<u8>) {
        let mut farm = Farm::restore(WINDOW, self.farm).expect("consistent");
        let v = farm.step(ev);
        if let (Verdict::Accept, FarmEvent::Ad { .. }) = (v, ev) {
            // The FDU of the accepted frame: the packet the frame carried.
            if let Some(p) = carrying {
                self.delivered.push(p);
            }
        }
        self.farm = farm.status();
        self.report();
    }
}

impl Model for Cop1 {
    type State = State;
    type Action = Action;

    fn init_states(&self) -> Vec<State> {
        let config = FopConfig {
            window: K as u8,
            t1_ms: 1000,
            tx_limit: self.tx_limit,
            timeout_type: TimeoutType::Alert,
            restart_t1_after_wait: self.restart_t1_after_wait,
        };
        let blank = |fop, farm| State {
            fop,
            farm,
            submitted: 0,
            up: vec![],
            down: vec![],
            losses: 0,
            duplicates: 0,
            busy: 0,
            reports: 0,
            delivered: vec![],
            confirmed: 0,
            alerts: 0,
            initiated: false,
        };
        // 1: initiate without CLCW, FARM-1 fresh.
        let mut fop = Fop::new(config);
        fop.directive(Directive::InitiateWithoutClcw, 0, &mut |_| {});
        let s1 = blank(fop, Farm::new(WINDOW).status());
        // 2: FARM-1 in Lockout; initiate with Unlock (the BC frame on the link).
        let mut fop = Fop::new(config);
        let mut outs = Vec::new();
        fop.directive(Directive::InitiateWithUnlock, 0, &mut |o| outs.push(o));
        let mut s2 = blank(
            fop,
            FarmStatus {
                state: FarmState::Lockout,
                ..FarmStatus::default()
            },
        );
        s2.fop_out(outs).expect("room for the BC frame");
        vec![s1, s2]
    }

    fn actions(&self, s: &State, actions: &mut Vec<Action>) {
        if s.submitted < N {
            actions.push(Action::Submit);
        }
        let mut seen = s.up.clone();
        seen.dedup();
        for f in seen {
            actions.push(Action::Deliver(f));
            if s.busy < MAX_BUSY && matches!(f, Up::Ad(..)) {
                actions.push(Action::DeliverBusy(f));
            }
            if s.losses < MAX_LOSSES {
                actions.push(Action::Drop(f));
            }
            if s.duplicates < MAX_DUPLICATES
                && s.up.len() < MAX_UP
                && (self.duplicate_bc || matches!(f, Up::Ad(..)))
            {
                actions.push(Action::Duplicate(f));
            }
        }
        if !s.down.is_empty() {
            actions.push(Action::DeliverClcw);
            if s.losses < MAX_LOSSES {
                actions.push(Action::DropClcw);
            }
            if s.duplicates < MAX_DUPLICATES && s.down.len() < MAX_DOWN {
                actions.push(Action::DuplicateClcw);
            }
        }
        let quiet = s.up.is_empty() && s.down.is_empty();
        if quiet && s.fop.timer_deadline().is_some() {
            actions.push(Action::Expire);
        }
        if s.farm.wait {
            actions.push(Action::Release);
        }
        if quiet
            && s.fop.timer_deadline().is_none()
            && !s.farm.wait
            && s.fop.sent_len() > 0
            && s.reports < MAX_REPORTS
        {
            actions.push(Action::Report);
        }
    }

    fn next_state(&self, s: &State, a: Action) -> Option<State> {
        let mut n = s.clone();
        let mut outs = Vec::new();
        match a {
            Action::Submit => {
                n.fop
                    .transfer_ad(n.submitted, 0, &mut |o| outs.push(o))
                    .ok()?;
                n.submitted += 1;
            }
            Action::Deliver(f) | Action::DeliverBusy(f) | Action::Drop(f) => {
                let i = n.up.iter().position(|x| *x == f)?;
                n.up.remove(i);
                match a {
                    Action::Drop(_) => n.losses += 1,
                    _ => {
                        let buffer_ready = !matches!(a, Action::DeliverBusy(_));
                        if !buffer_ready {
                            n.busy += 1;
                        }
                        let (ev, p) = match f {
                            Up::Ad(ns, p) => (FarmEvent::Ad { ns, buffer_ready }, Some(p)),
                            Up::Bc(c) => (FarmEvent::Bc(c), None),
                        };
                        n.farm_step(ev, p);
                    }
                }
            }
            Action::Duplicate(f) => {
                put(&mut n.up, f);
                n.duplicates += 1;
            }
            Action::DeliverClcw => {
                let c = n.down.remove(0);
                n.fop.clcw(&c, 0, &mut |o| outs.push(o));
            }
            Action::DropClcw => {
                n.down.remove(0);
                n.losses += 1;
            }
            Action::DuplicateClcw => {
                let c = *n.down.first()?;
                n.down.insert(0, c);
                n.duplicates += 1;
            }
            Action::Expire => n.fop.expire_timer(0, &mut |o| outs.push(o)),
            Action::Release => n.farm_step(FarmEvent::BufferRelease, None),
            Action::Report => {
                n.reports += 1;
                n.report();
            }
        }
        n.fop_out(outs)?;
        Some(n)
    }

    fn properties(&self) -> Vec<Property<Self>> {
        vec![
            Property::always(
                "FARM-accepted data is a prefix of the sent data, in order, once",
                |_, s: &State| {
                    s.delivered
                        .iter()
                        .enumerate()
                        .all(|(i, p)| *p as usize == i)
                },
            ),
            Property::always("FOP-1 raises no alert", |_, s: &State| s.alerts == 0),
            Property::eventually(
                "every packet accepted by FARM-1 and confirmed to the ground",
                |_, s: &State| s.delivered.len() == N as usize && s.confirmed == N,
            ),
            Property::sometimes("FOP-1 in Retransmit with Wait", |_, s: &State| {
                s.fop.state() == FopState::RetransmitWithWait
            }),
            Property::sometimes(
                "all delivered, copies still in flight, after a loss",
                |_, s: &State| s.losses > 0 && s.delivered.len() == N as usize && s.up.len() > 1,
            ),
            Property::sometimes("the Unlock start confirmed", |_, s: &State| s.initiated),
        ]
    }
}

/// Counts of one exhaustive run and which properties have a discovery (a violation for
/// `always`/`eventually`, an example for `sometimes`).
struct Run {
    unique: usize,
    total: usize,
    depth: usize,
    discovered: Vec<(&'static str, bool)>,
    time: std::time::Duration,
}

/// One thread: the depth stateright reports is then the same every run (with two threads it
/// varies by one).
fn run(m: Cop1) -> Run {
    let t0 = std::time::Instant::now();
    let names: Vec<&'static str> = m.properties().iter().map(|p| p.name).collect();
    let checker = m.checker().threads(1).spawn_bfs().join();
    assert!(checker.is_done());
    let discovered = names
        .iter()
        .map(|&p| (p, checker.discovery(p).is_some()))
        .collect();
    if std::env::var_os("COP1_TRACE").is_some() {
        for p in &names[1..3] {
            if let Some(path) = checker.discovery(p) {
                eprintln!("{p}: last state {:?}", path.last_state());
                eprintln!("{p}: {:?}", path.into_actions());
            }
        }
    }
    if let Some(path) = checker.discovery(names[0]) {
        panic!("{} violated:\n{:#?}", names[0], path.into_actions());
    }
    Run {
        unique: checker.unique_state_count(),
        total: checker.state_count(),
        depth: checker.max_depth(),
        discovered,
        time: t0.elapsed(),
    }
}

/// Depth-first over the whole reachable graph: no state reaches itself.
fn assert_acyclic(m: &Cop1) -> usize {
    use std::collections::HashMap;
    #[derive(PartialEq)]
    enum Mark {
        OnPath,
        Done,
    }
    let mut mark: HashMap<State, Mark> = HashMap::new();
    for init in m.init_states() {
        if mark.contains_key(&init) {
            continue;
        }
        // Each frame: a state and the successors still to visit.
        let mut stack: Vec<(State, Vec<State>)> = Vec::new();
        let succ = |s: &State| {
            let mut acts = Vec::new();
            m.actions(s, &mut acts);
            acts.into_iter()
                .filter_map(|a| m.next_state(s, a))
                .collect::<Vec<_>>()
        };
        mark.insert(init.clone(), Mark::OnPath);
        let next = succ(&init);
        stack.push((init, next));
        while let Some((s, rest)) = stack.last_mut() {
            match rest.pop() {
                Some(n) => match mark.get(&n) {
                    Some(Mark::OnPath) => panic!("cycle through {n:?}"),
                    Some(Mark::Done) => {}
                    None => {
                        mark.insert(n.clone(), Mark::OnPath);
                        let next = succ(&n);
                        stack.push((n, next));
                    }
                },
                None => {
                    let s = s.clone();
                    mark.insert(s, Mark::Done);
                    stack.pop();
                }
            }
        }
    }
    mark.len()
}

#[test]
fn cop1() {
    // The smallest transmission limit with no alert (the BC frame not duplicated): found by
    // trying 2, 3, …; the one below it alerts.
    let model = |tx_limit, duplicate_bc, restart_t1_after_wait| Cop1 {
        tx_limit,
        duplicate_bc,
        restart_t1_after_wait,
    };
    let mut limit = 2u8;
    let mut below = run(model(1, false, true));
    let a = loop {
        let r = run(model(limit, false, true));
        if !r.discovered[1].1 {
            break r;
        }
        below = r;
        limit += 1;
        assert!(limit <= 16, "FOP-1 alerts with every limit tried");
    };
    let c = below;
    assert!(
        c.discovered[1].1,
        "an alert is reachable with limit {}",
        limit - 1
    );
    // At that limit: safety and liveness hold; the three situations are reached.
    for (p, found) in &a.discovered[..3] {
        assert!(!found, "{p} violated");
    }
    for (p, found) in &a.discovered[3..] {
        assert!(found, "{p} is reachable");
    }
    let walked = assert_acyclic(&model(limit, false, true));
    assert_eq!(
        walked, a.unique,
        "the depth-first walk sees the states the checker saw"
    );
    // The BC frame duplicated too: the data stream stays safe, a late Unlock alerts.
    let b = run(model(limit, true, true));
    assert!(b.discovered[1].1, "a late Unlock alerts SYNCH");
    // Table 5-1 as written (T1 not restarted after Wait): a frame left unsent for good.
    let d = run(model(limit, false, false));
    assert!(!d.discovered[1].1, "no alert without T1 after Wait");
    assert!(
        d.discovered[2].1,
        "a frame left unsent without T1 after Wait"
    );
    for (name, r) in [("a", &a), ("b", &b), ("c", &c), ("d", &d)] {
        eprintln!(
            "COP-1 model {name}: {} unique states ({} visited), depth {}, in {:?}",
            r.unique, r.total, r.depth, r.time
        );
    }
    let text = format!(
        "# COP-1 (CCSDS 232.1-B-2), model-checked with stateright 0.31\n\
         # generated by proofs/tests/protocol/cop1.rs; regenerate: MMIC_REGENERATE=1 cargo test -p mmic-proofs --test protocol cop1\n\
         \n\
         ground FOP-1 (mmic::link::fop::Fop, window K = {K}) -> TC link losing, duplicating and\n\
         reordering frames (at most {MAX_UP} in flight) -> FARM-1 (mmic::link::farm::Farm, W = 20) ->\n\
         CLCWs on a TM link losing and duplicating them, in order (at most {MAX_DOWN}) -> FOP-1.\n\
         {N} packets; at most {MAX_LOSSES} losses and {MAX_DUPLICATES} duplication in all; FARM-1's buffer busy\n\
         {MAX_BUSY} time; T1 expires only with nothing in flight; FARM-1 reports after every frame and\n\
         buffer release, and on its own (at most {MAX_REPORTS} times) while T1 is stopped. Two starts:\n\
         initiate without CLCW (FARM-1 fresh), initiate with Unlock (FARM-1 in Lockout).\n\
         The model has no cycle (walked depth-first for a)), so `eventually` is checked on every\n\
         maximal path.\n\
         \n\
         a) transmission limit {limit} (the smallest with no alert), BC frame not duplicated:\n\
         {} unique states ({} visited), depth {}, breadth-first, exhaustive:\n\
         \x20 always: FARM-accepted data is a prefix of the sent data, in order, once   holds\n\
         \x20 always: FOP-1 raises no alert                                            holds\n\
         \x20 eventually: every packet accepted by FARM-1 and confirmed to the ground  holds\n\
         \x20 sometimes: FOP-1 in Retransmit with Wait; all delivered, copies still in flight,\n\
         \x20   after a loss; the Unlock start confirmed: found\n\
         b) transmission limit {limit}, the BC frame duplicated too (a late Unlock clears FARM-1's flags):\n\
         {} unique states ({} visited), depth {}:\n\
         \x20 always: FARM-accepted data is a prefix of the sent data, in order, once   holds\n\
         \x20 always: FOP-1 raises no alert                                            violated (SYNCH)\n\
         c) transmission limit {}, BC frame not duplicated:\n\
         {} unique states ({} visited), depth {}:\n\
         \x20 always: FARM-accepted data is a prefix of the sent data, in order, once   holds\n\
         \x20 always: FOP-1 raises no alert                                            violated\n\
         d) as a), but FOP-1 as Table 5-1 is written (restart_t1_after_wait false: T1's expiry in\n\
         \x20  Retransmit with Wait stops T1, and leaving it by E6 starts nothing):\n\
         {} unique states ({} visited), depth {}:\n\
         \x20 always: FARM-accepted data is a prefix of the sent data, in order, once   holds\n\
         \x20 always: FOP-1 raises no alert                                            holds\n\
         \x20 eventually: every packet accepted by FARM-1 and confirmed to the ground  violated\n\
         \x20   (a frame FARM-1 discarded ahead of a gap is never sent again)\n",
        a.unique, a.total, a.depth, b.unique, b.total, b.depth, limit - 1, c.unique, c.total, c.depth,
        d.unique, d.total, d.depth
    );
    let path = concat!(env!("CARGO_MANIFEST_DIR"), "/../spec/protocol/cop1.txt");
    if std::env::var_os("MMIC_REGENERATE").is_some() {
        std::fs::write(path, &text).expect("write spec/protocol/cop1.txt");
    }
    assert_eq!(
        std::fs::read_to_string(path).unwrap_or_default(),
        text,
        "stale: MMIC_REGENERATE=1 cargo test -p mmic-proofs --test protocol cop1"
    );
}
