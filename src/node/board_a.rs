//! Board A: the robot's primary board as one pure tick.
//!
//! Each tick takes what the shell gathered since the last one — at most one command packet
//! from the WiFi hand-off queue, at most one internal heartbeat from board B's serial line,
//! and side A's filtered sensors — and returns side A's module outputs, the A→B command to
//! send (if one is due), the 66-byte heartbeat answering the command (if one came), and what
//! happened, as [`Event`]s for logs. Inside, the pieces of the earlier modules are joined in
//! the order the paper gives: fault detection, then the mode supervisor (Tables 7 and 8),
//! then the command (exactly-once log, supervisor, dispatch), then motion (reconfiguration
//! runner, single-module moves), bolting (coordinator and side A's executor), and finally the
//! servo and hip outputs.
//!
//! ```
//! use mmic::command::Command;
//! use mmic::mode::Mode;
//! use mmic::node::board_a::{BoardA, Config, Inputs};
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
//! assert!(out.events.iter().any(|e| matches!(e, mmic::node::board_a::Event::Duplicate { seq: 1 })));
//! ```

use super::exactly_once::{Admission, CommandLog};
use crate::bolter::{
    self as coordinator, BolterDirection, BolterSide, Coordinator, Drive, Job, MuxLines, Sensed,
};
use crate::command::{preset_angle, BolterCommand, Command, HipTarget, ServoTarget};
use crate::control::hip::{self, HipController};
use crate::control::interp::{Interpolator, Rate, Travel};
use crate::faults::{Fault, Faults};
use crate::mode::Mode;
use crate::motion::estimate::{self, initial_state_consistent, Readings};
use crate::motion::runner::{RunStatus, Runner};
use crate::motion::sequencer::{self, Feedback, Targets};
use crate::motion::{map, State};
use crate::refusal::Refusal;
use crate::safety::detect::{self, hip_distance, CommMonitor, LowBattery};
use crate::safety::supervisor::{Answer, Incoming, Input, Supervisor};
use crate::safety::ModuleSet;
use crate::units::{
    BoardNumber, Electrical, Gravity, HipAngle, Instant, Module, PerSide, PulseWidth,
};
use crate::wire::b_command::{BCommandRepr, BPower, B_COMMAND_LEN};
use crate::wire::command::{CommandPacket, CommandRepr, COMMAND_LEN};
use crate::wire::heartbeat::{BolterAttempt, HeartbeatRepr, HEARTBEAT_LEN};
use crate::wire::internal_heartbeat::{InternalHeartbeatRepr, INTERNAL_HEARTBEAT_LEN};
use crate::wire::WireError;

/// Board A's settings.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Config {
    /// This robot's number.
    pub board: BoardNumber,
    /// Fault thresholds and timeouts (Table 8).
    pub safety: detect::Config,
    /// Primitive step timing.
    pub motion: sequencer::Config,
    /// Bolting.
    pub bolter: coordinator::Config,
    /// Servo interpolation rate (both sides).
    pub rate: Rate,
    /// What contract/extend mean for the arms.
    pub arm: Travel,
    /// What contract/extend mean for the grippers (extend = closed on a face).
    pub gripper: Travel,
    /// Hip PI controller.
    pub hip: hip::Config,
    /// A hip move is done within this distance of its target, 0.01°.
    pub hip_done_tolerance: u16,
    /// State estimation.
    pub estimate: estimate::Config,
    /// A→B command period, ms (sent sooner when its content changes).
    pub b_period_ms: u32,
    /// The idle overcurrent check starts this long after the last motion ended, ms. Default
    /// 600: the sensor front end's 50-sample window at a 10 ms tick (500 ms) plus two of
    /// board B's heartbeat periods, so no current of the motion is left in the averages.
    pub idle_settle_ms: u32,
}

impl Default for Config {
    fn default() -> Config {
        let pw = |us| match PulseWidth::new(us) {
            Ok(p) => p,
            Err(_) => PulseWidth::CENTER,
        };
        Config {
            board: BoardNumber::ONE,
            safety: detect::Config::default(),
            motion: sequencer::Config::default(),
            bolter: coordinator::Config::default(),
            rate: Rate::default(),
            arm: Travel {
                contracted: pw(900),
                extended: pw(2100),
            },
            gripper: Travel {
                contracted: pw(1000),
                extended: pw(2000),
            },
            hip: hip::Config::default(),
            hip_done_tolerance: 150,
            estimate: estimate::Config::default(),
            b_period_ms: 50,
            idle_settle_ms: 600,
        }
    }
}

/// One tick's inputs.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Inputs {
    /// A command packet from the WiFi hand-off queue.
    pub command: Option<[u8; COMMAND_LEN]>,
    /// An internal heartbeat from board B.
    pub from_b: Option<[u8; INTERNAL_HEARTBEAT_LEN]>,
    /// Side A's filtered voltages and currents.
    pub electrical: Electrical,
    /// Hip encoder angle.
    pub hip: HipAngle,
    /// Gravity in A's IMU frame.
    pub gravity: Option<Gravity>,
    /// Arm A's contraction switch.
    pub arm_contracted: bool,
    /// Bolter A's home switch: the bolter is in its initial configuration. (The end of a
    /// current-sensed bolter step is decided from `electrical.i_bo`.)
    pub bolter_at_home: bool,
}

impl Inputs {
    /// Nothing received; a full battery, no current; hip at the default home angle (180°),
    /// arm A contracted, bolter A at home.
    pub const fn at_home() -> Inputs {
        Inputs {
            command: None,
            from_b: None,
            electrical: Electrical {
                v_bat: 12_000,
                i_bat: 0,
                i_loc: 0,
                i_grip: 0,
                i_3v3: 0,
                v_reg: 7_400,
                i_bo: 0,
            },
            hip: HipAngle::STRAIGHT,
            gravity: None,
            arm_contracted: true,
            bolter_at_home: true,
        }
    }
}

/// Something that happened in a tick, for logs and tests.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum Event {
    /// A command was taken and run (or refused) — once per sequence number.
    Executed {
        /// Its sequence number (0 = unsequenced).
        seq: u16,
        /// The command; none when the packet held no command (an unknown opcode or invalid
        /// parameters, which are refused).
        command: Option<Command>,
        /// Refused, and why; none = accepted.
        refusal: Option<Refusal>,
    },
    /// A copy of the last command taken: answered, not run.
    Duplicate {
        /// Its sequence number.
        seq: u16,
    },
    /// A late copy of an older command: answered, not run.
    Stale {
        /// Its sequence number.
        seq: u16,
    },
    /// A packet failed its length, header or checksum check: dropped unanswered (the ground
    /// resends it).
    Rejected(WireError),
    /// A command for another robot: dropped unanswered.
    OtherRobot {
        /// The robot it was for.
        board: BoardNumber,
    },
    /// Faults latched this tick.
    Faults(Faults),
    /// The mode changed.
    Mode {
        /// Before.
        from: Mode,
        /// After.
        to: Mode,
    },
    /// A reconfiguration or primitive reached its target state.
    Reached(State),
    /// A bolting job ended: done (`None`) or failed with this fault.
    Bolting(Option<Fault>),
    /// A pair of a bolting job finished: fastened (or released) at attempt `attempts`, or not.
    Pair {
        /// The pair.
        pair: crate::command::BolterPair,
        /// Attempts made, 1..=3.
        attempts: u8,
        /// Whether the pair succeeded.
        ok: bool,
    },
}

/// Events per tick (more are counted in [`Outputs::events_lost`]).
pub const EVENTS: usize = 6;

/// One tick's outputs.
#[derive(Debug, Clone, PartialEq, Eq, Hash)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Outputs {
    /// Hip servo pulse; none = unpowered.
    pub hip: Option<PulseWidth>,
    /// Arm A pulse; none = unpowered.
    pub arm: Option<PulseWidth>,
    /// Gripper A pulse; none = unpowered.
    pub gripper: Option<PulseWidth>,
    /// 7.4 V regulator.
    pub regulator: bool,
    /// Bolter A motor.
    pub bolter: Drive,
    /// Bolter A multiplexer lines.
    pub mux: MuxLines,
    /// A→B command to send now.
    pub to_b: Option<[u8; B_COMMAND_LEN]>,
    /// Heartbeat answering this tick's command.
    pub heartbeat: Option<[u8; HEARTBEAT_LEN]>,
    /// What happened.
    pub events: heapless::Vec<Event, EVENTS>,
    /// Events that did not fit (never expected; counted so none is lost silently).
    pub events_lost: u8,
}

impl Outputs {
    /// Nothing driven, nothing to send, no event.
    fn empty() -> Outputs {
        Outputs {
            hip: None,
            arm: None,
            gripper: None,
            regulator: false,
            bolter: Drive::Idle,
            mux: MuxLines::default(),
            to_b: None,
            heartbeat: None,
            events: heapless::Vec::new(),
            events_lost: 0,
        }
    }

    fn push(&mut self, e: Event) {
        if self.events.push(e).is_err() {
            self.events_lost = self.events_lost.saturating_add(1);
        }
    }
}

/// Board A's state.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct BoardA {
    cfg: Config,
    sup: Supervisor,
    log: CommandLog,
    comm: CommMonitor,
    battery: LowBattery,
    runner: Option<Runner>,
    tracked: Option<State>,
    target_state: Option<State>,
    complete: bool,
    coord: Coordinator,
    side_a: BolterSide,
    waiting_job: Option<Job>,
    targets: Targets,
    arm: Interpolator,
    gripper: Interpolator,
    hip_ctl: HipController,
    b: InternalHeartbeatRepr,
    b_heard: bool,
    b_sent: Option<(Instant, BCommandRepr)>,
    contracting: bool,
    refusal: Option<Refusal>,
    moving: bool,
    pair: Option<(crate::command::BolterPair, u8)>,
    still_since: Option<Instant>,
}

impl BoardA {
    /// Startup: Standby, no state known, servos at their home pulses.
    pub fn new(cfg: Config) -> BoardA {
        let home = Targets::home();
        BoardA {
            cfg,
            sup: Supervisor::new(),
            log: CommandLog::new(),
            comm: CommMonitor::default(),
            battery: LowBattery::default(),
            runner: None,
            tracked: None,
            target_state: None,
            complete: false,
            coord: Coordinator::new(),
            side_a: BolterSide::new(),
            waiting_job: None,
            targets: Targets {
                hip: cfg.safety.hip_home,
                ..home
            },
            arm: Interpolator::new(cfg.arm.contracted, cfg.rate),
            gripper: Interpolator::new(cfg.gripper.extended, cfg.rate),
            hip_ctl: HipController::new(cfg.hip),
            b: InternalHeartbeatRepr::default(),
            b_heard: false,
            b_sent: None,
            contracting: false,
            refusal: None,
            moving: false,
            pair: None,
            still_since: None,
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

    /// A motion or bolting job was running at the last tick (a reconfiguration, a bolting
    /// job, or a module still moving to its target).
    pub const fn in_motion(&self) -> bool {
        self.moving
    }

    fn moving_now(&self, fb: &Feedback) -> bool {
        self.runner
            .is_some_and(|r| r.status() == RunStatus::Running)
            || self.coord.status() == coordinator::Status::Running
            || self.waiting_job.is_some()
            || !fb.arm_done.all()
            || !fb.gripper_done.all()
            || !fb.hip_done
    }

    fn feedback(&self, hip_now: HipAngle, arm_a_switch: bool) -> Feedback {
        let b_ok =
            |now: PulseWidth, target: PulseWidth, want: PulseWidth| now == target && target == want;
        Feedback {
            arm_done: PerSide::new(
                self.arm.done(),
                b_ok(
                    self.b.arm_b_now,
                    self.b.arm_b_target,
                    self.cfg.arm.resolve(self.targets.arm.b),
                ),
            ),
            gripper_done: PerSide::new(
                self.gripper.done(),
                b_ok(
                    self.b.gripper_b_now,
                    self.b.gripper_b_target,
                    self.cfg.gripper.resolve(self.targets.gripper.b),
                ),
            ),
            hip_done: hip_distance(hip_now, self.targets.hip) <= self.cfg.hip_done_tolerance,
            arm_switch: PerSide::new(arm_a_switch, self.b.arm_contracted),
        }
    }

    /// One tick at `now` (ms, wrapping), in phases that read in order: take board B's report,
    /// advance the motion and the bolting, detect the fault conditions, take the command
    /// through the exactly-once log, let the supervisor judge it against the faults, answer,
    /// drive the outputs.
    pub fn tick(&mut self, now: u32, inp: &Inputs) -> Outputs {
        let mut out = Outputs::empty();
        self.ingest_b(now, inp.from_b, &mut out);
        // Motion and bolting advance first, so the supervisor sees whether they still run.
        // The feedback is this tick's readings against the targets in force; a target the
        // motion sets now is judged from the next tick on (a primitive that issued one is
        // still running, so the robot counts as moving either way).
        let fb = self.feedback(inp.hip, inp.arm_contracted);
        let events = self.advance(now, &fb, inp.arm_contracted, &mut out);
        let in_motion = self.moving_now(&fb);
        self.moving = in_motion;
        let conditions = self.detect(now, inp, in_motion);
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

    /// Board B's report: refreshes the communication monitor and what A knows of side B.
    fn ingest_b(
        &mut self,
        now: u32,
        from_b: Option<[u8; INTERNAL_HEARTBEAT_LEN]>,
        out: &mut Outputs,
    ) {
        self.comm.tick(now);
        if let Some(bytes) = from_b {
            match InternalHeartbeatRepr::parse(&bytes) {
                Ok(hb) => {
                    self.comm.heartbeat(now, hb.command_received);
                    self.b = hb;
                    self.b_heard = true;
                }
                Err(e) => out.push(Event::Rejected(e)),
            }
        }
    }

    /// Advances the reconfiguration, the bolting and the arm contraction check; returns the
    /// faults they raised this tick (events, not conditions).
    fn advance(
        &mut self,
        now: u32,
        fb: &Feedback,
        arm_contracted: bool,
        out: &mut Outputs,
    ) -> Faults {
        let mut faults = Faults::EMPTY;
        if let Some(mut r) = self.runner {
            match r.step(now, fb) {
                RunStatus::Running => {
                    self.targets = r.targets();
                    self.runner = Some(r);
                }
                RunStatus::Complete => {
                    self.targets = r.targets();
                    self.tracked = Some(r.current_state());
                    self.complete = true;
                    self.runner = None;
                    out.push(Event::Reached(r.current_state()));
                }
                RunStatus::Failed(f) => {
                    self.tracked = None;
                    self.runner = None;
                    faults = faults.with(f);
                }
            }
        }
        self.bolting(now, out, &mut faults);
        // Arm contraction check (Table 8): when a commanded contraction of arm A ends.
        if self.contracting && self.arm.done() {
            self.contracting = false;
            if detect::arm_contraction_fault(true, arm_contracted) {
                faults = faults.with(Fault::ArmNotContracted);
            }
        }
        faults
    }

    /// The fault conditions holding now: overcurrent (the idle check once the robot has been
    /// still for `idle_settle_ms`), low battery, lost communication with board B.
    fn detect(&mut self, now: u32, inp: &Inputs, in_motion: bool) -> Faults {
        let e_b = self.b.electrical_b;
        let mut conditions =
            detect::operational_overcurrent(&self.cfg.safety, &inp.electrical, &e_b);
        // The idle check waits until the robot has been still for `idle_settle_ms`: currents
        // sampled while the last motion ended (still in the moving averages, and B's report
        // is up to a period old) are no fault.
        if in_motion {
            self.still_since = None;
        } else if self.still_since.is_none() {
            self.still_since = Some(Instant::from_millis(now));
        }
        let settled = self.still_since.is_some_and(|t| {
            Instant::from_millis(now).since(t).millis() >= self.cfg.idle_settle_ms
        });
        if settled {
            conditions = conditions.union(detect::idle_overcurrent(
                &self.cfg.safety,
                &inp.electrical,
                &e_b,
            ));
        }
        if self
            .battery
            .update(&self.cfg.safety, now, inp.electrical.v_bat, e_b.v_bat)
        {
            conditions = conditions.with(Fault::LowBattery);
        }
        if self.comm.lost(&self.cfg.safety) {
            conditions = conditions.with(Fault::InternalCommLoss);
        }
        conditions
    }

    /// The command packet of this tick, through the exactly-once log: what goes to the
    /// supervisor, and which number the heartbeat answers.
    fn take_command(
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
        self.refusal = refusal;
        out.push(Event::Executed {
            seq,
            command,
            refusal,
        });
    }

    /// The supervisor's step over this tick's faults and command; applies its stop and home
    /// orders, settles and dispatches the command, reports mode and fault changes.
    fn supervise(
        &mut self,
        now: u32,
        inp: &Inputs,
        faults: Faults,
        taken: Taken,
        in_motion: bool,
        out: &mut Outputs,
    ) -> crate::safety::supervisor::Output {
        let before = (self.sup.mode(), self.sup.faults());
        let initial_state_ok = match taken.incoming {
            Some(Incoming::Command(Command::Reconfigure(r))) => {
                let sensed = estimate::consistent(&self.cfg.estimate, &self.readings(inp));
                initial_state_consistent(r.initial(), self.tracked, sensed)
            }
            _ => true,
        };
        let s = self.sup.step(&Input {
            faults,
            command: taken.incoming,
            in_motion,
            hip_at_home: detect::hip_at_home(&self.cfg.safety, inp.hip),
            initial_state_ok,
        });
        if s.stop_motion {
            self.stop_all(now);
        }
        if s.go_home {
            self.go_home(now);
        }
        if let (Some(seq), Some(a)) = (taken.answer, s.answer) {
            match a {
                Answer::Accepted(c) => {
                    self.settle(seq, Some(c), None, out);
                    self.dispatch(c, now);
                }
                Answer::Refused(r) => {
                    let c = match taken.incoming {
                        Some(Incoming::Command(c)) => Some(c),
                        _ => None,
                    };
                    self.settle(seq, c, Some(r), out);
                }
            }
        }
        if s.mode != before.0 {
            out.push(Event::Mode {
                from: before.0,
                to: s.mode,
            });
        }
        let new_faults = Faults::from_iter(s.faults.iter().filter(|f| !before.1.contains(*f)));
        if !new_faults.is_empty() {
            out.push(Event::Faults(new_faults));
        }
        s
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
        let hip_pulse = self.hip_ctl.step(self.targets.hip, inp.hip, now);
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

    /// A command packet through the exactly-once log, admitted in this one place: not ours
    /// (ignored), a copy (answered from the log), or to be judged — by the supervisor, after
    /// the board-level checks it does not make.
    fn receive(&mut self, bytes: &[u8], in_motion: bool) -> Received {
        let (seq, command) = match CommandRepr::parse(bytes) {
            Ok(r) if r.board != self.cfg.board => {
                return Received::Ignore(Event::OtherRobot { board: r.board })
            }
            Ok(r) => (r.seq, Ok(r.command)),
            // Length, header and checksum held (the command check comes after them) but the
            // opcode or parameters are no command: ours to answer, with its sequence number,
            // so the ground stops resending it.
            Err(WireError::Command(ce)) => match crate::wire::check::<CommandPacket>(bytes) {
                Ok(p) if p.board_number() == self.cfg.board.get() => {
                    (p.seq(), Err(Refusal::for_command_error(&ce)))
                }
                _ => return Received::Ignore(Event::Rejected(WireError::Command(ce))),
            },
            Err(e) => return Received::Ignore(Event::Rejected(e)),
        };
        match self.log.admit(seq) {
            Admission::Duplicate => return Received::Answer(Event::Duplicate { seq }),
            Admission::Stale => return Received::Answer(Event::Stale { seq }),
            Admission::Execute => {}
        }
        let c = match command {
            // The supervisor refuses it like any other command it cannot take.
            Err(r) => return Received::Run(seq, Incoming::Malformed(r)),
            Ok(c) => c,
        };
        // Board-level checks the supervisor does not make: one motion at a time, and a
        // primitive must be a move from the state the robot is in.
        if c.kind().moves() && in_motion && self.sup.mode() == Mode::Operational {
            return Received::Refuse(seq, c, Refusal::Busy);
        }
        if let Command::Primitive(pr) = c {
            if self.sup.mode() == Mode::Operational && self.primitive_target(pr).is_none() {
                return Received::Refuse(seq, c, Refusal::InitialStateMismatch);
            }
        }
        Received::Run(seq, Incoming::Command(c))
    }

    fn primitive_target(&self, pr: crate::motion::Primitive) -> Option<State> {
        let from = self.tracked?;
        State::ALL
            .into_iter()
            .find(|&to| map::primitive(from, to) == Some(pr))
    }

    fn readings(&self, inp: &Inputs) -> Readings {
        Readings {
            gravity_a: inp.gravity,
            gravity_b: self.b.gravity,
            arm_a_contracted: inp.arm_contracted,
            arm_b_contracted: self.b.arm_contracted,
            hip: inp.hip,
        }
    }

    fn dispatch(&mut self, c: Command, now: u32) {
        match c {
            Command::Arm { side, target } => {
                self.targets.arm[side] = target;
                self.contracting = side as usize == 0 && target == ServoTarget::Contract;
            }
            Command::Gripper { side, target } => self.targets.gripper[side] = target,
            Command::Hip(h) => {
                self.targets.hip = match (h, preset_angle(h)) {
                    (_, Some(a)) => a,
                    (HipTarget::Angle(a), None) => a,
                    _ => self.cfg.safety.hip_home,
                }
            }
            Command::Bolter(b) => {
                let job = match b {
                    BolterCommand::Bolt(f) => Job {
                        direction: BolterDirection::Bolt,
                        fasteners: f,
                    },
                    BolterCommand::Unbolt(f) => Job {
                        direction: BolterDirection::Unbolt,
                        fasteners: f,
                    },
                    // Both bolters down: the first step of a bolting run on the selected pair.
                    BolterCommand::Down => Job {
                        direction: BolterDirection::Bolt,
                        fasteners: crate::command::Fasteners::Pair(crate::command::BolterPair::P1),
                    },
                };
                self.waiting_job = Some(job);
                self.bolting_start(now);
            }
            Command::Primitive(pr) => {
                if let (Some(from), Some(to)) = (self.tracked, self.primitive_target(pr)) {
                    self.start_run(from, to, now);
                }
            }
            Command::Reconfigure(r) => {
                let from = self.tracked.unwrap_or(r.initial());
                self.start_run(from, r.target(), now);
            }
            _ => {}
        }
    }

    fn start_run(&mut self, from: State, to: State, now: u32) {
        self.target_state = Some(to);
        self.complete = from == to;
        if from != to {
            self.runner = Some(Runner::start(self.cfg.motion, from, to, self.targets, now));
            if let Some(r) = self.runner {
                self.targets = r.targets();
            }
        }
    }

    /// A new job waits until B reports idle, so that B's executor cannot mistake the job's
    /// first order for its previous one (spec/control/bolter.md).
    fn bolting_start(&mut self, now: u32) {
        if let Some(job) = self.waiting_job {
            if self.b.bolter_aux.step.is_none() || !self.b_heard {
                self.coord.start(job, now);
                self.waiting_job = None;
            }
        }
    }

    fn bolting(&mut self, now: u32, out: &mut Outputs, faults: &mut Faults) {
        self.bolting_start(now);
        let was = self.coord.status();
        let b = self.b_heard.then_some(&self.b.bolter_aux);
        let o = self
            .coord
            .step(&self.cfg.bolter, now, &self.side_a.aux(), b);
        let order = o.order;
        self.side_a
            .order(order.map_or(0, |(s, _)| s), order.map(|(_, o)| o), now);
        if let (Some(p), coordinator::Status::Running) = (o.active, o.status) {
            if let Some((q, attempts)) = self.pair.filter(|(q, _)| *q != p) {
                out.push(Event::Pair {
                    pair: q,
                    attempts,
                    ok: true,
                });
            }
            self.pair = Some((p, o.attempt.get()));
        }
        if was == coordinator::Status::Running && o.status != coordinator::Status::Running {
            let ok = o.status == coordinator::Status::Done;
            if let Some((pair, attempts)) = self.pair.take() {
                out.push(Event::Pair { pair, attempts, ok });
            }
            match o.status {
                coordinator::Status::Failed(f) => {
                    *faults = faults.with(f);
                    out.push(Event::Bolting(Some(f)));
                }
                _ => out.push(Event::Bolting(None)),
            }
        }
    }

    fn stop_all(&mut self, now: u32) {
        self.runner = None;
        self.pair = None;
        self.pair = None;
        self.coord.stop();
        self.waiting_job = None;
        self.side_a.order(0, None, now);
        self.targets.arm = PerSide::new(
            ServoTarget::Position(self.arm.now()),
            ServoTarget::Position(self.b.arm_b_now),
        );
        self.targets.gripper = PerSide::new(
            ServoTarget::Position(self.gripper.now()),
            ServoTarget::Position(self.b.gripper_b_now),
        );
        self.contracting = false;
    }

    fn go_home(&mut self, now: u32) {
        let _ = now;
        self.targets = Targets {
            hip: self.cfg.safety.hip_home,
            ..Targets::home()
        };
    }

    fn arm_targets(&mut self, now: u32) {
        let arm = self.cfg.arm.resolve(self.targets.arm.a);
        if self.arm.target() != arm {
            self.arm.set_target(arm, now);
        }
        let gripper = self.cfg.gripper.resolve(self.targets.gripper.a);
        if self.gripper.target() != gripper {
            self.gripper.set_target(gripper, now);
        }
    }

    fn b_command(
        &mut self,
        now: u32,
        p: ModuleSet,
        regulator: bool,
    ) -> Option<[u8; B_COMMAND_LEN]> {
        let order = self.coord.order();
        let last_seq = self.b_sent.map_or(0, |(_, c)| c.seq);
        let live = self.sup.mode() != Mode::Standby;
        let cmd = BCommandRepr {
            // The coordinator's order number while an order runs (B records the packet's
            // number with the order); otherwise the last number sent.
            seq: order.map_or(last_seq, |(s, _)| s),
            power: BPower {
                regulator,
                arm: live && p.contains(Module::ArmB),
                gripper: live && p.contains(Module::GripperB),
                bolter: live && p.contains(Module::BolterB),
            },
            stop: self.sup.stopped() || self.sup.mode() == Mode::Safed,
            arm_target: self.cfg.arm.resolve(self.targets.arm.b),
            gripper_target: self.cfg.gripper.resolve(self.targets.gripper.b),
            bolter: order.map(|(_, o)| o),
        };
        let due = match self.b_sent {
            None => true,
            Some((t, last)) => {
                last != cmd || Instant::from_millis(now).since(t).millis() >= self.cfg.b_period_ms
            }
        };
        if !due {
            return None;
        }
        self.b_sent = Some((Instant::from_millis(now), cmd));
        self.comm.sent(cmd.seq);
        Some(cmd.to_bytes())
    }

    fn heartbeat(&self, inp: &Inputs, faults: &Faults) -> HeartbeatRepr {
        let (last_seq, _) = self.log.last();
        let o = self.coord.order();
        HeartbeatRepr {
            board: self.cfg.board,
            hip_target: self.targets.hip,
            hip_now: inp.hip,
            arm_a_target: self.arm.target(),
            arm_a_now: self.arm.now(),
            arm_b_target: self.b.arm_b_target,
            arm_b_now: self.b.arm_b_now,
            gripper_a_target: self.gripper.target(),
            gripper_a_now: self.gripper.now(),
            gripper_b_target: self.b.gripper_b_target,
            gripper_b_now: self.b.gripper_b_now,
            electrical_a: inp.electrical,
            electrical_b: self.b.electrical_b,
            target_state: self.target_state,
            command_complete: self.complete,
            active_bolter: o.map(|(_, o)| o.pair),
            bolter_attempt: match (o, BolterAttempt::new(self.coord.attempt())) {
                (Some(_), Ok(a)) => a,
                _ => BolterAttempt::NONE,
            },
            faults: *faults,
            refusal: self.refusal,
            mode: self.sup.mode(),
            last_seq,
        }
    }
}

/// This tick's command after the exactly-once log: what the supervisor judges, and the number
/// the heartbeat answers (0 for a copy, whose outcome the log already holds).
#[derive(Debug, Clone, Copy, Default)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
struct Taken {
    incoming: Option<Incoming>,
    answer: Option<u16>,
}

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
