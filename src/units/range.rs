//! The range check every bounded quantity of the crate shares: [`RangeError`], and the
//! [`ranged!`](ranged) macro that declares a checked integer newtype, so that a value outside
//! its range is refused by the same words in the constructor, in JSON and in proptest.

/// Out-of-range value handed to a unit constructor; carries the offending value and the range.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, thiserror::Error)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
#[error("{quantity} must be in {min}..={max}, found {found}")]
pub struct RangeError {
    /// Which quantity was being built.
    pub quantity: &'static str,
    /// Smallest accepted value.
    pub min: u32,
    /// Largest accepted value.
    pub max: u32,
    /// The value that was refused.
    pub found: u32,
}

/// Whether `v` lies in `min..=max` (a function, so that a bound at the type's end does not
/// read as an always-true comparison inside [`ranged!`](ranged)).
#[doc(hidden)]
pub const fn within(v: u32, min: u32, max: u32) -> bool {
    min <= v && v <= max
}

/// Declares `$vis struct $name($int)` holding `$min..=$max`: `new` (refusing with a
/// [`RangeError`] naming `$quantity`), `get`, `TryFrom<$int>`, `From<$name> for $int`, and,
/// with their features, serde (a plain number, read through [`Number`](super::Number) so that
/// an out-of-range one gets the same message), proptest (both bounds over-weighted: off-by-one
/// mistakes live there) and defmt. The bounds may name the type's own constants (`Self::MAX_US`).
macro_rules! ranged {
    (
        $(#[$m:meta])*
        $vis:vis struct $name:ident($int:ty), min $min:expr, max $max:expr, $quantity:literal;
    ) => {
        $(#[$m])*
        #[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord)]
        #[cfg_attr(feature = "defmt", derive(defmt::Format))]
        $vis struct $name($int);

        impl $name {
            #[doc = concat!("`v` as a ", $quantity, ", refused outside `", stringify!($min), "..=", stringify!($max), "`.")]
            pub const fn new(v: $int) -> Result<$name, $crate::units::RangeError> {
                let (min, max): ($int, $int) = ($min, $max);
                let (found, min, max) = (
                    $crate::units::widen::to_u32(v.to_le_bytes()),
                    $crate::units::widen::to_u32(min.to_le_bytes()),
                    $crate::units::widen::to_u32(max.to_le_bytes()),
                );
                if $crate::units::range::within(found, min, max) {
                    Ok($name(v))
                } else {
                    Err($crate::units::RangeError {
                        quantity: $quantity,
                        min,
                        max,
                        found,
                    })
                }
            }

            /// The value as it goes on the wire.
            pub const fn get(self) -> $int {
                self.0
            }
        }

        impl TryFrom<$int> for $name {
            type Error = $crate::units::RangeError;
            fn try_from(v: $int) -> Result<$name, $crate::units::RangeError> {
                $name::new(v)
            }
        }

        impl From<$name> for $int {
            fn from(v: $name) -> $int {
                v.0
            }
        }

        #[cfg(feature = "serde")]
        impl TryFrom<$crate::units::Number> for $name {
            type Error = $crate::units::NumberRangeError;
            fn try_from(
                n: $crate::units::Number,
            ) -> Result<$name, $crate::units::NumberRangeError> {
                let (min, max): ($int, $int) = ($min, $max);
                n.narrow($quantity, (i128::from(min), i128::from(max)), |v: $int| {
                    $name::new(v).ok()
                })
            }
        }

        #[cfg(feature = "serde")]
        impl serde::Serialize for $name {
            fn serialize<S: serde::Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
                serde::Serialize::serialize(&self.0, s)
            }
        }

        #[cfg(feature = "serde")]
        impl<'de> serde::Deserialize<'de> for $name {
            fn deserialize<D: serde::Deserializer<'de>>(d: D) -> Result<$name, D::Error> {
                let n = <$crate::units::Number as serde::Deserialize>::deserialize(d)?;
                $name::try_from(n).map_err(serde::de::Error::custom)
            }
        }

        #[cfg(feature = "proptest")]
        impl proptest::arbitrary::Arbitrary for $name {
            type Parameters = ();
            type Strategy = proptest::strategy::BoxedStrategy<$name>;
            fn arbitrary_with((): ()) -> Self::Strategy {
                use proptest::strategy::{Just, Strategy};
                let (lo, hi): ($int, $int) = ($min, $max);
                proptest::prop_oneof![1 => Just(lo), 1 => Just(hi), 8 => lo..=hi]
                    .prop_filter_map($quantity, |v| $name::new(v).ok())
                    .boxed()
            }
        }
    };
}
pub(crate) use ranged;
