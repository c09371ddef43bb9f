//! The opsUI's plan runner: a list of steps (commands and waits) driven through the
//! [`Uplink`], one command per 1.2 s slot, waiting for each motion to finish before the next
//! step.
//!
//! After a motion command (reconfiguration, primitive, bolting, a module move) is accepted,
//! the runner polls the robot with heartbeat requests until a heartbeat shows it settled
//! ([`settled`]). A step refused as `Busy` is sent again (as a new command) at the next slot;
//! any other refusal, or a command left unacknowledged, stops the plan with the reason.
//!
//! The operator can also act out of band ([`PlanRunner::interject`]): a Stop, a Reset, the
//! System fault command (Table 1) goes out in the next free slot, ahead of the plan's next
//! step and of polling, through the same uplink — so one command is outstanding at a time
//! and every command keeps its own sequence number, exactly once. An accepted Stop holds the
//! plan (no step is started or finished) until an accepted Reset.
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
pub use super::ground_link::{Link, LinkTick, MotionEnd};
use super::pus_ground::{self, TcLink, TcOut};
use crate::command::Reconfiguration;
use crate::command::{Command, CommandKind};
use crate::faults::Faults;
use crate::mode::Mode;
use crate::motion::State;
use crate::refusal::Refusal;
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

#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
enum Phase {
    /// Ready for step `next`.
    Ready,
    /// Step `next`'s command is outstanding.
    Sending,
    /// Step `next`'s motion is running; polling. A settled answer counts once `polls`
    /// reaches `need` (a bolting job may start a tick late, after board B reports idle).
    /// Over a link that reports motions' ends: `ended` once its end came (a mode step's at
    /// once), and the step is done then (a mode step: at the first settled status after it),
    /// unless a Stop holds the plan.
    Settling {
        polls: u16,
        need: u16,
        mode_step: bool,
        ended: bool,
    },
    /// Step `next` is a wait until this time.
    Waiting { until: u32 },
    /// Done.
    Ended(PlanEnd),
}

/// What the outstanding command is to the runner.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
enum Sent {
    /// Step `next`'s command.
    Step,
    /// A heartbeat request while a motion settles or a wait runs.
    Poll,
    /// An out-of-band command ([`PlanRunner::interject`]).
    Interjection,
}

/// Out-of-band commands that may wait for a slot at once ([`PlanRunner::interject`]): an
/// operator's Stop and Reset and a System fault fit with room to spare.
pub const INTERJECTIONS: usize = 4;

/// [`PlanRunner::interject`] did not take the command: it is handed back, never dropped.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, thiserror::Error)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum InterjectError {
    /// [`INTERJECTIONS`] commands already wait for a slot.
    #[error("{waiting} out-of-band commands already wait for a slot; {command:?} not taken")]
    Full {
        /// The command not taken.
        command: Command,
        /// How many wait.
        waiting: usize,
    },
    /// The plan has ended, so nothing is sent any more.
    #[error("the plan has ended ({end:?}); {command:?} not taken")]
    Ended {
        /// The command not taken.
        command: Command,
        /// How the plan ended.
        end: PlanEnd,
    },
}

/// The runner, over the legacy [`Uplink`] or another [`Link`].
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct PlanRunner<L = Uplink> {
    up: L,
    next: usize,
    /// The number of the current step's command, once submitted.
    step_seq: Option<u16>,
    phase: Phase,
    /// What the outstanding command is.
    sent: Sent,
    /// Out-of-band commands waiting for a slot, oldest first (filled from index 0).
    pending: [Option<Command>; INTERJECTIONS],
    /// An interjected Stop was accepted and no Reset since: the plan waits.
    held: bool,
    /// The next reconfiguration step goes out misstated ([`misstated`]).
    misstate: bool,
}

/// The same reconfiguration from a wrong initial state: the first matched state (Table 5
/// order) that is neither its initial nor its target state. A matched state is where a robot
/// rests between reconfigurations, so this is a belief the opsUI could plausibly hold — and
/// board A, which tracks the state it is in, refuses it (Table 8's initial state mismatch).
///
/// ```
/// use mmic::command::Reconfiguration;
/// use mmic::motion::State;
/// use mmic::node::plan_runner::misstated;
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

impl PlanRunner {
    /// At the first step, over the legacy uplink.
    pub const fn new(cfg: ground::Config, board: BoardNumber) -> PlanRunner {
        PlanRunner::over(Uplink::new(cfg, board))
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
}

impl PlanRunner<TcLink> {
    /// At the first step, over PUS: telecommands to robot `board`'s APID through the gateway.
    pub fn pus(cfg: pus_ground::Config, board: BoardNumber) -> PlanRunner<TcLink> {
        PlanRunner::over(TcLink::new(cfg, board))
    }

    /// A telemetry packet arrived at `now` (its CCSDS headers checked by the caller): its
    /// service, subservice and source data. ST\[1\] reports start and end the plan's commands
    /// ([`TcLink::telemetry`]); a housekeeping report settles a mode step.
    pub fn telemetry(
        &mut self,
        steps: &[PlanStep],
        now: u32,
        service: u8,
        subservice: u8,
        data: &[u8],
    ) -> PlanTick<TcOut> {
        let _ = (steps, now);
        let mut t = PlanTick::default();
        let h = self.up.telemetry(service, subservice, data);
        t.attempt = h.attempt;
        let status = self.up.status();
        if let Some(d) = h.done {
            t.done = Some(d);
            self.finished(d, status.as_ref());
        }
        if let Some((seq, _)) = h.rejected {
            if self.end().is_none() && self.up.is_idle() && self.is_ours(seq) {
                self.sent = Sent::Step;
                self.phase = Phase::Ended(PlanEnd::Rejected {
                    step: self.next,
                    code: h.rejected.map_or(0, |(_, f)| f.code),
                });
            }
        }
        if let Some((seq, e)) = h.ended {
            self.motion_ended(seq, e);
        }
        if let (
            Some(hb),
            Phase::Settling {
                mode_step: true,
                ended: true,
                ..
            },
        ) = (h.status, self.phase)
        {
            if !self.held && settled(&hb) {
                self.next += 1;
                self.phase = Phase::Ready;
            }
        }
        t.end = self.end();
        t
    }

    /// Whether the telecommand numbered `seq` is one the runner sent last (its step's or an
    /// interjection's).
    fn is_ours(&self, seq: u16) -> bool {
        self.step_seq == Some(seq) || self.sent == Sent::Interjection
    }
}

impl<L: Link> PlanRunner<L> {
    /// At the first step, over `link`.
    pub const fn over(link: L) -> PlanRunner<L> {
        PlanRunner {
            up: link,
            next: 0,
            step_seq: None,
            phase: Phase::Ready,
            sent: Sent::Step,
            pending: [None; INTERJECTIONS],
            held: false,
            misstate: false,
        }
    }

    /// The link (efficiency, outstanding command).
    pub const fn uplink(&self) -> &L {
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

    /// Sends `command` out of band: in the next free slot of the uplink, ahead of the plan's
    /// next step and of polling (after the command outstanding now, if any, and after those
    /// interjected before it). It gets its own sequence number and is resent until answered
    /// like any command; its answer does not advance the plan. An accepted Stop holds the
    /// plan — no step starts, no motion counts as settled — until an accepted Reset; an
    /// interjection left unacknowledged ends the plan as [`PlanEnd::Unacknowledged`] (the
    /// link is gone). Refused, with the command handed back, when [`INTERJECTIONS`] wait
    /// already or the plan has ended.
    pub fn interject(&mut self, command: Command) -> Result<(), InterjectError> {
        if let Some(end) = self.end() {
            return Err(InterjectError::Ended { command, end });
        }
        match self.pending.iter_mut().find(|p| p.is_none()) {
            Some(slot) => {
                *slot = Some(command);
                Ok(())
            }
            None => Err(InterjectError::Full {
                command,
                waiting: INTERJECTIONS,
            }),
        }
    }

    /// Out-of-band commands waiting for a slot.
    pub fn interjections_waiting(&self) -> usize {
        self.pending.iter().filter(|p| p.is_some()).count()
    }

    /// An accepted out-of-band Stop holds the plan (until an accepted Reset).
    pub const fn held(&self) -> bool {
        self.held
    }

    /// Fault injection for Table 8's initial state mismatch: the next reconfiguration step
    /// the runner sends goes out with a wrong initial state ([`misstated`]), as if the
    /// opsUI's belief of where the robot is were wrong. A step already sent keeps its command
    /// (a resend carries the same bytes).
    pub fn misstate_next_reconfiguration(&mut self) {
        self.misstate = true;
    }

    fn submit(&mut self, c: Command, sent: Sent) {
        // Only called when the uplink is idle.
        if let Some(seq) = self.up.submit(c) {
            self.sent = sent;
            if sent == Sent::Step {
                self.step_seq = Some(seq);
            }
        }
    }

    /// A motion the link reports ended: the step's settles, or the plan is interrupted.
    fn motion_ended(&mut self, seq: u16, e: MotionEnd) {
        let Phase::Settling {
            polls,
            need,
            mode_step,
            ..
        } = self.phase
        else {
            return;
        };
        if self.step_seq != Some(seq) {
            return;
        }
        let step = self.next;
        self.phase = match e {
            MotionEnd::Completed if !self.held && !mode_step => {
                self.next += 1;
                Phase::Ready
            }
            MotionEnd::Completed => Phase::Settling {
                polls,
                need,
                mode_step,
                ended: true,
            },
            MotionEnd::Interrupted { mode, faults } => {
                Phase::Ended(PlanEnd::Interrupted { step, mode, faults })
            }
            MotionEnd::Unacknowledged => Phase::Ended(PlanEnd::Unacknowledged { step }),
        };
    }

    /// The oldest waiting interjection, taken out of the queue.
    fn take_interjection(&mut self) -> Option<Command> {
        let c = self.pending[0]?;
        self.pending.rotate_left(1);
        self.pending[INTERJECTIONS - 1] = None;
        Some(c)
    }

    /// Step command `c` as it goes out: misstated if asked for and it is a reconfiguration.
    fn as_sent(&mut self, c: Command) -> Command {
        match c {
            Command::Reconfigure(r) if self.misstate => {
                self.misstate = false;
                Command::Reconfigure(misstated(r))
            }
            _ => c,
        }
    }

    /// Advances to `now`.
    pub fn tick(&mut self, steps: &[PlanStep], now: u32) -> PlanTick<L::Packet> {
        let mut t = PlanTick::default();
        if self.up.is_idle() && self.end().is_none() {
            if let Some(c) = self.take_interjection() {
                self.submit(c, Sent::Interjection);
            }
        }
        if self.up.is_idle() {
            match self.phase {
                Phase::Ready => match steps.get(self.next) {
                    None => self.phase = Phase::Ended(PlanEnd::Completed),
                    // Stopped by the operator: keep polling, start nothing.
                    Some(_) if self.held => {
                        if L::POLLS {
                            self.submit(Command::Heartbeat, Sent::Poll)
                        }
                    }
                    Some(PlanStep::Command(c)) => {
                        t.started = Some(self.next);
                        let c = self.as_sent(*c);
                        self.submit(c, Sent::Step);
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
                // A link that reports motions' ends: a step whose end came while a Stop
                // held the plan is done once the Reset is accepted.
                Phase::Settling {
                    ended: true,
                    mode_step: false,
                    ..
                } if !L::POLLS && !self.held => {
                    self.next += 1;
                    self.phase = Phase::Ready;
                    return self.tick(steps, now);
                }
                Phase::Waiting { .. } | Phase::Settling { .. } => {
                    if L::POLLS {
                        self.submit(Command::Heartbeat, Sent::Poll);
                    }
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
        if let Some((seq, e)) = u.ended {
            self.motion_ended(seq, e);
        }
        t.end = self.end();
        t
    }

    fn finished(&mut self, d: Done, hb: Option<&HeartbeatRepr>) {
        let step = self.next;
        let sent = core::mem::replace(&mut self.sent, Sent::Step);
        if sent == Sent::Interjection {
            match (d.outcome, d.command) {
                (Outcome::Unacknowledged, _) => {
                    self.phase = Phase::Ended(PlanEnd::Unacknowledged { step })
                }
                (Outcome::Accepted, Command::Stop) => self.held = true,
                (Outcome::Accepted, Command::Reset) => self.held = false,
                _ => {}
            }
            return;
        }
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
                        // A mode change is not a motion: over a link that reports motions'
                        // ends, it waits only for a settled status.
                        ended: !L::POLLS && mode_step,
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
                    ended,
                },
                _,
            ) => {
                if let Some(h) = hb.filter(|h| !mode_step && h.mode != Mode::Operational) {
                    self.phase = Phase::Ended(PlanEnd::Interrupted {
                        step,
                        mode: h.mode,
                        faults: h.faults,
                    });
                } else if !self.held && polls >= need && hb.is_some_and(settled) {
                    self.next += 1;
                    self.phase = Phase::Ready;
                } else {
                    self.phase = Phase::Settling {
                        polls: polls.saturating_add(1),
                        need,
                        mode_step,
                        ended,
                    };
                }
            }
            _ => {}
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A settled robot in `mode` answering `sent`.
    fn answer(sent: &CommandRepr, mode: Mode) -> HeartbeatRepr {
        HeartbeatRepr {
            last_seq: sent.seq,
            mode,
            ..HeartbeatRepr::default()
        }
    }

    /// Ticks every 100 ms from `from` until a packet goes out; answers it 20 ms later as a
    /// settled robot in `mode` would. Returns what went out and the answer's tick.
    fn exchange(
        run: &mut PlanRunner,
        steps: &[PlanStep],
        from: u32,
        mode: Mode,
    ) -> (u32, Option<CommandRepr>, PlanTick) {
        let mut now = from;
        while now < from + 10_000 {
            if let Some(p) = run.tick(steps, now).send {
                let t = run.heartbeat(steps, now + 20, &answer(&p, mode));
                return (now + 20, Some(p), t);
            }
            now += 100;
        }
        (now, None, PlanTick::default())
    }

    #[test]
    fn an_interjection_takes_the_next_slot_ahead_of_the_next_step_and_of_polling() {
        let steps = [
            PlanStep::Command(Command::Mode(Mode::Operational)),
            PlanStep::Wait { ms: 3000 },
            PlanStep::Command(Command::Mode(Mode::Standby)),
        ];
        let mut run = PlanRunner::new(ground::Config::default(), BoardNumber::ONE);
        let first = run.tick(&steps, 0).send;
        assert_eq!(first.map(|p| p.command), Some(steps_command(&steps[0])));
        // Interjected while the step's command is outstanding: it waits for that answer.
        assert_eq!(run.interject(Command::SystemFault), Ok(()));
        assert_eq!(run.tick(&steps, 50).send, None, "one command outstanding");
        let hb = first.map(|p| answer(&p, Mode::Operational));
        let done = hb.and_then(|hb| run.heartbeat(&steps, 60, &hb).done);
        assert_eq!(done.map(|d| d.outcome), Some(Outcome::Accepted));
        // The mode step settles by polling; the interjection goes out in the next slot
        // instead of that poll, with the next number.
        let (now, sent, t) = exchange(&mut run, &steps, 100, Mode::Operational);
        assert_eq!(sent.map(|p| p.command), Some(Command::SystemFault));
        assert_eq!(sent.map(|p| p.seq), first.map(|p| p.seq + 1));
        assert_eq!(t.done.map(|d| d.command), Some(Command::SystemFault));
        assert_eq!(run.interjections_waiting(), 0);
        assert_eq!(run.step(), 0, "its answer does not advance the plan");
        // Then polling resumes and the plan runs to its end, each number once.
        let mut seqs = heapless::Vec::<u16, 64>::new();
        for p in [first, sent].into_iter().flatten() {
            let _ = seqs.push(p.seq);
        }
        let mut now = now;
        while run.end().is_none() && now < 60_000 {
            let (t, p, _) = exchange(&mut run, &steps, now + 100, Mode::Operational);
            if let Some(p) = p {
                let _ = seqs.push(p.seq);
            }
            now = t;
        }
        assert_eq!(run.end(), Some(PlanEnd::Completed));
        assert!(seqs.windows(2).all(|w| w[1] == w[0] + 1), "{seqs:?}");
    }

    fn steps_command(s: &PlanStep) -> Command {
        match s {
            PlanStep::Command(c) => *c,
            PlanStep::Wait { .. } => Command::Heartbeat,
        }
    }

    #[test]
    fn an_accepted_stop_holds_the_plan_until_an_accepted_reset() {
        let steps = [
            PlanStep::Wait { ms: 1000 },
            PlanStep::Command(Command::Mode(Mode::Standby)),
        ];
        let mut run = PlanRunner::new(ground::Config::default(), BoardNumber::ONE);
        // The wait starts and polls; the Stop goes out in the next slot.
        let (now, sent, _) = exchange(&mut run, &steps, 0, Mode::Operational);
        assert_eq!(sent.map(|p| p.command), Some(Command::Heartbeat));
        assert_eq!(run.interject(Command::Stop), Ok(()));
        let (now, sent, _) = exchange(&mut run, &steps, now + 100, Mode::Operational);
        assert_eq!(sent.map(|p| p.command), Some(Command::Stop));
        assert!(run.held());
        // The wait ends, but no step starts while held: only polls go out.
        let mut now = now;
        for _ in 0..5 {
            let (t, sent, _) = exchange(&mut run, &steps, now + 100, Mode::Operational);
            assert_eq!(sent.map(|p| p.command), Some(Command::Heartbeat));
            now = t;
        }
        assert_eq!(run.step(), 1);
        assert_eq!(run.interject(Command::Reset), Ok(()));
        let (now, sent, _) = exchange(&mut run, &steps, now + 100, Mode::Operational);
        assert_eq!(sent.map(|p| p.command), Some(Command::Reset));
        assert!(!run.held());
        let (_, sent, _) = exchange(&mut run, &steps, now + 100, Mode::Operational);
        assert_eq!(sent.map(|p| p.command), Some(Command::Mode(Mode::Standby)));
    }

    #[test]
    fn a_held_motion_does_not_count_as_settled() {
        let steps = [
            PlanStep::Command(Command::Arm {
                side: crate::units::Side::A,
                target: crate::command::ServoTarget::Contract,
            }),
            PlanStep::Command(Command::Mode(Mode::Standby)),
        ];
        let mut run = PlanRunner::new(ground::Config::default(), BoardNumber::ONE);
        let (now, _, _) = exchange(&mut run, &steps, 0, Mode::Operational);
        assert_eq!(run.interject(Command::Stop), Ok(()));
        let (now, sent, _) = exchange(&mut run, &steps, now + 100, Mode::Operational);
        assert_eq!(sent.map(|p| p.command), Some(Command::Stop));
        // Settled-looking answers while stopped: the step is not finished.
        let mut now = now;
        for _ in 0..3 {
            now = exchange(&mut run, &steps, now + 100, Mode::Operational).0;
        }
        assert_eq!(run.step(), 0);
        assert_eq!(run.interject(Command::Reset), Ok(()));
        let (now, _, _) = exchange(&mut run, &steps, now + 100, Mode::Operational);
        let (_, _, _) = exchange(&mut run, &steps, now + 100, Mode::Operational);
        assert_eq!(run.step(), 1, "settled after the reset");
    }

    #[test]
    fn interjections_are_handed_back_when_full_or_after_the_end_never_dropped() {
        let mut run = PlanRunner::new(ground::Config::default(), BoardNumber::ONE);
        for _ in 0..INTERJECTIONS {
            assert_eq!(run.interject(Command::SystemFault), Ok(()));
        }
        assert_eq!(
            run.interject(Command::Stop),
            Err(InterjectError::Full {
                command: Command::Stop,
                waiting: INTERJECTIONS
            })
        );
        // Every waiting one goes out, in order, before the (empty) plan completes.
        let mut sent = 0;
        let mut now = 0;
        while run.end().is_none() && now < 60_000 {
            let (t, p, _) = exchange(&mut run, &[], now, Mode::Standby);
            sent += p.is_some() as usize;
            now = t + 100;
            if p.is_none() {
                run.tick(&[], now);
            }
        }
        assert_eq!(sent, INTERJECTIONS);
        assert_eq!(run.end(), Some(PlanEnd::Completed));
        assert_eq!(
            run.interject(Command::Reset),
            Err(InterjectError::Ended {
                command: Command::Reset,
                end: PlanEnd::Completed
            })
        );
    }

    #[test]
    fn an_unacknowledged_interjection_ends_the_plan() {
        let cfg = ground::Config {
            max_attempts: 2,
            ..ground::Config::default()
        };
        let steps = [PlanStep::Wait { ms: 60_000 }];
        let mut run = PlanRunner::new(cfg, BoardNumber::ONE);
        assert_eq!(run.interject(Command::Stop), Ok(()));
        let mut end = None;
        for now in (0..20_000).step_by(100) {
            end = end.or(run.tick(&steps, now).end);
        }
        assert_eq!(end, Some(PlanEnd::Unacknowledged { step: 0 }));
    }

    #[test]
    fn a_misstated_reconfiguration_goes_out_once_with_a_wrong_initial_state(
    ) -> Result<(), crate::command::ReconfigurationError> {
        let a_m = Reconfiguration::new(State::A, State::M)?;
        let m_b = Reconfiguration::new(State::M, State::B)?;
        let steps = [
            PlanStep::Command(Command::Mode(Mode::Operational)),
            PlanStep::Command(Command::Reconfigure(a_m)),
            PlanStep::Command(Command::Reconfigure(m_b)),
        ];
        let mut run = PlanRunner::new(ground::Config::default(), BoardNumber::ONE);
        run.misstate_next_reconfiguration();
        let mut reconfigurations = heapless::Vec::<Reconfiguration, 8>::new();
        let mut now = 0;
        while run.end().is_none() && now < 60_000 {
            let (t, p, _) = exchange(&mut run, &steps, now, Mode::Operational);
            if let Some(Command::Reconfigure(r)) = p.map(|p| p.command) {
                let _ = reconfigurations.push(r);
            }
            now = t + 100;
        }
        assert_eq!(reconfigurations.len(), 2, "{reconfigurations:?}");
        assert_eq!(reconfigurations[0], misstated(a_m));
        assert_ne!(reconfigurations[0].initial(), State::A);
        assert_eq!(reconfigurations[0].target(), State::M);
        assert_eq!(reconfigurations[1], m_b, "only the next one");
        Ok(())
    }
}
