//! CCSDS File Delivery Protocol (CCSDS 727.0-B-5), the wire layer: the fixed PDU [`header`],
//! the [`checksum`] of a file, and a checked view of a whole PDU ([`Pdu`]): its header, its
//! data field, and the CRC-16 the CRC flag asks for, checked on parse and written on emit.
//!
//! The mission's profile (`spec/ccsds/cfdp.toml`): 2-octet entity IDs, 4-octet transaction
//! sequence numbers, 32-bit file sizes (the large file flag is refused), no segment metadata,
//! PDUs of at most [`MAX_PDU_LEN`] octets. The PDUs' layout is the standard's; what YAMCS
//! 5.12.8 writes differently (version `000`) is read, and each such choice is a decision in
//! `spec/decisions.toml`.
//!
//! ```
//! use mmic::cfdp::header::{Direction, Lengths, Mode, PduHeader, PduType};
//! use mmic::cfdp::{Pdu, PduError};
//!
//! // YAMCS's EOF PDU (PacketParseTest): 12 header octets, 10 of data field, no CRC.
//! let eof = [
//!     0x00, 0x00, 0x0a, 0x13, 0x00, 0x18, 0x00, 0x00, 0x00, 0x01, 0x00, 0x15, // header
//!     0x04, 0x80, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x65, 0xfc, // EOF: code 4, condition 8 …
//! ];
//! let pdu = Pdu::parse(&eof).unwrap();
//! assert_eq!((pdu.header().source, pdu.header().seq, pdu.header().dest), (0x18, 1, 0x15));
//! assert_eq!(pdu.data(), &eof[12..]);
//! // One octet short: refused by name, with the numbers.
//! assert_eq!(Pdu::parse(&eof[..21]), Err(PduError::Length { declared: 10, found: 9 }));
//! ```
// req: D:cfdp-version, D:cfdp-profile

pub mod checksum;
pub mod codes;
pub mod directive;
pub mod entity;
mod error;
mod field;
mod flags;
pub mod header;
pub mod received;
pub mod tlv;

pub use error::PduError;
use header::PduHeader;

/// The longest PDU the mission sends or takes, octets (YAMCS's `maxPduSize`, 512).
pub const MAX_PDU_LEN: usize = 512;

/// Octets of the CRC when the CRC flag is set.
pub const CRC_LEN: usize = 2;

/// The CRC-16 a PDU ends with when its CRC flag is set: CRC-16/CCITT-FALSE over every octet
/// before it, the header included (727.0-B-5 §4.1.2, Annex F.3), as the space packets' error
/// control ([`crate::ccsds::pec`]).
pub fn pdu_crc(bytes: &[u8]) -> u16 {
    crate::ccsds::pec(bytes)
}

/// A whole PDU whose header and length (and CRC, when its flag is set) were checked.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Pdu<'a> {
    header: PduHeader,
    bytes: &'a [u8],
    data: &'a [u8],
}

impl<'a> Pdu<'a> {
    /// Checks `bytes` as exactly one PDU: the header ([`PduHeader::parse`]), then the data
    /// field length against the octets that follow (`length`), then, with the CRC flag, a data
    /// field long enough for the CRC (`truncated`) and the CRC itself (`crc`).
    pub fn parse(bytes: &'a [u8]) -> Result<Pdu<'a>, PduError> {
        let (header, len) = PduHeader::parse(bytes)?;
        let declared = usize::from(header.data_len);
        let found = bytes.len().saturating_sub(len);
        if found != declared {
            return Err(PduError::Length { declared, found });
        }
        Self::parse_prefix(bytes).map(|(pdu, _)| pdu)
    }

    /// The PDU at the start of `bytes` and the octets after it (a stream of PDUs): as
    /// [`Pdu::parse`], but octets after the data field are the next PDU's.
    pub fn parse_prefix(bytes: &'a [u8]) -> Result<(Pdu<'a>, &'a [u8]), PduError> {
        let (header, len) = PduHeader::parse(bytes)?;
        let declared = usize::from(header.data_len);
        let after = bytes.get(len..).unwrap_or(&[]);
        let (field, rest) = after.split_at_checked(declared).ok_or(PduError::Length {
            declared,
            found: after.len(),
        })?;
        let end = len.saturating_add(declared);
        let whole = bytes.get(..end).unwrap_or(&[]);
        let data = if header.crc {
            let (data, crc) = field
                .split_last_chunk::<CRC_LEN>()
                .ok_or(PduError::Truncated {
                    expected: len.saturating_add(CRC_LEN),
                    found: end,
                })?;
            let before = whole.get(..end.saturating_sub(CRC_LEN)).unwrap_or(&[]);
            let (expected, found) = (pdu_crc(before), u16::from_be_bytes(*crc));
            if expected != found {
                return Err(PduError::Crc { expected, found });
            }
            data
        } else {
            field
        };
        Ok((
            Pdu {
                header,
                bytes: whole,
                data,
            },
            rest,
        ))
    }

    /// The header.
    pub const fn header(&self) -> &PduHeader {
        &self.header
    }

    /// The data field, without the CRC.
    pub const fn data(&self) -> &'a [u8] {
        self.data
    }

    /// The whole PDU.
    pub const fn as_bytes(&self) -> &'a [u8] {
        self.bytes
    }
}

/// Writes a PDU of `header` (its `data_len` set here) and `data` into `out`, with its CRC when
/// the header's flag asks: the PDU's length.
pub fn emit(header: &PduHeader, data: &[u8], out: &mut [u8]) -> Result<usize, PduError> {
    let crc = if header.crc { CRC_LEN } else { 0 };
    let field = data.len().saturating_add(crc);
    let data_len = u16::try_from(field).map_err(|_| PduError::TooLarge {
        value: u64::try_from(field).unwrap_or(u64::MAX),
        octets: 2,
    })?;
    let h = PduHeader {
        data_len,
        ..*header
    };
    let len = h.len().saturating_add(field);
    let found = out.len();
    let pdu = out
        .get_mut(..len)
        .ok_or(PduError::Buffer { needed: len, found })?;
    let n = h.emit(pdu)?;
    let (_, rest) = pdu.split_at_mut(n);
    if let Some(body) = rest.get_mut(..data.len()) {
        body.copy_from_slice(data);
    }
    if header.crc {
        let (before, tail) = pdu.split_at_mut(len.saturating_sub(CRC_LEN));
        tail.copy_from_slice(&pdu_crc(before).to_be_bytes());
    }
    Ok(len)
}
