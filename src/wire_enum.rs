//! `wire_enum!`: the C-like enums of the protocol (primitives, states, faults, refusals, …)
//! declared once, as a table of variants with their wire values and names, instead of writing
//! `ALL`, the wire conversions, `name()`, `Display` and `TryFrom`/`From` by hand for each.
//!
//! ```text
//! wire_enum! {
//!     /// Doc and attributes of the enum (derives, `cfg_attr(serde…)`), passed through.
//!     #[derive(Debug, Clone, Copy, PartialEq, Eq)]
//!     pub enum Name: u8 {
//!         /// Variant doc and attributes, passed through.
//!         First = 1 => "first",
//!         Second = 2 => "second",
//!     }
//!
//!     // Then any of these sections, in any order, each generating what it shows:
//!     /// Doc.
//!     const ALL;                                      // every variant, in declaration order
//!     /// Doc.
//!     pub const fn to_wire(self) -> u8;               // the value (any method name)
//!     /// Doc.
//!     pub const fn from_wire(b: u8) -> Option<Self>;  // by matching the values (any name)
//!     /// Doc.
//!     pub const fn name(self) -> &'static str;        // the name
//!     /// Doc.
//!     pub const fn index(self) -> usize;              // the position in declaration order
//!                                                     // (in `ALL`; any method name)
//!     impl Display("{} {}", to_wire, name);           // write! of these methods' results
//!     /// Doc.
//!     #[error("message, found {0}")]
//!     pub struct NameError(pub u8);                   // this error type (thiserror), TryFrom<u8>
//!                                                     // with it, and From<Name> for u8
//!     impl TryFrom<Number>("quantity");               // (feature serde) from a JSON number,
//!                                                     // range: min..=max of the values
//! }
//! ```
//!
//! `= value` is a `u8` literal (`3`, `b'a'`). With `enum Name: u8` the enum is `#[repr(u8)]` and
//! every value is also the variant's discriminant (so `as u8` gives it); with `enum Name` the
//! discriminants stay Rust's own (0, 1, … in declaration order) and the values serve the
//! generated methods only. There the value and `=> "name"` may be left out, as long as no
//! section needs them.
//!
//! Conversions match the declared values, so no bound is written twice: adding a variant to
//! the table is the whole change. Every number the methods give comes from a `match` on the
//! variants, never from an `as` cast (rule R5 of `docs/coding-standard.md`): the enum's value
//! through the `-> u8` method (`to_wire`, `value`, …), its position through the `-> usize` one
//! (for indexing a table in declaration order), both `const`, and both compiled to the
//! discriminant itself where that is what they return.
// req: D:mode-codes, D:state-letters, D:zero-is-none

/// Declares a C-like wire enum and its conversions; see the module documentation.
macro_rules! wire_enum {
    // ---- sections, munched one at a time; `$data` is the variant table ----
    (@items $Name:ident $data:tt) => {};
    (@items $Name:ident $data:tt $(#[$m:meta])* const ALL; $($rest:tt)*) => {
        $crate::wire_enum::wire_enum!(@all $Name $data [$(#[$m])*]);
        $crate::wire_enum::wire_enum!(@items $Name $data $($rest)*);
    };
    (@items $Name:ident $data:tt $(#[$m:meta])* pub const fn name(self) -> &'static str;
        $($rest:tt)*) => {
        $crate::wire_enum::wire_enum!(@name $Name $data [$(#[$m])*]);
        $crate::wire_enum::wire_enum!(@items $Name $data $($rest)*);
    };
    (@items $Name:ident $data:tt $(#[$m:meta])* pub const fn $to:ident(self) -> u8;
        $($rest:tt)*) => {
        $crate::wire_enum::wire_enum!(@to $Name $data [$(#[$m])*] $to);
        $crate::wire_enum::wire_enum!(@items $Name $data $($rest)*);
    };
    (@items $Name:ident $data:tt $(#[$m:meta])* pub const fn $ix:ident(self) -> usize;
        $($rest:tt)*) => {
        $crate::wire_enum::wire_enum!(@index $Name $data [$(#[$m])*] $ix);
        $crate::wire_enum::wire_enum!(@items $Name $data $($rest)*);
    };
    (@items $Name:ident $data:tt
        $(#[$m:meta])* pub const fn $from:ident($arg:ident: u8) -> Option<Self>;
        $($rest:tt)*) => {
        $crate::wire_enum::wire_enum!(@from $Name $data [$(#[$m])*] $from $arg);
        $crate::wire_enum::wire_enum!(@items $Name $data $($rest)*);
    };
    (@items $Name:ident $data:tt impl Display($fmt:literal $(, $method:ident)* $(,)?);
        $($rest:tt)*) => {
        impl core::fmt::Display for $Name {
            fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
                write!(f, $fmt $(, self.$method())*)
            }
        }
        $crate::wire_enum::wire_enum!(@items $Name $data $($rest)*);
    };
    (@items $Name:ident $data:tt $(#[$m:meta])* pub struct $Err:ident(pub u8);
        $($rest:tt)*) => {
        $crate::wire_enum::wire_enum!(@error $Name $data [$(#[$m])*] $Err);
        $crate::wire_enum::wire_enum!(@items $Name $data $($rest)*);
    };
    (@items $Name:ident $data:tt impl TryFrom<Number>($quantity:literal); $($rest:tt)*) => {
        $crate::wire_enum::wire_enum!(@number $Name $data $quantity);
        $crate::wire_enum::wire_enum!(@items $Name $data $($rest)*);
    };
    (@items $Name:ident $data:tt $($rest:tt)+) => {
        compile_error!(concat!("wire_enum!: unknown section: ", stringify!($($rest)+)));
    };

    // ---- what each section generates ----
    (@all $Name:ident [$($V:ident $(= $val:literal)? $(=> $vname:literal)?;)+]
        [$(#[$m:meta])*]) => {
        impl $Name {
            $(#[$m])*
            pub const ALL: [$Name; [$($Name::$V),+].len()] = [$($Name::$V),+];
        }
    };
    (@name $Name:ident [$($V:ident $(= $val:literal)? $(=> $vname:literal)?;)+]
        [$(#[$m:meta])*]) => {
        impl $Name {
            $(#[$m])*
            pub const fn name(self) -> &'static str {
                match self {
                    $($Name::$V => $($vname)?,)+
                }
            }
        }
    };
    (@to $Name:ident [$($V:ident $(= $val:literal)? $(=> $vname:literal)?;)+]
        [$(#[$m:meta])*] $to:ident) => {
        impl $Name {
            $(#[$m])*
            pub const fn $to(self) -> u8 {
                match self {
                    $($Name::$V => $($val)?,)+
                }
            }
        }
    };
    (@index $Name:ident [$($V:ident $(= $val:literal)? $(=> $vname:literal)?;)+]
        [$(#[$m:meta])*] $ix:ident) => {
        impl $Name {
            $(#[$m])*
            pub const fn $ix(self) -> usize {
                let v = self;
                $crate::wire_enum::wire_enum!(@arms v $Name [] [] $($V)+)
            }
        }
    };
    // The `match` of `@index`, its arms built one variant at a time: each variant's position
    // is the number of those before it (`$before`), counted as the length of their names.
    (@arms $v:ident $Name:ident [$($arms:tt)*] [$($before:ident)*] $V:ident $($after:ident)*) => {
        $crate::wire_enum::wire_enum!(@arms $v $Name
            [$($arms)* $Name::$V => <[&str]>::len(&[$(stringify!($before)),*]),]
            [$($before)* $V] $($after)*)
    };
    (@arms $v:ident $Name:ident [$($arms:tt)*] [$($before:ident)*]) => {
        match $v {
            $($arms)*
        }
    };
    (@from $Name:ident [$($V:ident $(= $val:literal)? $(=> $vname:literal)?;)+]
        [$(#[$m:meta])*] $from:ident $arg:ident) => {
        impl $Name {
            $(#[$m])*
            pub const fn $from($arg: u8) -> Option<$Name> {
                match $arg {
                    $($($val)? => Some($Name::$V),)+
                    _ => None,
                }
            }
        }
    };
    (@error $Name:ident [$($V:ident $(= $val:literal)? $(=> $vname:literal)?;)+]
        [$(#[$m:meta])*] $Err:ident) => {
        #[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, thiserror::Error)]
        #[cfg_attr(feature = "defmt", derive(defmt::Format))]
        $(#[$m])*
        pub struct $Err(pub u8);

        impl TryFrom<u8> for $Name {
            type Error = $Err;
            fn try_from(n: u8) -> Result<$Name, $Err> {
                match n {
                    $($($val)? => Ok($Name::$V),)+
                    _ => Err($Err(n)),
                }
            }
        }

        impl From<$Name> for u8 {
            fn from(v: $Name) -> u8 {
                match v {
                    $($Name::$V => $($val)?,)+
                }
            }
        }
    };
    (@number $Name:ident [$($V:ident $(= $val:literal)? $(=> $vname:literal)?;)+]
        $quantity:literal) => {
        #[cfg(feature = "serde")]
        impl TryFrom<$crate::units::Number> for $Name {
            type Error = $crate::units::NumberRangeError;
            fn try_from(n: $crate::units::Number) -> Result<$Name, Self::Error> {
                let (min, max) = [$($($val)?),+]
                    .into_iter()
                    .fold((u8::MAX, u8::MIN), |(lo, hi), v: u8| (lo.min(v), hi.max(v)));
                n.narrow($quantity, (min.into(), max.into()), |b: u8| match b {
                    $($($val)? => Some($Name::$V),)+
                    _ => None,
                })
            }
        }
    };

    // ---- the enum: `: u8` makes the values the discriminants ----
    (
        $(#[$meta:meta])*
        $vis:vis enum $Name:ident: u8 {
            $($(#[$vmeta:meta])* $V:ident = $val:literal $(=> $vname:literal)?),+ $(,)?
        }
        $($rest:tt)*
    ) => {
        $(#[$meta])*
        #[repr(u8)]
        $vis enum $Name {
            $($(#[$vmeta])* $V = $val,)+
        }
        $crate::wire_enum::wire_enum!(@items $Name [$($V = $val $(=> $vname)?;)+] $($rest)*);
    };
    (
        $(#[$meta:meta])*
        $vis:vis enum $Name:ident {
            $($(#[$vmeta:meta])* $V:ident $(= $val:literal)? $(=> $vname:literal)?),+ $(,)?
        }
        $($rest:tt)*
    ) => {
        $(#[$meta])*
        $vis enum $Name {
            $($(#[$vmeta])* $V,)+
        }
        $crate::wire_enum::wire_enum!(@items $Name [$($V $(= $val)? $(=> $vname)?;)+] $($rest)*);
    };
}
pub(crate) use wire_enum;

#[cfg(test)]
mod tests {
    use core::fmt::Write;

    fn shown(v: impl core::fmt::Display) -> heapless::String<32> {
        let mut s = heapless::String::new();
        // A 32-byte string holds every name here; an overflow would show as a failed comparison.
        let _ = write!(s, "{v}");
        s
    }

    wire_enum! {
        /// Values with gaps, as discriminants.
        #[derive(Debug, Clone, Copy, PartialEq, Eq)]
        #[cfg_attr(feature = "defmt", derive(defmt::Format))]
        enum Sparse: u8 {
            /// Two.
            Two = 2 => "two",
            /// Five.
            Five = 5 => "five",
            /// Nine.
            Nine = 9 => "nine",
        }

        /// All.
        const ALL;
        /// Value.
        pub const fn value(self) -> u8;
        /// From a value.
        pub const fn from_value(v: u8) -> Option<Self>;
        /// Name.
        pub const fn name(self) -> &'static str;
        /// Position.
        pub const fn position(self) -> usize;
        impl Display("{}={}", name, value);
        /// Not a value.
        #[error("not a sparse value: {0}")]
        pub struct SparseError(pub u8);
        impl TryFrom<Number>("sparse");
    }

    wire_enum! {
        /// Values apart from the (default) discriminants.
        #[derive(Debug, Clone, Copy, PartialEq, Eq)]
        #[cfg_attr(feature = "defmt", derive(defmt::Format))]
        enum Letters {
            /// x.
            X = b'x',
            /// y.
            Y = b'y',
        }

        /// All.
        const ALL;
        /// Value.
        pub const fn to_wire(self) -> u8;
        /// From a value.
        pub const fn from_wire(b: u8) -> Option<Self>;
        /// Position.
        pub const fn index(self) -> usize;
    }

    #[test]
    fn conversions_follow_the_declared_values_only() {
        assert_eq!(Sparse::ALL, [Sparse::Two, Sparse::Five, Sparse::Nine]);
        for s in Sparse::ALL {
            assert_eq!(s as u8, s.value());
            assert_eq!(u8::from(s), s.value());
            assert_eq!(Sparse::try_from(s.value()), Ok(s));
        }
        let accepted = (0..=255u8).filter(|&v| Sparse::from_value(v).is_some());
        assert!(accepted.eq([2, 5, 9]));
        assert_eq!(Sparse::ALL.map(Sparse::position), [0, 1, 2]);
        assert_eq!(Sparse::try_from(3), Err(SparseError(3)));
        assert_eq!(shown(SparseError(3)), "not a sparse value: 3");
        assert_eq!(shown(Sparse::Five), "five=5");

        assert_eq!((Letters::X as u8, Letters::Y as u8), (0, 1));
        assert_eq!(Letters::ALL.map(Letters::to_wire), [b'x', b'y']);
        assert_eq!(Letters::ALL.map(Letters::index), [0, 1]);
        const { assert!(Letters::Y.index() == 1) };
        let accepted = (0..=255u8).filter(|&v| Letters::from_wire(v).is_some());
        assert!(accepted.eq([b'x', b'y']));
    }

    #[cfg(feature = "serde")]
    #[test]
    fn a_number_is_narrowed_to_the_values_range() {
        use crate::units::{Number, NumberRangeError};
        assert_eq!(Sparse::try_from(Number(9)), Ok(Sparse::Nine));
        let refused = |found| NumberRangeError {
            quantity: "sparse",
            min: 2,
            max: 9,
            found,
        };
        assert_eq!(Sparse::try_from(Number(4)), Err(refused(4)));
        assert_eq!(Sparse::try_from(Number(-1)), Err(refused(-1)));
    }
}
