//! The JSON form of [`BCommandRepr`] (feature `serde`): the field names of
//! [`FIELDS`](super::FIELDS), byte 5 as one object, `flags`, holding the power switches and
//! the stop bit.

use super::{BCommandRepr, BPower, BolterOrder};
use crate::units::PulseWidth;

/// Byte 5, bit by bit.
#[derive(serde::Serialize, serde::Deserialize)]
#[serde(deny_unknown_fields)]
struct Flags {
    regulator: bool,
    arm: bool,
    gripper: bool,
    bolter: bool,
    stop: bool,
}

#[derive(serde::Serialize, serde::Deserialize)]
#[serde(deny_unknown_fields)]
struct Form {
    #[serde(deserialize_with = "crate::units::de::seq8")]
    seq: u8,
    flags: Flags,
    arm_target: PulseWidth,
    gripper_target: PulseWidth,
    bolter: Option<BolterOrder>,
}

impl serde::Serialize for BCommandRepr {
    fn serialize<S: serde::Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        let p = self.power;
        Form {
            seq: self.seq,
            flags: Flags {
                regulator: p.regulator,
                arm: p.arm,
                gripper: p.gripper,
                bolter: p.bolter,
                stop: self.stop,
            },
            arm_target: self.arm_target,
            gripper_target: self.gripper_target,
            bolter: self.bolter,
        }
        .serialize(s)
    }
}

impl<'de> serde::Deserialize<'de> for BCommandRepr {
    fn deserialize<D: serde::Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        let f = Form::deserialize(d)?;
        Ok(BCommandRepr {
            seq: f.seq,
            power: BPower {
                regulator: f.flags.regulator,
                arm: f.flags.arm,
                gripper: f.flags.gripper,
                bolter: f.flags.bolter,
            },
            stop: f.flags.stop,
            arm_target: f.arm_target,
            gripper_target: f.gripper_target,
            bolter: f.bolter,
        })
    }
}
