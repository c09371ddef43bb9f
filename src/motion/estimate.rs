//! State estimation: which of the 15 states agree with the sensors (both boards' gravity
//! direction, the arm-contracted switches and the hip angle), given how the structure sits
//! relative to gravity. Used by the initial-state-mismatch check (Table 8). The paper computes
//! that state from "IMU measurements and PWM values"; the PWM values are the firmware's own
//! commands, which a robot positioned by hand in Standby does not change, so the switches and
//! the encoder that measure what they set are read instead (spec/decisions.toml,
//! `initial-state-sensors`).
//!
//! **Sensor model** (spec/motion/estimation.md). Each board's IMU frame is fixed to its side:
//! x along that side's arm (hip → gripper), z along the hip axis, y = z × x. Gravity is one of
//! the six axis directions of the structure frame (`Config::up` is the structure axis that
//! points up), so each reading is exactly one axis and sign. In a matched state both arms are
//! contracted; in a two-face state at least one is extended (the sequencer extends only the
//! moving arm). The hip angle is 180° when the arms are in
//! line (matched and stretch states) and 90° or 270° in a turn; in a turn it also fixes the hip
//! axis (h = dirA × dirB at 90°, −dirA × dirB at 270°), while in line the hip axis may be any of
//! the four directions across the arms — the estimator tries them all.
//!
//! ```
//! use mmic::motion::estimate::{consistent, predict, Config, Readings};
//! use mmic::motion::State;
//! let cfg = Config::default(); // structure Z up
//! for r in predict(&cfg, State::E) {
//!     assert!(consistent(&cfg, &r).contains(State::E));
//! }
//! ```

use crate::pose::geometry::{arm_direction, cross, unit, Vec3};
use crate::pose::State;
use crate::units::{Axis, Gravity, HipAngle, Side, Sign};

/// A set of states (bit i = Table 5 index i).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Default, PartialOrd, Ord)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct StateSet(u16);

impl StateSet {
    /// No state.
    pub const EMPTY: StateSet = StateSet(0);

    /// The set plus `s`.
    pub const fn with(self, s: State) -> StateSet {
        StateSet(self.0 | 1 << s.index())
    }

    /// Whether `s` is in the set.
    pub const fn contains(self, s: State) -> bool {
        self.0 & (1 << s.index()) != 0
    }

    /// Number of states.
    pub const fn len(self) -> u32 {
        self.0.count_ones()
    }

    /// Whether the set is empty.
    pub const fn is_empty(self) -> bool {
        self.0 == 0
    }

    /// Raw bits.
    pub const fn bits(self) -> u16 {
        self.0
    }

    /// The states in Table 5 order.
    pub fn iter(self) -> impl Iterator<Item = State> {
        State::ALL.into_iter().filter(move |s| self.contains(*s))
    }
}

/// Estimation settings.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Config {
    /// The structure axis pointing up (gravity points the other way). Default: +Z.
    pub up: (Axis, Sign),
    /// Hip tolerance around 90°, 180° and 270°, in 0.01°. Default 10.00°.
    pub hip_tolerance: u16,
}

impl Default for Config {
    fn default() -> Config {
        Config {
            up: (Axis::Z, Sign::Positive),
            hip_tolerance: 1000,
        }
    }
}

/// What the sensors say, already filtered.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Readings {
    /// Gravity in board A's IMU frame; none = no reading (not used).
    pub gravity_a: Option<Gravity>,
    /// Gravity in board B's IMU frame (Table 4 bytes 36–37); none = not used.
    pub gravity_b: Option<Gravity>,
    /// Arm A's contraction switch.
    pub arm_a_contracted: bool,
    /// Arm B's contraction switch (Table 4 byte 44).
    pub arm_b_contracted: bool,
    /// Hip encoder angle.
    pub hip: HipAngle,
}

fn dot(a: Vec3, b: Vec3) -> i8 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

fn neg(v: Vec3) -> Vec3 {
    [-v[0], -v[1], -v[2]]
}

/// Gravity as a board whose frame is (x = `arm`, z = `hip_axis`) reads it.
fn read(g: Vec3, arm: Vec3, hip_axis: Vec3) -> Option<Gravity> {
    let y = cross(hip_axis, arm);
    let comps = [
        (Axis::X, dot(g, arm)),
        (Axis::Y, dot(g, y)),
        (Axis::Z, dot(g, hip_axis)),
    ];
    comps
        .into_iter()
        .find(|c| c.1 != 0)
        .map(|(axis, v)| Gravity {
            axis,
            sign: if v > 0 {
                Sign::Positive
            } else {
                Sign::Negative
            },
        })
}

const ALL_DIRS: [Vec3; 6] = [
    [1, 0, 0],
    [-1, 0, 0],
    [0, 1, 0],
    [0, -1, 0],
    [0, 0, 1],
    [0, 0, -1],
];

/// The (hip axis, hip angle) pairs the model allows in `s`.
fn hip_options(s: State) -> impl Iterator<Item = (Vec3, u16)> {
    let a = arm_direction(s, Side::A);
    let b = arm_direction(s, Side::B);
    let c = cross(a, b);
    let in_line = c == [0, 0, 0];
    let mut out = [([0i8; 3], 0u16); 4];
    let mut n = 0;
    if in_line {
        for h in ALL_DIRS {
            if dot(h, a) == 0 && n < 4 {
                out[n] = (h, 18000);
                n += 1;
            }
        }
    } else {
        out[0] = (c, 9000);
        out[1] = (neg(c), 27000);
        n = 2;
    }
    out.into_iter().take(n)
}

fn gravity(cfg: &Config) -> Vec3 {
    neg(unit(cfg.up.0, cfg.up.1))
}

/// Every reading the model allows in state `s` (per hidden hip-axis choice and, in a two-face
/// state, per arm combination with at least one arm extended).
pub fn predict(cfg: &Config, s: State) -> impl Iterator<Item = Readings> {
    let g = gravity(cfg);
    let (a, b) = (arm_direction(s, Side::A), arm_direction(s, Side::B));
    let arms: &'static [(bool, bool)] = if s.is_matched() {
        &[(true, true)]
    } else {
        &[(false, false), (false, true), (true, false)]
    };
    hip_options(s).flat_map(move |(h, angle)| {
        arms.iter().map(move |&(ca, cb)| Readings {
            gravity_a: read(g, a, h),
            gravity_b: read(g, b, h),
            arm_a_contracted: ca,
            arm_b_contracted: cb,
            hip: HipAngle::new(angle).unwrap_or(HipAngle::ZERO),
        })
    })
}

fn hip_close(cfg: &Config, a: HipAngle, b: HipAngle) -> bool {
    a.distance(b) <= cfg.hip_tolerance
}

/// The states consistent with `r`: those for which some hidden hip-axis choice predicts the
/// same gravity readings (where given), switches, and a hip angle within tolerance.
pub fn consistent(cfg: &Config, r: &Readings) -> StateSet {
    let mut set = StateSet::EMPTY;
    for s in State::ALL {
        let ok = predict(cfg, s).any(|p| {
            r.gravity_a.is_none_or(|g| p.gravity_a == Some(g))
                && r.gravity_b.is_none_or(|g| p.gravity_b == Some(g))
                && p.arm_a_contracted == r.arm_a_contracted
                && p.arm_b_contracted == r.arm_b_contracted
                && hip_close(cfg, p.hip, r.hip)
        });
        if ok {
            set = set.with(s);
        }
    }
    set
}

/// The initial-state-mismatch check: a reconfiguration's initial state must be the tracked
/// state (when the robot tracks one) and agree with the sensors.
pub fn initial_state_consistent(initial: State, tracked: Option<State>, sensed: StateSet) -> bool {
    tracked.is_none_or(|t| t == initial) && sensed.contains(initial)
}
