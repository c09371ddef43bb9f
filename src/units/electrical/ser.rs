//! [`Electrical`]'s JSON form: the seven fields by name, as integers. Read through typed
//! millivolt and milliampere values, so that an out-of-range value names its quantity and
//! range (as the ranged types do) and the field list is written once, here.

use super::Electrical;
use crate::units::de;

/// A voltage as JSON reads it, mV.
struct Mv(u16);

impl<'de> serde::Deserialize<'de> for Mv {
    fn deserialize<D: serde::Deserializer<'de>>(d: D) -> Result<Mv, D::Error> {
        de::millivolts(d).map(Mv)
    }
}

/// A current as JSON reads it, mA.
struct Ma(u16);

impl<'de> serde::Deserialize<'de> for Ma {
    fn deserialize<D: serde::Deserializer<'de>>(d: D) -> Result<Ma, D::Error> {
        de::milliamps(d).map(Ma)
    }
}

/// The JSON object, field for field (names as [`Electrical`]'s, none unknown).
#[derive(serde::Deserialize)]
#[serde(deny_unknown_fields, rename = "Electrical")]
pub(super) struct Json {
    v_bat: Mv,
    i_bat: Ma,
    i_loc: Ma,
    i_grip: Ma,
    i_3v3: Ma,
    v_reg: Mv,
    i_bo: Ma,
}

impl From<Json> for Electrical {
    fn from(j: Json) -> Electrical {
        Electrical {
            v_bat: j.v_bat.0,
            i_bat: j.i_bat.0,
            i_loc: j.i_loc.0,
            i_grip: j.i_grip.0,
            i_3v3: j.i_3v3.0,
            v_reg: j.v_reg.0,
            i_bo: j.i_bo.0,
        }
    }
}
