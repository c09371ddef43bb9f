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
//!   raises power.
//! * **Every command ends**: at the end of the run, every command the ground sent is done
//!   (accepted, refused or reported unacknowledged), except one sent less than its longest
//!   life (attempts × period + answer window) before the end.
//!
//! Injected faults being raised, and no panic, are judged by the swarm from the run's outcome
//! ([`crate::swarm`]).

use super::link::Fate;
use super::SimConfig;
use crate::sim::plant::Plant;
use mmic::bolter::Drive;
use mmic::control::interp::Travel;
use mmic::faults::{Fault, Faults};
use mmic::mode::Mode;
use mmic::node::board_a::{self, BoardA, Event};
use mmic::safety::policy::fault_action;
use mmic::wire::command::COMMAND_LEN;
use std::collections::HashMap;

/// A gripper within this of its closed pulse holds the face, µs.
pub const GRIP_TOLERANCE_US: f64 = 20.0;
/// How long after entering Standby side B and the plant may still be moving, ms: board B hears
/// of the mode within one A→B period (50 ms) plus the line's latency and a tick, and a
/// servo stops at once when unpowered.
pub const STANDBY_GRACE_MS: u32 = 100;

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
    /// The run panicked.
    Panic,
}

impl Invariant {
    /// Every invariant, in the order reports list them.
    pub const ALL: [Invariant; 7] = [
        Invariant::ExecutedTwice,
        Invariant::GripperOpenInMotion,
        Invariant::MovedInStandby,
        Invariant::FaultMode,
        Invariant::CommandLost,
        Invariant::InjectedFaultMissed,
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
    /// Per robot: packets lost or cut on the A–B line (either way), with the time, ms.
    pub ab_dropped: Vec<Vec<u32>>,
}

impl Watch {
    /// Watching `n` robots of a run of `cfg`.
    pub fn new(cfg: &SimConfig, n: usize) -> Watch {
        let (period, attempts, answer) = match cfg.protocol {
            super::Protocol::Legacy => (
                cfg.ground.period_ms,
                cfg.ground.max_attempts as u32,
                cfg.ground.timeout_ms,
            ),
            super::Protocol::Pus => (
                cfg.pus.timeout_ms,
                cfg.pus.max_attempts as u32,
                cfg.pus.timeout_ms,
            ),
        };
        Watch {
            robots: (0..n).map(|_| RobotWatch::default()).collect(),
            command_life_ms: period.saturating_mul(attempts).saturating_add(answer),
            gripper_closed_us: Travel::GRIPPER.extended.micros() as f64,
            violations: Vec::new(),
            checked: Checked::default(),
            raised: vec![Vec::new(); n],
            ab_dropped: vec![Vec::new(); n],
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

    /// A sender (the ground, or the gateway) writes command packet `bytes` for robot `i`.
    pub fn commanded(&mut self, i: usize, bytes: &[u8], _now_us: u64) {
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

    /// A packet written to robot `i`'s hop `hop` met `fate`.
    pub fn sent(&mut self, i: usize, hop: usize, fate: Fate, now_us: u64) {
        // Hops 4 and 5: A→B and B→A.
        if hop >= 4 && fate != Fate::Delivered {
            self.ab_dropped[i].push((now_us / 1000) as u32);
        }
    }

    /// Board A's control tick at `now` took `command` and gave `out`; `a` and `plant` are as
    /// the tick left them.
    pub fn tick_a(
        &mut self,
        i: usize,
        now: u32,
        command: Option<&[u8; COMMAND_LEN]>,
        a: &BoardA,
        plant: &Plant,
        out: &board_a::Outputs,
    ) {
        self.admissions(i, now, command, out);
        self.fault_modes(i, now, a);
        if a.in_motion() {
            self.checked.motion_ticks += 1;
            let closed = |side: usize| {
                (plant.servos(side).1 - self.gripper_closed_us).abs() <= GRIP_TOLERANCE_US
            };
            if !closed(0) && !closed(1) {
                let (ga, gb) = (plant.servos(0).1, plant.servos(1).1);
                self.violation(
                    now,
                    i,
                    Invariant::GripperOpenInMotion,
                    format!("both grippers open in motion: A at {ga:.0} us, B at {gb:.0} us (closed: {:.0})", self.gripper_closed_us),
                );
            }
        }
        let r = &mut self.robots[i];
        if a.mode() == Mode::Standby {
            let since = *r.standby_since.get_or_insert(now);
            self.checked.standby_ticks += 1;
            let driven = out.regulator
                || out.hip.is_some()
                || out.arm.is_some()
                || out.gripper.is_some()
                || out.bolter != Drive::Idle;
            if driven {
                self.violation(
                    now,
                    i,
                    Invariant::MovedInStandby,
                    format!(
                        "board A drives in Standby: regulator {}, hip {:?}, arm {:?}, gripper {:?}, bolter {:?}",
                        out.regulator, out.hip, out.arm, out.gripper, out.bolter
                    ),
                );
            }
            self.plant_still(i, now, since, plant, 0);
        } else {
            r.standby_since = None;
        }
    }

    /// Board B's tick at `now`, `plant` as it left it.
    pub fn tick_b(&mut self, i: usize, now: u32, plant: &Plant) {
        if let Some(since) = self.robots[i].standby_since {
            self.plant_still(i, now, since, plant, 1);
        }
    }

    fn plant_still(&mut self, i: usize, now: u32, since: u32, plant: &Plant, side: usize) {
        if now < since.saturating_add(STANDBY_GRACE_MS) {
            return;
        }
        let (arm, gripper) = plant.moving(side);
        let bolter = plant.bolter_drive(side);
        if arm || gripper || bolter != Drive::Idle {
            self.violation(
                now,
                i,
                Invariant::MovedInStandby,
                format!(
                    "side {} moves {} ms into Standby: arm moving {arm}, gripper moving {gripper}, bolter {bolter:?}",
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
        out: &board_a::Outputs,
    ) {
        let Some(p) = command else { return };
        let admitted = out
            .events
            .iter()
            .any(|e| matches!(e, Event::Executed { .. }));
        if !admitted {
            return;
        }
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
        if let Some(first) = r.admitted.insert(origin, now) {
            r.admitted.insert(origin, first);
            let what = mmic::wire::command::CommandRepr::parse(p)
                .map(|c| format!("{:?} (seq {})", c.command, c.seq))
                .unwrap_or_else(|e| e.to_string());
            self.violation(
                now,
                i,
                Invariant::ExecutedTwice,
                format!("command {what} admitted at {first} ms and again at {now} ms"),
            );
        }
    }

    fn fault_modes(&mut self, i: usize, now: u32, a: &BoardA) {
        let r = &mut self.robots[i];
        let (faults, mode) = (a.faults(), a.mode());
        let before = r.last_mode.unwrap_or(mode);
        let new: Vec<Fault> = faults
            .iter()
            .filter(|f| !r.last_faults.contains(*f))
            .collect();
        r.last_faults = faults;
        r.last_mode = Some(mode);
        let deferred_since = r.deferred_since;
        for f in &new {
            self.raised[i].push((now, *f));
        }
        self.checked.faults_raised += new.len() as u64;
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
                } else if a.in_motion() {
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
                        format!("{new:?} raised in Operational: {mode:?}, Table 8 says {w:?}"),
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
                        format!("{new:?} raised in {before:?} raised power: {mode:?}"),
                    );
                }
            }
            _ => {}
        }
        // A deferred fault waits for the motion's end, then gives Standby.
        if let Some(since) = deferred_since {
            if mode != Mode::Operational {
                self.robots[i].deferred_since = None;
            } else if !a.in_motion() {
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
    pub fn finish(&mut self, i: usize, now: u32, _a: &BoardA, open: &[(u16, u32)]) {
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
}
