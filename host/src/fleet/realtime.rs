//! `mmic fleet --realtime`: the fleet on the wall clock, every node an async task of one tokio
//! runtime with two worker threads — no thread per robot. Per robot:
//!
//! * board A's **control task** ticks every 10 ms: side A and side B of the robot (the
//!   library's boards through [`crate::sim::shell`]) and the plant, the wired A–B line between
//!   them in memory, one packet per tick each way as on the firmware;
//! * board A's **WiFi task** listens on its own TCP port on loopback: it accepts the server
//!   board's connection, deframes commands into the library's hand-off queue and writes the
//!   heartbeats the control task queued (woken when one is queued);
//! * the **server board** receives the ground's packets on its own UDP socket and visits board A
//!   as the paper's does — connect over TCP, send, wait for the heartbeat (at most the visit
//!   window), forward it, disconnect — as the legacy relay or the PUS gateway;
//!
//! and one **ground** task runs every robot's plan runner ([`crate::sim::shell::GroundSide`])
//! over one UDP socket, ticking every 10 ms. The figure of merit: every poll answered within
//! 0.7 s.
//!
//! The hand-off queues of each robot are leaked (`Box::leak`) so that its two tasks can own
//! their ends for the process's life, as the firmware's statics do: a few hundred bytes per
//! robot, once per run.

use super::{FleetConfig, FleetResult};
use crate::sim::shell::{Ground, GroundSide, LegacyGround, SideA, SideB};
use crate::sim::{plant::Plant, Protocol, SimConfig};
use mmic::node::ground::plan_runner::PlanRunner;
use mmic::node::robot::board_a::{self, BoardA};
use mmic::node::robot::board_b::{self, BoardB};
use mmic::node::robot::handoff::{Consumer, PacketQueue, Producer};
use mmic::node::robot::wifi_session::{Outgoing, WifiConfig, WifiSession};
use mmic::node::server::gateway::Gateway;
use mmic::node::server::relay::Server;
use mmic::node::server::visit::Visit;
use mmic::units::BoardNumber;
use mmic::wire::command::COMMAND_LEN;
use mmic::wire::heartbeat::{HeartbeatRepr, HEARTBEAT_LEN};
use std::collections::{HashMap, VecDeque};
use std::net::SocketAddr;
use std::sync::atomic::{AtomicBool, AtomicU32, Ordering};
use std::sync::Arc;
use std::time::{Duration, Instant};
use tokio::io::{AsyncReadExt, AsyncWriteExt};
use tokio::net::{TcpListener, TcpStream, UdpSocket};
use tokio::sync::Notify;
use tokio::time::MissedTickBehavior;

/// Worker threads of the runtime.
pub const WORKERS: usize = 2;

/// What every task shares: the run's start (its clock), the stop flag, the worst tick
/// lateness.
struct Shared {
    start: Instant,
    stop: AtomicBool,
    late_ms: AtomicU32,
}

impl Shared {
    fn now_ms(&self) -> u32 {
        self.start.elapsed().as_millis() as u32
    }
}

/// Runs the fleet on the wall clock for `cfg.seconds`.
pub fn run(cfg: &FleetConfig) -> std::io::Result<FleetResult> {
    let rt = tokio::runtime::Builder::new_multi_thread()
        .worker_threads(WORKERS)
        .enable_all()
        .build()?;
    let sim = cfg.sim_config();
    let wall = Instant::now();
    let (ends, stats, late) = rt.block_on(fleet(sim))?;
    rt.shutdown_timeout(Duration::from_secs(2));
    let completed = ends
        .iter()
        .filter(|e| **e == Some(mmic::node::ground::plan_runner::PlanEnd::Completed))
        .count() as u32;
    let ended = ends.iter().filter(|e| e.is_some()).count() as u32;
    Ok(FleetResult {
        robots: cfg.robots.max(1),
        sim_seconds: stats.sim_ms as f64 / 1000.0,
        wall: wall.elapsed(),
        attempts: stats.attempts,
        max_latency_ms: stats.max_latency_ms,
        ends: (completed, ended - completed),
        // The runtime's workers and the thread that waits on it.
        threads: Some(WORKERS + 1),
        max_tick_lateness_ms: Some(late),
    })
}

type Ends = Vec<Option<mmic::node::ground::plan_runner::PlanEnd>>;

async fn fleet(cfg: SimConfig) -> std::io::Result<(Ends, crate::sim::shell::GroundStats, u32)> {
    let n = cfg.robots.max(1) as usize;
    let shared = Arc::new(Shared {
        start: Instant::now(),
        stop: AtomicBool::new(false),
        late_ms: AtomicU32::new(0),
    });
    let ground_sock = Arc::new(UdpSocket::bind("127.0.0.1:0").await?);
    let ground_addr = ground_sock.local_addr()?;
    let mut servers = Vec::with_capacity(n);
    for i in 0..n {
        let board = BoardNumber::new((i % 255) as u8 + 1).unwrap_or(BoardNumber::ONE);
        let listener = TcpListener::bind("127.0.0.1:0").await?;
        let a_addr = listener.local_addr()?;
        let server = UdpSocket::bind("127.0.0.1:0").await?;
        servers.push(server.local_addr()?);
        let queues: &'static mut (PacketQueue<COMMAND_LEN, 8>, PacketQueue<HEARTBEAT_LEN, 8>) =
            Box::leak(Box::new((PacketQueue::new(), PacketQueue::new())));
        let (cmd_p, cmd_c) = queues.0.split();
        let (hb_p, hb_c) = queues.1.split();
        let notify = Arc::new(Notify::new());
        let seed = cfg.seed.wrapping_mul(1000).wrapping_add(i as u64);
        let robot = Robot {
            a: SideA::new(BoardA::in_state(
                board_a::Config {
                    board,
                    ..board_a::Config::default()
                },
                cfg.start_state,
            )),
            b: SideB::new(BoardB::new(board_b::Config::default())),
            plant: Plant::new(
                crate::sim::PlantConfig {
                    seed,
                    ..cfg.plant.clone()
                },
                cfg.start_state,
            ),
            commands: cmd_c,
            heartbeats: hb_p,
            notify: notify.clone(),
        };
        tokio::spawn(control_task(robot, shared.clone()));
        tokio::spawn(wifi_task(
            listener,
            cmd_p,
            hb_c,
            notify,
            cfg.wifi_loss,
            seed ^ 0x5eed,
            shared.clone(),
        ));
        tokio::spawn(server_task(
            server,
            ground_addr,
            board,
            a_addr,
            cfg.clone(),
            shared.clone(),
        ));
    }
    let out = match cfg.protocol {
        Protocol::Legacy => {
            let runners = (0..n)
                .map(|i| LegacyGround {
                    run: PlanRunner::new(
                        cfg.ground,
                        BoardNumber::new((i % 255) as u8 + 1).unwrap_or(BoardNumber::ONE),
                    ),
                    last: None,
                })
                .collect();
            ground_task(&cfg, runners, ground_sock, servers, &shared).await
        }
        Protocol::Pus => {
            let runners = (0..n)
                .map(|i| {
                    PlanRunner::pus(
                        cfg.ground_pus(),
                        BoardNumber::new((i % 255) as u8 + 1).unwrap_or(BoardNumber::ONE),
                    )
                })
                .collect();
            ground_task(&cfg, runners, ground_sock, servers, &shared).await
        }
    };
    shared.stop.store(true, Ordering::Relaxed);
    let (ends, stats) = out?;
    Ok((ends, stats, shared.late_ms.load(Ordering::Relaxed)))
}

/// One robot's control side: both boards and the plant.
struct Robot {
    a: SideA,
    b: SideB,
    plant: Plant,
    commands: Consumer<'static, COMMAND_LEN, 8>,
    heartbeats: Producer<'static, HEARTBEAT_LEN, 8>,
    notify: Arc<Notify>,
}

/// Board A's control task (with board B and the plant): a tick every 10 ms.
async fn control_task(mut r: Robot, shared: Arc<Shared>) {
    let mut ticker = tokio::time::interval(Duration::from_millis(10));
    ticker.set_missed_tick_behavior(MissedTickBehavior::Delay);
    let (mut to_b, mut to_a): (VecDeque<_>, VecDeque<_>) = (VecDeque::new(), VecDeque::new());
    let mut due = shared.start;
    while !shared.stop.load(Ordering::Relaxed) {
        let at = ticker.tick().await;
        let at = at.into_std();
        if at > due {
            due = at;
        }
        let late = Instant::now().saturating_duration_since(due).as_millis() as u32;
        shared.late_ms.fetch_max(late, Ordering::Relaxed);
        due += Duration::from_millis(10);
        let now = shared.now_ms();
        let out_a =
            r.a.tick(&mut r.plant, now, r.commands.pop(), to_a.pop_front());
        let out_b = r.b.tick(&mut r.plant, now, to_b.pop_front());
        if let Some(b) = out_a.to_b {
            to_b.push_back(b);
        }
        if let Some(h) = out_b.heartbeat {
            to_a.push_back(h);
        }
        if let Some(hb) = out_a.heartbeat {
            if let Err(full) = r.heartbeats.push(hb) {
                r.heartbeats.give_up(full);
            }
            r.notify.notify_one();
        }
    }
}

/// Board A's WiFi task: one server connection at a time.
async fn wifi_task(
    listener: TcpListener,
    mut commands: Producer<'static, COMMAND_LEN, 8>,
    mut heartbeats: Consumer<'static, HEARTBEAT_LEN, 8>,
    notify: Arc<Notify>,
    loss: f64,
    seed: u64,
    shared: Arc<Shared>,
) {
    let mut rng = fastrand::Rng::with_seed(seed);
    let mut lost = move || loss > 0.0 && rng.f64() < loss;
    let mut session = WifiSession::new(WifiConfig::default());
    while !shared.stop.load(Ordering::Relaxed) {
        let accepted = tokio::time::timeout(Duration::from_millis(200), listener.accept()).await;
        let Ok(Ok((mut sock, peer))) = accepted else {
            continue;
        };
        // Only the server board's address holds the slot (loopback here).
        if !crate::sim::nodes::from_server(&peer, std::net::Ipv4Addr::LOCALHOST.into()) {
            drop(sock);
            continue;
        }
        let _ = sock.set_nodelay(true);
        // Heartbeats made while nobody was connected are not sent to the next connection.
        session.open(
            shared.now_ms(),
            std::iter::from_fn(|| heartbeats.pop()),
            drop,
        );
        let mut buf = [0u8; 256];
        loop {
            tokio::select! {
                r = sock.read(&mut buf) => {
                    let Ok(k) = r else { break };
                    if k == 0 {
                        break;
                    }
                    session.received(shared.now_ms(), &buf[..k], |p| {
                        if !lost() {
                            if let Err(full) = commands.push(p) {
                                commands.give_up(full);
                            }
                        }
                    });
                }
                _ = notify.notified() => {
                    while let Some(hb) = heartbeats.pop() {
                        let Outgoing::Send(hb) = session.heartbeat(hb) else { continue };
                        if !lost() && sock.write_all(&hb).await.is_err() {
                            break;
                        }
                    }
                }
            }
        }
        session.close();
    }
}

/// The server board: the ground's packets on its UDP socket, visits of board A over TCP.
async fn server_task(
    sock: UdpSocket,
    ground: SocketAddr,
    board: BoardNumber,
    a_addr: SocketAddr,
    cfg: SimConfig,
    shared: Arc<Shared>,
) {
    let mut buf = [0u8; 2048];
    match cfg.protocol {
        Protocol::Legacy => {
            let mut srv: Server<4> = Server::new();
            while !shared.stop.load(Ordering::Relaxed) {
                let got =
                    tokio::time::timeout(Duration::from_millis(200), sock.recv(&mut buf)).await;
                let Ok(Ok(k)) = got else { continue };
                if let Ok(p) = <[u8; COMMAND_LEN]>::try_from(&buf[..k]) {
                    let _ = srv.accept(&p);
                }
                // Anything else that arrived meanwhile, then the visits.
                while let Ok(k) = sock.try_recv(&mut buf) {
                    if let Ok(p) = <[u8; COMMAND_LEN]>::try_from(&buf[..k]) {
                        let _ = srv.accept(&p);
                    }
                }
                while let Some(mut v) = Visit::next(&mut srv, shared.now_ms(), cfg.visit_ms) {
                    // Marked delivered before the write, as before: a robot of another
                    // server board's fleet, or a visit that fails, is not retried.
                    v.written(&mut srv);
                    if v.board() != board {
                        continue;
                    }
                    if let Some(hb) = visit(a_addr, &mut v, &shared).await {
                        let _ = sock.send_to(&hb, ground).await;
                    }
                }
            }
        }
        Protocol::Pus => {
            let mut g: Box<Gateway<1, 8, 64>> = Box::new(Gateway::new(cfg.gateway));
            g.add(board);
            let wait = cfg.gateway.uplink.timeout_ms;
            while !shared.stop.load(Ordering::Relaxed) {
                let now = shared.now_ms();
                let sleep = g
                    .next_deadline(now)
                    .map_or(200, |t| t.saturating_sub(now).clamp(1, 200));
                if let Ok(Ok(k)) =
                    tokio::time::timeout(Duration::from_millis(sleep as u64), sock.recv(&mut buf))
                        .await
                {
                    if let Ok(out) = g.tc_packet(&buf[..k]) {
                        send_reports(&sock, ground, &mut g, out, shared.now_ms()).await;
                    }
                }
                let out = g.tick(shared.now_ms());
                let visits: Vec<_> = out.to_robots.iter().map(|(b, c)| (*b, *c)).collect();
                send_reports(&sock, ground, &mut g, out, shared.now_ms()).await;
                for (b, c) in visits {
                    if b != board {
                        continue;
                    }
                    let mut v = Visit::new(shared.now_ms(), b, c.to_bytes(), wait);
                    let hb = visit(a_addr, &mut v, &shared)
                        .await
                        .and_then(|h| HeartbeatRepr::parse(&h).ok());
                    if let Some(hb) = hb {
                        let out = g.heartbeat(shared.now_ms(), &hb);
                        send_reports(&sock, ground, &mut g, out, shared.now_ms()).await;
                    }
                }
            }
        }
    }
}

/// The gateway's reports, each a datagram to the ground.
async fn send_reports<const M: usize>(
    sock: &UdpSocket,
    ground: SocketAddr,
    g: &mut Gateway<1, 8, 64>,
    out: mmic::node::server::gateway::Out<M>,
    now: u32,
) {
    const MAX: usize = mmic::ccsds::tm::TM_MIN_LEN + mmic::node::server::gateway::MAX_TM_DATA;
    for tm in &out.reports {
        let mut b = [0u8; MAX];
        if let Ok(k) = g.encode(tm, now, &mut b) {
            let _ = sock.send_to(&b[..k], ground).await;
        }
    }
}

/// One visit of board A: connect, send, the first heartbeat by the visit's deadline (the
/// library's [`Visit`] decides), disconnect (with an abortive close, so that a thousand visits
/// a second leave no TIME_WAIT sockets behind).
async fn visit(a: SocketAddr, v: &mut Visit, shared: &Shared) -> Option<[u8; HEARTBEAT_LEN]> {
    let left = v.left_ms(shared.now_ms())?;
    let deadline = tokio::time::Instant::now() + Duration::from_millis(left as u64);
    let mut sock = tokio::time::timeout_at(deadline, TcpStream::connect(a))
        .await
        .ok()?
        .ok()?;
    let _ = sock.set_nodelay(true);
    let _ = sock.set_zero_linger();
    sock.write_all(v.packet()).await.ok()?;
    let mut buf = [0u8; 256];
    loop {
        let k = tokio::time::timeout_at(deadline, sock.read(&mut buf))
            .await
            .ok()?
            .ok()?;
        if k == 0 {
            return None;
        }
        if let Some(hb) = v.received(&buf[..k]) {
            return Some(hb);
        }
    }
}

/// The ground: every robot's plan runner over one UDP socket, a tick every 10 ms.
async fn ground_task<G: Ground>(
    cfg: &SimConfig,
    runners: Vec<G>,
    sock: Arc<UdpSocket>,
    servers: Vec<SocketAddr>,
    shared: &Shared,
) -> std::io::Result<(Ends, crate::sim::shell::GroundStats)> {
    let robot_of: HashMap<SocketAddr, usize> =
        servers.iter().enumerate().map(|(i, a)| (*a, i)).collect();
    let mut ground = GroundSide::new(
        &cfg.steps,
        cfg.start_state,
        &cfg.injections,
        runners,
        false,
        None,
    );
    let mut ticker = tokio::time::interval(Duration::from_millis(10));
    ticker.set_missed_tick_behavior(MissedTickBehavior::Delay);
    let mut buf = [0u8; 2048];
    loop {
        tokio::select! {
            _ = ticker.tick() => {
                let now = shared.now_ms();
                if now > cfg.max_sim_ms || ground.all_done() {
                    return Ok(ground.finish(now));
                }
                for (i, addr) in servers.iter().enumerate() {
                    if let Some(p) = ground.tick(i, now) {
                        let _ = sock.send_to(&p, addr).await;
                    }
                }
            }
            r = sock.recv_from(&mut buf) => {
                let (k, from) = r?;
                if let Some(&i) = robot_of.get(&from) {
                    let now = shared.now_ms();
                    if let Some(p) = ground.receive(i, now, &buf[..k]) {
                        let _ = sock.send_to(&p, servers[i]).await;
                    }
                }
            }
        }
    }
}
