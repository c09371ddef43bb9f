//! Numbers as serde reads them (feature `serde`): the exact integer every ranged type is read
//! through, so that an out-of-range value gets its field's own message.

use core::fmt;

/// Any integer as serde reads it, exactly: the intermediate through which the ranged types of
/// this crate deserialize (`serde(try_from = "Number")`), so that every out-of-range number gets
/// its field's own message — `board number must be in 1..=255, found 300`, `servo pulse width
/// (us) must be in 500..=2500, found -5` — instead of serde's `expected u8`, whatever its sign
/// or size.
///
/// ```
/// # #[cfg(feature = "serde")] {
/// use mmic::units::{BoardNumber, Number};
/// assert_eq!(BoardNumber::try_from(Number(7)).unwrap().get(), 7);
/// assert_eq!(
///     BoardNumber::try_from(Number(300)).unwrap_err().to_string(),
///     "board number must be in 1..=255, found 300"
/// );
/// # }
/// ```
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Number(pub i128);

/// A number outside the range of the field it was read for (see [`Number`]).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, thiserror::Error)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
#[error("{quantity} must be in {min}..={max}, found {found}")]
pub struct NumberRangeError {
    /// Which quantity was being read.
    pub quantity: &'static str,
    /// Smallest accepted value.
    pub min: i128,
    /// Largest accepted value.
    pub max: i128,
    /// The value that was refused.
    pub found: i128,
}

impl Number {
    /// The value as a `W` turned into a `T` by `make`; a value that does not fit `W`, or that
    /// `make` refuses, is a [`NumberRangeError`] naming `quantity` and `min..=max`.
    pub fn narrow<W: TryFrom<i128>, T>(
        self,
        quantity: &'static str,
        (min, max): (i128, i128),
        make: impl FnOnce(W) -> Option<T>,
    ) -> Result<T, NumberRangeError> {
        W::try_from(self.0)
            .ok()
            .and_then(make)
            .ok_or(NumberRangeError {
                quantity,
                min,
                max,
                found: self.0,
            })
    }
}

impl<'de> serde::Deserialize<'de> for Number {
    fn deserialize<D: serde::Deserializer<'de>>(d: D) -> Result<Number, D::Error> {
        struct V;
        impl serde::de::Visitor<'_> for V {
            type Value = Number;
            fn expecting(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
                f.write_str("an integer")
            }
            fn visit_i64<E: serde::de::Error>(self, v: i64) -> Result<Number, E> {
                Ok(Number(i128::from(v)))
            }
            fn visit_u64<E: serde::de::Error>(self, v: u64) -> Result<Number, E> {
                Ok(Number(i128::from(v)))
            }
            fn visit_i128<E: serde::de::Error>(self, v: i128) -> Result<Number, E> {
                Ok(Number(v))
            }
            fn visit_u128<E: serde::de::Error>(self, v: u128) -> Result<Number, E> {
                Ok(Number(i128::try_from(v).unwrap_or(i128::MAX)))
            }
            // JSON readers hand integers beyond u64 over as floats: a whole float is taken
            // as the integer it is (saturating beyond ±1.7e38), a fraction is refused.
            #[cfg_attr(
                not(test),
                expect(
                    clippy::as_conversions,
                    reason = "f64 to i128 and back, no From: `as` saturates (NaN to 0, but \
                              only finite values get here), and the round trip tells a whole \
                              number from a fraction"
                )
            )]
            fn visit_f64<E: serde::de::Error>(self, v: f64) -> Result<Number, E> {
                if v.is_finite() && v == (v as i128) as f64 {
                    Ok(Number(v as i128))
                } else {
                    Err(E::invalid_type(serde::de::Unexpected::Float(v), &self))
                }
            }
        }
        d.deserialize_any(V)
    }
}

/// Deserializers for plain integer fields, through [`Number`], so that an out-of-range value
/// names the field's quantity and range like the ranged types do.
pub(crate) mod de {
    use super::Number;

    macro_rules! integer_field {
        ($(#[$doc:meta] $name:ident: $t:ty, $quantity:literal;)*) => {$(
            #[$doc]
            pub(crate) fn $name<'de, D: serde::Deserializer<'de>>(d: D) -> Result<$t, D::Error> {
                <Number as serde::Deserialize>::deserialize(d)?
                    .narrow($quantity, (i128::from(<$t>::MIN), i128::from(<$t>::MAX)), Some)
                    .map_err(serde::de::Error::custom)
            }
        )*};
    }

    integer_field! {
        /// An exactly-once sequence number (u16).
        seq16: u16, "sequence number";
        /// An A→B sequence number (u8).
        seq8: u8, "A->B sequence number";
        /// A voltage in mV (u16).
        millivolts: u16, "voltage (mV)";
        /// A current in mA (u16).
        milliamps: u16, "current (mA)";
    }
}

#[cfg(all(test, feature = "serde"))]
mod tests {
    use super::*;

    /// A whole float (JSON's form of an integer beyond u64, or written with an exponent) is
    /// that integer; a fraction is refused.
    #[test]
    fn a_whole_float_is_its_integer() {
        let read = |s: &str| serde_json::from_str::<Number>(s).ok();
        assert_eq!(read("1e2"), Some(Number(100)));
        assert_eq!(read("-3.0"), Some(Number(-3)));
        assert_eq!(read("1e20"), Some(Number(100_000_000_000_000_000_000)));
        assert_eq!(read("1.5"), None);
        assert_eq!(read("7"), Some(Number(7)));
    }
}
