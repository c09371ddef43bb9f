//! The host simulator: the four nodes of Figure 3 — the ground's plan runner (opsUI), the
//! server board, board A (its WiFi task and its control task, joined by the library's
//! hand-off queues) and board B — run the real library around a plant model ([`plant`]).
//!
//! Two engines run the same node code ([`shell`]):
//!
//! * **virtual time** ([`engine`], the default): a discrete-event simulation in one thread, on
//!   one virtual clock, with simulated links (latency, jitter, loss, duplication, reordering,
//!   cuts). Deterministic — the same configuration and seed give a byte-identical log — and
//!   thousands of times faster than real time;
//! * **realtime** ([`realtime`], `mmic sim --realtime`, [`SimConfig::realtime`]): threads, OS
//!   pipes, TCP and UDP on loopback, on the wall clock times a scale. It proves the transports;
//!   its timing depends on the host.
//!
//! ```
//! use mmic_host::sim::{run, SimConfig};
//! let mut cfg = SimConfig::demo();
//! cfg.progress = false;
//! let summary = run(&cfg).expect("simulation ran");
//! assert!(summary.completed());
//! ```
//!
//! Losses are injected per link ([`SimConfig::wifi_loss`], …): a lost packet is logged with
//! fate `lost` and never written. Each of Table 8's ten faults, a silent sensor, and the
//! operator's Stop and Reset, can be injected at a time ([`inject`], [`SimConfig::inject`]):
//! in the plant ([`PlantConfig`]: a jammed fastener, a dead switch, an obstacle, an offset or
//! silent encoder, a silent ADC, a sagging battery), on the A–B line (cut, both directions) or
//! from the ground (a misstated reconfiguration, out-of-band commands).
//!
//! [`Protocol::Pus`] runs the same plans over CCSDS/PUS: the ground's plan runner sends PUS-C
//! telecommands ([`mmic::node::ground::pus`]) to the server board (UDP on loopback in the
//! realtime engine), which runs the PUS gateway ([`mmic::node::server::gateway`]) instead of the legacy
//! relay and sends its ST\[1\], ST\[3\], ST\[5\] and ST\[17\] telemetry back; the server board
//! and board A talk as before.

pub mod bench;
pub mod clock;
pub mod downtime;
pub mod durable;
pub mod engine;
pub mod inject;
pub mod lockstep;
pub mod log;
pub mod nodes;
pub mod opsline;
pub mod plant;
pub mod progress;
pub mod realtime;
pub mod report;
pub mod serial_line;
pub mod shell;
pub mod steps;

use mmic::link::sdls::{Key256, SdlsRefusal};
use mmic::motion::State;
use mmic::node::exactly_once::uplink;
use mmic::node::ground::plan_runner::PlanEnd;
use mmic::node::ground::pus;
use mmic::node::server::gateway;
use mmic::wire::heartbeat::HeartbeatRepr;
pub use plant::PlantConfig;
use serde_json::Value;
use std::path::PathBuf;
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

/// With [`Protocol::Pus`], what carries the packets between the ground and the server board.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum LinkLayer {
    /// One space packet per datagram.
    #[default]
    Packets,
    /// The space data link: TC transfer frames under COP-1 (the ground's FOP-1, the server
    /// board's FARM-1), fixed-length TM transfer frames with the CLCW
    /// ([`mmic::node::server::frames`], [`mmic::node::ground::frames`]).
    Frames,
}

impl LinkLayer {
    /// Its name on the command line and in the summary.
    pub const fn name(self) -> &'static str {
        match self {
            LinkLayer::Packets => "packets",
            LinkLayer::Frames => "frames",
        }
    }
}

impl std::str::FromStr for LinkLayer {
    type Err = String;
    fn from_str(s: &str) -> Result<LinkLayer, String> {
        match s {
            "packets" => Ok(LinkLayer::Packets),
            "frames" => Ok(LinkLayer::Frames),
            _ => Err(format!("{s:?} is no link: packets or frames")),
        }
    }
}

/// What the space data link did in a run with [`LinkLayer::Frames`], all robots.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, serde::Serialize)]
pub struct FrameStats {
    /// TC frames the ground sent (AD first transmissions, retransmissions, BC).
    pub tc_frames: u64,
    /// AD frames sent again by FOP-1 (the Retransmit flag, timer T1).
    pub retransmissions: u64,
    /// FOP-1 alerts (transmission limit, lockout, ...), each followed by a re-initiation.
    pub alerts: u64,
    /// CLCWs the ground received.
    pub clcws: u64,
    /// Of those, reporting Lockout.
    pub lockout_reports: u64,
    /// AD frames FARM-1 accepted.
    pub accepted: u64,
    /// Frames FARM-1 discarded (out of sequence, no buffer, locked out).
    pub discarded: u64,
    /// TM frames the server boards sent.
    pub tm_frames: u64,
    /// TM frames the ground's extractor found missing (VC frame count gaps).
    pub tm_lost: u64,
    /// TM packets dropped because a lost frame cut them.
    pub tm_packets_dropped: u64,
    /// SDLS on the link (`--sdls`): both ends' figures, and the attacker's.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub sdls: Option<SdlsStats>,
}

/// One end's SDLS figures ([`mmic::link::sdls::SdlsCounters`], summed over robots).
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, serde::Serialize)]
pub struct SdlsEnd {
    /// Frames that verified.
    pub verified: u64,
    /// Frames protected.
    pub protected: u64,
    /// Frames refused, by reason ([`SdlsRefusal::NAMES`]).
    #[serde(serialize_with = "by_reason")]
    pub refused: [u64; SdlsRefusal::NAMES.len()],
}

impl SdlsEnd {
    fn add(&mut self, c: &mmic::link::sdls::SdlsCounters) {
        self.verified += u64::from(c.accepted);
        self.protected += u64::from(c.protected);
        for (a, b) in self.refused.iter_mut().zip(c.refused) {
            *a += u64::from(b);
        }
    }

    fn merged(self, o: SdlsEnd) -> SdlsEnd {
        let mut refused = self.refused;
        for (a, b) in refused.iter_mut().zip(o.refused) {
            *a += b;
        }
        SdlsEnd {
            verified: self.verified + o.verified,
            protected: self.protected + o.protected,
            refused,
        }
    }

    /// Frames refused for any reason.
    pub fn refused_total(&self) -> u64 {
        self.refused.iter().sum()
    }

    /// The refusals as `name n, ...` (the reasons counted only), or `none`.
    pub fn refusals_text(&self) -> String {
        let parts: Vec<String> = SdlsRefusal::NAMES
            .iter()
            .zip(self.refused)
            .filter(|(_, n)| *n > 0)
            .map(|(name, n)| format!("{name} {n}"))
            .collect();
        if parts.is_empty() {
            "none".into()
        } else {
            parts.join(", ")
        }
    }
}

fn by_reason<S: serde::Serializer>(
    refused: &[u64; SdlsRefusal::NAMES.len()],
    s: S,
) -> Result<S::Ok, S::Error> {
    use serde::ser::SerializeMap;
    let mut m = s.serialize_map(Some(refused.len()))?;
    for (name, n) in SdlsRefusal::NAMES.iter().zip(refused) {
        m.serialize_entry(name, n)?;
    }
    m.end()
}

/// SDLS's figures of a run with [`SimConfig::sdls`], all robots.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, serde::Serialize)]
pub struct SdlsStats {
    /// The server boards' end: TC frames verified (and refused), TM frames protected.
    pub server: SdlsEnd,
    /// The ground's end: TC frames protected, TM frames verified (and refused).
    pub ground: SdlsEnd,
    /// Frames the attacker on the uplink sent (replays and bit-flipped copies of captured TC
    /// data frames, [`SdlsConfig::attack`]).
    pub attack_frames: u64,
    /// Of those, refused by SDLS.
    pub attacks_refused_sdls: u64,
    /// Of those, refused by a frame check before SDLS (a flipped bit in a field the frame
    /// checks read: the version, the flags, the length, the spacecraft ID, ...).
    pub attacks_refused_frame: u64,
    /// Of those, passed on to FARM-1: none may be.
    pub attacks_passed: u64,
}

impl SdlsStats {
    /// Both together: every figure summed.
    pub fn merged(self, o: SdlsStats) -> SdlsStats {
        SdlsStats {
            server: self.server.merged(o.server),
            ground: self.ground.merged(o.ground),
            attack_frames: self.attack_frames + o.attack_frames,
            attacks_refused_sdls: self.attacks_refused_sdls + o.attacks_refused_sdls,
            attacks_refused_frame: self.attacks_refused_frame + o.attacks_refused_frame,
            attacks_passed: self.attacks_passed + o.attacks_passed,
        }
    }
}

/// Merges two optional SDLS figures (none when neither end had SDLS).
fn merge_sdls(a: Option<SdlsStats>, b: Option<SdlsStats>) -> Option<SdlsStats> {
    match (a, b) {
        (Some(a), Some(b)) => Some(a.merged(b)),
        (a, b) => a.or(b),
    }
}

impl FrameStats {
    /// Adds the ground's end of one robot's link: the TC frames FOP-1 sent, its alerts, the
    /// CLCWs it heard, the TM frames its extractor found missing.
    pub fn add_ground<const K: usize, const Q: usize, const N: usize>(
        &mut self,
        gl: &mmic::node::ground::frames::GroundLink<K, Q, N>,
    ) {
        let c = gl.counters();
        self.tc_frames += u64::from(c.ad_frames) + u64::from(c.bc_frames);
        self.retransmissions += u64::from(c.retransmissions);
        self.alerts += c.alerts.iter().map(|&a| u64::from(a)).sum::<u64>();
        self.clcws += u64::from(c.clcws);
        self.lockout_reports += u64::from(c.lockouts);
        let x = gl.extract_counters();
        self.tm_lost += u64::from(x.lost_frames);
        self.tm_packets_dropped += u64::from(x.dropped);
        if let Some(c) = gl.security() {
            self.sdls.get_or_insert_default().ground.add(c);
        }
    }

    /// Adds the server board's end of robot `board`'s link: what its FARM-1 accepted and
    /// discarded, the TM frames it sent.
    pub fn add_server<const R: usize, const Q: usize, const K: usize, const N: usize>(
        &mut self,
        g: &mmic::node::server::frames::FrameGateway<R, Q, K, N>,
        board: mmic::units::BoardNumber,
    ) {
        if let Some(f) = g.farm(board) {
            self.accepted += u64::from(f.counters().accepted_ad);
            self.discarded += f
                .counters()
                .discarded
                .iter()
                .map(|&d| u64::from(d))
                .sum::<u64>();
        }
        if let Some(c) = g.counters(board) {
            self.tm_frames += u64::from(c.tm_frames);
        }
        if let Some(c) = g.security(board) {
            self.sdls.get_or_insert_default().server.add(c);
        }
    }

    /// Both ends together: every figure summed.
    pub fn merged(self, o: FrameStats) -> FrameStats {
        FrameStats {
            tc_frames: self.tc_frames + o.tc_frames,
            retransmissions: self.retransmissions + o.retransmissions,
            alerts: self.alerts + o.alerts,
            clcws: self.clcws + o.clcws,
            lockout_reports: self.lockout_reports + o.lockout_reports,
            accepted: self.accepted + o.accepted,
            discarded: self.discarded + o.discarded,
            tm_frames: self.tm_frames + o.tm_frames,
            tm_lost: self.tm_lost + o.tm_lost,
            tm_packets_dropped: self.tm_packets_dropped + o.tm_packets_dropped,
            sdls: merge_sdls(self.sdls, o.sdls),
        }
    }
}

/// What to simulate.
#[derive(Debug, Clone)]
pub struct SimConfig {
    /// How the ground and the server board talk.
    pub protocol: Protocol,
    /// With [`Protocol::Pus`], packets or frames.
    pub link: LinkLayer,
    /// The ground's telecommand link with [`Protocol::Pus`].
    pub pus: pus::Config,
    /// The server board's gateway with [`Protocol::Pus`] (its uplink to board A, polls,
    /// housekeeping interval).
    pub gateway: gateway::Config,
    /// The plan every robot runs.
    pub steps: Vec<SimStep>,
    /// Robots (each with its own server board and serial line to the one ground process).
    pub robots: u32,
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
    pub ground: uplink::Config,
    /// Stop after this much simulated time, ms.
    pub max_sim_ms: u32,
    /// How long the server waits for a heartbeat before disconnecting, ms: the relay's
    /// [`VISIT_MS`](mmic::node::server::relay::VISIT_MS) unless a test asks otherwise.
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
    /// An external ground (YAMCS) instead of the plan runner, with [`Protocol::Pus`]
    /// (realtime only: the ground's timeouts are wall time).
    pub external: Option<External>,
    /// Run on the wall clock with threads and real transports ([`realtime`]) instead of in
    /// virtual time ([`engine`]).
    pub realtime: bool,
    /// The virtual-time engine's link models (latency, jitter, duplication, reordering, cuts).
    pub links: engine::Links,
    /// Virtual time: board B ticks this long after board A in each 10 ms period, µs (the two
    /// boards' clocks are not synchronised).
    pub b_phase_us: u64,
    /// Log the nodes' events (off for large fleets, which keep only the summary).
    pub log_events: bool,
    /// Virtual time: a bug planted in the engine's shells, for the fault swarm's own test.
    pub planted_bug: engine::PlantedBug,
    /// Virtual time: run on to [`SimConfig::max_sim_ms`] after every plan ended (the robots
    /// idle, still watched), instead of stopping there.
    pub run_to_end: bool,
    /// SDLS on the space data link (`--sdls`, with [`LinkLayer::Frames`]): both ends of every
    /// robot's link secured, and an attacker on the uplink if [`SdlsConfig::attack`] says.
    pub sdls: Option<SdlsConfig>,
    /// Virtual time: write robot 1's replay trace here (`mmic sim --record`): every call of
    /// its nodes with its time, readings and bytes, for `mmic replay` and the RV32 runner
    /// (`benches/rv32`).
    pub record: Option<PathBuf>,
    /// Realtime, legacy protocol: the server board's opsUI line on a serial device (`mmic sim
    /// --opsui-serial DEV`, [`opsline`]) instead of the internal pipe, and no ground of its
    /// own: the run lasts until the line closes or [`SimConfig::max_sim_ms`].
    pub ops_line: Option<opsline::OpsLine>,
    /// Virtual time: the engine's exact shortcuts (the plant's hip angle kept within its turn
    /// without libm's `fmod` where it already is). On by default; off computes everything the
    /// long way, for the swarm's equivalence test (`host/tests/swarm_equivalence.rs`), which
    /// finds the same runs byte for byte.
    pub shortcuts: bool,
}

/// An external ground on UDP (`mmic sim --protocol pus --ground-tm-to ADDR --ground-tc-port
/// P`): the server board's gateway takes telecommands on 127.0.0.1:`tc_port` and sends its
/// telemetry to `tm_to`; no plan runs; the run ends after [`SimConfig::max_sim_ms`] of wall
/// time (the scale is 1, since the ground's timeouts run on the wall clock) or when killed.
/// One JSON line per packet on `wire` ([`nodes::WireLog`]), after `{"ready":true,"tc_port":P}`;
/// with [`LinkLayer::Frames`] TC and TM transfer frames instead of packets, one per datagram,
/// and one line per frame ([`nodes::FrameGatewayTask`]).
#[derive(Clone)]
pub struct External {
    /// Where telemetry goes (YAMCS's UDP TM link).
    pub tm_to: std::net::SocketAddr,
    /// The port telecommands arrive on (YAMCS's UDP TC link sends there); 0: any free one.
    pub tc_port: u16,
    /// Where the packet lines go (stdout in the CLI).
    pub wire: nodes::WireLog,
    /// SDLS on the space data link (`--sdls-keys`): robot 1's TC and TM keys.
    pub sdls: Option<(mmic::link::sdls::Key256, mmic::link::sdls::Key256)>,
    /// The server board's durable store (`--sdls-state FILE` with SDLS; without, memory for
    /// the run): SDLS counters, FARM-1's progress, the kept telecommand keys.
    pub store: durable::Durable,
}

impl std::fmt::Debug for External {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("External")
            .field("tm_to", &self.tm_to)
            .field("tc_port", &self.tc_port)
            .field("sdls", &self.sdls.is_some())
            .finish_non_exhaustive()
    }
}

/// Where a run's SDLS keys come from.
#[derive(Clone)]
pub enum SdlsKeys {
    /// Derived from the run's seed (the virtual-time engine's default: a run stays
    /// deterministic). For simulation only: anyone with the seed has the keys.
    Seeded,
    /// Made at run time from the operating system's random source (the realtime engine's
    /// default).
    Random,
    /// Read from files (`--sdls-keys DIR`): each robot's (TC, TM) keys, by robot index.
    Given(Vec<(Key256, Key256)>),
    /// Test keys made at random for one recorded run (`mmic replay --record-scenarios`),
    /// robot 1's, written into its replay trace (the other robots' derived from the seed):
    /// the only keys a trace may hold.
    Recorded(mmic_replay::trace::TestKeys),
}

/// SDLS in a run's own grounds ([`SimConfig::sdls`]).
#[derive(Clone)]
pub struct SdlsConfig {
    /// The keys.
    pub keys: SdlsKeys,
    /// The durable store of given keys' counters (`--sdls-state FILE`, made by `mmic sdls
    /// provision`): required with [`SdlsKeys::Given`], unused with keys made for the run.
    pub state: Option<PathBuf>,
    /// Virtual time: the attacker on each robot's uplink. For each TC frame the uplink
    /// delivers, the chance that the attacker also sends one frame, from its own address: a
    /// captured TC data frame again (a replay), a copy with one bit flipped and its FECF made
    /// good again (so that it gets past the FECF check to SDLS), or a BC frame (Unlock, Set
    /// V(R) to any value: refused as not from the ground), a third each. 0: no attacker.
    pub attack: f64,
}

impl std::fmt::Debug for SdlsConfig {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        let keys = match &self.keys {
            SdlsKeys::Seeded => "seeded",
            SdlsKeys::Random => "random",
            SdlsKeys::Given(_) => "given",
            SdlsKeys::Recorded(_) => "recorded",
        };
        f.debug_struct("SdlsConfig")
            .field("keys", &keys)
            .field("attack", &self.attack)
            .finish()
    }
}

/// Mixes the seeded keys' stream apart from every other draw of a run.
const SDLS_KEY_STREAM: u64 = 0x5d15_6b65_7900_0000;

impl SdlsConfig {
    /// Robot `i`'s (TC, TM) keys in a run seeded `seed`: given, derived from the seed, or
    /// random. Given keys for fewer robots than the run has: the rest are derived from the
    /// seed.
    pub fn keys(&self, seed: u64, i: usize) -> std::io::Result<(Key256, Key256)> {
        let seeded = |k: u64| {
            let mut rng = fastrand::Rng::with_seed(
                seed ^ SDLS_KEY_STREAM ^ (i as u64).wrapping_mul(0x9e37_79b9) ^ (k << 40),
            );
            let mut b = [0u8; mmic::link::sdls::KEY_LEN];
            rng.fill(&mut b);
            let k = Key256::from_bytes(b);
            zeroize::Zeroize::zeroize(&mut b);
            k
        };
        match &self.keys {
            SdlsKeys::Given(v) if i < v.len() => Ok(v[i].clone()),
            SdlsKeys::Recorded(k) if i == 0 => Ok(k.keys()),
            SdlsKeys::Given(_) | SdlsKeys::Seeded | SdlsKeys::Recorded(_) => {
                Ok((seeded(1), seeded(2)))
            }
            SdlsKeys::Random => {
                let read = || -> std::io::Result<Key256> {
                    let mut b = zeroize::Zeroizing::new([0u8; mmic::link::sdls::KEY_LEN]);
                    std::io::Read::read_exact(
                        &mut std::fs::File::open("/dev/urandom")?,
                        b.as_mut_slice(),
                    )?;
                    Ok(Key256::from_bytes(*b))
                };
                Ok((read()?, read()?))
            }
        }
    }
}

impl SdlsConfig {
    /// SDLS for a recorded scenario: robot 1's keys made at random now (fresh for every
    /// recording: test keys, written into the trace), no attacker, no state file.
    pub fn recorded() -> SdlsConfig {
        let mut rng = fastrand::Rng::new();
        let mut key = || {
            let mut b = [0u8; mmic::link::sdls::KEY_LEN];
            rng.fill(&mut b);
            b
        };
        let (tc, tm) = (key(), key());
        SdlsConfig {
            keys: SdlsKeys::Recorded(mmic_replay::trace::TestKeys::new(tc, tm)),
            state: None,
            attack: 0.0,
        }
    }

    /// The keys a replay trace of this run may hold: the recorded run's test keys, when there
    /// is no attacker (the replay runs the ground's frames only). `None`: the run cannot be
    /// recorded with SDLS (given keys never go into a file beside their state).
    pub fn trace_keys(&self) -> Option<mmic_replay::trace::TestKeys> {
        match &self.keys {
            SdlsKeys::Recorded(k) if self.attack == 0.0 => Some(*k),
            _ => None,
        }
    }

    /// The state file of given keys' counters, opened (`None`: no given keys).
    pub fn open_state(&self) -> std::io::Result<Option<durable::Durable>> {
        match (&self.keys, &self.state) {
            (SdlsKeys::Given(_), Some(path)) => durable::Durable::open(path)
                .map(Some)
                .map_err(|e| std::io::Error::new(std::io::ErrorKind::InvalidInput, e.to_string())),
            (SdlsKeys::Given(_), None) => Err(std::io::Error::new(
                std::io::ErrorKind::InvalidInput,
                "given SDLS keys need their durable state file (--sdls-state FILE): without it \
                 every run would start the counters afresh under the same keys (IV reuse)",
            )),
            _ => Ok(None),
        }
    }

    /// Robot `i`'s keys and the durable store of both ends of its link: for given keys the
    /// state file (`state`, from [`SdlsConfig::open_state`]), which must be provisioned for
    /// them; for keys made for the run a store in memory, provisioned here (both die with the
    /// run). Fails closed: keys that cannot be made stop the run.
    pub fn robot(
        &self,
        seed: u64,
        i: usize,
        state: Option<&durable::Durable>,
    ) -> std::io::Result<((Key256, Key256), durable::Durable)> {
        let keys = self.keys(seed, i)?;
        let board = mmic::units::BoardNumber::new((i % 255) as u8 + 1)
            .unwrap_or(mmic::units::BoardNumber::ONE);
        let store = match (&self.keys, state) {
            (SdlsKeys::Given(v), Some(d)) if i < v.len() => d.clone(),
            (SdlsKeys::Given(v), None) if i < v.len() => {
                return Err(std::io::Error::new(
                    std::io::ErrorKind::InvalidInput,
                    "given SDLS keys need their durable state file (--sdls-state FILE)",
                ))
            }
            _ => {
                let d = durable::Durable::memory();
                durable::provision_memory(&d, board, &keys)?;
                d
            }
        };
        Ok((keys, store))
    }
}

/// How far simulated time may run ahead of the slowest node of a paced run, ms: two of the
/// boards' 10 ms ticks, a 25th of the 500 ms communication timeout.
pub const PACE_SLACK_MS: u32 = 20;

impl SimConfig {
    /// The state a robot starts in when its plan does not say (`start` header): `a`, where
    /// the demo plan starts.
    pub const DEFAULT_START: State = State::A;

    /// The ground's telecommand link as it runs: [`SimConfig::pus`], and over frames with
    /// enough attempts to outlast FOP-1's (`pus::Config::under_cop1`).
    pub fn ground_pus(&self) -> pus::Config {
        match self.link {
            LinkLayer::Packets => self.pus,
            LinkLayer::Frames => self.pus.under_cop1(&mmic::link::fop::FopConfig::MISSION),
        }
    }

    /// The longest a command of the ground's may stay open, ms: every transmission its
    /// link makes before giving it up, and the last one's answer.
    pub fn command_life_ms(&self) -> u32 {
        let (period, attempts, answer) = match self.protocol {
            Protocol::Legacy => (
                self.ground.period_ms,
                u32::from(self.ground.max_attempts),
                self.ground.timeout_ms,
            ),
            Protocol::Pus => {
                let pus = self.ground_pus();
                (pus.timeout_ms, u32::from(pus.max_attempts), pus.timeout_ms)
            }
        };
        period.saturating_mul(attempts).saturating_add(answer)
    }

    /// The built-in demo plan at the default settings.
    pub fn demo() -> SimConfig {
        SimConfig::with_steps(demo_steps())
    }

    /// Default settings for these steps.
    pub fn with_steps(steps: Vec<SimStep>) -> SimConfig {
        SimConfig {
            protocol: Protocol::Legacy,
            link: LinkLayer::Packets,
            pus: pus::Config::default(),
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
            ground: uplink::Config {
                max_attempts: 20,
                ..uplink::Config::default()
            },
            max_sim_ms: 900_000,
            visit_ms: mmic::node::server::relay::VISIT_MS,
            log_path: None,
            log_packets: true,
            progress: false,
            paced: true,
            external: None,
            realtime: false,
            links: engine::Links::default(),
            b_phase_us: 3_000,
            log_events: true,
            planted_bug: engine::PlantedBug::None,
            run_to_end: false,
            record: None,
            sdls: None,
            ops_line: None,
            shortcuts: true,
        }
    }
}

/// What a run produced.
#[derive(Debug, Clone)]
pub struct Summary {
    /// The protocol between the ground and the server board.
    pub protocol: Protocol,
    /// Packets or frames (with [`Protocol::Pus`]).
    pub link: LinkLayer,
    /// The space data link's figures, with [`LinkLayer::Frames`].
    pub frames: Option<FrameStats>,
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
    /// The engine: the wall clock ([`realtime`]) or virtual time ([`engine`]).
    pub realtime: bool,
    /// Sequenced commands board A accepted more than once (per robot and number): 0 unless
    /// exactly-once broke. Counted by the virtual-time engine; the realtime engine counts from
    /// its log ([`Summary::events`]).
    pub executed_twice: u64,
    /// Restarts of board A, board B, the server board and the ground, all robots (`--inject
    /// reboot-*`; the ground's counted once per robot).
    pub restarts: [u32; 4],
}

impl Summary {
    /// A virtual-time run's summary of `cfg`: how the plans ended and what the ground
    /// measured, the log's records, robot 1's final status, the wall time it took (the
    /// realtime engine sets its own clock's figures over this).
    pub fn of_run(
        cfg: &SimConfig,
        ends: Vec<Option<PlanEnd>>,
        stats: shell::GroundStats,
        records: Vec<Value>,
        status: Value,
        wall: Duration,
    ) -> Summary {
        Summary {
            protocol: cfg.protocol,
            link: cfg.link,
            frames: None,
            ends,
            plan: cfg.steps.clone(),
            start_state: cfg.start_state,
            wifi_loss: cfg.wifi_loss,
            visit_ms: match cfg.protocol {
                Protocol::Legacy => cfg.visit_ms,
                Protocol::Pus => cfg.gateway.uplink.timeout_ms,
            },
            sim_ms: stats.sim_ms,
            wall,
            records,
            efficiency: stats.efficiency,
            attempts: stats.attempts,
            max_latency_ms: stats.max_latency_ms,
            status,
            max_tick_lateness_ms: 0,
            held_ms: 0,
            pace_slack_ms: None,
            last_heartbeat: stats.last_heartbeat,
            realtime: false,
            executed_twice: 0,
            restarts: [0; 4],
        }
    }

    /// Whether the host fell behind far enough to change what the firmware saw: a tick later
    /// than [`nodes::OVERRUN_MS`]. A paced run cannot get there (its ticks are at most
    /// [`PACE_SLACK_MS`] late); an unpaced run on a loaded host can, and then its timeouts
    /// and faults may come from the host.
    pub fn host_fell_behind(&self) -> bool {
        self.max_tick_lateness_ms >= nodes::OVERRUN_MS
    }
}

/// Runs the simulation to the end of every robot's plan (or the time limit): in virtual time
/// ([`engine::run`]), or on the wall clock when [`SimConfig::realtime`] ([`realtime::run`]).
pub fn run(cfg: &SimConfig) -> std::io::Result<Summary> {
    if cfg.realtime {
        realtime::run(cfg)
    } else {
        engine::run(cfg)
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
