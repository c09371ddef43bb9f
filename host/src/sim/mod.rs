//! The host simulator: the four nodes of Figure 3 run the real library over real transports —
//! the opsUI and the server board over an OS pipe (the RS232-over-USB line), the server and
//! board A over TCP on loopback (the WiFi link, connected and disconnected each server loop),
//! board A and board B over OS pipes (the wired serial line) — around a plant model
//! ([`plant`]). Time is wall time multiplied by a scale, so a two-minute plan runs in seconds.
//!
//! ```no_run
//! use mmic_host::sim::{run, SimConfig};
//! let cfg = SimConfig::demo();
//! let summary = run(&cfg).expect("simulation ran");
//! assert!(summary.completed());
//! ```
//!
//! Losses are injected per link ([`SimConfig::wifi_loss`], …): a lost packet is logged with
//! fate `lost` and never written. Each of Table 8's ten faults, a silent sensor, and the
//! operator's Stop and Reset, can be injected at a time ([`inject`], [`SimConfig::inject`]):
//! in the plant ([`PlantConfig`]: a jammed fastener, a dead switch, an obstacle, an offset or
//! silent encoder, a silent ADC, a sagging battery), on the A–B line (cut, both directions) or from the ground (a misstated
//! reconfiguration, out-of-band commands).
//!
//! [`Protocol::Pus`] runs the same plans over CCSDS/PUS: the ground's plan runner sends PUS-C
//! telecommands ([`mmic::node::pus_ground`]) over UDP on loopback to the server board, which
//! runs the PUS gateway ([`mmic::node::gateway`]) instead of the legacy relay and sends its
//! ST\[1\], ST\[3\], ST\[5\] and ST\[17\] telemetry back over UDP; the server board and board A talk
//! as before.

pub mod bench;
pub mod clock;
pub mod inject;
pub mod lockstep;
pub mod log;
pub mod nodes;
pub mod plant;
pub mod progress;
pub mod report;
pub mod steps;

use clock::Clock;
use mmic::motion::State;
use mmic::node::board_a::{self, BoardA};
use mmic::node::board_b::{self, BoardB};
use mmic::node::gateway;
use mmic::node::ground::{self, Efficiency};
use mmic::node::handoff::PacketQueue;
use mmic::node::plan_runner::{Link, PlanEnd, PlanRunner, PlanStep, PlanTick};
use mmic::node::pus_ground::{self, TcLink, TcOut};
use mmic::units::BoardNumber;
use mmic::wire::command::CommandRepr;
use mmic::wire::heartbeat::HeartbeatRepr;
use nodes::Lossy;
pub use plant::PlantConfig;
use serde_json::{json, Value};
use std::io::Write;
use std::net::{TcpListener, UdpSocket};
use std::path::PathBuf;
use std::sync::atomic::{AtomicBool, AtomicU32, Ordering};
use std::sync::{Arc, Mutex};
use std::time::Duration;
pub use steps::{demo_steps, steps_of, SimStep, DEMO_PLAN};

/// How the ground and the server board talk.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum Protocol {
    /// The paper's: 14-byte commands and 66-byte heartbeats over the serial line (an OS
    /// pipe), the server board relaying them.
    #[default]
    Legacy,
    /// CCSDS space packets with PUS-C services over UDP on loopback, the server board as the
    /// PUS gateway.
    Pus,
}

impl Protocol {
    /// Its name on the command line and in the summary.
    pub const fn name(self) -> &'static str {
        match self {
            Protocol::Legacy => "legacy",
            Protocol::Pus => "pus",
        }
    }
}

impl std::str::FromStr for Protocol {
    type Err = String;
    fn from_str(s: &str) -> Result<Protocol, String> {
        match s {
            "legacy" => Ok(Protocol::Legacy),
            "pus" => Ok(Protocol::Pus),
            _ => Err(format!("{s:?} is no protocol: legacy or pus")),
        }
    }
}

/// What to simulate.
#[derive(Debug, Clone)]
pub struct SimConfig {
    /// How the ground and the server board talk.
    pub protocol: Protocol,
    /// The ground's telecommand link with [`Protocol::Pus`].
    pub pus: pus_ground::Config,
    /// The server board's gateway with [`Protocol::Pus`] (its uplink to board A, polls,
    /// housekeeping interval).
    pub gateway: gateway::Config,
    /// The plan every robot runs.
    pub steps: Vec<SimStep>,
    /// Robots (each with its own server board and serial line to the one ground process).
    pub robots: u8,
    /// Simulated seconds per wall second.
    pub scale: f64,
    /// Seed for every random choice (losses, fastener locks).
    pub seed: u64,
    /// Packet loss on the WiFi link, each direction, 0..1.
    pub wifi_loss: f64,
    /// Packet loss on the opsUI ↔ server serial line.
    pub serial_loss: f64,
    /// Packet loss on the board A ↔ board B serial line.
    pub ab_loss: f64,
    /// Board B is cut off (both directions) from this time, ms.
    pub cut_b_at: Option<u32>,
    /// Plant parameters and injected faults.
    pub plant: PlantConfig,
    /// Every injection scheduled with [`SimConfig::inject`], in time order: the ground sends
    /// its out-of-band commands and misstates the next reconfiguration when their time
    /// comes, and logs each as an `inject` event.
    pub injections: Vec<inject::Scheduled>,
    /// The state the robot starts in (and board A knows it is in).
    pub start_state: State,
    /// The ground's uplink timing.
    pub ground: ground::Config,
    /// Stop after this much simulated time, ms.
    pub max_sim_ms: u32,
    /// How long the server waits for a heartbeat before disconnecting, ms.
    pub visit_ms: u32,
    /// Write the JSON-lines log here (none: keep only the summary).
    pub log_path: Option<PathBuf>,
    /// Log every packet (off for large scale runs).
    pub log_packets: bool,
    /// Print live progress to stderr.
    pub progress: bool,
    /// Hold simulated time back for the slowest node ([`clock`]), so that a busy host slows
    /// the run instead of stretching the firmware's timeouts. The scale benchmark, which
    /// measures what the host can do in real time, runs unpaced.
    pub paced: bool,
    /// An external ground (YAMCS) instead of the plan runner, with [`Protocol::Pus`].
    pub external: Option<External>,
}

/// An external ground on UDP (`mmic sim --protocol pus --ground-tm-to ADDR --ground-tc-port
/// P`): the server board's gateway takes telecommands on 127.0.0.1:`tc_port` and sends its
/// telemetry to `tm_to`; no plan runs; the run ends after [`SimConfig::max_sim_ms`] of wall
/// time (the scale is 1, since the ground's timeouts run on the wall clock) or when killed.
/// One JSON line per packet on `wire` ([`nodes::WireLog`]), after `{"ready":true,"tc_port":P}`.
#[derive(Clone)]
pub struct External {
    /// Where telemetry goes (YAMCS's UDP TM link).
    pub tm_to: std::net::SocketAddr,
    /// The port telecommands arrive on (YAMCS's UDP TC link sends there); 0: any free one.
    pub tc_port: u16,
    /// Where the packet lines go (stdout in the CLI).
    pub wire: nodes::WireLog,
}

impl std::fmt::Debug for External {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("External")
            .field("tm_to", &self.tm_to)
            .field("tc_port", &self.tc_port)
            .finish_non_exhaustive()
    }
}

/// How far simulated time may run ahead of the slowest node of a paced run, ms: two of the
/// boards' 10 ms ticks, a 25th of the 500 ms communication timeout.
pub const PACE_SLACK_MS: u32 = 20;

impl SimConfig {
    /// The state a robot starts in when its plan does not say (`start` header): `a`, where
    /// the demo plan starts.
    pub const DEFAULT_START: State = State::A;

    /// The built-in demo plan at the default settings.
    pub fn demo() -> SimConfig {
        SimConfig::with_steps(demo_steps())
    }

    /// Default settings for these steps.
    pub fn with_steps(steps: Vec<SimStep>) -> SimConfig {
        SimConfig {
            protocol: Protocol::Legacy,
            pus: pus_ground::Config::default(),
            gateway: gateway::Config::default(),
            steps,
            robots: 1,
            scale: 10.0,
            seed: 1,
            wifi_loss: 0.0,
            serial_loss: 0.0,
            ab_loss: 0.0,
            cut_b_at: None,
            plant: PlantConfig::default(),
            injections: Vec::new(),
            start_state: SimConfig::DEFAULT_START,
            // The paper resends until acknowledged; 20 attempts make an unacknowledged command
            // unlikely even at 30 % loss each way (0.51^20 < 2e-6) while still ending a run
            // whose link is gone.
            ground: ground::Config {
                max_attempts: 20,
                ..ground::Config::default()
            },
            max_sim_ms: 900_000,
            visit_ms: 250,
            log_path: None,
            log_packets: true,
            progress: false,
            paced: true,
            external: None,
        }
    }
}

/// What a run produced.
#[derive(Debug, Clone)]
pub struct Summary {
    /// The protocol between the ground and the server board.
    pub protocol: Protocol,
    /// How each robot's plan ended (none: the time limit came first).
    pub ends: Vec<Option<PlanEnd>>,
    /// The plan's steps (their number is the plan's length), for reports that quote the step
    /// that stopped the plan.
    pub plan: Vec<SimStep>,
    /// The state the robot started in.
    pub start_state: State,
    /// WiFi loss each way, 0..1, as configured.
    pub wifi_loss: f64,
    /// How long the server waits for a heartbeat, ms, as configured.
    pub visit_ms: u32,
    /// Simulated time, ms.
    pub sim_ms: u32,
    /// Wall time.
    pub wall: Duration,
    /// Every log record.
    pub records: Vec<Value>,
    /// (simulated s, efficiency % over the last 100 attempts) after each attempt, robot 1.
    pub efficiency: Vec<(f64, f64)>,
    /// Attempts answered in time and attempts made, all robots.
    pub attempts: (u64, u64),
    /// Longest command-to-heartbeat time observed, ms.
    pub max_latency_ms: u32,
    /// Board A's final status (mode, faults, state), robot 1.
    pub status: Value,
    /// The latest any board's control tick started after it was due, simulated ms, all robots.
    /// The firmware ticks every 10 ms on time; a host that falls behind (too high a `scale`,
    /// a loaded machine) stretches the time between ticks and can fake timeouts.
    pub max_tick_lateness_ms: u32,
    /// Simulated ms the paced clock was held back for slow nodes (0 unpaced).
    pub held_ms: u64,
    /// The pace's slack when paced: the bound on tick lateness by construction.
    pub pace_slack_ms: Option<u32>,
    /// Robot 1's last heartbeat as the ground received it.
    pub last_heartbeat: Option<HeartbeatRepr>,
}

impl Summary {
    /// Whether the host fell behind far enough to change what the firmware saw: a tick later
    /// than [`nodes::OVERRUN_MS`]. A paced run cannot get there (its ticks are at most
    /// [`PACE_SLACK_MS`] late); an unpaced run on a loaded host can, and then its timeouts
    /// and faults may come from the host.
    pub fn host_fell_behind(&self) -> bool {
        self.max_tick_lateness_ms >= nodes::OVERRUN_MS
    }
}

impl Summary {
    /// Every robot's plan completed.
    pub fn completed(&self) -> bool {
        self.ends.iter().all(|e| *e == Some(PlanEnd::Completed))
    }

    /// Board A's events of this type (robot 1 or any robot).
    pub fn events<'a>(&'a self, ty: &'a str) -> impl Iterator<Item = &'a Value> + 'a {
        self.records
            .iter()
            .filter(move |r| r["kind"] == "event" && r["event"]["type"] == ty)
    }
}

/// A robot's board A listening for the server board's connections (the WiFi link).
struct Robot {
    addr: std::net::SocketAddr,
    listener: TcpListener,
}

/// A serial line: its two ends as OS pipes, with a reader thread deframing packets into a
/// channel at the receiving end.
struct Serial {
    write: std::io::PipeWriter,
    read: std::sync::mpsc::Receiver<Vec<u8>>,
}

/// What every robot's threads share within one run.
struct RunEnv<'a> {
    cfg: &'a SimConfig,
    clock: Clock<'a>,
    stop: &'a AtomicBool,
    late: &'a AtomicU32,
    /// Events (always), packets (when logged).
    log: Option<log::Log>,
    packet_log: Option<log::Log>,
}

impl<'a> RunEnv<'a> {
    /// The context of one node loop, holding a slot of the paced clock.
    fn node(&self, name: &str, log: &Option<log::Log>) -> nodes::Node<'a> {
        nodes::Node {
            name: name.to_string(),
            clock: self.clock.node(),
            log: log.clone(),
            stop: self.stop,
            late: self.late,
        }
    }

    /// A lossy writer for one direction of a link; its loss draws are seeded from the robot's
    /// seed and `k`, so each direction draws its own sequence.
    #[allow(clippy::too_many_arguments)]
    fn lossy<W: Write>(
        &self,
        out: W,
        link: &'static str,
        (from, to): (&str, &str),
        loss: f64,
        cut_at: Option<u32>,
        seed: u64,
        k: u64,
    ) -> Lossy<W> {
        Lossy {
            out,
            link,
            from: from.to_string(),
            to: to.to_string(),
            loss,
            cut_at,
            rng: fastrand::Rng::with_seed(seed.wrapping_add(k * 7919)),
            log: self.packet_log.clone(),
        }
    }
}

/// Opens a serial line and starts its reader.
fn serial<'scope>(scope: &'scope std::thread::Scope<'scope, '_>) -> std::io::Result<Serial> {
    let (r, write) = std::io::pipe()?;
    let (tx, read) = std::sync::mpsc::channel();
    scope.spawn(move || nodes::reader(r, tx));
    Ok(Serial { write, read })
}

/// Starts robot `i`'s four nodes (board A's WiFi and control tasks joined by `queues`, board
/// B, the server board) and returns the ground's end of its serial line.
fn spawn_robot<'scope, 'env>(
    scope: &'scope std::thread::Scope<'scope, 'env>,
    env: &RunEnv<'env>,
    i: usize,
    robot: Robot,
    queues: &'env mut (PacketQueue<14, 8>, PacketQueue<66, 8>),
    status: Arc<Mutex<Value>>,
) -> std::io::Result<GroundLink> {
    let cfg = env.cfg;
    let board = BoardNumber::new(i as u8 + 1).unwrap_or(BoardNumber::ONE);
    let (name_a, name_b, name_s) = (
        format!("board_a{}", i + 1),
        format!("board_b{}", i + 1),
        format!("server{}", i + 1),
    );
    let seed = cfg.seed.wrapping_mul(1000).wrapping_add(i as u64);
    let plant = Arc::new(Mutex::new(plant::Plant::new(
        PlantConfig {
            seed,
            ..cfg.plant.clone()
        },
        cfg.start_state,
    )));
    let (a_to_b, b_to_a) = (serial(scope)?, serial(scope)?);
    let (cmd_queue, hb_queue) = (&mut queues.0, &mut queues.1);
    let (cmd_p, cmd_c) = cmd_queue.split();
    let (hb_p, hb_c) = hb_queue.split();
    let wifi = nodes::WifiTask {
        listener: robot.listener,
        commands: cmd_p,
        heartbeats: hb_c,
        loss: cfg.wifi_loss,
        seed: seed ^ 0x5eed,
    };
    let control = nodes::ControlTask {
        a: BoardA::in_state(
            board_a::Config {
                board,
                ..board_a::Config::default()
            },
            cfg.start_state,
        ),
        commands: cmd_c,
        heartbeats: hb_p,
        from_b: b_to_a.read,
        to_b: env.lossy(
            a_to_b.write,
            "serial_ab",
            (&name_a, &name_b),
            cfg.ab_loss,
            cfg.cut_b_at,
            seed,
            1,
        ),
        plant: plant.clone(),
        status,
    };
    let b = nodes::BoardBTask {
        b: BoardB::new(board_b::Config::default()),
        from_a: a_to_b.read,
        to_a: env.lossy(
            b_to_a.write,
            "serial_ab",
            (&name_b, &name_a),
            cfg.ab_loss,
            cfg.cut_b_at,
            seed,
            2,
        ),
        plant,
    };
    // The WiFi task logs its packets (the packet log) and the hand-off events with them.
    let nodes = (
        env.node(&name_a, &env.packet_log),
        env.node(&name_a, &env.log),
        env.node(&name_b, &env.log),
        env.node(&name_s, &env.log),
    );
    scope.spawn(move || wifi.run(nodes.0));
    scope.spawn(move || control.run(nodes.1));
    scope.spawn(move || b.run(nodes.2));
    match cfg.protocol {
        Protocol::Legacy => {
            let (ground_to_server, server_to_ground) = (serial(scope)?, serial(scope)?);
            let server = nodes::ServerTask {
                from_ground: ground_to_server.read,
                to_ground: env.lossy(
                    server_to_ground.write,
                    "serial_ground",
                    (&name_s, "ground"),
                    cfg.serial_loss,
                    None,
                    seed,
                    3,
                ),
                robots: vec![(board, robot.addr)],
                visit_ms: cfg.visit_ms,
            };
            scope.spawn(move || server.run(nodes.3));
            let to_server = env.lossy(
                ground_to_server.write,
                "serial_ground",
                ("ground", &name_s),
                cfg.serial_loss,
                None,
                seed,
                4,
            );
            Ok((to_server.boxed(), server_to_ground.read, board))
        }
        Protocol::Pus => {
            // UDP on loopback: one socket at the ground, one at the server board.
            let ground = UdpSocket::bind("127.0.0.1:0")?;
            let server =
                UdpSocket::bind(("127.0.0.1", cfg.external.as_ref().map_or(0, |x| x.tc_port)))?;
            let (mut ground_addr, server_addr) = (ground.local_addr()?, server.local_addr()?);
            if let Some(x) = &cfg.external {
                ground_addr = x.tm_to;
                x.wire
                    .line(json!({"ready": true, "tc_port": server_addr.port()}));
            }
            server.set_nonblocking(true)?;
            let to_ground = nodes::UdpOut {
                sock: server.try_clone()?,
                peer: ground_addr,
            };
            let to_server = nodes::UdpOut {
                sock: ground.try_clone()?,
                peer: server_addr,
            };
            let gw = nodes::GatewayTask {
                from_ground: server,
                to_ground: env.lossy(
                    to_ground,
                    "udp_ground",
                    (&name_s, "ground"),
                    cfg.serial_loss,
                    None,
                    seed,
                    3,
                ),
                robot: (board, robot.addr),
                config: cfg.gateway,
                wire: cfg.external.as_ref().map(|x| x.wire.clone()),
            };
            scope.spawn(move || gw.run(nodes.3));
            let (tx, rx) = std::sync::mpsc::channel();
            let stop = env.stop;
            scope.spawn(move || nodes::udp_reader(ground, tx, stop));
            let to_server = env.lossy(
                to_server,
                "udp_ground",
                ("ground", &name_s),
                cfg.serial_loss,
                None,
                seed,
                4,
            );
            Ok((to_server.boxed(), rx, board))
        }
    }
}

/// Runs the simulation to the end of every robot's plan (or the time limit).
pub fn run(cfg: &SimConfig) -> std::io::Result<Summary> {
    let n = cfg.robots.max(1) as usize;
    let steps: Vec<PlanStep> = cfg.steps.iter().map(|s| s.step).collect();
    let (logger, log_rx) = log::Log::new();
    let robots = (0..n)
        .map(|_| {
            let listener = TcpListener::bind("127.0.0.1:0")?;
            Ok(Robot {
                addr: listener.local_addr()?,
                listener,
            })
        })
        .collect::<std::io::Result<Vec<Robot>>>()?;
    let mut queues: Vec<(PacketQueue<14, 8>, PacketQueue<66, 8>)> = (0..n)
        .map(|_| (PacketQueue::new(), PacketQueue::new()))
        .collect();
    // Four paced nodes per robot (board A's two tasks, board B, the server board) and the
    // ground; an unpaced run hands out no slots.
    let pace = clock::Pace::new(if cfg.paced { 4 * n + 1 } else { 0 }, PACE_SLACK_MS);
    let clock = if cfg.paced {
        Clock::paced(cfg.scale, &pace)
    } else {
        Clock::start(cfg.scale)
    };
    let statuses: Vec<Arc<Mutex<Value>>> =
        (0..n).map(|_| Arc::new(Mutex::new(Value::Null))).collect();
    let (stop, lateness) = (AtomicBool::new(false), AtomicU32::new(0));
    let writer = spawn_log_writer(cfg.log_path.clone(), log_rx);
    let env = RunEnv {
        cfg,
        clock,
        stop: &stop,
        late: &lateness,
        log: Some(logger.clone()),
        packet_log: cfg.log_packets.then(|| logger.clone()),
    };
    drop(logger);
    let result = std::thread::scope(|scope| -> std::io::Result<_> {
        let mut ground_links = Vec::new();
        for (i, (robot, q)) in robots.into_iter().zip(queues.iter_mut()).enumerate() {
            ground_links.push(spawn_robot(scope, &env, i, robot, q, statuses[i].clone())?);
        }
        let out = match &cfg.external {
            None => ground_loop(cfg, &steps, ground_links, clock.node(), env.log.clone()),
            Some(_) => external_ground(cfg, &clock),
        };
        stop.store(true, Ordering::Relaxed);
        Ok(out)
    });
    drop(env);
    let (ends, stats) = result?;
    let records = writer
        .join()
        .map_err(|_| std::io::Error::other("log writer panicked"))??;
    let status = statuses[0].lock().map(|s| s.clone()).unwrap_or(Value::Null);
    Ok(Summary {
        protocol: cfg.protocol,
        ends,
        plan: cfg.steps.clone(),
        start_state: cfg.start_state,
        wifi_loss: cfg.wifi_loss,
        visit_ms: match cfg.protocol {
            Protocol::Legacy => cfg.visit_ms,
            Protocol::Pus => cfg.gateway.uplink.timeout_ms,
        },
        sim_ms: stats.sim_ms,
        wall: clock.wall_elapsed(),
        records,
        efficiency: stats.efficiency,
        attempts: stats.attempts,
        max_latency_ms: stats.max_latency_ms,
        status,
        max_tick_lateness_ms: lateness.load(Ordering::Relaxed),
        held_ms: clock.held_ms(),
        pace_slack_ms: clock.slack_ms(),
        last_heartbeat: stats.last_heartbeat,
    })
}

/// The thread that writes the log (to a file, or nowhere) and returns its records when every
/// sender has gone.
fn spawn_log_writer(
    path: Option<PathBuf>,
    rx: std::sync::mpsc::Receiver<log::Record>,
) -> std::thread::JoinHandle<std::io::Result<Vec<Value>>> {
    std::thread::spawn(move || match path {
        Some(p) => {
            let f = std::fs::File::create(p)?;
            log::write_all(rx, &mut std::io::BufWriter::new(f))
        }
        None => log::write_all(rx, &mut std::io::sink()),
    })
}

struct GroundStats {
    sim_ms: u32,
    efficiency: Vec<(f64, f64)>,
    attempts: (u64, u64),
    max_latency_ms: u32,
    last_heartbeat: Option<HeartbeatRepr>,
}

type GroundLink = (
    Lossy<Box<dyn Write + Send>>,
    std::sync::mpsc::Receiver<Vec<u8>>,
    BoardNumber,
);

/// The ground's part of an injection: an out-of-band command handed to the plan runner, or
/// the next reconfiguration misstated; nothing for the plant's and the line's. Returns why
/// the runner did not take the command, if it did not.
fn ground_injection<L: Link>(
    run: &mut PlanRunner<L>,
    injection: inject::Injection,
) -> Option<String> {
    if let Some(c) = injection.command() {
        return run.interject(c).err().map(|e| e.to_string());
    }
    if injection == inject::Injection::Fault(mmic::faults::Table8::InitialStateMismatch) {
        run.misstate_next_reconfiguration();
    }
    None
}

/// The ground's plan runner over one protocol, as the ground loop drives it: ticks, packets
/// from the server board in, packets to it out.
trait Ground {
    /// What the runner sends.
    type Packet: Copy;
    /// Advances to `now`.
    fn tick(&mut self, steps: &[PlanStep], now: u32) -> PlanTick<Self::Packet>;
    /// A packet from the server board: what the runner made of it, and whether it answered
    /// the command outstanding (for the latency); none if it is no packet of the protocol.
    fn receive(
        &mut self,
        steps: &[PlanStep],
        now: u32,
        bytes: &[u8],
    ) -> Option<(PlanTick<Self::Packet>, bool)>;
    /// A packet's bytes.
    fn bytes(p: &Self::Packet) -> Vec<u8>;
    /// The robot's status as last reported (a heartbeat, or a housekeeping report).
    fn status(&self) -> Option<HeartbeatRepr>;
    /// The attempts answered, Figure 11.
    fn efficiency(&self) -> Efficiency;
    /// An injection's ground part ([`ground_injection`]).
    fn inject(&mut self, injection: inject::Injection) -> Option<String>;
}

/// The legacy ground: the plan runner over the uplink, and the last heartbeat.
struct LegacyGround {
    run: PlanRunner,
    last: Option<HeartbeatRepr>,
}

impl Ground for LegacyGround {
    type Packet = CommandRepr;

    fn tick(&mut self, steps: &[PlanStep], now: u32) -> PlanTick {
        self.run.tick(steps, now)
    }

    fn receive(&mut self, steps: &[PlanStep], now: u32, bytes: &[u8]) -> Option<(PlanTick, bool)> {
        let hb = HeartbeatRepr::parse(bytes).ok()?;
        let answers = hb.last_seq == self.run.uplink().outstanding().unwrap_or(0);
        self.last = Some(hb);
        Some((self.run.heartbeat(steps, now, &hb), answers))
    }

    fn bytes(p: &CommandRepr) -> Vec<u8> {
        p.to_bytes().to_vec()
    }

    fn status(&self) -> Option<HeartbeatRepr> {
        self.last
    }

    fn efficiency(&self) -> Efficiency {
        self.run.uplink().efficiency()
    }

    fn inject(&mut self, injection: inject::Injection) -> Option<String> {
        ground_injection(&mut self.run, injection)
    }
}

impl Ground for PlanRunner<TcLink> {
    type Packet = TcOut;

    fn tick(&mut self, steps: &[PlanStep], now: u32) -> PlanTick<TcOut> {
        PlanRunner::tick(self, steps, now)
    }

    fn receive(
        &mut self,
        steps: &[PlanStep],
        now: u32,
        bytes: &[u8],
    ) -> Option<(PlanTick<TcOut>, bool)> {
        let tm = mmic::ccsds::tm::TmRepr::parse(bytes, &[self.uplink().apid()]).ok()?;
        let h = tm.header;
        let answers = h.service == mmic::pus::request::ST_VERIFICATION
            && mmic::pus::verification::Report::parse(h.subservice, tm.source_data)
                .is_ok_and(|r| Some(r.request.seq_count) == self.uplink().outstanding());
        let t = self.telemetry(steps, now, h.service, h.subservice, tm.source_data);
        Some((t, answers))
    }

    fn bytes(p: &TcOut) -> Vec<u8> {
        let mut b = [0u8; pus_ground::MAX_TC_LEN];
        match p.emit(&mut b) {
            Ok(n) => b.get(..n).unwrap_or(&[]).to_vec(),
            Err(_) => Vec::new(),
        }
    }

    fn status(&self) -> Option<HeartbeatRepr> {
        self.uplink().status()
    }

    fn efficiency(&self) -> Efficiency {
        self.uplink().efficiency()
    }

    fn inject(&mut self, injection: inject::Injection) -> Option<String> {
        ground_injection(self, injection)
    }
}

/// An external ground does the commanding: wait out the run's time.
fn external_ground(cfg: &SimConfig, clock: &Clock) -> (Vec<Option<PlanEnd>>, GroundStats) {
    while clock.now_ms() < cfg.max_sim_ms {
        std::thread::sleep(Duration::from_millis(20));
    }
    let stats = GroundStats {
        sim_ms: clock.now_ms(),
        efficiency: Vec::new(),
        attempts: (0, 0),
        max_latency_ms: 0,
        last_heartbeat: None,
    };
    (vec![None; cfg.robots.max(1) as usize], stats)
}

/// The opsUI over the configured protocol.
fn ground_loop(
    cfg: &SimConfig,
    steps: &[PlanStep],
    links: Vec<GroundLink>,
    clock: clock::NodeClock<'_>,
    log: Option<log::Log>,
) -> (Vec<Option<PlanEnd>>, GroundStats) {
    match cfg.protocol {
        Protocol::Legacy => {
            let runners = links
                .iter()
                .map(|(_, _, b)| LegacyGround {
                    run: PlanRunner::new(cfg.ground, *b),
                    last: None,
                })
                .collect();
            run_ground(cfg, steps, links, runners, clock, log)
        }
        Protocol::Pus => {
            let runners = links
                .iter()
                .map(|(_, _, b)| PlanRunner::pus(cfg.pus, *b))
                .collect();
            run_ground(cfg, steps, links, runners, clock, log)
        }
    }
}

/// The opsUI: one plan runner per robot, in one thread (one ground process).
fn run_ground<G: Ground>(
    cfg: &SimConfig,
    steps: &[PlanStep],
    mut links: Vec<GroundLink>,
    mut runners: Vec<G>,
    clock: clock::NodeClock<'_>,
    log: Option<log::Log>,
) -> (Vec<Option<PlanEnd>>, GroundStats) {
    let mut ends: Vec<Option<PlanEnd>> = vec![None; runners.len()];
    let mut sent_at: Vec<Option<u32>> = vec![None; runners.len()];
    let mut stats = GroundStats {
        sim_ms: 0,
        efficiency: Vec::new(),
        attempts: (0, 0),
        max_latency_ms: 0,
        last_heartbeat: None,
    };
    let mut progress = progress::Progress::new(cfg.progress, cfg.steps.clone(), cfg.start_state);
    // Each robot's next injection (cfg.injections is in time order).
    let mut next_injection = vec![0usize; runners.len()];
    loop {
        let now = clock.now_ms();
        clock.ready(now);
        stats.sim_ms = now;
        if now > cfg.max_sim_ms || ends.iter().all(|e| e.is_some()) {
            break;
        }
        for (i, ((writer, rx, _), run)) in links.iter_mut().zip(runners.iter_mut()).enumerate() {
            if ends[i].is_some() {
                continue;
            }
            while let Some(inj) = cfg
                .injections
                .get(next_injection[i])
                .filter(|s| s.at_ms <= now)
            {
                next_injection[i] += 1;
                let refused = run.inject(inj.injection);
                if i == 0 {
                    progress.inject(now, inj.injection);
                }
                if let Some(l) = &log {
                    l.event(
                        now,
                        "ground",
                        json!({"type": "inject", "robot": i + 1, "name": inj.injection.name(),
                        "at_ms": inj.at_ms, "refused": refused}),
                    );
                }
            }
            let mut ticks = vec![run.tick(steps, now)];
            while let Ok(bytes) = rx.try_recv() {
                let t = clock.now_ms();
                if let Some((tick, answers)) = run.receive(steps, t, &bytes) {
                    if let (Some(s), true) = (sent_at[i], answers) {
                        stats.max_latency_ms = stats.max_latency_ms.max(t.saturating_sub(s));
                    }
                    ticks.push(tick);
                }
            }
            for t in ticks {
                if let Some(p) = t.send {
                    sent_at[i] = Some(now);
                    writer.send(now, &G::bytes(&p));
                }
                if let Some(ok) = t.attempt {
                    stats.attempts.1 += 1;
                    stats.attempts.0 += ok as u64;
                    if i == 0 {
                        let e = run.efficiency().percent().unwrap_or(0);
                        stats.efficiency.push((now as f64 / 1000.0, e as f64));
                    }
                    if let Some(l) = &log {
                        l.event(
                            now,
                            "ground",
                            json!({"type": "attempt", "robot": i + 1, "ok": ok}),
                        );
                    }
                }
                if let Some(d) = t.done {
                    if let Some(l) = &log {
                        l.event(
                            now,
                            "ground",
                            json!({
                                "type": "done", "robot": i + 1, "seq": d.seq, "command": d.command,
                                "outcome": d.outcome, "attempts": d.attempts,
                            }),
                        );
                    }
                }
                if let (Some(k), 0) = (t.started, i) {
                    progress.step(now, k);
                    if let Some(l) = &log {
                        l.event(
                            now,
                            "ground",
                            json!({"type": "step", "robot": 1, "step": k + 1,
                            "line": cfg.steps[k].line, "text": cfg.steps[k].text}),
                        );
                    }
                }
                if let Some(e) = t.end {
                    ends[i] = Some(e);
                    if let Some(l) = &log {
                        l.event(
                            now,
                            "ground",
                            json!({"type": "plan_end", "robot": i + 1, "end": format!("{e:?}")}),
                        );
                    }
                }
            }
        }
        if let Some(r) = runners.first() {
            if let Some(hb) = r.status() {
                progress.status(now, &hb, r.efficiency());
            }
        }
        std::thread::sleep(Duration::from_micros(500));
    }
    progress.finish();
    let _ = std::io::stderr().flush();
    stats.last_heartbeat = runners.first().and_then(Ground::status);
    (ends, stats)
}
