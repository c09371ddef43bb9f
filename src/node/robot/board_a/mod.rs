//! Board A: the robot's primary board as one pure tick.
//!
//! Each tick takes what the shell gathered since the last one — at most one command packet
//! from the WiFi hand-off queue, at most one internal heartbeat from board B's serial line,
//! and side A's filtered sensors — and returns side A's module outputs, the A→B command to
//! send (if one is due), the 66-byte heartbeat answering the command (if one came), and what
//! happened, as [`Event`]s for logs. The paper gives no order for these steps (Section 4 lists
//! what board A embeds; Figure 6, board A's loop, is missing from its text), so the order of a
//! tick is the project's: board B's heartbeat is taken in; motion and bolting advance first
//! (the idle checks, the reconfiguration runner and single-module moves, the bolting
//! coordinator and side A's executor, the motion deadline, the arm-contraction check), so that
//! what follows knows whether they still run; then fault detection judges the conditions; then
//! the command is taken (exactly-once log, board A's own checks); then the mode supervisor
//! (Tables 7 and 8) decides on the faults and the command and dispatches it; finally the servo
//! and hip outputs and board B's command are driven, and the heartbeat answering the command is
//! built.
//!
//! ```
//! use mmic::command::Command;
//! use mmic::mode::Mode;
//! use mmic::node::robot::board_a::{BoardA, Config, Inputs};
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
//! assert!(out.events.iter().any(|e| matches!(e, mmic::node::robot::board_a::Event::Duplicate { seq: 1 })));
//! ```
// req: P4.1, P4.4, P3.14, P7.6

//!
//! The board is split by what each part holds: this file has the board's state and its tick;
//! [`interface`] what a tick takes and gives; `motion` the motion in progress (`Motion`:
//! the reconfiguration runner, single-module moves, the idle checks, the bolting job, the
//! targets), which a Stop sets aside and Reset puts back; `command_path` a command's way
//! through the exactly-once log, board A's own checks, the supervisor and the dispatch;
//! `bolting` the bolting job and the A→B link; `report` the fault conditions and the
//! heartbeat.

mod bolting;
mod command_path;
pub mod interface;
mod motion;
mod report;
mod restart;

pub use interface::{Config, Event, Inputs, Outputs, EVENTS};
use motion::{Motion, Watch};
pub use restart::Durable;

use super::b_link::BLink;
use crate::bolter::{BolterSide, Sensed};
use crate::control::hip::HipController;
use crate::control::interp::Interpolator;
use crate::faults::Faults;
use crate::mode::Mode;
use crate::motion::sequencer::{Feedback, Targets};
use crate::motion::State;
use crate::node::exactly_once::CommandLog;
use crate::refusal::Refusal;
use crate::restart::Boot;
use crate::safety::detect::{CommMonitor, LowBattery};
use crate::safety::supervisor::Supervisor;
use crate::units::{HipAngle, Instant, Module, PerSide, PulseWidth};
use crate::wire::internal_heartbeat::InternalHeartbeatRepr;

/// Board A's state.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct BoardA {
    cfg: Config,
    sup: Supervisor,
    log: CommandLog,
    comm: CommMonitor,
    battery: LowBattery,
    tracked: Option<State>,
    target_state: Option<State>,
    complete: bool,
    /// The motion in progress.
    motion: Motion,
    /// The motion a Stop interrupted, kept for Reset.
    paused: Option<Motion>,
    side_a: BolterSide,
    arm: Interpolator,
    gripper: Interpolator,
    hip_ctl: HipController,
    b: InternalHeartbeatRepr,
    b_heard: bool,
    link: BLink,
    refusal: Option<Refusal>,
    moving: bool,
    still_since: Option<Instant>,
    /// Board B holds where it is (the A→B stop flag): set by a Stop or a mode change, cleared
    /// by the next command that moves side B's modules, Reset, or going home.
    hold_b: bool,
    /// The last hip angle read: the heartbeat's "hip now" and the hold target of a Stop while
    /// the encoder is silent (the sensor-loss fault tells the ground it is stale).
    hip_seen: HipAngle,
    /// The deadline of the module motion in progress outside a primitive or a bolting job.
    watch: Watch,
    /// This start as heartbeat byte 59 reports it ([`BoardA::restarted`]).
    boot: Boot,
    /// Board B announced a restart since the last tick's fault detection.
    b_restarted: bool,
    /// The last sequenced command other than a Heartbeat poll, and its outcome: what flash
    /// keeps of the exactly-once log ([`BoardA::durable`]).
    kept: (u16, Option<Refusal>),
    /// Starts in all, this one included (0: started by [`BoardA::new`], not counted).
    boots: u16,
}

impl BoardA {
    /// The settings it runs with (a shell restarting the board starts it with the same).
    pub const fn config(&self) -> Config {
        self.cfg
    }

    /// Startup: Standby, no state known, servos at their home pulses.
    pub fn new(cfg: Config) -> BoardA {
        BoardA {
            cfg,
            sup: Supervisor::new(),
            log: CommandLog::new(),
            comm: CommMonitor::default(),
            battery: LowBattery::default(),
            tracked: None,
            target_state: None,
            complete: false,
            motion: Motion::new(Targets {
                hip: cfg.safety.hip_home,
                ..Targets::home()
            }),
            paused: None,
            side_a: BolterSide::new(),
            arm: Interpolator::new(cfg.arm.contracted, cfg.rate),
            gripper: Interpolator::new(cfg.gripper.extended, cfg.rate),
            hip_ctl: HipController::new(cfg.hip),
            b: InternalHeartbeatRepr::default(),
            b_heard: false,
            link: BLink::new(),
            refusal: None,
            moving: false,
            still_since: None,
            hold_b: false,
            hip_seen: cfg.safety.hip_home,
            watch: Watch::Idle,
            boot: Boot::UNREPORTED,
            b_restarted: false,
            kept: (0, None),
            boots: 0,
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
                    self.cfg.arm.resolve(self.motion.targets.arm.b),
                ),
            ),
            gripper_done: PerSide::new(
                self.gripper.done(),
                b_ok(
                    self.b.gripper_b_now,
                    self.b.gripper_b_target,
                    self.cfg.gripper.resolve(self.motion.targets.gripper.b),
                ),
            ),
            // An unread hip is not at its target: the motion waits (and times out).
            hip_done: hip_now.is_some_and(|h| {
                h.distance(self.motion.targets.hip) <= self.cfg.hip_done_tolerance
            }),
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
        if self.motion.physically_moving(&fb) {
            self.still_since = None;
        } else if self.still_since.is_none() {
            self.still_since = Some(Instant::from_millis(now));
        }
        let events = self.advance(now, inp, &fb, &mut out);
        let in_motion = self.motion.busy(&fb);
        if self.motion.single && !in_motion {
            self.motion.single = false;
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
            Some(h) => self.hip_ctl.step(self.motion.targets.hip, h, now),
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

    fn arm_targets(&mut self, now: u32) {
        let arm = self.cfg.arm.resolve(self.motion.targets.arm.a);
        if self.arm.target() != arm {
            self.arm.set_target(arm, now);
        }
        let gripper = self.cfg.gripper.resolve(self.motion.targets.gripper.a);
        if self.gripper.target() != gripper {
            self.gripper.set_target(gripper, now);
        }
    }
}
