//! `mmic decode cfdp HEX`: a CFDP PDU (CCSDS 727.0-B-5) as JSON, its header's fields and its
//! data field in hex; a refused PDU exits 1 with the check's name (spec/ccsds/bad-inputs.toml).

use crate::codec::to_hex;
use crate::pus::PusCodecError;
use mmic::cfdp::Pdu;
use serde_json::{json, Value};

/// Decodes one whole PDU.
pub fn decode(bytes: &[u8]) -> Result<Value, PusCodecError> {
    let pdu = Pdu::parse(bytes).map_err(|e| PusCodecError::Refused {
        name: e.name(),
        message: e.to_string(),
    })?;
    Ok(json!({
        "header": serde_json::to_value(pdu.header()).unwrap_or(Value::Null),
        "data": to_hex(pdu.data()),
    }))
}
