//! Oracles shared by the integration tests, written from the definitions and independent of the
//! library: a bitwise CRC-16/CCITT-FALSE (the library uses the `crc` crate's table) and the
//! framing verdict in the documented check order.
#![allow(dead_code)] // each test file uses part of this module

pub mod prop;

use mmic::wire::{PacketKind, WireError, CHECKSUM_LEN, HEADER_LEN};

/// CRC-16/CCITT-FALSE: poly 0x1021, init 0xFFFF, MSB first, no final xor; one bit at a time.
/// Each bit: shift left, and xor the polynomial in when the bit shifted out was set (the mask
/// `0u16.wrapping_sub(crc >> 15)`). No branch and no inner loop, so that CI's instrumented run
/// counts each octet once, not each bit's branch (issue 40); the proofs crate's oracle is the same.
pub fn crc16_bitwise(bytes: &[u8]) -> u16 {
    macro_rules! bit {
        ($crc:ident) => {
            $crc = ($crc << 1) ^ (0x1021 & 0u16.wrapping_sub($crc >> 15))
        };
    }
    let mut crc: u16 = 0xffff;
    for &b in bytes {
        crc ^= (b as u16) << 8;
        bit!(crc);
        bit!(crc);
        bit!(crc);
        bit!(crc);
        bit!(crc);
        bit!(crc);
        bit!(crc);
        bit!(crc);
    }
    crc
}

/// Writes `kind`'s header and the bitwise CRC of everything before the last two bytes.
pub fn seal(kind: PacketKind, packet: &mut [u8]) {
    assert_eq!(packet.len(), kind.len());
    let n = packet.len();
    packet[..HEADER_LEN].copy_from_slice(&kind.header());
    let crc = crc16_bitwise(&packet[..n - CHECKSUM_LEN]);
    packet[n - CHECKSUM_LEN..].copy_from_slice(&crc.to_le_bytes());
}

/// The error `parse` must return for `bytes` as a `kind` packet if length, header or checksum
/// is wrong (checked in that order); `None` when all three hold.
pub fn framing_error(kind: PacketKind, bytes: &[u8]) -> Option<WireError> {
    if bytes.len() != kind.len() {
        return Some(WireError::Length {
            kind,
            expected: kind.len(),
            found: bytes.len(),
        });
    }
    let found: [u8; HEADER_LEN] = bytes[..HEADER_LEN].try_into().unwrap();
    if found != kind.header() {
        return Some(WireError::Header {
            kind,
            expected: kind.header(),
            found,
        });
    }
    let (body, crc) = bytes.split_at(bytes.len() - CHECKSUM_LEN);
    let carried = u16::from_le_bytes([crc[0], crc[1]]);
    let computed = crc16_bitwise(body);
    (carried != computed).then_some(WireError::Checksum {
        kind,
        carried,
        computed,
    })
}

/// A seeded generator for the simulated links of the tests (xorshift64*): the same seed, the
/// same run. The one copy of it: the CFDP, COP-1 and frame link simulations all draw from it.
pub struct Rng(pub u64);

impl Rng {
    /// The generator for `seed`, scrambled (nearby seeds start far apart) and never zero.
    pub fn seeded(seed: u64) -> Rng {
        Rng(seed.wrapping_mul(0x9e37_79b9_7f4a_7c15) | 1)
    }

    pub fn next(&mut self) -> u64 {
        self.0 ^= self.0 >> 12;
        self.0 ^= self.0 << 25;
        self.0 ^= self.0 >> 27;
        self.0.wrapping_mul(0x2545_f491_4f6c_dd1d)
    }

    /// Uniform in [0, 1), from the 53 high bits of a draw.
    pub fn uniform(&mut self) -> f64 {
        (self.next() >> 11) as f64 / (1u64 << 53) as f64
    }

    /// True with probability `p`.
    pub fn chance(&mut self, p: f64) -> bool {
        self.uniform() < p
    }

    /// As [`Rng::chance`], but a `p` of 0 draws nothing: a fault switched off leaves the
    /// stream, and so every other draw of the run, as it was.
    pub fn maybe(&mut self, p: f64) -> bool {
        p > 0.0 && self.chance(p)
    }

    /// True for `percent` of the draws.
    pub fn below(&mut self, percent: u64) -> bool {
        self.next() % 100 < percent
    }

    /// One of `0..n` (0 when `n` is 0), from the high half of a draw.
    pub fn pick(&mut self, n: u32) -> u32 {
        (self.next() >> 33) as u32 % n.max(1)
    }
}
