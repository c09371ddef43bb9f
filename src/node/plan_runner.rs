//! The opsUI's plan runner: a list of steps (commands and waits) driven through the
//! [`Uplink`], one command per 1.2 s slot, waiting for each motion to finish before the next
//! step.
//!
//! After a motion command (reconfiguration, primitive, bolting, a module move) is accepted,
//! the runner polls the robot with heartbeat requests until a heartbeat shows it settled
//! ([`settled`]). A step refused as `Busy` is sent again (as a new command) at the next slot;
//! any other refusal, or a command left unacknowledged, stops the plan with the reason.
//!
//! ```
//! use mmic::command::Command;
//! use mmic::mode::Mode;
//! use mmic::node::ground::{self, Outcome};
//! use mmic::node::plan_runner::{PlanEnd, PlanRunner, PlanStep};
//! use mmic::units::BoardNumber;
//! use mmic::wire::heartbeat::HeartbeatRepr;
//!
//! let steps = [PlanStep::Command(Command::Mode(Mode::Operational)), PlanStep::Wait { ms: 2000 }];
//! let mut run = PlanRunner::new(ground::Config::default(), BoardNumber::ONE);
//! let sent = run.tick(&steps, 0).send.unwrap();
//! let hb = HeartbeatRepr { last_seq: sent.seq, mode: Mode::Operational, ..HeartbeatRepr::default() };
//! assert_eq!(run.heartbeat(&steps, 50, &hb).done.unwrap().outcome, Outcome::Accepted);
//! let mut now = 50;
//! let end = loop {
//!     now += 100;
//!     let t = run.tick(&steps, now);
//!     if let Some(p) = t.send { // a heartbeat poll: answer it
//!         let hb = HeartbeatRepr { last_seq: p.seq, ..hb };
//!         run.heartbeat(&steps, now + 20, &hb);
//!     }
//!     if let Some(end) = t.end { break end; }
//! };
//! assert_eq!(end, PlanEnd::Completed);
//! assert!(now >= 2050);
//! ```

use super::ground::{self, Done, Outcome, Uplink};
use crate::command::{Command, CommandKind};
use crate::faults::Faults;
use crate::mode::Mode;
use crate::refusal::Refusal;
use crate::safety::detect::hip_distance;
use crate::units::BoardNumber;
use crate::units::Instant;
use crate::wire::command::CommandRepr;
use crate::wire::heartbeat::HeartbeatRepr;

/// A step of a plan.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum PlanStep {
    /// Send this command (and, if it moves something, wait for the motion to finish).
    Command(Command),
    /// Wait this long (the robot is polled meanwhile).
    Wait {
        /// Milliseconds.
        ms: u32,
    },
}

/// How a plan ended.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum PlanEnd {
    /// Every step done.
    Completed,
    /// Step `step` (0-based) was refused for this reason.
    Refused {
        /// The step.
        step: usize,
        /// Why.
        refusal: Refusal,
        /// The mode and latched faults in the refusing heartbeat: a refusal for the mode
        /// often has a fault behind it (a robot safed by a fault refuses the next motion).
        robot: Option<(Mode, Faults)>,
    },
    /// Step `step`'s command (or a poll during it) went unacknowledged.
    Unacknowledged {
        /// The step.
        step: usize,
    },
    /// Step `step`'s motion was cut short: the robot left Operational (a fault, or a mode
    /// command from elsewhere).
    Interrupted {
        /// The step.
        step: usize,
        /// The mode the robot reported.
        mode: Mode,
        /// Its latched faults.
        faults: Faults,
    },
}

/// What one call asks for or reports.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct PlanTick {
    /// Transmit this packet now.
    pub send: Option<CommandRepr>,
    /// An attempt closed: answered in time or not (Figure 11).
    pub attempt: Option<bool>,
    /// A command finished.
    pub done: Option<Done>,
    /// A step started (0-based).
    pub started: Option<usize>,
    /// The plan ended.
    pub end: Option<PlanEnd>,
}

#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
enum Phase {
    /// Ready for step `next`.
    Ready,
    /// Step `next`'s command is outstanding.
    Sending,
    /// Step `next`'s motion is running; polling. A settled answer counts once `polls`
    /// reaches `need` (a bolting job may start a tick late, after board B reports idle).
    Settling {
        polls: u16,
        need: u16,
        mode_step: bool,
    },
    /// Step `next` is a wait until this time.
    Waiting { until: u32 },
    /// Done.
    Ended(PlanEnd),
}

/// The runner.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct PlanRunner {
    up: Uplink,
    next: usize,
    phase: Phase,
    /// The outstanding command is a poll, not a step.
    polling: bool,
}

/// Does this command start something that must settle before the next step? Every command
/// that moves an actuator ([`CommandKind::moves`]), and a mode change too: entering
/// Operational drives the servos home, leaving it powers them down.
pub const fn settles_after(c: &Command) -> bool {
    c.kind().moves() || matches!(c.kind(), CommandKind::Mode)
}

/// The heartbeat shows no motion: the last reconfiguration complete (if any), no bolter
/// active, every servo at its target, the hip within 3° of its target.
pub fn settled(hb: &HeartbeatRepr) -> bool {
    (hb.target_state.is_none() || hb.command_complete)
        && hb.active_bolter.is_none()
        && hb.arm_a_now == hb.arm_a_target
        && hb.arm_b_now == hb.arm_b_target
        && hb.gripper_a_now == hb.gripper_a_target
        && hb.gripper_b_now == hb.gripper_b_target
        && hip_distance(hb.hip_now, hb.hip_target) <= 300
}

impl PlanRunner {
    /// At the first step.
    pub const fn new(cfg: ground::Config, board: BoardNumber) -> PlanRunner {
        PlanRunner {
            up: Uplink::new(cfg, board),
            next: 0,
            phase: Phase::Ready,
            polling: false,
        }
    }

    /// The uplink (efficiency, outstanding command).
    pub const fn uplink(&self) -> &Uplink {
        &self.up
    }

    /// The step being run (0-based; = steps.len() when completed).
    pub const fn step(&self) -> usize {
        self.next
    }

    /// The end, once reached.
    pub const fn end(&self) -> Option<PlanEnd> {
        match self.phase {
            Phase::Ended(e) => Some(e),
            _ => None,
        }
    }

    fn submit(&mut self, c: Command, polling: bool) {
        // Only called when the uplink is idle.
        if self.up.submit(c).is_ok() {
            self.polling = polling;
        }
    }

    /// Advances to `now`.
    pub fn tick(&mut self, steps: &[PlanStep], now: u32) -> PlanTick {
        let mut t = PlanTick::default();
        if self.up.is_idle() {
            match self.phase {
                Phase::Ready => match steps.get(self.next) {
                    None => self.phase = Phase::Ended(PlanEnd::Completed),
                    Some(PlanStep::Command(c)) => {
                        t.started = Some(self.next);
                        self.submit(*c, false);
                        self.phase = Phase::Sending;
                    }
                    Some(PlanStep::Wait { ms }) => {
                        t.started = Some(self.next);
                        self.phase = Phase::Waiting {
                            until: now.wrapping_add(*ms),
                        };
                    }
                },
                Phase::Waiting { until }
                    if Instant::from_millis(now)
                        .since(Instant::from_millis(until))
                        .millis()
                        > 0
                        || until == now =>
                {
                    self.next += 1;
                    self.phase = Phase::Ready;
                    return self.tick(steps, now);
                }
                Phase::Waiting { .. } | Phase::Settling { .. } => {
                    self.submit(Command::Heartbeat, true);
                }
                Phase::Sending | Phase::Ended(_) => {}
            }
        }
        let u = self.up.tick(now);
        t.send = u.send;
        t.attempt = u.attempt;
        if let Some(d) = u.done {
            t.done = Some(d);
            self.finished(d, None);
        }
        t.end = self.end();
        t
    }

    /// A heartbeat arrived at `now`.
    pub fn heartbeat(&mut self, steps: &[PlanStep], now: u32, hb: &HeartbeatRepr) -> PlanTick {
        let _ = steps;
        let mut t = PlanTick::default();
        let u = self.up.heartbeat(now, hb);
        t.attempt = u.attempt;
        if let Some(d) = u.done {
            t.done = Some(d);
            self.finished(d, Some(hb));
        }
        t.end = self.end();
        t
    }

    fn finished(&mut self, d: Done, hb: Option<&HeartbeatRepr>) {
        let step = self.next;
        match (self.phase, d.outcome) {
            (_, Outcome::Unacknowledged) => {
                self.phase = Phase::Ended(PlanEnd::Unacknowledged { step })
            }
            (Phase::Sending, Outcome::Refused(Refusal::Busy)) => self.phase = Phase::Ready,
            (Phase::Sending, Outcome::Refused(refusal)) => {
                self.phase = Phase::Ended(PlanEnd::Refused {
                    step,
                    refusal,
                    robot: hb.map(|h| (h.mode, h.faults)),
                })
            }
            (Phase::Sending, Outcome::Accepted) => {
                if settles_after(&d.command) {
                    let need = matches!(d.command.kind(), CommandKind::Bolter) as u16;
                    let mode_step = matches!(d.command.kind(), CommandKind::Mode);
                    self.phase = Phase::Settling {
                        polls: 0,
                        need,
                        mode_step,
                    };
                } else {
                    self.next += 1;
                    self.phase = Phase::Ready;
                }
            }
            (
                Phase::Settling {
                    polls,
                    need,
                    mode_step,
                },
                _,
            ) => {
                if let Some(h) = hb.filter(|h| !mode_step && h.mode != Mode::Operational) {
                    self.phase = Phase::Ended(PlanEnd::Interrupted {
                        step,
                        mode: h.mode,
                        faults: h.faults,
                    });
                } else if polls >= need && hb.is_some_and(settled) {
                    self.next += 1;
                    self.phase = Phase::Ready;
                } else {
                    self.phase = Phase::Settling {
                        polls: polls.saturating_add(1),
                        need,
                        mode_step,
                    };
                }
            }
            _ => {}
        }
        self.polling = false;
    }
}
