//! The ACK PDU (727.0-B-5 §5.2.4): acknowledges an EOF (toward the sender) or a Finished
//! (toward the receiver) in class 2.
//!
//! | octets | field |
//! |---|---|
//! | 0 | directive code `0x06` |
//! | 1 | code of the directive acknowledged (bits 7–4), directive subtype (3–0) |
//! | 2 | condition code (7–4), spare (3–2), transaction status (1–0) |

use super::super::codes::{ConditionCode, DirectiveCode, TransactionStatus};
use super::super::error::PduError;
use super::super::field::{Reader, Writer};
use super::condition;

/// An ACK PDU's fields.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub struct AckRepr {
    /// The directive acknowledged: [`DirectiveCode::Eof`] or [`DirectiveCode::Finished`].
    pub of: DirectiveCode,
    /// The condition code of the PDU acknowledged.
    pub condition: ConditionCode,
    /// Where the acknowledging entity's transaction stands.
    pub status: TransactionStatus,
}

impl AckRepr {
    /// Reads the fields after the directive code. The subtype is not kept: 727.0-B-5 has
    /// `0001` for an ACK of Finished and `0000` otherwise, and the acknowledged code says the
    /// same (`spec/decisions.toml`, `cfdp-ack-subtype`).
    pub(super) fn read(r: &mut Reader<'_>) -> Result<AckRepr, PduError> {
        let b = r.u8()?;
        let of = match DirectiveCode::from_code(b >> 4) {
            Some(d @ (DirectiveCode::Eof | DirectiveCode::Finished)) => d,
            _ => return Err(PduError::AckOf { found: b >> 4 }),
        };
        let c = r.u8()?;
        let status = TransactionStatus::from_code(c & 0x03).unwrap_or(TransactionStatus::Undefined);
        Ok(AckRepr {
            of,
            condition: condition(c >> 4)?,
            status,
        })
    }

    /// Octets after the directive code.
    pub(super) const fn len(&self) -> usize {
        2
    }

    /// Writes the fields after the directive code (`ack-of` for a directive other than EOF
    /// and Finished).
    pub(super) fn write(&self, w: &mut Writer<'_>) -> Result<(), PduError> {
        let subtype = match self.of {
            DirectiveCode::Eof => 0,
            DirectiveCode::Finished => 1,
            other => {
                return Err(PduError::AckOf {
                    found: other.code(),
                })
            }
        };
        w.u8(self.of.code() << 4 | subtype)?;
        w.u8(self.condition.code() << 4 | self.status.code())
    }
}
