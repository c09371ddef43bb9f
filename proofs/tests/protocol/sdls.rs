//! SDLS's anti-replay counters across restarts (`mmic::link::sdls::counter`), model-checked
//! with stateright over the library's own [`TxCounter`] (the ground, sending TC frames) and
//! [`ReplayWindow`] (the server board, receiving them), each with its durable store (one number,
//! the shell's file or flash): the shell starts a write of what `due` asks for, the write
//! becomes durable, then `persisted` confirms it; a crash-restart of either end loses its RAM
//! and keeps only the store, and a write in flight at the crash is either lost or became
//! durable (both are steps). Between them a network that loses and reorders frames (at most
//! [`MAX_IN_FLIGHT`] in flight), and an attacker who sends again, at any moment, any frame ever
//! sent (authentic: the MAC verifies; forging one is the cipher's business, not this model's);
//! a duplicate on the network is such a replay. A frame is its IV. The bounds keep the check
//! near 30 s in a debug build (1,977,882 states); the counters' own tests in
//! `tests/ccsds/sdls.rs` walk longer schedules of one end at a time.
//!
//! Checked, breadth-first and exhaustive within the bounds ([`MAX_FRAMES`] frames,
//! [`MAX_RESTARTS`] restarts of each end, block K = [`K`], window W = [`W`]):
//! - always: no IV is sent twice (across the sender's restarts);
//! - always: no IV is accepted twice (across the receiver's restarts);
//! - always: every accepted frame is one the sender sent;
//! - always: each end is within its durable number: the sender's reservation and the
//!   receiver's floor are exactly what its store holds;
//! - always (liveness from every state): if the faults stop (every write completes, frames
//!   arrive), the receiver accepts a frame the sender sends next within [`RECOVERY`] frames:
//!   neither end is ever left refusing the other for good;
//! - sometimes: a frame sent after both ends restarted (twice each) is accepted.
//!
//! With a window smaller than the sender's possible lead (W = [`SMALL_W`]) the liveness
//! property fails: frames lost in a row and restarts' skips put the sender more than W ahead,
//! and every frame it sends is then refused as too far ahead, for good. Three planted faults
//! show the safety properties can fail: a sender that forgets its store at a
//! restart reuses an IV; a receiver that does accepts a replay; a sender that uses a
//! reservation as soon as the write starts (before it is durable) reuses an IV when the write
//! is lost in a crash.
//!
//! The counts are written to spec/protocol/sdls-counters.txt (checked fresh).

use mmic::link::sdls::{Iv, ReplayWindow, TxCounter};
use stateright::{Checker, HasDiscoveries, Model, Property};

/// Frames the sender sends at most (first transmissions and retransmissions alike: each
/// takes a fresh IV).
const MAX_FRAMES: u8 = 4;
/// Crash-restarts of each end at most.
const MAX_RESTARTS: u8 = 2;
/// The reservation's block, both ends.
const K: u32 = 2;
/// The receiver's window: more than the sender can get ahead within the bounds
/// ([`MAX_FRAMES`] lost in a row, and each restart skipping at most a block and a half).
const W: u32 = 16;
/// The window of the liveness counterexample: smaller than that lead.
const SMALL_W: u32 = 4;
/// Frames in flight at most.
const MAX_IN_FLIGHT: usize = 2;
/// Frames a fault-free continuation may take to get one accepted: after a restart the
/// receiver's floor lies at most a window and two blocks beyond the last IV the sender used.
const RECOVERY: usize = 2 * W as usize;

/// A fault planted to show that the properties can fail.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Plant {
    None,
    /// The sender boots as a new association, ignoring its store.
    SenderForgets,
    /// The receiver boots as a new association, ignoring its store.
    ReceiverForgets,
    /// The sender confirms a reservation when the write starts, not when it is durable.
    SenderConfirmsEarly,
}

#[derive(Clone, Debug, PartialEq, Eq, Hash)]
struct State {
    tx: TxCounter,
    tx_store: Option<u128>,
    tx_pending: Option<u128>,
    tx_restarts: u8,
    /// The sender's first IV since its last restart.
    tx_epoch: u128,
    rx: ReplayWindow,
    rx_store: Option<u128>,
    rx_pending: Option<u128>,
    rx_restarts: u8,
    /// IVs in flight, sorted (a multiset: the network may deliver any of them first).
    net: Vec<u8>,
    /// IVs sent, accepted: bit i for IV i.
    sent: u64,
    accepted: u64,
    frames: u8,
    reused: bool,
    accepted_twice: bool,
    forged: bool,
    /// Since the receiver's last restart, a frame sent after the sender's last restart was
    /// accepted.
    fresh_accepted: bool,
}

#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
enum Action {
    Send,
    TxWrite,
    TxDurable,
    /// Crash and restart; `true`: the write in flight had become durable.
    TxCrash(bool),
    RxWrite,
    RxDurable,
    RxCrash(bool),
    Deliver(u8),
    Lose(u8),
    /// The attacker sends frame `iv` again.
    Replay(u8),
}

struct Counters {
    plant: Plant,
    /// The receiver's window.
    window: u32,
}

impl Counters {
    fn tx_boot(&self, store: Option<u128>) -> TxCounter {
        match self.plant {
            Plant::SenderForgets => TxCounter::boot(None, K),
            _ => TxCounter::boot(store, K),
        }
    }

    fn rx_boot(&self, store: Option<u128>) -> ReplayWindow {
        match self.plant {
            Plant::ReceiverForgets => ReplayWindow::boot(None, self.window, K),
            _ => ReplayWindow::boot(store, self.window, K),
        }
    }
}

impl State {
    /// The receiver takes an authentic frame: the window's check, the MAC (it verifies: the
    /// frame was sent), then admit.
    fn receive(&mut self, iv: u8) {
        if self.rx.admit(Iv::wrapping(u128::from(iv))).is_ok() {
            let bit = 1u64 << iv;
            self.accepted_twice |= self.accepted & bit != 0;
            self.forged |= self.sent & bit == 0;
            self.accepted |= bit;
            if self.tx_restarts > 0 && self.rx_restarts > 0 && u128::from(iv) >= self.tx_epoch {
                self.fresh_accepted = true;
            }
        }
    }

    /// The receiver's floor is what its store holds (none: nothing may be accepted).
    fn rx_within_store(&self) -> bool {
        match self.rx_store {
            None => self.rx.floor() == self.rx.last(),
            Some(v) => self.rx.floor() == Iv::wrapping(v),
        }
    }

    /// If the faults stop: every write started completes, the ends write what they are due
    /// and confirm it, and the sender's frames arrive one by one. Whether the receiver
    /// accepts one of them within [`RECOVERY`].
    fn recovers(&self) -> bool {
        let (mut tx, mut rx) = (self.tx.clone(), self.rx.clone());
        if let Some(v) = self.tx_pending {
            tx.persisted(v);
        }
        if let Some(v) = self.rx_pending {
            rx.persisted(v);
        }
        for _ in 0..RECOVERY {
            while let Some(v) = tx.due() {
                tx.persisted(v);
            }
            while let Some(v) = rx.due() {
                if !rx.persisted(v) {
                    break;
                }
            }
            let Ok(iv) = tx.take() else {
                return false;
            };
            match rx.admit(iv) {
                Ok(()) => return true,
                Err(e) if e.name() == "too-far-ahead" => return false,
                Err(_) => {}
            }
        }
        false
    }
}

impl Model for Counters {
    type State = State;
    type Action = Action;

    fn init_states(&self) -> Vec<State> {
        let tx = TxCounter::boot(None, K);
        vec![State {
            tx_epoch: tx.next(),
            tx,
            tx_store: None,
            tx_pending: None,
            tx_restarts: 0,
            rx: ReplayWindow::boot(None, self.window, K),
            rx_store: None,
            rx_pending: None,
            rx_restarts: 0,
            net: vec![],
            sent: 0,
            accepted: 0,
            frames: 0,
            reused: false,
            accepted_twice: false,
            forged: false,
            fresh_accepted: false,
        }]
    }

    fn actions(&self, s: &State, actions: &mut Vec<Action>) {
        if s.frames < MAX_FRAMES && s.net.len() < MAX_IN_FLIGHT && s.tx.next() < s.tx.reserved() {
            actions.push(Action::Send);
        }
        if s.tx_pending.is_none() && s.tx.due().is_some() {
            actions.push(Action::TxWrite);
        }
        if s.tx_pending.is_some() {
            actions.push(Action::TxDurable);
        }
        if s.tx_restarts < MAX_RESTARTS {
            actions.push(Action::TxCrash(false));
            if s.tx_pending.is_some() {
                actions.push(Action::TxCrash(true));
            }
        }
        if s.rx_pending.is_none() && s.rx.due().is_some() {
            actions.push(Action::RxWrite);
        }
        if s.rx_pending.is_some() {
            actions.push(Action::RxDurable);
        }
        if s.rx_restarts < MAX_RESTARTS {
            actions.push(Action::RxCrash(false));
            if s.rx_pending.is_some() {
                actions.push(Action::RxCrash(true));
            }
        }
        let mut seen = s.net.clone();
        seen.dedup();
        for iv in seen {
            actions.push(Action::Deliver(iv));
            actions.push(Action::Lose(iv));
        }
        for iv in 0..64u8 {
            if s.sent & (1 << iv) != 0 {
                actions.push(Action::Replay(iv));
            }
        }
    }

    fn next_state(&self, s: &State, a: Action) -> Option<State> {
        let mut n = s.clone();
        match a {
            Action::Send => {
                let iv = n.tx.take().ok()?.get();
                let iv = u8::try_from(iv).ok().filter(|iv| *iv < 64)?;
                let bit = 1u64 << iv;
                n.reused |= n.sent & bit != 0;
                n.sent |= bit;
                n.frames += 1;
                let at = n.net.partition_point(|x| *x <= iv);
                n.net.insert(at, iv);
            }
            Action::TxWrite => {
                let v = n.tx.due()?;
                n.tx_pending = Some(v);
                if self.plant == Plant::SenderConfirmsEarly {
                    n.tx.persisted(v);
                }
            }
            Action::TxDurable => {
                let v = n.tx_pending.take()?;
                n.tx_store = Some(v);
                n.tx.persisted(v);
            }
            Action::TxCrash(durable) => {
                if let (true, Some(v)) = (durable, n.tx_pending) {
                    n.tx_store = Some(v);
                }
                n.tx_pending = None;
                n.tx = self.tx_boot(n.tx_store);
                n.tx_epoch = n.tx.next();
                n.tx_restarts += 1;
                n.fresh_accepted = false;
            }
            Action::RxWrite => {
                n.rx_pending = Some(n.rx.due()?);
            }
            Action::RxDurable => {
                let v = n.rx_pending.take()?;
                n.rx_store = Some(v);
                n.rx.persisted(v);
            }
            Action::RxCrash(durable) => {
                if let (true, Some(v)) = (durable, n.rx_pending) {
                    n.rx_store = Some(v);
                }
                n.rx_pending = None;
                n.rx = self.rx_boot(n.rx_store);
                n.rx_restarts += 1;
                n.fresh_accepted = false;
            }
            Action::Deliver(iv) | Action::Lose(iv) => {
                let at = n.net.iter().position(|x| *x == iv)?;
                n.net.remove(at);
                if let Action::Deliver(_) = a {
                    n.receive(iv);
                }
            }
            Action::Replay(iv) => n.receive(iv),
        }
        Some(n)
    }

    fn properties(&self) -> Vec<Property<Self>> {
        vec![
            Property::always("no IV sent twice", |_, s: &State| !s.reused),
            Property::always("no IV accepted twice", |_, s: &State| !s.accepted_twice),
            Property::always("every accepted frame was sent", |_, s: &State| !s.forged),
            Property::always("each end within its durable number", |_, s: &State| {
                s.tx.reserved() <= s.tx_store.unwrap_or(0) && s.rx_within_store()
            }),
            Property::always(
                "with the faults stopped, a frame sent next is accepted",
                |_, s: &State| s.recovers(),
            ),
            Property::sometimes(
                "a frame sent after both ends restarted twice is accepted",
                |_, s: &State| {
                    s.tx_restarts == MAX_RESTARTS
                        && s.rx_restarts == MAX_RESTARTS
                        && s.fresh_accepted
                },
            ),
        ]
    }
}

struct Run {
    unique: usize,
    total: usize,
    depth: usize,
    discovered: Vec<(&'static str, bool)>,
    time: std::time::Duration,
}

/// One thread, breadth-first (the counts are then the same every run); with `until`, the
/// check stops at that property's first discovery (the planted faults' counterexamples).
fn run(plant: Plant, window: u32, until: Option<usize>) -> Run {
    let t0 = std::time::Instant::now();
    let m = Counters { plant, window };
    let names: Vec<&'static str> = m.properties().iter().map(|p| p.name).collect();
    let mut builder = m.checker().threads(1);
    if let Some(i) = until {
        builder = builder.finish_when(HasDiscoveries::AnyOf([names[i]].into()));
    }
    let checker = builder.spawn_bfs().join();
    assert!(checker.is_done());
    let discovered = names
        .iter()
        .map(|&p| (p, checker.discovery(p).is_some()))
        .collect();
    if plant == Plant::None && window == W {
        for p in &names[..5] {
            if let Some(path) = checker.discovery(p) {
                panic!(
                    "{p} violated:\n{:#?}\nlast state {:#?}",
                    path.clone().into_actions(),
                    path.last_state()
                );
            }
        }
    }
    Run {
        unique: checker.unique_state_count(),
        total: checker.state_count(),
        depth: checker.max_depth(),
        discovered,
        time: t0.elapsed(),
    }
}

#[test]
fn sdls_counters_across_restarts() {
    let a = run(Plant::None, W, None);
    for (p, found) in &a.discovered[..5] {
        assert!(!found, "{p} violated");
    }
    assert!(a.discovered[5].1, "{} is reachable", a.discovered[5].0);
    let forgets_tx = run(Plant::SenderForgets, W, Some(0));
    assert!(
        forgets_tx.discovered[0].1,
        "a sender without its store reuses an IV"
    );
    let forgets_rx = run(Plant::ReceiverForgets, W, Some(1));
    assert!(
        forgets_rx.discovered[1].1,
        "a receiver without its store accepts a replay"
    );
    let early = run(Plant::SenderConfirmsEarly, W, Some(0));
    assert!(
        early.discovered[0].1,
        "a reservation used before it is durable reuses an IV"
    );
    let small = run(Plant::None, SMALL_W, Some(4));
    assert!(
        small.discovered[4].1,
        "W = {SMALL_W}: a sender too far ahead is refused for good"
    );
    for (name, r) in [
        ("a", &a),
        ("b", &forgets_tx),
        ("c", &forgets_rx),
        ("d", &early),
        ("e", &small),
    ] {
        eprintln!(
            "SDLS counters model {name}: {} unique states ({} visited), depth {}, in {:?}",
            r.unique, r.total, r.depth, r.time
        );
    }
    let verdict = |r: &Run, i: usize| {
        if r.discovered[i].1 {
            "violated"
        } else {
            "holds"
        }
    };
    let text = format!(
        "# SDLS anti-replay counters across restarts, model-checked with stateright 0.31\n\
         # generated by proofs/tests/protocol/sdls.rs; regenerate: MMIC_REGENERATE=1 cargo test -p mmic-proofs --test protocol sdls\n\
         \n\
         sender (mmic::link::sdls::TxCounter, block K = {K}) with its durable store -> network losing and\n\
         reordering frames (at most {MAX_IN_FLIGHT} in flight) and an attacker sending any frame ever sent\n\
         again, at any moment (a duplicate is such a replay) -> receiver (mmic::link::sdls::ReplayWindow, W = {W}, block K = {K}) with its store.\n\
         At most {MAX_FRAMES} frames and {MAX_RESTARTS} crash-restarts of each end; a restart keeps only the store, and a\n\
         write in flight is lost or became durable. A frame is its IV (authentic: sent with the key).\n\
         \n\
         a) the library as it is: {} unique states ({} visited), depth {}, breadth-first, exhaustive:\n\
         \x20 always: no IV sent twice                                              {}\n\
         \x20 always: no IV accepted twice                                          {}\n\
         \x20 always: every accepted frame was sent                                 {}\n\
         \x20 always: each end within its durable number                            {}\n\
         \x20 always: with the faults stopped, a frame sent next is accepted (within {RECOVERY})  {}\n\
         \x20 sometimes: a frame sent after both ends restarted twice is accepted   {}\n\
         b) planted: the sender boots without its store: no IV sent twice violated\n\
         \x20  (found after {} unique states, depth {})\n\
         c) planted: the receiver boots without its store: no IV accepted twice violated\n\
         \x20  (found after {} unique states, depth {})\n\
         d) planted: the sender uses a reservation once its write starts: no IV sent twice\n\
         \x20  violated (found after {} unique states, depth {})\n\
         e) W = {SMALL_W}: with the faults stopped, a frame sent next is accepted: violated (found after\n\
         \x20  {} unique states, depth {}): the sender more than W ahead (its frames lost, restarts'\n\
         \x20  skips) is refused as too far ahead, for good\n",
        a.unique,
        a.total,
        a.depth,
        verdict(&a, 0),
        verdict(&a, 1),
        verdict(&a, 2),
        verdict(&a, 3),
        verdict(&a, 4),
        if a.discovered[5].1 { "found" } else { "not found" },
        forgets_tx.unique,
        forgets_tx.depth,
        forgets_rx.unique,
        forgets_rx.depth,
        early.unique,
        early.depth,
        small.unique,
        small.depth,
    );
    let path = concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../spec/protocol/sdls-counters.txt"
    );
    if std::env::var_os("MMIC_REGENERATE").is_some() {
        std::fs::write(path, &text).expect("write spec/protocol/sdls-counters.txt");
    }
    assert_eq!(
        std::fs::read_to_string(path).unwrap_or_default(),
        text,
        "stale: MMIC_REGENERATE=1 cargo test -p mmic-proofs --test protocol sdls"
    );
}
