//! Primitive execution: a primitive as a sequence of module steps, run by a state machine that
//! hands module targets to sides A and B and waits for completion signals, with a timeout per
//! step that raises a fault (Table 8's "Arm not fully contracted" for an unsensed contraction,
//! the project's motion timeout otherwise) and then issues nothing more.
//!
//! Steps of one primitive, for the moving side S (A for fwd, B for back), the other side O
//! holding its face throughout:
//!
//! 1. **Release** S's gripper (gripper S → contract); wait until S's gripper reports done.
//! 2. **Move**: into a two-face state S's arm extends; into a matched state both arms contract
//!    (the robot ends contracted on one face; O's arm contracting while O grips carries the hip
//!    towards O's face). In a turn the hip also goes to the angle of the target state's shape
//!    ([`hip_goal`]): 180° when the arms end in line, 90° (CW) or 270° (CCW) when they end at a
//!    right angle. Wait for the arms and, in a turn, the hip in tolerance.
//! 3. **Confirm** (only into a matched state): wait for both arm-contracted switches.
//! 4. **Grip** S's gripper (gripper S → extend); wait until done.
//!
//! Only S's gripper is ever opened, and only after O's is closed, so the robot always holds the
//! structure with at least one closed gripper (checked exhaustively in `tests/motion/motion_sequencer.rs`).
//!
//! ```
//! use mmic::motion::sequencer::{Config, Feedback, Sequencer, Status, Targets};
//! use mmic::motion::State;
//! use mmic::units::PerSide;
//! let mut s = Sequencer::start(Config::default(), State::A, State::D, Targets::home(), 0).unwrap();
//! assert_eq!(s.step(10, &Feedback::default()), Status::Running); // waits for the release
//! let all = Feedback { arm_done: PerSide::both(true), gripper_done: PerSide::both(true), hip_done: true, arm_switch: PerSide::both(false) };
//! let mut t = 10;
//! while s.status() == Status::Running { t += 10; s.step(t, &all); }
//! assert_eq!(s.status(), Status::Done);
//! ```
// req: P6.5, P6.6

use crate::command::{preset_angle, HipTarget, ServoTarget};
use crate::faults::Fault;
use crate::pose::geometry::robot_move;
use crate::pose::{Primitive, State};
use crate::units::{HipAngle, Instant, PerSide, Side};

/// Per-step timeouts, ms.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Config {
    /// Release or grip: the gripper's interpolation. Default 3000 ms.
    pub gripper_ms: u32,
    /// Move: arm interpolation and a 90° hip turn at 10°/s (9 s). Default 15000 ms.
    pub move_ms: u32,
    /// Confirm: the arm-contracted switch after a contraction. Default 1000 ms.
    pub confirm_ms: u32,
}

impl Default for Config {
    fn default() -> Config {
        Config {
            gripper_ms: 3000,
            move_ms: 15000,
            confirm_ms: 1000,
        }
    }
}

/// Targets for every module; index 0 = side A, 1 = side B.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Targets {
    /// Arm targets.
    pub arm: PerSide<ServoTarget>,
    /// Gripper targets: `Extend` = closed on a face, `Contract` = released.
    pub gripper: PerSide<ServoTarget>,
    /// Hip target.
    pub hip: HipAngle,
}

impl Targets {
    /// Contracted and gripped, hip straight: the home position of a matched state.
    pub const fn home() -> Targets {
        Targets {
            arm: PerSide::both(ServoTarget::Contract),
            gripper: PerSide::both(ServoTarget::Extend),
            hip: HipAngle::STRAIGHT,
        }
    }

    /// Whether at least one gripper is commanded closed.
    pub const fn holds(&self) -> bool {
        matches!(self.gripper.a, ServoTarget::Extend)
            || matches!(self.gripper.b, ServoTarget::Extend)
    }
}

/// Completion signals, as of this tick.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Default)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Feedback {
    /// Arm interpolation finished (A: local; B: reported in the internal heartbeat).
    pub arm_done: PerSide<bool>,
    /// Gripper interpolation finished.
    pub gripper_done: PerSide<bool>,
    /// Hip within tolerance of its target.
    pub hip_done: bool,
    /// Arm-contracted switch pressed.
    pub arm_switch: PerSide<bool>,
}

/// A step of a primitive.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum Step {
    /// Open the moving side's gripper.
    Release,
    /// Move the arm (and the hip in a turn).
    Move,
    /// Check the arm-contracted switch.
    Confirm,
    /// Close the moving side's gripper.
    Grip,
}

/// Where a sequencer is.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum Status {
    /// Waiting for the current step.
    Running,
    /// The primitive completed: the robot is in the target state.
    Done,
    /// A step timed out: this fault is raised and no further step is issued.
    Failed(Fault),
}

/// `from → to` is not a single-primitive move.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, thiserror::Error)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
#[error("no single primitive of the robot takes {from} to {to} (Figure 9)")]
pub struct NotAMove {
    /// Initial state.
    pub from: State,
    /// Target state.
    pub to: State,
}

/// The hip angle a turn primitive drives to, from the shapes of its two states: `None` when the
/// hip does not move.
///
/// The hip angle is the angle from arm A to arm B about the hip axis: 180° with the arms in
/// line, 90° or 270° at a right angle (the two signs of the hip axis; spec/motion/estimation.md).
/// So the goal is absolute, not the current angle ± 90°: a plan that turns twice the same way in
/// the structure frame (a → e → n: B CCW, then A CCW) folds back to 180°, where adding +90° twice
/// would have left the hip at 0°, a pose no state has.
///
/// - straight primitives (1–4): `None`. So is a turn from one right-angle state to another
///   (e → k: A would swing from −X to −Z about B's arm, +Y), which no hip rotation makes: no
///   move of the robot ([`crate::pose::geometry::turns_without_hip`]), and [`Sequencer::start`]
///   refuses it;
/// - into a state with the arms in line (matched, stretch): [`HipTarget::Straight`], 180°;
/// - from arms in line into a right angle: [`HipTarget::RightAngleCw`] (90°) for a CW
///   primitive, [`HipTarget::RightAngleCcw`] (270°) for a CCW one. Either sign is a valid pose
///   of the state (the hip axis is free while the arms are in line); naming it after the
///   primitive keeps the choice deterministic.
pub fn hip_goal(from: State, to: State, primitive: Primitive) -> Option<HipAngle> {
    let in_line = |s: State| !matches!(s.kind(), crate::pose::StateKind::Turn);
    let target = match primitive {
        Primitive::FwdContract
        | Primitive::BackContract
        | Primitive::FwdExtend
        | Primitive::BackExtend => return None,
        _ if in_line(to) => HipTarget::Straight,
        _ if !in_line(from) => return None,
        Primitive::FwdTurnCw | Primitive::BackTurnCw => HipTarget::RightAngleCw,
        Primitive::FwdTurnCcw | Primitive::BackTurnCcw => HipTarget::RightAngleCcw,
    };
    preset_angle(target)
}

/// Runs one primitive.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Sequencer {
    cfg: Config,
    primitive: Primitive,
    side: Side,
    from: State,
    to: State,
    steps: [Step; 4],
    n_steps: u8,
    at: u8,
    last: Instant,
    waited_ms: u32,
    targets: Targets,
    status: Status,
}

impl Sequencer {
    /// Starts the primitive taking `from` to `to` at time `now` (ms), from the current module
    /// targets. The first step is issued at once.
    pub fn start(
        cfg: Config,
        from: State,
        to: State,
        targets: Targets,
        now: u32,
    ) -> Result<Sequencer, NotAMove> {
        let (side, primitive) = robot_move(from, to).ok_or(NotAMove { from, to })?;
        let contracting = to.is_matched();
        let (steps, n) = if contracting {
            ([Step::Release, Step::Move, Step::Confirm, Step::Grip], 4)
        } else {
            ([Step::Release, Step::Move, Step::Grip, Step::Grip], 3)
        };
        let mut s = Sequencer {
            cfg,
            primitive,
            side,
            from,
            to,
            steps,
            n_steps: n,
            at: 0,
            last: Instant::from_millis(now),
            waited_ms: 0,
            targets,
            status: Status::Running,
        };
        s.issue();
        Ok(s)
    }

    /// The primitive being run.
    pub const fn primitive(&self) -> Primitive {
        self.primitive
    }

    /// The side that moves.
    pub const fn side(&self) -> Side {
        self.side
    }

    /// The state the primitive ends in.
    pub const fn target_state(&self) -> State {
        self.to
    }

    /// Current status.
    pub const fn status(&self) -> Status {
        self.status
    }

    /// The current step while running.
    pub fn current_step(&self) -> Option<Step> {
        match self.status {
            Status::Running => self.steps.get(usize::from(self.at)).copied(),
            _ => None,
        }
    }

    /// The module targets to apply now.
    pub const fn targets(&self) -> Targets {
        self.targets
    }

    /// Sets the targets of the current step.
    fn issue(&mut self) {
        let s = self.side;
        match self.steps.get(usize::from(self.at)) {
            Some(Step::Release) => self.targets.gripper[s] = ServoTarget::Contract,
            Some(Step::Move) => {
                if self.to.is_matched() {
                    self.targets.arm = PerSide::both(ServoTarget::Contract);
                } else {
                    self.targets.arm[s] = ServoTarget::Extend;
                }
                if let Some(a) = hip_goal(self.from, self.to, self.primitive) {
                    self.targets.hip = a;
                }
            }
            Some(Step::Grip) => self.targets.gripper[s] = ServoTarget::Extend,
            Some(Step::Confirm) | None => {}
        }
    }

    /// Resumes at `now` after a pause (a Stop, then Reset): the current step is issued again
    /// and its timeout counts afresh, so the time spent stopped is no stall.
    pub fn resume(&mut self, now: u32) {
        self.last = Instant::from_millis(now);
        self.waited_ms = 0;
        if self.status == Status::Running {
            self.issue();
        }
    }

    fn is_turn(&self) -> bool {
        self.primitive.number() >= 5
    }

    /// One tick at time `now` (ms, wrapping) with this tick's feedback.
    pub fn step(&mut self, now: u32, fb: &Feedback) -> Status {
        if self.status != Status::Running {
            return self.status;
        }
        let t = Instant::from_millis(now);
        self.waited_ms = self.waited_ms.saturating_add(t.since(self.last).millis());
        self.last = t;
        let s = self.side;
        let step = match self.steps.get(usize::from(self.at)) {
            Some(st) => *st,
            None => {
                self.status = Status::Done;
                return self.status;
            }
        };
        let (done, limit) = match step {
            Step::Release | Step::Grip => (fb.gripper_done[s], self.cfg.gripper_ms),
            Step::Move => {
                let arms = if self.to.is_matched() {
                    fb.arm_done.all()
                } else {
                    fb.arm_done[s]
                };
                (arms && (!self.is_turn() || fb.hip_done), self.cfg.move_ms)
            }
            Step::Confirm => (fb.arm_switch.all(), self.cfg.confirm_ms),
        };
        if done {
            // Below `n_steps` (≤ 4) before: never saturates.
            self.at = self.at.saturating_add(1);
            self.waited_ms = 0;
            if self.at >= self.n_steps {
                self.status = Status::Done;
            } else {
                self.issue();
            }
        } else if self.waited_ms > limit {
            self.status = Status::Failed(self.timeout_fault(step, fb));
        }
        self.status
    }

    /// The fault a timed-out step raises (spec/motion/sequencer.md): a Table 8 fault only when
    /// its trigger holds — a contraction the switch did not sense is "Arm not fully
    /// contracted" — and otherwise the project's [`Fault::MotionTimeout`]. A hip turn that does
    /// not end is not "Hip mismatch" (Table 8 checks the hip only when Operational is
    /// entered), a stall is not an overcurrent unless a current reading says so (the
    /// overcurrent checks raise those on their own), and side B's servos not reporting done
    /// is not a communication loss while B's heartbeats and acknowledgements arrive (the
    /// communication monitor raises that on its own).
    fn timeout_fault(&self, step: Step, _fb: &Feedback) -> Fault {
        match step {
            Step::Confirm => Fault::ArmNotContracted,
            Step::Release | Step::Move | Step::Grip => Fault::MotionTimeout,
        }
    }
}
