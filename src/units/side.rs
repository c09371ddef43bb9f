//! The robot's two sides, and a value per side.

use core::fmt;

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

#[cfg(test)]
mod tests {
    use super::*;

    /// `all` and `any` over the four pairs of flags; indexing by side reads each.
    #[test]
    fn all_and_any_over_both_sides() {
        for (a, b) in [(false, false), (false, true), (true, false), (true, true)] {
            let p = PerSide { a, b };
            assert_eq!((p.all(), p.any()), (a && b, a || b), "{a} {b}");
            assert_eq!((p[Side::A], p[Side::B]), (a, b));
        }
    }

    /// A side prints as its letter (the messages that name a side: refusals, faults, logs).
    #[test]
    fn a_side_prints_as_its_letter() {
        extern crate std;
        use std::string::ToString;
        assert_eq!(Side::A.to_string(), "A");
        assert_eq!(Side::B.to_string(), "B");
    }
}
