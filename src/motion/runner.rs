//! A reconfiguration: its plan run primitive by primitive, tracking the current state.
//!
//! ```
//! use mmic::motion::runner::{Runner, RunStatus};
//! use mmic::motion::sequencer::{Config, Feedback, Targets};
//! use mmic::motion::State;
//! use mmic::units::PerSide;
//! let mut r = Runner::start(Config::default(), State::A, State::B, Targets::home(), 0);
//! assert_eq!(r.target_state(), State::B);
//! let all = Feedback { arm_done: PerSide::both(true), gripper_done: PerSide::both(true), hip_done: true, arm_switch: PerSide::both(true) };
//! let mut t = 0;
//! while r.status() == RunStatus::Running { t += 10; r.step(t, &all); }
//! assert_eq!(r.status(), RunStatus::Complete);
//! assert_eq!(r.current_state(), State::B);
//! assert!(r.command_complete());
//! ```
// req: P6.5, P6.4

use super::route::{lookup, Route};
use super::sequencer::{Config, Feedback, Sequencer, Status, Targets};
use crate::faults::Fault;
use crate::pose::State;

/// Where a reconfiguration is.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum RunStatus {
    /// A primitive is running.
    Running,
    /// The target state is reached.
    Complete,
    /// A primitive failed with this fault; the robot is in `current_state()` or between it and
    /// the next state of the plan.
    Failed(Fault),
}

/// Runs a reconfiguration plan.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Runner {
    cfg: Config,
    plan: Route,
    next: u8,
    current: State,
    target: State,
    seq: Option<Sequencer>,
    targets: Targets,
    status: RunStatus,
}

impl Runner {
    /// Starts the shortest plan from `from` (the tracked state) to `target` at time `now`.
    pub fn start(cfg: Config, from: State, target: State, targets: Targets, now: u32) -> Runner {
        let mut r = Runner {
            cfg,
            plan: lookup(from, target),
            next: 0,
            current: from,
            target,
            seq: None,
            targets,
            status: RunStatus::Running,
        };
        r.begin_next(now);
        r
    }

    fn begin_next(&mut self, now: u32) {
        match self.plan.states().get(usize::from(self.next)) {
            None => {
                self.seq = None;
                self.status = RunStatus::Complete;
            }
            Some(&to) => match Sequencer::start(self.cfg, self.current, to, self.targets, now) {
                Ok(s) => {
                    self.targets = s.targets();
                    self.seq = Some(s);
                }
                // Plans only contain map moves (checked exhaustively); refuse to move otherwise.
                Err(_) => self.status = RunStatus::Failed(Fault::InitialStateMismatch),
            },
        }
    }

    /// One tick.
    pub fn step(&mut self, now: u32, fb: &Feedback) -> RunStatus {
        if self.status != RunStatus::Running {
            return self.status;
        }
        let Some(seq) = self.seq.as_mut() else {
            return self.status;
        };
        let st = seq.step(now, fb);
        self.targets = seq.targets();
        match st {
            Status::Running => {}
            Status::Failed(f) => self.status = RunStatus::Failed(f),
            Status::Done => {
                self.current = seq.target_state();
                // At most the plan's length (≤ 3): never saturates.
                self.next = self.next.saturating_add(1);
                self.begin_next(now);
            }
        }
        self.status
    }

    /// Resumes at `now` after a pause: the running primitive re-issues its current step with a
    /// fresh timeout ([`Sequencer::resume`]).
    pub fn resume(&mut self, now: u32) {
        if let Some(s) = self.seq.as_mut() {
            s.resume(now);
            self.targets = s.targets();
        }
    }

    /// Status.
    pub const fn status(&self) -> RunStatus {
        self.status
    }

    /// The last state fully reached.
    pub const fn current_state(&self) -> State {
        self.current
    }

    /// The commanded target state (heartbeat byte 53).
    pub const fn target_state(&self) -> State {
        self.target
    }

    /// Heartbeat byte 54.
    pub const fn command_complete(&self) -> bool {
        matches!(self.status, RunStatus::Complete)
    }

    /// Module targets to apply now.
    pub const fn targets(&self) -> Targets {
        self.targets
    }

    /// The plan being run.
    pub const fn plan(&self) -> &Route {
        &self.plan
    }

    /// The primitive running now, if any.
    pub fn running(&self) -> Option<&Sequencer> {
        self.seq
            .as_ref()
            .filter(|_| self.status == RunStatus::Running)
    }
}
