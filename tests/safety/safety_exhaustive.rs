//! Exhaustive check of the mode supervisor over its whole finite input domain:
//! every start state (Standby, Safed, Operational idle / stopped / with a deferred fault
//! pending, each with the operator's power mask all-on or partial) × every command variant class
//! (61 opcodes, the two malformed-packet refusals, and no command) × every subset of the 13
//! faults × in-motion flag × hip-at-home × a reconfiguration's check on arrival (passed, arm
//! not contracted, initial state mismatch). Every property below is
//! asserted on every one of those steps; the test prints the domain size.

use mmic::arbitrary::for_each_variant_class;
use mmic::command::{Command, CommandKind, PowerTarget};
use mmic::faults::{Fault, Faults};
use mmic::mode::Mode;
use mmic::motion::estimate::InitialStateError;
use mmic::refusal::Refusal;
use mmic::safety::policy::{accepts, fault_action, is_condition, powered};
use mmic::safety::supervisor::{Answer, Incoming, Input, Supervisor};
use mmic::safety::ModuleSet;
use mmic::units::{HipAngle, Module, PulseWidth, Side};

fn cmd(c: Command) -> Input {
    Input {
        command: Some(Incoming::Command(c)),
        ..Input::quiet()
    }
}

/// Reachable start states, built through the public API only.
fn start_states() -> Vec<(&'static str, Supervisor)> {
    let mut v = Vec::new();
    let standby = Supervisor::new();
    v.push(("standby", standby));
    let mut s = Supervisor::new();
    s.step(&cmd(Command::Mode(Mode::Safed)));
    v.push(("safed", s));
    let mut op = Supervisor::new();
    op.step(&cmd(Command::Mode(Mode::Operational)));
    assert_eq!(op.mode(), Mode::Operational);
    v.push(("operational", op));
    let mut partial = op;
    partial.step(&cmd(Command::Power {
        target: PowerTarget::Module(Module::ArmA),
        on: false,
    }));
    partial.step(&cmd(Command::Power {
        target: PowerTarget::Module(Module::GripperB),
        on: false,
    }));
    v.push(("operational, arm A and gripper B off", partial));
    let mut safed_partial = partial;
    safed_partial.step(&cmd(Command::Mode(Mode::Safed)));
    v.push(("safed, arm A and gripper B off", safed_partial));
    let in_motion = |c| Input {
        in_motion: true,
        ..cmd(c)
    };
    let mut stopped = op;
    stopped.step(&in_motion(Command::Stop));
    assert!(stopped.stopped());
    v.push(("operational, a motion stopped", stopped));
    let mut held = op;
    held.step(&cmd(Command::Stop));
    assert!(!held.stopped(), "nothing moved: nothing kept");
    v.push(("operational, stopped while still", held));
    let mut safed_stopped = s;
    safed_stopped.step(&in_motion(Command::Stop));
    assert!(safed_stopped.stopped());
    v.push(("safed, a motion stopped", safed_stopped));
    let mut pending = op;
    pending.step(&Input {
        faults: Faults::EMPTY.with(Fault::LowBattery),
        in_motion: true,
        ..Input::quiet()
    });
    assert!(pending.standby_pending() && pending.mode() == Mode::Operational);
    v.push(("operational, standby pending", pending));
    v
}

fn incoming() -> Vec<Option<Incoming>> {
    let mut v = vec![
        None,
        Some(Incoming::Malformed(Refusal::UnknownCommand)),
        Some(Incoming::Malformed(Refusal::InvalidParameter)),
    ];
    for_each_variant_class(PulseWidth::CENTER, HipAngle::new(9000).unwrap(), |c| {
        v.push(Some(Incoming::Command(c)))
    });
    v
}

/// The mode Table 8 sends an Operational robot to for this set of faults, with no command.
fn table8_mode(faults: Faults, in_motion: bool) -> (Mode, bool) {
    let safed = faults.iter().any(|f| fault_action(f).mode == Mode::Safed);
    let standby_now = faults.iter().any(|f| {
        fault_action(f)
            == mmic::safety::policy::FaultAction {
                mode: Mode::Standby,
                deferred: false,
            }
    });
    let deferred = faults.iter().any(|f| fault_action(f).deferred);
    if safed {
        (Mode::Safed, false)
    } else if standby_now || (deferred && !in_motion) {
        (Mode::Standby, false)
    } else {
        (Mode::Operational, deferred)
    }
}

/// Every property of one step from `s0` on `input`; returns the state after it.
fn check_step(name: &str, s0: &Supervisor, input: &Input) -> Supervisor {
    let Input {
        faults,
        command: c,
        in_motion,
        hip_at_home,
        initial_state,
    } = *input;
    let c = &c;
    let power_before = powered(s0.mode(), s0.enabled());
    let mut s = *s0;
    let out = s.step(input);
    let ctx = || {
        format!("{name} {s0:?} / {c:?} / faults {faults:?} / motion {in_motion} / hip {hip_at_home} / init {initial_state:?}")
    };

    // Table 7 (spec/modes.toml [power]), as equalities: Standby powers
    // nothing, regulator off; Safed exactly the enabled ones among hip and
    // arms; Operational exactly the enabled modules; the regulator is on
    // outside Standby whenever anything is powered.
    let hip_and_arms = ModuleSet::EMPTY
        .with(Module::Hip)
        .with(Module::ArmA)
        .with(Module::ArmB);
    let want = match out.mode {
        Mode::Standby => ModuleSet::EMPTY,
        Mode::Safed => s.enabled().intersect(hip_and_arms),
        Mode::Operational => s.enabled(),
    };
    assert_eq!(out.powered, want, "{}", ctx());
    assert_eq!(
        out.regulator,
        out.mode != Mode::Standby && !want.is_empty(),
        "{}",
        ctx()
    );
    assert_eq!(out.mode, s.mode(), "{}", ctx());
    // Operational is entered only by command, and not while a condition holds.
    if s0.mode() != Mode::Operational && out.mode == Mode::Operational {
        assert_eq!(
            *c,
            Some(Incoming::Command(Command::Mode(Mode::Operational))),
            "{}",
            ctx()
        );
        assert!(!faults.iter().any(is_condition), "{}", ctx());
        assert!(out.go_home, "{}", ctx());
    }
    // Faults are latched, and change the mode only from Operational.
    assert!(faults.is_subset_of(out.faults), "{}", ctx());
    if c.is_none() {
        let (want, pending) = if s0.mode() == Mode::Operational {
            let (m, p) = table8_mode(faults, in_motion);
            // An earlier deferred fault acts at the first tick without motion.
            if m == Mode::Operational && s0.standby_pending() && !in_motion {
                (Mode::Standby, false)
            } else {
                (m, p || (m == Mode::Operational && s0.standby_pending()))
            }
        } else {
            (s0.mode(), false)
        };
        assert_eq!(out.mode, want, "{}", ctx());
        assert_eq!(out.standby_pending, pending, "{}", ctx());
        // A fault never raises power.
        assert!(out.powered.is_subset(power_before), "{}", ctx());
        assert!(out.answer.is_none());
    }
    // A deferred Standby is never lost: while the motion it waits for runs and the robot stays
    // Operational (no fault this step took it to another mode and back), it stays pending,
    // whatever the command (a redundant "operational" included).
    if s0.standby_pending() && in_motion && faults.is_empty() && out.mode == Mode::Operational {
        assert!(out.standby_pending, "{}", ctx());
    }
    // Every command gets an answer; accepted ones are allowed in the mode.
    if let Some(inc) = c {
        let ans = out.answer.unwrap_or_else(|| panic!("no answer: {}", ctx()));
        assert_eq!(
            ans.refusal(),
            match ans {
                Answer::Refused(r) => Some(r),
                Answer::Accepted(_) => None,
            }
        );
        match (inc, ans) {
            (Incoming::Malformed(r), a) => assert_eq!(a, Answer::Refused(*r)),
            (Incoming::Command(cm), Answer::Accepted(a)) => {
                assert_eq!(*cm, a);
                let k = cm.kind();
                if k.moves() {
                    // Faults are handled first, so `out.mode` is the mode the command met
                    // (a reconfiguration is accepted only with agreeing states, so it
                    // never changes the mode itself).
                    assert!(
                        out.mode == Mode::Operational
                            || (out.mode == Mode::Safed
                                && matches!(k, CommandKind::Arm | CommandKind::Hip)),
                        "{}",
                        ctx()
                    );
                    // Not while a Stop keeps a motion (unless a fault just
                    // changed the mode, which dropped it).
                    assert!(!s0.stopped() || out.mode != s0.mode(), "{}", ctx());
                }
            }
            (Incoming::Command(cm), Answer::Refused(r)) => {
                let k = cm.kind();
                let on_arrival =
                    matches!(r, Refusal::InitialStateMismatch | Refusal::ArmNotContracted);
                let mode_met = if on_arrival { s0.mode() } else { out.mode };
                match r {
                    Refusal::NotAllowedInMode => {
                        assert!(!accepts(mode_met, k), "{}", ctx())
                    }
                    Refusal::FaultConditionHolds => assert!(
                        faults.iter().any(is_condition)
                            && matches!(cm, Command::Mode(Mode::Operational)),
                        "{}",
                        ctx()
                    ),
                    // A reconfiguration's check on arrival: the fault it met latched and acted
                    // on (Table 8: arm not fully contracted Safed, the mismatch Standby).
                    Refusal::InitialStateMismatch | Refusal::ArmNotContracted => {
                        let e = initial_state.expect_err(&ctx());
                        assert!(
                            e.refusal() == r && k == CommandKind::Reconfiguration,
                            "{}",
                            ctx()
                        );
                        assert!(out.faults.contains(e.fault()), "{}", ctx());
                        if s0.mode() == Mode::Operational {
                            assert_eq!(out.mode, fault_action(e.fault()).mode, "{}", ctx());
                        }
                    }
                    Refusal::Stopped => {
                        assert!(s0.stopped() && k.moves(), "{}", ctx())
                    }
                    // Nothing kept, or a mode change this step dropped it.
                    Refusal::NothingToResume => assert!(
                        *cm == Command::Reset && (!s0.stopped() || out.mode != s0.mode()),
                        "{}",
                        ctx()
                    ),
                    other => panic!("unexpected refusal {other:?}: {}", ctx()),
                }
            }
        }
    }
    // Stop is obeyed and heartbeat requests answered in every mode. A motion in
    // progress (outside Standby) is kept for Reset, as is one kept before in
    // the same mode; a mode change drops it.
    if let Some(Incoming::Command(Command::Stop)) = c {
        let kept =
            out.mode == s0.mode() && (s0.stopped() || (in_motion && out.mode != Mode::Standby));
        assert!(out.stop_motion, "{}", ctx());
        assert_eq!(s.stopped(), kept, "{}", ctx());
    }
    // Reset resumes exactly what was kept, in the mode it was kept in.
    if let Some(Incoming::Command(Command::Reset)) = c {
        let resumes = s0.stopped() && out.mode == s0.mode();
        assert_eq!(out.resume, resumes, "{}", ctx());
        assert!(!s.stopped(), "{}", ctx());
    }
    if s.mode() != s0.mode() {
        assert!(!s.stopped() && out.stop_motion, "{}", ctx());
    }
    if let Some(Incoming::Command(Command::Heartbeat)) = c {
        assert_eq!(
            out.answer,
            Some(Answer::Accepted(Command::Heartbeat)),
            "{}",
            ctx()
        );
    }
    s
}

/// The hip and reconfiguration facts (hip at home; the reconfiguration's check on arrival: passed,
/// arm not contracted, initial state mismatch), enumerated for the two commands that read them.
fn facts(c: &Option<Incoming>) -> &'static [(bool, Result<(), InitialStateError>)] {
    const ARM: Result<(), InitialStateError> = Err(InitialStateError::ArmNotContracted(Side::A));
    const MISMATCH: Result<(), InitialStateError> = Err(InitialStateError::Mismatch);
    match c {
        Some(Incoming::Command(Command::Mode(Mode::Operational)))
        | Some(Incoming::Command(Command::Reconfigure(_))) => &[
            (true, Ok(())),
            (true, ARM),
            (true, MISMATCH),
            (false, Ok(())),
            (false, ARM),
            (false, MISMATCH),
        ],
        _ => &[(true, Ok(()))],
    }
}

/// One part of the whole domain: the start states whose index is `part` modulo `PARTS`, each
/// with every command, fault subset, motion flag and hip/initial-state fact. The domain is cut
/// into parts so that the test runner spreads it over the cores (one test is one thread).
fn supervisor_properties_hold_on_part(part: usize) {
    let starts = start_states();
    let cmds = incoming();
    let n_faults = 1u32 << Fault::ALL.len();
    let mut steps: u64 = 0;
    let mine: Vec<_> = starts.iter().skip(part).step_by(PARTS).collect();
    for (name, s0) in &mine {
        for c in &cmds {
            // hip/initial-state facts only matter to two commands: enumerate them there.
            let facts = facts(c);
            for raw in 0..n_faults {
                let faults = Faults::from_wire([raw as u8, (raw >> 8) as u8]).unwrap();
                for in_motion in [false, true] {
                    for &(hip_at_home, initial_state) in facts {
                        let input = Input {
                            faults,
                            command: *c,
                            in_motion,
                            hip_at_home,
                            initial_state,
                        };
                        check_step(name, s0, &input);
                        steps += 1;
                    }
                }
            }
        }
    }
    println!("supervisor, part {part} of {PARTS}: {steps} steps checked ({} of {} start states x {} inputs x {n_faults} fault subsets x 2 motion flags, + hip/initial-state facts)", mine.len(), starts.len(), cmds.len());
    assert_eq!(
        steps,
        mine.len() as u64 * (cmds.len() as u64 + 2 * 5) * n_faults as u64 * 2
    );
}

/// The parts the whole domain is walked in: one test each below (`part_0` to `part_3`), which
/// together take every start state once (state `i` in part `i % PARTS`).
const PARTS: usize = 4;
const _: () = assert!(
    PARTS == 4,
    "one test per part below: add or remove one with PARTS"
);

// req: T7/*, T8/*, P7.7
#[test]
fn supervisor_properties_hold_on_the_whole_domain_part_0() {
    supervisor_properties_hold_on_part(0);
}

// req: T7/*, T8/*, P7.7
#[test]
fn supervisor_properties_hold_on_the_whole_domain_part_1() {
    supervisor_properties_hold_on_part(1);
}

// req: T7/*, T8/*, P7.7
#[test]
fn supervisor_properties_hold_on_the_whole_domain_part_2() {
    supervisor_properties_hold_on_part(2);
}

// req: T7/*, T8/*, P7.7
#[test]
fn supervisor_properties_hold_on_the_whole_domain_part_3() {
    supervisor_properties_hold_on_part(3);
}

/// The fault sets the breadth-first search feeds: every subset of one representative per
/// class of fault the supervisor tells apart (its Table 8 mode, deferred or not, a condition or
/// an event). The supervisor reads a step's faults only through those classes (`raise`: any
/// Safed-class, any immediate-Standby, any deferred; entering Operational: any condition),
/// apart from latching them and ClearFaults keeping the latched ones still present, which act
/// fault by fault; every one of the 2^15 fault subsets is fed from the start states of
/// `supervisor_properties_hold_on_the_whole_domain`.
fn fault_classes() -> Vec<Faults> {
    let mut reps: Vec<Fault> = vec![];
    for f in Fault::ALL {
        let class = |g: Fault| (fault_action(g), is_condition(g));
        if !reps.iter().any(|r| class(*r) == class(f)) {
            reps.push(f);
        }
    }
    assert_eq!(reps.len(), 5, "classes: {reps:?}");
    (0..1u32 << reps.len())
        .map(|m| {
            reps.iter()
                .enumerate()
                .filter(|(i, _)| m & (1 << i) != 0)
                .fold(Faults::EMPTY, |acc, (_, f)| acc.with(*f))
        })
        .collect()
}

/// Every supervisor state reachable from start-up (`Supervisor::new()`), breadth-first, over
/// every incoming class × fault class subset × in-motion flag × hip/initial-state facts; every
/// property of `check_step` on every step from every one of them. The states are counted by
/// what the supervisor branches on (mode, enabled modules, deferred Standby pending, a motion
/// kept by Stop); the latched fault set rides along as data: no branch reads it (it is only
/// output, widened by each step's faults and narrowed by ClearFaults).
// req: T7/*, P7.7
#[test]
fn every_reachable_supervisor_state_satisfies_the_properties() {
    use std::collections::{HashSet, VecDeque};
    let t0 = std::time::Instant::now();
    let cmds = incoming();
    let faults = fault_classes();
    let key = |s: &Supervisor| (s.mode(), s.enabled(), s.standby_pending(), s.stopped());
    let start = Supervisor::new();
    let mut seen = HashSet::from([key(&start)]);
    let mut queue = VecDeque::from([start]);
    let (mut steps, mut latched_seen, mut stopped_safed_latched) = (0u64, 0usize, 0usize);
    while let Some(s0) = queue.pop_front() {
        latched_seen += usize::from(!s0.faults().is_empty());
        stopped_safed_latched +=
            usize::from(s0.stopped() && s0.mode() == Mode::Safed && !s0.faults().is_empty());
        for c in &cmds {
            let facts = facts(c);
            for &f in &faults {
                for in_motion in [false, true] {
                    for &(hip_at_home, initial_state) in facts {
                        let input = Input {
                            faults: f,
                            command: *c,
                            in_motion,
                            hip_at_home,
                            initial_state,
                        };
                        let s = check_step("reachable", &s0, &input);
                        steps += 1;
                        if seen.insert(key(&s)) {
                            queue.push_back(s);
                        }
                    }
                }
            }
        }
    }
    let modes: HashSet<Mode> = seen.iter().map(|k| k.0).collect();
    println!(
        "supervisor: {} reachable states (mode x enabled modules x standby pending x stopped), {steps} steps checked, {:.1} s",
        seen.len(),
        t0.elapsed().as_secs_f64()
    );
    // Every mode, and the states the hand-built starts lacked, are among them.
    assert_eq!(modes.len(), 3);
    assert!(
        seen.iter().any(|k| k.0 == Mode::Safed && k.3),
        "stopped in Safed"
    );
    assert!(
        stopped_safed_latched > 0 && latched_seen > 0,
        "with latched faults"
    );
    assert!(seen
        .iter()
        .any(|k| k.0 == Mode::Safed && k.1 == ModuleSet::EMPTY));
    assert_eq!(seen.len(), 896, "reachable states");
}

/// Deferred faults act exactly at motion end, never before, and are never lost: a deferred
/// fault raised at any tick of a motion of any length 1..=6 ticks (with the fault still
/// holding or gone afterwards) takes Operational to Standby at the first tick without motion.
// req: P7.12, P7.13, T8/assembly_system, T8/low_battery
#[test]
fn deferred_faults_act_exactly_at_motion_end() {
    let mut cases = 0;
    for f in [Fault::LowBattery, Fault::AssemblySystem] {
        for len in 1..=6 {
            for raised_at in 0..len {
                for persists in [false, true] {
                    let mut s = Supervisor::new();
                    s.step(&cmd(Command::Mode(Mode::Operational)));
                    for t in 0..len {
                        let faults = if t == raised_at || (persists && t > raised_at) {
                            Faults::EMPTY.with(f)
                        } else {
                            Faults::EMPTY
                        };
                        let out = s.step(&Input {
                            faults,
                            in_motion: true,
                            ..Input::quiet()
                        });
                        assert_eq!(
                            out.mode,
                            Mode::Operational,
                            "{f} len {len} at {raised_at}: changed before motion end"
                        );
                        assert_eq!(out.faults.contains(f), t >= raised_at);
                    }
                    let faults = if persists {
                        Faults::EMPTY.with(f)
                    } else {
                        Faults::EMPTY
                    };
                    let out = s.step(&Input {
                        faults,
                        in_motion: false,
                        ..Input::quiet()
                    });
                    assert_eq!(
                        out.mode,
                        Mode::Standby,
                        "{f} len {len} at {raised_at}: lost"
                    );
                    assert!(out.stop_motion && out.powered.is_empty());
                    cases += 1;
                }
            }
        }
    }
    // The system fault command acts the same way.
    let mut s = Supervisor::new();
    s.step(&cmd(Command::Mode(Mode::Operational)));
    let out = s.step(&Input {
        command: Some(Incoming::Command(Command::SystemFault)),
        in_motion: true,
        ..Input::quiet()
    });
    assert_eq!(out.mode, Mode::Operational);
    assert_eq!(
        s.step(&Input {
            in_motion: false,
            ..Input::quiet()
        })
        .mode,
        Mode::Standby
    );
    assert_eq!(cases, 2 * 21 * 2);
}
