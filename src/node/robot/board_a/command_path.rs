//! A command's way through board A: the exactly-once log (a copy is answered from it), board
//! A's own checks (travel, one motion at a time, the primitive's cell of Figure 9), the mode
//! supervisor (Tables 7 and 8), then the outcome settled in the log and the heartbeat, and an
//! accepted command dispatched to the motion.

use super::interface::{Event, Inputs, Outputs};
use super::motion::{Contraction, Queued, Watch};
use super::BoardA;
use crate::bolter::{BolterDirection, Job};
use crate::command::{preset_angle, BolterCommand, Command, PrimitiveMove, ServoTarget};
use crate::faults::Faults;
use crate::mode::Mode;
use crate::motion::estimate::{self, ArmPwm, InitialStateError, Readings, StateSet};
use crate::motion::State;
use crate::node::exactly_once::Admission;
use crate::refusal::Refusal;
use crate::safety::detect;
use crate::safety::supervisor::{Answer, Incoming, Input, Output};
use crate::units::PerSide;
use crate::wire::command::{CommandPacket, CommandRepr, COMMAND_LEN};
use crate::wire::WireError;

impl BoardA {
    /// The command packet of this tick, through the exactly-once log: what goes to the
    /// supervisor, and which number the heartbeat answers.
    pub(super) fn take_command(
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
        if seq != 0 && !BoardA::may_run_again(command) {
            self.kept = (seq, refusal);
        }
        self.refusal = refusal;
        out.push(Event::Executed {
            seq,
            command,
            refusal,
        });
    }

    /// The supervisor's step over this tick's faults and command; applies its stop and home
    /// orders, settles and dispatches the command, reports mode and fault changes.
    pub(super) fn supervise(
        &mut self,
        now: u32,
        inp: &Inputs,
        faults: Faults,
        taken: Taken,
        in_motion: bool,
        out: &mut Outputs,
    ) -> Output {
        let before = (self.sup.mode(), self.sup.faults());
        let s = self.sup.step(&Input {
            faults,
            command: taken.incoming,
            in_motion,
            hip_at_home: inp
                .hip
                .is_some_and(|h| detect::hip_at_home(&self.cfg.safety, h)),
            initial_state: self.initial_state(inp, taken.incoming),
        });
        self.obey(now, &s, out);
        if let (Some(seq), Some(a)) = (taken.answer, s.answer) {
            self.answer(now, seq, a, taken.incoming, out);
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

    /// A reconfiguration's check on arrival (Table 8, Section 7): each arm board A commands
    /// contracted must have its switch closed, and the initial state must be the state it
    /// tracked and one its readings allow (the IMUs, the arms' PWM values, the hip encoder).
    /// Without a hip reading the state cannot be confirmed. Any other command has no initial
    /// state to check.
    fn initial_state(
        &self,
        inp: &Inputs,
        incoming: Option<Incoming>,
    ) -> Result<(), InitialStateError> {
        let Some(Incoming::Command(Command::Reconfigure(r))) = incoming else {
            return Ok(());
        };
        let sensed = self.readings(inp).map_or(StateSet::EMPTY, |r| {
            estimate::consistent(&self.cfg.estimate, &r)
        });
        let switch = PerSide::new(inp.arm_contracted, self.b.arm_contracted);
        estimate::check_reconfiguration(r.initial(), self.tracked, sensed, self.arm_pwm(), switch)
    }

    /// The arms' PWM values as board A commands them, read against the arm travel: arm A's
    /// pulse as its servo output writes it, arm B's target as the A→B command carries it.
    /// Section 7's "PWM values": what the firmware drives the arms to, not what they measure.
    fn arm_pwm(&self) -> PerSide<ArmPwm> {
        let travel = &self.cfg.arm;
        PerSide::new(
            ArmPwm::of(travel, self.arm.now()),
            ArmPwm::of(travel, travel.resolve(self.motion.targets.arm.b)),
        )
    }

    /// The supervisor's orders: stop (a Stop keeps the motion for Reset), resume, go home.
    fn obey(&mut self, now: u32, s: &Output, out: &mut Outputs) {
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
            self.go_home();
        }
    }

    /// The supervisor's answer to command `seq`: settled, and dispatched if accepted.
    fn answer(
        &mut self,
        now: u32,
        seq: u16,
        a: Answer,
        incoming: Option<Incoming>,
        out: &mut Outputs,
    ) {
        match a {
            Answer::Accepted(c) => {
                self.settle(seq, Some(c), None, out);
                self.dispatch(c, now);
            }
            Answer::Refused(r) => {
                let c = match incoming {
                    Some(Incoming::Command(c)) => Some(c),
                    _ => None,
                };
                self.settle(seq, c, Some(r), out);
            }
        }
    }

    /// A command packet through the exactly-once log, admitted in this one place: not ours
    /// (ignored), a copy (answered from the log), or to be judged — by the supervisor, after
    /// the board-level checks it does not make.
    fn receive(&mut self, bytes: &[u8], in_motion: bool) -> Received {
        let (seq, command) = match self.unpack(bytes) {
            Ok(x) => x,
            Err(e) => return Received::Ignore(e),
        };
        match self.log.admit(seq) {
            Admission::Duplicate => return Received::Answer(Event::Duplicate { seq }),
            Admission::Stale => return Received::Answer(Event::Stale { seq }),
            Admission::Execute => {}
        }
        match command {
            // The supervisor refuses it like any other command it cannot take.
            Err(r) => Received::Run(seq, Incoming::Malformed(r)),
            Ok(c) => match self.board_check(c, in_motion) {
                Some(r) => Received::Refuse(seq, c, r),
                None => Received::Run(seq, Incoming::Command(c)),
            },
        }
    }

    /// A packet's sequence number and command, or why it is no command (answered as a
    /// refusal), or the event of a packet that is not ours to answer.
    pub(super) fn unpack(&self, bytes: &[u8]) -> Result<(u16, Result<Command, Refusal>), Event> {
        match CommandRepr::parse(bytes) {
            Ok(r) if r.board != self.cfg.board => Err(Event::OtherRobot { board: r.board }),
            Ok(r) => Ok((r.seq, Ok(r.command))),
            // Length, header and checksum held (the command check comes after them) but the
            // opcode or parameters are no command: ours to answer, with its sequence number,
            // so the ground stops resending it.
            Err(WireError::Command(ce)) => match crate::wire::check::<CommandPacket>(bytes) {
                Ok(p) if p.board_number() == self.cfg.board.get() => {
                    Ok((p.seq(), Err(ce.refusal())))
                }
                _ => Err(Event::Rejected(WireError::Command(ce))),
            },
            Err(e) => Err(Event::Rejected(e)),
        }
    }

    /// Board-level checks the supervisor does not make: the refusal, if one holds.
    fn board_check(&self, c: Command, in_motion: bool) -> Option<Refusal> {
        // A position outside this robot's configured travel is a malformed command here,
        // whatever the robot is doing (the packet's own check is against the library's
        // travel): the servo would be driven against its end stop.
        let travel = match c {
            Command::Arm { target, .. } => self.cfg.arm.check(target).err(),
            Command::Gripper { target, .. } => self.cfg.gripper.check(target).err(),
            _ => None,
        };
        if travel.is_some() {
            return Some(Refusal::InvalidParameter);
        }
        // One motion at a time, and a primitive must be the map's move from the state the
        // robot is in to the final state it names.
        if c.kind().moves() && in_motion && self.sup.mode() == Mode::Operational {
            return Some(Refusal::Busy);
        }
        let Command::Primitive(m) = c else {
            return None;
        };
        if self.sup.mode() != Mode::Operational || self.primitive_move(m).is_some() {
            return None;
        }
        // From where the robot is, the model's move is a turn the hip cannot make: the
        // ground's belief holds, the move does not exist. Otherwise the command holds only
        // where the primitive takes some state to its final state; the robot is in none of
        // them: the ground's belief of where the robot is does not hold, as with a
        // reconfiguration's initial state.
        if self.tracked.is_some_and(|t| m.turns_without_hip_from(t)) {
            Some(Refusal::TurnWithoutHip)
        } else {
            Some(Refusal::InitialStateMismatch)
        }
    }

    /// The move a primitive command asks for, as (from, to): from the tracked state to the
    /// command's final state, when that is the primitive's cell of the map (Figure 9). The
    /// final state settles the 12 (state, primitive) pairs that reach two states.
    fn primitive_move(&self, m: PrimitiveMove) -> Option<(State, State)> {
        let from = self.tracked?;
        m.is_move_from(from).then_some((from, m.target()))
    }

    /// What board A knows of the robot's state: both IMUs, the arms' PWM values, the hip
    /// encoder; none without a hip reading.
    fn readings(&self, inp: &Inputs) -> Option<Readings> {
        Some(Readings {
            gravity_a: inp.gravity,
            gravity_b: self.b.gravity,
            arm: self.arm_pwm(),
            hip: inp.hip?,
        })
    }

    /// An accepted command sets the motion going: new targets, a bolting job, a
    /// reconfiguration or primitive (after its idle check).
    fn dispatch(&mut self, c: Command, now: u32) {
        if c.kind().moves() {
            // A new motion gets a budget of its own, also after one that timed out.
            self.watch = Watch::Idle;
            self.release_b_hold();
            if !matches!(c, Command::Primitive(_) | Command::Reconfigure(_)) {
                self.complete = false;
                self.motion.single = true;
            }
        }
        match c {
            Command::Arm { side, target } => {
                self.motion.targets.arm[side] = target;
                self.motion.contracting[side] = if target == ServoTarget::Contract {
                    Contraction::Moving
                } else {
                    Contraction::Idle
                };
            }
            Command::Gripper { side, target } => self.motion.targets.gripper[side] = target,
            Command::Hip(h) => {
                // An angle, or a preset's angle; Home is this robot's home angle.
                self.motion.targets.hip = preset_angle(h).unwrap_or(self.cfg.safety.hip_home)
            }
            Command::Bolter(b) => {
                self.motion.waiting_job = Some(match b {
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
}

/// This tick's command after the exactly-once log: what the supervisor judges, and the number
/// the heartbeat answers (0 for a copy, whose outcome the log already holds).
#[derive(Debug, Clone, Copy, Default)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub(super) struct Taken {
    /// What the supervisor judges.
    pub(super) incoming: Option<Incoming>,
    /// The number the heartbeat answers.
    pub(super) answer: Option<u16>,
}

/// A command packet after the exactly-once log and board A's own checks.
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
