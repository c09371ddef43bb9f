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

mod agenda;
mod attacker;
mod boards;
mod deliver;
mod frames;
mod ground;
mod planted;
mod restart;
mod robot;
mod server;
mod state;

pub use boards::WIFI_TASK_US;
pub use ground::GROUND_TICK_MS;
pub use planted::PlantedBug;

use super::inject::{Injection, Node};
use super::log::{self, Log};
use super::shell::{Ground, GroundSide, LegacyGround};
use super::{LinkLayer, Protocol, SimConfig, Summary};
use agenda::{Agenda, Ev};
use link::LinkModel;
use mmic::node::ground::plan_runner::PlanRunner;
use robot::{board_number, Robot};
use serde_json::Value;
use state::{record_header, Engine};
use std::time::Instant;
use watch::Watch;

/// The boards' control period, ms.
pub const TICK_MS: u32 = 10;

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
            new_engine(cfg, runners, watched)?.run()
        }
        Protocol::Pus => {
            let runners = (0..n)
                .map(|i| PlanRunner::pus(cfg.ground_pus(), board_number(i)))
                .collect();
            new_engine(cfg, runners, watched)?.run()
        }
    }
}

/// The engine at the start of a run of `cfg` with these plan runners, its first events due.
fn new_engine<G: Ground>(
    cfg: &SimConfig,
    runners: Vec<G>,
    watched: bool,
) -> std::io::Result<Engine<'_, G>> {
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
        agenda: Agenda::default(),
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
    e.first_events();
    Ok(e)
}

impl<G: Ground> Engine<'_, G> {
    /// The run's first events: the boards' and the ground's ticks, the gateways' first
    /// loops, the restarts of the scenario.
    fn first_events(&mut self) {
        let cfg = self.cfg;
        self.at(0, Ev::TickA);
        self.at(cfg.b_phase_us % 10_000, Ev::TickB);
        if cfg.protocol == Protocol::Pus {
            for i in 0..self.robots.len() {
                self.wake_server(i, 0);
                // The ground initiates the AD service; it runs once a CLCW confirms it.
                if let Some(gl) = self.robots[i].ground_link.as_mut() {
                    gl.start(0, &mut |_: &[u8]| {});
                }
            }
        }
        self.at(0, Ev::GroundTick);
        for s in &cfg.injections {
            if let Injection::Reboot(node) = s.injection {
                self.at(u64::from(s.at_ms) * 1000, Ev::Reboot(node));
            }
        }
    }

    fn run(mut self) -> std::io::Result<(Summary, Option<Watch>)> {
        let wall = Instant::now();
        let max_us = (self.cfg.max_sim_ms as u64 + 1) * 1000;
        while let Some((at, ev)) = self.agenda.pop() {
            if at > max_us {
                break;
            }
            self.now = at;
            if !self.handle(ev) {
                break;
            }
        }
        let now = self.now_ms();
        self.watch_end(now);
        if let Some(r) = self.robots.first() {
            self.status = r.a.status(now - now % TICK_MS);
        }
        self.finish(now, wall)
    }

    /// The watch's last judgements: the commands still open, the SDLS counts.
    fn watch_end(&mut self, now: u32) {
        let Some(w) = &mut self.watch else {
            return;
        };
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

    /// The run's summary (its trace and log written, if asked for).
    fn finish(self, now: u32, wall: Instant) -> std::io::Result<(Summary, Option<Watch>)> {
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
            Ev::Close { robot, conn } => self.wifi_closed(robot, conn),
            Ev::VisitTimeout { robot, conn } => self.visit_timeout(robot, conn),
            Ev::Server { robot, token } => self.server_woken(robot, token),
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
}
