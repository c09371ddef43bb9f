//! spec/control/servos.toml equals the code's defaults: the interpolation rate of both boards,
//! the arms' and grippers' travel (the library's and both boards' configured ones), the hip's
//! done tolerance and speed, and the module-motion deadline's margins.

use mmic::control::{deadline, hip, interp};
use mmic::node::robot::{board_a, board_b};
use serde::Deserialize;

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct Spec {
    interpolation: Interpolation,
    travel: Travels,
    hip: Hip,
    deadline: Deadline,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct Interpolation {
    step_us: u16,
    period_ms: u32,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct Travels {
    arm: Travel,
    gripper: Travel,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct Travel {
    contracted_us: u16,
    extended_us: u16,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct Hip {
    done_tolerance_cdeg: u16,
    speed_cdeg_per_s: i32,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct Deadline {
    servo_margin_ms: u32,
    hip_margin_ms: u32,
}

fn spec() -> Spec {
    let p = concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../../spec/control/servos.toml"
    );
    toml::from_str(&std::fs::read_to_string(p).unwrap()).unwrap()
}

fn pair(t: interp::Travel) -> (u16, u16) {
    (t.contracted.micros(), t.extended.micros())
}

// req: P5.1
#[test]
fn servo_defaults_equal_spec() {
    let s = spec();
    let (a, b) = (board_a::Config::default(), board_b::Config::default());
    for rate in [a.rate, b.rate, interp::Rate::default()] {
        assert_eq!(
            (rate.step_us, rate.period_ms),
            (s.interpolation.step_us, s.interpolation.period_ms)
        );
    }
    let arm = (s.travel.arm.contracted_us, s.travel.arm.extended_us);
    let gripper = (s.travel.gripper.contracted_us, s.travel.gripper.extended_us);
    for t in [interp::Travel::ARM, a.arm, b.arm] {
        assert_eq!(pair(t), arm);
    }
    for t in [interp::Travel::GRIPPER, a.gripper, b.gripper] {
        assert_eq!(pair(t), gripper);
    }
    assert_eq!(a.hip_done_tolerance, s.hip.done_tolerance_cdeg);
    assert_eq!(a.hip.speed, s.hip.speed_cdeg_per_s);
    assert_eq!(hip::Config::default().speed, s.hip.speed_cdeg_per_s);
    let d = deadline::Config::default();
    assert_eq!(a.deadline, d);
    assert_eq!(
        (d.servo_margin_ms, d.hip_margin_ms),
        (s.deadline.servo_margin_ms, s.deadline.hip_margin_ms)
    );
}

/// The travel the spec states is the one the command decoder enforces: its ends accepted, one
/// past each refused with the range in the message.
// req: D:servo-travel
#[test]
fn the_decoder_enforces_the_spec_travel() {
    use mmic::wire::opcode::{decode, CommandError};
    let s = spec();
    for (base, t) in [(0x20u8, &s.travel.arm), (0x28, &s.travel.gripper)] {
        let (min, max) = (t.contracted_us, t.extended_us);
        for (us, ok) in [(min - 1, false), (min, true), (max, true), (max + 1, false)] {
            let mut p = [0u8; 6];
            p[2..4].copy_from_slice(&us.to_le_bytes());
            let r = decode(base + 2, p);
            assert_eq!(r.is_ok(), ok, "{base:#x} {us}: {r:?}");
            if let Err(e) = r {
                assert!(matches!(e, CommandError::OutOfTravel { .. }), "{e:?}");
                assert!(
                    e.to_string()
                        .contains(&format!("{min}..={max} us, found {us}")),
                    "{e}"
                );
            }
        }
    }
}

/// A mirrored servo (its contracted pulse above its extended one) has the same travel bounds:
/// `min` and `max` are the pulses' order, whichever end each is.
#[test]
fn a_mirrored_travel_has_the_same_bounds() {
    use mmic::command::Travel;
    use mmic::units::PulseWidth;
    let pw = |us| PulseWidth::new(us).unwrap();
    let plain = Travel {
        contracted: pw(900),
        extended: pw(2100),
    };
    let mirrored = Travel {
        contracted: pw(2100),
        extended: pw(900),
    };
    for t in [plain, mirrored] {
        assert_eq!((t.min(), t.max()), (pw(900), pw(2100)), "{t:?}");
    }
}
