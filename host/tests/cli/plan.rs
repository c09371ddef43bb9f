//! Plan files: every command class round-trips through the text, and every error names the
//! line and column of the token to fix.

use mmic::arbitrary::for_each_variant_class;
use mmic::command::{
    BolterCommand, BolterPair, Command, Fasteners, HipTarget, PowerTarget, ReconfigurationError,
    ServoTarget,
};
use mmic::mode::Mode;
use mmic::motion::{Primitive, State};
use mmic::units::{HipAngle, Module, PulseWidth, Side};
use mmic_host::plan::{self, Action, Plan, PlanError, PlanErrorKind};

fn actions(p: &Plan) -> Vec<Action> {
    p.steps.iter().map(|s| s.action).collect()
}

fn one(text: &str) -> Action {
    let p = plan::parse(text).unwrap_or_else(|e| panic!("{text:?}: {e}"));
    assert_eq!(p.steps.len(), 1, "{text:?}");
    p.steps[0].action
}

fn cmd(text: &str) -> Command {
    match one(text) {
        Action::Command(c) => c,
        other => panic!("{text:?}: {other:?}"),
    }
}

fn err(text: &str) -> PlanError {
    match plan::parse(text) {
        Ok(p) => panic!("{text:?} parsed: {p:?}"),
        Err(e) => e,
    }
}

/// Asserts the error's line and column and returns its kind.
fn err_at(text: &str, line: usize, column: usize) -> PlanErrorKind {
    let e = err(text);
    assert_eq!((e.line, e.column), (line, column), "{text:?}: {e}");
    e.kind
}

fn variant_classes(pw: u16, cdeg: u16) -> Vec<Command> {
    let mut v = Vec::new();
    let pw = PulseWidth::new(pw).expect("pulse width in range");
    let a = HipAngle::new(cdeg).expect("angle in range");
    for_each_variant_class(pw, a, |c| v.push(c));
    v
}

#[test]
fn every_variant_class_round_trips_through_the_text() {
    for (pw, cdeg) in [
        (1500, 4550),
        (500, 0),
        (2500, 35999),
        (1234, 12345),
        (777, 5),
    ] {
        let cmds = variant_classes(pw, cdeg);
        assert_eq!(cmds.len(), 61);
        let original = Plan {
            robot: mmic::units::BoardNumber::new(7).expect("robot 7"),
            start: None,
            steps: cmds
                .iter()
                .enumerate()
                .map(|(i, c)| plan::Step {
                    line: i + 1,
                    action: Action::Command(*c),
                    text: String::new(),
                    columns: Vec::new(),
                })
                .collect(),
        };
        let text = original.to_text();
        let back = plan::parse(&text).unwrap_or_else(|e| panic!("{e}\n{text}"));
        assert_eq!(back.robot, original.robot);
        assert_eq!(actions(&back), actions(&original), "{text}");
        // Each step is its own canonical line, and the text is a fixed point.
        for (step, line) in back.steps.iter().zip(text.lines().skip(1)) {
            assert_eq!(step.text, line);
            assert_eq!(step.action.to_string(), line);
            assert!(!step.action.describe().is_empty());
        }
        assert_eq!(back.to_text(), text);
    }
}

#[test]
fn every_reconfiguration_and_wait_round_trips() {
    let mut steps = Vec::new();
    for initial in State::ALL {
        for target in State::MATCHED {
            if let Ok(c) = Command::reconfigure(initial, target) {
                steps.push(Action::Command(c));
            }
        }
    }
    assert_eq!(steps.len(), 84);
    for ms in [0, 1, 999, 1000, 1500, 1250, 60_000, plan::MAX_WAIT_MS] {
        steps.push(Action::Wait { ms });
    }
    let text: String = steps.iter().map(|a| format!("{a}\n")).collect();
    let back = plan::parse(&text).unwrap_or_else(|e| panic!("{e}\n{text}"));
    assert_eq!(actions(&back), steps);
}

#[test]
fn each_step_form_parses_to_its_command() {
    use Command as C;
    assert_eq!(cmd("heartbeat"), C::Heartbeat);
    assert_eq!(cmd("stop"), C::Stop);
    assert_eq!(cmd("reset"), C::Reset);
    assert_eq!(cmd("system-fault"), C::SystemFault);
    assert_eq!(cmd("clear-faults"), C::ClearFaults);
    assert_eq!(cmd("mode safed"), C::Mode(Mode::Safed));
    let pw = |us| ServoTarget::Position(PulseWidth::new(us).expect("in range"));
    for (t, target) in [
        ("contract", ServoTarget::Contract),
        ("extend", ServoTarget::Extend),
        ("1500", pw(1500)),
        ("1500us", pw(1500)),
        ("1500µs", pw(1500)),
        ("500US", pw(500)),
        ("2500", pw(2500)),
    ] {
        assert_eq!(
            cmd(&format!("arm b {t}")),
            C::Arm {
                side: Side::B,
                target
            }
        );
        assert_eq!(
            cmd(&format!("gripper a {t}")),
            C::Gripper {
                side: Side::A,
                target
            }
        );
    }
    let angle = |c| HipTarget::Angle(HipAngle::new(c).expect("in range"));
    for (t, h) in [
        ("home", HipTarget::Home),
        ("straight", HipTarget::Straight),
        ("cw", HipTarget::RightAngleCw),
        ("ccw", HipTarget::RightAngleCcw),
        ("45", angle(4500)),
        ("45.5", angle(4550)),
        ("45.50", angle(4550)),
        ("45deg", angle(4500)),
        ("45.25°", angle(4525)),
        ("0", angle(0)),
        ("359.99", angle(35999)),
        ("90", angle(9000)), // an angle, not the `cw` preset: a different opcode
    ] {
        assert_eq!(cmd(&format!("hip {t}")), C::Hip(h), "{t}");
    }
    assert_eq!(
        cmd("bolt 3"),
        C::Bolter(BolterCommand::Bolt(Fasteners::Pair(BolterPair::P3)))
    );
    assert_eq!(
        cmd("unbolt all"),
        C::Bolter(BolterCommand::Unbolt(Fasteners::All))
    );
    assert_eq!(cmd("bolters down"), C::Bolter(BolterCommand::Down));
    let prim = |p, s| Command::primitive(p, s).expect("valid primitive command");
    assert_eq!(
        cmd("primitive 4 -> d"),
        prim(Primitive::BackExtend, State::D)
    );
    assert_eq!(cmd("primitive 4 d"), prim(Primitive::BackExtend, State::D));
    assert_eq!(cmd("primitive 7->D"), prim(Primitive::BackTurnCw, State::D));
    assert_eq!(
        cmd("primitive fwdturnccw -> k"),
        prim(Primitive::FwdTurnCcw, State::K)
    );
    let r = Command::reconfigure(State::A, State::M).expect("valid");
    assert_eq!(cmd("reconfigure a -> m"), r);
    assert_eq!(cmd("reconfigure A->M"), r);
    assert_eq!(cmd("reconfigure a ->m"), r);
    for m in Module::ALL {
        let kw = plan::module_keyword(m);
        assert_eq!(
            cmd(&format!("power off {kw}")),
            C::Power {
                target: PowerTarget::Module(m),
                on: false
            }
        );
    }
    assert_eq!(
        cmd("power on all"),
        C::Power {
            target: PowerTarget::All,
            on: true
        }
    );
    for (t, ms) in [
        ("2s", 2000),
        ("500ms", 500),
        ("1.5s", 1500),
        ("0.001s", 1),
        ("3600s", 3_600_000),
        ("1.500S", 1500),
    ] {
        assert_eq!(one(&format!("wait {t}")), Action::Wait { ms }, "{t}");
    }
}

#[test]
fn keywords_are_case_insensitive() {
    assert_eq!(
        cmd("ARM A Extend"),
        Command::Arm {
            side: Side::A,
            target: ServoTarget::Extend
        }
    );
    assert_eq!(cmd("Mode OPERATIONAL"), Command::Mode(Mode::Operational));
    assert_eq!(cmd("System-Fault"), Command::SystemFault);
    assert_eq!(
        cmd("POWER ON Gripper-B"),
        Command::Power {
            target: PowerTarget::Module(Module::GripperB),
            on: true
        }
    );
    assert_eq!(plan::parse("ROBOT 3\nstop").map(|p| p.robot.get()), Ok(3));
}

#[test]
fn comments_blank_lines_and_indentation_are_ignored() {
    let text = "# a plan\n\n   \n\tmode operational   # power up\nstop#tight\n  # indented comment\r\nheartbeat\r\n";
    let p = plan::parse(text).expect("parses");
    assert_eq!(
        actions(&p),
        [
            Action::Command(Command::Mode(Mode::Operational)),
            Action::Command(Command::Stop),
            Action::Command(Command::Heartbeat),
        ]
    );
    let lines: Vec<usize> = p.steps.iter().map(|s| s.line).collect();
    assert_eq!(lines, [4, 5, 7]);
    assert_eq!(p.steps[0].text, "mode operational   # power up");
    assert_eq!(p.steps[2].text, "heartbeat");
    assert_eq!(p.robot.get(), 1);
}

#[test]
fn robot_header() {
    let p = plan::parse("# header first\nrobot 255 # last client\nstop\n").expect("parses");
    assert_eq!(p.robot.get(), 255);
    assert_eq!(p.steps[0].line, 3);
    assert_eq!(
        err_at("stop\nrobot 2\n", 2, 1),
        PlanErrorKind::RobotAfterSteps
    );
    assert_eq!(
        err_at("robot 2\n  robot 3\nstop\n", 2, 3),
        PlanErrorKind::RobotTwice { first: 1 }
    );
    for n in ["0", "256", "-1", "99999999999999999999999"] {
        assert!(
            matches!(
                err_at(&format!("robot {n}\nstop"), 1, 7),
                PlanErrorKind::OutOfRange {
                    quantity: "robot number",
                    ..
                }
            ),
            "{n}"
        );
    }
    assert!(matches!(
        err_at("robot two\nstop", 1, 7),
        PlanErrorKind::BadArgument { .. }
    ));
    assert!(matches!(
        err_at("robot\nstop", 1, 6),
        PlanErrorKind::MissingArgument { step: "robot", .. }
    ));
    assert_eq!(
        err_at("robot 2 3\nstop", 1, 9),
        PlanErrorKind::TrailingToken { found: "3".into() }
    );
}

#[test]
fn empty_plans_are_refused() {
    for text in [
        "",
        "\n\n",
        "# nothing yet\n   # still nothing\n",
        "robot 4\n",
        "\u{feff}",
    ] {
        assert_eq!(err_at(text, 1, 1), PlanErrorKind::Empty, "{text:?}");
    }
}

#[test]
fn errors_name_line_and_column_of_the_offending_token() {
    let e = err("mode operational\nbolt 5\n");
    assert_eq!((e.line, e.column), (2, 6));
    assert_eq!(
        e.kind,
        PlanErrorKind::OutOfRange {
            quantity: "bolter pair",
            min: "1",
            max: "4",
            found: "5".into()
        }
    );
    assert_eq!(
        e.to_string(),
        "line 2, column 6: bolter pair must be 1..=4, found 5"
    );

    // Unknown keyword: at the keyword, whatever the indentation (a tab is one column).
    for (text, col) in [
        ("frobnicate", 1),
        ("   frobnicate 1", 4),
        ("\tfrobnicate", 2),
    ] {
        assert_eq!(
            err_at(&format!("stop\n{text}\n"), 2, col),
            PlanErrorKind::UnknownStep {
                found: "frobnicate".into()
            },
            "{text:?}"
        );
    }
    // Columns count characters, not bytes.
    assert!(matches!(
        err_at("hip 45°° # µ", 1, 5),
        PlanErrorKind::BadArgument { .. }
    ));
    assert_eq!(
        err_at("arm a 1500µs extra", 1, 14),
        PlanErrorKind::TrailingToken {
            found: "extra".into()
        }
    );
    assert!(matches!(
        err_at("# ünïcödé\n\t  arm c extend", 2, 8),
        PlanErrorKind::BadArgument {
            expected: "a side: a or b",
            ..
        }
    ));

    // Missing arguments: just past the last token.
    assert_eq!(
        err_at("mode", 1, 5),
        PlanErrorKind::MissingArgument {
            step: "mode",
            expected: "a mode: standby, operational or safed"
        }
    );
    assert!(matches!(
        err_at("  arm a   # nothing more", 1, 8),
        PlanErrorKind::MissingArgument { step: "arm", .. }
    ));
    assert!(matches!(
        err_at("reconfigure a ->", 1, 17),
        PlanErrorKind::MissingArgument {
            step: "reconfigure",
            ..
        }
    ));

    // Trailing tokens.
    assert_eq!(
        err_at("stop now", 1, 6),
        PlanErrorKind::TrailingToken {
            found: "now".into()
        }
    );
    assert!(matches!(
        err_at("arm a extend fast", 1, 14),
        PlanErrorKind::TrailingToken { .. }
    ));

    // Out of range: refused, never clamped.
    for (text, col, quantity) in [
        ("arm a 2501", 7, "pulse width"),
        ("gripper b 499us", 11, "pulse width"),
        ("arm a -5", 7, "pulse width"),
        ("arm a 70000", 7, "pulse width"),
        ("hip 360", 5, "hip angle"),
        ("hip -0.01", 5, "hip angle"),
        ("bolt 0", 6, "bolter pair"),
        ("unbolt 5", 8, "bolter pair"),
        ("primitive 9", 11, "primitive"),
        ("primitive 0", 11, "primitive"),
        ("wait 3600.001s", 6, "wait"),
        ("wait 2h", 6, ""),
        ("wait -1s", 6, "wait"),
    ] {
        let kind = err_at(text, 1, col);
        if quantity.is_empty() {
            assert!(matches!(kind, PlanErrorKind::BadArgument { .. }), "{text}");
        } else {
            assert!(
                matches!(kind, PlanErrorKind::OutOfRange { quantity: q, .. } if q == quantity),
                "{text}: {kind:?}"
            );
        }
    }
    assert_eq!(
        err("arm a 2501").to_string(),
        "line 1, column 7: pulse width must be 500us..=2500us, found 2501"
    );

    // Bad arguments.
    for (text, col) in [
        ("mode flying", 6),
        ("arm a halfway", 7),
        ("arm a 1500ms", 7),
        ("hip left", 5),
        ("hip 45.555", 5),
        ("bolt some", 6),
        ("bolters up", 9),
        ("primitive jump", 11),
        ("primitive 7 -> z", 16),
        ("primitive 7 ab", 13),
        ("reconfigure p -> a", 13),
        ("reconfigure a to m", 15),
        ("reconfigure a -> mm", 18),
        ("power up all", 7),
        ("power on arm", 10),
        ("wait 2", 6),
        ("wait 1.5ms", 6),
        ("wait 0.0005s", 6),
    ] {
        assert!(
            matches!(err_at(text, 1, col), PlanErrorKind::BadArgument { .. }),
            "{text}"
        );
    }
}

#[test]
fn impossible_reconfigurations_point_at_the_target() {
    assert_eq!(
        err_at("stop\nreconfigure  a -> d\n", 2, 19),
        PlanErrorKind::Reconfiguration(ReconfigurationError::TargetNotMatched { target: State::D })
    );
    assert_eq!(
        err_at("reconfigure m->M", 1, 16),
        PlanErrorKind::Reconfiguration(ReconfigurationError::SameState { state: State::M })
    );
    assert!(err("reconfigure m->M")
        .to_string()
        .starts_with("line 1, column 16: initial and target state are both m"));
}

#[test]
fn descriptions_are_short_and_specific() {
    let d = |t: &str| one(t).describe();
    assert_eq!(d("arm a 1500"), "arm A to 1500 µs");
    assert_eq!(d("gripper b extend"), "gripper B: extend");
    assert_eq!(d("wait 1.5s"), "wait 1.5 s");
    assert_eq!(d("wait 250ms"), "wait 250 ms");
    assert_eq!(d("hip 45.5"), "hip to 45.5°");
    assert_eq!(d("mode safed"), "switch to safed mode");
    assert_eq!(
        d("primitive 1 -> m"),
        "primitive 1 (fwdContract) to m (Xpos match)"
    );
    assert_eq!(d("bolt all"), "bolt all pairs");
    assert_eq!(d("power off all"), "power off all modules");
    assert_eq!(
        d("reconfigure a -> m"),
        "reconfigure a (Xneg match) -> m (Xpos match)"
    );
}

#[test]
fn a_start_header_round_trips_and_the_state_is_traced_through_the_plan() {
    let p = plan::parse(
        "robot 2\nstart a\nmode operational\nreconfigure a -> m\nbolt 1\nreconfigure m -> b\n",
    )
    .unwrap();
    assert_eq!(p.start, Some(State::A));
    assert_eq!(plan::parse(&p.to_text()).unwrap().start, Some(State::A));
    let states = p.trace(State::A).unwrap();
    assert_eq!(states, [State::A, State::M, State::M, State::B]);
    // The demo plan says where it starts, and traces through three voxels.
    let demo = plan::parse(mmic_host::sim::DEMO_PLAN).unwrap();
    assert_eq!(demo.start, Some(State::A));
    let ends: Vec<State> = demo.trace(State::A).unwrap();
    assert_eq!(ends.last(), Some(&State::N));
}

#[test]
fn a_step_that_does_not_fit_the_state_is_refused_with_line_and_column() {
    // With a start header, the parser itself refuses it.
    let e = plan::parse("start a\nmode operational\nreconfigure a -> m\n  reconfigure b -> n\n")
        .unwrap_err();
    assert_eq!((e.line, e.column), (4, 15));
    assert_eq!(
        e.kind,
        PlanErrorKind::StateMismatch {
            found: State::B,
            tracked: State::M,
            since: Some(3)
        }
    );
    assert!(e
        .to_string()
        .contains("but the robot is in m (Xpos match) here (since line 3)"));
    // From the start state.
    let e = plan::parse("start m\nreconfigure a -> b\n").unwrap_err();
    assert_eq!(e.to_string(), "line 2, column 13: this reconfiguration starts from a (Xneg match), but the robot is in m (Xpos match) here (its start state)");
    // Without one, parsing succeeds and the caller's start decides (mmic sim uses `a`).
    let p = plan::parse("reconfigure b -> n\n").unwrap();
    assert_eq!(p.start, None);
    assert!(p.trace(State::B).is_ok());
    assert_eq!(p.trace(State::A).unwrap_err().column, 13);
    // A primitive that is no move from the tracked state (Figure 9): a -> ? by primitive 1.
    let none = mmic::motion::Primitive::ALL
        .into_iter()
        .find(|&pr| {
            State::ALL
                .into_iter()
                .all(|to| mmic::motion::map::primitive(State::A, to) != Some(pr))
        })
        .unwrap();
    let e = plan::parse(&format!("start a\nprimitive {}\n", none.number())).unwrap_err();
    assert_eq!((e.line, e.column), (2, 11));
    assert!(matches!(
        e.kind,
        PlanErrorKind::NoSuchMove {
            tracked: State::A,
            since: None,
            ..
        }
    ));
    // A turn between two right-angle states (g -> j by 6, fwdTurnCCW: A would swing about B's
    // arm), named with its final state or without: refused by that name, the line of the step
    // that put the robot in g given.
    for step in ["primitive 6 -> j", "primitive 6"] {
        let e = plan::parse(&format!("start b\nprimitive 7 -> g\n{step}\n")).unwrap_err();
        assert_eq!((e.line, e.column), (3, 11), "{step}");
        assert_eq!(
            e.kind,
            PlanErrorKind::TurnWithoutHip {
                primitive: 6,
                tracked: State::G,
                target: State::J,
                since: Some(2),
            },
            "{step}"
        );
        assert!(e.to_string().contains("turn_without_hip"), "{e}");
    }
    // The header goes once, before the first step.
    assert_eq!(
        plan::parse("stop\nstart a\n").unwrap_err().kind,
        PlanErrorKind::StartMisplaced
    );
    assert_eq!(
        plan::parse("start a\nstart b\nstop\n").unwrap_err().kind,
        PlanErrorKind::StartMisplaced
    );
}

#[test]
fn every_primitive_command_round_trips_through_the_text() {
    let steps: Vec<Action> = mmic::command::PrimitiveMove::all()
        .map(|m| Action::Command(Command::Primitive(m)))
        .collect();
    assert_eq!(steps.len(), 60);
    let text: String = steps.iter().map(|a| format!("{a}\n")).collect();
    assert!(text.starts_with("primitive 1 -> m\n"), "{text}");
    let back = plan::parse(&text).unwrap_or_else(|e| panic!("{e}\n{text}"));
    assert_eq!(actions(&back), steps);
}

#[test]
fn a_primitive_step_names_its_final_state_or_the_plan_settles_it() {
    use mmic::command::PrimitiveMoveError;
    // Named: no start needed. Left out without a start header: nothing to fill it in from.
    assert_eq!(
        cmd("primitive 7 -> d"),
        Command::primitive(Primitive::BackTurnCw, State::D).unwrap()
    );
    assert_eq!(
        err_at("primitive 7\n", 1, 11),
        PlanErrorKind::MissingFinalState { primitive: 7 }
    );
    assert_eq!(
        err("primitive fwdContract").to_string(),
        "line 1, column 11: primitive 1 needs its final state, e.g. `primitive 1 -> m`, or a \
         `start` header to fill it in from"
    );
    assert_eq!(
        err_at("primitive 7 ->", 1, 15),
        PlanErrorKind::MissingArgument {
            step: "primitive",
            expected: "a state letter a..o (Table 5)"
        }
    );
    // A final state the primitive reaches from nowhere: refused where it stands.
    assert_eq!(
        err_at("primitive 3 -> a", 1, 16),
        PlanErrorKind::Primitive(PrimitiveMoveError::Unreachable {
            primitive: Primitive::FwdExtend,
            target: State::A
        })
    );
    // With a start, the one move from there fills it in: a -> e by 8, canonical text names it.
    let p = plan::parse("start a\nprimitive 8\n").unwrap();
    assert_eq!(
        actions(&p),
        [Action::Command(
            Command::primitive(Primitive::BackTurnCcw, State::E).unwrap()
        )]
    );
    assert_eq!(p.to_text(), "robot 1\nstart a\nprimitive 8 -> e\n");
    // A final state the primitive does not reach from the tracked state.
    let e = err("start a\nprimitive 8\n  primitive 7 -> b\n");
    assert_eq!((e.line, e.column), (3, 18));
    assert_eq!(
        e.kind,
        PlanErrorKind::WrongFinalState {
            primitive: 7,
            target: State::B,
            tracked: State::E,
            reaches: vec![State::A, State::D],
            since: Some(2)
        }
    );
    assert_eq!(
        e.to_string(),
        "line 3, column 18: primitive 7 takes e (Xneg Ypos turn) to a (Xneg match) or \
         d (Xneg Xpos stretch), not to b (Yneg match) (Figure 9); the robot is in e (Xneg Ypos \
         turn) here (since line 2)"
    );
}

/// Each of the 12 ambiguous (state, primitive) pairs: left out, the final state is an error
/// naming both candidates and the line; named, either candidate is accepted and traced.
#[test]
fn an_ambiguous_primitive_must_name_its_final_state() {
    let mut n = 0;
    for (from, p, first, second) in mmic::motion::map::ambiguous() {
        // Reach `from` by primitives, each naming its final state (some on the way are
        // ambiguous themselves).
        let route = mmic::motion::route::lookup(State::A, from);
        let mut text = String::from("start a\nmode operational\n");
        for (q, to) in route.primitives().iter().zip(route.states()) {
            text += &format!("primitive {} -> {}\n", q.number(), to.letter());
        }
        let line = 3 + route.len();
        let e = err(&format!("{text}primitive {}  # which?\n", p.name()));
        assert_eq!((e.line, e.column), (line, 11), "{from} by {p}");
        assert_eq!(
            e.kind,
            PlanErrorKind::AmbiguousPrimitive {
                primitive: p.number(),
                tracked: from,
                first,
                second,
                since: Some(line - 1)
            }
        );
        let message = e.to_string();
        for s in [first, second, from] {
            assert!(message.contains(&s.to_string()), "{message}");
        }
        assert!(
            message.starts_with(&format!("line {line}, column 11: ")),
            "{message}"
        );
        for target in [first, second] {
            let plan = plan::parse(&format!(
                "{text}primitive {} -> {}\n",
                p.number(),
                target.letter()
            ))
            .unwrap_or_else(|e| panic!("{e}"));
            assert_eq!(plan.trace(State::A).unwrap().last(), Some(&target));
        }
        n += 1;
    }
    assert_eq!(n, 12);
}
