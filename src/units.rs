//! Physical quantities and identifiers carried in packets, each with the unit and range that
//! `spec/decisions.toml` fixes (the paper names the fields but gives no unit or scale).
//!
//! ```
//! use mmic::units::{PulseWidth, HipAngle};
//! let pw = PulseWidth::new(1500).unwrap();
//! assert_eq!(pw.micros(), 1500);
//! assert!(PulseWidth::new(2501).is_err());
//! assert_eq!(HipAngle::new(18000).unwrap().centidegrees(), 18000); // 180.00°
//! ```

use core::fmt;

/// Out-of-range value handed to a unit constructor; carries the offending value and the range.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, thiserror::Error)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
#[error("{quantity} must be in {min}..={max}, found {found}")]
pub struct RangeError {
    /// Which quantity was being built.
    pub quantity: &'static str,
    /// Smallest accepted value.
    pub min: u32,
    /// Largest accepted value.
    pub max: u32,
    /// The value that was refused.
    pub found: u32,
}

/// Any integer as serde reads it, exactly: the intermediate through which the ranged types of
/// this crate deserialize (`serde(try_from = "Number")`), so that every out-of-range number gets
/// its field's own message — `board number must be in 1..=255, found 300`, `servo pulse width
/// (us) must be in 500..=2500, found -5` — instead of serde's `expected u8`, whatever its sign
/// or size.
///
/// ```
/// # #[cfg(feature = "serde")] {
/// use mmic::units::{BoardNumber, Number};
/// assert_eq!(BoardNumber::try_from(Number(7)).unwrap().get(), 7);
/// assert_eq!(
///     BoardNumber::try_from(Number(300)).unwrap_err().to_string(),
///     "board number must be in 1..=255, found 300"
/// );
/// # }
/// ```
#[cfg(feature = "serde")]
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Number(pub i128);

/// A number outside the range of the field it was read for (see [`Number`]).
#[cfg(feature = "serde")]
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, thiserror::Error)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
#[error("{quantity} must be in {min}..={max}, found {found}")]
pub struct NumberRangeError {
    /// Which quantity was being read.
    pub quantity: &'static str,
    /// Smallest accepted value.
    pub min: i128,
    /// Largest accepted value.
    pub max: i128,
    /// The value that was refused.
    pub found: i128,
}

#[cfg(feature = "serde")]
impl Number {
    /// The value as a `W` turned into a `T` by `make`; a value that does not fit `W`, or that
    /// `make` refuses, is a [`NumberRangeError`] naming `quantity` and `min..=max`.
    pub fn narrow<W: TryFrom<i128>, T>(
        self,
        quantity: &'static str,
        (min, max): (i128, i128),
        make: impl FnOnce(W) -> Option<T>,
    ) -> Result<T, NumberRangeError> {
        W::try_from(self.0)
            .ok()
            .and_then(make)
            .ok_or(NumberRangeError {
                quantity,
                min,
                max,
                found: self.0,
            })
    }
}

#[cfg(feature = "serde")]
impl<'de> serde::Deserialize<'de> for Number {
    fn deserialize<D: serde::Deserializer<'de>>(d: D) -> Result<Number, D::Error> {
        struct V;
        impl serde::de::Visitor<'_> for V {
            type Value = Number;
            fn expecting(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
                f.write_str("an integer")
            }
            fn visit_i64<E: serde::de::Error>(self, v: i64) -> Result<Number, E> {
                Ok(Number(v as i128))
            }
            fn visit_u64<E: serde::de::Error>(self, v: u64) -> Result<Number, E> {
                Ok(Number(v as i128))
            }
            fn visit_i128<E: serde::de::Error>(self, v: i128) -> Result<Number, E> {
                Ok(Number(v))
            }
            fn visit_u128<E: serde::de::Error>(self, v: u128) -> Result<Number, E> {
                Ok(Number(i128::try_from(v).unwrap_or(i128::MAX)))
            }
            // JSON readers hand integers beyond u64 over as floats: a whole float is taken
            // as the integer it is (saturating beyond ±1.7e38), a fraction is refused.
            fn visit_f64<E: serde::de::Error>(self, v: f64) -> Result<Number, E> {
                if v.is_finite() && v == (v as i128) as f64 {
                    Ok(Number(v as i128))
                } else {
                    Err(E::invalid_type(serde::de::Unexpected::Float(v), &self))
                }
            }
        }
        d.deserialize_any(V)
    }
}

/// Deserializers for plain integer fields, through [`Number`], so that an out-of-range value
/// names the field's quantity and range like the ranged types do.
#[cfg(feature = "serde")]
pub(crate) mod de {
    use super::Number;

    macro_rules! integer_field {
        ($(#[$doc:meta] $name:ident: $t:ty, $quantity:literal;)*) => {$(
            #[$doc]
            pub(crate) fn $name<'de, D: serde::Deserializer<'de>>(d: D) -> Result<$t, D::Error> {
                <Number as serde::Deserialize>::deserialize(d)?
                    .narrow($quantity, (<$t>::MIN as i128, <$t>::MAX as i128), Some)
                    .map_err(serde::de::Error::custom)
            }
        )*};
    }

    integer_field! {
        /// An exactly-once sequence number (u16).
        seq16: u16, "sequence number";
        /// An A→B sequence number (u8).
        seq8: u8, "A->B sequence number";
        /// A voltage in mV (u16).
        millivolts: u16, "voltage (mV)";
        /// A current in mA (u16).
        milliamps: u16, "current (mA)";
    }
}

/// Side of the robot. The robot is symmetric about the hip; board A is on side A.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub enum Side {
    /// Side A: board A (primary, WiFi client, hip), "fwd" in Table 6.
    #[cfg_attr(feature = "serde", serde(rename = "a"))]
    A,
    /// Side B: board B (subordinate, serial to A), "back" in Table 6.
    #[cfg_attr(feature = "serde", serde(rename = "b"))]
    B,
}

impl Side {
    /// Both sides, A first.
    pub const ALL: [Side; 2] = [Side::A, Side::B];
}

impl fmt::Display for Side {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(match self {
            Side::A => "A",
            Side::B => "B",
        })
    }
}

/// A moment on a board's millisecond clock, which wraps after 2³² ms (49.7 days): the time
/// every `tick(now, ..)` of the library receives, as a type (after smoltcp's `time::Instant`).
/// Differences are taken on the wrapping clock, so timers work across the wrap.
///
/// ```
/// use mmic::units::{Duration, Instant};
/// let t = Instant::from_millis(u32::MAX - 5);
/// let later = Instant::from_millis(4); // 10 ms later, across the wrap
/// assert_eq!(later.since(t), Duration::from_millis(10));
/// assert_eq!(t.since(later), Duration::ZERO); // the clock went backwards: no time passed
/// ```
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Default)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Instant(u32);

/// A span of milliseconds between two [`Instant`]s.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord, Default)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Duration(u32);

impl Instant {
    /// The clock's zero.
    pub const ZERO: Instant = Instant(0);

    /// The moment `ms` milliseconds after the clock's zero (modulo the wrap).
    pub const fn from_millis(ms: u32) -> Instant {
        Instant(ms)
    }

    /// Milliseconds since the clock's zero, as the board reads it.
    pub const fn millis(self) -> u32 {
        self.0
    }

    /// The moment `d` after this one, on the wrapping clock.
    pub const fn after(self, d: Duration) -> Instant {
        Instant(self.0.wrapping_add(d.0))
    }

    /// Whether `deadline` has come (`self` is at or after it on the wrapping clock, within
    /// half the wrap).
    ///
    /// ```
    /// use mmic::units::Instant;
    /// let t = |ms| Instant::from_millis(ms);
    /// assert!(t(10).reached(t(10)) && t(11).reached(t(10)) && !t(9).reached(t(10)));
    /// assert!(t(5).reached(t(u32::MAX - 5))); // across the wrap
    /// ```
    pub const fn reached(self, deadline: Instant) -> bool {
        self.0.wrapping_sub(deadline.0) <= i32::MAX as u32
    }

    /// Time from `earlier` to `self` on the wrapping clock; zero if `self` is earlier (a
    /// difference of more than half the wrap is read as the clock having gone backwards).
    pub const fn since(self, earlier: Instant) -> Duration {
        let d = self.0.wrapping_sub(earlier.0);
        if d > i32::MAX as u32 {
            Duration(0)
        } else {
            Duration(d)
        }
    }
}

impl Duration {
    /// No time.
    pub const ZERO: Duration = Duration(0);

    /// `ms` milliseconds.
    pub const fn from_millis(ms: u32) -> Duration {
        Duration(ms)
    }

    /// Milliseconds.
    pub const fn millis(self) -> u32 {
        self.0
    }
}

/// One value per side of the robot, indexed by [`Side`] (never by 0 and 1): the arms,
/// grippers, switches and their targets come in pairs, and an index that names the side cannot
/// pick the wrong one.
///
/// ```
/// use mmic::units::{PerSide, Side};
/// let mut done = PerSide::both(false);
/// done[Side::B] = true;
/// assert_eq!((done.a, done.b), (false, true));
/// assert!(!done.all());
/// ```
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Default)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub struct PerSide<T> {
    /// Side A's value.
    pub a: T,
    /// Side B's value.
    pub b: T,
}

impl<T: Copy> PerSide<T> {
    /// Side A's and side B's values.
    pub const fn new(a: T, b: T) -> Self {
        PerSide { a, b }
    }

    /// The same value on both sides.
    pub const fn both(v: T) -> Self {
        PerSide { a: v, b: v }
    }

    /// The value of side `s`.
    pub const fn get(&self, s: Side) -> T {
        match s {
            Side::A => self.a,
            Side::B => self.b,
        }
    }
}

impl PerSide<bool> {
    /// Both sides hold.
    pub const fn all(&self) -> bool {
        self.a && self.b
    }

    /// Either side holds.
    pub const fn any(&self) -> bool {
        self.a || self.b
    }
}

impl<T> core::ops::Index<Side> for PerSide<T> {
    type Output = T;
    fn index(&self, s: Side) -> &T {
        match s {
            Side::A => &self.a,
            Side::B => &self.b,
        }
    }
}

impl<T> core::ops::IndexMut<Side> for PerSide<T> {
    fn index_mut(&mut self, s: Side) -> &mut T {
        match s {
            Side::A => &mut self.a,
            Side::B => &mut self.b,
        }
    }
}

/// Number of a robot's WiFi client (board A) on a server, Table 2 byte 4 and Table 3 byte 4.
///
/// 1..=255; 0 is refused so that a zeroed buffer can never address a robot.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
#[cfg_attr(
    feature = "serde",
    derive(serde::Serialize, serde::Deserialize),
    serde(try_from = "Number", into = "u8")
)]
pub struct BoardNumber(core::num::NonZeroU8);

impl BoardNumber {
    /// The first robot.
    pub const ONE: BoardNumber = BoardNumber(core::num::NonZeroU8::MIN);

    /// Board number `n`, refused when 0.
    pub const fn new(n: u8) -> Result<Self, RangeError> {
        match core::num::NonZeroU8::new(n) {
            Some(n) => Ok(BoardNumber(n)),
            None => Err(RangeError {
                quantity: "board number",
                min: 1,
                max: 255,
                found: 0,
            }),
        }
    }

    /// The number as it goes on the wire.
    pub const fn get(self) -> u8 {
        self.0.get()
    }
}

impl TryFrom<u8> for BoardNumber {
    type Error = RangeError;
    fn try_from(n: u8) -> Result<Self, RangeError> {
        BoardNumber::new(n)
    }
}

#[cfg(feature = "serde")]
impl TryFrom<Number> for BoardNumber {
    type Error = NumberRangeError;
    fn try_from(n: Number) -> Result<Self, NumberRangeError> {
        n.narrow("board number", (1, 255), |v: u8| BoardNumber::new(v).ok())
    }
}

impl From<BoardNumber> for u8 {
    fn from(b: BoardNumber) -> u8 {
        b.get()
    }
}

/// Servo pulse width in microseconds, the unit of every arm and gripper target and "now" field.
///
/// Range 500..=2500 µs, the standard hobby-servo pulse range the MMIC-I servos accept.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
#[cfg_attr(
    feature = "serde",
    derive(serde::Serialize, serde::Deserialize),
    serde(try_from = "Number", into = "u16")
)]
pub struct PulseWidth(u16);

impl PulseWidth {
    /// Shortest pulse accepted, µs.
    pub const MIN_US: u16 = 500;
    /// Longest pulse accepted, µs.
    pub const MAX_US: u16 = 2500;
    /// Shortest pulse.
    pub const MIN: PulseWidth = PulseWidth(Self::MIN_US);
    /// Longest pulse.
    pub const MAX: PulseWidth = PulseWidth(Self::MAX_US);
    /// Neutral pulse, 1500 µs.
    pub const CENTER: PulseWidth = PulseWidth(1500);

    /// A pulse of `us` microseconds, refused outside 500..=2500.
    pub const fn new(us: u16) -> Result<Self, RangeError> {
        if us >= Self::MIN_US && us <= Self::MAX_US {
            Ok(PulseWidth(us))
        } else {
            Err(RangeError {
                quantity: "servo pulse width (us)",
                min: Self::MIN_US as u32,
                max: Self::MAX_US as u32,
                found: us as u32,
            })
        }
    }

    /// The pulse width clamped into range: for controllers whose arithmetic may leave it.
    pub const fn saturating(us: u16) -> Self {
        if us < Self::MIN_US {
            Self::MIN
        } else if us > Self::MAX_US {
            Self::MAX
        } else {
            PulseWidth(us)
        }
    }

    /// Microseconds.
    pub const fn micros(self) -> u16 {
        self.0
    }
}

impl TryFrom<u16> for PulseWidth {
    type Error = RangeError;
    fn try_from(us: u16) -> Result<Self, RangeError> {
        PulseWidth::new(us)
    }
}

#[cfg(feature = "serde")]
impl TryFrom<Number> for PulseWidth {
    type Error = NumberRangeError;
    fn try_from(n: Number) -> Result<Self, NumberRangeError> {
        let range = (Self::MIN_US as i128, Self::MAX_US as i128);
        n.narrow("servo pulse width (us)", range, |v: u16| {
            PulseWidth::new(v).ok()
        })
    }
}

impl From<PulseWidth> for u16 {
    fn from(p: PulseWidth) -> u16 {
        p.micros()
    }
}

/// Hip angle in hundredths of a degree, 0..=35999 (0.00° ..= 359.99°).
///
/// The paper calls the hip field "hip PWM", but the hip is a continuous-rotation servo closed
/// around an absolute magnetic encoder, so the commanded quantity is an angle. Centidegrees
/// keep the 3° and 10°/s of Section 5 exact in integers and fit a u16.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
#[cfg_attr(
    feature = "serde",
    derive(serde::Serialize, serde::Deserialize),
    serde(try_from = "Number", into = "u16")
)]
pub struct HipAngle(u16);

impl HipAngle {
    /// One full turn, in centidegrees (exclusive upper bound).
    pub const TURN: u16 = 36000;
    /// 0.00°.
    pub const ZERO: HipAngle = HipAngle(0);
    /// 180.00°: the hip straight, both sides in line (the robot's home and matched pose).
    pub const STRAIGHT: HipAngle = HipAngle(18000);

    /// `cdeg` hundredths of a degree, refused at or above 360.00°.
    pub const fn new(cdeg: u16) -> Result<Self, RangeError> {
        if cdeg < Self::TURN {
            Ok(HipAngle(cdeg))
        } else {
            Err(RangeError {
                quantity: "hip angle (0.01 deg)",
                min: 0,
                max: Self::TURN as u32 - 1,
                found: cdeg as u32,
            })
        }
    }

    /// `cdeg` reduced modulo one turn.
    pub const fn wrapping(cdeg: u16) -> Self {
        HipAngle(cdeg % Self::TURN)
    }

    /// Hundredths of a degree.
    pub const fn centidegrees(self) -> u16 {
        self.0
    }

    /// The circular distance to `other`, in 0.01°, 0..=18000: the shorter way round.
    ///
    /// ```
    /// use mmic::units::HipAngle;
    /// let a = HipAngle::wrapping;
    /// assert_eq!(a(100).distance(a(35900)), 200);
    /// assert_eq!(a(0).distance(a(18000)), 18000);
    /// ```
    pub const fn distance(self, other: HipAngle) -> u16 {
        let d = self.0.abs_diff(other.0);
        if d > Self::TURN / 2 {
            Self::TURN - d
        } else {
            d
        }
    }
}

impl TryFrom<u16> for HipAngle {
    type Error = RangeError;
    fn try_from(v: u16) -> Result<Self, RangeError> {
        HipAngle::new(v)
    }
}

#[cfg(feature = "serde")]
impl TryFrom<Number> for HipAngle {
    type Error = NumberRangeError;
    fn try_from(n: Number) -> Result<Self, NumberRangeError> {
        let range = (0, Self::TURN as i128 - 1);
        n.narrow("hip angle (0.01 deg)", range, |v: u16| {
            HipAngle::new(v).ok()
        })
    }
}

impl From<HipAngle> for u16 {
    fn from(a: HipAngle) -> u16 {
        a.centidegrees()
    }
}

/// A voltage in millivolts (battery 10.0–12.6 V, regulator 7.4 V: both fit a u16).
pub type Millivolts = u16;
/// A current in milliamperes (unsigned: the sense resistors measure draw only).
pub type Milliamps = u16;

/// A powered module (Table 1 "Power Control": individual modules).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
#[cfg_attr(feature = "serde", serde(rename_all = "snake_case"))]
pub enum Module {
    /// Hip servo (board A).
    Hip,
    /// Extension arm, side A.
    ArmA,
    /// Extension arm, side B.
    ArmB,
    /// Gripper, side A.
    GripperA,
    /// Gripper, side B.
    GripperB,
    /// Bolter, side A.
    BolterA,
    /// Bolter, side B.
    BolterB,
}

impl Module {
    /// Every module, in wire order (index = offset within the power command ranges).
    pub const ALL: [Module; 7] = [
        Module::Hip,
        Module::ArmA,
        Module::ArmB,
        Module::GripperA,
        Module::GripperB,
        Module::BolterA,
        Module::BolterB,
    ];

    /// Index 0..7 in [`Module::ALL`].
    pub const fn index(self) -> u8 {
        self as u8
    }

    /// Module with index `i`, if any.
    pub const fn from_index(i: u8) -> Option<Module> {
        if (i as usize) < Self::ALL.len() {
            Some(Self::ALL[i as usize])
        } else {
            None
        }
    }

    /// Side the module sits on; the hip belongs to board A.
    pub const fn side(self) -> Side {
        match self {
            Module::Hip | Module::ArmA | Module::GripperA | Module::BolterA => Side::A,
            _ => Side::B,
        }
    }
}

/// A lattice axis.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub enum Axis {
    /// X.
    #[cfg_attr(feature = "serde", serde(rename = "x"))]
    X,
    /// Y.
    #[cfg_attr(feature = "serde", serde(rename = "y"))]
    Y,
    /// Z.
    #[cfg_attr(feature = "serde", serde(rename = "z"))]
    Z,
}

impl Axis {
    /// X, Y, Z.
    pub const ALL: [Axis; 3] = [Axis::X, Axis::Y, Axis::Z];

    /// ASCII letter on the wire: `X`, `Y`, `Z`.
    pub const fn to_wire(self) -> u8 {
        match self {
            Axis::X => b'X',
            Axis::Y => b'Y',
            Axis::Z => b'Z',
        }
    }

    /// Axis from its wire letter.
    pub const fn from_wire(b: u8) -> Option<Axis> {
        match b {
            b'X' => Some(Axis::X),
            b'Y' => Some(Axis::Y),
            b'Z' => Some(Axis::Z),
            _ => None,
        }
    }
}

/// Sign along an axis.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub enum Sign {
    /// Positive direction.
    #[cfg_attr(feature = "serde", serde(rename = "+"))]
    Positive,
    /// Negative direction.
    #[cfg_attr(feature = "serde", serde(rename = "-"))]
    Negative,
}

impl Sign {
    /// ASCII on the wire: `+` or `-`.
    pub const fn to_wire(self) -> u8 {
        match self {
            Sign::Positive => b'+',
            Sign::Negative => b'-',
        }
    }

    /// Sign from its wire character.
    pub const fn from_wire(b: u8) -> Option<Sign> {
        match b {
            b'+' => Some(Sign::Positive),
            b'-' => Some(Sign::Negative),
            _ => None,
        }
    }
}

/// Direction of gravity in an IMU's frame: the axis with the largest acceleration and its sign
/// (Table 4 bytes 36–37).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
#[cfg_attr(feature = "serde", serde(deny_unknown_fields))]
pub struct Gravity {
    /// Dominant axis.
    pub axis: Axis,
    /// Sign of gravity along it.
    pub sign: Sign,
}

/// Voltage and current readings of one side's ADS7828 (Table 3 bytes 25–52, Table 4 bytes 12–25).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Default)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
#[cfg_attr(feature = "serde", serde(deny_unknown_fields))]
pub struct Electrical {
    /// Battery voltage V_bat, mV.
    #[cfg_attr(
        feature = "serde",
        serde(deserialize_with = "crate::units::de::millivolts")
    )]
    pub v_bat: Millivolts,
    /// Battery current I_bat, mA.
    #[cfg_attr(
        feature = "serde",
        serde(deserialize_with = "crate::units::de::milliamps")
    )]
    pub i_bat: Milliamps,
    /// Locomotion (arm and hip) current I_loc, mA.
    #[cfg_attr(
        feature = "serde",
        serde(deserialize_with = "crate::units::de::milliamps")
    )]
    pub i_loc: Milliamps,
    /// Gripper current I_grip, mA.
    #[cfg_attr(
        feature = "serde",
        serde(deserialize_with = "crate::units::de::milliamps")
    )]
    pub i_grip: Milliamps,
    /// 3.3 V rail current I_3v3, mA.
    #[cfg_attr(
        feature = "serde",
        serde(deserialize_with = "crate::units::de::milliamps")
    )]
    pub i_3v3: Milliamps,
    /// Regulated voltage V_reg, mV.
    #[cfg_attr(
        feature = "serde",
        serde(deserialize_with = "crate::units::de::millivolts")
    )]
    pub v_reg: Millivolts,
    /// Bolter current I_bo, mA.
    #[cfg_attr(
        feature = "serde",
        serde(deserialize_with = "crate::units::de::milliamps")
    )]
    pub i_bo: Milliamps,
}
