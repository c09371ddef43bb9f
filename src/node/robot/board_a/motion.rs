//! The motion in progress: one value ([`Motion`]) that a Stop sets aside whole and Reset puts
//! back, and board A's steps over it: the reconfiguration with its idle checks (Section 7),
//! the module-motion deadline, Table 8's contraction check, Stop, Reset and the move home.

use super::interface::{Event, Inputs, Outputs};
use super::BoardA;
use crate::bolter::{self as coordinator, Coordinator, Job};
use crate::command::{BolterPair, ServoTarget};
use crate::control::deadline;
use crate::faults::{Fault, Faults};
use crate::mode::Mode;
use crate::motion::runner::{RunStatus, Runner};
use crate::motion::sequencer::{Feedback, Targets};
use crate::motion::State;
use crate::units::{Duration, HipAngle, Instant, PerSide, PulseWidth, Side};

/// Everything of the motion in progress: what a Stop keeps aside for Reset, and what a mode
/// change drops. Before issue 26 these were eight loose fields of [`BoardA`], copied one by
/// one into a `Paused` and back.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub(super) struct Motion {
    /// The reconfiguration (or primitive) running, primitive by primitive.
    pub(super) runner: Option<Runner>,
    /// Section 7's idle check before the first primitive or after the last.
    pub(super) idle_check: Option<IdleCheck>,
    /// The bolting job (both sides' bolters).
    pub(super) coord: Coordinator,
    /// A bolting job that waits for board B's bolter to report idle.
    pub(super) waiting_job: Option<Queued>,
    /// Where every module is driven.
    pub(super) targets: Targets,
    /// Table 8's contraction check, per side.
    pub(super) contracting: PerSide<Contraction>,
    /// The bolting job's pair in progress and its attempt, for [`Event::Pair`].
    pub(super) pair: Option<(BolterPair, u8)>,
    /// A single-module motion (arm, gripper, hip, bolter) runs: when it ends (not stopped by a
    /// Stop or a mode change), the heartbeat's "command complete" (byte 54) is set, as a
    /// reconfiguration's is (spec/decisions.toml, `command-complete`).
    pub(super) single: bool,
}

impl Motion {
    /// Nothing runs; the modules are driven to `targets`.
    pub(super) fn new(targets: Targets) -> Motion {
        Motion {
            runner: None,
            idle_check: None,
            coord: Coordinator::new(),
            waiting_job: None,
            targets,
            contracting: PerSide::both(Contraction::Idle),
            pair: None,
            single: false,
        }
    }

    /// A motion with step timeouts of its own runs: a primitive, a bolting job, or a job
    /// waiting for board B.
    pub(super) fn timed(&self) -> bool {
        self.runner
            .is_some_and(|r| r.status() == RunStatus::Running)
            || self.coord.status() == coordinator::Status::Running
            || self.waiting_job.is_some()
    }

    /// Something physically moves: a primitive, a bolting job, a servo or the hip on its way.
    pub(super) fn physically_moving(&self, fb: &Feedback) -> bool {
        self.timed() || !fb.arm_done.all() || !fb.gripper_done.all() || !fb.hip_done
    }

    /// Busy: moving, or a reconfiguration waiting for its idle check.
    pub(super) fn busy(&self, fb: &Feedback) -> bool {
        self.physically_moving(fb) || self.idle_check.is_some()
    }

    /// The motion ends: the runner, the idle checks, the bolting job and the contraction
    /// checks stop, and every module holds at `hold`.
    pub(super) fn stop(&mut self, hold: Targets) {
        self.runner = None;
        self.idle_check = None;
        self.pair = None;
        self.single = false;
        self.coord.stop();
        self.waiting_job = None;
        self.targets = hold;
        self.contracting = PerSide::both(Contraction::Idle);
    }

    /// After Reset: the runner and the bolting job go on from the step where they stopped,
    /// with fresh step timeouts (the time stopped is no stall).
    pub(super) fn resume(&mut self, now: u32) {
        if let Some(r) = self.runner.as_mut() {
            r.resume(now);
            self.targets = r.targets();
        }
        if self.coord.status() == coordinator::Status::Running {
            self.coord.resume(now);
        }
    }

    /// Advances side `side`'s contraction check; true when it failed: the switch did not
    /// close within `confirm_ms` of the arm's travel ending.
    pub(super) fn contraction(
        &mut self,
        side: Side,
        now: u32,
        fb: &Feedback,
        confirm_ms: u32,
    ) -> bool {
        let now = Instant::from_millis(now);
        let (next, failed) = match self.contracting[side] {
            Contraction::Idle => (Contraction::Idle, false),
            _ if fb.arm_switch[side] => (Contraction::Idle, false),
            Contraction::Moving if fb.arm_done[side] => (Contraction::Confirming(now), false),
            Contraction::Moving => (Contraction::Moving, false),
            Contraction::Confirming(t) if now.since(t).millis() > confirm_ms => {
                (Contraction::Idle, true)
            }
            c @ Contraction::Confirming(_) => (c, false),
        };
        self.contracting[side] = next;
        failed
    }
}

/// The deadline of a module motion that has no step timeout of its own (arm, gripper and hip
/// commands, the move home, a module pushed off its target): armed when modules start to move
/// towards their targets with the budget of [`deadline::budget_ms`], disarmed when they are
/// there ([`BoardA::watch_modules`]).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub(super) enum Watch {
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
pub(super) enum Queued {
    /// Bolt or unbolt.
    Job(Job),
    /// Table 1's "move bolters down".
    Down,
}

/// Table 8's arm contraction check after a single-module "contract arm" command, per side.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub(super) enum Contraction {
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
pub(super) enum IdleCheck {
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

impl BoardA {
    /// Advances the reconfiguration (with its idle checks), the bolting and the arm
    /// contraction check; returns the faults they raised this tick (events, not conditions).
    pub(super) fn advance(
        &mut self,
        now: u32,
        inp: &Inputs,
        fb: &Feedback,
        out: &mut Outputs,
    ) -> Faults {
        let mut faults = self.idle_check_before(now, inp);
        faults = faults.union(self.step_runner(now, fb, out));
        faults = faults.union(self.idle_check_after(now, inp));
        self.bolting(now, out, &mut faults);
        if self.watch_modules(now, fb) {
            faults = faults.with(Fault::MotionTimeout);
        }
        // Arm contraction check (Table 8), on both sides: after a commanded contraction ends,
        // the switch must close.
        for side in [Side::A, Side::B] {
            if self
                .motion
                .contraction(side, now, fb, self.cfg.motion.confirm_ms)
            {
                faults = faults.with(Fault::ArmNotContracted);
            }
        }
        faults
    }

    /// The idle check before a reconfiguration: once the robot is still, its first primitive
    /// starts, or the faults the check found are returned and it does not start.
    fn idle_check_before(&mut self, now: u32, inp: &Inputs) -> Faults {
        let Some(IdleCheck::Before { from, to }) = self.motion.idle_check else {
            return Faults::EMPTY;
        };
        if self.sup.standby_pending() {
            // A deferred fault waits for the motion in progress; none has started, so none
            // starts: the reconfiguration is dropped and Standby comes next tick.
            self.motion.idle_check = None;
        } else if self.at_rest(now) && !inp.lost.adc {
            self.motion.idle_check = None;
            let f = self.idle_faults(inp);
            if !f.is_empty() {
                // Not gripping, an arm stuck, a bolter caught: starting would drop the robot
                // or burn a motor (Section 7). The motion does not start.
                return f;
            }
            let r = Runner::start(self.cfg.motion, from, to, self.motion.targets, now);
            self.motion.targets = r.targets();
            self.motion.runner = Some(r);
        }
        Faults::EMPTY
    }

    /// One step of the reconfiguration runner; a failed primitive's fault is returned.
    fn step_runner(&mut self, now: u32, fb: &Feedback, out: &mut Outputs) -> Faults {
        let Some(mut r) = self.motion.runner else {
            return Faults::EMPTY;
        };
        match r.step(now, fb) {
            RunStatus::Running => {
                self.motion.targets = r.targets();
                self.motion.runner = Some(r);
            }
            RunStatus::Complete => {
                self.motion.targets = r.targets();
                self.tracked = Some(r.current_state());
                self.motion.runner = None;
                // Command complete waits for the idle check at the end.
                self.motion.idle_check = Some(IdleCheck::After);
                out.push(Event::Reached(r.current_state()));
            }
            RunStatus::Failed(f) => {
                self.tracked = None;
                self.motion.runner = None;
                return Faults::EMPTY.with(f);
            }
        }
        Faults::EMPTY
    }

    /// The idle check after a reconfiguration reached its target: once the robot is still,
    /// command complete, or the faults the check found.
    fn idle_check_after(&mut self, now: u32, inp: &Inputs) -> Faults {
        if self.motion.idle_check != Some(IdleCheck::After) || !self.at_rest(now) || inp.lost.adc {
            return Faults::EMPTY;
        }
        self.motion.idle_check = None;
        let f = self.idle_faults(inp);
        self.complete = f.is_empty();
        f
    }

    /// The deadline of a module motion with no step timeout of its own (spec/decisions.toml,
    /// `module-motion-deadline`): armed when the modules start moving towards their targets
    /// outside a primitive, a bolting job or a job waiting for board B, in any mode but Standby
    /// (nothing is driven there, and the robot may be moved by hand); when it passes, the
    /// motion stops where the modules are ([`BoardA::stop_all`]) and true is returned: the
    /// motion-timeout fault. A motion that was Stopped and Reset starts with a fresh budget.
    fn watch_modules(&mut self, now: u32, fb: &Feedback) -> bool {
        let modules = !fb.arm_done.all() || !fb.gripper_done.all() || !fb.hip_done;
        let own = modules && !self.motion.timed() && self.sup.mode() != Mode::Standby;
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
            servo(self.arm.now(), arm.resolve(self.motion.targets.arm.a)),
            servo(self.b.arm_b_now, arm.resolve(self.motion.targets.arm.b)),
            servo(
                self.gripper.now(),
                gripper.resolve(self.motion.targets.gripper.a),
            ),
            servo(
                self.b.gripper_b_now,
                gripper.resolve(self.motion.targets.gripper.b),
            ),
        ];
        let servos = servos.into_iter().max().unwrap_or(0);
        let hip = deadline::hip_ms(self.hip_seen, self.motion.targets.hip, self.cfg.hip.speed);
        deadline::budget_ms(&self.cfg.deadline, servos, hip)
    }

    /// A reconfiguration (or primitive) accepted: it starts after the idle check
    /// ([`IdleCheck::Before`]), in [`BoardA::advance`].
    pub(super) fn start_run(&mut self, from: State, to: State) {
        self.target_state = Some(to);
        self.complete = from == to;
        if from != to {
            self.motion.idle_check = Some(IdleCheck::Before { from, to });
        }
    }

    /// A Stop keeps the motion in progress for Reset.
    pub(super) fn pause(&mut self) {
        self.paused = Some(self.motion);
    }

    /// Reset: the motion a Stop interrupted goes on from the step where it stopped, with fresh
    /// step timeouts (the time stopped is no stall).
    pub(super) fn resume(&mut self, now: u32) {
        let Some(m) = self.paused.take() else { return };
        self.watch = Watch::Idle;
        self.motion = m;
        self.hold_b = false;
        self.motion.resume(now);
    }

    /// Every actuator holds where it is (Table 1's Stop, Table 7's Safed): the servos at their
    /// last interpolated pulse, the hip at its reading `hip`, the bolters idle, board B told to
    /// hold; the motion in progress ends (kept for Reset by [`BoardA::pause`] if a Stop
    /// interrupted it).
    pub(super) fn stop_all(&mut self, now: u32, hip: HipAngle) {
        self.side_a.order(0, None, now);
        self.motion.stop(Targets {
            arm: PerSide::new(
                ServoTarget::Position(self.arm.now()),
                ServoTarget::Position(self.b.arm_b_now),
            ),
            gripper: PerSide::new(
                ServoTarget::Position(self.gripper.now()),
                ServoTarget::Position(self.b.gripper_b_now),
            ),
            hip,
        });
        self.hold_b = true;
    }

    /// A command that moves side B lifts the hold: side B's targets become where B reports it
    /// held (so only what is commanded now moves).
    pub(super) fn release_b_hold(&mut self) {
        if self.hold_b {
            self.hold_b = false;
            self.motion.targets.arm.b = ServoTarget::Position(self.b.arm_b_now);
            self.motion.targets.gripper.b = ServoTarget::Position(self.b.gripper_b_now);
        }
    }

    /// Just entered Operational (the supervisor's `go_home`): the modules go home, contracted
    /// and gripping, and board B's hold is lifted.
    pub(super) fn go_home(&mut self) {
        self.watch = Watch::Idle;
        self.hold_b = false;
        self.motion.targets = Targets {
            hip: self.cfg.safety.hip_home,
            ..Targets::home()
        };
    }
}
