//! Board A: the robot's primary board as one pure tick.
//!
//! Each tick takes what the shell gathered since the last one — at most one command packet
//! from the WiFi hand-off queue, at most one internal heartbeat from board B's serial line,
//! and side A's filtered sensors — and returns side A's module outputs, the A→B command to
//! send (if one is due), the 66-byte heartbeat answering the command (if one came), and what
//! happened, as [`Event`]s for logs. Inside, the pieces of the earlier modules are joined in
//! the order the paper gives: fault detection, then the mode supervisor (Tables 7 and 8),
//! then the command (exactly-once log, supervisor, dispatch), then motion (reconfiguration
//! runner, single-module moves), bolting (coordinator and side A's executor), and finally the
//! servo and hip outputs.
//!
//! ```
//! use mmic::command::Command;
//! use mmic::mode::Mode;
//! use mmic::node::board_a::{BoardA, Config, Inputs};
//! use mmic::units::BoardNumber;
//! use mmic::wire::command::CommandRepr;
//! use mmic::wire::heartbeat::HeartbeatRepr;
//!
//! let mut a = BoardA::new(Config::default());
//! let cmd = CommandRepr { board: BoardNumber::ONE, command: Command::Mode(Mode::Operational), seq: 1 };
//! let out = a.tick(0, &Inputs { command: Some(cmd.to_bytes()), ..Inputs::at_home() });
//! let hb = HeartbeatRepr::parse(&out.heartbeat.unwrap()).unwrap();
//! assert_eq!((hb.mode, hb.last_seq, hb.refusal), (Mode::Operational, 1, None));
//! // The same packet again (its heartbeat was lost): answered, not run again.
//! let out = a.tick(10, &Inputs { command: Some(cmd.to_bytes()), ..Inputs::at_home() });
//! assert_eq!(HeartbeatRepr::parse(&out.heartbeat.unwrap()).unwrap().last_seq, 1);
//! assert!(out.events.iter().any(|e| matches!(e, mmic::node::board_a::Event::Duplicate { seq: 1 })));
//! ```

use super::b_link::BLink;
use super::exactly_once::{Admission, CommandLog};
use crate::bolter::{
    self as coordinator, BolterDirection, BolterSide, Coordinator, Drive, Job, MuxLines, Sensed,
};
use crate::command::{preset_angle, BolterCommand, Command, HipTarget, PrimitiveMove, ServoTarget};
use crate::control::deadline;
use crate::control::hip::{self, HipController};
use crate::control::interp::{Interpolator, Rate, Travel};
use crate::faults::{Fault, Faults};
use crate::mode::Mode;
use crate::motion::estimate::{self, initial_state_consistent, Readings, StateSet};
use crate::motion::runner::{RunStatus, Runner};
use crate::motion::sequencer::{self, Feedback, Targets};
use crate::motion::State;
use crate::refusal::Refusal;
use crate::safety::detect::{self, CommMonitor, LowBattery};
use crate::safety::supervisor::{Answer, Incoming, Input, Supervisor};
use crate::safety::ModuleSet;
use crate::sensors::frontend::Lost;
use crate::units::{
    BoardNumber, Duration, Electrical, Gravity, HipAngle, Instant, Module, PerSide, PulseWidth,
    Side,
};
use crate::wire::b_command::{BCommandRepr, BPower, B_COMMAND_LEN};
use crate::wire::command::{CommandPacket, CommandRepr, COMMAND_LEN};
use crate::wire::heartbeat::{BolterAttempt, HeartbeatRepr, HEARTBEAT_LEN};
use crate::wire::internal_heartbeat::{InternalHeartbeatRepr, INTERNAL_HEARTBEAT_LEN};
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
        pair: crate::command::BolterPair,
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
    fn empty() -> Outputs {
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

    fn push(&mut self, e: Event) {
        if self.events.push(e).is_err() {
            self.events_lost = self.events_lost.saturating_add(1);
        }
    }
}

/// Board A's state.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct BoardA {
    cfg: Config,
    sup: Supervisor,
    log: CommandLog,
    comm: CommMonitor,
    battery: LowBattery,
    runner: Option<Runner>,
    tracked: Option<State>,
    target_state: Option<State>,
    complete: bool,
    /// A single-module motion (arm, gripper, hip, bolter) runs: when it ends (not stopped
    /// by a Stop or a mode change), the heartbeat's "command complete" (byte 54) is set, as a
    /// reconfiguration's is (spec/decisions.toml, `command-complete`).
    single: bool,
    coord: Coordinator,
    side_a: BolterSide,
    waiting_job: Option<Queued>,
    targets: Targets,
    arm: Interpolator,
    gripper: Interpolator,
    hip_ctl: HipController,
    b: InternalHeartbeatRepr,
    b_heard: bool,
    link: BLink,
    contracting: PerSide<Contraction>,
    refusal: Option<Refusal>,
    moving: bool,
    pair: Option<(crate::command::BolterPair, u8)>,
    still_since: Option<Instant>,
    idle_check: Option<IdleCheck>,
    /// The motion a Stop interrupted, kept for Reset.
    paused: Option<Paused>,
    /// Board B holds where it is (the A→B stop flag): set by a Stop or a mode change, cleared
    /// by the next command that moves side B's modules, Reset, or going home.
    hold_b: bool,
    /// The last hip angle read: the heartbeat's "hip now" and the hold target of a Stop while
    /// the encoder is silent (the sensor-loss fault tells the ground it is stale).
    hip_seen: HipAngle,
    /// The deadline of the module motion in progress outside a primitive or a bolting job.
    watch: Watch,
}

/// The deadline of a module motion that has no step timeout of its own (arm, gripper and hip
/// commands, the move home, a module pushed off its target): armed when modules start to move
/// towards their targets with the budget of [`deadline::budget_ms`], disarmed when they are
/// there ([`BoardA::watch_modules`]).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
enum Watch {
    /// Nothing moves on its own account.
    Idle,
    /// Modules move; the motion times out at this instant.
    Armed(Instant),
    /// The motion timed out and was stopped; not armed again until the modules are at their
    /// targets or a new motion is commanded (a module that stays off its target, a silent
    /// encoder, would otherwise time out again and again).
    Expired,
}

/// A bolting job that waits for board B's bolter to report idle.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
enum Queued {
    /// Bolt or unbolt.
    Job(Job),
    /// Table 1's "move bolters down".
    Down,
}

/// Table 8's arm contraction check after a single-module "contract arm" command, per side.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
enum Contraction {
    /// No contraction command to check.
    Idle,
    /// The arm is on its way.
    Moving,
    /// The arm finished its travel at this time: the switch has the sequencer's confirm time
    /// (`motion.confirm_ms`) to close, as in a primitive's Confirm step.
    Confirming(Instant),
}

/// Section 7's idle overcurrent check around a reconfiguration.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
enum IdleCheck {
    /// Accepted: the check runs once the robot is still, then the first primitive starts.
    Before {
        /// The state the reconfiguration starts from.
        from: State,
        /// Its target state.
        to: State,
    },
    /// The target is reached: the check runs once the robot is still, then command complete.
    After,
}

/// Everything of a motion in progress, as a Stop found it.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
struct Paused {
    runner: Option<Runner>,
    idle_check: Option<IdleCheck>,
    coord: Coordinator,
    waiting_job: Option<Queued>,
    targets: Targets,
    contracting: PerSide<Contraction>,
    pair: Option<(crate::command::BolterPair, u8)>,
    single: bool,
}

impl BoardA {
    /// Startup: Standby, no state known, servos at their home pulses.
    pub fn new(cfg: Config) -> BoardA {
        let home = Targets::home();
        BoardA {
            cfg,
            sup: Supervisor::new(),
            log: CommandLog::new(),
            comm: CommMonitor::default(),
            battery: LowBattery::default(),
            runner: None,
            tracked: None,
            target_state: None,
            complete: false,
            single: false,
            coord: Coordinator::new(),
            side_a: BolterSide::new(),
            waiting_job: None,
            targets: Targets {
                hip: cfg.safety.hip_home,
                ..home
            },
            arm: Interpolator::new(cfg.arm.contracted, cfg.rate),
            gripper: Interpolator::new(cfg.gripper.extended, cfg.rate),
            hip_ctl: HipController::new(cfg.hip),
            b: InternalHeartbeatRepr::default(),
            b_heard: false,
            link: BLink::new(),
            contracting: PerSide::both(Contraction::Idle),
            refusal: None,
            moving: false,
            pair: None,
            still_since: None,
            idle_check: None,
            paused: None,
            hold_b: false,
            hip_seen: cfg.safety.hip_home,
            watch: Watch::Idle,
        }
    }

    /// Starts knowing the state the robot is in (the host simulator's initial pose).
    pub fn in_state(cfg: Config, state: State) -> BoardA {
        let mut a = BoardA::new(cfg);
        a.tracked = Some(state);
        a
    }

    /// Mode.
    pub const fn mode(&self) -> Mode {
        self.sup.mode()
    }

    /// Latched faults.
    pub const fn faults(&self) -> Faults {
        self.sup.faults()
    }

    /// The state last reached, if known.
    pub const fn state(&self) -> Option<State> {
        self.tracked
    }

    /// The exactly-once log: last sequenced command and its outcome.
    pub const fn last_command(&self) -> (u16, Option<Refusal>) {
        self.log.last()
    }

    /// A motion or bolting job was running at the last tick (a reconfiguration with its idle
    /// checks, a bolting job, or a module still moving to its target).
    pub const fn in_motion(&self) -> bool {
        self.moving
    }

    /// A Stop interrupted a motion that waits for Reset.
    pub const fn paused(&self) -> bool {
        self.paused.is_some()
    }

    /// Something physically moves: a primitive, a bolting job, a servo or the hip on its way.
    fn physically_moving(&self, fb: &Feedback) -> bool {
        self.runner
            .is_some_and(|r| r.status() == RunStatus::Running)
            || self.coord.status() == coordinator::Status::Running
            || self.waiting_job.is_some()
            || !fb.arm_done.all()
            || !fb.gripper_done.all()
            || !fb.hip_done
    }

    /// Busy with a motion: moving, or a reconfiguration waiting for its idle check.
    fn moving_now(&self, fb: &Feedback) -> bool {
        self.physically_moving(fb) || self.idle_check.is_some()
    }

    /// The robot has been still for `idle_settle_ms`: its averaged currents are at rest. (The
    /// idle checks also wait for the ADC to answer: a stale average judges nothing.)
    fn at_rest(&self, now: u32) -> bool {
        self.still_since
            .is_some_and(|t| Instant::from_millis(now).since(t).millis() >= self.cfg.idle_settle_ms)
    }

    fn feedback(&self, hip_now: Option<HipAngle>, arm_a_switch: bool) -> Feedback {
        // Side B's servo is done when B reports it at the target A wants. While B holds (a
        // Stop, a mode change), B stops where it is when the hold reaches it, which is not
        // where its last report put it (B moved on for up to a report and a command period):
        // it is done when it reports itself at rest. Until issue 24 the hold was judged
        // against the stale report, so a robot stopped with a side-B servo on its way stayed
        // "in motion" for ever.
        let b_ok = |now: PulseWidth, target: PulseWidth, want: PulseWidth| {
            now == target && (self.hold_b || target == want)
        };
        Feedback {
            arm_done: PerSide::new(
                self.arm.done(),
                b_ok(
                    self.b.arm_b_now,
                    self.b.arm_b_target,
                    self.cfg.arm.resolve(self.targets.arm.b),
                ),
            ),
            gripper_done: PerSide::new(
                self.gripper.done(),
                b_ok(
                    self.b.gripper_b_now,
                    self.b.gripper_b_target,
                    self.cfg.gripper.resolve(self.targets.gripper.b),
                ),
            ),
            // An unread hip is not at its target: the motion waits (and times out).
            hip_done: hip_now
                .is_some_and(|h| h.distance(self.targets.hip) <= self.cfg.hip_done_tolerance),
            arm_switch: PerSide::new(arm_a_switch, self.b.arm_contracted),
        }
    }

    /// One tick at `now` (ms, wrapping), in phases that read in order: take board B's report,
    /// advance the motion and the bolting, detect the fault conditions, take the command
    /// through the exactly-once log, let the supervisor judge it against the faults, answer,
    /// drive the outputs.
    pub fn tick(&mut self, now: u32, inp: &Inputs) -> Outputs {
        let mut out = Outputs::empty();
        if let Some(h) = inp.hip {
            self.hip_seen = h;
        }
        self.ingest_b(now, inp.from_b, &mut out);
        // Motion and bolting advance first, so the supervisor sees whether they still run.
        // The feedback is this tick's readings against the targets in force; a target the
        // motion sets now is judged from the next tick on (a primitive that issued one is
        // still running, so the robot counts as moving either way).
        let fb = self.feedback(inp.hip, inp.arm_contracted);
        if self.physically_moving(&fb) {
            self.still_since = None;
        } else if self.still_since.is_none() {
            self.still_since = Some(Instant::from_millis(now));
        }
        let events = self.advance(now, inp, &fb, &mut out);
        let in_motion = self.moving_now(&fb);
        if self.single && !in_motion {
            self.single = false;
            self.complete = true;
        }
        self.moving = in_motion;
        let conditions = self.detect(now, inp);
        let taken = self.take_command(inp.command, in_motion, &mut out);
        let s = self.supervise(
            now,
            inp,
            conditions.union(events),
            taken,
            in_motion,
            &mut out,
        );
        self.drive(now, inp, &s, &mut out);
        if taken.answer.is_some() {
            out.heartbeat = Some(self.heartbeat(inp, &s.faults).to_bytes());
        }
        out
    }

    /// Board B's report: refreshes the communication monitor and what A knows of side B.
    fn ingest_b(
        &mut self,
        now: u32,
        from_b: Option<[u8; INTERNAL_HEARTBEAT_LEN]>,
        out: &mut Outputs,
    ) {
        self.comm.tick(now);
        if let Some(bytes) = from_b {
            match InternalHeartbeatRepr::parse(&bytes) {
                Ok(hb) => {
                    self.comm.heartbeat(now, hb.command_received);
                    self.b = hb;
                    self.b_heard = true;
                }
                Err(e) => out.push(Event::Rejected(e)),
            }
        }
    }

    /// Advances the reconfiguration (with its idle checks), the bolting and the arm
    /// contraction check; returns the faults they raised this tick (events, not conditions).
    fn advance(&mut self, now: u32, inp: &Inputs, fb: &Feedback, out: &mut Outputs) -> Faults {
        let mut faults = Faults::EMPTY;
        if let Some(IdleCheck::Before { from, to }) = self.idle_check {
            if self.sup.standby_pending() {
                // A deferred fault waits for the motion in progress; none has started, so
                // none starts: the reconfiguration is dropped and Standby comes next tick.
                self.idle_check = None;
            } else if self.at_rest(now) && !inp.lost.adc {
                self.idle_check = None;
                let f = self.idle_faults(inp);
                if f.is_empty() {
                    self.runner = Some(Runner::start(self.cfg.motion, from, to, self.targets, now));
                    if let Some(r) = self.runner {
                        self.targets = r.targets();
                    }
                } else {
                    // Not gripping, an arm stuck, a bolter caught: starting would drop the
                    // robot or burn a motor (Section 7). The motion does not start.
                    faults = faults.union(f);
                }
            }
        }
        if let Some(mut r) = self.runner {
            match r.step(now, fb) {
                RunStatus::Running => {
                    self.targets = r.targets();
                    self.runner = Some(r);
                }
                RunStatus::Complete => {
                    self.targets = r.targets();
                    self.tracked = Some(r.current_state());
                    self.runner = None;
                    // Command complete waits for the idle check at the end.
                    self.idle_check = Some(IdleCheck::After);
                    out.push(Event::Reached(r.current_state()));
                }
                RunStatus::Failed(f) => {
                    self.tracked = None;
                    self.runner = None;
                    faults = faults.with(f);
                }
            }
        }
        if self.idle_check == Some(IdleCheck::After) && self.at_rest(now) && !inp.lost.adc {
            self.idle_check = None;
            let f = self.idle_faults(inp);
            self.complete = f.is_empty();
            faults = faults.union(f);
        }
        self.bolting(now, out, &mut faults);
        if self.watch_modules(now, fb) {
            faults = faults.with(Fault::MotionTimeout);
        }
        // Arm contraction check (Table 8), on both sides: after a commanded contraction ends,
        // the switch must close.
        for side in [Side::A, Side::B] {
            if self.contraction(side, now, fb) {
                faults = faults.with(Fault::ArmNotContracted);
            }
        }
        faults
    }

    /// The deadline of a module motion with no step timeout of its own (spec/decisions.toml,
    /// `module-motion-deadline`): armed when the modules start moving towards their targets
    /// outside a primitive, a bolting job or a job waiting for board B, in any mode but Standby
    /// (nothing is driven there, and the robot may be moved by hand); when it passes, the
    /// motion stops where the modules are ([`BoardA::stop_all`]) and true is returned: the
    /// motion-timeout fault. A motion that was Stopped and Reset starts with a fresh budget.
    fn watch_modules(&mut self, now: u32, fb: &Feedback) -> bool {
        let modules = !fb.arm_done.all() || !fb.gripper_done.all() || !fb.hip_done;
        let timed = self
            .runner
            .is_some_and(|r| r.status() == RunStatus::Running)
            || self.coord.status() == coordinator::Status::Running
            || self.waiting_job.is_some();
        let own = modules && !timed && self.sup.mode() != Mode::Standby;
        let t = Instant::from_millis(now);
        match (self.watch, own) {
            (Watch::Idle, true) => {
                let budget = Duration::from_millis(self.module_budget_ms());
                self.watch = Watch::Armed(t.after(budget));
            }
            (Watch::Armed(deadline), true) if t.reached(deadline) => {
                self.watch = Watch::Expired;
                self.stop_all(now, self.hip_seen);
                return true;
            }
            (Watch::Armed(_), false) => self.watch = Watch::Idle,
            (Watch::Expired, _) if !modules => self.watch = Watch::Idle,
            _ => {}
        }
        false
    }

    /// The budget of the module motion towards the current targets, from where each module is
    /// now (side B's servos as board B last reported them): the slowest servo's interpolation
    /// time and the hip's time at its velocity-mode speed, with their margins.
    fn module_budget_ms(&self) -> u32 {
        let servo = |from: PulseWidth, to: PulseWidth| deadline::servo_ms(from, to, self.cfg.rate);
        let (arm, gripper) = (self.cfg.arm, self.cfg.gripper);
        let servos = [
            servo(self.arm.now(), arm.resolve(self.targets.arm.a)),
            servo(self.b.arm_b_now, arm.resolve(self.targets.arm.b)),
            servo(self.gripper.now(), gripper.resolve(self.targets.gripper.a)),
            servo(
                self.b.gripper_b_now,
                gripper.resolve(self.targets.gripper.b),
            ),
        ];
        let servos = servos.into_iter().max().unwrap_or(0);
        let hip = deadline::hip_ms(self.hip_seen, self.targets.hip, self.cfg.hip.speed);
        deadline::budget_ms(&self.cfg.deadline, servos, hip)
    }

    /// Advances side `side`'s contraction check; true when it failed.
    fn contraction(&mut self, side: Side, now: u32, fb: &Feedback) -> bool {
        let now = Instant::from_millis(now);
        let (next, failed) = match self.contracting[side] {
            Contraction::Idle => (Contraction::Idle, false),
            _ if fb.arm_switch[side] => (Contraction::Idle, false),
            Contraction::Moving if fb.arm_done[side] => (Contraction::Confirming(now), false),
            Contraction::Moving => (Contraction::Moving, false),
            Contraction::Confirming(t) if now.since(t).millis() > self.cfg.motion.confirm_ms => {
                (Contraction::Idle, true)
            }
            c @ Contraction::Confirming(_) => (c, false),
        };
        self.contracting[side] = next;
        failed
    }

    /// Section 7's idle check: side A's currents against the at-rest limits, side B as board B
    /// judged its own (Table 4 bytes 38–40).
    fn idle_faults(&self, inp: &Inputs) -> Faults {
        let b = detect::Over {
            locomotion: self.b.arm_over_idle,
            gripper: self.b.gripper_over_idle,
            bolter: self.b.bolter_over_idle,
        };
        detect::idle_overcurrent(&self.cfg.safety, &inp.electrical, b)
    }

    /// The fault conditions holding now: operational overcurrent (side A from its currents,
    /// side B as board B judged it: Table 4 bytes 41–43), low battery, lost communication with
    /// board B. The idle overcurrent check is not one: it runs at the start and the end of a
    /// reconfiguration only ([`IdleCheck`]).
    fn detect(&mut self, now: u32, inp: &Inputs) -> Faults {
        let e_b = self.b.electrical_b;
        let b_over = detect::Over {
            locomotion: self.b.arm_overcurrent,
            gripper: self.b.gripper_overcurrent,
            bolter: self.b.bolter_overcurrent,
        };
        let mut conditions = Faults::EMPTY;
        if inp.lost.any() {
            conditions = conditions.with(Fault::SensorLoss);
        }
        // Side A's currents and voltages are judged only while the ADC answers: a stale
        // average (or none) says nothing of now, and sensor loss already stops the robot.
        if !inp.lost.adc {
            conditions = conditions.union(detect::operational_overcurrent(
                &self.cfg.safety,
                &inp.electrical,
                b_over,
            ));
            // Side B's battery only once B has reported it (Table 4 bytes 12-13).
            let v_bat_b = self.b_heard.then_some(e_b.v_bat);
            if self
                .battery
                .update(&self.cfg.safety, now, inp.electrical.v_bat, v_bat_b)
            {
                conditions = conditions.with(Fault::LowBattery);
            }
        }
        if self.comm.lost(&self.cfg.safety) {
            conditions = conditions.with(Fault::InternalCommLoss);
        }
        conditions
    }

    /// The command packet of this tick, through the exactly-once log: what goes to the
    /// supervisor, and which number the heartbeat answers.
    fn take_command(
        &mut self,
        command: Option<[u8; COMMAND_LEN]>,
        in_motion: bool,
        out: &mut Outputs,
    ) -> Taken {
        let mut taken = Taken::default();
        let Some(bytes) = command else {
            return taken;
        };
        match self.receive(&bytes, in_motion) {
            Received::Ignore(e) => out.push(e),
            Received::Answer(ev) => {
                // A copy: byte 62 reports the outcome of the command bytes 57-58 name.
                out.push(ev);
                self.refusal = self.log.last().1;
                taken.answer = Some(0);
            }
            Received::Run(seq, inc) => {
                taken.incoming = Some(inc);
                taken.answer = Some(seq);
            }
            Received::Refuse(seq, command, r) => {
                self.settle(seq, Some(command), Some(r), out);
                taken.answer = Some(seq);
            }
        }
        taken
    }

    /// Writes a command's outcome: into the exactly-once log, the heartbeat's refusal byte and
    /// the events. The one place a command number is settled.
    fn settle(
        &mut self,
        seq: u16,
        command: Option<Command>,
        refusal: Option<Refusal>,
        out: &mut Outputs,
    ) {
        self.log.record(seq, refusal);
        self.refusal = refusal;
        out.push(Event::Executed {
            seq,
            command,
            refusal,
        });
    }

    /// The supervisor's step over this tick's faults and command; applies its stop and home
    /// orders, settles and dispatches the command, reports mode and fault changes.
    fn supervise(
        &mut self,
        now: u32,
        inp: &Inputs,
        faults: Faults,
        taken: Taken,
        in_motion: bool,
        out: &mut Outputs,
    ) -> crate::safety::supervisor::Output {
        let before = (self.sup.mode(), self.sup.faults());
        let initial_state_ok = match taken.incoming {
            Some(Incoming::Command(Command::Reconfigure(r))) => {
                // Without a hip reading the state cannot be confirmed from the sensors.
                let sensed = self.readings(inp).map_or(StateSet::EMPTY, |r| {
                    estimate::consistent(&self.cfg.estimate, &r)
                });
                initial_state_consistent(r.initial(), self.tracked, sensed)
            }
            _ => true,
        };
        let s = self.sup.step(&Input {
            faults,
            command: taken.incoming,
            in_motion,
            hip_at_home: inp
                .hip
                .is_some_and(|h| detect::hip_at_home(&self.cfg.safety, h)),
            initial_state_ok,
        });
        if s.stop_motion {
            if self.sup.stopped() {
                // A Stop interrupted a motion: keep it for Reset (a second Stop keeps the first).
                if self.paused.is_none() {
                    self.pause();
                    out.push(Event::Paused);
                }
            } else {
                // A mode change (or a Stop with nothing running) drops what a Stop had kept.
                self.paused = None;
            }
            self.stop_all(now, self.hip_seen);
        }
        if s.resume {
            self.resume(now);
            out.push(Event::Resumed);
        }
        if s.go_home {
            self.go_home(now);
        }
        if let (Some(seq), Some(a)) = (taken.answer, s.answer) {
            match a {
                Answer::Accepted(c) => {
                    self.settle(seq, Some(c), None, out);
                    self.dispatch(c, now);
                }
                Answer::Refused(r) => {
                    let c = match taken.incoming {
                        Some(Incoming::Command(c)) => Some(c),
                        _ => None,
                    };
                    self.settle(seq, c, Some(r), out);
                }
            }
        }
        if s.mode != before.0 {
            out.push(Event::Mode {
                from: before.0,
                to: s.mode,
            });
        }
        let new_faults = Faults::from_iter(s.faults.iter().filter(|f| !before.1.contains(*f)));
        if !new_faults.is_empty() {
            // A fault that stops the motion (a mode change: `stop_all`) leaves it incomplete;
            // one deferred to the motion's end lets it complete first, as Table 8 says.
            out.push(Event::Faults(new_faults));
        }
        s
    }

    /// Drives side A's actuators and board B's command from the supervisor's power decision.
    fn drive(
        &mut self,
        now: u32,
        inp: &Inputs,
        s: &crate::safety::supervisor::Output,
        out: &mut Outputs,
    ) {
        let live = s.mode != Mode::Standby;
        let p = s.powered;
        self.arm_targets(now);
        let arm_now = self.arm.tick(now);
        let gripper_now = self.gripper.tick(now);
        let hip_pulse = match inp.hip {
            Some(h) => self.hip_ctl.step(self.targets.hip, h, now),
            None => self.hip_ctl.blind(),
        };
        out.regulator = s.regulator;
        out.hip = (live && p.contains(Module::Hip)).then_some(hip_pulse);
        out.arm = (live && p.contains(Module::ArmA)).then_some(arm_now);
        out.gripper = (live && p.contains(Module::GripperA)).then_some(gripper_now);
        let bolter = Sensed {
            i_bo: inp.electrical.i_bo,
            at_home: inp.bolter_at_home,
        };
        self.side_a.tick(&self.cfg.bolter.side, now, bolter);
        if live && p.contains(Module::BolterA) {
            out.bolter = self.side_a.drive();
        }
        out.mux = self.side_a.mux();
        out.to_b = self.b_command(now, p, s.regulator);
    }

    /// A command packet through the exactly-once log, admitted in this one place: not ours
    /// (ignored), a copy (answered from the log), or to be judged — by the supervisor, after
    /// the board-level checks it does not make.
    fn receive(&mut self, bytes: &[u8], in_motion: bool) -> Received {
        let (seq, command) = match CommandRepr::parse(bytes) {
            Ok(r) if r.board != self.cfg.board => {
                return Received::Ignore(Event::OtherRobot { board: r.board })
            }
            Ok(r) => (r.seq, Ok(r.command)),
            // Length, header and checksum held (the command check comes after them) but the
            // opcode or parameters are no command: ours to answer, with its sequence number,
            // so the ground stops resending it.
            Err(WireError::Command(ce)) => match crate::wire::check::<CommandPacket>(bytes) {
                Ok(p) if p.board_number() == self.cfg.board.get() => (p.seq(), Err(ce.refusal())),
                _ => return Received::Ignore(Event::Rejected(WireError::Command(ce))),
            },
            Err(e) => return Received::Ignore(Event::Rejected(e)),
        };
        match self.log.admit(seq) {
            Admission::Duplicate => return Received::Answer(Event::Duplicate { seq }),
            Admission::Stale => return Received::Answer(Event::Stale { seq }),
            Admission::Execute => {}
        }
        let c = match command {
            // The supervisor refuses it like any other command it cannot take.
            Err(r) => return Received::Run(seq, Incoming::Malformed(r)),
            Ok(c) => c,
        };
        // Board-level checks the supervisor does not make. A position outside this robot's
        // configured travel is a malformed command here, whatever the robot is doing (the
        // packet's own check is against the library's travel): the servo would be driven
        // against its end stop.
        let travel = match c {
            Command::Arm { target, .. } => self.cfg.arm.check(target).err(),
            Command::Gripper { target, .. } => self.cfg.gripper.check(target).err(),
            _ => None,
        };
        if travel.is_some() {
            return Received::Refuse(seq, c, Refusal::InvalidParameter);
        }
        // One motion at a time, and a primitive must be the map's move from the state the
        // robot is in to the final state it names.
        if c.kind().moves() && in_motion && self.sup.mode() == Mode::Operational {
            return Received::Refuse(seq, c, Refusal::Busy);
        }
        if let Command::Primitive(m) = c {
            if self.sup.mode() == Mode::Operational && self.primitive_move(m).is_none() {
                // From where the robot is, the model's move is a turn the hip cannot make: the
                // ground's belief holds, the move does not exist.
                let hipless = self.tracked.is_some_and(|t| m.turns_without_hip_from(t));
                // Otherwise the command holds only where the primitive takes some state to its
                // final state; the robot is in none of them: the ground's belief of where the
                // robot is does not hold, as with a reconfiguration's initial state.
                let why = if hipless {
                    Refusal::TurnWithoutHip
                } else {
                    Refusal::InitialStateMismatch
                };
                return Received::Refuse(seq, c, why);
            }
        }
        Received::Run(seq, Incoming::Command(c))
    }

    /// The move a primitive command asks for, as (from, to): from the tracked state to the
    /// command's final state, when that is the primitive's cell of the map (Figure 9). The
    /// final state settles the 12 (state, primitive) pairs that reach two states.
    fn primitive_move(&self, m: PrimitiveMove) -> Option<(State, State)> {
        let from = self.tracked?;
        m.is_move_from(from).then_some((from, m.target()))
    }

    fn readings(&self, inp: &Inputs) -> Option<Readings> {
        Some(Readings {
            gravity_a: inp.gravity,
            gravity_b: self.b.gravity,
            arm_a_contracted: inp.arm_contracted,
            arm_b_contracted: self.b.arm_contracted,
            hip: inp.hip?,
        })
    }

    fn dispatch(&mut self, c: Command, now: u32) {
        if c.kind().moves() {
            // A new motion gets a budget of its own, also after one that timed out.
            self.watch = Watch::Idle;
            self.release_b_hold();
            if !matches!(c, Command::Primitive(_) | Command::Reconfigure(_)) {
                self.complete = false;
                self.single = true;
            }
        }
        match c {
            Command::Arm { side, target } => {
                self.targets.arm[side] = target;
                self.contracting[side] = if target == ServoTarget::Contract {
                    Contraction::Moving
                } else {
                    Contraction::Idle
                };
            }
            Command::Gripper { side, target } => self.targets.gripper[side] = target,
            Command::Hip(h) => {
                self.targets.hip = match (h, preset_angle(h)) {
                    (_, Some(a)) => a,
                    (HipTarget::Angle(a), None) => a,
                    _ => self.cfg.safety.hip_home,
                }
            }
            Command::Bolter(b) => {
                self.waiting_job = Some(match b {
                    BolterCommand::Bolt(f) => Queued::Job(Job {
                        direction: BolterDirection::Bolt,
                        fasteners: f,
                    }),
                    BolterCommand::Unbolt(f) => Queued::Job(Job {
                        direction: BolterDirection::Unbolt,
                        fasteners: f,
                    }),
                    // Table 1 lists it on its own: both bolters descend and stop there.
                    BolterCommand::Down => Queued::Down,
                });
                self.bolting_start(now);
            }
            Command::Primitive(m) => {
                if let Some((from, to)) = self.primitive_move(m) {
                    self.start_run(from, to);
                }
            }
            Command::Reconfigure(r) => {
                let from = self.tracked.unwrap_or(r.initial());
                self.start_run(from, r.target());
            }
            _ => {}
        }
    }

    /// A reconfiguration (or primitive) accepted: it starts after the idle check
    /// ([`IdleCheck::Before`]), in [`BoardA::advance`].
    fn start_run(&mut self, from: State, to: State) {
        self.target_state = Some(to);
        self.complete = from == to;
        if from != to {
            self.idle_check = Some(IdleCheck::Before { from, to });
        }
    }

    /// A new job waits until B reports idle, so that B's executor cannot mistake the job's
    /// first order for its previous one (spec/control/bolter.md).
    fn bolting_start(&mut self, now: u32) {
        if let Some(q) = self.waiting_job {
            if self.b.bolter_aux.step.is_none() || !self.b_heard {
                match q {
                    Queued::Job(job) => self.coord.start(job, now),
                    Queued::Down => self.coord.start_down(now),
                }
                self.waiting_job = None;
            }
        }
    }

    fn bolting(&mut self, now: u32, out: &mut Outputs, faults: &mut Faults) {
        self.bolting_start(now);
        let was = self.coord.status();
        // B's report names the A→B packet it adopted its order from; it is about the
        // coordinator's order when that packet was one of the run that carried the order
        // (node::b_link), and then it is handed over under the coordinator's number.
        let b = match self.coord.order() {
            Some((seq, order))
                if self.b_heard && self.link.carried(self.b.bolter_aux.seq, &order) =>
            {
                Some(crate::wire::internal_heartbeat::BolterAux {
                    seq,
                    ..self.b.bolter_aux
                })
            }
            _ => None,
        };
        let a_aux = self.side_a.aux();
        let o = self.coord.step(&self.cfg.bolter, now, &a_aux, b.as_ref());
        let order = o.order;
        self.side_a
            .order(order.map_or(0, |(s, _)| s), order.map(|(_, o)| o), now);
        let down = self.coord.descend_only();
        if was == coordinator::Status::Running && o.status != coordinator::Status::Running && down {
            out.push(Event::BoltersDown {
                contact: a_aux.threshold_reached && b.is_some_and(|x| x.threshold_reached),
            });
            return;
        }
        if let (Some(p), coordinator::Status::Running, false) = (o.active, o.status, down) {
            if let Some((q, attempts)) = self.pair.filter(|(q, _)| *q != p) {
                out.push(Event::Pair {
                    pair: q,
                    attempts,
                    ok: true,
                });
            }
            self.pair = Some((p, o.attempt.get()));
        }
        if was == coordinator::Status::Running && o.status != coordinator::Status::Running {
            let ok = o.status == coordinator::Status::Done;
            if let Some((pair, attempts)) = self.pair.take() {
                out.push(Event::Pair { pair, attempts, ok });
            }
            match o.status {
                coordinator::Status::Failed(f) => {
                    *faults = faults.with(f);
                    out.push(Event::Bolting(Some(f)));
                }
                _ => out.push(Event::Bolting(None)),
            }
        }
    }

    /// Keeps the motion in progress for Reset.
    fn pause(&mut self) {
        self.paused = Some(Paused {
            runner: self.runner,
            idle_check: self.idle_check,
            coord: self.coord,
            waiting_job: self.waiting_job,
            targets: self.targets,
            contracting: self.contracting,
            pair: self.pair,
            single: self.single,
        });
    }

    /// Reset: the motion a Stop interrupted goes on from the step where it stopped, with fresh
    /// step timeouts (the time stopped is no stall).
    fn resume(&mut self, now: u32) {
        let Some(p) = self.paused.take() else { return };
        self.watch = Watch::Idle;
        self.runner = p.runner;
        self.idle_check = p.idle_check;
        self.coord = p.coord;
        self.waiting_job = p.waiting_job;
        self.targets = p.targets;
        self.contracting = p.contracting;
        self.pair = p.pair;
        self.single = p.single;
        self.hold_b = false;
        if let Some(r) = self.runner.as_mut() {
            r.resume(now);
            self.targets = r.targets();
        }
        if self.coord.status() == coordinator::Status::Running {
            self.coord.resume(now);
        }
    }

    /// Every actuator holds where it is (Table 1's Stop, Table 7's Safed): the servos at their
    /// last interpolated pulse, the hip at its reading `hip`, the bolters idle, board B told to
    /// hold; the motion in progress ends (kept for Reset by [`BoardA::pause`] if a Stop
    /// interrupted it).
    fn stop_all(&mut self, now: u32, hip: HipAngle) {
        self.runner = None;
        self.idle_check = None;
        self.pair = None;
        self.single = false;
        self.coord.stop();
        self.waiting_job = None;
        self.side_a.order(0, None, now);
        self.targets = Targets {
            arm: PerSide::new(
                ServoTarget::Position(self.arm.now()),
                ServoTarget::Position(self.b.arm_b_now),
            ),
            gripper: PerSide::new(
                ServoTarget::Position(self.gripper.now()),
                ServoTarget::Position(self.b.gripper_b_now),
            ),
            hip,
        };
        self.hold_b = true;
        self.contracting = PerSide::both(Contraction::Idle);
    }

    /// A command that moves side B lifts the hold: side B's targets become where B reports it
    /// held (so only what is commanded now moves).
    fn release_b_hold(&mut self) {
        if self.hold_b {
            self.hold_b = false;
            self.targets.arm.b = ServoTarget::Position(self.b.arm_b_now);
            self.targets.gripper.b = ServoTarget::Position(self.b.gripper_b_now);
        }
    }

    fn go_home(&mut self, now: u32) {
        let _ = now;
        self.watch = Watch::Idle;
        self.hold_b = false;
        self.targets = Targets {
            hip: self.cfg.safety.hip_home,
            ..Targets::home()
        };
    }

    fn arm_targets(&mut self, now: u32) {
        let arm = self.cfg.arm.resolve(self.targets.arm.a);
        if self.arm.target() != arm {
            self.arm.set_target(arm, now);
        }
        let gripper = self.cfg.gripper.resolve(self.targets.gripper.a);
        if self.gripper.target() != gripper {
            self.gripper.set_target(gripper, now);
        }
    }

    fn b_command(
        &mut self,
        now: u32,
        p: ModuleSet,
        regulator: bool,
    ) -> Option<[u8; B_COMMAND_LEN]> {
        let live = self.sup.mode() != Mode::Standby;
        let snapshot = BCommandRepr {
            // Numbered by the link: every new snapshot gets a new number.
            seq: 0,
            power: BPower {
                regulator,
                arm: live && p.contains(Module::ArmB),
                gripper: live && p.contains(Module::GripperB),
                bolter: live && p.contains(Module::BolterB),
            },
            stop: self.hold_b,
            arm_target: self.cfg.arm.resolve(self.targets.arm.b),
            gripper_target: self.cfg.gripper.resolve(self.targets.gripper.b),
            bolter: self.coord.order().map(|(_, o)| o),
        };
        let cmd = self.link.due(now, self.cfg.b_period_ms, snapshot)?;
        self.comm.sent(cmd.seq);
        Some(cmd.to_bytes())
    }

    fn heartbeat(&self, inp: &Inputs, faults: &Faults) -> HeartbeatRepr {
        let (last_seq, _) = self.log.last();
        let o = self.coord.order();
        HeartbeatRepr {
            board: self.cfg.board,
            hip_target: self.targets.hip,
            hip_now: self.hip_seen,
            arm_a_target: self.arm.target(),
            arm_a_now: self.arm.now(),
            arm_b_target: self.b.arm_b_target,
            arm_b_now: self.b.arm_b_now,
            gripper_a_target: self.gripper.target(),
            gripper_a_now: self.gripper.now(),
            gripper_b_target: self.b.gripper_b_target,
            gripper_b_now: self.b.gripper_b_now,
            electrical_a: inp.electrical,
            electrical_b: self.b.electrical_b,
            target_state: self.target_state,
            command_complete: self.complete,
            active_bolter: o.map(|(_, o)| o.pair),
            bolter_attempt: match (o, BolterAttempt::new(self.coord.attempt())) {
                (Some(_), Ok(a)) => a,
                _ => BolterAttempt::NONE,
            },
            faults: *faults,
            refusal: self.refusal,
            mode: self.sup.mode(),
            last_seq,
        }
    }
}

/// This tick's command after the exactly-once log: what the supervisor judges, and the number
/// the heartbeat answers (0 for a copy, whose outcome the log already holds).
#[derive(Debug, Clone, Copy, Default)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
struct Taken {
    incoming: Option<Incoming>,
    answer: Option<u16>,
}

enum Received {
    /// Not for us, or not a packet: no answer.
    Ignore(Event),
    /// A copy: answer with the log's record.
    Answer(Event),
    /// Hand to the supervisor.
    Run(u16, Incoming),
    /// Refused by board A itself.
    Refuse(u16, Command, Refusal),
}
