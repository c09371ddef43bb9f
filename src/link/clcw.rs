//! The Communications Link Control Word (CCSDS 232.0-B-4 §4.2, 232.1-B-2 §4.2.1): the 32 bits
//! FARM-1 reports its state in, carried back to the ground in every TM frame's operational
//! control field, big-endian:
//!
//! | bits | field | here |
//! |---|---|---|
//! | 0 | control word type | always 0 (a CLCW) |
//! | 1–2 | CLCW version number | always `00` (version 1) |
//! | 3–5 | status field | [`StatusField`], mission-specific (0 here) |
//! | 6–7 | COP in effect | always `01` (COP-1) |
//! | 8–13 | virtual channel identifier | [`ClcwVcid`], the TC VC reported on |
//! | 14–15 | reserved spare | always `00` |
//! | 16 | No RF Available flag | |
//! | 17 | No Bit Lock flag | |
//! | 18 | Lockout flag | FARM-1 in Lockout (S3) |
//! | 19 | Wait flag | FARM-1 cannot take AD frames |
//! | 20 | Retransmit flag | an AD frame was lost or refused |
//! | 21–22 | FARM-B counter | [`FarmBCounter`], B frames accepted, mod 4 |
//! | 23 | reserved spare | always 0 |
//! | 24–31 | report value | N(R) = V(R), the next AD frame expected |
//!
//! ```
//! use mmic::link::clcw::{Clcw, ClcwVcid, FarmBCounter, StatusField};
//!
//! // VC 0, Retransmit set, FARM-B counter 2, expecting N(S) = 7.
//! let clcw = Clcw {
//!     retransmit: true,
//!     farm_b_counter: FarmBCounter::new(2).unwrap(),
//!     report_value: 7,
//!     ..Clcw::default()
//! };
//! assert_eq!(clcw.emit(), [0x01, 0x00, 0x0c, 0x07]);
//! assert_eq!(Clcw::parse(&[0x01, 0x00, 0x0c, 0x07]), Ok(clcw));
//!
//! // Strict: another COP in effect, or a set spare bit, is refused by name.
//! assert_eq!(Clcw::parse(&[0x02, 0x00, 0x0c, 0x07]).unwrap_err().name(), "cop-in-effect");
//! assert_eq!(Clcw::parse(&[0x01, 0x00, 0x0d, 0x07]).unwrap_err().name(), "reserved-spare");
//! ```
//!
//! The flags are named for what they say when set (the standard's sense), so a CLCW of a
//! ground station that hears the robot has `no_rf_available` and `no_bit_lock` clear.

use crate::units::ranged;

/// Octets of a CLCW.
pub const CLCW_LEN: usize = 4;
/// The control word type of a CLCW (232.0-B-4 §4.2.1.2): 0 (1 would be another report).
pub const CONTROL_WORD_TYPE: u8 = 0;
/// The only CLCW version number 232.0-B-4 defines (§4.2.1.3): `00`, version 1.
pub const CLCW_VERSION: u8 = 0;
/// The COP in effect field of COP-1 (232.0-B-4 §4.2.1.5): `01`.
pub const COP_1: u8 = 0b01;

ranged! {
    /// The CLCW's status field, 3 bits: mission-specific (232.0-B-4 §4.2.1.4); this mission
    /// sends 0 and reads whatever comes.
    #[derive(Default)]
    pub struct StatusField(u8), min 0, max 7, "CLCW status field";
}

impl StatusField {
    /// The status this mission sends.
    pub const ZERO: StatusField = StatusField(0);
}

ranged! {
    /// The virtual channel identifier the CLCW reports on, 6 bits (232.0-B-4 §4.2.1.6): the
    /// TC VC's number (the TC frame header's VCID is 6 bits too).
    #[derive(Default)]
    pub struct ClcwVcid(u8), min 0, max 63, "CLCW virtual channel identifier";
}

impl ClcwVcid {
    /// Virtual channel 0, the mission's one TC VC.
    pub const ZERO: ClcwVcid = ClcwVcid(0);
}

ranged! {
    /// The FARM-B counter, the two low bits of the count of type-B (BD and BC) frames FARM-1
    /// accepted (232.1-B-2 §6.1.5): the ground sees a BD or BC frame arrive when it changes.
    #[derive(Default)]
    pub struct FarmBCounter(u8), min 0, max 3, "FARM-B counter";
}

impl FarmBCounter {
    /// No B frame yet.
    pub const ZERO: FarmBCounter = FarmBCounter(0);

    /// The next count, wrapping from 3 to 0 (the counter is its two low bits).
    pub const fn wrapping_next(self) -> FarmBCounter {
        FarmBCounter(self.0.wrapping_add(1) & 3)
    }
}

/// A CLCW's fields (232.0-B-4 §4.2.1), the fixed ones left out: [`Clcw::emit`] writes them,
/// [`Clcw::parse`] checks them. Every value of every field is a valid CLCW, so
/// `parse(emit(c)) == Ok(c)` for all `c`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Default)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub struct Clcw {
    /// Bits 3–5, mission-specific.
    pub status: StatusField,
    /// Bits 8–13: the TC virtual channel this CLCW reports on.
    pub vcid: ClcwVcid,
    /// Bit 16: the physical layer has no RF (232.0-B-4 §4.2.1.8).
    pub no_rf_available: bool,
    /// Bit 17: the physical layer has no bit lock (232.0-B-4 §4.2.1.9).
    pub no_bit_lock: bool,
    /// Bit 18: FARM-1 is in Lockout (S3) and takes no AD frame until an Unlock.
    pub lockout: bool,
    /// Bit 19: FARM-1 has no room for AD frames (S2, Wait).
    pub wait: bool,
    /// Bit 20: FARM-1 saw a gap or refused an AD frame; the ground should retransmit.
    pub retransmit: bool,
    /// Bits 21–22.
    pub farm_b_counter: FarmBCounter,
    /// Bits 24–31: N(R), FARM-1's V(R), the N(S) of the next AD frame it expects.
    pub report_value: u8,
}

/// Why four octets are not a COP-1 CLCW. The checks run in the order of
/// [`ClcwError::NAMES`] (the variants' order), the first failure is the error: the length,
/// then the fixed fields in bit order (a word of another kind or version is refused for what
/// it is before its COP or spare bits are looked at).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, thiserror::Error)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
#[non_exhaustive]
pub enum ClcwError {
    /// Not four octets.
    #[error("CLCW: {found} octets, must be {expected}")]
    Length {
        /// 4.
        expected: usize,
        /// Octets given.
        found: usize,
    },
    /// Bit 0 set: another kind of report than a CLCW.
    #[error("CLCW: control word type must be {expected}, found {found}")]
    ControlWordType {
        /// 0.
        expected: u8,
        /// Bit 0.
        found: u8,
    },
    /// Bits 1–2 other than `00`.
    #[error("CLCW: version number must be {expected}, found {found}")]
    Version {
        /// 0.
        expected: u8,
        /// Bits 1–2.
        found: u8,
    },
    /// Bits 6–7 other than `01`: the word reports no COP, or one the standard does not define.
    #[error("CLCW: COP in effect must be {expected:#04b} (COP-1), found {found:#04b}")]
    CopInEffect {
        /// `0b01`.
        expected: u8,
        /// Bits 6–7.
        found: u8,
    },
    /// A reserved spare bit (14, 15 or 23) set.
    #[error("CLCW: reserved spare bits must be 0, found {found:#010x} set")]
    ReservedSpare {
        /// The word masked to its spare bits.
        found: u32,
    },
}

impl ClcwError {
    /// Every check's name, in the order [`Clcw::parse`] runs them.
    pub const NAMES: [&'static str; 5] = [
        "length",
        "control-word-type",
        "clcw-version",
        "cop-in-effect",
        "reserved-spare",
    ];

    /// The failed check's name.
    #[cfg_attr(
        not(test),
        expect(
            clippy::indexing_slicing,
            reason = "position() maps each variant to its place in NAMES, one entry per variant"
        )
    )]
    pub const fn name(&self) -> &'static str {
        Self::NAMES[self.position()]
    }

    /// The failed check's place in the check order (0 = first).
    pub const fn position(&self) -> usize {
        match self {
            ClcwError::Length { .. } => 0,
            ClcwError::ControlWordType { .. } => 1,
            ClcwError::Version { .. } => 2,
            ClcwError::CopInEffect { .. } => 3,
            ClcwError::ReservedSpare { .. } => 4,
        }
    }
}

/// Bit positions, as shifts of the 32-bit word (bit 0 of the standard is the most
/// significant): the one place the layout is written down.
mod field {
    pub const TYPE: u32 = 31;
    pub const VERSION: u32 = 29;
    pub const STATUS: u32 = 26;
    pub const COP: u32 = 24;
    pub const VCID: u32 = 18;
    pub const NO_RF: u32 = 15;
    pub const NO_BIT_LOCK: u32 = 14;
    pub const LOCKOUT: u32 = 13;
    pub const WAIT: u32 = 12;
    pub const RETRANSMIT: u32 = 11;
    pub const FARM_B: u32 = 9;
    /// Bits 14–15 and 23 of the standard.
    pub const SPARE_MASK: u32 = (0b11 << 16) | (1 << 8);
}

impl Clcw {
    /// The CLCW in `bytes`, which must be exactly its four octets, checked in the order of
    /// [`ClcwError::NAMES`].
    pub fn parse(bytes: &[u8]) -> Result<Clcw, ClcwError> {
        let word: [u8; CLCW_LEN] = bytes.try_into().map_err(|_| ClcwError::Length {
            expected: CLCW_LEN,
            found: bytes.len(),
        })?;
        Clcw::from_word(u32::from_be_bytes(word))
    }

    /// The CLCW of a 32-bit word (bit 0 of the standard the most significant), checked as
    /// [`Clcw::parse`] does after the length.
    pub fn from_word(w: u32) -> Result<Clcw, ClcwError> {
        use field::*;
        // The field's mask is written out (0b1, 0b11, …): its width is the mask's ones.
        let bits = |shift: u32, mask: u8| super::low::u8_of_u32(w >> shift) & mask;
        let flag = |shift: u32| (w >> shift) & 1 == 1;
        if bits(TYPE, 0b1) != CONTROL_WORD_TYPE {
            return Err(ClcwError::ControlWordType {
                expected: CONTROL_WORD_TYPE,
                found: bits(TYPE, 0b1),
            });
        }
        if bits(VERSION, 0b11) != CLCW_VERSION {
            return Err(ClcwError::Version {
                expected: CLCW_VERSION,
                found: bits(VERSION, 0b11),
            });
        }
        if bits(COP, 0b11) != COP_1 {
            return Err(ClcwError::CopInEffect {
                expected: COP_1,
                found: bits(COP, 0b11),
            });
        }
        if w & SPARE_MASK != 0 {
            return Err(ClcwError::ReservedSpare {
                found: w & SPARE_MASK,
            });
        }
        Ok(Clcw {
            status: StatusField(bits(STATUS, 0b111)),
            vcid: ClcwVcid(bits(VCID, 0x3f)),
            no_rf_available: flag(NO_RF),
            no_bit_lock: flag(NO_BIT_LOCK),
            lockout: flag(LOCKOUT),
            wait: flag(WAIT),
            retransmit: flag(RETRANSMIT),
            farm_b_counter: FarmBCounter(bits(FARM_B, 0b11)),
            report_value: super::low::u8_of_u32(w),
        })
    }

    /// The 32-bit word, the fixed fields written as 232.0-B-4 §4.2.1 says.
    pub fn to_word(&self) -> u32 {
        use field::*;
        let flag = |b: bool, shift: u32| u32::from(b) << shift;
        (u32::from(CONTROL_WORD_TYPE) << TYPE)
            | (u32::from(CLCW_VERSION) << VERSION)
            | (u32::from(self.status.get() & 0b111) << STATUS)
            | (u32::from(COP_1) << COP)
            | (u32::from(self.vcid.get() & 0x3f) << VCID)
            | flag(self.no_rf_available, NO_RF)
            | flag(self.no_bit_lock, NO_BIT_LOCK)
            | flag(self.lockout, LOCKOUT)
            | flag(self.wait, WAIT)
            | flag(self.retransmit, RETRANSMIT)
            | (u32::from(self.farm_b_counter.get() & 0b11) << FARM_B)
            | u32::from(self.report_value)
    }

    /// The four octets, high first.
    pub fn emit(&self) -> [u8; CLCW_LEN] {
        self.to_word().to_be_bytes()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Each field all ones in turn, by hand against the bit table of 232.0-B-4 §4.2.1 (bit 0
    /// the most significant of octet 0): the fixed part alone is `0x01 0x00 0x00 0x00`.
    // req: 232.1-B-2/CLCW-1
    #[test]
    fn every_field_lands_on_its_bits() {
        let z = Clcw::default();
        let cases: [(Clcw, [u8; 4]); 10] = [
            (z, [0x01, 0x00, 0x00, 0x00]),
            (
                Clcw {
                    status: StatusField(7),
                    ..z
                },
                [0x1d, 0x00, 0x00, 0x00],
            ),
            (
                Clcw {
                    vcid: ClcwVcid(63),
                    ..z
                },
                [0x01, 0xfc, 0x00, 0x00],
            ),
            (
                Clcw {
                    no_rf_available: true,
                    ..z
                },
                [0x01, 0x00, 0x80, 0x00],
            ),
            (
                Clcw {
                    no_bit_lock: true,
                    ..z
                },
                [0x01, 0x00, 0x40, 0x00],
            ),
            (Clcw { lockout: true, ..z }, [0x01, 0x00, 0x20, 0x00]),
            (Clcw { wait: true, ..z }, [0x01, 0x00, 0x10, 0x00]),
            (
                Clcw {
                    retransmit: true,
                    ..z
                },
                [0x01, 0x00, 0x08, 0x00],
            ),
            (
                Clcw {
                    farm_b_counter: FarmBCounter(3),
                    ..z
                },
                [0x01, 0x00, 0x06, 0x00],
            ),
            (
                Clcw {
                    report_value: 0xff,
                    ..z
                },
                [0x01, 0x00, 0x00, 0xff],
            ),
        ];
        for (c, bytes) in cases {
            assert_eq!(c.emit(), bytes, "{c:?}");
            assert_eq!(Clcw::parse(&bytes), Ok(c));
        }
    }

    /// Every fixed bit's value (type, version, COP, the three spare bits: 2^8 combinations)
    /// under a few variable parts: refused by the first check in order that fails, accepted
    /// only with all of them right.
    // req: 232.1-B-2/CLCW-2
    #[test]
    fn each_fixed_bit_is_checked_in_order() {
        for fixed in 0u32..256 {
            let t = fixed & 1;
            let v = (fixed >> 1) & 3;
            let cop = (fixed >> 3) & 3;
            let spare = (fixed >> 5) & 7;
            let spare_bits = ((spare & 1) << 17) | (((spare >> 1) & 1) << 16) | ((spare >> 2) << 8);
            for variable in [0u32, 0x1c00_0000 | 0x00fc_0000 | 0xfeff, 0x0410_2a5a] {
                let w = (t << 31) | (v << 29) | (cop << 24) | spare_bits | variable;
                let expected = if t != 0 {
                    Some("control-word-type")
                } else if v != 0 {
                    Some("clcw-version")
                } else if cop != 1 {
                    Some("cop-in-effect")
                } else if spare != 0 {
                    Some("reserved-spare")
                } else {
                    None
                };
                let got = Clcw::parse(&w.to_be_bytes());
                assert_eq!(got.err().map(|e| e.name()), expected, "{w:#010x}");
                if let Ok(c) = got {
                    assert_eq!(c.to_word(), w);
                }
            }
        }
        assert_eq!(
            Clcw::parse(&[1, 0, 0]),
            Err(ClcwError::Length {
                expected: 4,
                found: 3
            })
        );
        assert_eq!(Clcw::parse(&[1, 0, 0, 0, 0]).unwrap_err().name(), "length");
    }

    /// Exhaustive: all 2^24 valid words (every value of every variable field: status, VCID,
    /// five flags, FARM-B counter, report value) parse and emit back to themselves.
    #[test]
    #[cfg_attr(
        miri,
        ignore = "2^24 words: hours under Miri (each_fixed_bit_is_checked_in_order runs)"
    )]
    fn every_valid_word_round_trips() {
        let mut n = 0u32;
        for variable in 0u32..1 << 24 {
            // Spread the 24 variable bits over the word's variable positions.
            let w = 0x0100_0000
                | ((variable >> 21) << 26) // status, 3 bits
                | (((variable >> 15) & 0x3f) << 18) // VCID, 6 bits
                | (((variable >> 8) & 0x7f) << 9) // five flags, FARM-B counter
                | (variable & 0xff); // report value
            let c = Clcw::from_word(w).unwrap();
            assert_eq!(c.to_word(), w);
            assert_eq!(Clcw::parse(&c.emit()), Ok(c));
            n += 1;
        }
        assert_eq!(n, 1 << 24);
    }
}
