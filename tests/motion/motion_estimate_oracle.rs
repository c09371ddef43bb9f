//! State estimation against an independent sensor simulation over all 24 orientations of the
//! structure.
//!
//! `tests/motion/motion_estimate.rs` feeds the estimator the readings of its own `predict`, which shares
//! the estimator's code. Here the readings come from separate code: each of the 24 proper
//! rotations of the cube (signed permutation matrices with determinant +1) places the structure
//! in a world where gravity is −Z; each IMU frame is built from the arm and hip-axis vectors
//! (x = arm, z = hip axis, y = z × x, spec/motion/estimation.md) and reads gravity as its
//! largest component; hip angles are taken at the nominal value and at both edges of the
//! tolerance; the arms' PWM values follow the arm poses the sequencer leaves. For each case the true
//! state must be in the estimated set, and the estimate must not depend on the rotation about
//! gravity (the claim that six "up" directions cover the 24 orientations).

use mmic::motion::estimate::{consistent, ArmPwm, Config, Readings, StateSet};
use mmic::motion::geometry::arm_direction;
use mmic::motion::{State, StateKind};
use mmic::units::{Axis, Gravity, HipAngle, PerSide, Side, Sign};

type V = [i32; 3];

fn cross(a: V, b: V) -> V {
    [
        a[1] * b[2] - a[2] * b[1],
        a[2] * b[0] - a[0] * b[2],
        a[0] * b[1] - a[1] * b[0],
    ]
}

fn dot(a: V, b: V) -> i32 {
    a.iter().zip(b).map(|(x, y)| x * y).sum()
}

/// The 24 rotations: rows of a signed permutation matrix, determinant +1.
fn rotations() -> Vec<[V; 3]> {
    let perms = [
        [0, 1, 2],
        [0, 2, 1],
        [1, 0, 2],
        [1, 2, 0],
        [2, 0, 1],
        [2, 1, 0],
    ];
    let mut out = vec![];
    for p in perms {
        for signs in 0..8 {
            let mut m = [[0; 3]; 3];
            for r in 0..3 {
                m[r][p[r]] = if signs & (1 << r) != 0 { -1 } else { 1 };
            }
            let det = dot(m[0], cross(m[1], m[2]));
            if det == 1 {
                out.push(m);
            }
        }
    }
    out
}

/// World vector of structure vector `v` under rotation `m` (structure → world).
fn apply(m: &[V; 3], v: V) -> V {
    [dot(m[0], v), dot(m[1], v), dot(m[2], v)]
}

/// Structure vector of world vector `w` (the transpose).
fn apply_t(m: &[V; 3], w: V) -> V {
    let mut out = [0; 3];
    for (r, row) in m.iter().enumerate() {
        for c in 0..3 {
            out[c] += row[c] * w[r];
        }
    }
    out
}

fn v(x: [i8; 3]) -> V {
    [x[0] as i32, x[1] as i32, x[2] as i32]
}

/// Gravity as an IMU with frame (x = arm, z = hip) reads it: the largest component.
fn imu(g: V, arm: V, hip: V) -> Gravity {
    let y = cross(hip, arm);
    let comps = [
        (Axis::X, dot(g, arm)),
        (Axis::Y, dot(g, y)),
        (Axis::Z, dot(g, hip)),
    ];
    let (axis, val) = comps
        .into_iter()
        .max_by_key(|c| c.1.abs())
        .expect("three components");
    Gravity {
        axis,
        sign: if val > 0 {
            Sign::Positive
        } else {
            Sign::Negative
        },
    }
}

fn up_of(g_structure: V) -> (Axis, Sign) {
    let i = g_structure
        .iter()
        .position(|c| *c != 0)
        .expect("unit vector");
    let axis = Axis::ALL[i];
    // gravity = −up
    (
        axis,
        if g_structure[i] < 0 {
            Sign::Positive
        } else {
            Sign::Negative
        },
    )
}

const DIRS: [V; 6] = [
    [1, 0, 0],
    [-1, 0, 0],
    [0, 1, 0],
    [0, -1, 0],
    [0, 0, 1],
    [0, 0, -1],
];

// req: P2.5
#[test]
fn true_state_in_estimate_under_an_independent_simulation_for_all_24_orientations() {
    let rots = rotations();
    assert_eq!(rots.len(), 24);
    let tol = Config::default().hip_tolerance;
    let mut cases = 0u32;
    // Estimates per (up, readings): must not depend on the rotation about gravity.
    let mut by_up: std::collections::BTreeMap<(u8, u8, String), StateSet> = Default::default();
    for m in &rots {
        // The rotation really is a rotation: it preserves the right-hand rule.
        assert_eq!(
            apply(m, cross([1, 0, 0], [0, 1, 0])),
            cross(apply(m, [1, 0, 0]), apply(m, [0, 1, 0]))
        );
        let g = apply_t(m, [0, 0, -1]);
        let cfg = Config {
            up: up_of(g),
            ..Config::default()
        };
        for s in State::ALL {
            let a = v(arm_direction(s, Side::A));
            let b = v(arm_direction(s, Side::B));
            let c = cross(a, b);
            // (hip axis, nominal hip angle) poses of the state
            let poses: Vec<(V, u16)> = if c == [0, 0, 0] {
                DIRS.iter()
                    .filter(|h| dot(**h, a) == 0)
                    .map(|h| (*h, 18000))
                    .collect()
            } else {
                vec![(c, 9000), ([-c[0], -c[1], -c[2]], 27000)]
            };
            // The arms' commanded PWM values the sequencer can leave: both contracted in a
            // match, at least one extended otherwise.
            let (c, e) = (ArmPwm::Contracted, ArmPwm::Extended);
            let arms: &[(ArmPwm, ArmPwm)] = if s.is_matched() {
                &[(c, c)]
            } else {
                &[(c, e), (e, c), (e, e)]
            };
            for (h, nominal) in poses {
                let (ga, gb) = (imu(g, a, h), imu(g, b, h));
                for dh in [-(tol as i32), 0, tol as i32] {
                    let hip =
                        HipAngle::new((nominal as i32 + dh).rem_euclid(36000) as u16).unwrap();
                    for &(ca, cb) in arms {
                        for (ua, ub) in [(true, true), (true, false), (false, true), (false, false)]
                        {
                            let r = Readings {
                                gravity_a: Some(ga).filter(|_| ua),
                                gravity_b: Some(gb).filter(|_| ub),
                                arm: PerSide::new(ca, cb),
                                hip,
                            };
                            let set = consistent(&cfg, &r);
                            assert!(set.contains(s), "{s} rot {m:?}: {r:?} -> {set:?}");
                            let key = (cfg.up.0 as u8, cfg.up.1 as u8, format!("{r:?}"));
                            if let Some(prev) = by_up.insert(key, set) {
                                assert_eq!(
                                    prev, set,
                                    "estimate depends on the rotation about gravity"
                                );
                            }
                            cases += 1;
                        }
                    }
                }
            }
        }
    }
    // 24 rotations × Σ_states (poses × arm combinations) × 3 hip values × 4 gravity subsets.
    let per_rot: u32 = State::ALL
        .iter()
        .map(|s| {
            let poses = if s.kind() == StateKind::Turn { 2 } else { 4 };
            let arms = if s.is_matched() { 1 } else { 3 };
            poses * arms
        })
        .sum();
    assert_eq!(cases, 24 * per_rot * 3 * 4);
    println!("estimator vs independent simulation: {cases} cases over 24 orientations");
}

/// The estimate is not vacuous: a reading of a matched pose never admits a two-face state, and
/// a right-angle hip never admits a state with the arms in line.
#[test]
fn estimate_separates_shapes() {
    let cfg = Config::default();
    let hip = |c| HipAngle::new(c).unwrap();
    let r = Readings {
        gravity_a: None,
        gravity_b: None,
        arm: PerSide::both(ArmPwm::Contracted),
        hip: hip(18000),
    };
    assert!(consistent(&cfg, &r).iter().all(|s| s.is_matched()));
    assert_eq!(consistent(&cfg, &r).len(), 6);
    let r = Readings {
        arm: PerSide::new(ArmPwm::Extended, ArmPwm::Contracted),
        hip: hip(9000),
        ..r
    };
    assert!(consistent(&cfg, &r)
        .iter()
        .all(|s| s.kind() == StateKind::Turn));
    let r = Readings {
        hip: hip(4500),
        ..r
    };
    assert!(consistent(&cfg, &r).is_empty());
}
