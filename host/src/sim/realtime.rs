//! The realtime engine (`mmic sim --realtime`): the four nodes of Figure 3 run the real
//! library over real transports — the opsUI and the server board over an OS pipe (the
//! RS232-over-USB line; UDP on loopback with `--protocol pus`), the server and board A over TCP
//! on loopback (the WiFi link, connected and disconnected each server loop), board A's WiFi task
//! and control loop on two threads joined by the library's hand-off queues, board A and board B
//! over a Unix stream socket pair (the wired serial line, read by each board at its tick:
//! [`super::serial_line`]) — around the plant, on the wall clock multiplied by a scale
//! ([`super::clock`], paced). Six OS threads per robot: it proves the transports, but its
//! outcome can depend on how busy the host is, which the virtual-time engine
//! ([`super::engine`], the default) cannot.

use super::clock::{self, Clock};
use super::downtime::{Downtime, Phase};
use super::inject::{Node, BOOT_MS};
use super::log;
use super::nodes::{self, Lossy};
use super::plant::{self, PlantConfig};
use super::shell::{Ground, GroundSide, GroundStats, LegacyGround, SideA, SideB};
use super::{FrameStats, LinkLayer, Protocol, SimConfig, Summary, PACE_SLACK_MS};
use mmic::node::ground::frames::GroundLink as FopLink;
use mmic::node::ground::plan_runner::{PlanEnd, PlanRunner};
use mmic::node::robot::board_a::{self, BoardA};
use mmic::node::robot::board_b::{self, BoardB};
use mmic::node::robot::handoff::PacketQueue;
use mmic::units::BoardNumber;
use serde_json::{json, Value};
use std::io::Write;
use std::net::{TcpListener, UdpSocket};
use std::path::PathBuf;
use std::sync::atomic::{AtomicBool, AtomicU32, Ordering};
use std::sync::{Arc, Mutex};
use std::time::Duration;

/// A robot's board A listening for the server board's connections (the WiFi link).
struct Robot {
    addr: std::net::SocketAddr,
    listener: TcpListener,
}

/// A serial line: its writing end, and its receiving end read by the receiving node at its
/// tick ([`super::serial_line`]).
struct Serial {
    write: std::os::unix::net::UnixStream,
    read: super::serial_line::SerialRx,
}

/// A robot's SDLS keys, TC and TM, and the durable store of both ends of its link.
type Keys = (
    (mmic::link::sdls::Key256, mmic::link::sdls::Key256),
    super::durable::Durable,
);

/// The ground's end of a robot's link: the writer, the packets read, the robot's number.
type GroundLink = (
    Lossy<Box<dyn Write + Send>>,
    std::sync::mpsc::Receiver<Vec<u8>>,
    BoardNumber,
);

/// What every robot's threads share within one run.
struct RunEnv<'a> {
    cfg: &'a SimConfig,
    clock: Clock<'a>,
    stop: &'a AtomicBool,
    late: &'a AtomicU32,
    /// Events (always), packets (when logged).
    log: Option<log::Log>,
    packet_log: Option<log::Log>,
    /// The server boards' figures of the space data link, added when their tasks end.
    frames: Arc<Mutex<FrameStats>>,
    /// With SDLS in the run's own ground: every robot's (TC, TM) keys and store, by index.
    keys: &'a [Keys],
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
fn serial() -> std::io::Result<Serial> {
    let (write, read) = super::serial_line::pair()?;
    Ok(Serial { write, read })
}

/// The ground's line to a server board: an OS pipe each way, with a reader thread deframing
/// packets into a channel at the receiving end (the ground and the server wait on it).
struct GroundSerial {
    write: std::io::PipeWriter,
    read: std::sync::mpsc::Receiver<Vec<u8>>,
}

fn ground_serial<'scope>(
    scope: &'scope std::thread::Scope<'scope, '_>,
) -> std::io::Result<GroundSerial> {
    let (r, write) = std::io::pipe()?;
    let (tx, read) = std::sync::mpsc::channel();
    scope.spawn(move || nodes::reader(r, tx));
    Ok(GroundSerial { write, read })
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
    let (a_to_b, b_to_a) = (serial()?, serial()?);
    let (cmd_queue, hb_queue) = (&mut queues.0, &mut queues.1);
    let (cmd_p, cmd_c) = cmd_queue.split();
    let (hb_p, hb_c) = hb_queue.split();
    let a_down = Arc::new(AtomicBool::new(false));
    let wifi = nodes::WifiTask {
        listener: robot.listener,
        commands: cmd_p,
        heartbeats: hb_c,
        loss: cfg.wifi_loss,
        seed: seed ^ 0x5eed,
        down: a_down.clone(),
        server: std::net::Ipv4Addr::LOCALHOST.into(),
    };
    let control = nodes::ControlTask {
        a: SideA::new(BoardA::in_state(
            board_a::Config {
                board,
                ..board_a::Config::default()
            },
            cfg.start_state,
        )),
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
        restarts: Downtime::of(cfg, Node::A),
        down: a_down,
        kept: None,
    };
    let b = nodes::BoardBTask {
        b: SideB::new(BoardB::new(board_b::Config::default())),
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
        restarts: Downtime::of(cfg, Node::B),
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
    let server = ServerEnds {
        name: &name_s,
        board,
        addr: robot.addr,
        seed,
    };
    spawn_server(scope, env, server, nodes.3)
}

/// What a robot's server board is to the rest: its name in the log, the robot it serves,
/// where that robot's board A listens, and the robot's seed (of the links' loss draws).
struct ServerEnds<'n> {
    name: &'n str,
    board: BoardNumber,
    addr: std::net::SocketAddr,
    seed: u64,
}

impl ServerEnds<'_> {
    /// The lossy writer of the ground link's direction `k` (3: to the ground, 4: from it).
    fn lossy<W: Write>(&self, env: &RunEnv<'_>, out: W, link: &'static str, k: u64) -> Lossy<W> {
        let ends = if k == 3 {
            (self.name, "ground")
        } else {
            ("ground", self.name)
        };
        env.lossy(out, link, ends, env.cfg.serial_loss, None, self.seed, k)
    }

    /// The UDP link on loopback between the ground (its own socket, or an external ground's
    /// addresses) and the server board: the board's socket and its lossy writer to the ground,
    /// and the ground's end.
    fn udp(
        &self,
        env: &RunEnv<'_>,
    ) -> std::io::Result<(UdpSocket, Lossy<nodes::UdpOut>, GroundUdp)> {
        let cfg = env.cfg;
        // UDP on loopback: one socket at the ground, one at the server board.
        let ground = UdpSocket::bind("127.0.0.1:0")?;
        let port = cfg.external.as_ref().map_or(0, |x| x.tc_port);
        let server = UdpSocket::bind(("127.0.0.1", port))?;
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
        let to_ground = self.lossy(env, to_ground, "udp_ground", 3);
        Ok((server, to_ground, GroundUdp { ground, to_server }))
    }

    /// The PUS gateway's task on the UDP link, with the ground's end.
    fn gateway(&self, env: &RunEnv<'_>) -> std::io::Result<(nodes::GatewayTask, GroundUdp)> {
        let (server, to_ground, udp) = self.udp(env)?;
        let gw = nodes::GatewayTask {
            from_ground: server,
            to_ground,
            robot: (self.board, self.addr),
            config: env.cfg.gateway,
            wire: env.cfg.external.as_ref().map(|x| x.wire.clone()),
            restarts: Downtime::of(env.cfg, Node::Server),
        };
        Ok((gw, udp))
    }

    /// The PUS gateway behind the space data link (`--link frames`) on the UDP link, with the
    /// ground's end.
    fn frame_gateway(
        &self,
        env: &RunEnv<'_>,
    ) -> std::io::Result<(nodes::FrameGatewayTask, GroundUdp)> {
        let (server, to_ground, udp) = self.udp(env)?;
        let gw = nodes::FrameGatewayTask {
            from_ground: server,
            to_ground,
            robot: (self.board, self.addr),
            config: env.cfg.gateway,
            wire: env.cfg.external.as_ref().map(|x| x.wire.clone()),
            stats: env.frames.clone(),
            sdls: match (&env.cfg.external, &env.cfg.sdls) {
                (Some(x), _) => x.sdls.clone(),
                (None, Some(_)) => env
                    .keys
                    .get(self.board.get() as usize - 1)
                    .map(|k| k.0.clone()),
                (None, None) => None,
            },
            store: match &env.cfg.external {
                Some(x) => x.store.clone(),
                None => env
                    .keys
                    .get(self.board.get() as usize - 1)
                    .map_or_else(super::durable::Durable::memory, |k| k.1.clone()),
            },
            ground: env
                .cfg
                .external
                .as_ref()
                .map_or(std::net::Ipv4Addr::LOCALHOST.into(), |x| x.tm_to.ip()),
            restarts: Downtime::of(env.cfg, Node::Server),
        };
        Ok((gw, udp))
    }
}

/// The ground's end of a gateway's UDP link: its socket, and its writer to the gateway.
struct GroundUdp {
    ground: UdpSocket,
    to_server: nodes::UdpOut,
}

/// Starts robot `i`'s server board — the legacy relay ([`nodes::ServerTask`]) on a serial line,
/// or the PUS gateway ([`nodes::GatewayTask`]; [`nodes::FrameGatewayTask`] with `--link
/// frames`) on UDP — and returns the ground's end of its link.
fn spawn_server<'scope, 'env>(
    scope: &'scope std::thread::Scope<'scope, 'env>,
    env: &RunEnv<'env>,
    s: ServerEnds<'_>,
    node: nodes::Node<'env>,
) -> std::io::Result<GroundLink> {
    let cfg = env.cfg;
    match cfg.protocol {
        Protocol::Legacy => {
            let (from_ground, to_ground, ground_end) = match ops_line(scope, env) {
                // The opsUI is at the other end of a device: the run's ground has no link.
                Some((rx, write)) => {
                    let none = std::sync::mpsc::channel().1;
                    let sink = s.lossy(env, std::io::sink(), "serial_ground", 4);
                    (rx, write, (sink.boxed(), none, s.board))
                }
                None => {
                    let (ground_to_server, server_to_ground) =
                        (ground_serial(scope)?, ground_serial(scope)?);
                    let to_server = s.lossy(env, ground_to_server.write, "serial_ground", 4);
                    let write: Box<dyn Write + Send> = Box::new(server_to_ground.write);
                    let end = (to_server.boxed(), server_to_ground.read, s.board);
                    (ground_to_server.read, write, end)
                }
            };
            let server = nodes::ServerTask {
                from_ground,
                to_ground: s.lossy(env, to_ground, "serial_ground", 3),
                robots: vec![(s.board, s.addr)],
                visit_ms: cfg.visit_ms,
                restarts: Downtime::of(cfg, Node::Server),
            };
            scope.spawn(move || server.run(node));
            Ok(ground_end)
        }
        Protocol::Pus => {
            let udp = if cfg.link == LinkLayer::Frames {
                let (gw, udp) = s.frame_gateway(env)?;
                scope.spawn(move || gw.run(node));
                udp
            } else {
                let (gw, udp) = s.gateway(env)?;
                scope.spawn(move || gw.run(node));
                udp
            };
            let (tx, rx) = std::sync::mpsc::channel();
            let stop = env.stop;
            scope.spawn(move || nodes::udp_reader(udp.ground, tx, stop));
            let to_server = s.lossy(env, udp.to_server, "udp_ground", 4);
            Ok((to_server.boxed(), rx, s.board))
        }
    }
}

/// The server board's end of its opsUI line: the packets read, and where it writes.
type ServerLine = (std::sync::mpsc::Receiver<Vec<u8>>, Box<dyn Write + Send>);

/// The server board's opsUI line on a device ([`SimConfig::ops_line`]), the first time it is
/// asked for: its reader started, the packets it finds, and the device to write to.
fn ops_line<'scope, 'env>(
    scope: &'scope std::thread::Scope<'scope, 'env>,
    env: &RunEnv<'env>,
) -> Option<ServerLine> {
    let line = env.cfg.ops_line.as_ref()?;
    let ends = line.take()?;
    let (tx, rx) = std::sync::mpsc::channel();
    let (stats, stop) = (line.stats.clone(), env.stop);
    scope.spawn(move || super::opsline::reader(ends.read, tx, &stats, stop));
    Some((rx, Box::new(ends.write)))
}

/// Runs the simulation on the wall clock to the end of every robot's plan (or the time limit).
pub fn run(cfg: &SimConfig) -> std::io::Result<Summary> {
    let n = cfg.robots.max(1) as usize;
    let (logger, log_rx) = log::Log::new();
    let secured = cfg.link == LinkLayer::Frames
        && (cfg.sdls.is_some() || cfg.external.as_ref().is_some_and(|x| x.sdls.is_some()));
    let logger = logger.secured(secured);
    // With SDLS in the run's own ground, each robot's keys and store, for both ends.
    let keys = match (&cfg.sdls, &cfg.external) {
        (Some(c), None) if cfg.link == LinkLayer::Frames => {
            let state = c.open_state()?;
            (0..n)
                .map(|i| c.robot(cfg.seed, i, state.as_ref()))
                .collect::<std::io::Result<Vec<_>>>()?
        }
        _ => Vec::new(),
    };
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
    let server_frames = Arc::new(Mutex::new(FrameStats::default()));
    let env = RunEnv {
        cfg,
        clock,
        stop: &stop,
        late: &lateness,
        log: Some(logger.clone()),
        packet_log: cfg.log_packets.then(|| logger.clone()),
        frames: server_frames.clone(),
        keys: &keys,
    };
    drop(logger);
    let result = std::thread::scope(|scope| -> std::io::Result<_> {
        let mut ground_links = Vec::new();
        for (i, (robot, q)) in robots.into_iter().zip(queues.iter_mut()).enumerate() {
            ground_links.push(spawn_robot(scope, &env, i, robot, q, statuses[i].clone())?);
        }
        let out = match (&cfg.external, &cfg.ops_line) {
            (None, None) => ground_loop(cfg, ground_links, &keys, clock.node(), env.log.clone()),
            (None, Some(line)) => super::opsline::wait(cfg, &clock, line),
            (Some(_), _) => without_ground(cfg, &clock, || false),
        };
        stop.store(true, Ordering::Relaxed);
        Ok(out)
    });
    drop(env);
    let (ends, stats, ground_frames) = result?;
    let frames = (cfg.protocol == Protocol::Pus && cfg.link == LinkLayer::Frames).then(|| {
        let server = server_frames.lock().map(|s| *s).unwrap_or_default();
        ground_frames.merged(server)
    });
    let records = writer
        .join()
        .map_err(|_| std::io::Error::other("log writer panicked"))??;
    let status = statuses[0].lock().map(|s| s.clone()).unwrap_or(Value::Null);
    // The restarts, from the nodes' events (the ground's counted once per robot, as the
    // virtual-time engine counts them).
    let mut restarts = [0u32; 4];
    for r in records.iter().filter(|r| r["event"]["type"] == "restart") {
        let node = r["node"].as_str().unwrap_or("");
        match ["board_a", "board_b", "server", "ground"]
            .iter()
            .position(|p| node.starts_with(p))
        {
            Some(3) => restarts[3] += n as u32,
            Some(k) => restarts[k] += 1,
            None => {}
        }
    }
    Ok(Summary {
        restarts,
        max_tick_lateness_ms: lateness.load(Ordering::Relaxed),
        held_ms: clock.held_ms(),
        pace_slack_ms: clock.slack_ms(),
        realtime: true,
        frames,
        ..Summary::of_run(cfg, ends, stats, records, status, clock.wall_elapsed())
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

/// The run has no ground of its own (an external ground, or the opsUI on a device): wait
/// until the run's time is out or `done` says so; no plan of the run's own ends.
pub(super) fn without_ground(
    cfg: &SimConfig,
    clock: &Clock,
    done: impl Fn() -> bool,
) -> (Vec<Option<PlanEnd>>, GroundStats, FrameStats) {
    while clock.now_ms() < cfg.max_sim_ms && !done() {
        std::thread::sleep(Duration::from_millis(10));
    }
    let stats = GroundStats {
        sim_ms: clock.now_ms(),
        ..GroundStats::default()
    };
    (
        vec![None; cfg.robots.max(1) as usize],
        stats,
        FrameStats::default(),
    )
}

/// The ground's end of a robot's space data link in the realtime engine: FOP-1's window K =
/// 10, 64 packets waiting, packets of up to 1 KiB reassembled (the virtual-time engine's).
type SimFopLink = FopLink<10, 64, 1024>;

/// The opsUI over the configured protocol.
fn ground_loop(
    cfg: &SimConfig,
    links: Vec<GroundLink>,
    keys: &[Keys],
    clock: clock::NodeClock<'_>,
    log: Option<log::Log>,
) -> (Vec<Option<PlanEnd>>, GroundStats, FrameStats) {
    match cfg.protocol {
        Protocol::Legacy => {
            let runners = links
                .iter()
                .map(|(_, _, b)| LegacyGround {
                    run: PlanRunner::new(cfg.ground, *b),
                    last: None,
                })
                .collect();
            run_ground(cfg, links, runners, (Vec::new(), keys), clock, log)
        }
        Protocol::Pus => {
            let runners = links
                .iter()
                .map(|(_, _, b)| PlanRunner::pus(cfg.ground_pus(), *b))
                .collect();
            // With --link frames the ground's packets go through each robot's FOP-1.
            // With SDLS, each secured with its robot's keys.
            let fops = links
                .iter()
                .enumerate()
                .map(|(i, (_, _, b))| {
                    (cfg.link == LinkLayer::Frames)
                        .then(|| {
                            let mut gl = Box::new(SimFopLink::new(*b));
                            if let Some((k, d)) = keys.get(i) {
                                super::durable::boot_ground(&mut gl, *b, d, k.clone())?;
                            }
                            Ok(gl)
                        })
                        .transpose()
                })
                .collect::<Result<Vec<_>, super::durable::BootError>>();
            let fops = match fops {
                Ok(f) => f,
                Err(e) => {
                    ground_event(
                        &log,
                        0,
                        json!({"type": "link_stopped", "why": e.to_string()}),
                    );
                    links.iter().map(|_| None).collect()
                }
            };
            run_ground(cfg, links, runners, (fops, keys), clock, log)
        }
    }
}

/// The opsUI: one plan runner per robot, in one thread (one ground process). With a robot's
/// FOP-1 link in `fops` (`--link frames`), its packets go out in TC frames and the TM frames
/// that come back are taken apart by it (their CLCW to FOP-1, their packets to the runner);
/// the link's figures are returned. `--inject reboot-ground@S` restarts it (decision
/// `restart-ground`): down for [`BOOT_MS`], what reaches it lost, then each runner from what
/// the disk kept and each FOP-1 afresh, with SDLS from the stored counters.
fn run_ground<G: Ground>(
    cfg: &SimConfig,
    mut links: Vec<GroundLink>,
    runners: Vec<G>,
    (mut fops, keys): (Vec<Option<Box<SimFopLink>>>, &[Keys]),
    clock: clock::NodeClock<'_>,
    log: Option<log::Log>,
) -> (Vec<Option<PlanEnd>>, GroundStats, FrameStats) {
    let mut ground = GroundSide::new(
        &cfg.steps,
        cfg.start_state,
        &cfg.injections,
        runners,
        cfg.progress,
        log.clone(),
    );
    let mut restarts = Downtime::of(cfg, Node::Ground);
    // The link's figures of the ground's earlier lives.
    let mut past = FrameStats::default();
    // FOP-1 initiates the AD service; it runs once a CLCW confirms it.
    for (i, ((writer, _, _), fop)) in links.iter_mut().zip(fops.iter_mut()).enumerate() {
        if let Some(gl) = fop {
            persist(keys, i, gl);
            gl.start(clock.now_ms(), &mut |f: &[u8]| {
                writer.send(clock.now_ms(), f);
            });
        }
    }
    let mut now;
    loop {
        now = clock.now_ms();
        clock.ready(now);
        if now > cfg.max_sim_ms || ground.all_done() {
            break;
        }
        let phase = restarts.step(now);
        if phase == Phase::WentDown {
            ground_event(&log, now, json!({"type": "restart", "down_ms": BOOT_MS}));
            for f in fops.iter_mut() {
                if let Some(gl) = f.take() {
                    past.add_ground(&gl);
                }
            }
        }
        match phase {
            Phase::Running => {}
            Phase::WentDown | Phase::Down => {
                // Down: what reaches it is lost.
                for (_, rx, _) in links.iter_mut() {
                    while rx.try_recv().is_ok() {}
                }
                std::thread::sleep(Duration::from_micros(500));
                continue;
            }
            Phase::CameUp => {
                boot_links(
                    cfg,
                    &mut links,
                    &mut fops,
                    keys,
                    &mut ground,
                    (&clock, now),
                    &log,
                );
                ground_event(&log, now, json!({"type": "boot", "boot": null}));
            }
        }
        for (i, (writer, rx, _)) in links.iter_mut().enumerate() {
            let Some(gl) = fops.get_mut(i).and_then(|f| f.as_deref_mut()) else {
                if let Some(p) = ground.tick(i, now) {
                    writer.send(now, &p);
                }
                while let Ok(bytes) = rx.try_recv() {
                    let t = clock.now_ms();
                    if let Some(p) = ground.receive(i, t, &bytes) {
                        writer.send(t, &p);
                    }
                }
                continue;
            };
            frames_step(gl, i, (writer, rx), &mut ground, (&clock, now), &log, keys);
        }
        ground.progress(now);
        std::thread::sleep(Duration::from_micros(500));
    }
    let (ends, stats) = ground.finish(now);
    let mut frames = past;
    for gl in fops.iter().flatten() {
        frames.add_ground(gl);
    }
    let _ = std::io::stderr().flush();
    (ends, stats, frames)
}

/// The ground back up (`Phase::CameUp`): each runner from what the disk kept and, over frames,
/// each robot's FOP-1 afresh with SDLS from the stored counters (a link whose store cannot be
/// read stays stopped, logged).
fn boot_links<G: Ground>(
    cfg: &SimConfig,
    links: &mut [GroundLink],
    fops: &mut [Option<Box<SimFopLink>>],
    keys: &[Keys],
    ground: &mut GroundSide<G>,
    (clock, now): (&clock::NodeClock<'_>, u32),
    log: &Option<log::Log>,
) {
    for (i, (writer, _, b)) in links.iter_mut().enumerate() {
        ground.restart(i, now);
        if cfg.protocol == Protocol::Pus && cfg.link == LinkLayer::Frames {
            let mut gl = Box::new(SimFopLink::new(*b));
            if let Some((k, d)) = keys.get(i) {
                if let Err(e) = super::durable::boot_ground(&mut gl, *b, d, k.clone()) {
                    ground_event(
                        log,
                        now,
                        json!({"type": "link_stopped", "why": e.to_string()}),
                    );
                    continue;
                }
            }
            persist(keys, i, &mut gl);
            gl.start(now, &mut |f: &[u8]| {
                writer.send(clock.now_ms(), f);
            });
            fops[i] = Some(gl);
        }
    }
}

/// One loop of a robot's link over frames: FOP-1's timers, the runner's next telecommand
/// into a TC frame, and every TM frame read taken apart (its CLCW to FOP-1, its packets to
/// the runner, whose answers go out again).
fn frames_step<G: Ground>(
    gl: &mut SimFopLink,
    i: usize,
    (writer, rx): (
        &mut Lossy<Box<dyn Write + Send>>,
        &mut std::sync::mpsc::Receiver<Vec<u8>>,
    ),
    ground: &mut GroundSide<G>,
    (clock, now): (&clock::NodeClock<'_>, u32),
    log: &Option<log::Log>,
    keys: &[Keys],
) {
    let mut emit = |f: &[u8]| {
        writer.send(clock.now_ms(), f);
    };
    persist(keys, i, gl);
    gl.tick(now, &mut emit);
    if let Some(p) = ground.tick(i, now) {
        if gl.send(&p, now, &mut emit).is_err() {
            ground_event(log, now, json!({"type": "ground_outbox_full"}));
        }
    }
    while let Ok(bytes) = rx.try_recv() {
        let t = clock.now_ms();
        let mut packets = Vec::new();
        let taken = gl.tm_frame(t, &bytes, &mut emit, &mut |p: &[u8]| {
            packets.push(p.to_vec())
        });
        if let Err(e) = taken {
            ground_event(
                log,
                t,
                json!({"type": "tm_frame_refused", "check": e.name(),
                       "sdls": log::sdls_header(&bytes)}),
            );
        }
        persist(keys, i, gl);
        for p in packets {
            if let Some(q) = ground.receive(i, t, &p) {
                if gl.send(&q, t, &mut emit).is_err() {
                    ground_event(log, t, json!({"type": "ground_outbox_full"}));
                }
            }
        }
    }
}

/// The ground's durable SDLS counters of robot `i`'s link: its store (memory for the run, or
/// the state file of given keys).
fn persist(keys: &[Keys], i: usize, gl: &mut SimFopLink) {
    if let Some((_, d)) = keys.get(i) {
        super::durable::persist_ground(gl, d);
    }
}

/// An event of the ground's end of the space data link.
fn ground_event(log: &Option<log::Log>, now: u32, what: Value) {
    if let Some(l) = log {
        l.event(now, "ground", what);
    }
}
