//! The serde impls of the command set (feature `serde`) that a derive cannot give: servo
//! targets checked against their travel, and the state-naming commands checked against the
//! map, so that JSON is refused exactly where the packet's bytes are.
// req: D:opcodes

use super::{PrimitiveMove, Reconfiguration, ServoTarget, Travel};
use crate::pose::{Primitive, State};

/// An arm target from JSON, refused outside the arms' travel.
pub(super) fn arm_target<'de, D: serde::Deserializer<'de>>(d: D) -> Result<ServoTarget, D::Error> {
    use serde::Deserialize as _;
    let t = ServoTarget::deserialize(d)?;
    Travel::ARM
        .check(t)
        .map_err(|e| serde::de::Error::custom(format_args!("arm target: {e}")))
}

/// A gripper target from JSON, refused outside the grippers' travel.
pub(super) fn gripper_target<'de, D: serde::Deserializer<'de>>(
    d: D,
) -> Result<ServoTarget, D::Error> {
    use serde::Deserialize as _;
    let t = ServoTarget::deserialize(d)?;
    Travel::GRIPPER
        .check(t)
        .map_err(|e| serde::de::Error::custom(format_args!("gripper target: {e}")))
}

impl<'de> serde::Deserialize<'de> for Reconfiguration {
    fn deserialize<D: serde::Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        #[derive(serde::Deserialize)]
        #[serde(deny_unknown_fields)]
        struct Raw {
            initial: State,
            target: State,
        }
        let r = Raw::deserialize(d)?;
        Reconfiguration::new(r.initial, r.target).map_err(serde::de::Error::custom)
    }
}

impl<'de> serde::Deserialize<'de> for PrimitiveMove {
    fn deserialize<D: serde::Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        #[derive(serde::Deserialize)]
        #[serde(deny_unknown_fields)]
        struct Raw {
            primitive: Primitive,
            target: State,
        }
        let r = Raw::deserialize(d)?;
        PrimitiveMove::new(r.primitive, r.target).map_err(serde::de::Error::custom)
    }
}
