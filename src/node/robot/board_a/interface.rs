//! What a tick of board A takes and gives: its settings ([`Config`]), one tick's sensed
//! [`Inputs`] and received packets, and its [`Outputs`]: drives, packets to send and the
//! [`Event`]s that happened.

use crate::bolter::{self as coordinator, Drive, MuxLines};
use crate::command::{BolterPair, Command};
use crate::control::deadline;
use crate::control::hip;
use crate::control::interp::{Rate, Travel};
use crate::faults::{Fault, Faults};
use crate::mode::Mode;
use crate::motion::estimate;
use crate::motion::sequencer;
use crate::motion::State;
use crate::refusal::Refusal;
use crate::safety::detect;
use crate::sensors::frontend::Lost;
use crate::units::{BoardNumber, Electrical, Gravity, HipAngle, PulseWidth};
use crate::wire::b_command::B_COMMAND_LEN;
use crate::wire::command::COMMAND_LEN;
use crate::wire::heartbeat::HEARTBEAT_LEN;
use crate::wire::internal_heartbeat::INTERNAL_HEARTBEAT_LEN;
use crate::wire::WireError;

/// Board A's settings.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Config {
    /// This robot's number.
    pub board: BoardNumber,
    /// Fault thresholds and timeouts (Table 8).
    pub safety: detect::Config,
    /// Primitive step timing.
    pub motion: sequencer::Config,
    /// Bolting.
    pub bolter: coordinator::Config,
    /// Servo interpolation rate (both sides).
    pub rate: Rate,
    /// What contract/extend mean for the arms.
    pub arm: Travel,
    /// What contract/extend mean for the grippers (extend = closed on a face).
    pub gripper: Travel,
    /// Hip PI controller.
    pub hip: hip::Config,
    /// A hip move is done within this distance of its target, 0.01°.
    pub hip_done_tolerance: u16,
    /// The time budget of a module motion outside a primitive or a bolting job (arm, gripper
    /// and hip commands, the move home): its size over the actuator's speed plus these margins
    /// (spec/control/servos.toml).
    pub deadline: deadline::Config,
    /// State estimation.
    pub estimate: estimate::Config,
    /// A→B command period, ms (sent sooner when its content changes).
    pub b_period_ms: u32,
    /// The idle overcurrent checks at the start and the end of a reconfiguration (Section 7)
    /// read the currents once the robot has been still this long, ms. Default 600: the sensor
    /// front end's 50-sample window at a 10 ms tick (500 ms) plus two of board B's heartbeat
    /// periods, so no current of the last motion is left in the averages. A reconfiguration
    /// accepted sooner waits for it before its first primitive; command complete (heartbeat
    /// byte 54) comes after the check at its end.
    pub idle_settle_ms: u32,
}

impl Default for Config {
    fn default() -> Config {
        Config {
            board: BoardNumber::ONE,
            safety: detect::Config::default(),
            motion: sequencer::Config::default(),
            bolter: coordinator::Config::default(),
            rate: Rate::default(),
            arm: Travel::ARM,
            gripper: Travel::GRIPPER,
            hip: hip::Config::default(),
            hip_done_tolerance: 150,
            deadline: deadline::Config::default(),
            estimate: estimate::Config::default(),
            b_period_ms: 50,
            idle_settle_ms: 600,
        }
    }
}

/// One tick's inputs.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Inputs {
    /// A command packet from the WiFi hand-off queue.
    pub command: Option<[u8; COMMAND_LEN]>,
    /// An internal heartbeat from board B.
    pub from_b: Option<[u8; INTERNAL_HEARTBEAT_LEN]>,
    /// Side A's filtered voltages and currents.
    pub electrical: Electrical,
    /// Hip encoder angle; `None` when the encoder gave no reading this tick: the hip is then
    /// not steered (stop pulse), not judged at its target, and not at home
    /// (spec/decisions.toml, `sensor-loss`).
    pub hip: Option<HipAngle>,
    /// Gravity in A's IMU frame.
    pub gravity: Option<Gravity>,
    /// Arm A's contraction switch.
    pub arm_contracted: bool,
    /// Bolter A's home switch: the bolter is in its initial configuration. (The end of a
    /// current-sensed bolter step is decided from `electrical.i_bo`.)
    pub bolter_at_home: bool,
    /// Side A's devices silent for a whole window (the sensor front end's verdict): raises
    /// [`Fault::SensorLoss`]; with the ADC lost, the checks on `electrical` are not made.
    pub lost: Lost,
}

impl Inputs {
    /// Nothing received; a full battery, no current; hip at the default home angle (180°),
    /// arm A contracted, bolter A at home.
    pub const fn at_home() -> Inputs {
        Inputs {
            command: None,
            from_b: None,
            electrical: Electrical {
                v_bat: 12_000,
                i_bat: 0,
                i_loc: 0,
                i_grip: 0,
                i_3v3: 0,
                v_reg: 7_400,
                i_bo: 0,
            },
            hip: Some(HipAngle::STRAIGHT),
            gravity: None,
            arm_contracted: true,
            bolter_at_home: true,
            lost: Lost::NONE,
        }
    }
}

/// Something that happened in a tick, for logs and tests.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum Event {
    /// A command was taken and run (or refused) — once per sequence number.
    Executed {
        /// Its sequence number (0 = unsequenced).
        seq: u16,
        /// The command; none when the packet held no command (an unknown opcode or invalid
        /// parameters, which are refused).
        command: Option<Command>,
        /// Refused, and why; none = accepted.
        refusal: Option<Refusal>,
    },
    /// A copy of the last command taken: answered, not run.
    Duplicate {
        /// Its sequence number.
        seq: u16,
    },
    /// A late copy of an older command: answered, not run.
    Stale {
        /// Its sequence number.
        seq: u16,
    },
    /// A packet failed its length, header or checksum check: dropped unanswered (the ground
    /// resends it).
    Rejected(WireError),
    /// A command for another robot: dropped unanswered.
    OtherRobot {
        /// The robot it was for.
        board: BoardNumber,
    },
    /// Faults latched this tick.
    Faults(Faults),
    /// The mode changed.
    Mode {
        /// Before.
        from: Mode,
        /// After.
        to: Mode,
    },
    /// A reconfiguration or primitive reached its target state.
    Reached(State),
    /// A bolting job ended: done (`None`) or failed with this fault.
    Bolting(Option<Fault>),
    /// A "move bolters down" ended: both bolters touched (`contact`), or a descent timed out
    /// first. Nothing engaged or rotated.
    BoltersDown {
        /// Both sides' currents passed the push threshold.
        contact: bool,
    },
    /// A Stop interrupted a motion; it waits for Reset.
    Paused,
    /// Reset resumed the motion a Stop interrupted, from the step where it stopped.
    Resumed,
    /// A pair of a bolting job finished: fastened (or released) at attempt `attempts`, or not.
    Pair {
        /// The pair.
        pair: BolterPair,
        /// Attempts made, 1..=3.
        attempts: u8,
        /// Whether the pair succeeded.
        ok: bool,
    },
}

/// Events per tick (more are counted in [`Outputs::events_lost`]).
pub const EVENTS: usize = 6;

/// One tick's outputs.
#[derive(Debug, Clone, PartialEq, Eq, Hash)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Outputs {
    /// Hip servo pulse; none = unpowered.
    pub hip: Option<PulseWidth>,
    /// Arm A pulse; none = unpowered.
    pub arm: Option<PulseWidth>,
    /// Gripper A pulse; none = unpowered.
    pub gripper: Option<PulseWidth>,
    /// 7.4 V regulator.
    pub regulator: bool,
    /// Bolter A motor.
    pub bolter: Drive,
    /// Bolter A multiplexer lines.
    pub mux: MuxLines,
    /// A→B command to send now.
    pub to_b: Option<[u8; B_COMMAND_LEN]>,
    /// Heartbeat answering this tick's command.
    pub heartbeat: Option<[u8; HEARTBEAT_LEN]>,
    /// What happened.
    pub events: heapless::Vec<Event, EVENTS>,
    /// Events that did not fit (never expected; counted so none is lost silently).
    pub events_lost: u8,
}

impl Outputs {
    /// Nothing driven, nothing to send, no event.
    pub(super) fn empty() -> Outputs {
        Outputs {
            hip: None,
            arm: None,
            gripper: None,
            regulator: false,
            bolter: Drive::Idle,
            mux: MuxLines::default(),
            to_b: None,
            heartbeat: None,
            events: heapless::Vec::new(),
            events_lost: 0,
        }
    }

    /// Records an event; one that does not fit is counted in `events_lost`.
    pub(super) fn push(&mut self, e: Event) {
        if self.events.push(e).is_err() {
            self.events_lost = self.events_lost.saturating_add(1);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Events past [`EVENTS`] in one tick are counted, the first ones kept.
    #[test]
    fn events_past_the_capacity_are_counted() {
        let mut out = Outputs::empty();
        for _ in 0..EVENTS {
            out.push(Event::Paused);
        }
        assert_eq!((out.events.len(), out.events_lost), (EVENTS, 0));
        out.push(Event::Resumed);
        out.push(Event::Resumed);
        assert_eq!(out.events_lost, 2);
        assert!(out.events.iter().all(|e| *e == Event::Paused));
    }
}
