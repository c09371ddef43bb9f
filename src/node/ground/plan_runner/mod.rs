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
//! use mmic::node::exactly_once::uplink::{self, Outcome};
//! use mmic::node::ground::plan_runner::{PlanEnd, PlanRunner, PlanStep};
//! use mmic::units::BoardNumber;
//! use mmic::wire::heartbeat::HeartbeatRepr;
//!
//! let steps = [PlanStep::Command(Command::Mode(Mode::Operational)), PlanStep::Wait { ms: 2000 }];
//! let mut run = PlanRunner::new(uplink::Config::default(), BoardNumber::ONE);
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
// req: P3.1, P8.3

mod interject;
mod over_pus;
mod plan;

pub use super::link::{Link, LinkTick, MotionEnd};
use crate::command::{Command, CommandKind};
use crate::mode::Mode;
use crate::node::exactly_once::uplink::{self, Done, Outcome, Uplink};
use crate::refusal::Refusal;
use crate::units::BoardNumber;
use crate::units::Instant;
use crate::wire::heartbeat::HeartbeatRepr;
pub use interject::{InterjectError, INTERJECTIONS};
pub use plan::{misstated, settled, settles_after, PlanEnd, PlanStep, PlanTick};

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

/// What the ground's disk keeps of a plan runner across the ground's restart (decision
/// `restart-ground`): where the plan stands, whether a Stop holds it, and the out-of-band
/// commands still waiting for a slot. The link's numbering is kept beside it, by the link
/// ([`Uplink::next_seq`], [`super::pus::TcLink::next_count`]). Written whenever it changes.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct PlanKept {
    /// The step being run (0-based).
    pub step: usize,
    /// Its command was outstanding, or its motion running: its outcome is lost with the RAM.
    pub open: bool,
    /// An accepted Stop held the plan.
    pub held: bool,
    /// The plan had ended.
    pub end: Option<PlanEnd>,
    /// Out-of-band commands not yet sent, oldest first.
    pub pending: [Option<Command>; INTERJECTIONS],
}

/// The runner, over the legacy [`Uplink`] or another [`Link`].
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct PlanRunner<L = Uplink> {
    up: L,
    /// The current step's index: at most the plan's length, so stepping on by
    /// `saturating_add(1)` never saturates.
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

impl PlanRunner {
    /// At the first step, over the legacy uplink.
    pub const fn new(cfg: uplink::Config, board: BoardNumber) -> PlanRunner {
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

    /// What to keep across the ground's restart ([`PlanRunner::restarted`]).
    pub const fn kept(&self) -> PlanKept {
        PlanKept {
            step: self.next,
            open: matches!(self.phase, Phase::Sending | Phase::Settling { .. }),
            held: self.held,
            end: self.end(),
            pending: self.pending,
        }
    }

    /// The runner of a ground that restarted, over `link` (numbering after the last number
    /// the ground gave out: decision `restart-ground`), from what its disk kept. A step whose
    /// command or motion was open at the crash ends the plan as [`PlanEnd::Restarted`]: the
    /// ground does not know whether it ran, and sending it again as a new command could run
    /// it twice. Otherwise the plan goes on at the step it stood at (a wait starts again).
    /// An out-of-band command that was outstanding is lost with the RAM; those still waiting
    /// are sent.
    ///
    /// ```
    /// use mmic::command::Command;
    /// use mmic::mode::Mode;
    /// use mmic::node::exactly_once::uplink::{Config, Uplink};
    /// use mmic::node::ground::plan_runner::{PlanEnd, PlanRunner, PlanStep};
    /// use mmic::units::BoardNumber;
    ///
    /// let steps = [PlanStep::Command(Command::Mode(Mode::Operational))];
    /// let mut run = PlanRunner::new(Config::default(), BoardNumber::ONE);
    /// let sent = run.tick(&steps, 0).send.unwrap(); // step 0 outstanding: the ground crashes
    /// let up = Uplink::starting_at(Config::default(), BoardNumber::ONE, run.uplink().next_seq());
    /// let mut again = PlanRunner::restarted(up, run.kept());
    /// assert_eq!(again.end(), Some(PlanEnd::Restarted { step: 0 }));
    /// assert_eq!(again.tick(&steps, 100).send, None); // nothing is sent again
    /// assert!(again.uplink().next_seq() > sent.seq);
    /// ```
    pub const fn restarted(link: L, kept: PlanKept) -> PlanRunner<L> {
        let mut run = PlanRunner::over(link);
        run.next = kept.step;
        run.held = kept.held;
        run.pending = kept.pending;
        run.phase = match (kept.end, kept.open) {
            (Some(e), _) => Phase::Ended(e),
            (None, true) => Phase::Ended(PlanEnd::Restarted { step: kept.step }),
            (None, false) => Phase::Ready,
        };
        run
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
                self.next = self.next.saturating_add(1);
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
        // A step that ends now (a wait over, a motion's end reported) frees the slot at once.
        while self.use_slot(steps, now, &mut t) {}
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

    /// A free slot of the link goes to an interjection, else to the plan: its next step, or a
    /// poll while a motion settles or a wait runs. True when the current step ended here and
    /// the slot is free again.
    fn use_slot(&mut self, steps: &[PlanStep], now: u32, t: &mut PlanTick<L::Packet>) -> bool {
        if self.up.is_idle()
            && self.end().is_none()
            && let Some(c) = self.take_interjection()
        {
            self.submit(c, Sent::Interjection);
        }
        if !self.up.is_idle() {
            return false;
        }
        match self.phase {
            Phase::Ready => self.start_step(steps, now, t),
            Phase::Waiting { until }
                if Instant::from_millis(now)
                    .since(Instant::from_millis(until))
                    .millis()
                    > 0
                    || until == now =>
            {
                self.next = self.next.saturating_add(1);
                self.phase = Phase::Ready;
                return true;
            }
            // A link that reports motions' ends: a step whose end came while a Stop held the
            // plan is done once the Reset is accepted.
            Phase::Settling {
                ended: true,
                mode_step: false,
                ..
            } if !L::POLLS && !self.held => {
                self.next = self.next.saturating_add(1);
                self.phase = Phase::Ready;
                return true;
            }
            Phase::Waiting { .. } | Phase::Settling { .. } => {
                if L::POLLS {
                    self.submit(Command::Heartbeat, Sent::Poll);
                }
            }
            Phase::Sending | Phase::Ended(_) => {}
        }
        false
    }

    /// Ready: the next step starts (its command goes out, or its wait begins), the plan is
    /// complete, or — held by a Stop — the runner only polls.
    fn start_step(&mut self, steps: &[PlanStep], now: u32, t: &mut PlanTick<L::Packet>) {
        match steps.get(self.next) {
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
        }
    }

    /// The outstanding command ended (`hb`: the heartbeat that answered it, if one did): an
    /// interjection holds or frees the plan; a step's command moves the plan on, ends it, or
    /// starts its settling; a poll's answer settles the motion or shows it interrupted.
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
            (Phase::Sending, Outcome::Accepted) => self.accepted(d.command),
            (Phase::Settling { .. }, _) => self.settling(hb),
            _ => {}
        }
    }

    /// The current step's command was accepted: a command that must settle starts its
    /// settling, any other is done.
    fn accepted(&mut self, c: Command) {
        if settles_after(&c) {
            let need = u16::from(matches!(c.kind(), CommandKind::Bolter));
            let mode_step = matches!(c.kind(), CommandKind::Mode);
            self.phase = Phase::Settling {
                polls: 0,
                need,
                mode_step,
                // A mode change is not a motion: over a link that reports motions' ends, it
                // waits only for a settled status.
                ended: !L::POLLS && mode_step,
            };
        } else {
            self.next = self.next.saturating_add(1);
            self.phase = Phase::Ready;
        }
    }

    /// A poll answered while the step settles: the robot left Operational (the plan is
    /// interrupted), or it is settled (the step is done), or one more poll counts.
    fn settling(&mut self, hb: Option<&HeartbeatRepr>) {
        let Phase::Settling {
            polls,
            need,
            mode_step,
            ended,
        } = self.phase
        else {
            return;
        };
        if let Some(h) = hb.filter(|h| !mode_step && h.mode != Mode::Operational) {
            self.phase = Phase::Ended(PlanEnd::Interrupted {
                step: self.next,
                mode: h.mode,
                faults: h.faults,
            });
        } else if !self.held && polls >= need && hb.is_some_and(settled) {
            self.next = self.next.saturating_add(1);
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
}

#[cfg(test)]
mod tests;
