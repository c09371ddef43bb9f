//! The virtual-time engine (the default of `mmic sim`): every node of Figure 3 — the ground's
//! plan runners, each robot's server board (the legacy relay or the PUS gateway), board A's
//! WiFi task and control task with the library's hand-off queues between them, board B, and
//! the plant — runs on one virtual clock, as a discrete-event simulation in one thread. No wall
//! clock, no OS thread, no socket: the links between the nodes are simulated ([`link`]: latency,
//! jitter, loss, duplication, reordering, cuts, per link and direction, each from its own
//! seeded stream), and events at the same instant run in the order they were scheduled. The
//! same configuration and seed give the same run, byte for byte of its log, on any host at any
//! load, as fast as the host goes (the demo plan runs at thousands of times real time).
//!
//! ```
//! use mmic_host::sim::{engine, SimConfig};
//! let mut cfg = SimConfig::demo();
//! cfg.progress = false;
//! let a = engine::run(&cfg).unwrap();
//! let b = engine::run(&cfg).unwrap();
//! assert!(a.completed());
//! assert_eq!(a.records, b.records); // deterministic
//! ```
//!
//! The nodes are the same as the realtime engine's ([`super::shell`]): one control tick of each
//! board, the ground's plan runners, the server board's relay and the gateway are the library's
//! pure nodes, and the engine only moves bytes between them at the right virtual times:
//!
//! * boards A and B tick every 10 ms (board B at its own phase, [`SimConfig::b_phase_us`]; the
//!   boards A of a fleet tick in one event, robot by robot, and so do its boards B);
//!   board A's control task takes at most one command from the WiFi hand-off queue and one
//!   internal heartbeat per tick, as the firmware does;
//! * board A's WiFi task runs when the server board opens a connection (it discards the
//!   heartbeats made while nobody was connected, as the firmware does), when command bytes
//!   arrive (deframed into the hand-off queue), and [`WIFI_TASK_US`] after the control task
//!   queued a heartbeat (written to the connection, if one is open);
//! * the server board visits its robot as the firmware does (open a connection, send the
//!   command, wait up to `visit_ms` for the heartbeat, forward it, close) and reads the ground's
//!   line only between visits; the PUS gateway wakes at its own next deadline;
//! * what board A's WiFi task and the server board's visit do with their bytes is the
//!   library's, as in every other shell ([`mmic::node::robot::wifi_session`], [`mmic::node::server::visit`]);
//!   the engine only carries those bytes and times them;
//! * the ground ticks its plan runners every [`GROUND_TICK_MS`] and takes each packet from a
//!   server board when it arrives.

pub mod link;
pub mod watch;

use super::inject::{Injection, Node, BOOT_MS};
use super::log::{self, Log};
use super::plant::{Drives, Plant};
use super::shell::{frames, Ground, GroundSide, LegacyGround, SideA, SideB};
use super::{FrameStats, LinkLayer, Protocol, SimConfig, Summary};
use link::{Fate, Link, LinkModel};
use mmic::link::sdls::Key256;
use mmic::node::ground::frames::GroundLink;
use mmic::node::ground::plan_runner::PlanRunner;
use mmic::node::robot::board_a::{self, BoardA, Durable};
use mmic::node::robot::board_b::{self, BoardB};
use mmic::node::robot::handoff::PacketQueue;
use mmic::node::robot::wifi_session::{Outgoing, WifiConfig, WifiSession};
use mmic::node::server::gateway::{Gateway, Kept, Out};
use mmic::node::server::relay::{Accepted, Server};
use mmic::node::server::visit::Visit;
use mmic::restart::ResetCause;
use mmic::units::BoardNumber;
use mmic::wire::command::{CommandRepr, COMMAND_LEN};
use mmic::wire::deframer::Deframer;
use mmic::wire::heartbeat::{HeartbeatRepr, HEARTBEAT_LEN};
use mmic_replay::trace::{self, Record};
use serde_json::{json, Value};
use std::cmp::Reverse;
use std::collections::{BinaryHeap, VecDeque};
use std::time::Instant;
use watch::Watch;

/// The boards' control period, ms.
pub const TICK_MS: u32 = 10;
/// How often the ground's loop ticks its plan runners, ms (packets from the server boards are
/// taken as they arrive; this is the resolution of the runners' own timers: the 1.2 s slots
/// and 0.7 s answer windows).
pub const GROUND_TICK_MS: u32 = 10;
/// How soon board A's WiFi task writes a heartbeat the control task queued, µs: the firmware's
/// WiFi task polls its connection with a 2 ms read timeout and then drains the queue, 1 ms
/// later on average.
pub const WIFI_TASK_US: u64 = 1_000;

/// The links of every robot in the virtual-time engine: the model of each (both directions
/// alike); the losses are the run's `wifi_loss`, `serial_loss` and `ab_loss`, and board B's cut
/// is `cut_b_at`.
#[derive(Debug, Clone, PartialEq)]
pub struct Links {
    /// The WiFi link between the server board and board A (a TCP connection per visit).
    pub wifi: LinkModel,
    /// The ground's link to the server board: the serial line (legacy) or UDP (PUS).
    pub ground: LinkModel,
    /// The serial line between boards A and B.
    pub ab: LinkModel,
}

impl Default for Links {
    fn default() -> Links {
        Links {
            wifi: LinkModel::wifi(),
            ground: LinkModel::serial(),
            ab: LinkModel::serial(),
        }
    }
}

/// A bug the engine's shells can be told to have, so that a test can show the fault swarm
/// finds it (`mmic swarm --plant-bug double-exec`). None is ever on in a plain run.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum PlantedBug {
    /// No bug.
    #[default]
    None,
    /// Board A's WiFi task hands a copy of a command the WiFi link duplicated to the control
    /// task with its sequence number cleared (an unsequenced command, which board A runs
    /// whatever its log says: the paper's scheme): a double execution on a duplicated packet.
    DoubleExec,
    /// Board A restarts without its exactly-once log (as if the shell never read flash back):
    /// a command resent after a restart runs again.
    LogNotRestored,
}

impl std::str::FromStr for PlantedBug {
    type Err = String;
    fn from_str(s: &str) -> Result<PlantedBug, String> {
        match s {
            "none" => Ok(PlantedBug::None),
            "double-exec" => Ok(PlantedBug::DoubleExec),
            "log-not-restored" => Ok(PlantedBug::LogNotRestored),
            _ => Err(format!(
                "{s:?} is no planted bug: none, double-exec or log-not-restored"
            )),
        }
    }
}

/// The hops of one robot's links, each one direction of a link.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Hop {
    GroundToServer = 0,
    ServerToGround = 1,
    ServerToA = 2,
    AToServer = 3,
    AToB = 4,
    BToA = 5,
}

/// Something that happens at a virtual instant.
#[derive(Debug)]
enum Ev {
    /// Every robot's board A control task ticks (in robot order; all boards A share a phase).
    TickA,
    /// Every robot's board B ticks (all boards B share their phase).
    TickB,
    /// Board A's WiFi task drains the heartbeat queue.
    Wifi(usize),
    /// Bytes arrive at the end of a hop (`conn`: the WiFi connection they were written to).
    Deliver {
        robot: usize,
        hop: Hop,
        conn: u64,
        bytes: Vec<u8>,
    },
    /// The server board's connection reaches board A's WiFi task.
    Open { robot: usize, conn: u64 },
    /// The server board's disconnection reaches board A's WiFi task.
    Close { robot: usize, conn: u64 },
    /// The server board stops waiting for the visit's heartbeat.
    VisitTimeout { robot: usize, conn: u64 },
    /// The server board's loop runs (the gateway's next deadline).
    Server { robot: usize, token: u64 },
    /// The ground's loop ticks every plan runner.
    GroundTick,
    /// A node of every robot restarts: it goes down now.
    Reboot(Node),
    /// Robot `robot`'s node comes up again after its boot.
    Up { robot: usize, node: Node },
}

struct Queued {
    at: u64,
    seq: u64,
    ev: Ev,
}

impl PartialEq for Queued {
    fn eq(&self, o: &Self) -> bool {
        (self.at, self.seq) == (o.at, o.seq)
    }
}
impl Eq for Queued {}
impl PartialOrd for Queued {
    fn partial_cmp(&self, o: &Self) -> Option<std::cmp::Ordering> {
        Some(self.cmp(o))
    }
}
impl Ord for Queued {
    fn cmp(&self, o: &Self) -> std::cmp::Ordering {
        (self.at, self.seq).cmp(&(o.at, o.seq))
    }
}

/// One robot, eight waiting telecommands, 64 remembered keys (as the realtime engine's).
type SimGateway = Gateway<1, 8, 64>;

/// The largest telemetry packet the gateway writes, bytes.
const MAX_TM_LEN: usize = mmic::ccsds::tm::TM_MIN_LEN + mmic::node::server::gateway::MAX_TM_DATA;

/// The PUS gateway behind the space data link (`--link frames`): the same sizes, 4 KiB of
/// TM packets waiting for frames. The replay's own type (`mmic_replay::ReplayFrameGateway`),
/// so that a recorded trace replays with the same sizes.
type SimFrameGateway = mmic_replay::ReplayFrameGateway;

/// The ground's end of a robot's space data link: FOP-1's window K = 10, 64 packets waiting,
/// packets of up to 1 KiB reassembled.
type SimGroundLink = GroundLink<10, 64, 1024>;

/// The server board's logic: the legacy relay, the PUS gateway, or the PUS gateway behind the
/// space data link.
enum Board {
    Relay(Server<4>),
    Gateway(Box<SimGateway>),
    Frames(Box<SimFrameGateway>),
}

/// One robot's nodes and links.
struct Robot {
    number: BoardNumber,
    names: [String; 4],
    a: SideA,
    b: SideB,
    plant: Plant,
    commands: PacketQueue<COMMAND_LEN, 8>,
    heartbeats: PacketQueue<HEARTBEAT_LEN, 8>,
    /// Board A's serial reader (from board B) and what it has deframed.
    a_reader: Deframer<256>,
    a_from_b: VecDeque<[u8; mmic::wire::internal_heartbeat::INTERNAL_HEARTBEAT_LEN]>,
    /// Board B's serial reader (from board A).
    b_reader: Deframer<256>,
    b_from_a: VecDeque<[u8; mmic::wire::b_command::B_COMMAND_LEN]>,
    b_lost: bool,
    /// Board A's WiFi task (the library's session) and its open connection's number.
    wifi: WifiSession,
    wifi_conn: u64,
    board: Board,
    /// The server board's visit in progress: its connection's number, the library's visit.
    visit: Option<(u64, Visit)>,
    /// Packets from the ground waiting for the server board's loop.
    inbox: VecDeque<Vec<u8>>,
    server_reader: Deframer<256>,
    /// The gateway's next wake, and its token (a wake with an older token is stale).
    server_wake: Option<(u64, u64)>,
    /// The ground's reader of this robot's serial line (legacy).
    ground_reader: Deframer<256>,
    /// The ground's end of the space data link (`--link frames`).
    ground_link: Option<Box<SimGroundLink>>,
    links: [Link; 6],
    /// The durable store of both ends (`sim::durable`): SDLS counters, FARM-1's progress, the
    /// kept telecommand keys behind frames. Memory for the run, or with given keys the state
    /// file: a server board or ground that starts again boots from it.
    store: super::durable::Durable,
    /// With SDLS and an attacker: the attacker on the uplink.
    attacker: Option<Attacker>,
    /// Board A's flash: its exactly-once log and boot count (decision `restart-board-a`).
    kept_a: Option<Durable>,
    /// The server board's flash without frames: its PUS gateway's newest TC key per source
    /// (`restart-server`; behind frames they are in `store`).
    kept_server: Kept,
    /// With SDLS: the robot's (TC, TM) keys, as provisioned in the server board's image.
    keys: Option<(Key256, Key256)>,
    /// Board A, board B, the server board: down (restarting) until their `Up` event.
    down: [bool; 4],
    /// The restarts of each node so far.
    restarts: [u32; 4],
    /// The space data link's figures of the ends' earlier lives (a restarted end counts
    /// from 0 again).
    past_frames: FrameStats,
}

/// The attacker on a robot's uplink ([`super::SdlsConfig::attack`]): it captures the TC data
/// frames the uplink delivers and, at its rate, sends one of them again or a copy with one bit
/// flipped (its FECF made good again). Its draws are its own stream, seeded from the robot's.
struct Attacker {
    rate: f64,
    rng: fastrand::Rng,
    /// The last [`Attacker::KEPT`] data frames the uplink delivered.
    captured: VecDeque<Vec<u8>>,
    /// Attack frames waiting for the server board's loop.
    waiting: VecDeque<Vec<u8>>,
    sent: u64,
    refused_sdls: u64,
    refused_frame: u64,
    passed: u64,
}

impl Attacker {
    const KEPT: usize = 64;

    /// The uplink delivered `frame`: captured if a data frame (BC frames go in clear by
    /// decision `sdls-clear-bc`), and maybe an attack frame made.
    fn delivered(&mut self, frame: &[u8]) {
        let data_frame = frame.first().is_some_and(|b| b & 0x10 == 0);
        if data_frame && frame.len() > 2 {
            if self.captured.len() == Self::KEPT {
                self.captured.pop_front();
            }
            self.captured.push_back(frame.to_vec());
        }
        if self.captured.is_empty() || self.rng.f64() >= self.rate {
            return;
        }
        let pick = self.rng.usize(..self.captured.len());
        let mut f = self.captured[pick].clone();
        match self.rng.u8(..3) {
            0 => {}
            1 => {
                let n = f.len();
                let bit = self.rng.usize(..(n - 2) * 8);
                f[bit / 8] ^= 0x80 >> (bit % 8);
                let crc = mmic::ccsds::pec(&f[..n - 2]);
                f[n - 2..].copy_from_slice(&crc.to_be_bytes());
            }
            _ => {
                // A BC frame (in clear by decision sdls-clear-bc) for the same spacecraft:
                // Set V(R) to any value, or Unlock, from the attacker's own address.
                use mmic::link::tc_frame::{
                    SpacecraftId, TcContent, TcFrameRepr, TcPrimaryHeader, Vcid,
                };
                let Some(h) = TcPrimaryHeader::read(&f) else {
                    return;
                };
                let command = if self.rng.bool() {
                    mmic::link::ControlCommand::Unlock
                } else {
                    mmic::link::ControlCommand::SetVr(self.rng.u8(..))
                };
                let repr = TcFrameRepr {
                    spacecraft_id: SpacecraftId::new(h.spacecraft_id).unwrap_or_default(),
                    vcid: Vcid::new(h.vcid).unwrap_or_default(),
                    seq: 0,
                    content: TcContent::Bc(command),
                };
                let mut b = [0u8; 16];
                let Ok(n) = repr.emit(&mut b) else {
                    return;
                };
                f = b[..n].to_vec();
            }
        }
        self.sent += 1;
        self.waiting.push_back(f);
    }
}

/// The engine's state for one run.
struct Engine<'c, G: Ground> {
    cfg: &'c SimConfig,
    now: u64,
    seq: u64,
    queue: BinaryHeap<Reverse<Queued>>,
    robots: Vec<Robot>,
    ground: GroundSide<G>,
    log: Option<Log>,
    packet_log: bool,
    conns: u64,
    tokens: u64,
    watch: Option<Watch>,
    status: Value,
    /// Robot 1's replay trace, when recording.
    trace: Option<Vec<u8>>,
    /// Accepted executions of each (robot, sequence number ≠ 0) by board A.
    executions: std::collections::HashMap<(usize, u16), u32>,
}

/// Runs the simulation to the end of every robot's plan (or the time limit) in virtual time.
pub fn run(cfg: &SimConfig) -> std::io::Result<Summary> {
    run_watched(cfg, false).map(|(s, _)| s)
}

/// [`run`], also watching the invariants of the fault swarm on every tick ([`watch`]) when
/// `watched`.
pub fn run_watched(cfg: &SimConfig, watched: bool) -> std::io::Result<(Summary, Option<Watch>)> {
    if cfg.external.is_some() {
        return Err(std::io::Error::other(
            "an external ground runs on the wall clock: use the realtime engine",
        ));
    }
    if cfg.record.is_some() && cfg.sdls.as_ref().is_some_and(|s| s.trace_keys().is_none()) {
        return Err(std::io::Error::other(
            "a replay trace holds only test keys made for it: --record runs without --sdls",
        ));
    }
    let n = cfg.robots.max(1) as usize;
    match cfg.protocol {
        Protocol::Legacy => {
            let runners = (0..n)
                .map(|i| LegacyGround {
                    run: PlanRunner::new(cfg.ground, board_number(i)),
                    last: None,
                })
                .collect();
            Engine::new(cfg, runners, watched)?.run()
        }
        Protocol::Pus => {
            let runners = (0..n)
                .map(|i| PlanRunner::pus(cfg.ground_pus(), board_number(i)))
                .collect();
            Engine::new(cfg, runners, watched)?.run()
        }
    }
}

/// Robot `i`'s board number: 1..=255 by index (each robot has its own server board, so
/// numbers may repeat in a larger fleet: they only need to match between a robot's ground
/// runner, server board and board A).
fn board_number(i: usize) -> BoardNumber {
    BoardNumber::new((i % 255) as u8 + 1).unwrap_or(BoardNumber::ONE)
}

impl<'c, G: Ground> Engine<'c, G> {
    fn new(cfg: &'c SimConfig, runners: Vec<G>, watched: bool) -> std::io::Result<Engine<'c, G>> {
        let n = runners.len();
        let secured = cfg.sdls.is_some() && cfg.link == LinkLayer::Frames;
        let log = (cfg.log_events || cfg.log_packets || cfg.log_path.is_some())
            .then(|| Log::memory().secured(secured));
        let ground = GroundSide::new(
            &cfg.steps,
            cfg.start_state,
            &cfg.injections,
            runners,
            cfg.progress,
            log.clone(),
        );
        let state = match &cfg.sdls {
            Some(s) if cfg.link == LinkLayer::Frames => s.open_state()?,
            _ => None,
        };
        let robots = (0..n)
            .map(|i| Robot::new(cfg, i, state.as_ref()))
            .collect::<std::io::Result<_>>()?;
        let mut e = Engine {
            cfg,
            now: 0,
            seq: 0,
            queue: BinaryHeap::new(),
            robots,
            ground,
            log,
            packet_log: cfg.log_packets,
            conns: 0,
            tokens: 0,
            watch: watched.then(|| Watch::new(cfg, n)),
            status: Value::Null,
            executions: Default::default(),
            trace: cfg.record.as_ref().map(|_| {
                let mut t = Vec::new();
                record_header(cfg).emit(&mut t);
                t
            }),
        };
        e.at(0, Ev::TickA);
        e.at(cfg.b_phase_us % 10_000, Ev::TickB);
        if cfg.protocol == Protocol::Pus {
            for i in 0..n {
                e.wake_server(i, 0);
                // The ground initiates the AD service; it runs once a CLCW confirms it.
                if let Some(gl) = e.robots[i].ground_link.as_mut() {
                    gl.start(0, &mut |_: &[u8]| {});
                }
            }
        }
        e.at(0, Ev::GroundTick);
        for s in &cfg.injections {
            if let Injection::Reboot(node) = s.injection {
                e.at(u64::from(s.at_ms) * 1000, Ev::Reboot(node));
            }
        }
        Ok(e)
    }

    fn at(&mut self, at: u64, ev: Ev) {
        self.seq += 1;
        self.queue.push(Reverse(Queued {
            at,
            seq: self.seq,
            ev,
        }));
    }

    fn now_ms(&self) -> u32 {
        (self.now / 1000) as u32
    }

    /// Appends robot `i`'s call to the replay trace, if recording (robot 1 only).
    fn record<'b>(&mut self, i: usize, r: impl FnOnce(u32) -> Record<'b>) {
        if i == 0 {
            let t = self.now_ms();
            if let Some(trace) = &mut self.trace {
                r(t).emit(trace);
            }
        }
    }

    fn run(mut self) -> std::io::Result<(Summary, Option<Watch>)> {
        let wall = Instant::now();
        let max_us = (self.cfg.max_sim_ms as u64 + 1) * 1000;
        while let Some(Reverse(q)) = self.queue.pop() {
            if q.at > max_us {
                break;
            }
            self.now = q.at;
            if !self.handle(q.ev) {
                break;
            }
        }
        let now = self.now_ms();
        if let Some(w) = &mut self.watch {
            for i in 0..self.robots.len() {
                w.finish(i, now, &self.ground.open_commands(i));
            }
            // SDLS: the server board verified no more TC frames than the ground protected
            // (over every life of each end).
            for (i, r) in self.robots.iter().enumerate() {
                if let Some(x) = r.frames().sdls {
                    w.sdls_checked(i, now, x.server.verified, x.ground.protected);
                }
            }
        }
        if let Some(r) = self.robots.first() {
            self.status = r.a.status(now - now % TICK_MS);
        }
        if let (Some(p), Some(t)) = (&self.cfg.record, &self.trace) {
            std::fs::write(p, t)?;
        }
        let frames = self.frame_stats();
        let (ends, stats) = self.ground.finish(now);
        let records = self.log.as_ref().map(Log::take).unwrap_or_default();
        if let Some(p) = &self.cfg.log_path {
            let f = std::fs::File::create(p)?;
            log::write_lines(&records, &mut std::io::BufWriter::new(f))?;
        }
        let mut restarts = [0u32; 4];
        for r in &self.robots {
            for (t, n) in restarts.iter_mut().zip(r.restarts) {
                *t += n;
            }
        }
        let summary = Summary {
            frames,
            executed_twice: self.executions.values().filter(|&&n| n > 1).count() as u64,
            restarts,
            ..Summary::of_run(self.cfg, ends, stats, records, self.status, wall.elapsed())
        };
        Ok((summary, self.watch))
    }

    /// Handles one event; false when the run is over.
    fn handle(&mut self, ev: Ev) -> bool {
        match ev {
            Ev::TickA => {
                for i in 0..self.robots.len() {
                    self.tick_a(i);
                }
                self.at(self.now + TICK_MS as u64 * 1000, Ev::TickA);
            }
            Ev::TickB => {
                for i in 0..self.robots.len() {
                    self.tick_b(i);
                }
                self.at(self.now + TICK_MS as u64 * 1000, Ev::TickB);
            }
            Ev::Wifi(i) => self.wifi_drain(i),
            Ev::Deliver {
                robot,
                hop,
                conn,
                bytes,
            } => self.deliver(robot, hop, conn, bytes),
            Ev::Open { robot, conn } if !self.robots[robot].down[Node::A as usize] => {
                self.wifi_opened(robot, conn)
            }
            Ev::Open { .. } => {}
            Ev::Close { robot, conn } => {
                let r = &mut self.robots[robot];
                if r.wifi_conn == conn && r.wifi.close() {
                    self.record(robot, |t| Record::WifiClose { t });
                }
            }
            Ev::VisitTimeout { robot, conn } => {
                let now = self.now_ms();
                let due = |(c, v): &(u64, Visit)| *c == conn && v.left_ms(now).is_none();
                if self.robots[robot].visit.as_ref().is_some_and(due) {
                    self.end_visit(robot);
                    self.server_loop(robot);
                }
            }
            Ev::Server { robot, token } => {
                if self.robots[robot].server_wake.map(|(_, t)| t) == Some(token) {
                    self.robots[robot].server_wake = None;
                    self.server_loop(robot);
                }
            }
            Ev::GroundTick => return self.ground_tick(),
            Ev::Reboot(node) => {
                for i in 0..self.robots.len() {
                    self.down(i, node);
                }
            }
            Ev::Up { robot, node } => self.up(robot, node),
        }
        true
    }

    /// Robot `i`'s `node` goes down (a power cycle): what it held in RAM is gone, its
    /// connections drop, its outputs are unpowered; it comes up [`BOOT_MS`] later.
    fn down(&mut self, i: usize, node: Node) {
        let now = self.now_ms();
        let r = &mut self.robots[i];
        let k = node as usize;
        if r.down[k] {
            return; // already restarting: one boot
        }
        r.down[k] = true;
        r.restarts[k] += 1;
        match node {
            Node::A => {
                r.commands = PacketQueue::new();
                r.heartbeats = PacketQueue::new();
                r.a_reader = Deframer::new();
                r.a_from_b.clear();
                r.wifi = WifiSession::new(WifiConfig::default());
                r.wifi_conn = 0;
                r.plant.advance(now);
                r.plant.drive_a(Drives::off(), None);
                if let Some(w) = &mut self.watch {
                    w.restarted_a(i, now);
                }
            }
            Node::B => {
                r.b_reader = Deframer::new();
                r.b_from_a.clear();
                r.plant.advance(now);
                r.plant.drive_b(Drives::off());
            }
            Node::Server => {
                r.visit = None;
                r.inbox.clear();
                r.server_reader = Deframer::new();
                r.server_wake = None;
                if let Some(a) = &mut r.attacker {
                    a.waiting.clear();
                }
                if let Board::Frames(g) = &r.board {
                    r.past_frames.add_server(g, r.number);
                }
            }
            Node::Ground => {
                r.ground_reader = Deframer::new();
                if let Some(gl) = r.ground_link.take() {
                    r.past_frames.add_ground(&gl);
                }
            }
        }
        self.node_event(i, k, json!({"type": "restart", "down_ms": BOOT_MS}));
        self.at(
            self.now + u64::from(BOOT_MS) * 1000,
            Ev::Up { robot: i, node },
        );
    }

    /// Robot `i`'s `node` boots from what it kept (decisions `restart-*`).
    fn up(&mut self, i: usize, node: Node) {
        let cfg = self.cfg;
        let r = &mut self.robots[i];
        r.down[node as usize] = false;
        match node {
            Node::A => {
                let kept = match cfg.planted_bug {
                    PlantedBug::LogNotRestored => None,
                    _ => r.kept_a,
                };
                let board = BoardA::restarted(
                    board_a::Config {
                        board: r.number,
                        ..board_a::Config::default()
                    },
                    kept,
                    ResetCause::PowerOn,
                );
                r.kept_a = Some(board.durable());
                r.a = SideA::new(board);
            }
            Node::B => r.b = SideB::new(BoardB::restarted(board_b::Config::default())),
            Node::Server => {
                // A store the run provisioned itself boots: a refusal here would be the
                // simulator's fault, and the server board then stays down (its link stopped).
                match server_board(
                    cfg,
                    r.number,
                    Some(r.kept_server.clone()),
                    &r.store,
                    r.keys.clone(),
                ) {
                    Ok(b) => r.board = b,
                    Err(e) => {
                        // Nothing reaches a stopped link: it stays down.
                        r.down[Node::Server as usize] = true;
                        let why = e.to_string();
                        self.node_event(i, 2, json!({"type": "link_stopped", "why": why}));
                        return;
                    }
                }
                self.wake_server(i, self.now);
            }
            Node::Ground => {
                let now = self.now_ms();
                self.ground.restart(i, now);
                let r = &mut self.robots[i];
                if cfg.protocol == Protocol::Pus && cfg.link == LinkLayer::Frames {
                    // FOP-1 starts afresh (its AD service initiated again with a CLCW check);
                    // SDLS continues from the stored counters (decision `sdls-counters`).
                    let mut gl = Box::new(SimGroundLink::new(r.number));
                    if let Some(keys) = r.keys.clone() {
                        if let Err(e) =
                            super::durable::boot_ground(&mut gl, r.number, &r.store, keys)
                        {
                            // The link stopped: the ground's end of it is gone with its RAM.
                            r.ground_link = None;
                            let why = e.to_string();
                            self.node_event(i, 3, json!({"type": "link_stopped", "why": why}));
                            return;
                        }
                    }
                    gl.start(now, &mut |_: &[u8]| {});
                    r.ground_link = Some(gl);
                    r.persist();
                }
            }
        }
        let boot = match node {
            Node::A => json!(self.robots[i].a.board.boot().to_wire()),
            _ => Value::Null,
        };
        self.node_event(i, node as usize, json!({"type": "boot", "boot": boot}));
    }

    /// Logs robot `i`'s event from its node `node` (0 board A, 1 board B, 2 the server board).
    fn node_event(&self, i: usize, node: usize, what: Value) {
        if let (Some(l), true) = (&self.log, self.cfg.log_events) {
            l.event(self.now_ms(), &self.robots[i].names[node], what);
        }
    }

    /// Writes `bytes` to robot `i`'s `hop` at the current instant: logged with its fate, and
    /// delivered (once or twice) unless lost or cut.
    fn send(&mut self, i: usize, hop: Hop, conn: u64, bytes: &[u8]) -> Fate {
        let now = self.now;
        let sent = self.robots[i].links[hop as usize].send(now);
        if self.packet_log {
            if let Some(l) = &self.log {
                let (link, from, to) = self.robots[i].ends(hop, self.cfg.protocol);
                let t = self.now_ms();
                l.packet(t, link, from, to, sent.fate.name(), bytes);
                if sent.at_us.len() > 1 {
                    l.packet(t, link, from, to, "duplicated", bytes);
                }
            }
        }
        for (k, at) in sent.at_us.iter().enumerate() {
            self.at(
                *at,
                Ev::Deliver {
                    robot: i,
                    hop,
                    conn: if k == 0 { conn } else { conn | DUPLICATE },
                    bytes: bytes.to_vec(),
                },
            );
        }
        sent.fate
    }

    fn ground_tick(&mut self) -> bool {
        let now = self.now_ms();
        let over = self.ground.all_done() && !self.cfg.run_to_end;
        if now > self.cfg.max_sim_ms || over {
            return false;
        }
        self.ground_links_tick();
        for i in 0..self.robots.len() {
            if self.robots[i].down[Node::Ground as usize] {
                continue;
            }
            for p in self.ground.tick(i, now) {
                self.ground_sends(i, &p);
            }
        }
        self.ground.progress(now);
        if self.ground.all_done() && !self.cfg.run_to_end {
            return false;
        }
        self.at(self.now + GROUND_TICK_MS as u64 * 1000, Ev::GroundTick);
        true
    }

    /// The ground writes `p` to robot `i`'s server board (through FOP-1 with `--link frames`:
    /// the frames due go out).
    fn ground_sends(&mut self, i: usize, p: &[u8]) {
        if self.cfg.protocol == Protocol::Legacy {
            if let Some(w) = &mut self.watch {
                w.commanded(i, p);
            }
        }
        let now = self.now_ms();
        self.robots[i].persist();
        if let Some(gl) = self.robots[i].ground_link.as_mut() {
            let mut frames = Vec::new();
            if gl
                .send(p, now, &mut |f: &[u8]| frames.push(f.to_vec()))
                .is_err()
            {
                self.node_event(i, 2, json!({"type": "ground_outbox_full"}));
            }
            for f in frames {
                self.send(i, Hop::GroundToServer, 0, &f);
            }
            return;
        }
        self.send(i, Hop::GroundToServer, 0, p);
    }

    /// A TM frame reaches the ground's end of robot `i`'s link: its CLCW to FOP-1 (frames
    /// it sends again go out), its packets returned.
    fn tm_frame_at_ground(&mut self, i: usize, bytes: &[u8]) -> Vec<Vec<u8>> {
        let now = self.now_ms();
        let (mut frames, mut packets) = (Vec::new(), Vec::new());
        self.robots[i].persist();
        if let Some(gl) = self.robots[i].ground_link.as_mut() {
            let refused = gl.tm_frame(
                now,
                bytes,
                &mut |f: &[u8]| frames.push(f.to_vec()),
                &mut |p: &[u8]| packets.push(p.to_vec()),
            );
            if let Err(e) = refused {
                self.node_event(i, 2, json!({"type": "tm_frame_refused", "check": e.name()}));
            }
        }
        for f in frames {
            self.send(i, Hop::GroundToServer, 0, &f);
        }
        packets
    }

    /// The ground's end of every link: timer T1.
    fn ground_links_tick(&mut self) {
        let now = self.now_ms();
        for i in 0..self.robots.len() {
            let mut frames = Vec::new();
            self.robots[i].persist();
            if let Some(gl) = self.robots[i].ground_link.as_mut() {
                gl.tick(now, &mut |f: &[u8]| frames.push(f.to_vec()));
            }
            for f in frames {
                self.send(i, Hop::GroundToServer, 0, &f);
            }
        }
    }

    fn deliver(&mut self, i: usize, hop: Hop, conn: u64, bytes: Vec<u8>) {
        // A node that is down (restarting) hears nothing.
        let to = match hop {
            Hop::GroundToServer | Hop::AToServer => Some(Node::Server),
            Hop::ServerToA | Hop::BToA => Some(Node::A),
            Hop::AToB => Some(Node::B),
            Hop::ServerToGround => Some(Node::Ground),
        };
        if let Some(n) = to {
            if self.robots[i].down[n as usize] {
                if self.packet_log {
                    if let Some(l) = &self.log {
                        let (link, from, to) = self.robots[i].ends(hop, self.cfg.protocol);
                        l.packet(self.now_ms(), link, from, to, "node_down", &bytes);
                    }
                }
                return;
            }
        }
        match hop {
            Hop::GroundToServer => {
                self.record(i, |t| Record::ServerIn { t, bytes: &bytes });
                let r = &mut self.robots[i];
                match r.board {
                    Board::Relay(_) => {
                        for f in frames(&mut r.server_reader, &bytes) {
                            r.inbox.push_back(f.as_bytes().to_vec());
                        }
                    }
                    Board::Gateway(_) => r.inbox.push_back(bytes),
                    Board::Frames(_) => {
                        if let Some(a) = &mut r.attacker {
                            a.delivered(&bytes);
                        }
                        r.inbox.push_back(bytes);
                    }
                }
                self.server_loop(i);
            }
            Hop::ServerToGround => {
                let now = self.now_ms();
                let packets = match self.cfg.protocol {
                    Protocol::Legacy => frames(&mut self.robots[i].ground_reader, &bytes)
                        .into_iter()
                        .map(|f| f.as_bytes().to_vec())
                        .collect(),
                    Protocol::Pus if self.cfg.link == LinkLayer::Frames => {
                        self.tm_frame_at_ground(i, &bytes)
                    }
                    Protocol::Pus => vec![bytes],
                };
                for p in packets {
                    for out in self.ground.receive(i, now, &p) {
                        self.ground_sends(i, &out);
                    }
                }
            }
            Hop::ServerToA => self.wifi_bytes(i, conn, &bytes),
            Hop::AToServer => self.heartbeat_at_server(i, conn, &bytes),
            Hop::AToB => {
                self.record(i, |t| Record::ToB { t, bytes: &bytes });
                let r = &mut self.robots[i];
                for f in frames(&mut r.b_reader, &bytes) {
                    if let Ok(p) = f.as_bytes().try_into() {
                        r.b_from_a.push_back(p);
                    }
                }
            }
            Hop::BToA => {
                self.record(i, |t| Record::ToA { t, bytes: &bytes });
                let r = &mut self.robots[i];
                for f in frames(&mut r.a_reader, &bytes) {
                    if let Ok(p) = f.as_bytes().try_into() {
                        r.a_from_b.push_back(p);
                    }
                }
            }
        }
    }

    /// Board A's control task: one tick (while board A is down, the plant alone moves on).
    fn tick_a(&mut self, i: usize) {
        let now = self.now_ms();
        let r = &mut self.robots[i];
        if r.down[Node::A as usize] {
            r.plant.advance(now);
            return;
        }
        let command = r.commands.split().1.pop();
        // Board A's flash: the record written before a tick that may run a new sequenced
        // command, then after the tick (decision `restart-board-a`).
        if let Some(d) = r.a.board.ahead(command.as_ref()) {
            r.kept_a = Some(d);
        }
        let from_b = r.a_from_b.pop_front();
        let out = r.a.tick(&mut r.plant, now, command, from_b);
        r.kept_a = Some(r.a.board.durable());
        for e in &out.events {
            // Nothing but a Heartbeat poll may run twice (`BoardA::may_run_again`).
            if let board_a::Event::Executed {
                seq,
                refusal: None,
                command,
            } = e
            {
                if *seq != 0 && !mmic::node::robot::board_a::BoardA::may_run_again(*command) {
                    *self.executions.entry((i, *seq)).or_default() += 1;
                }
            }
        }
        let r = &mut self.robots[i];
        if let Some(s) = r.a.sensed {
            self.record(i, |t| Record::TickA {
                t,
                reading: reading(&s),
            });
        }
        let r = &mut self.robots[i];
        if let Some(w) = &mut self.watch {
            w.tick_a(
                i,
                now,
                &watch::TickA::of(command, &r.a.board, &r.plant, &out),
            );
        }
        if self.cfg.log_events {
            for e in &out.events {
                self.node_event(i, 0, super::shell::event_json(e));
            }
        }
        if let Some(b) = out.to_b {
            self.send(i, Hop::AToB, 0, &b);
        }
        if let Some(hb) = out.heartbeat {
            let r = &mut self.robots[i];
            if let Err(full) = r.heartbeats.split().0.push(hb) {
                self.node_event(
                    i,
                    0,
                    json!({"type": "handoff_full", "hex": log::hex(&full.0)}),
                );
            }
            self.at(self.now + WIFI_TASK_US, Ev::Wifi(i));
        }
    }

    /// Board B: one tick (none while it is down).
    fn tick_b(&mut self, i: usize) {
        let now = self.now_ms();
        let r = &mut self.robots[i];
        if r.down[Node::B as usize] {
            return;
        }
        let command = r.b_from_a.pop_front();
        let out = r.b.tick(&mut r.plant, now, command);
        if let Some(s) = r.b.sensed {
            self.record(i, |t| Record::TickB {
                t,
                reading: reading(&s),
            });
        }
        let r = &mut self.robots[i];
        if let Some(w) = &mut self.watch {
            w.tick_b(i, now, &watch::SideMotion::of(&r.plant, 1));
        }
        if out.link_lost != r.b_lost {
            r.b_lost = out.link_lost;
            let holding = r.b_lost;
            self.node_event(i, 1, json!({"type": "link_lost", "holding": holding}));
        }
        if let Some(hb) = out.heartbeat {
            self.send(i, Hop::BToA, 0, &hb);
        }
    }

    /// Board A's WiFi task takes a connection: heartbeats made while nobody was connected
    /// are discarded (the library's session says so), then it serves this one.
    fn wifi_opened(&mut self, i: usize, conn: u64) {
        self.record(i, |t| Record::WifiOpen { t });
        let now = self.now_ms();
        let r = &mut self.robots[i];
        r.wifi_conn = conn;
        let (_, mut queued) = r.heartbeats.split();
        let mut stale = Vec::new();
        r.wifi.open(now, std::iter::from_fn(|| queued.pop()), |hb| {
            stale.push(hb)
        });
        for hb in stale {
            self.unconnected(i, &hb);
        }
    }

    /// Logs a heartbeat board A's WiFi task dropped with no server connected.
    fn unconnected(&self, i: usize, hb: &[u8]) {
        if self.packet_log {
            if let Some(l) = &self.log {
                let r = &self.robots[i];
                l.packet(
                    self.now_ms(),
                    "wifi",
                    &r.names[0],
                    &r.names[2],
                    "unconnected",
                    hb,
                );
            }
        }
    }

    /// Board A's WiFi task writes the queued heartbeats to the open connection (or drops
    /// them, unconnected).
    fn wifi_drain(&mut self, i: usize) {
        self.record(i, |t| Record::WifiDrain { t });
        while let Some(hb) = self.robots[i].heartbeats.split().1.pop() {
            let r = &mut self.robots[i];
            match r.wifi.heartbeat(hb) {
                Outgoing::Send(hb) => {
                    let conn = r.wifi_conn;
                    self.send(i, Hop::AToServer, conn, &hb);
                }
                Outgoing::Drop(hb) => self.unconnected(i, &hb),
            }
        }
    }

    /// Command bytes reach board A's WiFi task on connection `conn`.
    fn wifi_bytes(&mut self, i: usize, conn: u64, bytes: &[u8]) {
        let copy = conn & DUPLICATE != 0;
        let r = &mut self.robots[i];
        if !r.wifi.is_open() || r.wifi_conn != conn & !DUPLICATE {
            self.node_event(i, 0, json!({"type": "wifi_closed", "hex": log::hex(bytes)}));
            return;
        }
        self.record(i, |t| Record::WifiBytes { t, bytes });
        let now = self.now_ms();
        let r = &mut self.robots[i];
        let mut packets: Vec<[u8; COMMAND_LEN]> = Vec::new();
        r.wifi.received(now, bytes, |c| packets.push(c));
        if copy && self.cfg.planted_bug == PlantedBug::DoubleExec {
            for p in packets.iter_mut() {
                if let Ok(mut c) = CommandRepr::parse(p) {
                    let origin = *p;
                    c.seq = 0;
                    *p = c.to_bytes();
                    if let Some(w) = &mut self.watch {
                        w.same_origin(i, &origin, p);
                    }
                }
            }
        }
        for p in packets {
            let r = &mut self.robots[i];
            if let Err(full) = r.commands.split().0.push(p) {
                self.node_event(
                    i,
                    0,
                    json!({"type": "handoff_full", "hex": log::hex(&full.0)}),
                );
            }
        }
    }

    /// A heartbeat reaches the server board on connection `conn`.
    fn heartbeat_at_server(&mut self, i: usize, conn: u64, bytes: &[u8]) {
        let now = self.now_ms();
        let r = &mut self.robots[i];
        let current = r
            .visit
            .as_ref()
            .is_some_and(|(c, _)| *c == conn & !DUPLICATE);
        if !current {
            self.node_event(
                i,
                2,
                json!({"type": "heartbeat_after_visit", "hex": log::hex(bytes)}),
            );
            return;
        }
        self.record(i, |t| Record::ServerHeartbeat { t, bytes });
        let r = &mut self.robots[i];
        let Some((_, v)) = r.visit.as_mut() else {
            return;
        };
        let Some(hb) = v.received(bytes) else {
            return;
        };
        match &mut r.board {
            Board::Relay(_) => {
                self.end_visit(i);
                self.send(i, Hop::ServerToGround, 0, &hb);
            }
            Board::Gateway(g) => {
                let out = HeartbeatRepr::parse(&hb).map(|h| g.heartbeat(now, &h));
                self.end_visit(i);
                if let Ok(out) = out {
                    self.reports(i, out);
                }
            }
            Board::Frames(g) => {
                if let Ok(h) = HeartbeatRepr::parse(&hb) {
                    g.heartbeat(now, &h);
                }
                self.end_visit(i);
                self.tm_frames(i);
            }
        }
        self.server_loop(i);
    }

    /// The server board closes the visit's connection.
    fn end_visit(&mut self, i: usize) {
        if let Some((conn, _)) = self.robots[i].visit.take() {
            let at = self.now
                + self.robots[i].links[Hop::ServerToA as usize]
                    .model()
                    .latency_us;
            self.at(at, Ev::Close { robot: i, conn });
        }
    }

    /// The server board opens a connection to board A and writes the visit's packet to it.
    fn start_visit(&mut self, i: usize, visit: Visit) {
        let packet = *visit.packet();
        let wait_ms = visit.deadline().wrapping_sub(self.now_ms());
        self.conns += 1;
        let conn = self.conns;
        let at = self.now
            + self.robots[i].links[Hop::ServerToA as usize]
                .model()
                .latency_us;
        self.at(at, Ev::Open { robot: i, conn });
        self.robots[i].visit = Some((conn, visit));
        if self.cfg.protocol == Protocol::Pus {
            if let Some(w) = &mut self.watch {
                w.commanded(i, &packet);
            }
        }
        self.send(i, Hop::ServerToA, conn, &packet);
        self.at(
            self.now + wait_ms as u64 * 1000,
            Ev::VisitTimeout { robot: i, conn },
        );
    }

    /// The server board's loop, between visits: the ground's packets, then the next visit.
    fn server_loop(&mut self, i: usize) {
        if self.robots[i].visit.is_some() || self.robots[i].down[Node::Server as usize] {
            return;
        }
        self.record(i, |t| Record::ServerLoop { t });
        let now = self.now_ms();
        let inbox: Vec<Vec<u8>> = self.robots[i].inbox.drain(..).collect();
        let number = self.robots[i].number;
        if let Board::Relay(_) = self.robots[i].board {
            for p in inbox {
                let Board::Relay(srv) = &mut self.robots[i].board else {
                    return;
                };
                let Ok(packet) = <[u8; COMMAND_LEN]>::try_from(p.as_slice()) else {
                    continue;
                };
                let what = match srv.accept(&packet) {
                    Ok(Accepted::Queued) => json!({"type": "queued"}),
                    Ok(Accepted::Resend) => json!({"type": "resend"}),
                    Ok(Accepted::Superseded(old)) => {
                        json!({"type": "superseded", "old": log::hex(&old)})
                    }
                    Err(e) => json!({"type": "refused", "error": e.to_string()}),
                };
                self.node_event(i, 2, what);
            }
            let Board::Relay(srv) = &mut self.robots[i].board else {
                return;
            };
            if let Some(visit) = Visit::next(srv, now, self.cfg.visit_ms) {
                // The engine's write to the link cannot fail (the link may lose it).
                visit.written(srv);
                if visit.board() == number {
                    self.start_visit(i, visit);
                } else {
                    let board = visit.board().get();
                    self.node_event(i, 2, json!({"type": "no_such_robot", "board": board}));
                }
            }
            return;
        }
        if let Board::Frames(_) = self.robots[i].board {
            self.frames_loop(i, inbox);
            return;
        }
        for p in inbox {
            let Board::Gateway(g) = &mut self.robots[i].board else {
                return;
            };
            match g.tc_packet(&p) {
                Ok(out) => self.reports(i, out),
                Err(e) => self.node_event(
                    i,
                    2,
                    json!({"type": "tc_refused", "error": e.to_string(), "hex": log::hex(&p)}),
                ),
            }
        }
        let Board::Gateway(g) = &mut self.robots[i].board else {
            return;
        };
        let out = g.tick(now);
        let visit = out
            .to_robots
            .iter()
            .find(|(b, _)| *b == number)
            .map(|(_, c)| c.to_bytes());
        self.reports(i, out);
        if let Some(packet) = visit {
            let wait = self.cfg.gateway.uplink.timeout_ms;
            self.start_visit(i, Visit::new(now, number, packet, wait));
            return;
        }
        let Board::Gateway(g) = &self.robots[i].board else {
            return;
        };
        if let Some(t) = g.next_deadline(now) {
            let at = (t.max(now.saturating_add(1)) as u64) * 1000;
            self.wake_server(i, at);
        }
    }

    /// The server board's loop behind the space data link: the ground's TC frames through
    /// FARM-1 into the gateway, the gateway's tick, the TM frames due, the next visit.
    fn frames_loop(&mut self, i: usize, inbox: Vec<Vec<u8>>) {
        let now = self.now_ms();
        let number = self.robots[i].number;
        self.robots[i].persist();
        let attacks: Vec<Vec<u8>> = self.robots[i]
            .attacker
            .as_mut()
            .map(|a| a.waiting.drain(..).collect())
            .unwrap_or_default();
        let secured = self.cfg.sdls.is_some();
        let frames = inbox
            .into_iter()
            .map(|f| (f, false))
            .chain(attacks.into_iter().map(|f| (f, true)));
        for (f, attack) in frames {
            let Board::Frames(g) = &mut self.robots[i].board else {
                return;
            };
            // The attacker sends from its own address (decision sdls-bc-origin).
            let origin = if attack {
                mmic::node::server::frames::Origin::Elsewhere
            } else {
                mmic::node::server::frames::Origin::Ground
            };
            let got = g.tc_frame_from(now, &f, origin);
            // The security header as sent (never the key; the data stays ciphertext).
            let sec = if secured {
                log::sdls_header(&f)
            } else {
                Value::Null
            };
            if attack {
                self.attack_outcome(i, now, &f, &got.verdict);
            }
            match got.verdict {
                Err(e) => {
                    let mut ev = json!({"type": "tc_frame_refused", "check": e.name(),
                                        "layer": e.layer(), "hex": log::hex(&f)});
                    if secured {
                        ev["sdls"] = sec;
                        ev["attack"] = json!(attack);
                    }
                    self.node_event(i, 2, ev);
                }
                Ok(v) if self.packet_log => {
                    let mut ev = json!({"type": "tc_frame", "farm": format!("{v:?}"),
                                        "packets": got.accepted, "refused": got.refused});
                    if secured {
                        ev["sdls"] = sec;
                    }
                    self.node_event(i, 2, ev);
                }
                Ok(_) => {}
            }
        }
        let r = &mut self.robots[i];
        let Board::Frames(g) = &mut r.board else {
            return;
        };
        // The store written first; a telecommand held until it says so leaves in this pass.
        let visit = super::durable::tick_gateway(g, &r.store, now)
            .iter()
            .find(|(b, _)| *b == number)
            .map(|(_, c)| c.to_bytes());
        self.tm_frames(i);
        if let Some(packet) = visit {
            let wait = self.cfg.gateway.uplink.timeout_ms;
            self.start_visit(i, Visit::new(now, number, packet, wait));
            return;
        }
        let Board::Frames(g) = &self.robots[i].board else {
            return;
        };
        if let Some(t) = g.next_deadline(now) {
            let at = (t.max(now.saturating_add(1)) as u64) * 1000;
            self.wake_server(i, at);
        }
    }

    /// What became of an attack frame: counted, and none may reach FARM-1 (the watch's
    /// `forged-frame`).
    fn attack_outcome(
        &mut self,
        i: usize,
        now: u32,
        f: &[u8],
        verdict: &Result<mmic::link::farm::Verdict, mmic::node::server::frames::FrameRefusal>,
    ) {
        let Some(a) = self.robots[i].attacker.as_mut() else {
            return;
        };
        if let Some(w) = &mut self.watch {
            w.attack_judged();
        }
        match verdict {
            Err(e) if e.layer() == "sdls" => a.refused_sdls += 1,
            Err(_) => a.refused_frame += 1,
            Ok(v) => {
                a.passed += 1;
                let detail = format!(
                    "an attack frame reached FARM-1 ({v:?}): {}",
                    log::hex(f.get(..24).unwrap_or(f))
                );
                if let Some(w) = &mut self.watch {
                    w.forged(i, now, detail);
                }
            }
        }
    }

    /// The TM frames due at robot `i`'s server board, sent to the ground.
    fn tm_frames(&mut self, i: usize) {
        let now = self.now_ms();
        self.robots[i].persist();
        let mut out = Vec::new();
        if let Board::Frames(g) = &mut self.robots[i].board {
            let mut buf = [0u8; mmic::link::tm_frame::TM_FRAME_LEN];
            while let Some((_, n)) = g.frame(now, &mut buf) {
                out.push(buf.get(..n).unwrap_or(&[]).to_vec());
            }
        }
        for f in out {
            self.send(i, Hop::ServerToGround, 0, &f);
        }
    }

    /// The space data link's figures of the run, all robots.
    fn frame_stats(&self) -> Option<FrameStats> {
        if self.cfg.link != LinkLayer::Frames || self.cfg.protocol != Protocol::Pus {
            return None;
        }
        let mut s = FrameStats::default();
        for r in &self.robots {
            s = s.merged(r.frames());
            if let (Some(a), Some(sdls)) = (&r.attacker, s.sdls.as_mut()) {
                sdls.attack_frames += a.sent;
                sdls.attacks_refused_sdls += a.refused_sdls;
                sdls.attacks_refused_frame += a.refused_frame;
                sdls.attacks_passed += a.passed;
            }
        }
        Some(s)
    }

    /// Schedules the gateway's loop at `at` (µs) unless it runs sooner already.
    fn wake_server(&mut self, i: usize, at: u64) {
        if self.robots[i].server_wake.is_some_and(|(t, _)| t <= at) {
            return;
        }
        self.tokens += 1;
        let token = self.tokens;
        self.robots[i].server_wake = Some((at, token));
        self.at(at, Ev::Server { robot: i, token });
    }

    /// The gateway's reports, written to the ground.
    fn reports<const M: usize>(&mut self, i: usize, out: Out<M>) {
        let now = self.now_ms();
        if out.overflow > 0 {
            self.node_event(i, 2, json!({"type": "overflow", "count": out.overflow}));
        }
        for tm in &out.reports {
            let Board::Gateway(g) = &mut self.robots[i].board else {
                return;
            };
            let mut b = [0u8; MAX_TM_LEN];
            match g.encode(tm, now, &mut b) {
                Ok(n) => {
                    let p = b.get(..n).unwrap_or(&[]).to_vec();
                    self.send(i, Hop::ServerToGround, 0, &p);
                }
                Err(e) => {
                    self.node_event(
                        i,
                        2,
                        json!({"type": "tm_unwritten", "error": e.to_string()}),
                    );
                }
            }
        }
    }
}

/// The replay trace's header of a run (`mmic sim --record`).
fn record_header(cfg: &SimConfig) -> trace::Header {
    let frames = cfg.protocol == Protocol::Pus && cfg.link == LinkLayer::Frames;
    let sdls = cfg
        .sdls
        .as_ref()
        .filter(|_| frames)
        .and_then(|s| s.trace_keys());
    trace::Header {
        sdls,
        protocol: match cfg.protocol {
            Protocol::Legacy => trace::Protocol::Legacy,
            Protocol::Pus if sdls.is_some() => trace::Protocol::PusFramesSdls,
            Protocol::Pus if frames => trace::Protocol::PusFrames,
            Protocol::Pus => trace::Protocol::Pus,
        },
        board: board_number(0),
        start: cfg.start_state,
        gateway: cfg.gateway,
    }
}

/// A side's senses as a trace reading.
fn reading(s: &super::plant::Senses) -> trace::Reading {
    trace::Reading {
        raw: s.raw,
        arm_contracted: s.arm_contracted,
        bolter_at_home: s.bolter_at_home,
    }
}

/// Robot `i`'s server board as it starts: at power-on, or after a restart from what its flash
/// kept (behind frames `store`: the kept telecommand keys, FARM-1's progress, the SDLS
/// counters; the PUS gateway over packets its `kept` keys).
fn server_board(
    cfg: &SimConfig,
    number: BoardNumber,
    kept: Option<Kept>,
    store: &super::durable::Durable,
    keys: Option<(Key256, Key256)>,
) -> Result<Board, super::durable::BootError> {
    Ok(match cfg.protocol {
        Protocol::Legacy => Board::Relay(Server::new()),
        Protocol::Pus if cfg.link == LinkLayer::Frames => Board::Frames(
            super::durable::boot_gateway(cfg.gateway, number, store, keys)?,
        ),
        Protocol::Pus => {
            let mut g = Box::new(SimGateway::new(cfg.gateway));
            match kept {
                Some(k) => g.add_restarted(number, k),
                None => g.add(number),
            };
            Board::Gateway(g)
        }
    })
}

/// Marks the copy of a duplicated packet in its delivery's connection number (connection
/// numbers count up from 1 and stay far below this bit).
const DUPLICATE: u64 = 1 << 63;

impl Robot {
    fn new(
        cfg: &SimConfig,
        i: usize,
        state: Option<&super::durable::Durable>,
    ) -> std::io::Result<Robot> {
        let number = board_number(i);
        let seed = cfg.seed.wrapping_mul(1000).wrapping_add(i as u64);
        let plant = Plant::new(
            super::PlantConfig {
                seed,
                ..cfg.plant.clone()
            },
            cfg.start_state,
        );
        let mut ab = cfg.links.ab.clone();
        if let Some(t) = cfg.cut_b_at {
            ab.cuts.push((t, None));
        }
        let link = |model: &LinkModel, loss: f64, k: u64, stream: bool| {
            Link::new(
                model.clone(),
                loss,
                seed.wrapping_add(k * 7919) ^ 0x11_4c_5e_ed,
                stream,
            )
        };
        let ground_stream = cfg.protocol == Protocol::Legacy;
        // With SDLS the uplink keeps order under jitter, as a space link does: the receiver's
        // anti-replay window takes only IVs above the last accepted one, so a datagram link
        // that lets frames sent together overtake each other would refuse the earlier ones as
        // replays, and FOP-1's go-back-N, sending its window again under fresh IVs each time,
        // could find it shuffled every round (seen: 590 TC frames for 14 accepted). The
        // reordering fault model (a frame held back) still applies.
        let secured = cfg.sdls.is_some() && cfg.link == LinkLayer::Frames;
        let links = [
            link(
                &cfg.links.ground,
                cfg.serial_loss,
                4,
                ground_stream || secured,
            ),
            link(&cfg.links.ground, cfg.serial_loss, 3, ground_stream),
            link(&cfg.links.wifi, cfg.wifi_loss, 5, true),
            link(&cfg.links.wifi, cfg.wifi_loss, 6, true),
            link(&ab, cfg.ab_loss, 1, true),
            link(&ab, cfg.ab_loss, 2, true),
        ];
        let frames = cfg.protocol == Protocol::Pus && cfg.link == LinkLayer::Frames;
        let mut ground_link = frames.then(|| Box::new(SimGroundLink::new(number)));
        let sdls = cfg.sdls.as_ref().filter(|_| frames);
        // Made once: both ends (and the server board after a restart, as from its flash)
        // share them. Keys that cannot be made stop the run (never a link in clear).
        let (keys, store) = match sdls {
            Some(s) => {
                let (k, d) = s.robot(cfg.seed, i, state)?;
                (Some(k), d)
            }
            None => (None, super::durable::Durable::memory()),
        };
        let board = server_board(cfg, number, None, &store, keys.clone())?;
        let mut attacker = None;
        if let (Some(sdls), Some(gl)) = (sdls, &mut ground_link) {
            if let Some(k) = keys.clone() {
                super::durable::boot_ground(gl, number, &store, k)?;
            }
            attacker = (sdls.attack > 0.0).then(|| Attacker {
                rate: sdls.attack,
                rng: fastrand::Rng::with_seed(seed ^ 0xa77a_c4e5_0000),
                captured: VecDeque::new(),
                waiting: VecDeque::new(),
                sent: 0,
                refused_sdls: 0,
                refused_frame: 0,
                passed: 0,
            });
        }
        Ok(Robot {
            number,
            names: [
                format!("board_a{}", i + 1),
                format!("board_b{}", i + 1),
                format!("server{}", i + 1),
                "ground".to_string(),
            ],
            a: SideA::new(BoardA::in_state(
                board_a::Config {
                    board: number,
                    ..board_a::Config::default()
                },
                cfg.start_state,
            )),
            b: SideB::new(BoardB::new(board_b::Config::default())),
            plant,
            commands: PacketQueue::new(),
            heartbeats: PacketQueue::new(),
            a_reader: Deframer::new(),
            a_from_b: VecDeque::new(),
            b_reader: Deframer::new(),
            b_from_a: VecDeque::new(),
            b_lost: false,
            wifi: WifiSession::new(WifiConfig::default()),
            wifi_conn: 0,
            board,
            visit: None,
            inbox: VecDeque::new(),
            server_reader: Deframer::new(),
            server_wake: None,
            ground_reader: Deframer::new(),
            ground_link,
            links,
            store,
            attacker,
            kept_a: None,
            kept_server: Kept::new(),
            keys,
            down: [false; 4],
            restarts: [0; 4],
            past_frames: FrameStats::default(),
        }
        .persisted())
    }

    /// Writes what both ends ask to keep to the store and confirms it (memory: at once; a
    /// state file: flushed to the disk first).
    fn persist(&mut self) {
        let kept = match &self.board {
            Board::Gateway(g) => g.kept(self.number),
            Board::Frames(g) => g.kept(self.number),
            Board::Relay(_) => None,
        };
        if let Some(k) = kept {
            self.kept_server = k;
        }
        if let Board::Frames(g) = &mut self.board {
            super::durable::persist_gateway(g, &self.store);
        }
        if let Some(gl) = &mut self.ground_link {
            super::durable::persist_ground(gl, &self.store);
        }
    }

    /// This robot's space data link figures, over every life of both ends.
    fn frames(&self) -> FrameStats {
        let mut s = self.past_frames;
        if let Some(gl) = &self.ground_link {
            s.add_ground(gl);
        }
        if let Board::Frames(g) = &self.board {
            s.add_server(g, self.number);
        }
        s
    }

    fn persisted(mut self) -> Robot {
        self.persist();
        self
    }

    /// A hop's link name and its two ends' names in the log (as the realtime engine names them).
    fn ends(&self, hop: Hop, protocol: Protocol) -> (&'static str, &str, &str) {
        let ground_link = match protocol {
            Protocol::Legacy => "serial_ground",
            Protocol::Pus => "udp_ground",
        };
        let [a, b, s, _] = &self.names;
        match hop {
            Hop::GroundToServer => (ground_link, "ground", s),
            Hop::ServerToGround => (ground_link, s, "ground"),
            Hop::ServerToA => ("wifi", s, a),
            Hop::AToServer => ("wifi", a, s),
            Hop::AToB => ("serial_ab", a, b),
            Hop::BToA => ("serial_ab", b, a),
        }
    }
}
