//! Exhaustive check of the mode supervisor over its whole finite input domain:
//! every start state (Standby, Safed, Operational idle / stopped / with a deferred fault
//! pending, each with the operator's power mask all-on or partial) × every command variant class
//! (61 opcodes, the two malformed-packet refusals, and no command) × every subset of the 13
//! faults × in-motion flag × hip-at-home × initial-state-agrees. Every property below is
//! asserted on every one of those steps; the test prints the domain size.

use mmic::command::{for_each_variant_class, Command, CommandKind, PowerTarget};
use mmic::faults::{Fault, Faults};
use mmic::mode::Mode;
use mmic::refusal::Refusal;
use mmic::safety::policy::{accepts, fault_action, is_condition, powered};
use mmic::safety::supervisor::{Answer, Incoming, Input, Supervisor};
use mmic::safety::ModuleSet;
use mmic::units::{HipAngle, Module, PulseWidth};

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

#[test]
fn supervisor_properties_hold_on_the_whole_domain() {
    let starts = start_states();
    let cmds = incoming();
    let n_faults = 1u32 << Fault::ALL.len();
    let mut steps: u64 = 0;
    for (name, s0) in &starts {
        let power_before = powered(s0.mode(), s0.enabled());
        for c in &cmds {
            // hip/initial-state facts only matter to two commands: enumerate them there.
            let facts: &[(bool, bool)] = match c {
                Some(Incoming::Command(Command::Mode(Mode::Operational)))
                | Some(Incoming::Command(Command::Reconfigure(_))) => {
                    &[(true, true), (true, false), (false, true), (false, false)]
                }
                _ => &[(true, true)],
            };
            for raw in 0..n_faults {
                let faults = Faults::from_wire([raw as u8, (raw >> 8) as u8]).unwrap();
                for in_motion in [false, true] {
                    for &(hip_at_home, initial_state_ok) in facts {
                        let input = Input {
                            faults,
                            command: *c,
                            in_motion,
                            hip_at_home,
                            initial_state_ok,
                        };
                        let mut s = *s0;
                        let out = s.step(&input);
                        steps += 1;
                        let ctx = || {
                            format!("{name} / {c:?} / faults {raw:#06x} / motion {in_motion} / hip {hip_at_home} / init {initial_state_ok}")
                        };

                        // Standby powers nothing; Safed only hip and arms.
                        match out.mode {
                            Mode::Standby => {
                                assert!(out.powered.is_empty() && !out.regulator, "{}", ctx())
                            }
                            Mode::Safed => {
                                assert!(out.powered.is_subset(ModuleSet::HIP_AND_ARMS), "{}", ctx())
                            }
                            Mode::Operational => {
                                assert!(out.powered.is_subset(s.enabled()), "{}", ctx())
                            }
                        }
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
                        // Every command gets an answer; accepted ones are allowed in the mode.
                        if let Some(inc) = c {
                            let ans = out.answer.unwrap_or_else(|| panic!("no answer: {}", ctx()));
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
                                                    && matches!(
                                                        k,
                                                        CommandKind::Arm | CommandKind::Hip
                                                    )),
                                            "{}",
                                            ctx()
                                        );
                                        // Not while a Stop keeps a motion (unless a fault just
                                        // changed the mode, which dropped it).
                                        assert!(
                                            !s0.stopped() || out.mode != s0.mode(),
                                            "{}",
                                            ctx()
                                        );
                                    }
                                }
                                (Incoming::Command(cm), Answer::Refused(r)) => {
                                    let k = cm.kind();
                                    let mode_met = if r == Refusal::InitialStateMismatch {
                                        s0.mode()
                                    } else {
                                        out.mode
                                    };
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
                                        Refusal::InitialStateMismatch => {
                                            assert!(
                                                !initial_state_ok
                                                    && k == CommandKind::Reconfiguration,
                                                "{}",
                                                ctx()
                                            );
                                            assert!(out
                                                .faults
                                                .contains(Fault::InitialStateMismatch));
                                        }
                                        Refusal::Stopped => {
                                            assert!(s0.stopped() && k.moves(), "{}", ctx())
                                        }
                                        // Nothing kept, or a mode change this step dropped it.
                                        Refusal::NothingToResume => assert!(
                                            *cm == Command::Reset
                                                && (!s0.stopped() || out.mode != s0.mode()),
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
                            let kept = out.mode == s0.mode()
                                && (s0.stopped() || (in_motion && out.mode != Mode::Standby));
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
                    }
                }
            }
        }
    }
    println!("supervisor: {steps} steps checked ({} start states x {} inputs x {n_faults} fault subsets x 2 motion flags, + hip/initial-state facts)", starts.len(), cmds.len());
    assert_eq!(
        steps,
        starts.len() as u64 * (cmds.len() as u64 + 2 * 3) * n_faults as u64 * 2
    );
}

/// Deferred faults act exactly at motion end, never before, and are never lost: a deferred
/// fault raised at any tick of a motion of any length 1..=6 ticks (with the fault still
/// holding or gone afterwards) takes Operational to Standby at the first tick without motion.
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
