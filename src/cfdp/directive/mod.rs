//! Every PDU the mission's CFDP uses, read from and written to a checked [`Pdu`]: the file
//! data PDU and the file directives Metadata, EOF, Finished, ACK, NAK, Prompt and Keep Alive
//! (727.0-B-5 §5.2–5.3), each a `Repr` of borrowed fields in the manner of smoltcp's `wire`.
//! Each directive travels one way only (the ACK's way is that of the directive it
//! acknowledges): a PDU whose direction bit says otherwise is refused (`direction`), as are
//! octets after a directive of fixed length (`trailing`) and reserved codes.
//!
//! ```
//! use mmic::cfdp::codes::ConditionCode;
//! use mmic::cfdp::directive::{EofRepr, PduRepr};
//! use mmic::cfdp::header::{Direction, Lengths, Mode, PduHeader, PduType};
//! use mmic::cfdp::{Pdu, PduError};
//!
//! // YAMCS's EOF (PacketParseTest): inactivity detected, no fault location.
//! let bytes = [
//!     0x00, 0x00, 0x0a, 0x13, 0x00, 0x18, 0x00, 0x00, 0x00, 0x01, 0x00, 0x15,
//!     0x04, 0x80, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x65, 0xfc,
//! ];
//! let pdu = Pdu::parse(&bytes).unwrap();
//! let eof = EofRepr {
//!     condition: ConditionCode::InactivityDetected,
//!     checksum: 0,
//!     file_size: 0x65fc,
//!     fault_location: None,
//! };
//! assert_eq!(PduRepr::parse(&pdu), Ok(PduRepr::Eof(eof)));
//! // Written back: the same octets, but for the version (001 here).
//! let mut out = [0u8; 32];
//! let n = PduRepr::Eof(eof).emit(pdu.header(), &mut out).unwrap();
//! assert_eq!((&out[1..n], out[0]), (&bytes[1..], 0x20));
//! // The same EOF said to travel toward the sender: refused.
//! let mut back = bytes;
//! back[0] |= 0x08;
//! let pdu = Pdu::parse(&back).unwrap();
//! assert!(matches!(PduRepr::parse(&pdu), Err(PduError::Direction { .. })));
//! ```
// req: D:cfdp-fault-location, D:cfdp-ack-subtype, D:cfdp-direction

mod ack;
mod eof;
mod finished;
mod metadata;
mod nak;

pub use ack::AckRepr;
pub use eof::EofRepr;
pub use finished::FinishedRepr;
pub use metadata::MetadataRepr;
pub use nak::{NakRepr, Segments, SEGMENT_LEN};

use super::codes::{ConditionCode, DirectiveCode};
use super::error::PduError;
use super::field::{Reader, Writer};
use super::header::{Direction, PduHeader, PduType};
use super::{Pdu, CRC_LEN};

/// What a Prompt PDU asks for (its one bit, 727.0-B-5 §5.2.7).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum PromptFor {
    /// A NAK now (bit 0).
    Nak,
    /// A Keep Alive now (bit 1).
    KeepAlive,
}

/// A file data PDU's fields (727.0-B-5 §5.3, without segment metadata).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub struct FileDataRepr<'a> {
    /// Where the octets go in the file.
    pub offset: u32,
    /// The octets.
    pub data: &'a [u8],
}

/// Any PDU of the profile, its fields decoded.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum PduRepr<'a> {
    /// A transaction's Metadata.
    Metadata(MetadataRepr<'a>),
    /// File data.
    FileData(FileDataRepr<'a>),
    /// End of file.
    Eof(EofRepr),
    /// The receiver's end.
    Finished(FinishedRepr<'a>),
    /// An acknowledgement of EOF or Finished.
    Ack(AckRepr),
    /// A request for what is missing.
    Nak(NakRepr<'a>),
    /// A request for a NAK or a Keep Alive.
    Prompt(PromptFor),
    /// The receiver's progress: the offset up to which it has every octet.
    KeepAlive {
        /// Octets received without a gap from the start.
        progress: u32,
    },
}

impl<'a> PduRepr<'a> {
    /// Decodes a checked PDU's data field. Checks, in order: for file data the direction bit
    /// (`direction`), then an offset (`truncated`); for a directive a directive code
    /// (`truncated` when the field is empty) that 727.0-B-5 defines (`directive`), the
    /// direction bit (`direction`; an ACK's after its fields, which say its way), then the
    /// directive's own fields; last, no octet after a directive of fixed length (`trailing`).
    pub fn parse(pdu: &Pdu<'a>) -> Result<PduRepr<'a>, PduError> {
        let mut r = Reader::new(pdu.data());
        let repr = if pdu.header().pdu_type == PduType::FileData {
            check_direction(Direction::TowardReceiver, pdu.header().direction)?;
            let offset = r.u32()?;
            PduRepr::FileData(FileDataRepr {
                offset,
                data: r.rest(),
            })
        } else {
            let code = r.u8()?;
            let directive =
                DirectiveCode::from_code(code).ok_or(PduError::Directive { found: code })?;
            Self::read_directive(directive, pdu.header(), &mut r)?
        };
        r.end()?;
        Ok(repr)
    }

    /// The directive's fields, its direction checked first.
    fn read_directive(
        directive: DirectiveCode,
        header: &PduHeader,
        r: &mut Reader<'a>,
    ) -> Result<PduRepr<'a>, PduError> {
        let fixed = match directive {
            DirectiveCode::Ack => None,
            d => Some(direction_of(d)),
        };
        if let Some(expected) = fixed {
            check_direction(expected, header.direction)?;
        }
        let repr = match directive {
            DirectiveCode::Eof => PduRepr::Eof(EofRepr::read(r, header.lengths.entity)?),
            DirectiveCode::Finished => {
                PduRepr::Finished(FinishedRepr::read(r, header.lengths.entity)?)
            }
            DirectiveCode::Ack => PduRepr::Ack(AckRepr::read(r)?),
            DirectiveCode::Metadata => PduRepr::Metadata(MetadataRepr::read(r)?),
            DirectiveCode::Nak => PduRepr::Nak(NakRepr::read(r)?),
            DirectiveCode::Prompt => PduRepr::Prompt(if r.u8()? & 0x80 == 0 {
                PromptFor::Nak
            } else {
                PromptFor::KeepAlive
            }),
            DirectiveCode::KeepAlive => PduRepr::KeepAlive { progress: r.u32()? },
        };
        if let PduRepr::Ack(_) = repr {
            check_direction(repr.direction(), header.direction)?;
        }
        Ok(repr)
    }

    /// The directive's code; none for file data.
    pub const fn directive(&self) -> Option<DirectiveCode> {
        Some(match self {
            PduRepr::FileData(_) => return None,
            PduRepr::Metadata(_) => DirectiveCode::Metadata,
            PduRepr::Eof(_) => DirectiveCode::Eof,
            PduRepr::Finished(_) => DirectiveCode::Finished,
            PduRepr::Ack(_) => DirectiveCode::Ack,
            PduRepr::Nak(_) => DirectiveCode::Nak,
            PduRepr::Prompt(_) => DirectiveCode::Prompt,
            PduRepr::KeepAlive { .. } => DirectiveCode::KeepAlive,
        })
    }

    /// The way this PDU travels.
    pub const fn direction(&self) -> Direction {
        match (self, self.directive()) {
            (PduRepr::Ack(a), _) => match a.of {
                DirectiveCode::Finished => Direction::TowardReceiver,
                _ => Direction::TowardSender,
            },
            (_, Some(d)) => direction_of(d),
            (_, None) => Direction::TowardReceiver,
        }
    }

    /// Octets of the data field (the CRC aside) with `entity`-octet IDs.
    pub fn data_len(&self, entity: u8) -> usize {
        let fields = match self {
            PduRepr::FileData(f) => return 4usize.saturating_add(f.data.len()),
            PduRepr::Metadata(m) => m.len(),
            PduRepr::Eof(e) => e.len(entity),
            PduRepr::Finished(f) => f.len(entity),
            PduRepr::Ack(a) => a.len(),
            PduRepr::Nak(n) => n.len(),
            PduRepr::Prompt(_) => 1,
            PduRepr::KeepAlive { .. } => 4,
        };
        fields.saturating_add(1)
    }

    /// Writes the whole PDU into `out`: `header` with this PDU's type, direction and data
    /// field length, the fields, and the CRC when the header's flag asks; its length.
    pub fn emit(&self, header: &PduHeader, out: &mut [u8]) -> Result<usize, PduError> {
        let crc = if header.crc { CRC_LEN } else { 0 };
        let field = self.data_len(header.lengths.entity).saturating_add(crc);
        let data_len = u16::try_from(field).map_err(|_| PduError::TooLarge {
            value: u64::try_from(field).unwrap_or(u64::MAX),
            octets: 2,
        })?;
        let h = PduHeader {
            pdu_type: match self {
                PduRepr::FileData(_) => PduType::FileData,
                _ => PduType::Directive,
            },
            direction: self.direction(),
            data_len,
            ..*header
        };
        let len = h.len().saturating_add(field);
        let found = out.len();
        let pdu = out
            .get_mut(..len)
            .ok_or(PduError::Buffer { needed: len, found })?;
        let n = h.emit(pdu)?;
        let (_, body) = pdu.split_at_mut(n);
        let mut w = Writer::new(body);
        self.write(&mut w, header.lengths.entity)?;
        let written = n.saturating_add(w.written());
        if header.crc {
            let (before, tail) = pdu.split_at_mut(written);
            tail.copy_from_slice(&super::pdu_crc(before).to_be_bytes());
        }
        Ok(len)
    }

    /// Writes the data field (the CRC aside).
    fn write(&self, w: &mut Writer<'_>, entity: u8) -> Result<(), PduError> {
        if let Some(d) = self.directive() {
            w.u8(d.code())?;
        }
        match self {
            PduRepr::FileData(f) => {
                w.u32(f.offset)?;
                w.put(f.data)
            }
            PduRepr::Metadata(m) => m.write(w),
            PduRepr::Eof(e) => e.write(w, entity),
            PduRepr::Finished(f) => f.write(w, entity),
            PduRepr::Ack(a) => a.write(w),
            PduRepr::Nak(n) => n.write(w),
            PduRepr::Prompt(p) => w.u8(match p {
                PromptFor::Nak => 0,
                PromptFor::KeepAlive => 0x80,
            }),
            PduRepr::KeepAlive { progress } => w.u32(*progress),
        }
    }
}

/// The way a directive other than ACK travels.
const fn direction_of(d: DirectiveCode) -> Direction {
    match d {
        DirectiveCode::Finished | DirectiveCode::Nak | DirectiveCode::KeepAlive => {
            Direction::TowardSender
        }
        _ => Direction::TowardReceiver,
    }
}

/// Refuses a PDU whose direction bit is not its directive's (`direction`).
fn check_direction(expected: Direction, found: Direction) -> Result<(), PduError> {
    if expected != found {
        return Err(PduError::Direction { expected, found });
    }
    Ok(())
}

/// A four-bit condition code; 12 and 13 are reserved (`condition`).
fn condition(code: u8) -> Result<ConditionCode, PduError> {
    ConditionCode::from_code(code).ok_or(PduError::Condition { found: code })
}
