//! State estimation: which of the 15 states agree with what board A knows of the robot — both
//! boards' gravity direction, the PWM values it commands the two arms and the hip angle — given
//! how the structure sits relative to gravity. Used by the initial-state-mismatch check of a
//! reconfiguration (Table 8), which computes the current state, as Section 7 says, "using IMU
//! measurements and PWM values" (spec/decisions.toml, `initial-state-sensors`).
//!
//! **PWM values.** An arm's PWM value is the pulse width board A commands it: arm A's as its
//! own servo output writes it, arm B's as the A→B command carries it (board A commands B). Read
//! against the arm's travel ([`ArmPwm::of`]) it is contracted, extended or between. Entering
//! Operational sends every actuator home (contracted, Section 7) and reconfigurations are taken
//! only there, so the commanded values are where the powered arms are. The hip is a continuous
//! servo whose PWM value is a speed (Section 2), not a position: its angle is the encoder's, the
//! reading the hip loop closes on.
//!
//! **The switches** are not read for the state: they are Table 8's arm check at the start of the
//! motion ([`unsensed_contraction`]): an arm commanded contracted whose switch does not sense the
//! contraction is "arm not fully contracted", not a wrong belief of where the robot is.
//!
//! **Sensor model** (spec/motion/estimation.md). Each board's IMU frame is fixed to its side:
//! x along that side's arm (hip → gripper), z along the hip axis, y = z × x. Gravity is one of
//! the six axis directions of the structure frame (`Config::up` is the structure axis that
//! points up), so each reading is exactly one axis and sign. In a matched state both arms are
//! commanded contracted; in a two-face state at least one is commanded extended and neither
//! stands between (the sequencer extends only the moving arm). The hip angle is 180° when the
//! arms are in line (matched and stretch states) and 90° or 270° in a turn; in a turn it also
//! fixes the hip axis (h = dirA × dirB at 90°, −dirA × dirB at 270°), while in line the hip
//! axis may be any of the four directions across the arms — the estimator tries them all.
//!
//! ```
//! use mmic::motion::estimate::{consistent, predict, Config, Readings};
//! use mmic::motion::State;
//! let cfg = Config::default(); // structure Z up
//! for r in predict(&cfg, State::E) {
//!     assert!(consistent(&cfg, &r).contains(State::E));
//! }
//! ```
// req: P2.5, P7.10, D:initial-state-sensors

use crate::command::Travel;
use crate::faults::Fault;
use crate::pose::geometry::{arm_direction, cross, unit, Vec3};
use crate::pose::State;
use crate::refusal::Refusal;
use crate::units::{Axis, Gravity, HipAngle, PerSide, PulseWidth, Side, Sign};

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

/// Where an arm's PWM value puts it: at one end of the arm's travel, or between them.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum ArmPwm {
    /// The travel's contracted end ("totally contract", Table 1).
    Contracted,
    /// The travel's extended end ("totally extend").
    Extended,
    /// Any other pulse: a partial position, which no Table 5 state has.
    Between,
}

impl ArmPwm {
    /// Every value.
    pub const ALL: [ArmPwm; 3] = [ArmPwm::Contracted, ArmPwm::Extended, ArmPwm::Between];

    /// `pulse` read against the arm's `travel`. The ends are exact: a commanded value is the
    /// interpolator's, which lands on its target (src/control/interp.rs), and a contraction or
    /// extension command targets the travel's end itself.
    ///
    /// ```
    /// use mmic::command::Travel;
    /// use mmic::motion::estimate::ArmPwm;
    /// use mmic::units::PulseWidth;
    /// assert_eq!(ArmPwm::of(&Travel::ARM, Travel::ARM.contracted), ArmPwm::Contracted);
    /// assert_eq!(ArmPwm::of(&Travel::ARM, PulseWidth::new(1500).unwrap()), ArmPwm::Between);
    /// ```
    pub fn of(travel: &Travel, pulse: PulseWidth) -> ArmPwm {
        if pulse == travel.contracted {
            ArmPwm::Contracted
        } else if pulse == travel.extended {
            ArmPwm::Extended
        } else {
            ArmPwm::Between
        }
    }
}

/// What board A knows of the robot's state: the IMUs' gravity, already filtered, the arms' PWM
/// values and the hip encoder.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Readings {
    /// Gravity in board A's IMU frame; none = no reading (not used).
    pub gravity_a: Option<Gravity>,
    /// Gravity in board B's IMU frame (Table 4 bytes 36–37); none = not used.
    pub gravity_b: Option<Gravity>,
    /// Each arm's PWM value as board A commands it (arm B's through the A→B command).
    pub arm: PerSide<ArmPwm>,
    /// Hip encoder angle (the hip's PWM value is a speed: it gives no position).
    pub hip: HipAngle,
}

/// Dot product of the model's vectors (unit vectors and their cross products, components in
/// −1..=1): each product is in −1..=1 and the sum in −3..=3, so the wrapping operations (free on
/// board A's tick, which estimates every state; coding standard R4, "exact") never wrap.
fn dot(a: Vec3, b: Vec3) -> i8 {
    let [a0, a1, a2] = a;
    let [b0, b1, b2] = b;
    a0.wrapping_mul(b0)
        .wrapping_add(a1.wrapping_mul(b1))
        .wrapping_add(a2.wrapping_mul(b2))
}

/// `−v`, of a model vector (components in −1..=1: the negation is exact).
fn neg(v: Vec3) -> Vec3 {
    let [x, y, z] = v;
    [x.wrapping_neg(), y.wrapping_neg(), z.wrapping_neg()]
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
    let n;
    if in_line {
        let across = ALL_DIRS.into_iter().filter(|&h| dot(h, a) == 0);
        n = out
            .iter_mut()
            .zip(across)
            .map(|(slot, h)| *slot = (h, 18000))
            .count();
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

/// The arms' PWM values a matched state has: both contracted.
const MATCHED_ARMS: [PerSide<ArmPwm>; 1] = [PerSide::both(ArmPwm::Contracted)];

/// The arms' PWM values a two-face state has: at least one arm extended, the other extended or
/// contracted.
const TWO_FACE_ARMS: [PerSide<ArmPwm>; 3] = [
    PerSide::both(ArmPwm::Extended),
    PerSide::new(ArmPwm::Extended, ArmPwm::Contracted),
    PerSide::new(ArmPwm::Contracted, ArmPwm::Extended),
];

/// Every reading the model allows in state `s` (per hidden hip-axis choice and, in a two-face
/// state, per arm combination with at least one arm extended).
pub fn predict(cfg: &Config, s: State) -> impl Iterator<Item = Readings> + use<> {
    let g = gravity(cfg);
    let (a, b) = (arm_direction(s, Side::A), arm_direction(s, Side::B));
    hip_options(s).flat_map(move |(h, angle)| {
        arms_of(s).iter().map(move |&arm| Readings {
            gravity_a: read(g, a, h),
            gravity_b: read(g, b, h),
            arm,
            hip: hip_angle(angle),
        })
    })
}

/// The arms' PWM values state `s` allows.
fn arms_of(s: State) -> &'static [PerSide<ArmPwm>] {
    if s.is_matched() {
        &MATCHED_ARMS
    } else {
        &TWO_FACE_ARMS
    }
}

/// A hip option's angle (0.01°) as the reading it predicts: 90°, 180° and 270° are all valid.
fn hip_angle(angle: u16) -> HipAngle {
    HipAngle::new(angle).unwrap_or(HipAngle::ZERO)
}

fn hip_close(cfg: &Config, a: HipAngle, b: HipAngle) -> bool {
    a.distance(b) <= cfg.hip_tolerance
}

/// The states consistent with `r`: those for which some reading of [`predict`] has the same
/// gravity readings (where given), arm PWM values, and a hip angle within tolerance.
///
/// The same test as `predict(cfg, s).any(..)`, with its terms taken cheapest first: a state
/// whose arm PWM values differ from `r`'s is out before any geometry, and a hip option whose
/// angle is out of tolerance before its gravity is computed. Board A runs this on the tick a
/// reconfiguration arrives, its most expensive tick: with the search over every prediction
/// board A's part of that tick took 29,334 RV32 instructions, 10,113 in this order (issue 40,
/// `benches/rv32`). `tests/motion/motion_estimate.rs` checks it against that search.
pub fn consistent(cfg: &Config, r: &Readings) -> StateSet {
    let g = gravity(cfg);
    let mut set = StateSet::EMPTY;
    for s in State::ALL {
        if !arms_of(s).contains(&r.arm) {
            continue;
        }
        let (a, b) = (arm_direction(s, Side::A), arm_direction(s, Side::B));
        let ok = hip_options(s).any(|(h, angle)| {
            hip_close(cfg, hip_angle(angle), r.hip)
                && r.gravity_a.is_none_or(|x| read(g, a, h) == Some(x))
                && r.gravity_b.is_none_or(|x| read(g, b, h) == Some(x))
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

/// Table 8's arm check when a reconfiguration arrives: the first arm (A, then B) whose PWM value
/// board A commands is the contracted one while its `switch` does not sense the contraction.
/// Table 8's trigger, "After executing an arm contraction command, the contraction is not sensed
/// by hardware", holds for it; receiving a reconfiguration is the start of a motion, where
/// Section 7 says the fault happens. An arm commanded extended or between is not checked: its
/// switch is open when it works, and Table 8 names no fault for a switch closed on it.
pub fn unsensed_contraction(arm: PerSide<ArmPwm>, switch: PerSide<bool>) -> Option<Side> {
    Side::ALL
        .into_iter()
        .find(|s| arm[*s] == ArmPwm::Contracted && !switch[*s])
}

/// Why a reconfiguration is not taken when it arrives: one of Table 8's two faults it can meet.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, thiserror::Error)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum InitialStateError {
    /// Arm not fully contracted: this arm is commanded contracted and its switch does not sense
    /// it (Safed: the arms stay powered).
    #[error("arm {0} is commanded contracted but its switch does not sense the contraction")]
    ArmNotContracted(Side),
    /// Initial state mismatch: the command's initial state is not the tracked state or not one
    /// the readings allow (Standby: the robot is gripped).
    #[error("the initial state is not the state the robot is in")]
    Mismatch,
}

impl InitialStateError {
    /// The Table 8 fault it latches.
    pub const fn fault(self) -> Fault {
        match self {
            InitialStateError::ArmNotContracted(_) => Fault::ArmNotContracted,
            InitialStateError::Mismatch => Fault::InitialStateMismatch,
        }
    }

    /// The refusal code the heartbeat answers the reconfiguration with.
    pub const fn refusal(self) -> Refusal {
        match self {
            InitialStateError::ArmNotContracted(_) => Refusal::ArmNotContracted,
            InitialStateError::Mismatch => Refusal::InitialStateMismatch,
        }
    }
}

/// A reconfiguration's check on arrival, from `initial`: first the arms (a switch that does not
/// sense a commanded contraction is a hardware fault whatever the opsUI believes, and the state
/// estimate does not read the switches), then the initial state against the `tracked` state and
/// the states the readings allow (`sensed`: empty without a hip reading, so nothing is confirmed).
///
/// ```
/// use mmic::motion::estimate::{check_reconfiguration, consistent, predict, ArmPwm, Config, InitialStateError};
/// use mmic::motion::State;
/// use mmic::units::{PerSide, Side};
/// let cfg = Config::default();
/// let r = predict(&cfg, State::A).next().unwrap();
/// let sensed = consistent(&cfg, &r);
/// let closed = PerSide::both(true);
/// assert_eq!(check_reconfiguration(State::A, Some(State::A), sensed, r.arm, closed), Ok(()));
/// assert_eq!(check_reconfiguration(State::D, None, sensed, r.arm, closed), Err(InitialStateError::Mismatch));
/// let dead_b = PerSide::new(true, false);
/// assert_eq!(
///     check_reconfiguration(State::A, Some(State::A), sensed, r.arm, dead_b),
///     Err(InitialStateError::ArmNotContracted(Side::B))
/// );
/// ```
pub fn check_reconfiguration(
    initial: State,
    tracked: Option<State>,
    sensed: StateSet,
    arm: PerSide<ArmPwm>,
    switch: PerSide<bool>,
) -> Result<(), InitialStateError> {
    if let Some(side) = unsensed_contraction(arm, switch) {
        return Err(InitialStateError::ArmNotContracted(side));
    }
    if !initial_state_consistent(initial, tracked, sensed) {
        return Err(InitialStateError::Mismatch);
    }
    Ok(())
}
