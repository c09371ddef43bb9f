//! The paper's commanding scheme, model-checked with stateright (issue 6, first half of item 2):
//! the opsUI sends a command through the server and resends it until a heartbeat comes back
//! (Section 3). Over a WiFi link that loses, duplicates and reorders packets, a command whose
//! heartbeat is lost is executed twice. This test asserts that stateright finds exactly that
//! counterexample and writes the traces to spec/protocol/paper-counterexample.txt.
//!
//! Model: two non-idempotent commands (say, two primitives). The opsUI ↔ server serial line is
//! reliable; the server ↔ board A WiFi link is a bounded multiset of in-flight packets (at most
//! 3), duplicating or not. The robot executes every command packet it receives and
//! answers each with a heartbeat, which — as in Table 3 — does not say which command it answers.
//! The opsUI resends on timeout, at most 3 sends per command.

use stateright::{Checker, Model, Property};

const COMMANDS: u8 = 2;
const MAX_SENDS: u8 = 3;
const MAX_IN_FLIGHT: usize = 3;

#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
enum Packet {
    /// Server → robot: a command packet (the command's index).
    Command(u8),
    /// Robot → server: a heartbeat (carries no command identity).
    Heartbeat,
}

#[derive(Clone, Debug, PartialEq, Eq, Hash)]
struct State {
    /// Next command the opsUI will send (all sent and acknowledged when = COMMANDS).
    ops_next: u8,
    /// The opsUI is waiting for a heartbeat for `ops_next`.
    ops_waiting: bool,
    /// Sends of the current command.
    sends: u8,
    /// The server's "command byte": pending until it reaches the link.
    server_pending: Option<u8>,
    /// In flight on the WiFi link (sorted: a multiset).
    wifi: Vec<Packet>,
    duplicates: u8,
    /// How often the robot executed each command.
    executed: [u8; COMMANDS as usize],
}

#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
enum Action {
    OpsSend,
    OpsTimeout,
    ServerTransmit,
    Deliver(Packet),
    Drop(Packet),
    Duplicate(Packet),
}

struct PaperProtocol {
    /// The opsUI times out only when nothing is in flight (the packet or its heartbeat was
    /// really lost), not merely late.
    patient: bool,
    /// How many duplications the link may make in a run.
    max_duplicates: u8,
}

fn put(wifi: &mut Vec<Packet>, p: Packet) {
    wifi.push(p);
    wifi.sort();
}

fn take(wifi: &mut Vec<Packet>, p: Packet) -> bool {
    match wifi.iter().position(|x| *x == p) {
        Some(i) => {
            wifi.remove(i);
            true
        }
        None => false,
    }
}

impl Model for PaperProtocol {
    type State = State;
    type Action = Action;

    fn init_states(&self) -> Vec<State> {
        vec![State {
            ops_next: 0,
            ops_waiting: false,
            sends: 0,
            server_pending: None,
            wifi: vec![],
            duplicates: 0,
            executed: [0; COMMANDS as usize],
        }]
    }

    fn actions(&self, s: &State, actions: &mut Vec<Action>) {
        if s.ops_next < COMMANDS && !s.ops_waiting {
            actions.push(Action::OpsSend);
        }
        let quiet = s.wifi.is_empty() && s.server_pending.is_none();
        if s.ops_waiting && s.sends < MAX_SENDS && (!self.patient || quiet) {
            actions.push(Action::OpsTimeout);
        }
        if s.server_pending.is_some() && s.wifi.len() < MAX_IN_FLIGHT {
            actions.push(Action::ServerTransmit);
        }
        let mut seen = s.wifi.clone();
        seen.dedup();
        for p in seen {
            actions.push(Action::Deliver(p));
            actions.push(Action::Drop(p));
            if s.duplicates < self.max_duplicates && s.wifi.len() < MAX_IN_FLIGHT {
                actions.push(Action::Duplicate(p));
            }
        }
    }

    fn next_state(&self, s: &State, a: Action) -> Option<State> {
        let mut n = s.clone();
        match a {
            Action::OpsSend | Action::OpsTimeout => {
                // Section 3: send (or send again) and wait for a heartbeat.
                n.ops_waiting = true;
                n.sends += 1;
                n.server_pending = Some(s.ops_next);
            }
            Action::ServerTransmit => {
                let c = n.server_pending.take()?;
                put(&mut n.wifi, Packet::Command(c));
            }
            Action::Deliver(p) => {
                take(&mut n.wifi, p);
                match p {
                    Packet::Command(c) => {
                        // Board A executes what it receives and answers with a heartbeat.
                        n.executed[c as usize] = n.executed[c as usize].saturating_add(1);
                        if n.wifi.len() < MAX_IN_FLIGHT {
                            put(&mut n.wifi, Packet::Heartbeat);
                        }
                    }
                    Packet::Heartbeat => {
                        // Any heartbeat acknowledges the pending command.
                        if n.ops_waiting {
                            n.ops_waiting = false;
                            n.ops_next += 1;
                            n.sends = 0;
                        }
                    }
                }
            }
            Action::Drop(p) => {
                take(&mut n.wifi, p);
            }
            Action::Duplicate(p) => {
                put(&mut n.wifi, p);
                n.duplicates += 1;
            }
        }
        Some(n)
    }

    fn properties(&self) -> Vec<Property<Self>> {
        vec![
            Property::always("no command executed twice", |_, s: &State| {
                s.executed.iter().all(|&e| e <= 1)
            }),
            Property::sometimes("all commands acknowledged", |_, s: &State| {
                s.ops_next == COMMANDS
            }),
        ]
    }
}

/// The trace ends with a command delivered for the second time.
fn assert_twice(trace: &[String]) {
    let last = trace.last().expect("non-empty trace");
    assert!(last.starts_with("Deliver(Command("), "{trace:?}");
    assert_eq!(trace.iter().filter(|a| *a == last).count(), 2, "{trace:?}");
}

/// Runs the checker and returns the number of states explored and the breadth-first trace (up to the first
/// violating state) of "no command executed twice".
fn double_execution(patient: bool, max_duplicates: u8) -> (usize, Vec<String>) {
    let checker = PaperProtocol {
        patient,
        max_duplicates,
    }
    .checker()
    .threads(1)
    .spawn_bfs()
    .join();
    assert!(
        checker.discovery("all commands acknowledged").is_some(),
        "the protocol can make progress"
    );
    let path = checker
        .discovery("no command executed twice")
        .expect("stateright must find the double execution");
    let states = path.clone().into_states();
    let actions = path.into_actions();
    let cut = states
        .iter()
        .position(|s| s.executed.iter().any(|&e| e > 1))
        .expect("violating state");
    (
        checker.unique_state_count(),
        actions[..cut].iter().map(|a| format!("{a:?}")).collect(),
    )
}

// req: P3.11
#[test]
fn the_papers_resend_scheme_executes_a_command_twice() {
    // A link that duplicates: the robot executes both copies (nothing deduplicates).
    let (n_dup, dup) = double_execution(false, 2);
    assert_twice(&dup);
    // No duplication, the paper's timeout firing while a packet is merely late.
    let (n_late, late) = double_execution(false, 0);
    assert!(late.iter().any(|a| a == "OpsTimeout"), "{late:?}");
    assert_twice(&late);
    // No duplication, and an opsUI that resends only after a real loss: the command arrives,
    // its heartbeat is lost, the resend arrives too.
    let (n_lost, lost) = double_execution(true, 0);
    assert!(
        lost.iter().any(|a| a == "Drop(Heartbeat)") && lost.iter().any(|a| a == "OpsTimeout"),
        "{lost:?}"
    );
    assert_twice(&lost);
    let mut text = String::from(
        "# The paper's commanding scheme (Section 3) model-checked with stateright\n\
         # generated by proofs/tests/protocol/protocol_paper.rs; regenerate: MMIC_REGENERATE=1 cargo test -p mmic-proofs --test protocol protocol_paper\n\
         # 2 commands, at most 3 sends each, at most 3 packets in flight on the WiFi link\n",
    );
    for (title, n, trace) in [
        ("link duplicates (at most 2)", n_dup, &dup),
        (
            "no duplication; the opsUI's timeout fires while a packet is late",
            n_late,
            &late,
        ),
        (
            "no duplication; the opsUI resends only after a real loss",
            n_lost,
            &lost,
        ),
    ] {
        text += &format!("\n{title}: {n} states explored; counterexample (breadth-first) to \"no command executed twice\":\n");
        for (i, a) in trace.iter().enumerate() {
            text += &format!("  {:>2}. {a}\n", i + 1);
        }
    }
    let path = concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../spec/protocol/paper-counterexample.txt"
    );
    if std::env::var_os("MMIC_REGENERATE").is_some() {
        std::fs::create_dir_all(concat!(env!("CARGO_MANIFEST_DIR"), "/../spec/protocol")).unwrap();
        std::fs::write(path, &text).unwrap();
    }
    assert_eq!(
        std::fs::read_to_string(path).unwrap_or_default(),
        text,
        "stale: MMIC_REGENERATE=1 cargo test -p mmic-proofs --test protocol protocol_paper"
    );
}
