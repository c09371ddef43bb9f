//! The geometric model behind Figure 9: which face each side grips in each state, the direction
//! of each arm, which single-side moves the model allows ([`single_move`], 72) and which of them
//! the robot's joints can make ([`robot_move`], 60). Everything here is `const fn`, so the
//! reconfiguration map is computed at compile time, never typed in (spec/motion/model.md).
//!
//! ```
//! use mmic::pose::geometry::{robot_move, single_move, turns_without_hip};
//! use mmic::pose::{Primitive, State};
//! use mmic::units::Side;
//! // b -> g: B leaves the Y- face for X+, its arm turns with the hip: a move of the robot.
//! assert_eq!(robot_move(State::B, State::G), Some((Side::B, Primitive::BackTurnCw)));
//! // g -> j: A swings from -Y to -Z about B's +X arm. The model has the move; the hip, whose
//! // axis is perpendicular to both arms, cannot make it.
//! assert!(single_move(State::G, State::J).is_some());
//! assert_eq!(robot_move(State::G, State::J), None);
//! assert!(turns_without_hip(State::G, State::J));
//! ```
// req: P6.2, D:turn-primitives

use super::{Primitive, State, StateKind};
use crate::units::{Axis, Side, Sign};

/// A face of the reference voxel.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Face {
    /// The axis the face is normal to.
    pub axis: Axis,
    /// Negative (X−, Y−, Z−) or positive face.
    pub sign: Sign,
}

/// A unit vector along an axis, as integer components (x, y, z).
pub type Vec3 = [i8; 3];

const fn axis_index(a: Axis) -> usize {
    match a {
        Axis::X => 0,
        Axis::Y => 1,
        Axis::Z => 2,
    }
}

/// Unit vector `sign · axis`.
pub const fn unit(axis: Axis, sign: Sign) -> Vec3 {
    let s = match sign {
        Sign::Positive => 1,
        Sign::Negative => -1,
    };
    match axis {
        Axis::X => [s, 0, 0],
        Axis::Y => [0, s, 0],
        Axis::Z => [0, 0, s],
    }
}

/// Cross product. The model's vectors are unit vectors and their cross products, components
/// in −1..=1: each component here is in −2..=2, so the wrapping operations (free on board A's
/// tick; coding standard R4, "exact") never wrap.
pub const fn cross(a: Vec3, b: Vec3) -> Vec3 {
    let [a0, a1, a2] = a;
    let [b0, b1, b2] = b;
    [
        a1.wrapping_mul(b2).wrapping_sub(a2.wrapping_mul(b1)),
        a2.wrapping_mul(b0).wrapping_sub(a0.wrapping_mul(b2)),
        a0.wrapping_mul(b1).wrapping_sub(a1.wrapping_mul(b0)),
    ]
}

const fn neg(a: Axis) -> Face {
    Face {
        axis: a,
        sign: Sign::Negative,
    }
}

const fn pos(a: Axis) -> Face {
    Face {
        axis: a,
        sign: Sign::Positive,
    }
}

/// The faces sides A and B grip in `s`. Two-face states (d–l): A on a negative face, B on a
/// positive face ("Xneg Ypos": A on X−, B on Y+). Matched states: both on the one face.
pub const fn faces(s: State) -> (Face, Face) {
    match s {
        State::A => (neg(Axis::X), neg(Axis::X)),
        State::B => (neg(Axis::Y), neg(Axis::Y)),
        State::C => (neg(Axis::Z), neg(Axis::Z)),
        State::M => (pos(Axis::X), pos(Axis::X)),
        State::N => (pos(Axis::Y), pos(Axis::Y)),
        State::O => (pos(Axis::Z), pos(Axis::Z)),
        // d..l in Table 5 order: A's axis major, B's axis minor.
        State::D => (neg(Axis::X), pos(Axis::X)),
        State::E => (neg(Axis::X), pos(Axis::Y)),
        State::F => (neg(Axis::X), pos(Axis::Z)),
        State::G => (neg(Axis::Y), pos(Axis::X)),
        State::H => (neg(Axis::Y), pos(Axis::Y)),
        State::I => (neg(Axis::Y), pos(Axis::Z)),
        State::J => (neg(Axis::Z), pos(Axis::X)),
        State::K => (neg(Axis::Z), pos(Axis::Y)),
        State::L => (neg(Axis::Z), pos(Axis::Z)),
    }
}

/// Direction of `side`'s arm (hip → gripper) in state `s`. In a two-face state each arm points
/// at its face (A: −axis of its negative face, B: +axis of its positive face). In a matched
/// state the side inside the reference voxel points into it along the face normal: B (+axis)
/// in a negative match, A (−axis) in a positive match; the outside side points the other way.
///
/// Both cases come to the same rule: A's arm points along −(axis of A's face), B's along
/// +(axis of B's face).
pub const fn arm_direction(s: State, side: Side) -> Vec3 {
    let (fa, fb) = faces(s);
    match side {
        Side::A => unit(fa.axis, Sign::Negative),
        Side::B => unit(fb.axis, Sign::Positive),
    }
}

const fn same(x: Face, y: Face) -> bool {
    axis_index(x.axis) == axis_index(y.axis)
        && matches!(
            (x.sign, y.sign),
            (Sign::Positive, Sign::Positive) | (Sign::Negative, Sign::Negative)
        )
}

/// The single-primitive move from `from` to `to`, if one exists: exactly one side moves
/// (the other keeps its face), by the rules of spec/motion/model.md.
pub const fn single_move(from: State, to: State) -> Option<(Side, Primitive)> {
    if from.index() == to.index() {
        return None;
    }
    let (fa, fb) = faces(from);
    let (ta, tb) = faces(to);
    // Which side moves: the other one must keep its face.
    let side = if same(fb, tb) && !same(fa, ta) {
        Side::A
    } else if same(fa, ta) && !same(fb, tb) {
        Side::B
    } else {
        return None;
    };
    // Who may move where (the model's rules).
    let allowed = match (from.is_matched(), side) {
        // Negative match: B (inside) may go to any positive face. Positive match: A may go to
        // any negative face.
        (true, Side::B) => matches!(fa.sign, Sign::Negative) && matches!(tb.sign, Sign::Positive),
        (true, Side::A) => matches!(fb.sign, Sign::Positive) && matches!(ta.sign, Sign::Negative),
        // Two-face: A to B's face (positive match) or another negative face; B to A's face
        // (negative match) or another positive face. `to` being a state already makes these the
        // only possibilities.
        (false, _) => true,
    };
    if !allowed {
        return None;
    }
    let old = arm_direction(from, side);
    let new = arm_direction(to, side);
    let c = cross(old, new);
    let fwd = matches!(side, Side::A);
    let p = if c[0] == 0 && c[1] == 0 && c[2] == 0 {
        // Same axis: extend from matched to stretch, contract from stretch to matched.
        match (from.is_matched(), fwd) {
            (true, true) => Primitive::FwdExtend,
            (true, false) => Primitive::BackExtend,
            (false, true) => Primitive::FwdContract,
            (false, false) => Primitive::BackContract,
        }
    } else {
        // CCW when old × new points along a positive axis (right-hand rule).
        let [c0, c1, c2] = c;
        // Components in −2..=2: the sum is exact.
        let ccw = c0.wrapping_add(c1).wrapping_add(c2) > 0;
        match (fwd, ccw) {
            (true, false) => Primitive::FwdTurnCw,
            (true, true) => Primitive::FwdTurnCcw,
            (false, false) => Primitive::BackTurnCw,
            (false, true) => Primitive::BackTurnCcw,
        }
    };
    Some((side, p))
}

/// Whether the geometric move `from → to` is a turn between two right-angle (turn) states: the
/// moving arm would swing about the holding arm's axis (g → j: arm A from −Y to −Z about arm B's
/// +X). MMIC-I's only rotary joint is the hip, whose axis is perpendicular to both arms, and
/// Table 6's caption says the turns "include a rotation of the hip": no joint makes such a
/// move, so the robot has 12 fewer moves than the model (spec/decisions.toml,
/// `turn-to-turn-moves`).
pub const fn turns_without_hip(from: State, to: State) -> bool {
    matches!(from.kind(), StateKind::Turn)
        && matches!(to.kind(), StateKind::Turn)
        && single_move(from, to).is_some()
}

/// The single-primitive move from `from` to `to` the robot can make: [`single_move`] but for
/// the 12 [`turns_without_hip`]. Every straight move (primitives 1–4) is one, and every turn
/// that has a state with the arms in line (matched or stretch) at one end, so the hip rotates
/// between 180° and a right angle. This is the map of Figure 9 ([`super::map::MAP`]).
pub const fn robot_move(from: State, to: State) -> Option<(Side, Primitive)> {
    if turns_without_hip(from, to) {
        None
    } else {
        single_move(from, to)
    }
}

/// Every move of the model, as (from, to, moving side, primitive), rows and columns in Table 5
/// order: the 72 of [`single_move`], the 12 [`turns_without_hip`] among them.
pub fn model_moves() -> impl Iterator<Item = (State, State, Side, Primitive)> {
    State::ALL.into_iter().flat_map(|f| {
        State::ALL
            .into_iter()
            .filter_map(move |t| single_move(f, t).map(|(side, p)| (f, t, side, p)))
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A face as Table 5 names it: `Xneg`, `Ypos`, ...
    fn named(f: Face) -> &'static str {
        match (f.axis, f.sign) {
            (Axis::X, Sign::Negative) => "Xneg",
            (Axis::Y, Sign::Negative) => "Yneg",
            (Axis::Z, Sign::Negative) => "Zneg",
            (Axis::X, Sign::Positive) => "Xpos",
            (Axis::Y, Sign::Positive) => "Ypos",
            (Axis::Z, Sign::Positive) => "Zpos",
        }
    }

    // req: P6.2
    #[test]
    fn faces_follow_the_table_5_names() {
        for s in State::ALL {
            let (a, b) = faces(s);
            let mut words = s.name().split(' ');
            let first = words.next().unwrap();
            let second = words.next().unwrap();
            if second == "match" {
                assert_eq!((named(a), named(b)), (first, first), "{s}");
            } else {
                assert_eq!((named(a), named(b)), (first, second), "{s}");
            }
        }
    }

    // req: P6.2
    #[test]
    fn unit_and_cross_follow_the_right_hand_rule() {
        let (x, y, z) = (
            unit(Axis::X, Sign::Positive),
            unit(Axis::Y, Sign::Positive),
            unit(Axis::Z, Sign::Positive),
        );
        assert_eq!((x, y, z), ([1, 0, 0], [0, 1, 0], [0, 0, 1]));
        assert_eq!(unit(Axis::Y, Sign::Negative), [0, -1, 0]);
        assert_eq!(cross(x, y), z);
        assert_eq!(cross(y, z), x);
        assert_eq!(cross(z, x), y);
        assert_eq!(cross(y, x), [0, 0, -1]);
        assert_eq!(cross(x, x), [0, 0, 0]);
    }
}
