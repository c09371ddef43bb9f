//! CCSDS space packets with PUS-C secondary headers: the wire layer of the standard protocol
//! stack, beside the paper's own packets ([`crate::wire`]), big-endian as the standards are.
//!
//! One module per concept: the space packet [`primary`] header (CCSDS 133.0-B-2), the
//! telecommand and telemetry secondary headers ([`tc_header`], [`tm_header`]; ECSS-E-ST-70-41C),
//! the telemetry time field ([`cuc`]; CCSDS 301.0-B-4), and whole packets ([`tc`], [`tm`]):
//! a checked view over the bytes and a `Repr` with `parse`/`emit`. The packet error control
//! is the CRC-16/CCITT-FALSE the legacy packets end with ([`crate::wire::checksum`]), over the
//! whole packet, sent high octet first.
//!
//! ```
//! use mmic::ccsds::{primary::{Apid, SeqCount}, tc::TcRepr, tc_header::{AckFlags, TcSecondaryHeader}, PacketError};
//!
//! // TC(17,1) are-you-alive to APID 0x42, sequence count 7, every report asked for.
//! let ping = TcRepr {
//!     apid: Apid::new(0x42).unwrap(),
//!     seq_count: SeqCount::new(7).unwrap(),
//!     header: TcSecondaryHeader { ack: AckFlags::ALL, service: 17, subservice: 1, source_id: 0 },
//!     app_data: &[],
//! };
//! let mut buf = [0u8; 13];
//! assert_eq!(ping.emit(&mut buf), Ok(13));
//! assert_eq!(buf, [0x18, 0x42, 0xc0, 0x07, 0x00, 0x06, 0x2f, 0x11, 0x01, 0x00, 0x00, 0x12, 0xd0]);
//! assert_eq!(TcRepr::parse(&buf, &[0x42]), Ok(ping));
//!
//! // Strict: a packet for another APID, or any flipped bit, is refused by name.
//! assert!(matches!(TcRepr::parse(&buf, &[0x43]), Err(PacketError::Apid { found: 0x42, .. })));
//! buf[8] ^= 0x01;
//! assert_eq!(TcRepr::parse(&buf, &[0x42]).unwrap_err().name(), "checksum");
//! ```
//!
//! Every check, its order and its error are listed on [`PacketError`]; exactly one error
//! comes out for a given input. The checks end at the secondary header: whether a service and
//! subservice exist and what their data must hold is the services layer's, which reports
//! through [`crate::pus::PusError`], which wraps [`PacketError`] (the services stand above
//! the packets, so the error that joins both is theirs). `spec/ccsds/bad-inputs.toml` holds one refused packet per check, which
//! `tests/ccsds/bad_inputs.rs` walks through the parsers.
// req: D:ccsds-own-layer, D:ccsds-time, D:ccsds-check-order, D:ccsds-ack-flags

mod bit_field;
pub mod cuc;
mod error;
mod packet;
pub mod primary;
pub mod tc;
pub mod tc_header;
pub mod tm;
pub mod tm_header;

pub use error::{EmitError, PacketError};
pub use packet::MAX_PACKET_LEN;

/// The PUS version number of PUS-C (ECSS-E-ST-70-41C), in both secondary headers.
pub const PUS_VERSION: u8 = 2;

/// Octets of the packet error control.
pub const PEC_LEN: usize = 2;

/// The packet error control of `bytes` (every octet of the packet before it):
/// CRC-16/CCITT-FALSE, as ECSS-E-ST-70-41C §B.1 defines it and as the legacy packets use it.
///
/// ```
/// assert_eq!(mmic::ccsds::pec(b"123456789"), 0x29b1);
/// ```
#[inline]
pub fn pec(bytes: &[u8]) -> u16 {
    crate::wire::checksum::crc16(bytes)
}
