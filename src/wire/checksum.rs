//! The 16-bit checksum every packet ends with: CRC-16/CCITT-FALSE (`crc::CRC_16_IBM_3740`,
//! poly 0x1021, init 0xFFFF, no reflection, no final xor), the CCSDS packet error control.
//!
//! It catches every 1-, 2- and 3-bit error in packets this short (the Hamming distance of this
//! polynomial is 4 up to 32751 data bits), which `tests` in the repository check exhaustively.
//!
//! Table size: a 256-entry table (512 bytes of flash, one lookup per byte). The ESP32-C3 has
//! 4 MiB of flash, so 512 bytes costs nothing, while the bit-by-bit variant is several times
//! slower and the 16-table slice-by-16 variant spends 8 KiB to gain little on 12–64 byte
//! packets. The benchmark in `benches/wire.rs` measures the choice.
//!
//! ```
//! // The CRC-16/CCITT-FALSE check value.
//! assert_eq!(mmic::wire::checksum::crc16(b"123456789"), 0x29b1);
//! ```

/// The CRC engine, table-driven with one 256-entry table.
pub const CRC: crc::Crc<u16, crc::Table<1>> =
    crc::Crc::<u16, crc::Table<1>>::new(&crc::CRC_16_IBM_3740);

/// CRC-16/CCITT-FALSE of `bytes`.
pub fn crc16(bytes: &[u8]) -> u16 {
    CRC.checksum(bytes)
}
