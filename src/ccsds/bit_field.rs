//! Narrow integer fields (11-bit APID, 14-bit sequence count, 4-bit nibbles) as checked
//! newtypes, so that a `Repr` can only hold what its bits can carry and `emit` never has to
//! truncate (which would break `parse(emit(x)) == x`).

/// Declares `$name($int)` holding `0..=$max`, `$max` all ones: a [`ranged!`] type
/// (`new`, `get`, the conversions, serde, proptest, defmt) with the field's `MAX` and the
/// `masked` of decoding, where the bits cannot hold more.
///
/// [`ranged!`]: crate::units::ranged
macro_rules! bit_field {
    ($(#[$doc:meta])* $name:ident($int:ty), max $max:expr, $quantity:literal) => {
        crate::units::ranged! {
            $(#[$doc])*
            #[derive(Default)]
            pub struct $name($int), min 0, max $max, $quantity;
        }

        // `masked` relies on the maximum being all ones: its ones are all at the bottom.
        const _: () = {
            let max: $int = $max;
            assert!(max.trailing_ones() == max.count_ones());
        };

        impl $name {
            /// The largest value the field's bits carry.
            pub const MAX: $name = $name($max);

            /// The field's bits of `v` (the others dropped): for decoding, where the bits
            /// cannot hold more.
            pub(crate) const fn masked(v: $int) -> $name {
                $name(v & $max)
            }
        }

        impl From<$name> for u32 {
            fn from(v: $name) -> u32 {
                u32::from(v.0)
            }
        }
    };
}
pub(crate) use bit_field;
