//! The primitive sequencer and the reconfiguration runner, exhaustively: every one of the 60
//! moves under every sequence of up to 7 ticks drawn from {the awaited signal arrives, only
//! unrelated signals arrive, the step's time runs out, nothing happens}.
//! Checked at every tick: at least one gripper closed; only the moving side's gripper and arm
//! and the hip ever change; after a timeout the fault matches the step and nothing changes
//! again; Done comes only after every step.

use mmic::command::ServoTarget;
use mmic::faults::Fault;
use mmic::motion::runner::{RunStatus, Runner};
use mmic::motion::sequencer::{Config, Feedback, Sequencer, Status, Step, Targets};
use mmic::motion::{map, route, State};
use mmic::units::{PerSide, Side};

#[derive(Clone, Copy, Debug)]
enum Ev {
    Done,
    Unrelated,
    Late,
    Idle,
}

const EVS: [Ev; 4] = [Ev::Done, Ev::Unrelated, Ev::Late, Ev::Idle];

fn feedback(side: Side, ev: Ev) -> Feedback {
    let s = side;
    match ev {
        Ev::Done => Feedback {
            arm_done: PerSide::both(true),
            gripper_done: PerSide::both(true),
            hip_done: true,
            arm_switch: PerSide::both(true),
        },
        Ev::Unrelated => {
            // Everything of the holding side, nothing of the moving side; the hip moves only with S's arm.
            let mut f = Feedback {
                arm_done: PerSide::both(true),
                gripper_done: PerSide::both(true),
                hip_done: true,
                arm_switch: PerSide::both(true),
            };
            f.arm_done[s] = false;
            f.gripper_done[s] = false;
            f.arm_switch[s] = false;
            f
        }
        Ev::Late | Ev::Idle => Feedback::default(),
    }
}

/// The mapping of spec/motion/sequencer.md, for a timeout with no signal at all: Table 8's
/// "Arm not fully contracted" when the contraction switch was awaited, the project's motion
/// timeout for every other step, whichever side moves and whatever the primitive.
fn expected_fault(step: Step) -> Fault {
    match step {
        Step::Confirm => Fault::ArmNotContracted,
        Step::Release | Step::Move | Step::Grip => Fault::MotionTimeout,
    }
}

// req: P6.6
#[test]
fn every_move_under_every_signal_interleaving() {
    let cfg = Config::default();
    let depth = 7;
    let mut runs = 0u64;
    let mut outcomes = [0u64; 3];
    for (from, to, prim) in map::moves() {
        let n = 4usize.pow(depth);
        for code in 0..n {
            let mut s = Sequencer::start(cfg, from, to, Targets::home(), u32::MAX - 50).unwrap();
            assert_eq!(s.primitive(), prim);
            let side = s.side();
            let o = if side == Side::A { Side::B } else { Side::A };
            let turn = prim.number() >= 5;
            let mut now = u32::MAX - 50; // across the clock's wrap
            let mut c = code;
            let mut frozen: Option<(Status, Targets)> = None;
            let mut completed_steps = 0;
            for _ in 0..depth {
                let ev = EVS[c % 4];
                c /= 4;
                let step_before = s.current_step();
                now = now.wrapping_add(match ev {
                    Ev::Late => cfg.move_ms + 1,
                    _ => 10,
                });
                let st = s.step(now, &feedback(side, ev));
                let t = s.targets();
                assert!(t.holds(), "{from}->{to} code {code}: no gripper closed");
                assert_eq!(t.gripper[o], ServoTarget::Extend, "holding side released");
                // The holding side's arm only ever contracts (it starts contracted here).
                assert_eq!(
                    t.arm[o],
                    ServoTarget::Contract,
                    "holding side's arm extended"
                );
                if !turn {
                    assert_eq!(
                        t.hip,
                        Targets::home().hip,
                        "hip moved in a straight primitive"
                    );
                }
                if let Some((fs, ft)) = frozen {
                    assert_eq!((st, t), (fs, ft), "changed after it ended");
                }
                match st {
                    Status::Failed(f) if frozen.is_none() => {
                        let step = step_before.expect("failed while running");
                        assert!(matches!(ev, Ev::Late), "timed out without time passing");
                        assert_eq!(f, expected_fault(step), "{from}->{to} {step:?}");
                        frozen = Some((st, t));
                    }
                    Status::Done if frozen.is_none() => {
                        completed_steps += 1;
                        let steps = if to.is_matched() { 4 } else { 3 };
                        assert_eq!(completed_steps, steps, "{from}->{to}: done early");
                        assert_eq!(t.gripper, PerSide::both(ServoTarget::Extend));
                        let want_arm = if to.is_matched() {
                            ServoTarget::Contract
                        } else {
                            ServoTarget::Extend
                        };
                        assert_eq!(t.arm[side], want_arm);
                        if to.is_matched() {
                            assert_eq!(t.arm, PerSide::both(ServoTarget::Contract));
                        }
                        frozen = Some((st, t));
                    }
                    Status::Running if s.current_step() != step_before => completed_steps += 1,
                    _ => {}
                }
            }
            runs += 1;
            outcomes[match s.status() {
                Status::Running => 0,
                Status::Done => 1,
                Status::Failed(_) => 2,
            }] += 1;
        }
    }
    assert_eq!(runs, 60 * 4u64.pow(depth));
    assert!(outcomes.iter().all(|&n| n > 0), "{outcomes:?}");
    println!("sequencer: {runs} runs of {depth} ticks (running/done/failed: {outcomes:?})");
}

// req: P6.4, P6.5
#[test]
fn every_reconfiguration_reaches_its_target() {
    let all = Feedback {
        arm_done: PerSide::both(true),
        gripper_done: PerSide::both(true),
        hip_done: true,
        arm_switch: PerSide::both(true),
    };
    for from in State::ALL {
        for to in State::ALL {
            let mut r = Runner::start(Config::default(), from, to, Targets::home(), 0);
            // The plan the runner runs is the route table's, empty exactly from a state to itself.
            assert_eq!(*r.plan(), route::lookup(from, to), "{from}->{to}");
            assert_eq!(r.plan().is_empty(), from == to, "{from}->{to}");
            assert_eq!(r.plan().is_empty(), r.plan().primitives().is_empty());
            let mut visited = vec![];
            let mut t = 0u32;
            let mut last = from;
            while r.status() == RunStatus::Running {
                t += 10;
                r.step(t, &all);
                assert!(r.targets().holds());
                assert!(!r.command_complete() || r.status() == RunStatus::Complete);
                if r.current_state() != last {
                    last = r.current_state();
                    visited.push(last);
                }
                assert!(t < 1_000_000, "{from}->{to} never ends");
            }
            assert_eq!(r.status(), RunStatus::Complete, "{from}->{to}");
            assert_eq!(r.current_state(), to);
            assert_eq!(visited, route::lookup(from, to).states(), "{from}->{to}");
            // A matched target ends contracted and gripped, with the hip straight again.
            if from.is_matched() && to.is_matched() {
                assert_eq!(r.targets().arm, PerSide::both(ServoTarget::Contract));
                assert_eq!(r.targets().hip.centidegrees(), 18000, "{from}->{to}");
            }
        }
    }
}

// req: P6.5
#[test]
fn a_failed_primitive_stops_the_reconfiguration() {
    let mut r = Runner::start(Config::default(), State::A, State::M, Targets::home(), 0);
    // Release completes, then the move never finishes.
    let all = Feedback {
        arm_done: PerSide::both(true),
        gripper_done: PerSide::both(true),
        hip_done: true,
        arm_switch: PerSide::both(true),
    };
    r.step(10, &all);
    // a -> d moves side B: its arm never reports done. That is a stalled step, not a lost
    // link (the communication monitor judges the link from B's heartbeats).
    assert_eq!(
        r.step(20_000, &Feedback::default()),
        RunStatus::Failed(Fault::MotionTimeout)
    );
    assert_eq!(r.current_state(), State::A);
    assert!(!r.command_complete());
    assert_eq!(
        r.step(30_000, &all),
        RunStatus::Failed(Fault::MotionTimeout)
    );
}

/// The pose the sequencer leaves the robot in after each primitive is one the state estimator
/// accepts for the state the runner tracks: starting from home in each matched state, along the
/// plan to each of the 15 states, the arms' commanded PWM values (the arm targets' pulses) and the
/// hip angle (the hip target) give a set containing the tracked state. Otherwise the next
/// reconfiguration would raise a spurious initial-state mismatch. (Before the hip goal became
/// absolute, 24 of the 30 matched-to-matched reconfigurations ended with the hip at 0°, 90° or
/// 270° in a matched state, which the estimator rightly excludes.)
#[test]
fn every_pose_reached_is_accepted_by_the_estimator() {
    use mmic::command::Travel;
    use mmic::motion::estimate::{
        consistent, initial_state_consistent, ArmPwm, Config as Est, Readings,
    };
    let pwm = |t: ServoTarget| ArmPwm::of(&Travel::ARM, Travel::ARM.resolve(t));
    let all = Feedback {
        arm_done: PerSide::both(true),
        gripper_done: PerSide::both(true),
        hip_done: true,
        arm_switch: PerSide::both(true),
    };
    let mut poses = 0;
    for from in State::MATCHED {
        for to in State::ALL {
            let mut r = Runner::start(Config::default(), from, to, Targets::home(), 0);
            let mut t = 0u32;
            loop {
                let tg = r.targets();
                let here = r.current_state();
                let busy = r.running().map(|s| s.current_step());
                // Check only at rest: between primitives (or at the end).
                if busy.is_none() || busy == Some(Some(Step::Release)) {
                    let readings = Readings {
                        gravity_a: None,
                        gravity_b: None,
                        arm: PerSide::new(pwm(tg.arm.a), pwm(tg.arm.b)),
                        hip: tg.hip,
                    };
                    let set = consistent(&Est::default(), &readings);
                    assert!(
                        initial_state_consistent(here, Some(here), set),
                        "{from}->{to}: at {here} with hip {} the estimator gives {:?}",
                        tg.hip.centidegrees(),
                        set.iter().map(|s| s.letter()).collect::<String>()
                    );
                    poses += 1;
                }
                if r.status() != RunStatus::Running {
                    break;
                }
                t += 10;
                r.step(t, &all);
                assert!(t < 1_000_000);
            }
            assert_eq!(r.status(), RunStatus::Complete, "{from}->{to}");
        }
    }
    assert!(poses >= 6 * 15);
}

/// The model's 12 turns between two right-angle states need a joint the robot does not have:
/// the sequencer refuses each, the hip has no goal for it, and no chosen plan uses one.
// req: D:turn-to-turn-moves
#[test]
fn turns_without_the_hip_are_no_primitive() {
    use mmic::motion::geometry::{model_moves, turns_without_hip};
    use mmic::motion::sequencer::{hip_goal, NotAMove};
    let tt: Vec<_> = model_moves()
        .filter(|&(f, t, _, _)| turns_without_hip(f, t))
        .collect();
    assert_eq!(tt.len(), 12);
    for &(f, t, _, p) in &tt {
        assert_eq!(hip_goal(f, t, p), None, "{f}->{t}");
        assert_eq!(
            Sequencer::start(Config::default(), f, t, Targets::home(), 0),
            Err(NotAMove { from: f, to: t })
        );
        assert!(!mmic::motion::figure9::used_between_matched(f, t));
    }
}
