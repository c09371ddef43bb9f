//! The Finished PDU (727.0-B-5 §5.2.3): the receiver's end of the transaction.
//!
//! | octets | field |
//! |---|---|
//! | 0 | directive code `0x05` |
//! | 1 | condition code (bits 7–4), spare (3), delivery code (2: 0 complete), file status (1–0) |
//! | 2– | filestore responses (TLV `0x01`, any number), then the fault location (TLV `0x06`) |

use super::super::codes::{ConditionCode, FileStatus};
use super::super::error::PduError;
use super::super::field::{Reader, Writer};
use super::super::tlv::{self, Tlvs, ENTITY_ID, FILESTORE_RESPONSE};
use super::condition;
use super::eof::tlv_len;

/// A Finished PDU's fields.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub struct FinishedRepr<'a> {
    /// Why the transaction ended.
    pub condition: ConditionCode,
    /// Whether every octet of the file arrived (the delivery code, 0).
    pub data_complete: bool,
    /// What the receiver kept.
    pub status: FileStatus,
    /// The filestore responses, TLVs of type `0x01` only.
    pub responses: Tlvs<'a>,
    /// The entity where the fault was found, for an error.
    pub fault_location: Option<u64>,
}

impl<'a> FinishedRepr<'a> {
    /// Reads the fields after the directive code, in a PDU of `entity`-octet IDs.
    pub(super) fn read(r: &mut Reader<'a>, entity: u8) -> Result<FinishedRepr<'a>, PduError> {
        let b = r.u8()?;
        let condition = condition(b >> 4)?;
        let status = FileStatus::from_code(b & 0x03).unwrap_or(FileStatus::Unreported);
        let rest = r.rest();
        let mut fault_location = None;
        let (mut used, mut responses_len) = (0usize, 0usize);
        for t in Tlvs::parse(rest)?.iter() {
            if fault_location.is_some() {
                // Nothing may follow the fault location.
                return Err(PduError::Trailing {
                    expected: used,
                    found: rest.len(),
                });
            }
            let n = t.value.len().saturating_add(2);
            match t.kind {
                FILESTORE_RESPONSE => responses_len = responses_len.saturating_add(n),
                ENTITY_ID => fault_location = Some(tlv::entity_id(t, entity)?),
                found => return Err(PduError::TlvType { found }),
            }
            used = used.saturating_add(n);
        }
        let responses = Tlvs::parse(rest.get(..responses_len).unwrap_or(&[]))?;
        Ok(FinishedRepr {
            condition,
            data_complete: b & 0x04 == 0,
            status,
            responses,
            fault_location,
        })
    }

    /// Octets after the directive code, with `entity`-octet IDs.
    pub(super) fn len(&self, entity: u8) -> usize {
        1usize
            .saturating_add(self.responses.as_bytes().len())
            .saturating_add(tlv_len(self.fault_location, entity))
    }

    /// Writes the fields after the directive code; responses of another type are refused
    /// (`tlv-type`), as on parse.
    pub(super) fn write(&self, w: &mut Writer<'_>, entity: u8) -> Result<(), PduError> {
        if let Some(t) = self.responses.iter().find(|t| t.kind != FILESTORE_RESPONSE) {
            return Err(PduError::TlvType { found: t.kind });
        }
        let delivery = if self.data_complete { 0 } else { 0x04 };
        w.u8(self.condition.code() << 4 | delivery | self.status.code())?;
        w.put(self.responses.as_bytes())?;
        if let Some(id) = self.fault_location {
            tlv::write_entity_id(w, id, entity)?;
        }
        Ok(())
    }
}
