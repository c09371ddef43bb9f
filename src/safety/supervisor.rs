//! The mode and fault supervisor: Table 7's modes and Table 8's fault reactions as one pure
//! state machine, stepped once per control tick.
//!
//! Each step takes the faults detected in this tick (conditions holding now, from
//! [`detect`](super::detect), plus events such as a failed bolting run), the command received
//! (if any), and whether a motion is running; it returns the mode, what is powered, the latched
//! faults, and the answer to the command. Faults are handled before the command, so a command
//! never acts on a stale view of the robot.
//!
//! ```
//! use mmic::command::Command;
//! use mmic::faults::{Fault, Faults};
//! use mmic::mode::Mode;
//! use mmic::safety::supervisor::{Answer, Incoming, Input, Supervisor};
//!
//! let mut s = Supervisor::new();
//! assert_eq!(s.mode(), Mode::Standby); // startup
//! let out = s.step(&Input { command: Some(Incoming::Command(Command::Mode(Mode::Operational))), ..Input::quiet() });
//! assert_eq!(out.mode, Mode::Operational);
//! assert!(out.go_home);
//!
//! // Low battery during a motion: latched at once, Standby only when the motion completes.
//! let lb = Faults::EMPTY.with(Fault::LowBattery);
//! let out = s.step(&Input { faults: lb, in_motion: true, ..Input::quiet() });
//! assert_eq!(out.mode, Mode::Operational);
//! assert!(out.faults.contains(Fault::LowBattery));
//! let out = s.step(&Input { faults: lb, in_motion: false, ..Input::quiet() });
//! assert_eq!(out.mode, Mode::Standby);
//! assert!(out.powered.is_empty() && !out.regulator);
//!
//! // Operational is refused while the condition still holds, with the reason.
//! let out = s.step(&Input { faults: lb, command: Some(Incoming::Command(Command::Mode(Mode::Operational))), ..Input::quiet() });
//! assert_eq!(out.answer, Some(Answer::Refused(mmic::refusal::Refusal::FaultConditionHolds)));
//! ```
// req: P7.2, P7.7, P7.12, P7.13

use super::module_set::ModuleSet;
use super::policy::{accepts, fault_action, is_condition, powered, regulator_on};
use crate::command::{Command, PowerTarget};
use crate::faults::{Fault, Faults};
use crate::mode::Mode;
use crate::motion::estimate::InitialStateError;
use crate::refusal::Refusal;

/// What reached the supervisor from the command link in this tick.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum Incoming {
    /// A well-formed command.
    Command(Command),
    /// A packet whose header and checksum held but whose fields did not decode.
    Malformed(Refusal),
}

/// One tick's inputs.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Input {
    /// Faults detected in this tick: conditions holding now and events raised now.
    pub faults: Faults,
    /// The command received in this tick, if any.
    pub command: Option<Incoming>,
    /// A motion (primitive, reconfiguration, bolting run, single-module move) is in progress.
    pub in_motion: bool,
    /// The hip reads within tolerance of its home angle ([`detect::hip_at_home`](super::detect::hip_at_home));
    /// consulted when entering Operational.
    pub hip_at_home: bool,
    /// A reconfiguration command's check on arrival
    /// ([`check_reconfiguration`](crate::motion::estimate::check_reconfiguration)): its arms
    /// sense the contraction commanded and its initial state agrees with the detected state, or
    /// the Table 8 fault it met; consulted for reconfiguration commands.
    pub initial_state: Result<(), InitialStateError>,
}

impl Input {
    /// No fault, no command, no motion, hip at home, arms and states agree.
    pub const fn quiet() -> Input {
        Input {
            faults: Faults::EMPTY,
            command: None,
            in_motion: false,
            hip_at_home: true,
            initial_state: Ok(()),
        }
    }
}

/// The answer to a command, reported in the heartbeat that follows it.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum Answer {
    /// Accepted: the motion and module layers execute it.
    Accepted(Command),
    /// Refused, with the reason.
    Refused(Refusal),
}

impl Answer {
    /// The refusal code for the heartbeat (none when accepted).
    pub const fn refusal(&self) -> Option<Refusal> {
        match self {
            Answer::Accepted(_) => None,
            Answer::Refused(r) => Some(*r),
        }
    }
}

/// One tick's outputs.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Output {
    /// Mode after this tick.
    pub mode: Mode,
    /// Modules that must be powered.
    pub powered: ModuleSet,
    /// The 7.4 V regulator.
    pub regulator: bool,
    /// Latched faults (heartbeat bytes 60–61).
    pub faults: Faults,
    /// The answer to this tick's command, if one came.
    pub answer: Option<Answer>,
    /// Just entered Operational: send the actuators home (contracted, gripped).
    pub go_home: bool,
    /// Hold every actuator where it is now (Stop command, or the mode changed). Whether the
    /// interrupted motion is kept for [`Reset`](Command::Reset) is [`Supervisor::stopped`]
    /// after the step: kept while it holds, discarded otherwise.
    pub stop_motion: bool,
    /// Reset accepted: resume the motion the last Stop interrupted.
    pub resume: bool,
    /// A deferred fault waits for the running motion to complete.
    pub standby_pending: bool,
}

/// The supervisor's state.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Supervisor {
    mode: Mode,
    enabled: ModuleSet,
    latched: Faults,
    standby_pending: bool,
    stopped: bool,
}

impl Default for Supervisor {
    fn default() -> Self {
        Self::new()
    }
}

impl Supervisor {
    /// Startup: Standby, every module enabled for when Operational is entered, no fault.
    pub const fn new() -> Supervisor {
        Supervisor {
            mode: Mode::Standby,
            enabled: ModuleSet::ALL,
            latched: Faults::EMPTY,
            standby_pending: false,
            stopped: false,
        }
    }

    /// Current mode.
    pub const fn mode(&self) -> Mode {
        self.mode
    }

    /// Latched faults.
    pub const fn faults(&self) -> Faults {
        self.latched
    }

    /// Modules enabled by Power Control commands.
    pub const fn enabled(&self) -> ModuleSet {
        self.enabled
    }

    /// Whether a Stop interrupted a motion that waits for Reset (Table 1: "After a stop
    /// command, resume motion"). While it holds, commands that move are refused with
    /// [`Refusal::Stopped`]; a mode change discards the interrupted motion and clears it.
    pub const fn stopped(&self) -> bool {
        self.stopped
    }

    /// Whether a deferred fault waits for the running motion to complete.
    pub const fn standby_pending(&self) -> bool {
        self.standby_pending
    }

    fn enter(&mut self, mode: Mode, stop: &mut bool) {
        if self.mode != mode {
            // Whatever moved in the old mode stops here; a motion a Stop interrupted is not
            // resumed in another mode.
            *stop = true;
            self.stopped = false;
        }
        if self.mode == Mode::Operational && mode != Mode::Operational {
            self.standby_pending = false;
        }
        self.mode = mode;
    }

    /// Raises `faults`: latches them and, from Operational only, applies Table 8.
    fn raise(&mut self, faults: Faults, in_motion: bool, stop: &mut bool) {
        self.latched = self.latched.union(faults);
        if self.mode != Mode::Operational || faults.is_empty() {
            return;
        }
        let (mut safed, mut standby, mut deferred) = (false, false, false);
        for f in faults.iter() {
            let a = fault_action(f);
            match (a.mode, a.deferred) {
                (Mode::Safed, _) => safed = true,
                (_, true) => deferred = true,
                _ => standby = true,
            }
        }
        // Precedence: Safed (hold hip and arms) over Standby, immediate over deferred.
        if safed {
            self.enter(Mode::Safed, stop);
        } else if standby || (deferred && !in_motion) {
            self.enter(Mode::Standby, stop);
        } else if deferred {
            self.standby_pending = true;
        }
    }

    /// One tick.
    pub fn step(&mut self, input: &Input) -> Output {
        let mut stop = false;
        let mut go_home = false;
        let mut resume = false;
        let mode_before = self.mode;
        self.raise(input.faults, input.in_motion, &mut stop);
        if self.standby_pending && !input.in_motion && self.mode == Mode::Operational {
            self.enter(Mode::Standby, &mut stop);
        }
        let answer = input.command.map(|c| {
            // A motion is still in progress for the command only if no fault this tick
            // changed the mode (which stopped it for good).
            let moving = input.in_motion && self.mode == mode_before;
            self.command(c, input, moving, &mut stop, &mut go_home, &mut resume)
        });
        let powered = powered(self.mode, self.enabled);
        Output {
            mode: self.mode,
            powered,
            regulator: regulator_on(self.mode) && !powered.is_empty(),
            faults: self.latched,
            answer,
            go_home,
            stop_motion: stop,
            resume,
            standby_pending: self.standby_pending,
        }
    }

    /// One command of this tick, admitted ([`Supervisor::admit`]) and obeyed: its answer; what
    /// it asks of the motion (stop, go home, resume) through the flags.
    fn command(
        &mut self,
        incoming: Incoming,
        input: &Input,
        moving: bool,
        stop: &mut bool,
        go_home: &mut bool,
        resume: &mut bool,
    ) -> Answer {
        let cmd = match self.admit(incoming) {
            Ok(c) => c,
            Err(r) => return Answer::Refused(r),
        };
        match cmd {
            Command::Stop => {
                // Every actuator holds; a motion in progress waits for Reset. A second Stop
                // keeps the first one's interrupted motion.
                // (Nothing moves in Standby, whatever the flag says: nothing to keep there.)
                self.stopped |= moving && self.mode != Mode::Standby;
                *stop = true;
            }
            Command::Reset if !self.stopped => return Answer::Refused(Refusal::NothingToResume),
            Command::Reset => {
                self.stopped = false;
                *resume = true;
            }
            Command::SystemFault => self.raise(
                Faults::EMPTY.with(Fault::AssemblySystem),
                input.in_motion,
                stop,
            ),
            Command::ClearFaults => {
                // Only faults that no longer hold are cleared: conditions holding now and events
                // raised in this very tick stay latched.
                self.latched =
                    Faults::from_iter(self.latched.iter().filter(|f| input.faults.contains(*f)));
            }
            Command::Mode(Mode::Operational) if self.mode != Mode::Operational => {
                if let Err(r) = self.enter_operational(input, stop, go_home) {
                    return Answer::Refused(r);
                }
            }
            Command::Mode(m) => self.enter(m, stop),
            Command::Reconfigure(_) => {
                // Table 8 on arrival: an arm not sensed contracted (Safed) or an initial state
                // mismatch (Standby), latched and answered by name.
                if let Err(e) = input.initial_state {
                    self.raise(Faults::EMPTY.with(e.fault()), input.in_motion, stop);
                    return Answer::Refused(e.refusal());
                }
            }
            Command::Power { target, on } => self.switch(target, on),
            _ => {}
        }
        Answer::Accepted(cmd)
    }

    /// The command `incoming` is, if it is one, the present mode accepts its kind (Table 7),
    /// and no Stop holds the motion it asks for; otherwise the refusal, before anything
    /// changes.
    #[inline]
    fn admit(&self, incoming: Incoming) -> Result<Command, Refusal> {
        let cmd = match incoming {
            Incoming::Command(c) => c,
            Incoming::Malformed(r) => return Err(r),
        };
        let kind = cmd.kind();
        if !accepts(self.mode, kind) {
            return Err(Refusal::NotAllowedInMode);
        }
        if self.stopped && kind.moves() {
            return Err(Refusal::Stopped);
        }
        Ok(cmd)
    }

    /// A mode command to Operational from another mode: refused while a fault condition
    /// holds (Table 7); otherwise every module enabled and the servos sent home, or, with the
    /// hip away from home, the hip mismatch fault raised (Table 8).
    fn enter_operational(
        &mut self,
        input: &Input,
        stop: &mut bool,
        go_home: &mut bool,
    ) -> Result<(), Refusal> {
        if input.faults.iter().any(is_condition) {
            return Err(Refusal::FaultConditionHolds);
        }
        self.enter(Mode::Operational, stop);
        self.enabled = ModuleSet::ALL;
        if input.hip_at_home {
            *go_home = true;
        } else {
            self.raise(
                Faults::EMPTY.with(Fault::HipMismatch),
                input.in_motion,
                stop,
            );
        }
        Ok(())
    }

    /// A power command: the modules the operator enables (Table 7 powers them by mode).
    fn switch(&mut self, target: PowerTarget, on: bool) {
        self.enabled = match (target, on) {
            (PowerTarget::All, true) => ModuleSet::ALL,
            (PowerTarget::All, false) => ModuleSet::EMPTY,
            (PowerTarget::Module(m), true) => self.enabled.with(m),
            (PowerTarget::Module(m), false) => self.enabled.without(m),
        };
    }
}
