//! The fault swarm's invariants, watched on every tick of a virtual-time run
//! ([`super::run_watched`]). Each is judged from what the engine sees, not from what the
//! firmware reports about itself: which sender wrote the command packet board A took, where
//! the plant's grippers physically are, what board A drives and what moves in the plant.
//!
//! * **No command admitted twice** (so none executed twice): every command packet a sender
//!   writes (the ground's plan runner, or with PUS the gateway) is numbered by the engine the
//!   first time its bytes are written (a resend has the same bytes). A packet board A takes
//!   and admits (an `executed` event: run, or refused after judging) is traced back to that
//!   number; a number admitted twice is a violation, whatever sequence number the packet
//!   carried.
//! * **A gripper holds the lattice during a motion**: at every board A tick while board A is in
//!   motion, at least one of the plant's two grippers is at its closed pulse (within
//!   [`GRIP_TOLERANCE_US`]).
//! * **Nothing moves in Standby**: at every tick board A is in Standby, board A drives nothing
//!   (regulator off, no servo pulse, bolter idle); from [`STANDBY_GRACE_MS`] after it entered
//!   Standby, no servo of either side moves in the plant and no bolter is driven (board B
//!   learns of the mode through board A's next command, at most one B period later).
//! * **A fault reaches its Table 8 mode**: a fault raised while Operational takes the robot to
//!   Safed or Standby in the same tick as `mmic::safety::policy::fault_action` (Table 8) says;
//!   a deferred one (low battery, assembly system) keeps Operational while the motion runs and
//!   gives Standby in the tick the motion ends. A fault raised in Safed or Standby never
//!   raises power. A mode command board A takes in the same tick sets the mode the faults act
//!   on (Standby to Operational stops at Safed when the hip check on the way in fails, as Table
//!   8 says; the operator's Standby in the tick a Safed fault comes up stays Standby).
//! * **Every command ends**: at the end of the run, every command the ground sent is done
//!   (accepted, refused or reported unacknowledged), except one sent less than its longest
//!   life (attempts × period + answer window) before the end.
//!
//! Injected faults being raised, and no panic, are judged by the swarm from the run's outcome
//! ([`crate::swarm`]).

use crate::sim::plant::Plant;
use crate::sim::SimConfig;
use mmic::bolter::Drive;
use mmic::control::interp::Travel;
use mmic::faults::{Fault, Faults};
use mmic::mode::Mode;
use mmic::node::robot::board_a::{self, BoardA, Event};
use mmic::safety::policy::fault_action;
use mmic::wire::command::COMMAND_LEN;
use std::collections::HashMap;

/// A gripper within this of its closed pulse holds the face, µs.
pub const GRIP_TOLERANCE_US: f64 = 20.0;
/// How long after entering Standby side B and the plant may still be moving, ms: board B hears
/// of the mode within one A→B period (50 ms) plus the line's latency and a tick, and a
/// servo stops at once when unpowered.
pub const STANDBY_GRACE_MS: u32 = 100;
/// How long after board A goes down side B may still be moving, beyond the Standby grace, ms:
/// board B holds once A has been silent past its link timeout (board B's default, 500 ms)
/// and a tick.
pub const RESTART_GRACE_MS: u32 = 500 + 10;

/// The invariants.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub enum Invariant {
    /// A command packet admitted twice by board A.
    ExecutedTwice,
    /// Both grippers open during a motion.
    GripperOpenInMotion,
    /// Something driven or moving in Standby.
    MovedInStandby,
    /// A fault did not reach its Table 8 mode (or raised power).
    FaultMode,
    /// A command the ground sent never ended.
    CommandLost,
    /// An injected fault the firmware must see was not raised in time.
    InjectedFaultMissed,
    /// With SDLS: a TC frame that did not verify reached FARM-1 (an attack frame passed), or
    /// the server board verified more TC frames than the ground protected.
    ForgedFrame,
    /// The run panicked.
    Panic,
}

impl Invariant {
    /// Every invariant, in the order reports list them.
    pub const ALL: [Invariant; 8] = [
        Invariant::ExecutedTwice,
        Invariant::GripperOpenInMotion,
        Invariant::MovedInStandby,
        Invariant::FaultMode,
        Invariant::CommandLost,
        Invariant::InjectedFaultMissed,
        Invariant::ForgedFrame,
        Invariant::Panic,
    ];

    /// Its name in reports.
    pub const fn name(self) -> &'static str {
        match self {
            Invariant::ExecutedTwice => "executed-twice",
            Invariant::GripperOpenInMotion => "gripper-open-in-motion",
            Invariant::MovedInStandby => "moved-in-standby",
            Invariant::FaultMode => "fault-mode",
            Invariant::CommandLost => "command-lost",
            Invariant::InjectedFaultMissed => "injected-fault-missed",
            Invariant::ForgedFrame => "forged-frame",
            Invariant::Panic => "panic",
        }
    }
}

/// One broken invariant.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Violation {
    /// Simulated time, ms.
    pub t_ms: u32,
    /// The robot (0-based).
    pub robot: usize,
    /// Which invariant.
    pub invariant: Invariant,
    /// What was seen.
    pub detail: String,
}

/// How many times each invariant was checked (its opportunities), for reports.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct Checked {
    /// Commands admitted (each traced to its sender's packet).
    pub admissions: u64,
    /// Board A ticks in motion (grippers checked).
    pub motion_ticks: u64,
    /// Ticks in Standby (board A's outputs checked; the plant after the grace).
    pub standby_ticks: u64,
    /// Faults raised (their mode checked).
    pub faults_raised: u64,
    /// Commands the ground sent and saw end.
    pub commands_ended: u64,
    /// With SDLS and an attacker: attack frames judged (each refused, or a violation).
    pub attack_frames: u64,
    /// Restarts of board A watched through.
    pub restarts: u64,
    /// Commands board A admitted a second time (or more): each such admission counts, every
    /// one (the violations keep only the first few).
    pub executed_twice: u64,
}

/// What board A drives (its outputs that power something).
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct Driven {
    /// The 7.4 V regulator.
    pub regulator: bool,
    /// A hip pulse.
    pub hip: bool,
    /// An arm pulse.
    pub arm: bool,
    /// A gripper pulse.
    pub gripper: bool,
    /// The bolter motor, other than idle.
    pub bolter: bool,
}

impl Driven {
    /// Board A's outputs, as what they drive.
    pub fn of(out: &board_a::Outputs) -> Driven {
        Driven {
            regulator: out.regulator,
            hip: out.hip.is_some(),
            arm: out.arm.is_some(),
            gripper: out.gripper.is_some(),
            bolter: out.bolter != Drive::Idle,
        }
    }

    /// Anything at all.
    pub fn any(&self) -> bool {
        self.regulator || self.hip || self.arm || self.gripper || self.bolter
    }
}

/// What moves on one side of the plant.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct SideMotion {
    /// The arm servo moved in the last step of the physics.
    pub arm: bool,
    /// The gripper servo moved.
    pub gripper: bool,
    /// What the bolter motor does.
    pub bolter: Drive,
}

impl SideMotion {
    /// Side `side` of `plant`.
    pub fn of(plant: &Plant, side: usize) -> SideMotion {
        let (arm, gripper) = plant.moving(side);
        SideMotion {
            arm,
            gripper,
            bolter: plant.bolter_drive(side),
        }
    }
}

/// One board A tick as the watch needs it.
#[derive(Debug, Clone)]
pub struct TickA {
    /// The command packet the control task took from the hand-off queue.
    pub command: Option<[u8; COMMAND_LEN]>,
    /// Board A admitted it (an `executed` event: run, or refused after judging).
    pub admitted: bool,
    /// The command board A admitted and accepted (ran) this tick, if any.
    pub accepted: Option<mmic::command::Command>,
    /// Board A's mode, faults and motion after the tick.
    pub mode: Mode,
    /// Its latched faults.
    pub faults: Faults,
    /// In motion.
    pub in_motion: bool,
    /// What board A drives.
    pub driven: Driven,
    /// The plant's gripper pulses, sides A and B, µs.
    pub grippers: [f64; 2],
    /// What moves on side A.
    pub side: SideMotion,
}

impl TickA {
    /// The tick that took `command` and gave `out`, with board A and the plant as it left them.
    pub fn of(
        command: Option<[u8; COMMAND_LEN]>,
        a: &BoardA,
        plant: &Plant,
        out: &board_a::Outputs,
    ) -> TickA {
        TickA {
            command,
            admitted: out
                .events
                .iter()
                .any(|e| matches!(e, Event::Executed { .. })),
            accepted: out.events.iter().find_map(|e| match e {
                Event::Executed {
                    command,
                    refusal: None,
                    ..
                } => *command,
                _ => None,
            }),
            mode: a.mode(),
            faults: a.faults(),
            in_motion: a.in_motion(),
            driven: Driven::of(out),
            grippers: [plant.servos(0).1, plant.servos(1).1],
            side: SideMotion::of(plant, 0),
        }
    }
}

#[derive(Debug, Default)]
struct RobotWatch {
    origins: HashMap<[u8; COMMAND_LEN], u64>,
    next_origin: u64,
    /// Origin → when first admitted, ms.
    admitted: HashMap<u64, u32>,
    last_faults: Faults,
    last_mode: Option<Mode>,
    standby_since: Option<u32>,
    /// Deferred faults raised in motion, waiting for the motion's end: since when.
    deferred_since: Option<u32>,
}

/// What the engine watched in one run.
#[derive(Debug)]
pub struct Watch {
    robots: Vec<RobotWatch>,
    /// The longest a command can stay outstanding, ms.
    command_life_ms: u32,
    gripper_closed_us: f64,
    /// Every violation, in the order seen.
    pub violations: Vec<Violation>,
    /// The opportunities each invariant had.
    pub checked: Checked,
    /// Per robot: the faults board A raised, with the time, in order.
    pub raised: Vec<Vec<(u32, Fault)>>,
    /// Per robot: board A's latched faults from each time on (a row per change), in order.
    pub faults: Vec<Vec<(u32, Faults)>>,
}

impl Watch {
    /// Watching `n` robots of a run of `cfg`.
    pub fn new(cfg: &SimConfig, n: usize) -> Watch {
        Watch {
            robots: (0..n).map(|_| RobotWatch::default()).collect(),
            command_life_ms: cfg.command_life_ms(),
            gripper_closed_us: Travel::GRIPPER.extended.micros() as f64,
            violations: Vec::new(),
            checked: Checked::default(),
            raised: vec![Vec::new(); n],
            faults: vec![Vec::new(); n],
        }
    }

    fn violation(&mut self, t_ms: u32, robot: usize, invariant: Invariant, detail: String) {
        // One report per invariant and robot is enough to fail a run; keep the first few.
        let seen = self
            .violations
            .iter()
            .filter(|v| v.robot == robot && v.invariant == invariant)
            .count();
        if seen < 3 {
            self.violations.push(Violation {
                t_ms,
                robot,
                invariant,
                detail,
            });
        }
    }

    /// With SDLS: an attack frame on robot `i`'s uplink reached FARM-1.
    pub fn forged(&mut self, i: usize, now: u32, detail: String) {
        self.violation(now, i, Invariant::ForgedFrame, detail);
    }

    /// With SDLS: an attack frame on robot `i`'s uplink was judged (refused, or [`Watch::forged`]).
    pub fn attack_judged(&mut self) {
        self.checked.attack_frames += 1;
    }

    /// With SDLS, at the end of a run: robot `i`'s server board verified `verified` TC frames,
    /// its ground protected `protected`; every verified frame must be one the ground sent.
    pub fn sdls_checked(&mut self, i: usize, now: u32, verified: u64, protected: u64) {
        if verified > protected {
            self.violation(
                now,
                i,
                Invariant::ForgedFrame,
                format!("SDLS verified {verified} TC frames, the ground protected {protected}"),
            );
        }
    }

    /// A sender (the ground, or the gateway) writes command packet `bytes` for robot `i`.
    pub fn commanded(&mut self, i: usize, bytes: &[u8]) {
        let Ok(p) = <[u8; COMMAND_LEN]>::try_from(bytes) else {
            return;
        };
        let r = &mut self.robots[i];
        if !r.origins.contains_key(&p) {
            r.next_origin += 1;
            r.origins.insert(p, r.next_origin);
        }
    }

    /// A shell turned packet `original` into `copy` (the same command, other bytes).
    pub fn same_origin(
        &mut self,
        i: usize,
        original: &[u8; COMMAND_LEN],
        copy: &[u8; COMMAND_LEN],
    ) {
        let r = &mut self.robots[i];
        if let Some(o) = r.origins.get(original).copied() {
            r.origins.insert(*copy, o);
        }
    }

    /// Board A's control tick at `now`, as the engine saw it ([`TickA`]).
    pub fn tick_a(&mut self, i: usize, now: u32, t: &TickA) {
        self.admissions(i, now, t.command.as_ref(), t.admitted);
        // A mode command taken this tick changes the mode the faults act on: Standby to
        // Operational, held at Safed by a fault found on the way in (Table 8's hip mismatch
        // is checked on entering Operational); Operational to Standby by the operator in the
        // tick a Safed fault comes up, which leaves the robot in Standby (a fault never raises
        // power).
        let commanded = match t.accepted {
            Some(mmic::command::Command::Mode(m)) => Some(m),
            _ => None,
        };
        self.fault_modes(i, now, t.faults, t.mode, t.in_motion, commanded);
        if t.in_motion {
            self.checked.motion_ticks += 1;
            let closed = |g: f64| (g - self.gripper_closed_us).abs() <= GRIP_TOLERANCE_US;
            let [ga, gb] = t.grippers;
            if !closed(ga) && !closed(gb) {
                self.violation(
                    now,
                    i,
                    Invariant::GripperOpenInMotion,
                    format!(
                        "both grippers open in motion: A at {ga:.0} us, B at {gb:.0} us (closed: {:.0} us)",
                        self.gripper_closed_us
                    ),
                );
            }
        }
        if t.mode == Mode::Standby {
            let since = *self.robots[i].standby_since.get_or_insert(now);
            self.checked.standby_ticks += 1;
            if t.driven.any() {
                self.violation(
                    now,
                    i,
                    Invariant::MovedInStandby,
                    format!("board A drives in Standby: {:?}", t.driven),
                );
            }
            self.still(i, now, since, &t.side, 0);
        } else {
            self.robots[i].standby_since = None;
        }
    }

    /// Board A restarted at `now` (it comes up in Standby): nothing may move from when board
    /// B, no longer hearing A, holds its side ([`RESTART_GRACE_MS`]).
    pub fn restarted_a(&mut self, i: usize, now: u32) {
        self.robots[i].standby_since = Some(now.saturating_add(RESTART_GRACE_MS));
        self.robots[i].last_mode = Some(Mode::Standby);
        self.checked.restarts += 1;
    }

    /// Board B's tick at `now`: side B of the plant as it left it.
    pub fn tick_b(&mut self, i: usize, now: u32, side: &SideMotion) {
        if let Some(since) = self.robots[i].standby_since {
            self.still(i, now, since, side, 1);
        }
    }

    fn still(&mut self, i: usize, now: u32, since: u32, m: &SideMotion, side: usize) {
        if now < since.saturating_add(STANDBY_GRACE_MS) {
            return;
        }
        if m.arm || m.gripper || m.bolter != Drive::Idle {
            self.violation(
                now,
                i,
                Invariant::MovedInStandby,
                format!(
                    "side {} moves {} ms into Standby: {m:?}",
                    if side == 0 { "A" } else { "B" },
                    now - since
                ),
            );
        }
    }

    fn admissions(
        &mut self,
        i: usize,
        now: u32,
        command: Option<&[u8; COMMAND_LEN]>,
        admitted: bool,
    ) {
        let (Some(p), true) = (command, admitted) else {
            return;
        };
        self.checked.admissions += 1;
        let r = &mut self.robots[i];
        let Some(origin) = r.origins.get(p).copied() else {
            self.violation(
                now,
                i,
                Invariant::ExecutedTwice,
                format!(
                    "board A admitted a command no sender wrote: {}",
                    crate::sim::log::hex(p)
                ),
            );
            return;
        };
        // Nothing but a Heartbeat poll may run twice (`BoardA::may_run_again`).
        let exempt = mmic::wire::command::CommandRepr::parse(p)
            .is_ok_and(|c| mmic::node::robot::board_a::BoardA::may_run_again(Some(c.command)));
        if exempt {
            return;
        }
        if let Some(first) = r.admitted.insert(origin, now) {
            r.admitted.insert(origin, first);
            self.checked.executed_twice += 1;
            let what = mmic::wire::command::CommandRepr::parse(p)
                .map(|c| format!("{:?} (this copy numbered {})", c.command, c.seq))
                .unwrap_or_else(|e| e.to_string());
            self.violation(
                now,
                i,
                Invariant::ExecutedTwice,
                format!("command {what} admitted at {first} ms and again at {now} ms"),
            );
        }
    }

    /// Robot `i`'s fault set and mode at `now` remembered; the faults raised since the last
    /// tick returned (and counted, and logged with their time).
    fn record_faults(&mut self, i: usize, now: u32, faults: Faults, mode: Mode) -> Vec<Fault> {
        let r = &mut self.robots[i];
        // Most ticks raise nothing: the set compared before any list is made.
        let new: Vec<Fault> = if faults == r.last_faults {
            Vec::new()
        } else {
            faults
                .iter()
                .filter(|f| !r.last_faults.contains(*f))
                .collect()
        };
        r.last_faults = faults;
        r.last_mode = Some(mode);
        if self.faults[i].last().map(|(_, f)| *f) != Some(faults) {
            self.faults[i].push((now, faults));
        }
        for f in &new {
            self.raised[i].push((now, *f));
        }
        self.checked.faults_raised += new.len() as u64;
        new
    }

    fn fault_modes(
        &mut self,
        i: usize,
        now: u32,
        faults: Faults,
        mode: Mode,
        in_motion: bool,
        commanded: Option<Mode>,
    ) {
        let before = commanded.or(self.robots[i].last_mode).unwrap_or(mode);
        let deferred_since = self.robots[i].deferred_since;
        let new = self.record_faults(i, now, faults, mode);
        let expect = |f: &Fault| fault_action(*f);
        match before {
            Mode::Operational if !new.is_empty() => {
                let safed = new
                    .iter()
                    .any(|f| !expect(f).deferred && expect(f).mode == Mode::Safed);
                let standby = new
                    .iter()
                    .any(|f| !expect(f).deferred && expect(f).mode == Mode::Standby);
                let want = if safed {
                    Some(Mode::Safed)
                } else if standby {
                    Some(Mode::Standby)
                } else if in_motion {
                    self.robots[i].deferred_since.get_or_insert(now);
                    Some(Mode::Operational)
                } else {
                    Some(Mode::Standby)
                };
                if let Some(w) = want.filter(|w| *w != mode) {
                    self.violation(
                        now,
                        i,
                        Invariant::FaultMode,
                        format!(
                            "{new:?} raised in Operational{}: {mode:?}, Table 8 says {w:?}",
                            if commanded.is_some() {
                                " (commanded this tick)"
                            } else {
                                ""
                            }
                        ),
                    );
                }
            }
            Mode::Safed | Mode::Standby if !new.is_empty() => {
                let raised = matches!(
                    (before, mode),
                    (Mode::Standby, Mode::Safed | Mode::Operational)
                        | (Mode::Safed, Mode::Operational)
                );
                if raised {
                    self.violation(
                        now,
                        i,
                        Invariant::FaultMode,
                        format!(
                            "{new:?} raised in {before:?} raised power: {mode:?}{}",
                            if commanded.is_some() {
                                " (mode commanded this tick)"
                            } else {
                                ""
                            }
                        ),
                    );
                }
            }
            _ => {}
        }
        // A deferred fault waits for the motion's end, then gives Standby.
        if let Some(since) = deferred_since {
            if mode != Mode::Operational {
                self.robots[i].deferred_since = None;
            } else if !in_motion {
                self.robots[i].deferred_since = None;
                self.violation(
                    now,
                    i,
                    Invariant::FaultMode,
                    format!("a deferred fault raised at {since} ms: the motion ended and the robot is still Operational"),
                );
            }
        }
    }

    /// The run ended at `now`: robot `i`'s commands still open (number, first sent, ms).
    pub fn finish(&mut self, i: usize, now: u32, open: &[(u16, u32)]) {
        for &(seq, sent) in open {
            if now.saturating_sub(sent) > self.command_life_ms {
                self.violation(
                    now,
                    i,
                    Invariant::CommandLost,
                    format!(
                        "command {seq} first sent at {sent} ms never ended ({} ms; its longest life is {} ms)",
                        now - sent,
                        self.command_life_ms
                    ),
                );
            }
        }
    }

    /// Commands that ended (counted by the swarm from the ground's `done` events).
    pub fn ended(&mut self, n: u64) {
        self.checked.commands_ended += n;
    }

    /// Whether robot `i`'s board A had `fault` latched at some tick in `[from, to]` (ms).
    pub fn had(&self, i: usize, fault: Fault, from: u32, to: u32) -> bool {
        let h = &self.faults[i];
        // The set in force at `from`, and every change up to `to`.
        let before = h.iter().rev().find(|(t, _)| *t <= from);
        before
            .into_iter()
            .chain(h.iter().filter(|(t, _)| *t > from && *t <= to))
            .any(|(_, f)| f.contains(fault))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use mmic::command::Command;
    use mmic::units::BoardNumber;
    use mmic::wire::command::CommandRepr;

    const CLOSED: f64 = 2000.0;
    const OPEN: f64 = 1000.0;

    fn watch() -> Watch {
        Watch::new(&SimConfig::demo(), 1)
    }

    fn still() -> SideMotion {
        SideMotion {
            arm: false,
            gripper: false,
            bolter: Drive::Idle,
        }
    }

    fn tick(mode: Mode) -> TickA {
        TickA {
            command: None,
            admitted: false,
            accepted: None,
            mode,
            faults: Faults::EMPTY,
            in_motion: false,
            driven: Driven::default(),
            grippers: [CLOSED, CLOSED],
            side: still(),
        }
    }

    fn kinds(w: &Watch) -> Vec<Invariant> {
        w.violations.iter().map(|v| v.invariant).collect()
    }

    fn packet(seq: u16) -> [u8; COMMAND_LEN] {
        CommandRepr {
            board: BoardNumber::ONE,
            command: Command::Stop,
            seq,
        }
        .to_bytes()
    }

    #[test]
    fn a_packet_admitted_twice_is_caught_whatever_its_number() {
        let mut w = watch();
        let (p, copy) = (packet(7), packet(0));
        w.commanded(0, &p);
        let mut t = tick(Mode::Operational);
        t.command = Some(p);
        t.admitted = true;
        w.tick_a(0, 10, &t);
        // A copy answered from the log (not admitted) is no execution.
        t.admitted = false;
        w.tick_a(0, 20, &t);
        assert!(w.violations.is_empty());
        // The same command again under another number (a shell that stripped it).
        w.same_origin(0, &p, &copy);
        t.command = Some(copy);
        t.admitted = true;
        w.tick_a(0, 30, &t);
        assert_eq!(kinds(&w), [Invariant::ExecutedTwice]);
        assert!(w.violations[0]
            .detail
            .contains("at 10 ms and again at 30 ms"));
        assert_eq!(w.checked.admissions, 2);
        // A packet nobody wrote.
        let mut w = watch();
        t.command = Some(packet(9));
        w.tick_a(0, 10, &t);
        assert_eq!(kinds(&w), [Invariant::ExecutedTwice]);
    }

    #[test]
    fn both_grippers_open_in_motion_is_caught_one_is_not() {
        let mut w = watch();
        let mut t = tick(Mode::Operational);
        t.in_motion = true;
        t.grippers = [OPEN, CLOSED - GRIP_TOLERANCE_US];
        w.tick_a(0, 10, &t);
        t.grippers = [CLOSED + 5.0, OPEN];
        w.tick_a(0, 20, &t);
        assert!(w.violations.is_empty());
        t.grippers = [OPEN, CLOSED - GRIP_TOLERANCE_US - 1.0];
        w.tick_a(0, 30, &t);
        assert_eq!(kinds(&w), [Invariant::GripperOpenInMotion]);
        // Outside a motion, the grippers are the operator's.
        let mut w = watch();
        t.in_motion = false;
        w.tick_a(0, 10, &t);
        assert!(w.violations.is_empty());
    }

    // req: P7.3
    #[test]
    fn standby_drives_nothing_and_nothing_moves_after_the_grace() {
        let mut w = watch();
        let mut t = tick(Mode::Standby);
        t.side.arm = true; // still settling: within the grace
        w.tick_a(0, 1_000, &t);
        w.tick_b(0, 1_000 + STANDBY_GRACE_MS - 1, &t.side);
        assert!(w.violations.is_empty());
        w.tick_b(0, 1_000 + STANDBY_GRACE_MS, &t.side);
        assert_eq!(kinds(&w), [Invariant::MovedInStandby]);
        // Board A driving anything in Standby, at once.
        let mut w = watch();
        let mut t = tick(Mode::Standby);
        t.driven.regulator = true;
        w.tick_a(0, 10, &t);
        assert_eq!(kinds(&w), [Invariant::MovedInStandby]);
        // The same outputs in Operational are fine.
        let mut w = watch();
        t.mode = Mode::Operational;
        t.side.bolter = Drive::Rotate;
        w.tick_a(0, 10, &t);
        assert!(w.violations.is_empty());
    }

    // req: T8/*
    #[test]
    fn a_fault_must_reach_its_table8_mode_in_its_tick() {
        // Safed fault in Operational: Safed at once.
        let mut w = watch();
        let mut t = tick(Mode::Operational);
        w.tick_a(0, 10, &t);
        t.faults = Faults::EMPTY.with(Fault::InternalCommLoss);
        w.tick_a(0, 20, &t);
        assert_eq!(kinds(&w), [Invariant::FaultMode]);
        let mut w = watch();
        w.tick_a(0, 10, &tick(Mode::Operational));
        t.mode = Mode::Safed;
        w.tick_a(0, 20, &t);
        assert!(w.violations.is_empty());
        assert_eq!(w.raised[0], [(20, Fault::InternalCommLoss)]);
        // Safed and Standby faults together: Safed.
        let mut w = watch();
        w.tick_a(0, 10, &tick(Mode::Operational));
        t.faults = t.faults.with(Fault::BoltingFailure);
        t.mode = Mode::Standby;
        w.tick_a(0, 20, &t);
        assert_eq!(kinds(&w), [Invariant::FaultMode]);
    }

    // req: P7.13
    #[test]
    fn a_deferred_fault_waits_for_the_motion_then_gives_standby() {
        let mut moving = tick(Mode::Operational);
        moving.in_motion = true;
        let mut low = moving.clone();
        low.faults = Faults::EMPTY.with(Fault::LowBattery);
        // Raised in motion: Operational until the motion ends, Standby then.
        let mut w = watch();
        w.tick_a(0, 10, &moving);
        w.tick_a(0, 20, &low);
        w.tick_a(0, 30, &low);
        let mut end = low.clone();
        end.in_motion = false;
        end.mode = Mode::Standby;
        w.tick_a(0, 40, &end);
        assert!(w.violations.is_empty(), "{:?}", w.violations);
        // The motion ends and the robot stays Operational: caught.
        let mut w = watch();
        w.tick_a(0, 10, &moving);
        w.tick_a(0, 20, &low);
        end.mode = Mode::Operational;
        w.tick_a(0, 30, &end);
        assert_eq!(kinds(&w), [Invariant::FaultMode]);
        // Going to Standby at once, mid-motion: caught too.
        let mut w = watch();
        w.tick_a(0, 10, &moving);
        low.mode = Mode::Standby;
        w.tick_a(0, 20, &low);
        assert_eq!(kinds(&w), [Invariant::FaultMode]);
    }

    #[test]
    fn a_fault_in_safed_or_standby_never_raises_power_a_mode_command_may() {
        let mut w = watch();
        w.tick_a(0, 10, &tick(Mode::Safed));
        let mut t = tick(Mode::Operational);
        t.faults = Faults::EMPTY.with(Fault::LowBattery);
        w.tick_a(0, 20, &t);
        assert_eq!(kinds(&w), [Invariant::FaultMode]);
        // Standby, the operator asks for Operational, the hip check fails on the way in: Safed.
        let mut w = watch();
        w.tick_a(0, 10, &tick(Mode::Standby));
        let mut t = tick(Mode::Safed);
        t.faults = Faults::EMPTY.with(Fault::HipMismatch);
        w.tick_a(0, 20, &t);
        assert_eq!(
            kinds(&w),
            [Invariant::FaultMode],
            "no command: the fault raised power"
        );
        let mut w = watch();
        w.tick_a(0, 10, &tick(Mode::Standby));
        t.accepted = Some(mmic::command::Command::Mode(Mode::Operational));
        w.tick_a(0, 20, &t);
        assert!(w.violations.is_empty(), "{:?}", w.violations);
        // Operational, the operator's Standby and a Safed fault in one tick: Standby.
        let mut w = watch();
        w.tick_a(0, 10, &tick(Mode::Operational));
        let mut t = tick(Mode::Standby);
        t.faults = Faults::EMPTY.with(Fault::InternalCommLoss);
        t.accepted = Some(mmic::command::Command::Mode(Mode::Standby));
        w.tick_a(0, 20, &t);
        assert!(w.violations.is_empty(), "{:?}", w.violations);
        // ... but not Operational.
        let mut w = watch();
        w.tick_a(0, 10, &tick(Mode::Operational));
        t.mode = Mode::Operational;
        w.tick_a(0, 20, &t);
        assert_eq!(kinds(&w), [Invariant::FaultMode]);
    }

    #[test]
    fn a_command_older_than_its_longest_life_is_lost() {
        let mut w = watch();
        let life = w.command_life_ms;
        w.finish(0, 100_000, &[(3, 100_000 - life)]);
        assert!(w.violations.is_empty());
        w.finish(0, 100_000, &[(3, 100_000 - life - 1)]);
        assert_eq!(kinds(&w), [Invariant::CommandLost]);
    }

    #[test]
    fn the_fault_history_answers_what_was_latched_when() {
        let mut w = watch();
        let mut t = tick(Mode::Safed);
        w.tick_a(0, 10, &t);
        t.faults = Faults::EMPTY.with(Fault::SensorLoss);
        w.tick_a(0, 500, &t);
        t.faults = Faults::EMPTY;
        w.tick_a(0, 900, &t);
        assert!(w.had(0, Fault::SensorLoss, 400, 600));
        assert!(w.had(0, Fault::SensorLoss, 600, 700), "latched since 500");
        assert!(!w.had(0, Fault::SensorLoss, 900, 2_000), "cleared at 900");
        assert!(!w.had(0, Fault::SensorLoss, 0, 499));
        assert!(!w.had(0, Fault::LowBattery, 0, 2_000));
    }
}
