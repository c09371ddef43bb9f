//! The variable fields of CFDP's directives (727.0-B-5 §5.1.8–5.1.9, §5.4): LV (a length
//! octet, then that many octets: file names) and TLV (a type octet, a length octet, the
//! value: options, filestore responses, the fault location). Borrowed views, checked whole
//! on parse, so that iterating them later cannot fail.
//!
//! ```
//! use mmic::cfdp::tlv::{Tlvs, ENTITY_ID};
//!
//! // A message to user (type 2) of two octets, then an entity ID TLV.
//! let bytes = [0x02, 0x02, 0xab, 0xcd, 0x06, 0x02, 0x00, 0x15];
//! let tlvs = Tlvs::parse(&bytes).unwrap();
//! let kinds: Vec<u8> = tlvs.iter().map(|t| t.kind).collect();
//! assert_eq!(kinds, [0x02, ENTITY_ID]);
//! assert!(Tlvs::parse(&bytes[..7]).is_err()); // the last value cut short
//! ```

use super::error::PduError;
use super::field::Writer;

/// TLV type of a filestore request (Metadata option).
pub const FILESTORE_REQUEST: u8 = 0x00;
/// TLV type of a filestore response (Finished PDU).
pub const FILESTORE_RESPONSE: u8 = 0x01;
/// TLV type of a message to user (Metadata option).
pub const MESSAGE_TO_USER: u8 = 0x02;
/// TLV type of a fault handler override (Metadata option).
pub const FAULT_HANDLER_OVERRIDE: u8 = 0x04;
/// TLV type of a flow label (Metadata option).
pub const FLOW_LABEL: u8 = 0x05;
/// TLV type of an entity ID: the fault location of an EOF or Finished PDU.
pub const ENTITY_ID: u8 = 0x06;

/// One TLV.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub struct Tlv<'a> {
    /// Its type.
    pub kind: u8,
    /// Its value.
    pub value: &'a [u8],
}

/// A run of TLVs, each checked to lie within the run.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Default)]
pub struct Tlvs<'a> {
    bytes: &'a [u8],
}

impl<'a> Tlvs<'a> {
    /// No TLVs.
    pub const EMPTY: Tlvs<'static> = Tlvs { bytes: &[] };

    /// Checks that `bytes` is a whole number of TLVs: each one's type and length octets
    /// present and its value within `bytes` (`tlv`, with the octets it declares and those
    /// left).
    pub fn parse(bytes: &'a [u8]) -> Result<Tlvs<'a>, PduError> {
        let mut rest = bytes;
        while !rest.is_empty() {
            let (_, after) = split_tlv(rest)?;
            rest = after;
        }
        Ok(Tlvs { bytes })
    }

    /// The TLVs in order.
    pub fn iter(&self) -> impl Iterator<Item = Tlv<'a>> + 'a {
        let mut rest = self.bytes;
        core::iter::from_fn(move || {
            let (tlv, after) = split_tlv(rest).ok()?;
            rest = after;
            Some(tlv)
        })
    }

    /// The run's octets.
    pub const fn as_bytes(&self) -> &'a [u8] {
        self.bytes
    }

    /// Whether there are none.
    pub const fn is_empty(&self) -> bool {
        self.bytes.is_empty()
    }
}

/// The TLV at the start of `bytes` and what follows it.
fn split_tlv(bytes: &[u8]) -> Result<(Tlv<'_>, &[u8]), PduError> {
    let [kind, len, rest @ ..] = bytes else {
        return Err(PduError::Tlv {
            declared: 2,
            found: bytes.len(),
        });
    };
    let n = usize::from(*len);
    let (value, after) = rest.split_at_checked(n).ok_or(PduError::Tlv {
        declared: n.saturating_add(2),
        found: bytes.len(),
    })?;
    Ok((Tlv { kind: *kind, value }, after))
}

/// Writes an LV; a value over 255 octets cannot be carried (`too-large`).
pub(super) fn write_lv(w: &mut Writer<'_>, value: &[u8]) -> Result<(), PduError> {
    let n = u8::try_from(value.len()).map_err(|_| PduError::TooLarge {
        value: u64::try_from(value.len()).unwrap_or(u64::MAX),
        octets: 1,
    })?;
    w.u8(n)?;
    w.put(value)
}

/// The entity ID an entity ID TLV carries, big-endian, of the `octets` the PDU's header gives
/// its entity IDs (`entity-id` otherwise: an ID of another length would write back otherwise).
pub(super) fn entity_id(tlv: Tlv<'_>, octets: u8) -> Result<u64, PduError> {
    if tlv.kind != ENTITY_ID {
        return Err(PduError::TlvType { found: tlv.kind });
    }
    if tlv.value.len() != usize::from(octets) {
        return Err(PduError::EntityId {
            expected: octets,
            found: tlv.value.len(),
        });
    }
    Ok(tlv
        .value
        .iter()
        .fold(0u64, |v, &b| v.wrapping_shl(8) | u64::from(b)))
}

/// Writes the fault location: an entity ID TLV of `octets` octets.
pub(super) fn write_entity_id(w: &mut Writer<'_>, id: u64, octets: u8) -> Result<(), PduError> {
    let n = usize::from(octets);
    let bytes = id.to_be_bytes();
    let start = bytes.len().saturating_sub(n);
    let (high, value) = bytes.split_at_checked(start).ok_or(PduError::Lengths {
        entity: octets,
        seq: 0,
    })?;
    if high.iter().any(|&b| b != 0) || n == 0 {
        return Err(PduError::TooLarge { value: id, octets });
    }
    w.u8(ENTITY_ID)?;
    w.u8(octets)?;
    w.put(value)
}
