//! The modular checksum of CCSDS 727.0-B-5 Annex F.2, checksum type 0 (YAMCS's `MODULAR`): the
//! file read as big-endian 32-bit words aligned on its start (the last one padded with zero
//! octets), summed modulo 2³². File data arrives in pieces at any offset, in any order, more
//! than once; the sum takes each piece where it lies, so a receiver adds what it writes.
//!
//! ```
//! use mmic::cfdp::checksum::Modular;
//!
//! // YAMCS's ChecksumTest: octets 00..0e.
//! let data: Vec<u8> = (0u8..=0x0e).collect();
//! let mut whole = Modular::new();
//! whole.add(0, &data);
//! assert_eq!(whole.value(), 0x181c_2015);
//! // The same octets in two pieces, the second first.
//! let mut pieces = Modular::new();
//! pieces.add(5, &data[5..]);
//! pieces.add(0, &data[..5]);
//! assert_eq!(pieces, whole);
//! ```

/// A running modular checksum.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Default)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Modular {
    sum: u32,
}

impl Modular {
    /// The checksum of no octets: 0.
    pub const fn new() -> Modular {
        Modular { sum: 0 }
    }

    /// Adds `data`, which lies at `offset` in the file.
    pub fn add(&mut self, offset: u64, data: &[u8]) {
        // The octet at file position p is octet p mod 4 of its word: shifted left by 24, 16, 8
        // or 0 bits. The low two bits of the offset are all that matter.
        let [.., last] = offset.to_be_bytes();
        let mut lane = last & 0x03;
        for &b in data {
            let shift = 24u32.saturating_sub(u32::from(lane).saturating_mul(8));
            self.sum = self.sum.wrapping_add(u32::from(b).wrapping_shl(shift));
            lane = lane.wrapping_add(1) & 0x03;
        }
    }

    /// The checksum so far.
    pub const fn value(&self) -> u32 {
        self.sum
    }
}

/// The modular checksum of a whole file.
pub fn modular(file: &[u8]) -> u32 {
    let mut m = Modular::new();
    m.add(0, file);
    m.value()
}
