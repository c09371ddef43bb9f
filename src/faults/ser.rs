//! [`Faults`]' JSON form: the list of the latched faults' names, in bit order; a name listed
//! twice is refused.

use super::{Fault, Faults};

impl serde::Serialize for Faults {
    fn serialize<S: serde::Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        use serde::ser::SerializeSeq;
        let mut seq = s.serialize_seq(None)?;
        for f in self.iter() {
            seq.serialize_element(&f)?;
        }
        seq.end()
    }
}

impl<'de> serde::Deserialize<'de> for Faults {
    fn deserialize<D: serde::Deserializer<'de>>(d: D) -> Result<Faults, D::Error> {
        struct V;
        impl<'de> serde::de::Visitor<'de> for V {
            type Value = Faults;
            fn expecting(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
                f.write_str("a list of fault names")
            }
            fn visit_seq<A: serde::de::SeqAccess<'de>>(self, mut a: A) -> Result<Faults, A::Error> {
                let mut set = Faults::EMPTY;
                while let Some(f) = a.next_element::<Fault>()? {
                    // A set: a name listed twice is an operator's slip, not a second fault.
                    if set.contains(f) {
                        return Err(serde::de::Error::custom(format_args!(
                            "fault `{}` (bit {}) listed twice",
                            f.name(),
                            f.bit()
                        )));
                    }
                    set = set.with(f);
                }
                Ok(set)
            }
        }
        d.deserialize_seq(V)
    }
}
