//! The hip's absolute magnetic encoder (I2C, 12-bit) to a hip angle.
//!
//! ```
//! use mmic::sensors::encoder::hip_angle;
//! assert_eq!(hip_angle(0, 0).centidegrees(), 0);
//! assert_eq!(hip_angle(2048, 0).centidegrees(), 18000);
//! assert_eq!(hip_angle(0, 1024).centidegrees(), 27000); // the zero offset wraps
//! ```
// req: P2.9

use crate::units::widen::to_u32;
use crate::units::HipAngle;

/// Counts per turn of the 12-bit encoder.
pub const COUNTS: u32 = 4096;

/// A turn in centidegrees, as the u32 of the arithmetic.
const TURN: u32 = to_u32(HipAngle::TURN.to_le_bytes());

/// Hip angle of raw reading `raw` (low 12 bits used) with `zero` the raw reading at 0°,
/// rounded to the nearest 0.01°.
pub fn hip_angle(raw: u16, zero: u16) -> HipAngle {
    // Exact in u32: at most 65535 + 4096 before the first `%`, and 4095 × 36000 + 2048 before
    // the division; the angle is then below 36000, a u16.
    let counts = u32::from(raw)
        .wrapping_add(COUNTS)
        .wrapping_sub(u32::from(zero) % COUNTS)
        % COUNTS;
    let cdeg = counts.wrapping_mul(TURN).wrapping_add(COUNTS / 2) / COUNTS;
    u16::try_from(cdeg % TURN)
        .ok()
        .and_then(|c| HipAngle::new(c).ok())
        .unwrap_or(HipAngle::ZERO)
}
