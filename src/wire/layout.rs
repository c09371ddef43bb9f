//! Field tables: name, byte range, unit and the paper's label for every field of a packet,
//! built from the zerocopy layouts so that the layout struct stays the one place a range is
//! defined. spec/ is checked against these tables, and the review pages are rendered from them.

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
#[allow(missing_docs)] // the fields are those of `Electrical`
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

/// Byte range of field `$f` (of type `$ft`) in layout `$t`.
macro_rules! span {
    ($t:ty, $($f:ident).+, $ft:ty) => {
        core::mem::offset_of!($t, $($f).+)..core::mem::offset_of!($t, $($f).+) + core::mem::size_of::<$ft>()
    };
}
pub(crate) use span;

/// A packet's field table, `&[FieldSpec]`, from layout `$t` and its entries in byte order, each
/// one of:
/// - a row `(name, field, type, unit, paper)`: field `field` (of type `type`) of `$t`, named
///   `name`, its unit `Unit::unit` and the paper's label `paper`;
/// - `..electrical(field, "X")`: the seven readings of the [`ElectricalLayout`] `field`, named
///   `field.v_bat` … `field.i_bo` and labelled as the paper does, `V_{batX}` … `I_{boX}` (`X` the
///   side): both heartbeats carry such blocks;
/// - any `FieldSpec` expression (explicit `cells`).
macro_rules! field_table {
    (@munch $t:ty; [$($done:expr,)*];) => {
        &[$($done,)*]
    };
    (
        @munch $t:ty; [$($done:expr,)*];
        ($name:literal, $($field:ident).+, $ft:ty, $unit:ident, $paper:expr) $(, $($rest:tt)*)?
    ) => {
        $crate::wire::layout::field_table!(@munch $t; [
            $($done,)*
            $crate::wire::layout::field_table!(@field $t, $name, $($field).+, $ft, $unit, $paper),
        ]; $($($rest)*)?)
    };
    (
        @munch $t:ty; [$($done:expr,)*];
        ..electrical($side:ident, $x:literal) $(, $($rest:tt)*)?
    ) => {
        $crate::wire::layout::field_table!(@munch $t; [
            $($done,)*
            $crate::wire::layout::field_table!(@reading $t, $side, v_bat, Millivolts, "V_{bat", $x),
            $crate::wire::layout::field_table!(@reading $t, $side, i_bat, Milliamps, "I_{bat", $x),
            $crate::wire::layout::field_table!(@reading $t, $side, i_loc, Milliamps, "I_{loc", $x),
            $crate::wire::layout::field_table!(@reading $t, $side, i_grip, Milliamps, "I_{grip", $x),
            $crate::wire::layout::field_table!(@reading $t, $side, i_3v3, Milliamps, "I_{3v3", $x),
            $crate::wire::layout::field_table!(@reading $t, $side, v_reg, Millivolts, "V_{reg", $x),
            $crate::wire::layout::field_table!(@reading $t, $side, i_bo, Milliamps, "I_{bo", $x),
        ]; $($($rest)*)?)
    };
    (@munch $t:ty; [$($done:expr,)*]; $entry:expr $(, $($rest:tt)*)?) => {
        $crate::wire::layout::field_table!(@munch $t; [$($done,)* $entry,]; $($($rest)*)?)
    };
    (@reading $t:ty, $side:ident, $reading:ident, $unit:ident, $label:literal, $x:literal) => {
        $crate::wire::layout::field_table!(
            @field $t,
            concat!(stringify!($side), ".", stringify!($reading)),
            $side.$reading,
            zerocopy::byteorder::little_endian::U16,
            $unit,
            concat!($label, $x, "}")
        )
    };
    (@field $t:ty, $name:expr, $($field:ident).+, $ft:ty, $unit:ident, $paper:expr) => {
        $crate::wire::layout::FieldSpec {
            name: $name,
            range: $crate::wire::layout::span!($t, $($field).+, $ft),
            unit: $crate::wire::layout::Unit::$unit,
            paper: $paper,
            cells: &[],
        }
    };
    ($t:ty; $($entries:tt)*) => {
        $crate::wire::layout::field_table!(@munch $t; []; $($entries)*)
    };
}
pub(crate) use field_table;

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
    /// Zero on emit; refused unless zero on parse.
    Reserved,
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
            Unit::Reserved => "reserved",
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
