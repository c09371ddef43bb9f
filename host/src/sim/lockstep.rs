//! One robot in lock-step, without threads or transports: board A, board B and the plant
//! stepped together every 10 ms of virtual time, packets between A and B delivered at the next
//! tick (each direction can be cut), commands handed straight to board A. Deterministic: the
//! same calls give the same run. Tests use it to check board A's behaviour against the paper
//! on the whole robot (servos, hip, currents, the bolter) where the threaded simulator
//! ([`super::run`]) would add timing noise.
//!
//! ```
//! use mmic::command::Command;
//! use mmic::mode::Mode;
//! use mmic::motion::State;
//! use mmic_host::sim::lockstep::Robot;
//! use mmic_host::sim::PlantConfig;
//! let mut r = Robot::new(State::A, PlantConfig::default());
//! let hb = r.command(Command::Mode(Mode::Operational)).expect("answered");
//! assert_eq!((hb.mode, hb.refusal), (Mode::Operational, None));
//! assert!(r.run_until(5_000, |r| !r.a.in_motion()));
//! ```

use super::plant::{Plant, PlantConfig};
use super::shell::{tick_a, tick_b};
use mmic::command::Command;
use mmic::motion::State;
use mmic::node::robot::board_a::{self, BoardA, Event};
use mmic::node::robot::board_b::{self, BoardB};
use mmic::sensors::frontend::{self, Frontend, WINDOW};
use mmic::units::BoardNumber;
use mmic::wire::b_command::B_COMMAND_LEN;
use mmic::wire::command::CommandRepr;
use mmic::wire::heartbeat::HeartbeatRepr;
use mmic::wire::internal_heartbeat::INTERNAL_HEARTBEAT_LEN;

/// The control tick, ms.
pub const TICK_MS: u32 = 10;

/// A robot: both boards, their sensor front ends and the plant.
pub struct Robot {
    /// Board A.
    pub a: BoardA,
    /// Board B.
    pub b: BoardB,
    /// The body.
    pub plant: Plant,
    /// Virtual time of the last tick, ms.
    pub now: u32,
    /// Whether A→B packets are delivered.
    pub a_to_b: bool,
    /// Whether B→A packets are delivered.
    pub b_to_a: bool,
    /// Board A's events with their time, oldest first.
    pub events: Vec<(u32, Event)>,
    /// Board A's last outputs.
    pub out_a: Option<board_a::Outputs>,
    /// Board B's last outputs.
    pub out_b: Option<board_b::Outputs>,
    sensors: (Frontend<WINDOW>, Frontend<WINDOW>),
    to_b: Option<[u8; B_COMMAND_LEN]>,
    to_a: Option<[u8; INTERNAL_HEARTBEAT_LEN]>,
    seq: u16,
}

impl Robot {
    /// At rest in `state` (arms contracted, grippers closed, hip straight), in Standby, with
    /// board A knowing the state; the sensor averages are filled with a second of readings at
    /// rest first, as after power-up.
    pub fn new(state: State, plant: PlantConfig) -> Robot {
        let mut r = Robot {
            a: BoardA::in_state(board_a::Config::default(), state),
            b: BoardB::new(board_b::Config::default()),
            plant: Plant::new(plant, state),
            now: 0,
            a_to_b: true,
            b_to_a: true,
            events: Vec::new(),
            out_a: None,
            out_b: None,
            sensors: (
                Frontend::new(frontend::Config::default()),
                Frontend::new(frontend::Config {
                    hip_encoder: false,
                    ..frontend::Config::default()
                }),
            ),
            to_b: None,
            to_a: None,
            seq: 0,
        };
        r.run_for(1_000);
        r
    }

    /// One tick `TICK_MS` after the last, with `command` (as a packet numbered by the caller)
    /// reaching board A; returns the heartbeat board A answered with.
    pub fn tick_with(&mut self, command: Option<CommandRepr>) -> Option<HeartbeatRepr> {
        self.now += TICK_MS;
        let now = self.now;
        let from_b = self.to_a.take().filter(|_| self.b_to_a);
        let to_b = self.to_b.take().filter(|_| self.a_to_b);
        let out_a = tick_a(
            &mut self.a,
            &mut self.sensors.0,
            &mut self.plant,
            now,
            command.map(|c| c.to_bytes()),
            from_b,
        );
        let out_b = tick_b(&mut self.b, &mut self.sensors.1, &mut self.plant, now, to_b);
        for e in &out_a.events {
            self.events.push((now, *e));
        }
        self.to_b = out_a.to_b;
        self.to_a = out_b.heartbeat;
        let hb = out_a.heartbeat.and_then(|b| HeartbeatRepr::parse(&b).ok());
        self.out_a = Some(out_a);
        self.out_b = Some(out_b);
        hb
    }

    /// One tick with no command.
    pub fn tick(&mut self) {
        self.tick_with(None);
    }

    /// Sends `c` with the next sequence number in the next tick; returns the heartbeat that
    /// answers it.
    pub fn command(&mut self, c: Command) -> Option<HeartbeatRepr> {
        self.seq = self.seq.wrapping_add(1).max(1);
        self.tick_with(Some(CommandRepr {
            board: BoardNumber::ONE,
            command: c,
            seq: self.seq,
        }))
    }

    /// Ticks for `ms` of virtual time.
    pub fn run_for(&mut self, ms: u32) {
        let end = self.now + ms;
        while self.now < end {
            self.tick();
        }
    }

    /// Ticks until `done` holds (true) or `max_ms` of virtual time passed (false).
    pub fn run_until(&mut self, max_ms: u32, mut done: impl FnMut(&Robot) -> bool) -> bool {
        let end = self.now + max_ms;
        while self.now < end {
            self.tick();
            if done(self) {
                return true;
            }
        }
        false
    }

    /// The events since virtual time `t` (inclusive).
    pub fn events_since(&self, t: u32) -> impl Iterator<Item = &Event> + '_ {
        self.events
            .iter()
            .filter(move |(at, _)| *at >= t)
            .map(|(_, e)| e)
    }

    /// The hip angle the plant is at, 0.01°.
    pub fn hip(&self) -> f64 {
        self.plant.hip_centidegrees()
    }
}
