//! What the servos are told: arm and gripper pulse widths, the hip's angle.

use super::ranged;

ranged! {
    /// Servo pulse width in microseconds, the unit of every arm and gripper target and "now" field.
    ///
    /// Range 500..=2500 µs, the standard hobby-servo pulse range the MMIC-I servos accept.
    pub struct PulseWidth(u16), min Self::MIN_US, max Self::MAX_US, "servo pulse width (us)";
}

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

ranged! {
    /// Hip angle in hundredths of a degree, 0..=35999 (0.00° ..= 359.99°).
    ///
    /// The paper calls the hip field "hip PWM", but the hip is a continuous-rotation servo closed
    /// around an absolute magnetic encoder, so the commanded quantity is an angle. Centidegrees
    /// keep the 3° and 10°/s of Section 5 exact in integers and fit a u16.
    pub struct HipAngle(u16), min 0, max Self::TURN - 1, "hip angle (0.01 deg)";
}

impl HipAngle {
    /// One full turn, in centidegrees (exclusive upper bound).
    pub const TURN: u16 = 36000;
    /// 0.00°.
    pub const ZERO: HipAngle = HipAngle(0);
    /// 180.00°: the hip straight, both sides in line (the robot's home and matched pose).
    pub const STRAIGHT: HipAngle = HipAngle(18000);

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
            // Both angles are below TURN, so `d` is too: the subtraction never saturates.
            Self::TURN.saturating_sub(d)
        } else {
            d
        }
    }
}
