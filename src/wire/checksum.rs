//! The 16-bit checksum every packet ends with: CRC-16/CCITT-FALSE (`crc::CRC_16_IBM_3740`,
//! poly 0x1021, init 0xFFFF, no reflection, no final xor), the CCSDS packet error control.
//!
//! It catches every 1-, 2- and 3-bit error in packets this short (the Hamming distance of this
//! polynomial is 4 up to 32751 data bits), which `tests/wire/corruption.rs` checks exhaustively.
//!
//! **Table size.** By default the `crc` crate's slice-by-16 tables (16 × 256 × 2 = 8 KiB of
//! flash), because they make the 47- and 66-byte heartbeats several times faster to check than
//! the single 256-entry table (512 B): see `benches/README.md` for the numbers. 8 KiB is 0.2 %
//! of an ESP32-C3's 4 MiB flash and costs no RAM (the tables are `const` data). A build that is
//! short of flash enables the feature `small-crc-table` and gets the 512-byte table; the
//! bitwise variant (no table) is about 7× slower again and is not offered.
//!
//! **The loop.** The `crc` crate builds the tables (at compile time); the library runs its own
//! loop over them, because the crate's handles the octets after the last whole 16-octet block
//! one at a time, each lookup waiting on the previous one, and that serial remainder was most
//! of the time of a 16-octet telecommand's or a 66-octet heartbeat's parse (issue 25,
//! `benches/README.md`). The CRC is linear, so the register after `n` octets is the xor of one
//! lookup per octet in table `n - 1 - i` (the register xored into the first two octets): the
//! remainder takes one step, as a whole block does.
//!
//! Every packet's header is fixed, so the CRC register after the four header bytes is a
//! constant: [`packet_crc`] starts from it and only processes the bytes after the header.
//!
//! ```
//! use mmic::wire::checksum::{crc16, packet_crc};
//! use mmic::wire::PacketKind;
//! // The CRC-16/CCITT-FALSE check value.
//! assert_eq!(crc16(b"123456789"), 0x29b1);
//! let mut body = *b"MICM\x01\x02\x00\x00\x00\x00\x00\x00";
//! assert_eq!(packet_crc(PacketKind::Command, &body), crc16(&body));
//! ```
// req: D:checksum, D:crc-table

use super::{PacketKind, HEADER_LEN};

#[cfg(not(feature = "small-crc-table"))]
const LANES: usize = 16;
#[cfg(feature = "small-crc-table")]
const LANES: usize = 1;
type Tables = crc::Table<LANES>;

/// The CRC engine. The library's loop runs its tables (`CRC.table()`: `table[k][b]` is the
/// register after octet `b` and `k` zero octets, from a zero register); they stay inside the
/// engine, so that an identical engine of another crate (spacepackets has the 256-entry one)
/// shares them in a linked image.
pub const CRC: crc::Crc<u16, Tables> = crc::Crc::<u16, Tables>::new(&crc::CRC_16_IBM_3740);

/// Flash taken by the CRC tables, in bytes.
pub const TABLE_BYTES: usize = core::mem::size_of::<<Tables as crc::Implementation>::Data<u16>>();

/// CRC-16/CCITT-FALSE of `bytes`.
#[inline]
pub fn crc16(bytes: &[u8]) -> u16 {
    update(crc::CRC_16_IBM_3740.init, bytes)
}

/// The register after `bytes`, from register `crc` (the algorithm has no reflection and no
/// final xor, so the register is the CRC so far): 16 octets at a time as the `crc` crate
/// does, then the remaining 0–15 octets in one step too (module docs, "The loop"). Never
/// inlined: one copy serves every packet (inlined, each caller had its own, 460 octets more
/// flash per copy on the ESP32-C3, and no faster on the host), but for the two whose body
/// after the header is shorter than a block ([`checked_packet_crc`]).
#[cfg(not(feature = "small-crc-table"))]
#[inline(never)]
fn update(mut crc: u16, bytes: &[u8]) -> u16 {
    let t = CRC.table();
    let (blocks, tail) = bytes.as_chunks::<16>();
    for block in blocks {
        // The fourteen lookups that do not depend on the register first, so that they run
        // ahead; the register's two last, the only ones on the path from block to block.
        let mut r = 0;
        for (lane, &x) in t.iter().zip(block.iter().rev().take(14)) {
            r ^= at(lane, x);
        }
        let [hi, lo] = crc.to_be_bytes();
        let (x0, x1) = (block[0] ^ hi, block[1] ^ lo);
        crc = r ^ at(&t[14], x1) ^ at(&t[15], x0);
    }
    remainder(crc, tail)
}

/// Entry `x` of a table: every octet indexes one of its 256 entries, so the fallback never
/// shows and the compiler drops the check.
#[inline(always)]
fn at(table: &[u16; 256], x: u8) -> u16 {
    table.get(usize::from(x)).copied().unwrap_or(0)
}

/// Table `k` of the sixteen, `k` taken modulo 16 (the callers' `k` are below 16, and the
/// modulo lets the compiler drop the check).
#[cfg(not(feature = "small-crc-table"))]
#[inline(always)]
fn lane(t: &[[u16; 256]; LANES], k: usize) -> &[u16; 256] {
    t.get(k & 15).unwrap_or(&t[0])
}

/// The register after the 0–15 octets `tail`, from register `crc`, in one step (module docs,
/// "The loop"). Always inlined: in [`update`], and in [`checked_packet_crc`] for the packets
/// shorter than a block after the header, where the length is a constant.
#[cfg(not(feature = "small-crc-table"))]
#[inline(always)]
fn remainder(crc: u16, tail: &[u8]) -> u16 {
    let t = CRC.table();
    let n = tail.len();
    let [hi, lo] = crc.to_be_bytes();
    let mut r = match tail {
        [] => return crc,
        [x] => return (crc << 8) ^ at(&t[0], x ^ hi),
        // The tables are linear in their index, so the register's share is two lookups of
        // its own, and the octets' shares do not wait for it. Two octets or more: neither
        // subtraction saturates.
        _ => at(lane(t, n.saturating_sub(1)), hi) ^ at(lane(t, n.saturating_sub(2)), lo),
    };
    // The octets in pieces of 8, 4, 2 and 1, each piece unrolled; `k` octets are left, so
    // the next octet's table is `k - 1`. A piece was split off `k` octets, so no subtraction
    // saturates.
    let mut rest = tail;
    let mut k = n;
    if let Some((p, more)) = rest.split_first_chunk::<8>() {
        k = k.saturating_sub(8);
        r ^= piece(t.get(k..).unwrap_or_default(), p);
        rest = more;
    }
    if let Some((p, more)) = rest.split_first_chunk::<4>() {
        k = k.saturating_sub(4);
        r ^= piece(t.get(k..).unwrap_or_default(), p);
        rest = more;
    }
    if let Some((p, more)) = rest.split_first_chunk::<2>() {
        k = k.saturating_sub(2);
        r ^= piece(t.get(k..).unwrap_or_default(), p);
        rest = more;
    }
    if let [x] = rest {
        r ^= at(&t[0], *x);
    }
    r
}

/// The share of the `N` octets `p` in the register, when `lanes` starts at the table of
/// `p`'s last octet (the number of octets after it).
#[cfg(not(feature = "small-crc-table"))]
#[inline(always)]
fn piece<const N: usize>(lanes: &[[u16; 256]], p: &[u8; N]) -> u16 {
    let Some(lanes) = lanes.first_chunk::<N>() else {
        return 0; // never: a piece and the octets after it are fewer than 16
    };
    let mut r = 0;
    for (lane, &x) in lanes.iter().rev().zip(p) {
        r ^= at(lane, x);
    }
    r
}

/// The register after `bytes`, from register `crc`: one octet at a time (`small-crc-table`).
#[cfg(feature = "small-crc-table")]
#[inline]
fn update(mut crc: u16, bytes: &[u8]) -> u16 {
    let t = &CRC.table()[0];
    for &x in bytes {
        let [hi, _] = crc.to_be_bytes();
        crc = (crc << 8) ^ at(t, x ^ hi);
    }
    crc
}

const HEADER_CRC: [u16; 4] = [
    CRC.checksum(&PacketKind::ALL[0].header()),
    CRC.checksum(&PacketKind::ALL[1].header()),
    CRC.checksum(&PacketKind::ALL[2].header()),
    CRC.checksum(&PacketKind::ALL[3].header()),
];

/// The register after `kind`'s header.
#[inline]
const fn header_crc(kind: PacketKind) -> u16 {
    match kind {
        PacketKind::Command => HEADER_CRC[0],
        PacketKind::Heartbeat => HEADER_CRC[1],
        PacketKind::InternalHeartbeat => HEADER_CRC[2],
        PacketKind::BCommand => HEADER_CRC[3],
    }
}

/// CRC-16/CCITT-FALSE of a packet body (`body` = every byte before the checksum) whose first
/// four bytes are `kind`'s header, which the caller has already checked. Equal to
/// `crc16(body)`, with the header's share precomputed (unless the body is whole 16-octet
/// blocks, the 66-octet heartbeat's).
#[inline]
pub fn packet_crc(kind: PacketKind, body: &[u8]) -> u16 {
    // A body of whole 16-octet blocks (the heartbeat's 64) is faster from the start than as
    // three blocks and a 12-octet remainder after the header.
    #[cfg(not(feature = "small-crc-table"))]
    if body.len().is_multiple_of(16) {
        return crc16(body);
    }
    // The algorithm has no reflection and no final xor, so the register after the header is
    // the header's CRC and the computation can resume from it.
    update(header_crc(kind), body.get(HEADER_LEN..).unwrap_or(&[]))
}

/// [`packet_crc`] for a caller that has checked `body`'s length against `kind` (the packets'
/// [`check`](super::check)), so that once inlined the length is a constant. A body of fewer
/// than 16 octets after the header, the command's 8 and the B command's 9, then takes the
/// remainder step in line, unrolled for its length: no call, no tests of the length, and the
/// header's share a constant. The call was a quarter of the instructions of the command's
/// parse on x86-64 (callgrind; issue 40, `benches/README.md`). Longer bodies go through the one copy of [`update`].
#[inline(always)]
pub(crate) fn checked_packet_crc(kind: PacketKind, body: &[u8]) -> u16 {
    #[cfg(not(feature = "small-crc-table"))]
    if let Some(rest) = body.get(HEADER_LEN..)
        && rest.len() < 16
    {
        return remainder(header_crc(kind), rest);
    }
    packet_crc(kind, body)
}

#[cfg(test)]
mod tests {
    use super::*;

    // req: D:checksum
    #[test]
    fn every_length_and_start_equals_the_crc_crate() {
        // Every length 0..=80 (so every remainder after whole 16-octet blocks), from the
        // algorithm's start and from other registers, against the `crc` crate's own loop.
        // Under Miri one pattern, two registers and the lengths 0..=34 (every tail after none,
        // one and two 16-octet blocks: the tables' indexing and the block loop's tails, what
        // Miri checks, depend on the length only; 0..=80 took 12 s there).
        let patterns: &[u8] = if cfg!(miri) {
            &[0x5a]
        } else {
            &[0, 0x5a, 0xff]
        };
        let starts: &[u16] = if cfg!(miri) {
            &[0x1d0f, 0xffff]
        } else {
            &[0, 1, 0x8000, 0x1d0f, 0xffff, 0xa5c3]
        };
        for &pattern in patterns {
            let mut bytes = [0u8; 80];
            for (i, b) in bytes.iter_mut().enumerate() {
                *b = (i as u8).wrapping_mul(151).wrapping_mul(pattern & 1) ^ pattern;
            }
            let longest = if cfg!(miri) { 34 } else { bytes.len() };
            for len in 0..=longest {
                let b = &bytes[..len];
                assert_eq!(crc16(b), CRC.checksum(b), "{len}");
                for &start in starts {
                    let mut d = CRC.digest_with_initial(start);
                    d.update(b);
                    assert_eq!(update(start, b), d.finalize(), "{len} from {start:#06x}");
                }
            }
        }
        assert_eq!(crc16(b"123456789"), 0x29b1);
    }

    // req: D:checksum
    #[test]
    fn resuming_after_the_header_equals_the_full_crc() {
        for kind in PacketKind::ALL {
            assert_eq!(PacketKind::ALL[kind as usize], kind);
            let mut body = [0u8; 64];
            body[..4].copy_from_slice(&kind.header());
            // Under Miri every length 4..=20 (each tail after a 16-octet block) and 64.
            for len in (4..=64).filter(|l| !cfg!(miri) || *l <= 20 || *l == 64) {
                for (i, b) in body.iter_mut().enumerate().take(len).skip(4) {
                    *b = (i as u8).wrapping_mul(37) ^ len as u8;
                }
                assert_eq!(
                    packet_crc(kind, &body[..len]),
                    crc16(&body[..len]),
                    "{kind} {len}"
                );
                assert_eq!(
                    checked_packet_crc(kind, &body[..len]),
                    crc16(&body[..len]),
                    "{kind} {len}"
                );
            }
        }
    }
}
