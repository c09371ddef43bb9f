//! One seed's scenario: a plan, link impairments and a fault schedule, all drawn from the
//! seed, so that the seed alone replays the run.
//!
//! Two streams of draws per seed. The main stream draws, in this order, the protocol, the plan,
//! board B's phase, the losses, the links and the faults — as it has since the swarm began, so
//! a seed's scenario on these is what it always was. The link stream, seeded apart, draws what
//! came later: with [`Protocol::Pus`], whether the packets travel bare or in the space data
//! link's frames ([`LinkLayer`], half each unless [`Options::link`] says), and for frames the
//! ground link's loss, duplication and reordering again, heavier (COP-1 retransmits what is
//! lost, FARM-1 discards copies and frames out of order, the extractor skips stale TM frames:
//! these are the faults the frame link exists for), and then for frames whether the link is
//! secured with SDLS (half of them, unless [`Options::sdls`] says) and the rate of an attacker
//! on its uplink (in 0.7 of the secured runs, up to 0.3: replays and bit-flipped copies of
//! captured TC data frames). Adding a draw to the link stream leaves every main-stream draw of
//! every seed alone; `--link packets` gives a seed's scenario as it was before frames were
//! drawn, and the SDLS draws come after every earlier link-stream draw, so a frames run
//! without SDLS is the scenario it was before SDLS was drawn.

use crate::plan;
use crate::sim::engine::link::LinkModel;
use crate::sim::engine::{Links, PlantedBug};
use crate::sim::inject::{Injection, Scheduled};
use crate::sim::{LinkLayer, Protocol, SdlsConfig, SdlsKeys, SimConfig};
use mmic::motion::State;

/// What every scenario shares: the simulated span, a planted bug, if any, and the link layers
/// PUS scenarios draw from.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Options {
    /// Simulated ms each run lasts (the robot idles, still watched, after its plan ends).
    pub horizon_ms: u32,
    /// A bug planted in the engine's shells (for the swarm's own test).
    pub planted_bug: PlantedBug,
    /// The link layer of PUS scenarios: drawn, or always one.
    pub link: LinkDraw,
    /// SDLS on frames scenarios: drawn, or always or never.
    pub sdls: SdlsDraw,
    /// Node restarts: drawn, or never, or in every run.
    pub restarts: RestartDraw,
}

impl Default for Options {
    fn default() -> Options {
        Options {
            horizon_ms: 200_000,
            planted_bug: PlantedBug::None,
            link: LinkDraw::Any,
            sdls: SdlsDraw::Any,
            restarts: RestartDraw::Any,
        }
    }
}

/// Whether a scenario gets a feature drawn from its own stream: drawn (`any`), never (`off`:
/// every seed's scenario as before the feature was drawn) or always (`on`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum Draw {
    /// Drawn from the seed's stream.
    #[default]
    Any,
    /// Never.
    Off,
    /// In every run that can have it.
    On,
}

impl Draw {
    /// Its name on the command line.
    pub const fn name(self) -> &'static str {
        match self {
            Draw::Any => "any",
            Draw::Off => "off",
            Draw::On => "on",
        }
    }
}

impl std::str::FromStr for Draw {
    type Err = String;
    fn from_str(s: &str) -> Result<Draw, String> {
        match s {
            "any" => Ok(Draw::Any),
            "off" => Ok(Draw::Off),
            "on" => Ok(Draw::On),
            _ => Err(format!("{s:?} is no choice: any, off or on")),
        }
    }
}

/// Whether a scenario's nodes restart (`--inject reboot-*`): `any` draws it from the seed's
/// restart stream (0.4 of the runs, one to three restarts).
pub type RestartDraw = Draw;

/// The restart stream's draws for `seed`, seeded apart from the others (so that every earlier
/// draw of every seed stays what it was): whether the run has restarts (0.4 of them, unless
/// [`Options::restarts`] says), then one to three, each of board A, board B, the server board
/// or the ground (a quarter each) at a time in the run's fault window. All drawn whatever the choice, so the
/// stream stays aligned.
fn draw_restarts(seed: u64, opts: &Options, cfg: &mut SimConfig, latest: u32) {
    let mut rng = fastrand::Rng::with_seed(seed ^ RESTART_STREAM);
    let wanted = rng.f64() < 0.4;
    let n = rng.usize(1..=3);
    let draws: Vec<(Injection, u32)> = (0..3)
        .map(|_| {
            let node = Injection::REBOOTS[rng.usize(..Injection::REBOOTS.len())];
            (node, rng.u32(1_000..latest.max(1_001)))
        })
        .collect();
    let on = match opts.restarts {
        RestartDraw::Any => wanted,
        RestartDraw::Off => false,
        RestartDraw::On => true,
    };
    if on {
        for (injection, at_ms) in draws.into_iter().take(n) {
            let _ = cfg.inject(Scheduled { injection, at_ms });
        }
    }
}

/// The restart stream's seed mask.
const RESTART_STREAM: u64 = 0x5245_5354_0000_0000;

/// Whether a frames scenario's link is secured with SDLS: `any` draws it from the seed's link
/// stream (half of the frames runs).
pub type SdlsDraw = Draw;

/// The link layer a PUS scenario gets (legacy scenarios have none to choose).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum LinkDraw {
    /// Drawn from the seed's link stream: packets or frames, half each.
    #[default]
    Any,
    /// Always bare packets: every seed's scenario as before frames were drawn.
    Packets,
    /// Always the space data link's frames.
    Frames,
}

impl LinkDraw {
    /// Its name on the command line.
    pub const fn name(self) -> &'static str {
        match self {
            LinkDraw::Any => "any",
            LinkDraw::Packets => "packets",
            LinkDraw::Frames => "frames",
        }
    }
}

impl std::str::FromStr for LinkDraw {
    type Err = String;
    fn from_str(s: &str) -> Result<LinkDraw, String> {
        match s {
            "any" => Ok(LinkDraw::Any),
            "packets" => Ok(LinkDraw::Packets),
            "frames" => Ok(LinkDraw::Frames),
            _ => Err(format!("{s:?} is no link choice: any, packets or frames")),
        }
    }
}

/// A seed's scenario.
#[derive(Debug, Clone)]
pub struct Scenario {
    /// The seed it was drawn from.
    pub seed: u64,
    /// The protocol between the ground and the server board.
    pub protocol: Protocol,
    /// With [`Protocol::Pus`], packets or frames (legacy: packets, the serial line's own).
    pub link: LinkLayer,
    /// With frames: SDLS on the link, and the attacker's rate (0: none).
    pub sdls: Option<f64>,
    /// The plan's text (a plan file).
    pub plan: String,
    /// The run's simulator configuration (plan, links, losses, injections).
    pub cfg: SimConfig,
}

/// The faults a scenario draws from: every injection but the operator's Stop and Reset (which
/// it schedules in pairs of its own).
fn faults() -> Vec<Injection> {
    Injection::ALL
        .into_iter()
        .filter(|i| !matches!(i, Injection::Stop | Injection::Reset))
        .collect()
}

/// A random plan from a random state (any of the 15): Operational, a few reconfigurations (each
/// to a matched state, from where the previous one left the robot), bolts, unbolts and waits,
/// Standby; three seeds in ten run the demo plan instead.
fn random_plan(rng: &mut fastrand::Rng) -> String {
    if rng.f64() < 0.3 {
        return crate::sim::DEMO_PLAN.to_string();
    }
    let states = State::ALL;
    let mut at = states[rng.usize(..states.len())];
    let mut text = format!("robot 1\nstart {}\nmode operational\n", at.letter());
    for _ in 0..rng.usize(2..=6) {
        match rng.u8(0..10) {
            0..=4 => {
                // A reconfiguration ends in a matched state (Table 5), another than the start.
                let mut to = at;
                while to == at || !to.is_matched() {
                    to = states[rng.usize(..states.len())];
                }
                text.push_str(&format!("reconfigure {} -> {}\n", at.letter(), to.letter()));
                at = to;
            }
            5 | 6 => text.push_str(&format!("bolt {}\n", pair(rng))),
            7 => text.push_str(&format!("unbolt {}\n", pair(rng))),
            _ => text.push_str(&format!("wait {}s\n", rng.u8(1..=5))),
        }
    }
    text.push_str("mode standby\n");
    text
}

fn pair(rng: &mut fastrand::Rng) -> String {
    match rng.u8(0..5) {
        0 => "all".to_string(),
        p => p.to_string(),
    }
}

/// A probability drawn as 0 most of the time, else uniform in `0..max`.
fn sometimes(rng: &mut fastrand::Rng, p: f64, max: f64) -> f64 {
    if rng.f64() < p {
        rng.f64() * max
    } else {
        0.0
    }
}

/// Up to three cuts of a link, each 0.2..5 s, before the horizon.
fn cuts(rng: &mut fastrand::Rng, p: f64, horizon_ms: u32) -> Vec<(u32, Option<u32>)> {
    let mut out = Vec::new();
    for _ in 0..3 {
        let (take, from, len) = (
            rng.f64() < p,
            rng.u32(1_000..horizon_ms.max(2_000)),
            rng.u32(200..5_000),
        );
        if take {
            out.push((from, Some(from + len)));
        }
    }
    out
}

/// The link stream's seed: apart from the main stream's (`seed ^ 0x5_3a4a_0000`).
const LINK_STREAM: u64 = 0x4c49_4e4b_0000_0000;

/// The link stream's draws for `seed` (module docs): the link layer of a PUS scenario and, for
/// frames, the ground link's loss (in 0.6 of the runs, up to 0.3), duplication (0.5, up to 0.3)
/// and reordering (0.5, up to 0.2, by 10..300 ms), which replace the main stream's. Every value
/// is drawn whatever the outcome, so that the stream stays aligned for draws added after them;
/// then SDLS (half the frames runs) and the attacker's rate (0.7 of those, up to 0.3), with
/// keys derived from the seed.
fn draw_link(seed: u64, protocol: Protocol, opts: &Options, cfg: &mut SimConfig) -> LinkLayer {
    let choice = opts.link;
    let mut rng = fastrand::Rng::with_seed(seed ^ LINK_STREAM);
    let frames = rng.bool();
    let loss = sometimes(&mut rng, 0.6, 0.3);
    let duplicate = sometimes(&mut rng, 0.5, 0.3);
    let reorder = sometimes(&mut rng, 0.5, 0.2);
    let reorder_us = rng.u64(10_000..300_000);
    let secured = rng.bool();
    let attack = sometimes(&mut rng, 0.7, 0.3);
    let link = match (protocol, choice) {
        (Protocol::Legacy, _) | (_, LinkDraw::Packets) => LinkLayer::Packets,
        (Protocol::Pus, LinkDraw::Frames) => LinkLayer::Frames,
        (Protocol::Pus, LinkDraw::Any) if frames => LinkLayer::Frames,
        (Protocol::Pus, LinkDraw::Any) => LinkLayer::Packets,
    };
    cfg.link = link;
    if link == LinkLayer::Frames {
        cfg.serial_loss = loss;
        let g = &mut cfg.links.ground;
        g.duplicate = duplicate;
        g.reorder = reorder;
        g.reorder_us = reorder_us;
        let secured = match opts.sdls {
            SdlsDraw::Any => secured,
            SdlsDraw::Off => false,
            SdlsDraw::On => true,
        };
        cfg.sdls = secured.then_some(SdlsConfig {
            keys: SdlsKeys::Seeded,
            state: None,
            attack,
        });
    }
    link
}

/// Faults: none to three plant or link faults, each once; the operator's Stop (and, usually,
/// Reset) and the System fault command, which may repeat. Gives the latest time a fault is
/// drawn at, which the restarts' draws share.
fn draw_faults(rng: &mut fastrand::Rng, cfg: &mut SimConfig, horizon: u32) -> u32 {
    let latest = horizon.saturating_sub(3_000).max(2_000);
    let at = |rng: &mut fastrand::Rng| rng.u32(1_000..latest);
    let mut pool = faults();
    rng.shuffle(&mut pool);
    let k = [0, 0, 1, 1, 1, 2, 2, 3][rng.usize(..8)];
    for injection in pool.into_iter().take(k) {
        let t = at(rng);
        let _ = cfg.inject(Scheduled {
            injection,
            at_ms: t,
        });
    }
    for _ in 0..[0, 0, 1, 1, 2][rng.usize(..5)] {
        let t = at(rng);
        let _ = cfg.inject(Scheduled {
            injection: Injection::Stop,
            at_ms: t,
        });
        if rng.f64() < 0.8 {
            let _ = cfg.inject(Scheduled {
                injection: Injection::Reset,
                at_ms: (t + rng.u32(100..8_000)).min(latest),
            });
        }
    }
    latest
}

impl Scenario {
    /// The scenario of `seed`.
    pub fn from_seed(seed: u64, opts: &Options) -> Scenario {
        let mut rng = fastrand::Rng::with_seed(seed ^ 0x5_3a4a_0000);
        let horizon = opts.horizon_ms.max(10_000);
        let protocol = if rng.bool() {
            Protocol::Legacy
        } else {
            Protocol::Pus
        };
        let plan_text = random_plan(&mut rng);
        // Every drawn plan parses and fits its states (tested over many seeds); the demo
        // stands in should one not.
        let (steps, start) = match plan::parse(&plan_text) {
            Ok(p) => (
                crate::sim::steps_of(&p),
                p.start.unwrap_or(SimConfig::DEFAULT_START),
            ),
            Err(_) => (crate::sim::demo_steps(), SimConfig::DEFAULT_START),
        };
        let mut cfg = SimConfig::with_steps(steps);
        cfg.start_state = start;
        cfg.protocol = protocol;
        cfg.seed = seed;
        cfg.progress = false;
        cfg.log_packets = false;
        cfg.log_events = true;
        cfg.max_sim_ms = horizon;
        cfg.run_to_end = true;
        cfg.planted_bug = opts.planted_bug;
        cfg.b_phase_us = rng.u64(0..10_000);
        cfg.wifi_loss = sometimes(&mut rng, 0.5, 0.3);
        cfg.serial_loss = sometimes(&mut rng, 0.3, 0.1);
        cfg.ab_loss = sometimes(&mut rng, 0.3, 0.05);
        cfg.links = Links {
            wifi: LinkModel {
                latency_us: rng.u64(500..20_000),
                jitter_us: rng.u64(0..10_000),
                duplicate: sometimes(&mut rng, 0.6, 0.2),
                reorder: sometimes(&mut rng, 0.3, 0.1),
                reorder_us: rng.u64(10_000..100_000),
                cuts: cuts(&mut rng, 0.2, horizon),
            },
            ground: LinkModel {
                latency_us: rng.u64(500..5_000),
                jitter_us: rng.u64(0..2_000),
                // Resent commands: the ground's line delivers a packet twice.
                duplicate: sometimes(&mut rng, 0.3, 0.2),
                reorder: if protocol == Protocol::Pus {
                    sometimes(&mut rng, 0.2, 0.1)
                } else {
                    0.0
                },
                reorder_us: rng.u64(10_000..200_000),
                cuts: cuts(&mut rng, 0.1, horizon),
            },
            ab: LinkModel {
                latency_us: rng.u64(200..2_000),
                jitter_us: rng.u64(0..500),
                duplicate: 0.0,
                reorder: 0.0,
                reorder_us: 0,
                cuts: cuts(&mut rng, 0.1, horizon),
            },
        };
        let latest = draw_faults(&mut rng, &mut cfg, horizon);
        let link = draw_link(seed, protocol, opts, &mut cfg);
        draw_restarts(seed, opts, &mut cfg, latest);
        Scenario {
            seed,
            protocol,
            link,
            sdls: cfg.sdls.as_ref().map(|s| s.attack),
            plan: plan_text,
            cfg,
        }
    }

    /// One line: protocol (and with PUS its link layer), plan, links, faults; SDLS and the
    /// attacker's rate last, when drawn.
    pub fn describe(&self) -> String {
        let c = &self.cfg;
        let steps: Vec<&str> = c
            .steps
            .iter()
            .map(|s| s.text.split('#').next().unwrap_or_default().trim())
            .collect();
        let inj: Vec<String> = c
            .injections
            .iter()
            .map(|s| format!("{}@{:.3}", s.injection.name(), s.at_ms as f64 / 1000.0))
            .collect();
        let w = &c.links.wifi;
        format!(
            "seed {}: {}{} from {}: [{}]; wifi loss {:.2} dup {:.2} reorder {:.2} latency {:.1} ms \
             jitter {:.1} ms cuts {:?}; ground loss {:.2} dup {:.2} reorder {:.2} cuts {:?}; \
             a-b loss {:.3} cuts {:?}; b phase {:.1} ms; injections [{}]",
            self.seed,
            self.protocol.name(),
            match self.protocol {
                Protocol::Pus => format!(" over {}", self.link.name()),
                Protocol::Legacy => String::new(),
            },
            c.start_state.letter(),
            steps.join("; "),
            c.wifi_loss,
            w.duplicate,
            w.reorder,
            w.latency_us as f64 / 1000.0,
            w.jitter_us as f64 / 1000.0,
            w.cuts,
            c.serial_loss,
            c.links.ground.duplicate,
            c.links.ground.reorder,
            c.links.ground.cuts,
            c.ab_loss,
            c.links.ab.cuts,
            c.b_phase_us as f64 / 1000.0,
            inj.join(", ")
        ) + &match self.sdls {
            Some(a) => format!("; SDLS, attacker rate {a:.2}"),
            None => String::new(),
        }
    }
}
