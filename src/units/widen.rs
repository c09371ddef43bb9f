//! Lossless widening of unsigned integers inside `const fn`s, where `From` cannot be called
//! (trait methods are not `const` on stable Rust) and `as` would hide a truncation if a type
//! were ever changed (coding standard, R5).
//!
//! The value goes in as its little-endian octets (`to_le_bytes`, a `const fn` of every integer
//! type) and comes out zero-extended; a type wider than the result does not compile. The
//! optimiser reduces both to a plain zero extension (no instruction on RV32 for a `u32`).
//!
//! ```
//! use mmic::units::widen::{to_u32, to_usize};
//! const N: u32 = to_u32(0xabcd_u16.to_le_bytes());
//! assert_eq!(N, 0xabcd);
//! assert_eq!(to_usize(200_u8.to_le_bytes()), 200);
//! ```

/// The compile-time check that `N` octets fit the result.
struct Fits<const N: usize, const W: usize>;

impl<const N: usize, const W: usize> Fits<N, W> {
    const OK: () = assert!(N <= W, "the integer is wider than the result");
}

/// `octets` (little-endian) zero-extended to `W` octets.
const fn extend<const N: usize, const W: usize>(octets: [u8; N]) -> [u8; W] {
    let () = Fits::<N, W>::OK;
    let mut wide = [0; W];
    // `N <= W` (checked at compile time just above): the split always succeeds.
    if let Some((low, _)) = wide.split_at_mut_checked(N) {
        low.copy_from_slice(&octets);
    }
    wide
}

/// The unsigned integer whose little-endian octets are `octets` (of a `u8` or `u16`), as a
/// `u16`.
pub const fn to_u16<const N: usize>(octets: [u8; N]) -> u16 {
    u16::from_le_bytes(extend(octets))
}

/// The unsigned integer whose little-endian octets are `octets` (of a `u8`, `u16` or `u32`),
/// as a `u32`.
pub const fn to_u32<const N: usize>(octets: [u8; N]) -> u32 {
    u32::from_le_bytes(extend(octets))
}

/// The unsigned integer whose little-endian octets are `octets` (of a `u8` or `u16`, and of a
/// `u32` on the 32- and 64-bit targets), as a `usize`.
pub const fn to_usize<const N: usize>(octets: [u8; N]) -> usize {
    usize::from_le_bytes(extend(octets))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn widening_is_exact_at_the_ends() {
        for v in [0u8, 1, 0x7f, 0x80, u8::MAX] {
            assert_eq!(to_u16(v.to_le_bytes()), u16::from(v));
            assert_eq!(to_u32(v.to_le_bytes()), u32::from(v));
            assert_eq!(to_usize(v.to_le_bytes()), usize::from(v));
        }
        for v in [0u16, 1, 0xff, 0x100, 0x8000, u16::MAX] {
            assert_eq!(to_u16(v.to_le_bytes()), v);
            assert_eq!(to_u32(v.to_le_bytes()), u32::from(v));
            assert_eq!(to_usize(v.to_le_bytes()), usize::from(v));
        }
        for v in [0u32, 0x8000_0000, u32::MAX] {
            assert_eq!(to_u32(v.to_le_bytes()), v);
            assert_eq!(to_usize(v.to_le_bytes()), usize::try_from(v).unwrap());
        }
    }
}
