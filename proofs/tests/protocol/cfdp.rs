//! CFDP class 2 (`mmic::cfdp::entity`), model-checked with stateright over the library's own
//! entities: the ground's entity sends a file to the robot's through a network that loses,
//! duplicates (at most [`MAX_DUPS`] copies in all) and reorders PDUs (at most [`IN_FLIGHT`] in
//! flight each way), while time passes in steps of [`STEP`] ms up to [`LIMIT`]. Every
//! interleaving of sends, deliveries, losses, copies and time steps is walked, breadth-first
//! and exhaustively; the file is [`FILE`] (three file data PDUs of two octets), the timers
//! small so that a transaction's whole life fits the bound (see [`config`]).
//!
//! Checked:
//! - always: a file under its name at the robot is the ground's, octet for octet;
//! - always: the sender reports success only once the file is at the robot;
//! - always: the receiver's report says what its store holds (delivered, or no file);
//! - always: no incoming (half-received) file is left once the receiver has ended;
//! - always: once the link has been down long enough (from [`LIMIT`] every PDU sent is lost;
//!   at [`CAP`], nothing in flight), both ends have ended and reported (an end with a fault
//!   counts): no transaction waits for ever;
//! - sometimes: the file arrives; sometimes: both ends end with a fault.
//!
//! The counts are written to spec/protocol/cfdp.txt (checked fresh).

use super::{put, InFlight, Shared};
use mmic::cfdp::codes::ConditionCode;
use mmic::cfdp::entity::{Config, Entity, Event, MemoryStore, Put};
use mmic::cfdp::header::Mode;
use stateright::{Checker, Model, Property};

/// The file.
const FILE: &[u8] = b"plan:A";
/// Its names.
const SOURCE: &[u8] = b"p";
const DEST: &[u8] = b"q";
/// Time step and bound, ms.
const STEP: u64 = 10;
const LIMIT: u64 = 100;
/// From [`LIMIT`] the link is down (what is in flight and every PDU sent is lost) and time
/// runs on to this bound: each end must then end by its timers.
const CAP: u64 = 200;
/// PDUs in flight each way at most.
const IN_FLIGHT: usize = 2;
/// Copies the network makes in all.
const MAX_DUPS: u8 = 1;

type Node = Entity<1, 4, 4>;
type Store = MemoryStore<2, 16>;
type Pdu = heapless::Vec<u8, 64>;

/// Small timers: a transaction's life is bounded by about 130 ms (four rounds of progress of
/// two NAKs each, two Finished PDUs, the sender's inactivity), under [`LIMIT`].
fn config(local: u64) -> Config {
    Config {
        file_data: 2,
        ack_timeout_ms: 10,
        ack_limit: 2,
        nak_timeout_ms: 10,
        nak_limit: 2,
        inactivity_ms: 30,
        ..Config::mission(local)
    }
}

#[derive(Clone, Debug, PartialEq, Eq, Hash)]
struct State {
    now: u64,
    ground: Shared<(Node, Store)>,
    robot: Shared<(Node, Store)>,
    up: InFlight<Pdu>,
    down: InFlight<Pdu>,
    dups: u8,
    sent: Option<ConditionCode>,
    received: Option<(ConditionCode, bool)>,
}

#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
enum Action {
    /// A PDU toward the robot (`true`) or the ground delivered, lost, copied.
    Deliver(bool, usize),
    Lose(bool, usize),
    Copy(bool, usize),
    Tick,
}

struct Cfdp;

impl State {
    fn link(&self, up: bool) -> &InFlight<Pdu> {
        if up {
            &self.up
        } else {
            &self.down
        }
    }

    fn link_mut(&mut self, up: bool) -> &mut InFlight<Pdu> {
        if up {
            &mut self.up
        } else {
            &mut self.down
        }
    }

    /// Moves each end's events into the record (each reports once: a second is a bug).
    fn take_events(&mut self) {
        if let Some(e) = self.ground.update(|(n, _)| n.take_event()) {
            let Event::Sent { condition, .. } = e else {
                panic!("the ground received: {e:?}")
            };
            assert!(self.sent.replace(condition).is_none(), "two events");
        }
        if let Some(e) = self.robot.update(|(n, _)| n.take_event()) {
            let Event::Received {
                condition,
                delivered,
                ..
            } = e
            else {
                panic!("the robot sent: {e:?}")
            };
            assert!(
                self.received.replace((condition, delivered)).is_none(),
                "two events"
            );
        }
    }

    /// Each end sends what it has, as its shell does (polls until nothing is left); a PDU
    /// for a full link, or sent once the link is down (from [`LIMIT`]), is lost. Then the
    /// ends' events are taken.
    fn settle(&mut self) {
        let mut buf = [0u8; 512];
        let now = self.now;
        for up in [true, false] {
            loop {
                let end = if up {
                    &mut self.ground
                } else {
                    &mut self.robot
                };
                let Some(len) = end.update(|(node, store)| node.poll(now, store, &mut buf)) else {
                    break;
                };
                let pdu = Pdu::from_slice(&buf[..len]).expect("small PDUs");
                if self.link(up).len() < IN_FLIGHT && now < LIMIT {
                    put(self.link_mut(up), pdu);
                }
            }
        }
        self.take_events();
    }

    /// Whether nothing can happen any more without time: nothing in flight (the ends have
    /// sent all they had: [`State::settle`]).
    fn quiescent(&self) -> bool {
        self.up.is_empty() && self.down.is_empty()
    }

    fn delivered(&self) -> Option<&[u8]> {
        self.robot.1.get(DEST)
    }
}

impl Model for Cfdp {
    type State = State;
    type Action = Action;

    fn init_states(&self) -> Vec<State> {
        let mut gs = Store::new();
        gs.put(SOURCE, FILE).expect("fits");
        let mut ground = Node::new(config(0x15), 1);
        let put = Put::new(SOURCE, DEST, Mode::Acknowledged).expect("short names");
        ground.put(0, 0x42, put, &mut gs).expect("room");
        let mut s = State {
            now: 0,
            ground: Shared::new((ground, gs)),
            robot: Shared::new((Node::new(config(0x42), 1), Store::new())),
            up: InFlight::new(),
            down: InFlight::new(),
            dups: 0,
            sent: None,
            received: None,
        };
        s.settle();
        vec![s]
    }

    fn actions(&self, s: &State, actions: &mut Vec<Action>) {
        for up in [true, false] {
            let link = s.link(up);
            for (k, p) in link.iter().enumerate() {
                if k > 0 && link[k - 1] == *p {
                    continue; // the same PDU twice: one choice
                }
                actions.push(Action::Deliver(up, k));
                actions.push(Action::Lose(up, k));
                if s.dups < MAX_DUPS && link.len() < IN_FLIGHT {
                    actions.push(Action::Copy(up, k));
                }
            }
        }
        if s.now < CAP {
            actions.push(Action::Tick);
        }
    }

    fn next_state(&self, s: &State, a: Action) -> Option<State> {
        let mut n = s.clone();
        let now = s.now;
        match a {
            Action::Deliver(up, k) => {
                let pdu = n.link_mut(up).remove(k);
                let end = if up { &mut n.robot } else { &mut n.ground };
                // Refusals (late PDUs of an ended transaction) change nothing but a counter.
                let _ = end.update(|(node, store)| node.handle(now, &pdu, store));
            }
            Action::Lose(up, k) => {
                n.link_mut(up).remove(k);
            }
            Action::Copy(up, k) => {
                let pdu = n.link(up)[k].clone();
                put(n.link_mut(up), pdu);
                n.dups += 1;
            }
            Action::Tick => {
                n.now += STEP;
                if n.now >= LIMIT {
                    // The link goes down: what is in flight is lost too.
                    n.up.clear();
                    n.down.clear();
                }
            }
        }
        n.settle();
        Some(n)
    }

    fn properties(&self) -> Vec<Property<Self>> {
        vec![
            Property::always("a file at the robot is the ground's", |_, s: &State| {
                s.delivered().is_none_or(|d| d == FILE)
            }),
            Property::always(
                "the sender's success means the file is there",
                |_, s: &State| s.sent != Some(ConditionCode::NoError) || s.delivered().is_some(),
            ),
            Property::always(
                "the receiver's report says what it holds",
                |_, s: &State| {
                    s.received
                        .is_none_or(|(_, delivered)| delivered == s.delivered().is_some())
                },
            ),
            Property::always(
                "no incoming file left once the receiver ended",
                |_, s: &State| s.received.is_none() || s.robot.1.incoming() == 0,
            ),
            Property::always(
                "with the link down, both ends end and report",
                |_, s: &State| {
                    !(s.now == CAP && s.quiescent())
                        || (s.sent.is_some()
                            && s.ground.0.active() == 0
                            && s.robot.0.active() == 0
                            && (s.received.is_some() || s.robot.0.counters() == Default::default()))
                },
            ),
            Property::sometimes("the file arrives", |_, s: &State| s.delivered().is_some()),
            Property::sometimes("both ends end with a fault", |_, s: &State| {
                matches!(s.sent, Some(c) if c != ConditionCode::NoError)
                    && matches!(s.received, Some((c, false)) if c != ConditionCode::NoError)
            }),
        ]
    }
}

#[test]
fn cfdp_class2_over_a_lossy_link() {
    let t0 = std::time::Instant::now();
    let mut builder = Cfdp.checker().threads(super::model_threads());
    if let Some(n) = std::env::var("CFDP_MODEL_STATES")
        .ok()
        .and_then(|n| n.parse().ok())
    {
        builder = builder.target_state_count(n);
    }
    let checker = builder.spawn_bfs().join();
    eprintln!(
        "{} unique, depth {}",
        checker.unique_state_count(),
        checker.max_depth()
    );
    assert!(checker.is_done());
    let names: Vec<&'static str> = Cfdp.properties().iter().map(|p| p.name).collect();
    for p in &names[..5] {
        if let Some(path) = checker.discovery(p) {
            panic!(
                "{p} violated:\n{:#?}\nlast state {:#?}",
                path.clone().into_actions(),
                path.last_state()
            );
        }
    }
    for p in &names[5..] {
        assert!(checker.discovery(p).is_some(), "{p}: not reachable");
    }
    let (unique, depth) = (checker.unique_state_count(), checker.max_depth());
    eprintln!(
        "CFDP class 2 model: {unique} unique states, depth {depth}, in {:?}",
        t0.elapsed()
    );
    let text = format!(
        "# CFDP class 2 over a lossy link, model-checked with stateright 0.31\n\
         # generated by proofs/tests/protocol/cfdp.rs; regenerate: MMIC_REGENERATE=1 cargo test -p mmic-proofs --test protocol cfdp\n\
         \n\
         the ground's entity (mmic::cfdp::entity::Entity) sends a {}-octet file in file data PDUs of 2 octets to the\n\
         robot's entity through a network that loses, reorders (at most {IN_FLIGHT} PDUs in flight each way) and copies\n\
         (at most {MAX_DUPS} copy) PDUs, time in steps of {STEP} ms; from {LIMIT} ms the link is down (all in flight\n\
         and all sent is lost) and time runs to {CAP} ms. Each end sends all it has after every step (a PDU for a\n\
         full link is lost). ACK and NAK timers 10 ms, limits 2, inactivity 30 ms.\n\
         \n\
         {unique} unique states, breadth-first, exhaustive:\n\
         \x20 always: a file at the robot is the ground's                     holds\n\
         \x20 always: the sender's success means the file is there            holds\n\
         \x20 always: the receiver's report says what it holds                holds\n\
         \x20 always: no incoming file left once the receiver ended           holds\n\
         \x20 always: with the link down, both ends end and report            holds\n\
         \x20 sometimes: the file arrives                                     found\n\
         \x20 sometimes: both ends end with a fault                           found\n",
        FILE.len()
    );
    let path = concat!(env!("CARGO_MANIFEST_DIR"), "/../spec/protocol/cfdp.txt");
    if std::env::var_os("MMIC_REGENERATE").is_some() {
        std::fs::write(path, &text).expect("write spec/protocol/cfdp.txt");
    }
    assert_eq!(
        std::fs::read_to_string(path).unwrap_or_default(),
        text,
        "stale: MMIC_REGENERATE=1 cargo test -p mmic-proofs --test protocol cfdp"
    );
}
