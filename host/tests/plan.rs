//! Plan files: every command of Table 1 round-trips through the text form, errors point at the
//! exact line and column, and the built-in demo parses. Plus the SVG plots' well-formedness.

use mmic::command::{for_each_variant_class, Command};
use mmic::units::{HipAngle, PulseWidth};
use mmic_host::plan::{command_text, parse, Action, PlanErrorKind};
use mmic_host::plot::{bar_chart, line_chart, Series};

#[test]
fn every_command_class_round_trips_through_plan_text() {
    let mut n = 0;
    for (pw, deg) in [(500, 0), (2500, 35999), (1234, 4550)] {
        let mut text = String::from("robot 9\n");
        let mut want = Vec::new();
        for_each_variant_class(
            PulseWidth::new(pw).unwrap(),
            HipAngle::new(deg).unwrap(),
            |c| {
                text += &command_text(&c);
                text += "\n";
                want.push(c);
            },
        );
        let plan = parse(&text).unwrap();
        assert_eq!(plan.robot.get(), 9);
        let got: Vec<Command> = plan
            .steps
            .iter()
            .map(|s| match s.action {
                Action::Command(c) => c,
                Action::Wait { .. } => panic!("no waits here"),
            })
            .collect();
        assert_eq!(got, want);
        // Canonical text parses back to the same steps.
        let again = parse(&plan.to_text()).unwrap();
        assert_eq!(
            again.steps.iter().map(|s| s.action).collect::<Vec<_>>(),
            plan.steps.iter().map(|s| s.action).collect::<Vec<_>>()
        );
        n += want.len();
    }
    assert_eq!(n, 3 * 61, "all 61 variant classes of Table 1");
}

#[test]
fn all_84_reconfigurations_and_the_spellings_users_write() {
    let mut n = 0;
    for a in mmic::motion::State::ALL {
        for b in mmic::motion::State::ALL {
            if let Ok(c) = Command::reconfigure(a, b) {
                for text in [
                    format!("reconfigure {} -> {}", a.letter(), b.letter()),
                    format!(
                        "RECONFIGURE {}->{}",
                        a.letter().to_ascii_uppercase(),
                        b.letter()
                    ),
                    format!(
                        "  reconfigure\t{}  ->  {}   # comment",
                        a.letter(),
                        b.letter()
                    ),
                ] {
                    let p = parse(&text).unwrap();
                    assert_eq!(p.steps[0].action, Action::Command(c), "{text}");
                }
                n += 1;
            }
        }
    }
    assert_eq!(n, 84);
    let p =
        parse("wait 500ms\nwait 2s\nwait 1.25s\nhip 45.5deg\narm b 1500us\npower off gripper-b\n")
            .unwrap();
    let actions: Vec<String> = p.steps.iter().map(|s| s.action.describe()).collect();
    assert_eq!(
        actions,
        [
            "wait 500ms",
            "wait 2000ms",
            "wait 1250ms",
            "hip 45.50",
            "arm b 1500us",
            "power off gripper-b"
        ]
    );
    assert_eq!(p.steps[3].line, 4);
    assert_eq!(p.steps[3].text, "hip 45.5deg");
}

#[track_caller]
fn error_at(text: &str, line: usize, column: usize) -> PlanErrorKind {
    let e = parse(text).unwrap_err();
    assert_eq!((e.line, e.column), (line, column), "{text:?}: {e}");
    e.kind
}

#[test]
fn errors_name_line_and_column() {
    assert!(matches!(
        error_at("mode operational\nbolt 5\n", 2, 6),
        PlanErrorKind::Bad { .. }
    ));
    assert!(matches!(
        error_at("\n\n   jump 3\n", 3, 4),
        PlanErrorKind::UnknownStep { .. }
    ));
    assert!(matches!(
        error_at("\tarm c contract", 1, 6),
        PlanErrorKind::Bad { .. }
    ));
    assert!(matches!(
        error_at("arm a", 1, 6),
        PlanErrorKind::Missing { step: "arm", .. }
    ));
    assert!(matches!(
        error_at("arm a 2501", 1, 7),
        PlanErrorKind::Bad { .. }
    ));
    assert!(matches!(
        error_at("hip 360", 1, 5),
        PlanErrorKind::Bad { .. }
    ));
    assert!(matches!(
        error_at("hip 12.345", 1, 5),
        PlanErrorKind::Bad { .. }
    ));
    assert!(matches!(
        error_at("stop now", 1, 6),
        PlanErrorKind::Trailing { .. }
    ));
    assert!(matches!(
        error_at("mode standby\nrobot 2", 2, 1),
        PlanErrorKind::RobotAfterSteps
    ));
    assert!(matches!(
        error_at("robot 0", 1, 7),
        PlanErrorKind::Bad { .. }
    ));
    assert!(matches!(
        error_at("reconfigure a -> a", 1, 13),
        PlanErrorKind::Reconfiguration(_)
    ));
    assert!(matches!(
        error_at("reconfigure a m", 1, 15),
        PlanErrorKind::Bad { .. }
    ));
    assert!(matches!(
        error_at("wait 2h", 1, 6),
        PlanErrorKind::Bad { .. }
    ));
    assert!(matches!(
        error_at("wait 3601s", 1, 6),
        PlanErrorKind::Bad { .. }
    ));
    assert!(matches!(
        error_at("# nothing\n\n", 2, 1),
        PlanErrorKind::Empty
    ));
    // Columns count characters, not bytes.
    assert!(matches!(
        error_at("mode °", 1, 6),
        PlanErrorKind::Bad { .. }
    ));
}

#[test]
fn the_demo_plan_parses() {
    let p = parse(mmic_host::sim::report::DEMO_PLAN).unwrap();
    assert!(p.steps.len() >= 8);
    assert_eq!(mmic_host::sim::report::demo_steps().len(), p.steps.len());
}

fn balanced(svg: &str) {
    assert!(svg.starts_with("<svg") && svg.trim_end().ends_with("</svg>"));
    for bad in ["NaN", "inf"] {
        assert!(!svg.contains(bad), "{bad} in {svg}");
    }
    // Every opened element is closed (self-closing or with its end tag), in order.
    let mut stack = Vec::new();
    let mut rest = svg;
    while let Some(i) = rest.find('<') {
        let j = rest[i..].find('>').unwrap() + i;
        let tag = &rest[i + 1..j];
        if let Some(name) = tag.strip_prefix('/') {
            assert_eq!(stack.pop(), Some(name.to_string()));
        } else if !tag.ends_with('/') {
            stack.push(tag.split_whitespace().next().unwrap().to_string());
        }
        rest = &rest[j + 1..];
    }
    assert!(stack.is_empty(), "{stack:?}");
}

#[test]
fn plots_are_well_formed_for_empty_single_and_many_points() {
    let many: Vec<(f64, f64)> = (0..50).map(|i| (i as f64, (i % 7) as f64 * 10.0)).collect();
    for points in [
        &[][..],
        &[(3.0, 3.0)][..],
        &many[..],
        &[(0.0, f64::NAN), (1.0, 2.0)][..],
    ] {
        let svg = line_chart("a <b> & c", "x", "y", None, &[Series { name: "s", points }]);
        balanced(&svg);
        assert!(svg.contains("a &lt;b&gt; &amp; c"));
    }
    let svg = line_chart(
        "t",
        "x",
        "y",
        Some((0.0, 100.0)),
        &[Series {
            name: "s",
            points: &many,
        }],
    );
    let poly = svg
        .split("points=\"")
        .nth(1)
        .unwrap()
        .split('"')
        .next()
        .unwrap();
    assert_eq!(poly.split(' ').count(), 50);
    let two = line_chart(
        "t",
        "x",
        "y",
        None,
        &[
            Series {
                name: "one",
                points: &many,
            },
            Series {
                name: "two",
                points: &many,
            },
        ],
    );
    balanced(&two);
    assert!(two.contains(">one<") && two.contains(">two<"), "legend");
    let bars = bar_chart(
        "b",
        "n",
        &[("1st", 10.0), ("2nd", 0.0), ("x&y", f64::INFINITY)],
    );
    balanced(&bars);
    assert!(bars.contains(">10<") && bars.contains("x&amp;y"));
    balanced(&bar_chart("empty", "n", &[]));
}
