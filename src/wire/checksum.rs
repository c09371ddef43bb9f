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

use super::{PacketKind, HEADER_LEN};

#[cfg(not(feature = "small-crc-table"))]
type Tables = crc::Table<16>;
#[cfg(feature = "small-crc-table")]
type Tables = crc::Table<1>;

/// The CRC engine.
pub const CRC: crc::Crc<u16, Tables> = crc::Crc::<u16, Tables>::new(&crc::CRC_16_IBM_3740);

/// Flash taken by the CRC tables, in bytes.
pub const TABLE_BYTES: usize = core::mem::size_of::<<Tables as crc::Implementation>::Data<u16>>();

/// CRC-16/CCITT-FALSE of `bytes`.
pub fn crc16(bytes: &[u8]) -> u16 {
    CRC.checksum(bytes)
}

const HEADER_CRC: [u16; 4] = [
    CRC.checksum(&PacketKind::ALL[0].header()),
    CRC.checksum(&PacketKind::ALL[1].header()),
    CRC.checksum(&PacketKind::ALL[2].header()),
    CRC.checksum(&PacketKind::ALL[3].header()),
];

/// CRC-16/CCITT-FALSE of a packet body (`body` = every byte before the checksum) whose first
/// four bytes are `kind`'s header, which the caller has already checked. Equal to
/// `crc16(body)`, with the header's share precomputed.
pub fn packet_crc(kind: PacketKind, body: &[u8]) -> u16 {
    // The algorithm has no reflection and no final xor, so the register after the header is
    // the header's CRC and the computation can resume from it.
    let start = match kind {
        PacketKind::Command => HEADER_CRC[0],
        PacketKind::Heartbeat => HEADER_CRC[1],
        PacketKind::InternalHeartbeat => HEADER_CRC[2],
        PacketKind::BCommand => HEADER_CRC[3],
    };
    let mut d = CRC.digest_with_initial(start);
    d.update(body.get(HEADER_LEN..).unwrap_or(&[]));
    d.finalize()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn resuming_after_the_header_equals_the_full_crc() {
        for kind in PacketKind::ALL {
            assert_eq!(PacketKind::ALL[kind as usize], kind);
            let mut body = [0u8; 64];
            body[..4].copy_from_slice(&kind.header());
            for len in 4..=64 {
                for (i, b) in body.iter_mut().enumerate().take(len).skip(4) {
                    *b = (i as u8).wrapping_mul(37) ^ len as u8;
                }
                assert_eq!(
                    packet_crc(kind, &body[..len]),
                    crc16(&body[..len]),
                    "{kind} {len}"
                );
            }
        }
    }
}
