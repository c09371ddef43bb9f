//! The hip's absolute magnetic encoder (I2C, 12-bit) to a hip angle.
//!
//! ```
//! use mmic::sensors::encoder::hip_angle;
//! assert_eq!(hip_angle(0, 0).centidegrees(), 0);
//! assert_eq!(hip_angle(2048, 0).centidegrees(), 18000);
//! assert_eq!(hip_angle(0, 1024).centidegrees(), 27000); // the zero offset wraps
//! ```

use crate::units::HipAngle;

/// Counts per turn of the 12-bit encoder.
pub const COUNTS: u32 = 4096;

/// Hip angle of raw reading `raw` (low 12 bits used) with `zero` the raw reading at 0°,
/// rounded to the nearest 0.01°.
pub fn hip_angle(raw: u16, zero: u16) -> HipAngle {
    let counts = (raw as u32 + COUNTS - (zero as u32 % COUNTS)) % COUNTS;
    let cdeg = (counts * HipAngle::TURN as u32 + COUNTS / 2) / COUNTS;
    HipAngle::new((cdeg % HipAngle::TURN as u32) as u16).unwrap_or(HipAngle::ZERO)
}
