//! Where things point in the lattice: the modules of a side, the axes, signs and the direction
//! of gravity an IMU sees.

use super::Side;

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
        match self {
            Module::Hip => 0,
            Module::ArmA => 1,
            Module::ArmB => 2,
            Module::GripperA => 3,
            Module::GripperB => 4,
            Module::BolterA => 5,
            Module::BolterB => 6,
        }
    }

    /// Module with index `i`, if any.
    pub const fn from_index(i: u8) -> Option<Module> {
        match super::slice::get(&Self::ALL, super::widen::to_usize(i.to_le_bytes())) {
            Some(m) => Some(*m),
            None => None,
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

#[cfg(test)]
mod tests {
    use super::*;

    /// The hip and side A's arm, gripper and bolter sit on side A (board A drives them); side
    /// B's three on side B.
    #[test]
    fn each_module_sits_on_its_side() {
        let a = [Module::Hip, Module::ArmA, Module::GripperA, Module::BolterA];
        for m in Module::ALL {
            let want = if a.contains(&m) { Side::A } else { Side::B };
            assert_eq!(m.side(), want, "{m:?}");
        }
        assert_eq!(
            Module::ALL.iter().filter(|m| m.side() == Side::B).count(),
            3
        );
    }

    #[test]
    fn module_index_is_the_position_in_all() {
        for (i, m) in Module::ALL.iter().enumerate() {
            assert_eq!(usize::from(m.index()), i);
            assert_eq!(m.index(), *m as u8);
            assert_eq!(Module::from_index(m.index()), Some(*m));
        }
        assert_eq!(Module::from_index(7), None);
        assert_eq!(Module::from_index(u8::MAX), None);
    }
}
