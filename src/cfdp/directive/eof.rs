//! The EOF PDU (727.0-B-5 §5.2.2): the sender's end of the file data, or its giving up.
//!
//! | octets | field |
//! |---|---|
//! | 0 | directive code `0x04` |
//! | 1 | condition code (high four bits), spare |
//! | 2–5 | file checksum |
//! | 6–9 | file size (32 bits: no large files) |
//! | 10– | fault location, an entity ID TLV: only when the condition is an error |

use super::super::codes::ConditionCode;
use super::super::error::PduError;
use super::super::field::{Reader, Writer};
use super::super::tlv::{self, Tlvs};
use super::condition;

/// An EOF PDU's fields.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub struct EofRepr {
    /// Why the sender ends: `NoError` when every octet was sent.
    pub condition: ConditionCode,
    /// The checksum of the whole file, of the type the Metadata announced.
    pub checksum: u32,
    /// The file's size, octets.
    pub file_size: u32,
    /// The entity where the fault was found, for an error (read when present, as YAMCS
    /// 5.12.8 leaves it out: `spec/decisions.toml`, `cfdp-fault-location`).
    pub fault_location: Option<u64>,
}

impl EofRepr {
    /// Reads the fields after the directive code, in a PDU of `entity`-octet IDs.
    pub(super) fn read(r: &mut Reader<'_>, entity: u8) -> Result<EofRepr, PduError> {
        let condition = condition(r.u8()? >> 4)?;
        let checksum = r.u32()?;
        let file_size = r.u32()?;
        let fault_location = fault_location(r, entity)?;
        Ok(EofRepr {
            condition,
            checksum,
            file_size,
            fault_location,
        })
    }

    /// Octets after the directive code, with `entity`-octet IDs.
    pub(super) fn len(&self, entity: u8) -> usize {
        9usize.saturating_add(tlv_len(self.fault_location, entity))
    }

    /// Writes the fields after the directive code.
    pub(super) fn write(&self, w: &mut Writer<'_>, entity: u8) -> Result<(), PduError> {
        w.u8(self.condition.code() << 4)?;
        w.u32(self.checksum)?;
        w.u32(self.file_size)?;
        if let Some(id) = self.fault_location {
            tlv::write_entity_id(w, id, entity)?;
        }
        Ok(())
    }
}

/// Octets of a fault location TLV, if any.
pub(super) fn tlv_len(at: Option<u64>, entity: u8) -> usize {
    at.map_or(0, |_| usize::from(entity).saturating_add(2))
}

/// The optional fault location that ends the field: nothing, or exactly one entity ID TLV.
fn fault_location(r: &mut Reader<'_>, entity: u8) -> Result<Option<u64>, PduError> {
    let rest = r.rest();
    let Some(first) = Tlvs::parse(rest)?.iter().next() else {
        return Ok(None);
    };
    let used = first.value.len().saturating_add(2);
    if used < rest.len() {
        return Err(PduError::Trailing {
            expected: used,
            found: rest.len(),
        });
    }
    tlv::entity_id(first, entity).map(Some)
}
