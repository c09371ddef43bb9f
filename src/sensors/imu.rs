//! Gravity direction from the MPU-6000's raw accelerations (Table 4 bytes 36–37).
//!
//! ```
//! use mmic::sensors::imu::gravity;
//! use mmic::units::{Axis, Gravity, Sign};
//! assert_eq!(gravity([120, -16200, 300]), Some(Gravity { axis: Axis::Y, sign: Sign::Negative }));
//! assert_eq!(gravity([0, 0, 0]), None);
//! ```
// req: P2.5, D:gravity-encoding

use crate::units::{Axis, Gravity, Sign};

/// The axis with the largest |acceleration| and its sign; `None` when all three are zero.
/// Ties go to the earlier axis (X, then Y, then Z) so the answer is deterministic.
pub fn gravity(accel: [i16; 3]) -> Option<Gravity> {
    let mut best: Option<(Axis, i16, u16)> = None;
    for (&axis, &a) in Axis::ALL.iter().zip(accel.iter()) {
        let m = a.unsigned_abs();
        if m > 0 && best.is_none_or(|(_, _, b)| m > b) {
            best = Some((axis, a, m));
        }
    }
    let (axis, a, _) = best?;
    let sign = if a > 0 {
        Sign::Positive
    } else {
        Sign::Negative
    };
    Some(Gravity { axis, sign })
}
