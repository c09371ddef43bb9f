//! Narrow integer fields (11-bit APID, 14-bit sequence count, 4-bit nibbles) as checked
//! newtypes, so that a `Repr` can only hold what its bits can carry and `emit` never has to
//! truncate (which would break `parse(emit(x)) == x`).

/// Declares `$name($int)` holding `0..=$max`, with `new`, `get`, `MAX`, the conversions and
/// the serde, proptest and defmt impls of the crate's other ranged types.
macro_rules! ranged {
    ($(#[$doc:meta])* $name:ident($int:ty), max $max:expr, $quantity:literal) => {
        $(#[$doc])*
        #[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord, Default)]
        #[cfg_attr(feature = "defmt", derive(defmt::Format))]
        #[cfg_attr(
            feature = "serde",
            derive(serde::Serialize, serde::Deserialize),
            serde(try_from = "crate::units::Number", into = "u32")
        )]
        pub struct $name($int);

        // `masked` relies on the maximum being all ones.
        const _: () = assert!(($max as u32) & ($max as u32 + 1) == 0);

        impl $name {
            /// The largest value the field's bits carry.
            pub const MAX: $name = $name($max);

            #[doc = concat!("`v` as a ", $quantity, ", refused above `", stringify!($max), "`.")]
            pub const fn new(v: $int) -> Result<$name, crate::units::RangeError> {
                if v <= $max {
                    Ok($name(v))
                } else {
                    Err(crate::units::RangeError {
                        quantity: $quantity,
                        min: 0,
                        max: $max as u32,
                        found: v as u32,
                    })
                }
            }

            /// The value as it goes on the wire.
            pub const fn get(self) -> $int {
                self.0
            }

            /// The field's bits of `v` (the others dropped): for decoding, where the bits
            /// cannot hold more.
            pub(crate) const fn masked(v: $int) -> $name {
                $name(v & $max)
            }
        }

        impl TryFrom<$int> for $name {
            type Error = crate::units::RangeError;
            fn try_from(v: $int) -> Result<$name, crate::units::RangeError> {
                $name::new(v)
            }
        }

        impl From<$name> for $int {
            fn from(v: $name) -> $int {
                v.0
            }
        }

        impl From<$name> for u32 {
            fn from(v: $name) -> u32 {
                v.0 as u32
            }
        }

        #[cfg(feature = "serde")]
        impl TryFrom<crate::units::Number> for $name {
            type Error = crate::units::NumberRangeError;
            fn try_from(n: crate::units::Number) -> Result<$name, crate::units::NumberRangeError> {
                n.narrow($quantity, (0, $max as i128), |v: $int| $name::new(v).ok())
            }
        }

        #[cfg(feature = "proptest")]
        impl proptest::arbitrary::Arbitrary for $name {
            type Parameters = ();
            type Strategy = proptest::strategy::BoxedStrategy<$name>;
            fn arbitrary_with((): ()) -> Self::Strategy {
                use proptest::strategy::{Just, Strategy};
                // Both bounds over-weighted, as the crate's other ranged types.
                proptest::prop_oneof![1 => Just(0 as $int), 1 => Just($max), 8 => 0..=($max as $int)]
                    .prop_filter_map($quantity, |v| $name::new(v).ok())
                    .boxed()
            }
        }
    };
}
pub(crate) use ranged;
