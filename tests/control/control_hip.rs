//! The hip PI controller on a servo plant model with a gravity load: from any start to any
//! target it settles within tolerance (0.5°, and stays within it to the end of the run), its overshoot stays under a bound, and it never leaves
//! the pulse range.
//!
//! Plant (per 10 ms tick): the continuous servo turns at 10 (0.01°/s) per µs away from 1500 µs
//! (so 100 µs ≈ 10°/s), through a first-order lag of 50 ms, minus a gravity term
//! `load · sin(angle + phase)` (0.01°/s) from the robot's weight; the encoder quantises the
//! angle to 4096 counts per turn.

use mmic::control::hip::{Config, HipController};
use mmic::units::HipAngle;
use proptest::prelude::*;

use crate::common;

const TOL: f64 = 50.0; // 0.50°
const OVERSHOOT_MAX: f64 = 150.0; // 1.50°, documented in spec/control/hip.md
/// Overshoot counts from the moment the error first comes within 10°: the side the hip
/// approaches the target from.
const APPROACH: f64 = 1000.0;
/// The path may exceed the short way by the overshoot there and back plus this: the
/// load's push at the start and the settling wobble. A turn the wrong way adds at least
/// twice the error's distance from 180°, far more for any target not within a few degrees of
/// the opposite side, and 360° − 2·short-way in general.
const DETOUR_MAX: f64 = 2.0 * OVERSHOOT_MAX + 100.0;

struct Run {
    settled_at: Option<u32>,
    overshoot: f64,
    /// Angle travelled in total, 0.01°.
    travelled: f64,
    /// How much longer the path was than the short way, 0.01°.
    detour: f64,
    min_pw: u16,
    max_pw: u16,
}

/// The angle as the controller reads it: the true angle quantised to the encoder's 4096
/// counts per turn, each count read as the centre of its 0.088° bin.
fn encoder(angle: f64) -> HipAngle {
    let count = (angle.rem_euclid(36000.0) / 36000.0 * 4096.0).floor() as u32 % 4096;
    HipAngle::new(((count * 36000 + 2048) / 4096 % 36000) as u16).unwrap()
}

fn simulate(start: f64, target: u16, load: f64, phase: f64, seconds: u32) -> Run {
    let mut c = HipController::new(Config::default());
    let tgt = HipAngle::new(target).unwrap();
    let mut angle = start;
    let mut speed = 0.0f64; // 0.01°/s
    let mut run = Run {
        settled_at: None,
        overshoot: 0.0,
        travelled: 0.0,
        detour: 0.0,
        min_pw: u16::MAX,
        max_pw: 0,
    };
    // Which way is right is judged on the true angle, with the quantisation and the load in
    // mind: near 180° both ways are equally short, and the encoder's rounding (start 424,
    // target 18423: 179.99° true, 180.01° measured) or the load's first push decides. So the
    // oracle does not fix a direction in advance: the path travelled must be a short way
    // (`detour`), and overshoot is measured against the side the hip approached from
    // (`approach`: the sign of the error when it first came within APPROACH).
    let shortest = short_way(start, target);
    let mut approach: Option<f64> = None;
    let mut last = start;
    let dt = 0.01;
    for tick in 0..(seconds * 100) {
        let m = encoder(angle);
        let pw = c.step(tgt, m, tick * 10);
        run.min_pw = run.min_pw.min(pw.micros());
        run.max_pw = run.max_pw.max(pw.micros());
        let cmd = (pw.micros() as f64 - 1500.0) * 10.0;
        speed += (cmd - speed) * (dt / 0.05);
        let grav = load * ((angle / 36000.0 * std::f64::consts::TAU) + phase).sin();
        angle += (speed - grav) * dt;
        let true_err = {
            let mut d = target as f64 - angle.rem_euclid(36000.0);
            if d > 18000.0 {
                d -= 36000.0
            }
            if d <= -18000.0 {
                d += 36000.0
            }
            d
        };
        run.travelled += (angle - last).abs();
        last = angle;
        if approach.is_none() && true_err.abs() <= APPROACH {
            approach = Some(true_err.signum());
        }
        // Overshoot: error of the opposite sign to the approach.
        if let Some(dir) = approach
            && true_err * dir < 0.0
        {
            run.overshoot = run.overshoot.max(true_err.abs());
        }
        // Settled: within TOL from this tick to the end of the run. Any later tick outside
        // the band, by any amount, un-settles it.
        if true_err.abs() <= TOL {
            run.settled_at.get_or_insert(tick);
        } else {
            run.settled_at = None;
        }
    }
    run.detour = run.travelled - shortest;
    run
}

/// The true angular distance from `start` to `target` the short way, 0.01° (0..=18000).
fn short_way(start: f64, target: u16) -> f64 {
    let d = (target as f64 - start).rem_euclid(36000.0);
    d.min(36000.0 - d)
}

proptest! {
    #![proptest_config(common::prop::config(200))]
    // req: P5.5, P5.8
    #[test]
    fn reaches_any_target_without_large_overshoot(start in 0u16..36000, target in 0u16..36000, load in 0.0f64..300.0, phase in 0.0f64..6.3) {
        // 180° at 10°/s takes 18 s; allow 30 s.
        let r = simulate(start as f64, target, load, phase, 30);
        prop_assert!(r.settled_at.is_some(), "never settled");
        prop_assert!(r.overshoot <= OVERSHOOT_MAX, "overshoot {}", r.overshoot);
        prop_assert!(r.detour <= DETOUR_MAX, "travelled {} past the short way", r.detour);
        prop_assert!(r.min_pw >= 1200 && r.max_pw <= 1800);
    }
}

/// The input that made the property test flaky (about 1 run in 100): a target 179.99° from the
/// true start reads 180.01° through the encoder, so the controller turns the other way. Kept as
/// a fixed case over loads and phases, because proptest's random inputs rarely land within one
/// encoder count of 180°.
// req: P5.5
#[test]
fn half_turn_within_one_encoder_count_takes_either_short_way() {
    for load in [0.0, 150.0, 300.0] {
        for quarter in 0..4 {
            let phase = quarter as f64 * std::f64::consts::FRAC_PI_2;
            let r = simulate(424.0, 18423, load, phase, 30);
            assert!(
                r.settled_at.is_some(),
                "never settled (load {load}, phase {phase})"
            );
            assert!(
                r.overshoot <= OVERSHOOT_MAX,
                "overshoot {} (load {load}, phase {phase})",
                r.overshoot
            );
            assert!(
                r.detour <= DETOUR_MAX,
                "detour {} (load {load}, phase {phase})",
                r.detour
            );
        }
    }
}

// req: P2.9, P5.6, P5.7
#[test]
fn turns_at_about_ten_degrees_per_second() {
    // 90° with no load: velocity mode until 3°, so about 9 s plus the final approach.
    let r = simulate(0.0, 9000, 0.0, 0.0, 30);
    let t = r.settled_at.unwrap() as f64 / 100.0;
    assert!((8.0..=12.0).contains(&t), "took {t} s");
}

// req: P5.8
#[test]
fn sweep_reports_the_worst_case() {
    let mut worst_overshoot: f64 = 0.0;
    let mut worst_settle = 0u32;
    let mut worst_detour: f64 = 0.0;
    let mut runs = 0;
    for s in (0..36000).step_by(3000) {
        for t in (0..36000u16).step_by(3000) {
            for load in [0.0, 150.0, 300.0] {
                for quarter in 0..4 {
                    let phase = quarter as f64 * std::f64::consts::FRAC_PI_2;
                    let r = simulate(s as f64 + 37.0, t, load, phase, 30);
                    let settled = r
                        .settled_at
                        .unwrap_or_else(|| panic!("{s} -> {t} load {load} phase {phase}"));
                    worst_settle = worst_settle.max(settled);
                    worst_overshoot = worst_overshoot.max(r.overshoot);
                    worst_detour = worst_detour.max(r.detour);
                    runs += 1;
                }
            }
        }
    }
    println!(
        "hip sweep: {runs} runs, worst settle {:.2} s, worst overshoot {:.1}, worst detour {:.1} (0.01 deg)",
        worst_settle as f64 / 100.0,
        worst_overshoot,
        worst_detour
    );
    assert!(worst_overshoot <= OVERSHOOT_MAX);
    assert!(worst_detour <= DETOUR_MAX);
}

/// spec/control/hip.md's parameter table is the code's defaults: each row names one parameter
/// (or two, "a / b") and gives its default first in the value column (likewise "x / y").
// req: P5.6, P5.7
#[test]
fn the_defaults_equal_the_table_of_spec_control_hip_md() {
    let md = std::fs::read_to_string(concat!(env!("CARGO_MANIFEST_DIR"), "/spec/control/hip.md"))
        .unwrap();
    let c = Config::default();
    let code: [(&str, i64); 9] = [
        ("position_band", c.position_band.into()),
        ("speed", c.speed.into()),
        ("servo_gain", c.servo_gain.into()),
        ("kp_velocity_q8", c.kp_velocity_q8.into()),
        ("ki_velocity_q8", c.ki_velocity_q8.into()),
        ("kp_position_q8", c.kp_position_q8.into()),
        ("ki_position_q8", c.ki_position_q8.into()),
        ("max_offset_us", c.max_offset_us.into()),
        ("smoothing_shift", c.smoothing_shift.into()),
    ];
    let mut table = std::collections::BTreeMap::new();
    for line in md.lines() {
        let cells: Vec<&str> = line.split('|').map(str::trim).collect();
        let [_, names, values, ..] = cells[..] else {
            continue;
        };
        let values: Vec<i64> = values
            .split(" / ")
            .filter_map(|v| v.split_whitespace().next()?.parse().ok())
            .collect();
        for (name, value) in names.split(" / ").zip(values) {
            table.insert(name.to_string(), value);
        }
    }
    for (name, value) in &code {
        assert_eq!(table.get(*name), Some(value), "spec/control/hip.md: {name}");
    }
    assert_eq!(table.len(), code.len(), "{table:?}");
}

/// The controller's law and velocity estimate as the heartbeat and the logs read them: far
/// from the target it tracks a speed (Velocity) and its estimate follows the hip turning;
/// at the target it holds the angle (Position); without a reading it starts afresh.
#[test]
fn the_law_and_the_velocity_estimate_follow_the_hip() {
    use mmic::control::hip::Mode;
    let mut c = HipController::new(Config::default());
    assert_eq!((c.mode(), c.velocity()), (Mode::Position, 0));
    let target = HipAngle::STRAIGHT;
    // Far from the target, turning 1° every 10 ms tick toward it.
    for t in 0..20u32 {
        let at = HipAngle::wrapping(9000 + 100 * t as u16);
        c.step(target, at, t * 10);
    }
    assert_eq!(c.mode(), Mode::Velocity);
    assert!(c.velocity() > 0, "{}", c.velocity());
    c.blind();
    assert_eq!((c.mode(), c.velocity()), (Mode::Position, 0));
    // At the target and still: Position.
    for t in 0..5u32 {
        c.step(target, target, 1_000 + t * 10);
    }
    assert_eq!(c.mode(), Mode::Position);
}
