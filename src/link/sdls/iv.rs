//! The initialization vector, which is also the anti-replay sequence number: a 96-bit counter
//! carried big-endian in the security header (YAMCS's `IvSeqNum`; 355.0-B-2 §4.1.1.4 lets the
//! IV and the sequence number be one field).
//!
//! ```
//! use mmic::link::sdls::Iv;
//!
//! let iv = Iv::new(0x0102).unwrap();
//! assert_eq!(iv.to_bytes(), [0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0x01, 0x02]);
//! assert_eq!(Iv::from_bytes(iv.to_bytes()), iv);
//! // The receiver measures how far a counter is ahead of the last one, modulo 2^96:
//! assert_eq!(Iv::new(3).unwrap().ahead_of(Iv::MAX), 4);
//! ```

/// Octets of the IV in the security header.
pub const IV_LEN: usize = 12;

/// 2^96: the number of distinct IVs.
pub const IV_SPACE: u128 = 1 << 96;

/// A 96-bit counter value (below 2^96).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord, Default)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Iv(u128);

impl Iv {
    /// The first IV a sender uses (YAMCS's first frame carries 0).
    pub const ZERO: Iv = Iv(0);
    /// The last IV, 2^96 − 1. A receiver that has accepted nothing yet takes it as its "last",
    /// so that 0 is one ahead.
    pub const MAX: Iv = Iv(IV_SPACE - 1);

    /// `v` as an IV, `None` at or above 2^96.
    pub const fn new(v: u128) -> Option<Iv> {
        if v < IV_SPACE {
            Some(Iv(v))
        } else {
            None
        }
    }

    /// `v` modulo 2^96.
    pub const fn wrapping(v: u128) -> Iv {
        Iv(v & (IV_SPACE - 1))
    }

    /// The counter's value.
    pub const fn get(self) -> u128 {
        self.0
    }

    /// Big-endian, as it goes into the security header.
    pub const fn to_bytes(self) -> [u8; IV_LEN] {
        // The low IV_LEN octets of the 16 (IV_LEN <= 16: the `None` arm is never taken).
        match self.0.to_be_bytes().split_last_chunk::<IV_LEN>() {
            Some((_, low)) => *low,
            None => [0; IV_LEN],
        }
    }

    /// Read from the security header.
    pub const fn from_bytes(bytes: [u8; IV_LEN]) -> Iv {
        let mut b = [0u8; 16];
        // The low IV_LEN octets of the 16 (IV_LEN <= 16: always `Some`).
        if let Some((_, low)) = b.split_last_chunk_mut::<IV_LEN>() {
            *low = bytes;
        }
        Iv(u128::from_be_bytes(b))
    }

    /// How far `self` is ahead of `last`, modulo 2^96: 1 for the next counter, 0 for the same,
    /// 2^96 − 1 for the one before.
    pub const fn ahead_of(self, last: Iv) -> u128 {
        self.0.wrapping_sub(last.0) & (IV_SPACE - 1)
    }

    /// `self + n` modulo 2^96.
    pub const fn wrapping_add(self, n: u128) -> Iv {
        Iv::wrapping(self.0.wrapping_add(n))
    }
}
