//! A plan as the opsUI writes it ([`PlanStep`]), how it ends ([`PlanEnd`]), what each tick
//! of the runner reports ([`PlanTick`]), and the judgements the runner makes of a command and
//! of a heartbeat.

use crate::command::Reconfiguration;
use crate::command::{Command, CommandKind};
use crate::faults::Faults;
use crate::mode::Mode;
use crate::motion::State;
use crate::node::exactly_once::uplink::Done;
use crate::refusal::Refusal;
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
    /// The ground restarted while step `step`'s command was outstanding or its motion ran
    /// ([`super::PlanRunner::restarted`]): its outcome is not known to the ground (it ran at
    /// most once). The operator looks at the robot before planning on.
    Restarted {
        /// The step.
        step: usize,
    },
    /// Step `step`'s telecommand (or an out-of-band one during it) was refused by the PUS
    /// gateway itself, not by board A (a failure code of spec/ccsds/services.toml that is no
    /// refusal: the request did not read, the queue was full, the key was reused).
    Rejected {
        /// The step.
        step: usize,
        /// The ST\[1\] failure code.
        code: u16,
    },
}

/// What one call asks for or reports.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct PlanTick<P = CommandRepr> {
    /// Transmit this packet now.
    pub send: Option<P>,
    /// An attempt closed: answered in time or not (Figure 11).
    pub attempt: Option<bool>,
    /// A command finished.
    pub done: Option<Done>,
    /// A step started (0-based).
    pub started: Option<usize>,
    /// The plan ended.
    pub end: Option<PlanEnd>,
}

impl<P> Default for PlanTick<P> {
    fn default() -> Self {
        PlanTick {
            send: None,
            attempt: None,
            done: None,
            started: None,
            end: None,
        }
    }
}

/// The same reconfiguration from a wrong initial state: the first matched state (Table 5
/// order) that is neither its initial nor its target state. A matched state is where a robot
/// rests between reconfigurations, so this is a belief the opsUI could plausibly hold — and
/// board A, which tracks the state it is in, refuses it (Table 8's initial state mismatch).
///
/// ```
/// use mmic::command::Reconfiguration;
/// use mmic::motion::State;
/// use mmic::node::ground::plan_runner::misstated;
/// let r = Reconfiguration::new(State::A, State::M).unwrap();
/// let wrong = misstated(r);
/// assert_eq!(wrong.target(), State::M);
/// assert!(wrong.initial() != State::A && wrong.initial().is_matched());
/// ```
pub fn misstated(r: Reconfiguration) -> Reconfiguration {
    State::ALL
        .into_iter()
        .filter(|s| s.is_matched() && *s != r.initial())
        .find_map(|s| Reconfiguration::new(s, r.target()).ok())
        // Six matched states: there is always one besides the initial and the target.
        .unwrap_or(r)
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
        && hb.hip_now.distance(hb.hip_target) <= 300
}
