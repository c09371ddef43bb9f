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
use mmic::node::ground;
use mmic::node::handoff::PacketQueue;
use mmic::node::plan_runner::{PlanEnd, PlanRunner, PlanStep};
use mmic::units::BoardNumber;
use mmic::wire::heartbeat::HeartbeatRepr;
use nodes::Lossy;
pub use plant::PlantConfig;
use serde_json::{json, Value};
use std::io::Write;
use std::net::TcpListener;
use std::path::PathBuf;
use std::sync::atomic::{AtomicBool, AtomicU32, Ordering};
use std::sync::{Arc, Mutex};
use std::time::Duration;
pub use steps::{demo_steps, steps_of, SimStep, DEMO_PLAN};

/// What to simulate.
#[derive(Debug, Clone)]
pub struct SimConfig {
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
        }
    }
}

/// What a run produced.
#[derive(Debug, Clone)]
pub struct Summary {
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
    fn lossy(
        &self,
        out: std::io::PipeWriter,
        link: &'static str,
        (from, to): (&str, &str),
        loss: f64,
        cut_at: Option<u32>,
        seed: u64,
        k: u64,
    ) -> Lossy<std::io::PipeWriter> {
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
    let (ground_to_server, server_to_ground) = (serial(scope)?, serial(scope)?);
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
    Ok((to_server, server_to_ground.read, board))
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
        let out = ground_loop(cfg, &steps, ground_links, clock.node(), env.log.clone());
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
        ends,
        plan: cfg.steps.clone(),
        start_state: cfg.start_state,
        wifi_loss: cfg.wifi_loss,
        visit_ms: cfg.visit_ms,
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
    Lossy<std::io::PipeWriter>,
    std::sync::mpsc::Receiver<Vec<u8>>,
    BoardNumber,
);

/// The ground's part of an injection: an out-of-band command handed to the plan runner, or
/// the next reconfiguration misstated; nothing for the plant's and the line's. Returns why
/// the runner did not take the command, if it did not.
fn ground_injection(run: &mut PlanRunner, injection: inject::Injection) -> Option<String> {
    if let Some(c) = injection.command() {
        return run.interject(c).err().map(|e| e.to_string());
    }
    if injection == inject::Injection::Fault(mmic::faults::Table8::InitialStateMismatch) {
        run.misstate_next_reconfiguration();
    }
    None
}

/// The opsUI: one plan runner per robot, in one thread (one ground process).
fn ground_loop(
    cfg: &SimConfig,
    steps: &[PlanStep],
    mut links: Vec<GroundLink>,
    clock: clock::NodeClock<'_>,
    log: Option<log::Log>,
) -> (Vec<Option<PlanEnd>>, GroundStats) {
    let mut runners: Vec<PlanRunner> = links
        .iter()
        .map(|(_, _, b)| PlanRunner::new(cfg.ground, *b))
        .collect();
    let mut ends: Vec<Option<PlanEnd>> = vec![None; runners.len()];
    let mut sent_at: Vec<Option<u32>> = vec![None; runners.len()];
    let mut last_hb: Vec<Option<HeartbeatRepr>> = vec![None; runners.len()];
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
                let refused = ground_injection(run, inj.injection);
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
                if let Ok(hb) = HeartbeatRepr::parse(&bytes) {
                    let t = clock.now_ms();
                    if let Some(s) = sent_at[i] {
                        if hb.last_seq == run.uplink().outstanding().unwrap_or(0) {
                            stats.max_latency_ms = stats.max_latency_ms.max(t.saturating_sub(s));
                        }
                    }
                    ticks.push(run.heartbeat(steps, t, &hb));
                    last_hb[i] = Some(hb);
                }
            }
            for t in ticks {
                if let Some(p) = t.send {
                    sent_at[i] = Some(now);
                    writer.send(now, &p.to_bytes());
                }
                if let Some(ok) = t.attempt {
                    stats.attempts.1 += 1;
                    stats.attempts.0 += ok as u64;
                    if i == 0 {
                        let e = run.uplink().efficiency().percent().unwrap_or(0);
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
        if let Some(hb) = &last_hb[0] {
            let eff = runners[0].uplink().efficiency();
            progress.status(now, hb, eff);
        }
        std::thread::sleep(Duration::from_micros(500));
    }
    progress.finish();
    let _ = std::io::stderr().flush();
    stats.last_heartbeat = last_hb.first().copied().flatten();
    (ends, stats)
}
