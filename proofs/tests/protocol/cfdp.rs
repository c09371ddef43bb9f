//! CFDP class 2 (`mmic::cfdp::entity`), model-checked with stateright over the library's own
//! entities: the ground's entity sends a file to the robot's through a network that loses,
//! duplicates (at most [`Cfdp::dups`] copies in all) and reorders PDUs (at most
//! [`Cfdp::in_flight`] in flight each way), while either end may restart ([`Cfdp::restarts`] times in all) and
//! time passes in steps of [`STEP`] ms up to [`LIMIT`]. Every interleaving of sends,
//! deliveries, losses, copies, restarts and time steps is walked, breadth-first and
//! exhaustively; the file is [`FILES`]`[0]` (file data PDUs of two octets), the timers small
//! so that a transaction's whole life fits the bound (see [`config`]).
//!
//! A restart loses every transaction's state; the filestore and the next sequence number
//! (durable in the shell) survive, and the shell discards incoming files at boot. The ground's
//! shell then sends a corrected file, [`FILES`]`[1]`, under the same name: a new transaction.
//!
//! Checked:
//! - always: a file under its name at the robot is one the ground sent, octet for octet (a mix
//!   of the two would be an old transaction's data taken into a new one);
//! - always: the sender reports success only once its file is at the robot;
//! - always: a receiver's delivery is in the store (or a later transaction's file);
//! - always: no incoming (half-received) file is left without a receiver;
//! - always: once the link has been down long enough (from [`LIMIT`] every PDU sent is lost;
//!   at [`CAP`], nothing in flight), both ends have ended and reported (an end with a fault
//!   counts): no transaction waits for ever;
//! - sometimes: the file arrives; sometimes: both ends end with a fault.
//!
//! Walks (their bounds, counts, times and where each runs: spec/protocol/README.md, "CFDP"):
//! copies without restarts, restarts without copies, each in a small form that the README's
//! test command runs and a larger one that CI runs (`--ignored`), and by hand a restart with
//! reordering. The counts are written to spec/protocol/cfdp*.txt (checked fresh).
//!
//! At these bounds a late transaction never ends after a newer one to the same name: the
//! receiver's inactivity timer (30 ms) ends the old one first. The filestore's refusal of such
//! a late commit (`StoreError::Stale`) is checked by tests/ccsds/cfdp_edges.rs instead.

use super::{put, InFlight, Shared};
use mmic::cfdp::codes::ConditionCode;
use mmic::cfdp::entity::{Config, Entity, Event, Filestore, MemoryStore, Put};
use mmic::cfdp::header::Mode;
use stateright::{Checker, Model, Property};

/// The file, and the one the ground sends after a restart of its own (a corrected plan, under
/// the same name): a mix of the two at the robot would be an old transaction's data taken
/// into a new one.
const FILES: [&[u8]; 2] = [b"plan:A", b"plan:B"];
/// The same, shorter (two file data PDUs): the walk across restarts.
const SHORT: [&[u8]; 2] = [b"pl:A", b"pl:B"];
/// Its names.
const SOURCE: &[u8] = b"p";
const DEST: &[u8] = b"q";
/// Time step and bound, ms.
const STEP: u64 = 10;
const LIMIT: u64 = 100;
/// From [`LIMIT`] the link is down (what is in flight and every PDU sent is lost) and time
/// runs on to this bound: each end must then end by its timers.
const CAP: u64 = 200;

type Node = Entity<1, 4, 4>;
type Store = MemoryStore<3, 16>;
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
    restarts: u8,
    /// The ground's current transaction's end (since its last restart).
    sent: Option<ConditionCode>,
    /// The robot's last report since its last restart: condition, delivered, sequence number.
    received: Option<(ConditionCode, bool, u64)>,
    /// The transactions it reported since then (bit `seq`).
    reported: u8,
}

#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
enum Action {
    /// A PDU toward the robot (`true`) or the ground delivered, lost, copied.
    Deliver(bool, usize),
    Lose(bool, usize),
    Copy(bool, usize),
    Tick,
    /// The robot (`true`) or the ground restarts: every transaction's state is lost, the
    /// filestore and the next sequence number (kept durable by the shell) survive, and the
    /// shell discards incoming files at boot. The ground's shell then sends its second file.
    Restart(bool),
}

/// The walk's bounds.
#[derive(Clone, Copy)]
struct Cfdp {
    /// PDUs in flight each way at most.
    in_flight: usize,
    /// Copies the network makes in all.
    dups: u8,
    /// Restarts, of either end, in all.
    restarts: u8,
    /// The ground's file, and the one it sends once restarted.
    files: [&'static [u8]; 2],
    /// The page under spec/protocol/ the counts go to.
    page: &'static str,
}

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
                id,
                condition,
                delivered,
                ..
            } = e
            else {
                panic!("the robot sent: {e:?}")
            };
            let bit = 1u8 << id.seq;
            assert!(self.reported & bit == 0, "two events of one transaction");
            self.reported |= bit;
            self.received = Some((condition, delivered, id.seq));
        }
    }

    /// Each end sends what it has, as its shell does (polls until nothing is left); a PDU
    /// for a full link (`in_flight` PDUs), or sent once the link is down (from [`LIMIT`]), is
    /// lost. Then the ends' events are taken.
    fn settle(&mut self, in_flight: usize) {
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
                if self.link(up).len() < in_flight && now < LIMIT {
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

    /// The sequence number of the ground's current transaction.
    fn sending(&self) -> u64 {
        self.ground.0.next_seq() - 1
    }

    fn delivered(&self) -> Option<&[u8]> {
        self.robot.1.get(DEST)
    }

    /// The restarts of an end: a new entity over the durable filestore and sequence number.
    fn restart(&mut self, robot: bool, file: &[u8]) {
        self.restarts += 1;
        if robot {
            self.robot.update(|(node, store)| {
                *node = Node::new(config(0x42), node.next_seq());
                store.discard_all_incoming();
            });
            self.received = None;
            self.reported = 0;
        } else {
            self.ground.update(|(node, store)| {
                *node = Node::new(config(0x15), node.next_seq());
                store.discard_all_incoming();
                store.put(SOURCE, file).expect("fits");
                let put = Put::new(SOURCE, DEST, Mode::Acknowledged).expect("short names");
                node.put(self.now, 0x42, put, store).expect("room");
            });
            self.sent = None;
        }
    }
}

impl Model for Cfdp {
    type State = State;
    type Action = Action;

    fn init_states(&self) -> Vec<State> {
        let mut gs = Store::new();
        gs.put(SOURCE, self.files[0]).expect("fits");
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
            restarts: 0,
            sent: None,
            reported: 0,
            received: None,
        };
        s.settle(self.in_flight);
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
                if s.dups < self.dups && link.len() < self.in_flight {
                    actions.push(Action::Copy(up, k));
                }
            }
        }
        if s.now < CAP {
            actions.push(Action::Tick);
        }
        if s.restarts < self.restarts && s.now < LIMIT {
            actions.push(Action::Restart(true));
            actions.push(Action::Restart(false));
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
            Action::Restart(robot) => n.restart(robot, self.files[1]),
        }
        n.settle(self.in_flight);
        Some(n)
    }

    fn properties(&self) -> Vec<Property<Self>> {
        vec![
            Property::always(
                "a file at the robot is one the ground sent, whole",
                |m, s: &State| s.delivered().is_none_or(|d| m.files.contains(&d)),
            ),
            Property::always(
                "the sender's success means its file is there",
                |m, s: &State| {
                    s.sent != Some(ConditionCode::NoError)
                        || s.delivered() == Some(m.file_of(s.sending()))
                },
            ),
            Property::always(
                "a receiver's delivery is there, or a later one",
                |m, s: &State| match s.received {
                    Some((_, true, seq)) => s
                        .delivered()
                        .is_some_and(|d| d == m.file_of(seq) || d == m.files[1]),
                    _ => true,
                },
            ),
            Property::always("no incoming file without a receiver", |_, s: &State| {
                s.robot.0.active() > 0 || s.robot.1.incoming() == 0
            }),
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
                    && matches!(s.received, Some((c, false, _)) if c != ConditionCode::NoError)
            }),
        ]
    }
}

/// Copies: two PDUs in flight each way, one copy, a 4-octet file (two file data PDUs).
#[test]
fn cfdp_class2_over_a_lossy_link() {
    check(Cfdp {
        in_flight: 2,
        dups: 1,
        restarts: 0,
        files: SHORT,
        page: "cfdp.txt",
    })
}

/// The same with the 6-octet file (three file data PDUs: a gap between two received ones).
/// About 17 s: CI runs it (`.ci/run`, the tests step), the README's command does not.
#[test]
#[ignore = "about 17 s: CI runs it after the README's command (.ci/run)"]
fn cfdp_class2_over_a_lossy_link_three_pdus() {
    check(Cfdp {
        in_flight: 2,
        dups: 1,
        restarts: 0,
        files: FILES,
        page: "cfdp-three-pdus.txt",
    })
}

/// One restart of either end, one PDU in flight each way: a PDU of the old transaction may
/// still be in flight when the new one starts.
#[test]
fn cfdp_class2_across_restarts() {
    check(Cfdp {
        in_flight: 1,
        dups: 0,
        restarts: 1,
        files: FILES,
        page: "cfdp-restarts.txt",
    })
}

/// Two restarts (of either end, or one twice). About 6 s: CI runs it (`.ci/run`, the tests
/// step), the README's command does not.
#[test]
#[ignore = "about 6 s: CI runs it after the README's command (.ci/run)"]
fn cfdp_class2_across_two_restarts() {
    check(Cfdp {
        in_flight: 1,
        dups: 0,
        restarts: 2,
        files: FILES,
        page: "cfdp-two-restarts.txt",
    })
}

/// One restart with two PDUs in flight each way, so that the old transaction's PDUs and the
/// new one's overtake each other, with a shorter file (two file data PDUs): 28,306,601 states,
/// 459 s and 10.7 GB on one thread here (2026-11-29, beside other work), every property
/// holding. Too slow for the test command and CI; run it by hand:
/// `cargo test -p mmic-proofs --test protocol -- --ignored cfdp_class2_across_a_restart`.
#[test]
#[ignore = "8 minutes and 11 GB: run by hand (spec/protocol/README.md)"]
fn cfdp_class2_across_a_restart_reordered() {
    check(Cfdp {
        in_flight: 2,
        dups: 0,
        restarts: 1,
        files: SHORT,
        page: "cfdp-restarts-reordered.txt",
    })
}

/// Walks `model` whole, fails on any property's counterexample, and checks its section of
/// spec/protocol/cfdp.txt.
fn check(model: Cfdp) {
    let t0 = std::time::Instant::now();
    let mut builder = model.checker().threads(super::model_threads());
    if let Some(n) = std::env::var("CFDP_MODEL_STATES")
        .ok()
        .and_then(|n| n.parse().ok())
    {
        builder = builder.target_state_count(n);
    }
    let checker = builder.spawn_bfs().join();
    assert!(checker.is_done());
    let mut verdicts = String::new();
    for p in model.properties() {
        let found = checker.discovery(p.name);
        if let (stateright::Expectation::Always, Some(path)) = (&p.expectation, &found) {
            panic!(
                "{} violated:\n{:#?}\nlast state {:#?}",
                p.name,
                path.clone().into_actions(),
                path.last_state()
            );
        }
        let (kind, verdict) = match p.expectation {
            stateright::Expectation::Sometimes => {
                assert!(found.is_some(), "{}: not reachable", p.name);
                ("sometimes", "found")
            }
            _ => ("always", "holds"),
        };
        verdicts += &format!("  {:<66}{verdict}\n", format!("{kind}: {}", p.name));
    }
    let unique = checker.unique_state_count();
    eprintln!(
        "CFDP class 2 model {}: {unique} unique states in {:?}",
        model.page,
        t0.elapsed()
    );
    let text = format!(
        "{}\n{unique} unique states, breadth-first, exhaustive:\n{verdicts}",
        model.head()
    );
    let path = format!(
        "{}/../spec/protocol/{}",
        env!("CARGO_MANIFEST_DIR"),
        model.page
    );
    if std::env::var_os("MMIC_REGENERATE").is_some() {
        std::fs::write(&path, &text).expect("write the model's page");
    }
    assert_eq!(
        std::fs::read_to_string(&path).unwrap_or_default(),
        text,
        "stale: MMIC_REGENERATE=1 cargo test -p mmic-proofs --test protocol cfdp"
    );
}

impl Cfdp {
    /// The file of transaction `seq`: the first [`Cfdp::files`]`[0]`, the one a restarted
    /// ground sends `[1]`.
    fn file_of(&self, seq: u64) -> &'static [u8] {
        self.files[usize::from(seq != 1)]
    }

    /// The page's head: the walk's bounds.
    fn head(&self) -> String {
        let restarts = if self.restarts == 0 {
            "No restarts.".to_string()
        } else {
            format!(
                "Either end may restart (restarts in all: at most {}) before {LIMIT} ms:\n\
                 its transactions are lost, its filestore and next sequence number kept, incoming files\n\
                 discarded at boot; a restarted ground sends a corrected file of the same length under the same name.",
                self.restarts
            )
        };
        format!(
            "# CFDP class 2 over a lossy link, model-checked with stateright 0.31\n\
             # generated by proofs/tests/protocol/cfdp.rs; regenerate: MMIC_REGENERATE=1 cargo test -p mmic-proofs --test protocol cfdp\n\
             \n\
             the ground's entity (mmic::cfdp::entity::Entity) sends a {}-octet file in file data PDUs of 2 octets to the\n\
             robot's entity through a network that loses, reorders (PDUs in flight each way: at most {}) and\n\
             copies (copies in all: at most {}) PDUs, time in steps of {STEP} ms; from {LIMIT} ms the link is down (all in flight and all\n\
             sent is lost) and time runs to {CAP} ms. Each end sends all it has after every step (a PDU for a full link is\n\
             lost). ACK and NAK timers 10 ms, limits 2, inactivity 30 ms. {restarts}\n",
            self.files[0].len(),
            self.in_flight,
            self.dups
        )
    }
}
