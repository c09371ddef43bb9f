//! Exactly-once commanding over PUS, model-checked with stateright over the real library
//! nodes: a ground that sends PUS telecommands and may send one again (same request key), a
//! ground ↔ server-board link that loses, duplicates and reorders telecommands and reports,
//! the server board's PUS gateway ([`Gateway`], over the legacy uplink), the legacy WiFi link
//! (losing, duplicating, reordering), and board A ([`BoardA`], the real tick).
//!
//! Checked, breadth-first and exhaustive within the bounds: no telecommand executed twice; a
//! telecommand reported started (or completed) ran exactly once; one reported failed at start
//! did not run, unless the failure says "unacknowledged" (ran once or not at all); every
//! telecommand ends, at the gateway, in a final report (on every path); the ground never
//! holds two different final reports for one telecommand. The counts are written to
//! spec/protocol/pus-exactly-once.txt (checked fresh).

use mmic::command::Command;
use mmic::mode::Mode;
use mmic::node::exactly_once::uplink;
use mmic::node::robot::board_a::{self, BoardA};
use mmic::node::server::gateway::{Config, Gateway, Tc};
use mmic::pus::request::Request;
use mmic::pus::verification::{Report, RequestId, Stage, UNACKNOWLEDGED};
use mmic::units::BoardNumber;
use mmic::wire::command::COMMAND_LEN;
use mmic::wire::heartbeat::{HeartbeatRepr, HEARTBEAT_LEN};
use stateright::{Checker, Model, Property};

/// The telecommands: two non-idempotent commands.
const TCS: [Command; 2] = [Command::Mode(Mode::Operational), Command::Stop];
const APID: u16 = 0x101;
/// Packets in flight per link at most.
const MAX_IN_FLIGHT: usize = 2;
/// Duplications over all links.
const MAX_DUPLICATES: u8 = 1;

/// A packet on either link (the ground link carries telecommands and final reports, the
/// WiFi link legacy commands and heartbeats).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
enum Packet {
    Tc(u8),
    Report(u8, Final),
    Command([u8; COMMAND_LEN]),
    Heartbeat([u8; HEARTBEAT_LEN]),
}

/// How a telecommand ended, as its last ST[1] report says.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
enum Final {
    Completed,
    Refused,
    Unacknowledged,
}

#[derive(Clone, Debug, PartialEq, Eq, Hash)]
struct State {
    g: super::Shared<Gateway<1, 4, 8>>,
    now: u32,
    sent: usize,
    resent: u8,
    up: super::InFlight<Packet>,
    down: super::InFlight<Packet>,
    wifi: super::InFlight<Packet>,
    duplicates: u8,
    a: super::Shared<BoardA>,
    a_now: u32,
    /// Executions per telecommand (board A's `Executed` for its legacy number).
    executed: [u8; TCS.len()],
    /// The legacy number each telecommand went out under.
    seq_of: [Option<u16>; TCS.len()],
    /// Final report made by the gateway, per telecommand.
    made: [Option<Final>; TCS.len()],
    /// Started (start success) reported by the gateway.
    started: [bool; TCS.len()],
    /// Final reports the ground received.
    got: [Option<Final>; TCS.len()],
    conflict: bool,
}

#[derive(Clone, Debug, PartialEq, Eq, Hash)]
enum Action {
    /// The ground sends its next telecommand.
    Send,
    /// The ground sends an earlier telecommand again (same key).
    Resend(u8),
    /// Time passes to the gateway's next deadline.
    Advance,
    Deliver(Packet),
    Drop(Packet),
    Duplicate(Packet),
}

struct PusModel;

fn tc(i: u8) -> Tc {
    Tc {
        request: RequestId {
            apid: APID,
            seq_count: u16::from(i) + 1,
        },
        source_id: 1,
        ack: 0b1111,
        request_of: Ok(Request::Function(TCS[usize::from(i)])),
    }
}

impl PusModel {
    /// The gateway's output: legacy commands onto the WiFi link, final reports downlink.
    fn out(&self, n: &mut State, out: mmic::node::server::gateway::Out<16>) {
        for (_, c) in out.to_robots {
            if let Some(i) = TCS.iter().position(|t| *t == c.command) {
                n.seq_of[i] = Some(c.seq);
            }
            if n.wifi.len() < MAX_IN_FLIGHT {
                super::put(&mut n.wifi, Packet::Command(c.to_bytes()));
            }
        }
        for tm in out.reports {
            let Ok(r) = Report::parse(tm.subservice, &tm.data) else {
                continue;
            };
            let Some(i) = usize::from(r.request.seq_count)
                .checked_sub(1)
                .filter(|&i| i < TCS.len())
            else {
                continue;
            };
            let fin = match (r.stage, r.failure) {
                (Stage::Start, None) => {
                    n.started[i] = true;
                    None
                }
                (Stage::Completion, None) => Some(Final::Completed),
                (_, Some(f)) if f.code == UNACKNOWLEDGED => Some(Final::Unacknowledged),
                (_, Some(_)) => Some(Final::Refused),
                _ => None,
            };
            if let Some(f) = fin {
                n.conflict |= n.made[i].is_some_and(|m| m != f);
                n.made[i] = Some(f);
                if n.down.len() < MAX_IN_FLIGHT {
                    super::put(&mut n.down, Packet::Report(i as u8, f));
                }
            }
        }
    }
}

impl Model for PusModel {
    type State = State;
    type Action = Action;

    fn init_states(&self) -> Vec<State> {
        let cfg = Config {
            uplink: uplink::Config {
                max_attempts: 3,
                ..Config::default().uplink
            },
            poll_ms: 0,
            hk_enabled: false,
            ..Config::default()
        };
        let mut g = Gateway::new(cfg);
        g.add(BoardNumber::ONE);
        // The model starts once board A's first heartbeat reached the gateway (power-up: Standby,
        // nothing run), which the gateway waits for before it forwards a telecommand (that hold
        // is tests/pus/gateway.rs, `telecommands_wait_for_board_as_first_heartbeat`).
        g.heartbeat(
            0,
            &HeartbeatRepr {
                board: BoardNumber::ONE,
                mode: Mode::Standby,
                ..HeartbeatRepr::default()
            },
        );
        vec![State {
            g: super::Shared::new(g),
            now: 0,
            sent: 0,
            resent: 0,
            up: super::InFlight::new(),
            down: super::InFlight::new(),
            wifi: super::InFlight::new(),
            duplicates: 0,
            a: super::Shared::new(BoardA::new(board_a::Config::default())),
            a_now: 0,
            executed: [0; TCS.len()],
            seq_of: [None; TCS.len()],
            made: [None; TCS.len()],
            started: [false; TCS.len()],
            got: [None; TCS.len()],
            conflict: false,
        }]
    }

    fn actions(&self, s: &State, actions: &mut Vec<Action>) {
        if s.sent < TCS.len() && s.up.len() < MAX_IN_FLIGHT {
            actions.push(Action::Send);
        }
        if s.resent == 0 && s.up.len() < MAX_IN_FLIGHT {
            for i in 0..s.sent {
                actions.push(Action::Resend(i as u8));
            }
        }
        if s.g.next_deadline(s.now).is_some() {
            actions.push(Action::Advance);
        }
        for link in [&s.up, &s.down, &s.wifi] {
            for p in super::distinct(link) {
                actions.push(Action::Deliver(p));
                actions.push(Action::Drop(p));
                if s.duplicates < MAX_DUPLICATES && link.len() < MAX_IN_FLIGHT {
                    actions.push(Action::Duplicate(p));
                }
            }
        }
    }

    fn next_state(&self, s: &State, a: Action) -> Option<State> {
        let mut n = s.clone();
        match a {
            Action::Send => {
                super::put(&mut n.up, Packet::Tc(n.sent as u8));
                n.sent += 1;
            }
            Action::Resend(i) => {
                super::put(&mut n.up, Packet::Tc(i));
                n.resent += 1;
            }
            Action::Advance => {
                let t = n.g.next_deadline(n.now)?;
                n.now = t.max(n.now);
                let now = n.now;
                let out = n.g.update(|g| g.tick(now));
                self.out(&mut n, out);
            }
            Action::Deliver(p) | Action::Drop(p) => {
                let v = match p {
                    Packet::Tc(_) => &mut n.up,
                    Packet::Report(..) => &mut n.down,
                    _ => &mut n.wifi,
                };
                let i = v.iter().position(|x| *x == p)?;
                v.remove(i);
                if matches!(a, Action::Deliver(_)) {
                    match p {
                        Packet::Tc(i) => {
                            let out = n.g.update(|g| g.tc(&tc(i)));
                            self.out(&mut n, out);
                        }
                        Packet::Report(i, f) => {
                            let i = usize::from(i);
                            n.conflict |= n.got[i].is_some_and(|g| g != f);
                            n.got[i] = Some(f);
                        }
                        Packet::Command(bytes) => {
                            let (executed, seq_of) = (&mut n.executed, &n.seq_of);
                            let a_now = &mut n.a_now;
                            let hb = n.a.update(|a| {
                                super::board_a_takes(a, a_now, bytes, |seq| {
                                    if let Some(i) = seq_of.iter().position(|s| *s == Some(seq)) {
                                        executed[i] = executed[i].saturating_add(1);
                                    }
                                })
                            });
                            if let Some(hb) = hb {
                                if n.wifi.len() < MAX_IN_FLIGHT {
                                    super::put(&mut n.wifi, Packet::Heartbeat(hb));
                                }
                            }
                        }
                        Packet::Heartbeat(bytes) => {
                            let hb = HeartbeatRepr::parse(&bytes).ok()?;
                            let now = n.now;
                            let out = n.g.update(|g| g.heartbeat(now, &hb));
                            self.out(&mut n, out);
                        }
                    }
                }
            }
            Action::Duplicate(p) => {
                let v = match p {
                    Packet::Tc(_) => &mut n.up,
                    Packet::Report(..) => &mut n.down,
                    _ => &mut n.wifi,
                };
                super::put(v, p);
                n.duplicates += 1;
            }
        }
        Some(n)
    }

    fn properties(&self) -> Vec<Property<Self>> {
        vec![
            Property::always("no telecommand executed twice", |_, s: &State| {
                s.executed.iter().all(|&e| e <= 1)
            }),
            Property::always(
                "a telecommand reported started or completed ran exactly once",
                |_, s: &State| {
                    (0..TCS.len()).all(|i| {
                        !(s.started[i] || s.made[i] == Some(Final::Completed)) || s.executed[i] == 1
                    })
                },
            ),
            Property::always("one refused at start did not run", |_, s: &State| {
                (0..TCS.len()).all(|i| s.made[i] != Some(Final::Refused) || s.executed[i] == 0)
            }),
            Property::always(
                "no telecommand has two different final reports",
                |_, s: &State| !s.conflict,
            ),
            Property::eventually(
                "every telecommand the gateway took ends in a final report",
                |_, s: &State| {
                    s.sent == TCS.len()
                        && s.up.is_empty()
                        && s.g.next_deadline(s.now).is_none()
                        && (0..TCS.len()).all(|i| s.made[i].is_some() || s.seq_of[i].is_none())
                },
            ),
            Property::sometimes(
                "every telecommand completed and known on the ground",
                |_, s: &State| s.got.iter().all(|g| *g == Some(Final::Completed)),
            ),
            Property::sometimes(
                "a resent telecommand suppressed after it ran",
                |_, s: &State| s.resent > 0 && s.executed.contains(&1) && s.up.is_empty(),
            ),
        ]
    }
}

#[test]
fn pus_exactly_once() {
    let t0 = std::time::Instant::now();
    // A violation ends the search at once (and fails below, with its path).
    let checker = PusModel
        .checker()
        .threads(crate::model_threads())
        .finish_when(stateright::HasDiscoveries::AnyFailures)
        .spawn_bfs()
        .join();
    for p in [
        "no telecommand executed twice",
        "a telecommand reported started or completed ran exactly once",
        "one refused at start did not run",
        "no telecommand has two different final reports",
        "every telecommand the gateway took ends in a final report",
    ] {
        if let Some(path) = checker.discovery(p) {
            panic!("{p} violated:\n{:#?}", path.into_actions());
        }
    }
    for p in [
        "every telecommand completed and known on the ground",
        "a resent telecommand suppressed after it ran",
    ] {
        assert!(checker.discovery(p).is_some(), "{p} is reachable");
    }
    assert!(checker.is_done());
    let (unique, total) = (checker.unique_state_count(), checker.state_count());
    eprintln!("PUS model: {unique} unique states in {:?}", t0.elapsed());
    let text = format!(
        "# Exactly-once commanding over PUS, model-checked with stateright 0.31\n\
         # generated by proofs/tests/protocol/protocol_pus.rs; regenerate: MMIC_REGENERATE=1 cargo test -p mmic-proofs --test protocol pus_exactly_once\n\
         \n\
         ground (sends each TC once, may send one again with the same key) <-> server board:\n\
         a link losing, reordering and duplicating TCs and final ST[1] reports; the PUS gateway\n\
         (node::server::gateway, legacy uplink with 3 attempts); the WiFi link losing, reordering and\n\
         duplicating legacy packets; BoardA. At most {MAX_IN_FLIGHT} packets in flight per link,\n\
         {MAX_DUPLICATES} duplication in all. Telecommands {TCS:?}\n\
         {unique} unique states ({total} visited), breadth-first, exhaustive:\n\
         \x20 always: no telecommand executed twice                                holds\n\
         \x20 always: a telecommand reported started or completed ran exactly once  holds\n\
         \x20 always: one refused at start did not run                             holds\n\
         \x20 always: no telecommand has two different final reports               holds\n\
         \x20 eventually: every telecommand the gateway took ends in a final report holds\n\
         \x20 sometimes: every telecommand completed and known on the ground; a resent telecommand\n\
         \x20   suppressed after it ran: found\n"
    );
    let path = concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../spec/protocol/pus-exactly-once.txt"
    );
    if std::env::var_os("MMIC_REGENERATE").is_some() {
        std::fs::write(path, &text).expect("write spec/protocol/pus-exactly-once.txt");
    }
    assert_eq!(
        std::fs::read_to_string(path).unwrap_or_default(),
        text,
        "stale: MMIC_REGENERATE=1 cargo test -p mmic-proofs --test protocol pus_exactly_once"
    );
}
