//! Board B: executes board A's commands on side B, acknowledges them, and reports.
//!
//! Each tick takes at most one A→B command packet (from the serial deframer) and side B's
//! filtered sensors; it returns side B's module outputs and, every `heartbeat_period_ms`, the
//! 47-byte internal heartbeat of Table 4, whose byte 35 echoes the last command's sequence
//! number (the acknowledgement). If A falls silent for `link_timeout_ms`, B holds its servos
//! where they are and idles its bolter until A speaks again: B never moves on stale orders.
//! The hold is this project's addition (the paper has B only execute A's commands); the
//! period and the timeout are spec/boards.toml's (spec/decisions.toml,
//! `board-b-heartbeat-and-hold`).
//!
//! ```
//! use mmic::node::robot::board_b::{BoardB, Config, Inputs};
//! use mmic::wire::b_command::{BCommandRepr, BPower};
//! use mmic::wire::internal_heartbeat::InternalHeartbeatRepr;
//! use mmic::units::PulseWidth;
//!
//! let mut b = BoardB::new(Config::default());
//! let cmd = BCommandRepr {
//!     seq: 7, power: BPower { regulator: true, arm: true, gripper: true, bolter: false },
//!     stop: false, arm_target: PulseWidth::new(2000).unwrap(),
//!     gripper_target: PulseWidth::CENTER, bolter: None,
//! };
//! let out = b.tick(0, &Inputs { command: Some(cmd.to_bytes()), ..Inputs::default() });
//! let hb = InternalHeartbeatRepr::parse(&out.heartbeat.unwrap()).unwrap();
//! assert_eq!(hb.command_received, 7);              // acknowledged
//! assert_eq!(hb.arm_b_target.micros(), 2000);
//! let out = b.tick(400, &Inputs::default());       // from home (900 µs) at 500 µs/s
//! assert_eq!(out.arm.unwrap().micros(), 1100);
//! let out = b.tick(901, &Inputs::default());       // A silent for over 500 ms: hold
//! assert!(out.link_lost);
//! assert_eq!(out.arm.unwrap().micros(), 1100);
//! ```
// req: P4.3, P4.5, P4.6, D:board-b-heartbeat-and-hold, D:b-starts-at-home

use crate::bolter::{BolterSide, Drive, MuxLines, Sensed, SideConfig};
use crate::control::interp::{Interpolator, Rate, Travel};
use crate::safety::detect;
use crate::sensors::frontend::Lost;
use crate::units::Instant;
use crate::units::{Electrical, Gravity, PulseWidth};
use crate::wire::b_command::{BCommandRepr, B_COMMAND_LEN};
use crate::wire::internal_heartbeat::{InternalHeartbeatRepr, INTERNAL_HEARTBEAT_LEN};
use crate::wire::WireError;

/// Board B's settings.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Config {
    /// Internal heartbeat period, ms. Default 50.
    pub heartbeat_period_ms: u32,
    /// Silence from A after which B holds everything, ms. Default 500 (A's own timeout).
    pub link_timeout_ms: u32,
    /// Servo interpolation rate.
    pub rate: Rate,
    /// Bolter B's step timeouts and current thresholds (the same defaults as side A's,
    /// board A's `bolter.side`: the two bolters are identical).
    pub bolter: SideConfig,
    /// Current limits for the over-idle and overcurrent flags (Table 4 bytes 38–43).
    pub limits: detect::Config,
    /// Arm B's travel: it starts contracted, as board A's arm does.
    pub arm: Travel,
    /// Gripper B's travel: it starts closed on the face, as board A's gripper does.
    pub gripper: Travel,
}

impl Default for Config {
    fn default() -> Config {
        Config {
            heartbeat_period_ms: 50,
            link_timeout_ms: 500,
            rate: Rate::default(),
            bolter: SideConfig::default(),
            limits: detect::Config::default(),
            arm: Travel::ARM,
            gripper: Travel::GRIPPER,
        }
    }
}

/// One tick's inputs.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Default)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Inputs {
    /// An A→B command packet received since the last tick.
    pub command: Option<[u8; B_COMMAND_LEN]>,
    /// Side B's filtered voltages and currents.
    pub electrical: Electrical,
    /// Gravity in B's IMU frame.
    pub gravity: Option<Gravity>,
    /// Arm B's contraction switch.
    pub arm_contracted: bool,
    /// Bolter B's home switch: the bolter is in its initial configuration. (The end of a
    /// current-sensed bolter step is decided from `electrical.i_bo`.)
    pub bolter_at_home: bool,
    /// Side B's devices silent for a whole window (the sensor front end's verdict). With its
    /// ADC lost, board B holds its actuators and stops its heartbeat: Table 4 has no byte to
    /// say so, and board A, hearing nothing, raises internal comm loss (Safed) — a side that
    /// cannot sense its currents is treated as a side that is not there
    /// (spec/decisions.toml, `sensor-loss`).
    pub lost: Lost,
}

/// One tick's outputs.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Outputs {
    /// Arm B pulse; none = unpowered.
    pub arm: Option<PulseWidth>,
    /// Gripper B pulse; none = unpowered.
    pub gripper: Option<PulseWidth>,
    /// 7.4 V regulator.
    pub regulator: bool,
    /// Bolter B motor (idle when unpowered).
    pub bolter: Drive,
    /// Bolter B multiplexer lines.
    pub mux: MuxLines,
    /// Internal heartbeat to send now.
    pub heartbeat: Option<[u8; INTERNAL_HEARTBEAT_LEN]>,
    /// A has been silent past the timeout: holding.
    pub link_lost: bool,
    /// The packet received this tick was refused (it is ignored).
    pub rejected: Option<WireError>,
}

/// Board B's state.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct BoardB {
    cfg: Config,
    arm: Interpolator,
    gripper: Interpolator,
    bolter: BolterSide,
    last: Option<BCommandRepr>,
    heard: Option<Instant>,
    sent: Option<Instant>,
    holding: bool,
    /// After a restart: heartbeats still to send reporting "nothing received" (0) before any
    /// command is taken ([`BoardB::restarted`]).
    announce: u8,
}

/// Heartbeats a restarted board B sends reporting 0 before it takes a command: board A must
/// hear one to know B restarted, and the A–B line may lose one or two.
pub const RESTART_ANNOUNCEMENTS: u8 = 3;

impl BoardB {
    /// Startup: servos at home — arm contracted, gripper closed — as on board A (Section 7:
    /// "actuators are set to go to their home position"), so that powering up never drives
    /// side B's servos to mid-travel; nothing received.
    pub const fn new(cfg: Config) -> BoardB {
        BoardB {
            cfg,
            arm: Interpolator::new(cfg.arm.contracted, cfg.rate),
            gripper: Interpolator::new(cfg.gripper.extended, cfg.rate),
            bolter: BolterSide::new(),
            last: None,
            heard: None,
            sent: None,
            holding: false,
            announce: 0,
        }
    }

    /// Board B after a restart (a power cycle, a watchdog, a brown-out): as at power-on, but
    /// it first says so. It cannot know where its servos stopped (they have no feedback), and
    /// what it would report from its start-up pose could tell board A that a gripper holds when
    /// it hangs open; so it takes no command until it has sent [`RESTART_ANNOUNCEMENTS`]
    /// heartbeats whose "command received" is 0, which board A, having heard a number before,
    /// takes as B's restart: internal communication loss, Safed (decision `restart-board-b`).
    /// B keeps nothing across a restart.
    ///
    /// ```
    /// use mmic::node::robot::board_b::{BoardB, Config, Inputs, RESTART_ANNOUNCEMENTS};
    /// use mmic::units::PulseWidth;
    /// use mmic::wire::b_command::{BCommandRepr, BPower};
    /// use mmic::wire::internal_heartbeat::InternalHeartbeatRepr;
    /// let mut b = BoardB::restarted(Config::default());
    /// let cmd = BCommandRepr {
    ///     seq: 7, power: BPower::default(), stop: false, arm_target: PulseWidth::CENTER,
    ///     gripper_target: PulseWidth::CENTER, bolter: None,
    /// };
    /// let mut zeros = 0;
    /// for t in (0..2000).step_by(10) {
    ///     // A's refreshes keep coming; none is taken until the announcements are out.
    ///     let out = b.tick(t, &Inputs { command: Some(cmd.to_bytes()), ..Inputs::default() });
    ///     if let Some(hb) = out.heartbeat {
    ///         if InternalHeartbeatRepr::parse(&hb).unwrap().command_received == 0 { zeros += 1 }
    ///     }
    /// }
    /// assert_eq!(zeros, RESTART_ANNOUNCEMENTS);
    /// ```
    pub const fn restarted(cfg: Config) -> BoardB {
        let mut b = BoardB::new(cfg);
        b.announce = RESTART_ANNOUNCEMENTS;
        b
    }

    /// Starts with the servos at these pulses (the host simulator's initial pose).
    pub const fn with_pose(cfg: Config, arm: PulseWidth, gripper: PulseWidth) -> BoardB {
        let mut b = BoardB::new(cfg);
        b.arm = Interpolator::new(arm, cfg.rate);
        b.gripper = Interpolator::new(gripper, cfg.rate);
        b
    }

    fn hold(&mut self, now: u32) {
        self.arm.set_target(self.arm.now(), now);
        self.gripper.set_target(self.gripper.now(), now);
        self.bolter.order(0, None, now);
    }

    /// One tick at `now` (ms).
    pub fn tick(&mut self, now: u32, inp: &Inputs) -> Outputs {
        let rejected = match self.announce {
            0 => inp.command.and_then(|bytes| self.take(now, &bytes)),
            _ => None, // restarted: announcing, nothing taken yet
        };
        let silent = match self.heard {
            Some(t) => Instant::from_millis(now).since(t).millis() > self.cfg.link_timeout_ms,
            None => false,
        };
        let blind = inp.lost.adc;
        if (silent || blind) && !self.holding {
            self.holding = true;
            self.hold(now);
        }
        let bolter = Sensed {
            i_bo: inp.electrical.i_bo,
            at_home: inp.bolter_at_home,
        };
        self.bolter.tick(&self.cfg.bolter, now, bolter);
        let arm_now = self.arm.tick(now);
        let gripper_now = self.gripper.tick(now);
        let power = self.last.map(|c| c.power).unwrap_or_default();
        let live = power.regulator && !self.holding;
        Outputs {
            arm: (power.regulator && power.arm).then_some(arm_now),
            gripper: (power.regulator && power.gripper).then_some(gripper_now),
            regulator: power.regulator,
            bolter: if live && power.bolter {
                self.bolter.drive()
            } else {
                Drive::Idle
            },
            mux: self.bolter.mux(),
            heartbeat: self.heartbeat_due(now, inp, blind),
            link_lost: silent,
            rejected,
        }
    }

    /// Board A's command packet: adopted (a stop flag holds everything where it is), or the
    /// reason it was rejected.
    fn take(&mut self, now: u32, bytes: &[u8; B_COMMAND_LEN]) -> Option<WireError> {
        let c = match BCommandRepr::parse(bytes) {
            Ok(c) => c,
            Err(e) => return Some(e),
        };
        self.heard = Some(Instant::from_millis(now));
        self.holding = false;
        if c.stop {
            self.hold(now);
        } else {
            if self.arm.target() != c.arm_target {
                self.arm.set_target(c.arm_target, now);
            }
            if self.gripper.target() != c.gripper_target {
                self.gripper.set_target(c.gripper_target, now);
            }
            self.bolter.order(c.seq, c.bolter, now);
        }
        self.last = Some(c);
        None
    }

    /// The internal heartbeat, once a period; none while blind: B says nothing rather than
    /// report stale currents as its own verdicts.
    fn heartbeat_due(
        &mut self,
        now: u32,
        inp: &Inputs,
        blind: bool,
    ) -> Option<[u8; INTERNAL_HEARTBEAT_LEN]> {
        let period = self.cfg.heartbeat_period_ms;
        match self.sent {
            Some(t) if Instant::from_millis(now).since(t).millis() < period => None,
            _ if blind => None,
            _ => {
                self.sent = Some(Instant::from_millis(now));
                self.announce = self.announce.saturating_sub(1);
                Some(self.report(inp).to_bytes())
            }
        }
    }

    /// The internal heartbeat for the current state.
    pub fn report(&self, inp: &Inputs) -> InternalHeartbeatRepr {
        let e = &inp.electrical;
        // B's own verdicts, against B's limits: board A takes them as they are.
        let idle = detect::Over::judge(e, &self.cfg.limits.idle);
        let abs = detect::Over::judge(e, &self.cfg.limits.absolute);
        InternalHeartbeatRepr {
            arm_b_target: self.arm.target(),
            arm_b_now: self.arm.now(),
            gripper_b_target: self.gripper.target(),
            gripper_b_now: self.gripper.now(),
            electrical_b: *e,
            bolter_aux: self.bolter.aux(),
            command_received: self.last.map_or(0, |c| c.seq),
            gravity: inp.gravity,
            arm_over_idle: idle.locomotion,
            gripper_over_idle: idle.gripper,
            bolter_over_idle: idle.bolter,
            arm_overcurrent: abs.locomotion,
            gripper_overcurrent: abs.gripper,
            bolter_overcurrent: abs.bolter,
            arm_contracted: inp.arm_contracted,
        }
    }
}
