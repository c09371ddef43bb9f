//! Enumerations of the command set for exhaustive checks: every variant class (one command
//! per opcode) and every representable command. Behind the `proptest` feature with the
//! strategies: the checks that use them live in several crates of the workspace (the tests,
//! the proofs, the review pages of `host`), and the robot needs none of them.

use crate::bolter::BolterPair;
use crate::command::{
    BolterCommand, Command, Fasteners, HipTarget, PowerTarget, PrimitiveMove, Reconfiguration,
    ServoTarget, Travel,
};
use crate::mode::Mode;
use crate::pose::{Primitive, State};
use crate::units::{HipAngle, Module, PulseWidth, Side};

/// Every command whose parameters are discrete, plus each parameterised variant at the given
/// representative values: the "variant classes" that exhaustive checks iterate over.
///
/// `visit` is called once per command; 61 calls, one per opcode.
pub fn for_each_variant_class(pw: PulseWidth, angle: HipAngle, mut visit: impl FnMut(Command)) {
    visit(Command::Heartbeat);
    visit(Command::Stop);
    visit(Command::Reset);
    visit(Command::SystemFault);
    visit(Command::ClearFaults);
    for m in Mode::ALL {
        visit(Command::Mode(m));
    }
    servo_classes(pw, &mut visit);
    for h in [
        HipTarget::Home,
        HipTarget::Straight,
        HipTarget::RightAngleCw,
        HipTarget::RightAngleCcw,
        HipTarget::Angle(angle),
    ] {
        visit(Command::Hip(h));
    }
    bolter_classes(&mut visit);
    // Each primitive with its first final state in Table 5 order.
    for p in Primitive::ALL {
        let first = State::ALL
            .into_iter()
            .find_map(|to| PrimitiveMove::new(p, to).ok());
        if let Some(m) = first {
            visit(Command::Primitive(m));
        }
    }
    // a -> m is a reconfiguration (two different states), so the constructor takes it.
    if let Ok(r) = Reconfiguration::new(State::A, State::M) {
        visit(Command::Reconfigure(r));
    }
    for on in [true, false] {
        for m in Module::ALL {
            visit(Command::Power {
                target: PowerTarget::Module(m),
                on,
            });
        }
        visit(Command::Power {
            target: PowerTarget::All,
            on,
        });
    }
}

/// The arm classes, then the gripper classes: each side, contract, extend and `pw`.
fn servo_classes(pw: PulseWidth, visit: &mut impl FnMut(Command)) {
    let targets = [
        ServoTarget::Contract,
        ServoTarget::Extend,
        ServoTarget::Position(pw),
    ];
    for side in Side::ALL {
        for target in targets {
            visit(Command::Arm { side, target });
        }
    }
    for side in Side::ALL {
        for target in targets {
            visit(Command::Gripper { side, target });
        }
    }
}

/// Bolt, then unbolt, each pair and all four; then both bolters down.
fn bolter_classes(visit: &mut impl FnMut(Command)) {
    for bolt in [true, false] {
        for which in [
            Fasteners::Pair(BolterPair::P1),
            Fasteners::Pair(BolterPair::P2),
            Fasteners::Pair(BolterPair::P3),
            Fasteners::Pair(BolterPair::P4),
            Fasteners::All,
        ] {
            visit(Command::Bolter(if bolt {
                BolterCommand::Bolt(which)
            } else {
                BolterCommand::Unbolt(which)
            }));
        }
    }
    visit(Command::Bolter(BolterCommand::Down));
}

/// Calls `visit` with every representable command: each variant class, an arm or gripper
/// with every pulse width of its travel, every hip angle, every valid primitive command and
/// every valid reconfiguration: 40,595 calls.
pub fn for_each_command(mut visit: impl FnMut(Command)) {
    for_each_variant_class(PulseWidth::CENTER, HipAngle::ZERO, |c| match c {
        Command::Arm {
            side,
            target: ServoTarget::Position(_),
        } => {
            let t = Travel::ARM;
            for us in t.min().micros()..=t.max().micros() {
                if let Ok(pw) = PulseWidth::new(us) {
                    visit(Command::Arm {
                        side,
                        target: ServoTarget::Position(pw),
                    });
                }
            }
        }
        Command::Gripper {
            side,
            target: ServoTarget::Position(_),
        } => {
            let t = Travel::GRIPPER;
            for us in t.min().micros()..=t.max().micros() {
                if let Ok(pw) = PulseWidth::new(us) {
                    visit(Command::Gripper {
                        side,
                        target: ServoTarget::Position(pw),
                    });
                }
            }
        }
        Command::Hip(HipTarget::Angle(_)) => {
            for a in 0..HipAngle::TURN {
                if let Ok(a) = HipAngle::new(a) {
                    visit(Command::Hip(HipTarget::Angle(a)));
                }
            }
        }
        Command::Primitive(m) => {
            for other in PrimitiveMove::all().filter(|o| o.primitive() == m.primitive()) {
                visit(Command::Primitive(other));
            }
        }
        Command::Reconfigure(_) => {
            for initial in State::ALL {
                for target in State::MATCHED {
                    if let Ok(r) = Reconfiguration::new(initial, target) {
                        visit(Command::Reconfigure(r));
                    }
                }
            }
        }
        other => visit(other),
    });
}
