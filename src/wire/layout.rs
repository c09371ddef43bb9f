//! Field tables: name, byte range, unit and the paper's label for every field of a packet,
//! built from the zerocopy layouts so that the layout struct stays the one place a range is
//! defined. spec/ is checked against these tables, and the review pages are rendered from them.
// req: D:byte-order

use crate::units::Electrical;
use core::ops::Range;
use zerocopy::byteorder::little_endian::U16;
use zerocopy::{FromBytes, Immutable, IntoBytes, KnownLayout, Unaligned};

/// One side's seven ADS7828 readings as they lie in both heartbeats (Table 3 bytes 25–38 and
/// 39–52, Table 4 bytes 12–25): V_bat, I_bat, I_loc, I_grip, I_3v3, V_reg, I_bo.
#[derive(
    Debug, Clone, Copy, PartialEq, Eq, Hash, FromBytes, IntoBytes, KnownLayout, Immutable, Unaligned,
)]
#[repr(C)]
#[expect(missing_docs, reason = "the fields are those of `Electrical`")]
pub struct ElectricalLayout {
    pub v_bat: U16,
    pub i_bat: U16,
    pub i_loc: U16,
    pub i_grip: U16,
    pub i_3v3: U16,
    pub v_reg: U16,
    pub i_bo: U16,
}

impl From<&ElectricalLayout> for Electrical {
    fn from(l: &ElectricalLayout) -> Electrical {
        Electrical {
            v_bat: l.v_bat.get(),
            i_bat: l.i_bat.get(),
            i_loc: l.i_loc.get(),
            i_grip: l.i_grip.get(),
            i_3v3: l.i_3v3.get(),
            v_reg: l.v_reg.get(),
            i_bo: l.i_bo.get(),
        }
    }
}

impl From<&Electrical> for ElectricalLayout {
    fn from(e: &Electrical) -> ElectricalLayout {
        ElectricalLayout {
            v_bat: U16::new(e.v_bat),
            i_bat: U16::new(e.i_bat),
            i_loc: U16::new(e.i_loc),
            i_grip: U16::new(e.i_grip),
            i_3v3: U16::new(e.i_3v3),
            v_reg: U16::new(e.v_reg),
            i_bo: U16::new(e.i_bo),
        }
    }
}

/// `offset..offset + size`: the byte range of a field of `size` octets at `offset`. The sum is
/// at most the layout's size (a field lies inside its struct), so the `None` arm, an empty
/// range, is never taken; the callers are `const` items, evaluated as the crate builds.
pub(crate) const fn span_of(offset: usize, size: usize) -> core::ops::Range<usize> {
    match offset.checked_add(size) {
        Some(end) => offset..end,
        None => offset..offset,
    }
}

/// Byte range of field `$f` (of type `$ft`) in layout `$t`.
macro_rules! span {
    ($t:ty, $($f:ident).+, $ft:ty) => {
        $crate::wire::layout::span_of(core::mem::offset_of!($t, $($f).+), core::mem::size_of::<$ft>())
    };
}
pub(crate) use span;

/// A packet's fields, written once: `pub const FIELDS: &[FieldSpec]` (the table spec/ is
/// checked against) and `pub mod field` (one `Range<usize>` constant per field, for code that
/// indexes the bytes), both from layout `$t` and its entries in byte order, each one of:
/// - `CONST: (name, field, type, unit, paper)`: field `field` (of type `type`) of `$t`, named
///   `name`, its unit `Unit::unit` and the paper's label `paper`, optionally followed by
///   `cells [..]` (the paper's grid cells, when they are not one label);
/// - `[V_BAT, I_BAT, I_LOC, I_GRIP, I_3V3, V_REG, I_BO]: ..electrical(field, "X")`: the seven
///   readings of the [`ElectricalLayout`] `field`, named `field.v_bat` … `field.i_bo` and
///   labelled as the paper does, `V_{batX}` … `I_{boX}` (`X` the side): both heartbeats carry
///   such blocks.
macro_rules! fields {
    (@munch $t:ty; [$($c:item)*] [$($s:expr,)*];) => {
        /// Byte ranges of every field, from the layout (the same ranges as [`FIELDS`], by name).
        pub mod field {
            #[allow(unused_imports, reason = "a packet whose fields need no name of the module above leaves the import unused; the macro cannot tell")]
            use super::*;
            $($c)*
        }

        /// Field table, from the layout (spec/packets/ is checked against it).
        pub const FIELDS: &[$crate::wire::layout::FieldSpec] = &[$($s,)*];
    };
    (
        @munch $t:ty; [$($c:item)*] [$($s:expr,)*];
        $C:ident:
            ($name:expr, $($f:ident).+, $ft:ty, $unit:ident, $paper:expr $(, cells $cells:expr)?)
        $(, $($rest:tt)*)?
    ) => {
        $crate::wire::layout::fields!(@munch $t; [
            $($c)*
            #[doc = concat!("`", $name, "`.")]
            pub const $C: core::ops::Range<usize> =
                $crate::wire::layout::span!($t, $($f).+, $ft);
        ] [
            $($s,)*
            $crate::wire::layout::FieldSpec {
                name: $name,
                range: field::$C,
                unit: $crate::wire::layout::Unit::$unit,
                paper: $paper,
                cells: $crate::wire::layout::fields!(@cells $($cells)?),
            },
        ]; $($($rest)*)?);
    };
    (
        @munch $t:ty; [$($c:item)*] [$($s:expr,)*];
        [$vb:ident, $ib:ident, $il:ident, $ig:ident, $i3:ident, $vr:ident, $io:ident $(,)?]:
            ..electrical($side:ident, $x:literal)
        $(, $($rest:tt)*)?
    ) => {
        $crate::wire::layout::fields!(@munch $t; [$($c)*] [$($s,)*];
            $vb: (concat!(stringify!($side), ".v_bat"), $side.v_bat, U16, Millivolts,
                concat!("V_{bat", $x, "}")),
            $ib: (concat!(stringify!($side), ".i_bat"), $side.i_bat, U16, Milliamps,
                concat!("I_{bat", $x, "}")),
            $il: (concat!(stringify!($side), ".i_loc"), $side.i_loc, U16, Milliamps,
                concat!("I_{loc", $x, "}")),
            $ig: (concat!(stringify!($side), ".i_grip"), $side.i_grip, U16, Milliamps,
                concat!("I_{grip", $x, "}")),
            $i3: (concat!(stringify!($side), ".i_3v3"), $side.i_3v3, U16, Milliamps,
                concat!("I_{3v3", $x, "}")),
            $vr: (concat!(stringify!($side), ".v_reg"), $side.v_reg, U16, Millivolts,
                concat!("V_{reg", $x, "}")),
            $io: (concat!(stringify!($side), ".i_bo"), $side.i_bo, U16, Milliamps,
                concat!("I_{bo", $x, "}"))
            $(, $($rest)*)?
        );
    };
    (@cells) => { &[] };
    (@cells $cells:expr) => { $cells };
    ($t:ty; $($entries:tt)*) => {
        $crate::wire::layout::fields!(@munch $t; [] []; $($entries)*);
    };
}
pub(crate) use fields;

/// Unit or encoding of a field, as spec/ names it.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum Unit {
    /// Fixed ASCII bytes.
    Header,
    /// Robot number 1..=255.
    Board,
    /// Command opcode (see the command table).
    Opcode,
    /// Servo pulse width, µs, 500..=2500.
    Micros,
    /// Hip angle, 0.01°, 0..=35999.
    Centidegrees,
    /// Voltage, mV.
    Millivolts,
    /// Current, mA.
    Milliamps,
    /// 0 or 1.
    Bool,
    /// State letter 'a'..='o', or 0 for none.
    StateLetter,
    /// A small enumeration documented with the field.
    Enum,
    /// Bit map documented with the field.
    Bits,
    /// Wrapping 8-bit sequence number.
    Sequence,
    /// 16-bit sequence number, little-endian (exactly-once commanding).
    Sequence16,
    /// Parameter bytes whose meaning depends on the opcode.
    Parameter,
    /// CRC-16/CCITT-FALSE, little-endian.
    Crc16,
}

impl Unit {
    /// Name as written in spec/.
    pub const fn name(self) -> &'static str {
        match self {
            Unit::Header => "header",
            Unit::Board => "board",
            Unit::Opcode => "opcode",
            Unit::Micros => "us",
            Unit::Centidegrees => "0.01 deg",
            Unit::Millivolts => "mV",
            Unit::Milliamps => "mA",
            Unit::Bool => "bool",
            Unit::StateLetter => "state",
            Unit::Enum => "enum",
            Unit::Bits => "bits",
            Unit::Sequence => "seq",
            Unit::Sequence16 => "seq16",
            Unit::Parameter => "param",
            Unit::Crc16 => "crc16",
        }
    }
}

/// One field of a packet.
#[derive(Debug, Clone, PartialEq, Eq, Hash)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct FieldSpec {
    /// Field name (spec/ and JSON).
    pub name: &'static str,
    /// Byte range in the packet.
    pub range: Range<usize>,
    /// Unit or encoding.
    pub unit: Unit,
    /// The paper's label for these bytes (two-byte fields: without "lowByte"/"highByte").
    pub paper: &'static str,
    /// The paper's grid cells for these bytes when they are not derived from `paper`
    /// (empty: derived, see [`FieldSpec::cell`]).
    pub cells: &'static [&'static str],
}

impl FieldSpec {
    /// The label the paper's grid shows in cell `index` (which must lie in `range`): the
    /// explicit `cells` if given; else "lowByte"/"highByte" + `paper` for two-byte fields;
    /// else `paper` in every cell (the paper's merged cells).
    pub fn cell(&self, index: usize, out: &mut impl core::fmt::Write) -> core::fmt::Result {
        if let Some(c) = index
            .checked_sub(self.range.start)
            .and_then(|i| self.cells.get(i))
        {
            out.write_str(c)
        } else if self.range.len() == 2 {
            let half = if index == self.range.start {
                "lowByte"
            } else {
                "highByte"
            };
            write!(out, "{half} {}", self.paper)
        } else {
            out.write_str(self.paper)
        }
    }
}
