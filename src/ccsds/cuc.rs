//! The telemetry time field: CCSDS unsegmented time code (CUC, CCSDS 301.0-B-4 §3.2), four
//! octets of coarse time (seconds) and two of fine time (units of 2⁻¹⁶ s), big-endian.
//!
//! The robot has no absolute clock, only each board's millisecond counter since power-on
//! ([`crate::units::Instant`], a `u32` that wraps after 2³² ms ≈ 49.7 days). So the epoch is
//! **the power-on of the node that makes the telemetry** — the server board as PUS gateway
//! (`crate::node::server::gateway`) — mission elapsed time: an agency-defined epoch, level 2. The
//! P-field is implicit (not in the packet, as ECSS-E-ST-70-41C §7.4.3.1 allows when the time
//! format is fixed per mission); were it sent it would be [`P_FIELD`] = `0x2E`: no extension
//! (bit 0 = 0), time code ID `010` (agency-defined epoch), 4 coarse octets (`11`), 2 fine
//! octets (`10`). Decision `ccsds-time` in `spec/decisions.toml` has the other readings.
//!
//! Milliseconds convert **to the nearest** fine unit (resolution 15.26 µs, so the error is at
//! most 7.6 µs), and back to the nearest millisecond; every millisecond count survives the
//! round trip. The coarse field counts seconds modulo 2³² (136 years). The `u32` clock
//! wraps first, after 49.7 days: [`Cuc::from_instant`] then starts again at 0, a jump back the
//! ground sees; a caller that counts the wraps passes the widened count to
//! [`Cuc::from_millis`], which takes a `u64`.
//!
//! ```
//! use mmic::ccsds::cuc::Cuc;
//! use mmic::units::Instant;
//!
//! let t = Cuc::from_instant(Instant::from_millis(90_500)); // 90.5 s after power-on
//! assert_eq!((t.coarse, t.fine), (90, 0x8000));
//! assert_eq!(t.to_bytes(), [0, 0, 0, 90, 0x80, 0x00]);
//! assert_eq!(t.to_millis(), 90_500);
//! ```

use zerocopy::byteorder::big_endian::{U16, U32};
use zerocopy::{FromBytes, Immutable, IntoBytes, KnownLayout, Unaligned};

/// Octets of the time field in every TM packet.
pub const CUC_LEN: usize = 6;

/// The P-field this time code would carry if it were sent (it is not; see the module docs).
// Grouped as the fields: extension | time code ID | coarse octets - 1 | fine octets.
#[expect(
    clippy::unusual_byte_groupings,
    reason = "grouped as the P-field's own fields"
)]
pub const P_FIELD: u8 = 0b0_010_11_10;

/// The CUC T-field, byte for byte.
#[derive(
    Debug, Clone, Copy, PartialEq, Eq, Hash, FromBytes, IntoBytes, KnownLayout, Immutable, Unaligned,
)]
#[repr(C)]
pub struct CucLayout {
    /// Octets 0–3: whole seconds since the epoch.
    pub coarse: U32,
    /// Octets 4–5: fraction of a second in units of 2⁻¹⁶ s.
    pub fine: U16,
}

const _: () = assert!(core::mem::size_of::<CucLayout>() == CUC_LEN);

/// Mission elapsed time since the power-on of the node that stamps the packet.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord, Default)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
#[cfg_attr(feature = "serde", serde(deny_unknown_fields))]
pub struct Cuc {
    /// Whole seconds.
    pub coarse: u32,
    /// Fraction of a second, in units of 2⁻¹⁶ s.
    pub fine: u16,
}

impl Cuc {
    /// The time `ms` milliseconds after the epoch, the fraction rounded to the nearest fine
    /// unit; seconds beyond 2³² − 1 wrap (after 136 years).
    pub const fn from_millis(ms: u64) -> Cuc {
        let frac = ms % 1000;
        // frac < 1000: neither operation comes near saturating.
        let fine = frac.saturating_mul(65536).saturating_add(500) / 1000;
        let [s0, s1, s2, s3, ..] = (ms / 1000).to_le_bytes();
        // At most (999 · 65536 + 500) / 1000 = 65470: never reaches the next second, and its
        // two low octets are all of it.
        let [f0, f1, ..] = fine.to_le_bytes();
        Cuc {
            // The seconds' low 32 bits: they wrap, as documented above.
            coarse: u32::from_le_bytes([s0, s1, s2, s3]),
            fine: u16::from_le_bytes([f0, f1]),
        }
    }

    /// The time of board A's clock reading `t` (restarts at 0 when the `u32` clock wraps).
    pub const fn from_instant(t: crate::units::Instant) -> Cuc {
        let [m0, m1, m2, m3] = t.millis().to_le_bytes();
        // The u32 widened (`u64::from` is not `const`).
        Cuc::from_millis(u64::from_le_bytes([m0, m1, m2, m3, 0, 0, 0, 0]))
    }

    /// Milliseconds since the epoch, the fraction rounded to the nearest millisecond (a fine
    /// value of 65503 or more rounds up into the next second).
    pub const fn to_millis(self) -> u64 {
        let [c0, c1, c2, c3] = self.coarse.to_le_bytes();
        let [f0, f1] = self.fine.to_le_bytes();
        // Both widened (`u64::from` is not `const`); below 2³² · 1000 + 1000 < 2⁴², so no
        // operation comes near saturating.
        let coarse = u64::from_le_bytes([c0, c1, c2, c3, 0, 0, 0, 0]);
        let fine = u64::from_le_bytes([f0, f1, 0, 0, 0, 0, 0, 0]);
        coarse
            .saturating_mul(1000)
            .saturating_add(fine.saturating_mul(1000).saturating_add(32768) >> 16)
    }

    /// The six octets.
    pub fn to_bytes(self) -> [u8; CUC_LEN] {
        let mut out = [0u8; CUC_LEN];
        out.copy_from_slice(CucLayout::from(self).as_bytes());
        out
    }
}

impl From<&CucLayout> for Cuc {
    fn from(l: &CucLayout) -> Cuc {
        Cuc {
            coarse: l.coarse.get(),
            fine: l.fine.get(),
        }
    }
}

impl From<Cuc> for CucLayout {
    fn from(c: Cuc) -> CucLayout {
        CucLayout {
            coarse: U32::new(c.coarse),
            fine: U16::new(c.fine),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_millisecond_of_a_second_survives_the_round_trip() {
        for s in [0u64, 1, 4_294_967] {
            for ms in 0..1000 {
                let t = s * 1000 + ms;
                let c = Cuc::from_millis(t);
                assert_eq!(c.coarse as u64, s);
                assert_eq!(c.to_millis(), t, "{t} ms -> {c:?}");
                // Nearest fine unit: within half a unit (1/131072 s) of the exact fraction.
                let exact = ms as f64 * 65.536;
                assert!((c.fine as f64 - exact).abs() <= 0.5, "{t}: {c:?}");
            }
        }
    }

    #[test]
    fn the_u32_clock_maps_to_whole_seconds_and_the_top_of_the_fine_range_rounds_up() {
        let c = Cuc::from_instant(crate::units::Instant::from_millis(u32::MAX));
        assert_eq!((c.coarse, c.to_millis()), (4_294_967, u32::MAX as u64));
        assert_eq!(
            Cuc {
                coarse: 1,
                fine: 65503
            }
            .to_millis(),
            1999
        );
        assert_eq!(
            Cuc {
                coarse: 1,
                fine: 65504
            }
            .to_millis(),
            2000
        );
        // Seconds wrap modulo 2^32.
        assert_eq!(Cuc::from_millis((1u64 << 32) * 1000 + 5).coarse, 0);
    }

    // req: PUS/tm-time-cuc
    #[test]
    fn p_field_is_agency_epoch_4_coarse_2_fine() {
        assert_eq!(P_FIELD, 0x2e);
        assert_eq!((P_FIELD >> 4) & 0b111, 0b010); // agency-defined epoch
        assert_eq!(((P_FIELD >> 2) & 0b11) + 1, 4); // coarse octets
        assert_eq!(P_FIELD & 0b11, 2); // fine octets
    }
}
