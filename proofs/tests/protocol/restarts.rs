//! Exactly-once across restarts (issue 29, point 2), model-checked with stateright over the
//! real library nodes. The two commanding paths of `protocol_exactly_once.rs` and
//! `protocol_pus.rs`, smaller, with crash-restart steps of board A, of the server board and of
//! the ground, each keeping what the library says it keeps and losing the rest:
//!
//! - **board A** keeps its store, the last record written: [`BoardA::ahead`]'s record is
//!   written before the tick that takes a new sequenced command, [`BoardA::durable`]'s after
//!   it, and a crash can come before the tick (the packet lost, the ahead record kept), after
//!   the tick before the second write (its heartbeat may be out), or between ticks. It comes
//!   back as [`BoardA::restarted`] from the store;
//! - **the server board**: the legacy relay restarts empty ([`Server::new`]); the PUS gateway
//!   keeps its newest key per source ([`Gateway::kept`], written before each tick, so a crash
//!   can fall between a telecommand and the write) and comes back as
//!   [`Gateway::add_restarted`] (its legacy uplink probing board A, [`Uplink::after_restart`]);
//! - **the ground** keeps nothing on the legacy path: what it had open ends "unknown (ground
//!   restarted)", and its new uplink is [`Uplink::after_restart`] (or, the design change the
//!   model calls for, [`Uplink::starting_at`] past the last number it gave out, kept). Over
//!   PUS it keeps its next TC sequence count and forgets everything else.
//!
//! Checked: no command runs twice, and board A judges none twice, over every restart; an
//! acknowledged command ran once (accepted) or not at all (refused); every command ends
//! (accepted, refused, unacknowledged, RESTARTED or unknown at a ground restart); restarts
//! happen mid-command. Planted faults (board A restarted without its store, the gateway
//! restarted without its keys, the PUS ground forgetting its sequence count) are found. The
//! counts go to spec/protocol/restarts.txt (checked fresh).
//!
//! The probes after a restart never give up (the robot may be off), which would make the
//! state space infinite (time grows): each life of a sender sends at most [`MAX_PROBES`]
//! probes in the model, after which that sender waits (the robot unreachable as far as the
//! model goes) — with no command open at it, which the end properties accept.

use mmic::command::Command;
use mmic::mode::Mode;
use mmic::node::exactly_once::uplink::{self, Outcome, Uplink};
use mmic::node::robot::board_a::{self, BoardA, Durable, Event};
use mmic::node::server::gateway::{self, Gateway, Kept, Tc};
use mmic::node::server::relay::{Accepted, Server};
use mmic::pus::request::Request;
use mmic::pus::verification::{Report, RequestId, Stage, KEY_REUSED, RESTARTED, UNACKNOWLEDGED};
use mmic::restart::ResetCause;
use mmic::units::BoardNumber;
use mmic::wire::command::{CommandRepr, COMMAND_LEN};
use mmic::wire::heartbeat::{HeartbeatRepr, HEARTBEAT_LEN};
use stateright::{Checker, HasDiscoveries, Model, Property};
use std::fmt::Debug;

/// Probes one life of a restarted sender sends at most (see the module's doc).
const MAX_PROBES: u8 = 2;

/// The nodes that restart.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
enum Node {
    BoardA,
    Server,
    Ground,
}

const NODES: [Node; 3] = [Node::BoardA, Node::Server, Node::Ground];

/// A packet on a link.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
enum Packet {
    /// A telecommand (index into the plan) from the ground to the gateway.
    Tc(u8),
    /// A final ST[1] report for a telecommand, to the ground.
    Report(u8, Final),
    Command([u8; COMMAND_LEN]),
    Heartbeat([u8; HEARTBEAT_LEN]),
}

impl Packet {
    fn label(&self) -> String {
        match self {
            Packet::Command(b) => match CommandRepr::parse(b) {
                Ok(r) => format!("command #{} {:?}", r.seq, r.command),
                Err(e) => format!("command ({e})"),
            },
            Packet::Heartbeat(b) => match HeartbeatRepr::parse(b) {
                Ok(h) => format!(
                    "heartbeat acknowledging #{} ({})",
                    h.last_seq,
                    h.refusal.map_or("accepted".into(), |r| format!("{r:?}"))
                ),
                Err(e) => format!("heartbeat ({e})"),
            },
            other => format!("{other:?}"),
        }
    }
}

/// Board A's part, shared by both models: the board, its clock and its store.
#[derive(Clone, Debug, PartialEq, Eq, Hash)]
struct RobotA {
    a: BoardA,
    now: u32,
    /// The last record written to flash (a fresh flash reads as the default record).
    store: Durable,
}

/// What board A's tick did to the plan's commands: judged (an `Executed` event) and run
/// (accepted), counted per command of the plan.
struct Counts<'a, const N: usize> {
    plan: &'a [Command; N],
    judged: &'a mut [u8; N],
    ran: &'a mut [u8; N],
}

/// How board A takes a command packet (a crash can cut it short).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
enum Take {
    /// Ahead write, tick, after-tick write.
    Whole,
    /// Ahead write, then a crash before the tick: the packet is lost.
    CrashBeforeTick,
    /// Ahead write, tick (its heartbeat goes out), then a crash before the after-tick write.
    CrashBeforeWrite,
}

impl RobotA {
    fn new() -> RobotA {
        RobotA {
            a: BoardA::new(board_a::Config::default()),
            now: 0,
            store: Durable::default(),
        }
    }

    /// Board A restarts from its store (`restore`), or from a blank flash (the planted fault).
    fn restart(&mut self, restore: bool) {
        let kept = restore.then_some(self.store);
        self.a = BoardA::restarted(board_a::Config::default(), kept, ResetCause::BrownOut);
    }

    /// Takes a command packet as `how` says; returns the heartbeat to send.
    fn take<const N: usize>(
        &mut self,
        bytes: [u8; COMMAND_LEN],
        how: Take,
        (restore, ahead_accepted): (bool, bool),
        c: Counts<'_, N>,
    ) -> (Option<[u8; HEARTBEAT_LEN]>, bool) {
        let ahead = self.a.ahead(Some(&bytes));
        if let Some(ahead) = ahead {
            self.store = match ahead_accepted {
                true => Durable {
                    outcome: None,
                    ..ahead
                },
                false => ahead,
            };
        }
        if how == Take::CrashBeforeTick {
            self.restart(restore);
            return (None, ahead.is_some());
        }
        self.now += 10;
        let out = self.a.tick(
            self.now,
            &board_a::Inputs {
                command: Some(bytes),
                ..board_a::Inputs::at_home()
            },
        );
        for e in &out.events {
            if let Event::Executed {
                command: Some(cmd),
                refusal,
                ..
            } = e
            {
                if let Some(i) = c.plan.iter().position(|p| p == cmd) {
                    c.judged[i] = c.judged[i].saturating_add(1);
                    if refusal.is_none() {
                        c.ran[i] = c.ran[i].saturating_add(1);
                    }
                }
            }
        }
        if how == Take::CrashBeforeWrite {
            self.restart(restore);
        } else {
            self.store = self.a.durable();
        }
        (out.heartbeat, ahead.is_some())
    }
}

/// Prints a discovery's path as its actions, one a line.
fn trace<M: Model>(
    path: stateright::Path<M::State, M::Action>,
    label: impl Fn(&M::Action) -> String,
) -> String
where
    M::State: Debug,
{
    path.into_actions()
        .iter()
        .map(label)
        .collect::<Vec<_>>()
        .join("\n")
}

// ---------------------------------------------------------------- legacy: ground → robot

/// Three non-idempotent commands: with two, no number the ground gives out after its restart
/// can meet one of its earlier life still in flight.
const COMMANDS: [Command; 3] = [
    Command::Mode(Mode::Operational),
    Command::Stop,
    Command::Reset,
];

/// How a command ended, as the ground has it.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
enum End {
    Done(Outcome),
    /// Open when the ground restarted: it ran once or not at all, which the ground no longer
    /// knows.
    Unknown,
}

/// What the legacy ground keeps across its restart.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
enum GroundKeeps {
    /// Nothing: its new uplink probes board A ([`Uplink::after_restart`]).
    Nothing,
    /// The last number it gave out, written before a number is first sent: its new uplink
    /// numbers past it ([`Uplink::starting_at`]).
    LastNumber,
}

#[derive(Clone, Debug, PartialEq, Eq, Hash)]
struct Legacy {
    up: Uplink,
    now: u32,
    submitted: usize,
    /// The last number the ground gave a command (what `GroundKeeps::LastNumber` keeps).
    issued: u16,
    probes: u8,
    ends: [Option<End>; COMMANDS.len()],
    server: Server<1>,
    wifi: super::InFlight<Packet>,
    drops: u8,
    duplicates: u8,
    robot: super::Shared<RobotA>,
    judged: [u8; COMMANDS.len()],
    ran: [u8; COMMANDS.len()],
    restarts: [u8; NODES.len()],
    silent_drop: bool,
    /// A restart of that node while a command was open at the ground.
    mid_command: [bool; NODES.len()],
    /// Commands that ran before board A restarted, and whether the ground then had one
    /// acknowledged (a resend after the restart answered, not run).
    ran_before_a_restart: [bool; COMMANDS.len()],
    acked_after_a_restart: bool,
}

#[derive(Clone, Debug, PartialEq, Eq, Hash)]
enum LegacyAction {
    Submit,
    Advance,
    ServerTransmit,
    Deliver(Packet),
    /// Board A takes the command, and crashes as `Take` says.
    Crash(Packet, Take),
    Drop(Packet),
    Duplicate(Packet),
    Restart(Node),
}

#[derive(Clone)]
struct LegacyModel {
    max_in_flight: usize,
    max_drops: u8,
    max_duplicates: u8,
    max_attempts: u8,
    /// Restarts of each node at most.
    max_restarts: u8,
    /// Restarts of all nodes at most.
    max_restarts_total: u8,
    keeps: GroundKeeps,
    /// Board A restarts from its store (false: the planted fault).
    restore_a: bool,
    /// Board A's ahead record says "accepted" (the planted fault: the record before the
    /// design change, which a crash between the two writes turned into a false
    /// acknowledgement) instead of "restarted while taking it" (`Refusal::Restarted`).
    ahead_accepted: bool,
}

fn plan_index(c: &Command) -> Option<usize> {
    COMMANDS.iter().position(|x| x == c)
}

impl LegacyModel {
    fn cfg(&self) -> uplink::Config {
        uplink::Config {
            max_attempts: self.max_attempts,
            ..uplink::Config::default()
        }
    }

    /// The uplink's output; `None` when it would send a probe beyond the bound.
    fn uplink_step(&self, n: &mut Legacy, t: uplink::Tick) -> Option<()> {
        if let Some(p) = t.send {
            if p.command == Command::Heartbeat {
                n.probes += 1;
                if n.probes > MAX_PROBES {
                    return None;
                }
            }
            match n.server.accept(&p.to_bytes()) {
                Ok(Accepted::Superseded(old)) => {
                    // Allowed only for a command the ground has finished with (or a probe).
                    let open = CommandRepr::parse(&old)
                        .ok()
                        .and_then(|r| plan_index(&r.command))
                        .is_some_and(|i| n.ends[i].is_none());
                    n.silent_drop |= open;
                }
                Ok(_) => {}
                Err(_) => n.silent_drop = true,
            }
        }
        if let Some(d) = t.done {
            if let Some(i) = plan_index(&d.command) {
                n.ends[i] = Some(End::Done(d.outcome));
                if n.restarts[0] > 0 && n.ran_before_a_restart[i] {
                    n.acked_after_a_restart = true;
                }
            }
        }
        Some(())
    }

    fn open(s: &Legacy) -> bool {
        (0..s.submitted).any(|i| s.ends[i].is_none())
    }
}

impl Model for LegacyModel {
    type State = Legacy;
    type Action = LegacyAction;

    fn init_states(&self) -> Vec<Legacy> {
        vec![Legacy {
            up: Uplink::new(self.cfg(), BoardNumber::ONE),
            now: 0,
            submitted: 0,
            issued: 0,
            probes: 0,
            ends: [None; COMMANDS.len()],
            server: Server::new(),
            wifi: super::InFlight::new(),
            drops: 0,
            duplicates: 0,
            robot: super::Shared::new(RobotA::new()),
            judged: [0; COMMANDS.len()],
            ran: [0; COMMANDS.len()],
            restarts: [0; NODES.len()],
            silent_drop: false,
            mid_command: [false; NODES.len()],
            ran_before_a_restart: [false; COMMANDS.len()],
            acked_after_a_restart: false,
        }]
    }

    fn actions(&self, s: &Legacy, actions: &mut Vec<LegacyAction>) {
        if s.up.is_idle() && s.submitted < COMMANDS.len() {
            actions.push(LegacyAction::Submit);
        }
        if s.up.next_deadline().is_some() {
            actions.push(LegacyAction::Advance);
        }
        if s.server.pending_count() > 0 && s.wifi.len() < self.max_in_flight {
            actions.push(LegacyAction::ServerTransmit);
        }
        let total: u8 = s.restarts.iter().sum();
        for p in super::distinct(&s.wifi) {
            actions.push(LegacyAction::Deliver(p));
            if matches!(p, Packet::Command(_))
                && s.restarts[0] < self.max_restarts
                && total < self.max_restarts_total
            {
                actions.push(LegacyAction::Crash(p, Take::CrashBeforeTick));
                actions.push(LegacyAction::Crash(p, Take::CrashBeforeWrite));
            }
            if s.drops < self.max_drops {
                actions.push(LegacyAction::Drop(p));
            }
            if s.duplicates < self.max_duplicates && s.wifi.len() < self.max_in_flight {
                actions.push(LegacyAction::Duplicate(p));
            }
        }
        for (k, node) in NODES.iter().enumerate() {
            if s.restarts[k] < self.max_restarts && total < self.max_restarts_total {
                actions.push(LegacyAction::Restart(*node));
            }
        }
    }

    fn next_state(&self, s: &Legacy, act: LegacyAction) -> Option<Legacy> {
        let mut n = s.clone();
        match act {
            LegacyAction::Submit => {
                n.issued = n.up.submit(COMMANDS[n.submitted]).ok()?;
                n.submitted += 1;
                let t = n.up.tick(n.now);
                self.uplink_step(&mut n, t)?;
            }
            LegacyAction::Advance => {
                n.now = n.now.max(n.up.next_deadline()?);
                let t = n.up.tick(n.now);
                self.uplink_step(&mut n, t)?;
            }
            LegacyAction::ServerTransmit => {
                let (robot, packet) = n.server.next_visit()?;
                n.server.delivered(robot, &packet);
                super::put(&mut n.wifi, Packet::Command(packet));
            }
            LegacyAction::Deliver(p) | LegacyAction::Crash(p, _) => {
                let i = n.wifi.iter().position(|x| *x == p)?;
                n.wifi.remove(i);
                let how = match act {
                    LegacyAction::Crash(_, how) => {
                        n.mid_command[0] |= LegacyModel::open(&n);
                        n.restarts[0] += 1;
                        how
                    }
                    _ => Take::Whole,
                };
                match p {
                    Packet::Command(bytes) => {
                        let ran_before = n.ran;
                        let counts = Counts {
                            plan: &COMMANDS,
                            judged: &mut n.judged,
                            ran: &mut n.ran,
                        };
                        let keeps = (self.restore_a, self.ahead_accepted);
                        let (hb, _) = n.robot.update(|r| r.take(bytes, how, keeps, counts));
                        if how != Take::Whole {
                            for (k, r) in ran_before.iter().enumerate() {
                                n.ran_before_a_restart[k] |= *r > 0 || n.ran[k] > 0;
                            }
                        }
                        if let Some(hb) = hb {
                            if n.wifi.len() < self.max_in_flight {
                                super::put(&mut n.wifi, Packet::Heartbeat(hb));
                            }
                        }
                    }
                    Packet::Heartbeat(bytes) => {
                        let hb = HeartbeatRepr::parse(&bytes).ok()?;
                        let t = n.up.heartbeat(n.now, &hb);
                        self.uplink_step(&mut n, t)?;
                    }
                    _ => return None,
                }
            }
            LegacyAction::Drop(p) => {
                let i = n.wifi.iter().position(|x| *x == p)?;
                n.wifi.remove(i);
                n.drops += 1;
            }
            LegacyAction::Duplicate(p) => {
                super::put(&mut n.wifi, p);
                n.duplicates += 1;
            }
            LegacyAction::Restart(node) => {
                let k = node as usize;
                n.mid_command[k] |= LegacyModel::open(&n);
                n.restarts[k] += 1;
                match node {
                    Node::BoardA => {
                        for (k, r) in n.ran.iter().enumerate() {
                            n.ran_before_a_restart[k] |= *r > 0;
                        }
                        n.robot.update(|r| r.restart(self.restore_a));
                    }
                    Node::Server => n.server = Server::new(),
                    Node::Ground => {
                        for i in 0..n.submitted {
                            if n.ends[i].is_none() {
                                n.ends[i] = Some(End::Unknown);
                            }
                        }
                        n.probes = 0;
                        n.up = match self.keeps {
                            GroundKeeps::Nothing => {
                                Uplink::after_restart(self.cfg(), BoardNumber::ONE)
                            }
                            GroundKeeps::LastNumber => Uplink::starting_at(
                                self.cfg(),
                                BoardNumber::ONE,
                                n.issued.wrapping_add(1),
                            ),
                        };
                    }
                }
            }
        }
        Some(n)
    }

    fn properties(&self) -> Vec<Property<Self>> {
        vec![
            Property::always("no command run twice", |_, s: &Legacy| {
                s.ran.iter().all(|&r| r <= 1)
            }),
            Property::always("board A judges no command twice", |_, s: &Legacy| {
                s.judged.iter().all(|&j| j <= 1)
            }),
            Property::always(
                "an accepted command ran once, a refused one not at all",
                |_, s: &Legacy| {
                    (0..COMMANDS.len()).all(|i| match s.ends[i] {
                        Some(End::Done(Outcome::Accepted)) => s.ran[i] == 1,
                        Some(End::Done(Outcome::Refused(_))) => s.ran[i] == 0,
                        _ => true,
                    })
                },
            ),
            Property::always(
                "the server never silently drops a pending command",
                |_, s: &Legacy| !s.silent_drop,
            ),
            Property::eventually("every command ends", |_, s: &Legacy| {
                let ended = s.ends.iter().take(s.submitted).all(Option::is_some);
                let waiting = s.up.is_syncing() && s.probes >= MAX_PROBES;
                ended && ((s.submitted == COMMANDS.len() && s.up.is_idle()) || waiting)
            }),
            Property::sometimes("every command accepted", |_, s: &Legacy| {
                s.ends
                    .iter()
                    .all(|e| *e == Some(End::Done(Outcome::Accepted)))
            }),
            Property::sometimes("board A restarted mid-command", |_, s: &Legacy| {
                s.mid_command[0]
            }),
            Property::sometimes("the server restarted mid-command", |_, s: &Legacy| {
                s.mid_command[1]
            }),
            Property::sometimes("the ground restarted mid-command", |_, s: &Legacy| {
                s.mid_command[2]
            }),
            Property::sometimes(
                "a command run before board A restarted acknowledged after it",
                |_, s: &Legacy| s.acked_after_a_restart,
            ),
            Property::sometimes(
                "a command accepted after the ground restarted",
                |_, s: &Legacy| {
                    s.restarts[2] > 0
                        && s.ends.contains(&Some(End::Unknown))
                        && s.ends.contains(&Some(End::Done(Outcome::Accepted)))
                        && s.up.is_idle()
                },
            ),
        ]
    }
}

const LEGACY_SAFETY: [&str; 5] = [
    "no command run twice",
    "board A judges no command twice",
    "an accepted command ran once, a refused one not at all",
    "the server never silently drops a pending command",
    "every command ends",
];
const LEGACY_REACH: [&str; 6] = [
    "every command accepted",
    "board A restarted mid-command",
    "the server restarted mid-command",
    "the ground restarted mid-command",
    "a command run before board A restarted acknowledged after it",
    "a command accepted after the ground restarted",
];

fn legacy_label(a: &LegacyAction) -> String {
    match a {
        LegacyAction::Deliver(p) => format!("deliver {}", p.label()),
        LegacyAction::Crash(p, how) => format!("board A takes {} and crashes: {how:?}", p.label()),
        LegacyAction::Drop(p) => format!("drop {}", p.label()),
        LegacyAction::Duplicate(p) => format!("duplicate {}", p.label()),
        other => format!("{other:?}"),
    }
}

/// Runs a model to the end (or to its first failure); the failures found, each with its trace.
fn run<M>(model: M, label: impl Fn(&M::Action) -> String, names: &[&'static str]) -> Run
where
    M: Model + Send + Sync + 'static,
    M::State: Debug + Send + Sync + std::hash::Hash + Clone + PartialEq,
    M::Action: Debug + Send + Sync + Clone + PartialEq,
{
    let t0 = std::time::Instant::now();
    let checker = model
        .checker()
        .threads(crate::model_threads())
        .finish_when(HasDiscoveries::AnyFailures)
        .spawn_bfs()
        .join();
    let mut failures = vec![];
    for &p in names {
        if let Some(path) = checker.discovery(p) {
            failures.push((p, trace::<M>(path, &label)));
        }
    }
    let found = checker
        .discoveries()
        .into_keys()
        .collect::<std::collections::BTreeSet<_>>();
    Run {
        unique: checker.unique_state_count(),
        total: checker.state_count(),
        secs: t0.elapsed().as_secs_f64(),
        failures,
        found,
        done: checker.is_done(),
    }
}

struct Run {
    unique: usize,
    total: usize,
    secs: f64,
    failures: Vec<(&'static str, String)>,
    found: std::collections::BTreeSet<&'static str>,
    done: bool,
}

impl Run {
    fn assert_holds(&self, what: &str, reach: &[&str]) {
        if let Some((p, t)) = self.failures.first() {
            panic!("{what}: {p} violated:\n{t}");
        }
        assert!(self.done, "{what}: not exhausted");
        for p in reach {
            assert!(self.found.contains(p), "{what}: {p} is reachable");
        }
        eprintln!(
            "{what}: {} unique states ({} visited), {:.1} s",
            self.unique, self.total, self.secs
        );
    }

    /// The fault is found: one of `ps` is violated, with a trace; which one.
    fn assert_finds(&self, what: &str, ps: &[&'static str]) -> &'static str {
        let (p, t) = self
            .failures
            .iter()
            .find(|(q, _)| ps.contains(q))
            .unwrap_or_else(|| panic!("{what}: none of {ps:?} violated (found {:?})", self.found));
        assert!(!t.is_empty(), "{what}: a trace");
        eprintln!("{what}: {p} violated ({:.1} s):\n{t}\n", self.secs);
        p
    }
}

fn legacy(keeps: GroundKeeps, restore_a: bool) -> LegacyModel {
    LegacyModel {
        max_in_flight: 2,
        max_drops: 1,
        max_duplicates: 0,
        max_attempts: 2,
        max_restarts: 1,
        max_restarts_total: 1,
        keeps,
        restore_a,
        ahead_accepted: false,
    }
}

// ---------------------------------------------------------------- PUS: ground → gateway → robot

/// Two non-idempotent telecommands.
const TCS: [Command; 2] = [Command::Mode(Mode::Operational), Command::Stop];
const APID: u16 = 0x101;

/// How a telecommand ended, as its final ST[1] report says.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
enum Final {
    Completed,
    Refused,
    Unacknowledged,
    /// Taken before the gateway restarted: ran at most once, outcome unknown (0x0202).
    Restarted,
}

#[derive(Clone, Debug, PartialEq, Eq, Hash)]
struct Pus {
    g: super::Shared<Gateway<1, 4, 8>>,
    /// What the gateway wrote to flash (the last `kept`).
    g_store: Kept,
    g_life: u8,
    g_probes: u8,
    now: u32,
    /// Telecommands the ground sent (the next one is `TCS[sent]`).
    sent: usize,
    /// The next sequence count (kept across the ground's restart, unless planted otherwise).
    next_count: u16,
    /// The key (sequence count) each telecommand went out under.
    key_of: [Option<u16>; TCS.len()],
    resent: u8,
    up: super::InFlight<Packet>,
    down: super::InFlight<Packet>,
    wifi: super::InFlight<Packet>,
    drops: u8,
    robot: super::Shared<RobotA>,
    judged: [u8; TCS.len()],
    ran: [u8; TCS.len()],
    /// The gateway life that took (accepted) each telecommand, and the life that made its
    /// final report.
    taken_in: [Option<u8>; TCS.len()],
    made_in: [Option<u8>; TCS.len()],
    made: [Option<Final>; TCS.len()],
    started: [bool; TCS.len()],
    /// Final reports the ground received.
    got: [Option<Final>; TCS.len()],
    /// Open at the ground when it restarted.
    unknown: [bool; TCS.len()],
    conflict: bool,
    key_reused: bool,
    restarts: [u8; NODES.len()],
    mid_command: [bool; NODES.len()],
    restarted_answer: bool,
}

#[derive(Clone, Debug, PartialEq, Eq, Hash)]
enum PusAction {
    Send,
    Resend(u8),
    Advance,
    Deliver(Packet),
    Crash(Packet, Take),
    Drop(Packet),
    Restart(Node),
}

#[derive(Clone)]
struct PusModel {
    max_in_flight: usize,
    max_drops: u8,
    max_resends: u8,
    max_restarts: u8,
    max_restarts_total: u8,
    /// The gateway restarts with its kept keys (false: the planted fault, `add`).
    restore_gateway: bool,
    /// The ground keeps its next sequence count (false: the planted fault, from 1 again).
    ground_keeps_count: bool,
    restore_a: bool,
    /// As `LegacyModel::ahead_accepted`.
    ahead_accepted: bool,
}

impl PusModel {
    fn cfg() -> gateway::Config {
        gateway::Config {
            uplink: uplink::Config {
                max_attempts: 2,
                ..gateway::Config::default().uplink
            },
            poll_ms: 0,
            hk_enabled: false,
            ..gateway::Config::default()
        }
    }

    fn tc(s: &Pus, i: u8) -> Option<Tc> {
        Some(Tc {
            request: RequestId {
                apid: APID,
                seq_count: s.key_of[usize::from(i)]?,
            },
            source_id: 1,
            ack: 0b1111,
            request_of: Ok(Request::Function(TCS[usize::from(i)])),
        })
    }

    /// The gateway's output; `None` when it would send a probe beyond the bound.
    fn out(&self, n: &mut Pus, out: gateway::Out<16>) -> Option<()> {
        for (_, c) in out.to_robots {
            if c.command == Command::Heartbeat {
                n.g_probes += 1;
                if n.g_probes > MAX_PROBES {
                    return None;
                }
            }
            if n.wifi.len() < self.max_in_flight {
                super::put(&mut n.wifi, Packet::Command(c.to_bytes()));
            }
        }
        for tm in out.reports {
            let Ok(r) = Report::parse(tm.subservice, &tm.data) else {
                continue;
            };
            // The newest telecommand sent under that key.
            let Some(i) = (0..TCS.len())
                .rev()
                .find(|&i| n.key_of[i] == Some(r.request.seq_count))
            else {
                continue;
            };
            let fin = match (r.stage, r.failure) {
                (Stage::Acceptance, None) => {
                    n.taken_in[i] = Some(n.g_life);
                    None
                }
                (Stage::Start, None) => {
                    n.started[i] = true;
                    None
                }
                (Stage::Completion, None) => Some(Final::Completed),
                (_, Some(f)) if f.code == UNACKNOWLEDGED => Some(Final::Unacknowledged),
                (_, Some(f)) if f.code == RESTARTED => Some(Final::Restarted),
                (_, Some(f)) => {
                    n.key_reused |= f.code == KEY_REUSED;
                    Some(Final::Refused)
                }
            };
            if let Some(f) = fin {
                if f == Final::Restarted {
                    n.restarted_answer = true;
                } else {
                    n.conflict |= n.made[i].is_some_and(|m| m != f && m != Final::Restarted);
                    n.made[i] = Some(f);
                }
                n.made_in[i] = Some(n.g_life);
                if n.down.len() < self.max_in_flight {
                    super::put(&mut n.down, Packet::Report(i as u8, f));
                }
            }
        }
        Some(())
    }

    fn open(s: &Pus) -> bool {
        (0..s.sent).any(|i| s.got[i].is_none() && !s.unknown[i])
    }
}

impl Model for PusModel {
    type State = Pus;
    type Action = PusAction;

    fn init_states(&self) -> Vec<Pus> {
        let mut g = Gateway::new(PusModel::cfg());
        g.add(BoardNumber::ONE);
        // As in protocol_pus.rs: the model starts once board A's first heartbeat reached the
        // gateway.
        g.heartbeat(
            0,
            &HeartbeatRepr {
                board: BoardNumber::ONE,
                mode: Mode::Standby,
                ..HeartbeatRepr::default()
            },
        );
        vec![Pus {
            g_store: g.kept(BoardNumber::ONE).unwrap_or_default(),
            g: super::Shared::new(g),
            g_life: 0,
            g_probes: 0,
            now: 0,
            sent: 0,
            next_count: 1,
            key_of: [None; TCS.len()],
            resent: 0,
            up: super::InFlight::new(),
            down: super::InFlight::new(),
            wifi: super::InFlight::new(),
            drops: 0,
            robot: super::Shared::new(RobotA::new()),
            judged: [0; TCS.len()],
            ran: [0; TCS.len()],
            taken_in: [None; TCS.len()],
            made_in: [None; TCS.len()],
            made: [None; TCS.len()],
            started: [false; TCS.len()],
            got: [None; TCS.len()],
            unknown: [false; TCS.len()],
            conflict: false,
            key_reused: false,
            restarts: [0; NODES.len()],
            mid_command: [false; NODES.len()],
            restarted_answer: false,
        }]
    }

    fn actions(&self, s: &Pus, actions: &mut Vec<PusAction>) {
        if s.sent < TCS.len() && s.up.len() < self.max_in_flight {
            actions.push(PusAction::Send);
        }
        if s.resent < self.max_resends && s.up.len() < self.max_in_flight {
            // The ground sends again a telecommand of its own life it has no final report of.
            for i in 0..s.sent {
                if s.got[i].is_none() && !s.unknown[i] {
                    actions.push(PusAction::Resend(i as u8));
                }
            }
        }
        if s.g.next_deadline(s.now).is_some() {
            actions.push(PusAction::Advance);
        }
        let total: u8 = s.restarts.iter().sum();
        let restart_a = s.restarts[0] < self.max_restarts && total < self.max_restarts_total;
        for link in [&s.up, &s.down, &s.wifi] {
            for p in super::distinct(link) {
                actions.push(PusAction::Deliver(p));
                if matches!(p, Packet::Command(_)) && restart_a {
                    actions.push(PusAction::Crash(p, Take::CrashBeforeTick));
                    actions.push(PusAction::Crash(p, Take::CrashBeforeWrite));
                }
                if s.drops < self.max_drops {
                    actions.push(PusAction::Drop(p));
                }
            }
        }
        for (k, node) in NODES.iter().enumerate() {
            if s.restarts[k] < self.max_restarts && total < self.max_restarts_total {
                actions.push(PusAction::Restart(*node));
            }
        }
    }

    fn next_state(&self, s: &Pus, act: PusAction) -> Option<Pus> {
        let mut n = s.clone();
        match act {
            PusAction::Send => {
                n.key_of[n.sent] = Some(n.next_count);
                n.next_count += 1;
                super::put(&mut n.up, Packet::Tc(n.sent as u8));
                n.sent += 1;
            }
            PusAction::Resend(i) => {
                super::put(&mut n.up, Packet::Tc(i));
                n.resent += 1;
            }
            PusAction::Advance => {
                let t = n.g.next_deadline(n.now)?;
                n.now = t.max(n.now);
                // The kept keys are written before the tick.
                n.g_store = n.g.kept(BoardNumber::ONE)?;
                let now = n.now;
                let out = n.g.update(|g| g.tick(now));
                self.out(&mut n, out)?;
            }
            PusAction::Drop(p) => {
                let v = match p {
                    Packet::Tc(_) => &mut n.up,
                    Packet::Report(..) => &mut n.down,
                    _ => &mut n.wifi,
                };
                let i = v.iter().position(|x| *x == p)?;
                v.remove(i);
                n.drops += 1;
            }
            PusAction::Deliver(p) | PusAction::Crash(p, _) => {
                let v = match p {
                    Packet::Tc(_) => &mut n.up,
                    Packet::Report(..) => &mut n.down,
                    _ => &mut n.wifi,
                };
                let i = v.iter().position(|x| *x == p)?;
                v.remove(i);
                let how = match act {
                    PusAction::Crash(_, how) => {
                        n.mid_command[0] |= PusModel::open(&n);
                        n.restarts[0] += 1;
                        how
                    }
                    _ => Take::Whole,
                };
                match p {
                    Packet::Tc(i) => {
                        let tc = PusModel::tc(&n, i)?;
                        let out = n.g.update(|g| g.tc(&tc));
                        self.out(&mut n, out)?;
                    }
                    Packet::Report(i, f) => {
                        let i = usize::from(i);
                        if !n.unknown[i] {
                            n.conflict |= n.got[i].is_some_and(|g| {
                                g != f && g != Final::Restarted && f != Final::Restarted
                            });
                            n.got[i] = Some(f);
                        }
                    }
                    Packet::Command(bytes) => {
                        let counts = Counts {
                            plan: &TCS,
                            judged: &mut n.judged,
                            ran: &mut n.ran,
                        };
                        let keeps = (self.restore_a, self.ahead_accepted);
                        let (hb, _) = n.robot.update(|r| r.take(bytes, how, keeps, counts));
                        if let Some(hb) = hb {
                            if n.wifi.len() < self.max_in_flight {
                                super::put(&mut n.wifi, Packet::Heartbeat(hb));
                            }
                        }
                    }
                    Packet::Heartbeat(bytes) => {
                        let hb = HeartbeatRepr::parse(&bytes).ok()?;
                        let now = n.now;
                        let out = n.g.update(|g| g.heartbeat(now, &hb));
                        self.out(&mut n, out)?;
                    }
                }
            }
            PusAction::Restart(node) => {
                let k = node as usize;
                n.mid_command[k] |= PusModel::open(&n);
                n.restarts[k] += 1;
                match node {
                    Node::BoardA => n.robot.update(|r| r.restart(self.restore_a)),
                    Node::Server => {
                        let mut g = Gateway::new(PusModel::cfg());
                        if self.restore_gateway {
                            g.add_restarted(BoardNumber::ONE, n.g_store.clone());
                        } else {
                            g.add(BoardNumber::ONE);
                        }
                        n.g = super::Shared::new(g);
                        n.g_life += 1;
                        n.g_probes = 0;
                    }
                    Node::Ground => {
                        for i in 0..n.sent {
                            n.unknown[i] |= n.got[i].is_none();
                        }
                        if !self.ground_keeps_count {
                            n.next_count = 1;
                        }
                    }
                }
            }
        }
        Some(n)
    }

    fn properties(&self) -> Vec<Property<Self>> {
        vec![
            Property::always("no telecommand run twice", |_, s: &Pus| {
                s.ran.iter().all(|&r| r <= 1)
            }),
            Property::always("board A judges no telecommand twice", |_, s: &Pus| {
                s.judged.iter().all(|&j| j <= 1)
            }),
            Property::always(
                "a telecommand reported started or completed ran exactly once",
                |_, s: &Pus| {
                    (0..TCS.len()).all(|i| {
                        !(s.started[i] || s.made[i] == Some(Final::Completed)) || s.ran[i] == 1
                    })
                },
            ),
            Property::always("one refused did not run", |_, s: &Pus| {
                (0..TCS.len()).all(|i| s.made[i] != Some(Final::Refused) || s.ran[i] == 0)
            }),
            Property::always(
                "no telecommand has two different final reports (RESTARTED aside)",
                |_, s: &Pus| !s.conflict,
            ),
            Property::always("no telecommand refused for a reused key", |_, s: &Pus| {
                !s.key_reused
            }),
            Property::eventually(
                "every telecommand the gateway took ends in a final report of that life",
                |_, s: &Pus| {
                    let waiting = s.g_probes >= MAX_PROBES;
                    s.sent == TCS.len()
                        && s.up.is_empty()
                        && (s.g.next_deadline(s.now).is_none() || waiting)
                        && (0..TCS.len()).all(|i| {
                            s.taken_in[i] != Some(s.g_life)
                                || s.made_in[i] == Some(s.g_life)
                                || waiting
                        })
                },
            ),
            Property::sometimes(
                "every telecommand completed and known on the ground",
                |_, s: &Pus| s.got.iter().all(|g| *g == Some(Final::Completed)),
            ),
            Property::sometimes("board A restarted mid-command", |_, s: &Pus| {
                s.mid_command[0]
            }),
            Property::sometimes("the gateway restarted mid-command", |_, s: &Pus| {
                s.mid_command[1]
            }),
            Property::sometimes("the ground restarted mid-command", |_, s: &Pus| {
                s.mid_command[2]
            }),
            Property::sometimes(
                "a resend after the gateway restarted answered RESTARTED after it ran",
                |_, s: &Pus| s.restarted_answer && s.ran.contains(&1) && s.restarts[1] > 0,
            ),
        ]
    }
}

const PUS_SAFETY: [&str; 7] = [
    "no telecommand run twice",
    "board A judges no telecommand twice",
    "a telecommand reported started or completed ran exactly once",
    "one refused did not run",
    "no telecommand has two different final reports (RESTARTED aside)",
    "no telecommand refused for a reused key",
    "every telecommand the gateway took ends in a final report of that life",
];
const PUS_REACH: [&str; 5] = [
    "every telecommand completed and known on the ground",
    "board A restarted mid-command",
    "the gateway restarted mid-command",
    "the ground restarted mid-command",
    "a resend after the gateway restarted answered RESTARTED after it ran",
];

fn pus_label(a: &PusAction) -> String {
    match a {
        PusAction::Deliver(p) => format!("deliver {}", p.label()),
        PusAction::Crash(p, how) => format!("board A takes {} and crashes: {how:?}", p.label()),
        PusAction::Drop(p) => format!("drop {}", p.label()),
        other => format!("{other:?}"),
    }
}

fn pus() -> PusModel {
    PusModel {
        max_in_flight: 2,
        max_drops: 0,
        max_resends: 1,
        max_restarts: 1,
        max_restarts_total: 1,
        restore_gateway: true,
        ground_keeps_count: true,
        restore_a: true,
        ahead_accepted: false,
    }
}

/// The models and the faults, run in turn; the counts go to spec/protocol/restarts.txt.
#[test]
#[cfg_attr(miri, ignore = "model checking: minutes under Miri")]
fn exactly_once_across_restarts() {
    let mut text = String::from(
        "# Exactly-once across restarts of board A, the server board and the ground, model-checked with stateright 0.31\n\
         # generated by proofs/tests/protocol/restarts.rs; regenerate: MMIC_REGENERATE=1 cargo test -p mmic-proofs --test protocol restarts\n\
         # (times are not recorded here: they depend on the build and the machine, see spec/protocol/README.md)\n",
    );

    // Legacy: the ground keeping its last number (the design change its counterexample asks).
    let m = legacy(GroundKeeps::LastNumber, true);
    let r = run(m.clone(), legacy_label, &LEGACY_SAFETY);
    r.assert_holds("legacy", &LEGACY_REACH);
    text += &format!(
        "\nlegacy: opsUI Uplink ({} attempts), Server<1>, WiFi losing (at most {}) and reordering up to {}\n\
         packets in flight, BoardA with its store; commands {COMMANDS:?};\n\
         crash-restarts: each node at most {}, {} in all; board A's crash before the tick, before the\n\
         after-tick write, or between ticks; the ground keeps the last number it gave out\n\
         {} unique states ({} visited), breadth-first, exhaustive:\n",
        m.max_attempts, m.max_drops, m.max_in_flight, m.max_restarts, m.max_restarts_total, r.unique, r.total
    );
    for p in LEGACY_SAFETY {
        text += &format!("  holds: {p}\n");
    }
    for p in LEGACY_REACH {
        text += &format!("  found: {p}\n");
    }
    let faults: [(&str, LegacyModel, &[&'static str]); 3] = [
        (
            "the ground keeping nothing (Uplink::after_restart alone)",
            legacy(GroundKeeps::Nothing, true),
            &["an accepted command ran once, a refused one not at all"],
        ),
        (
            "planted: board A's ahead record saying accepted, as before the design change",
            LegacyModel {
                ahead_accepted: true,
                ..legacy(GroundKeeps::LastNumber, true)
            },
            &["an accepted command ran once, a refused one not at all"],
        ),
        (
            "planted: board A restarted without its store (BoardA::restarted(cfg, None, ..))",
            legacy(GroundKeeps::LastNumber, false),
            &["no command run twice", "board A judges no command twice"],
        ),
    ];
    for (what, m, expect) in faults {
        run(m, legacy_label, &LEGACY_SAFETY).assert_finds(what, expect);
        text += &format!("  {what}: found violated: {}\n", expect.join(" or "));
    }

    let m = pus();
    let r = run(m.clone(), pus_label, &PUS_SAFETY);
    r.assert_holds("PUS", &PUS_REACH);
    text += &format!(
        "\nPUS: the ground sending each TC once (more than one in flight) and again up to {} times in all\n\
         while it has no final report; a ground link and the WiFi link reordering up to {} packets each (what\n\
         does not fit is lost) and dropping at most {} more; the PUS gateway (legacy uplink with 2 attempts) with its kept\n\
         keys written before each tick; BoardA with its store; telecommands {TCS:?};\n\
         crash-restarts: each node at most {}, {} in all; the ground keeps its next sequence count\n\
         {} unique states ({} visited), breadth-first, exhaustive:\n",
        m.max_resends, m.max_in_flight, m.max_drops, m.max_restarts, m.max_restarts_total, r.unique, r.total
    );
    for p in PUS_SAFETY {
        text += &format!("  holds: {p}\n");
    }
    for p in PUS_REACH {
        text += &format!("  found: {p}\n");
    }
    let faults: [(&str, PusModel, &[&'static str]); 3] = [
        (
            "planted: board A's ahead record saying accepted, as before the design change",
            PusModel {
                ahead_accepted: true,
                ..pus()
            },
            &["a telecommand reported started or completed ran exactly once"],
        ),
        (
            "planted: the gateway restarted without its kept keys (Gateway::add)",
            PusModel {
                restore_gateway: false,
                ..pus()
            },
            &[
                "no telecommand run twice",
                "board A judges no telecommand twice",
            ],
        ),
        (
            "planted: the ground restarted numbering its TCs from 1 again",
            PusModel {
                ground_keeps_count: false,
                ..pus()
            },
            &["no telecommand refused for a reused key"],
        ),
    ];
    for (what, m, expect) in faults {
        run(m, pus_label, &PUS_SAFETY).assert_finds(what, expect);
        text += &format!("  {what}: found violated: {}\n", expect.join(" or "));
    }

    let path = concat!(env!("CARGO_MANIFEST_DIR"), "/../spec/protocol/restarts.txt");
    if std::env::var_os("MMIC_REGENERATE").is_some() {
        std::fs::write(path, &text).expect("write spec/protocol/restarts.txt");
    }
    assert_eq!(
        std::fs::read_to_string(path).unwrap_or_default(),
        text,
        "stale: MMIC_REGENERATE=1 cargo test -p mmic-proofs --test protocol restarts"
    );
}

/// The legacy model with two losses and two restarts (of different nodes) on one path (the
/// default: one and one): measured 282 s, 7,643,500 states, in a debug build.
#[test]
#[ignore = "about 5 minutes in a debug build"]
fn legacy_across_two_restarts() {
    let m = LegacyModel {
        max_drops: 2,
        max_restarts_total: 2,
        ..legacy(GroundKeeps::LastNumber, true)
    };
    run(m, legacy_label, &LEGACY_SAFETY).assert_holds("legacy, two losses", &LEGACY_REACH);
}
