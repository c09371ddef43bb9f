//! Where an arm, a gripper or the hip is told to go, and the travel that gives "contract" and
//! "extend" a pulse width. The travel is here, beside the targets, because a command is only
//! valid within it: decoding and JSON refuse a position outside it.
// req: D:servo-travel, D:hip-presets

use crate::units::{HipAngle, PulseWidth};

/// Where an arm or gripper goes.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
#[cfg_attr(feature = "serde", serde(rename_all = "snake_case"))]
pub enum ServoTarget {
    /// Totally contract (arm retracted / gripper released).
    Contract,
    /// Totally extend (arm out / gripper engaged on the face).
    Extend,
    /// Partially contract or extend: go to this pulse width.
    Position(PulseWidth),
}

/// Where the hip goes: one of the common positions, or any angle.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
#[cfg_attr(feature = "serde", serde(rename_all = "snake_case"))]
pub enum HipTarget {
    /// The contracted-gripped (home) angle, a configuration value.
    Home,
    /// Arms in line: 180.00°.
    Straight,
    /// Quarter turn clockwise: 90.00°.
    RightAngleCw,
    /// Quarter turn counter-clockwise: 270.00°.
    RightAngleCcw,
    /// Any other angle.
    Angle(HipAngle),
}

/// The angle a hip target stands for; `None` for [`HipTarget::Home`], whose angle is a
/// configuration value (the contracted-gripped angle).
pub const fn preset_angle(t: HipTarget) -> Option<HipAngle> {
    let cdeg = match t {
        HipTarget::Home => return None,
        HipTarget::Straight => 18000,
        HipTarget::RightAngleCw => 9000,
        HipTarget::RightAngleCcw => 27000,
        HipTarget::Angle(a) => return Some(a),
    };
    match HipAngle::new(cdeg) {
        Ok(a) => Some(a),
        Err(_) => None,
    }
}

/// The pulse widths that "totally contract" and "totally extend" mean for one servo: its travel.
/// A partial target from the command set is honoured as given when it lies within them.
///
/// ```
/// use mmic::command::ServoTarget;
/// use mmic::command::Travel;
/// use mmic::units::PulseWidth;
/// let arm = Travel { contracted: PulseWidth::new(900).unwrap(), extended: PulseWidth::new(2100).unwrap() };
/// assert_eq!(arm.resolve(ServoTarget::Extend).micros(), 2100);
/// assert_eq!(arm.resolve(ServoTarget::Position(PulseWidth::new(1300).unwrap())).micros(), 1300);
/// ```
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Travel {
    /// Fully contracted (arm retracted / gripper open).
    pub contracted: PulseWidth,
    /// Fully extended (arm out / gripper closed on the face).
    pub extended: PulseWidth,
}

impl Travel {
    /// The arms' travel: contracted 900 µs, extended 2100 µs (spec/control/servos.toml). No
    /// arm command may leave it.
    pub const ARM: Travel = Travel {
        contracted: PulseWidth::saturating(900),
        extended: PulseWidth::saturating(2100),
    };
    /// The grippers' travel: open 1000 µs, closed on a face 2000 µs (spec/control/servos.toml).
    /// No gripper command may leave it.
    pub const GRIPPER: Travel = Travel {
        contracted: PulseWidth::saturating(1000),
        extended: PulseWidth::saturating(2000),
    };

    /// The pulse a command's target stands for; partial targets are taken as given.
    pub const fn resolve(&self, t: ServoTarget) -> PulseWidth {
        match t {
            ServoTarget::Contract => self.contracted,
            ServoTarget::Extend => self.extended,
            ServoTarget::Position(p) => p,
        }
    }

    /// The smallest pulse of the travel (whichever end it is).
    pub const fn min(&self) -> PulseWidth {
        if self.contracted.micros() <= self.extended.micros() {
            self.contracted
        } else {
            self.extended
        }
    }

    /// The largest pulse of the travel.
    pub const fn max(&self) -> PulseWidth {
        if self.contracted.micros() <= self.extended.micros() {
            self.extended
        } else {
            self.contracted
        }
    }

    /// `target` when the pulse it stands for lies within the travel (its two ends included);
    /// otherwise the error, with the range. A partial target outside the travel would drive
    /// the servo against its end stop (issue 24): the commands refuse it at decoding
    /// (`CommandError::OutOfTravel`), board A against its configured travel.
    ///
    /// ```
    /// use mmic::command::ServoTarget;
    /// use mmic::command::{OutOfTravel, Travel};
    /// use mmic::units::PulseWidth;
    /// let at = |us| ServoTarget::Position(PulseWidth::new(us).unwrap());
    /// assert_eq!(Travel::ARM.check(at(2100)), Ok(at(2100)));
    /// assert_eq!(Travel::ARM.check(at(2101)), Err(OutOfTravel { found: 2101, min: 900, max: 2100 }));
    /// assert_eq!(Travel::ARM.check(ServoTarget::Extend), Ok(ServoTarget::Extend));
    /// ```
    pub const fn check(&self, target: ServoTarget) -> Result<ServoTarget, OutOfTravel> {
        let p = self.resolve(target).micros();
        let (min, max) = (self.min().micros(), self.max().micros());
        if p < min || p > max {
            Err(OutOfTravel { found: p, min, max })
        } else {
            Ok(target)
        }
    }
}

/// A servo target outside the module's travel.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, thiserror::Error)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
#[error("pulse width {found} us is outside the travel {min}..={max} us")]
pub struct OutOfTravel {
    /// The pulse width asked for, µs.
    pub found: u16,
    /// The travel's smallest pulse, µs.
    pub min: u16,
    /// The travel's largest pulse, µs.
    pub max: u16,
}
