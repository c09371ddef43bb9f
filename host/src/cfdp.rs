//! `mmic decode cfdp HEX`: a CFDP PDU (CCSDS 727.0-B-5) as JSON, its header's fields, its data
//! field in hex and its directive's fields (`mmic::cfdp::directive`); a refused PDU exits 1
//! with the check's name (spec/ccsds/bad-inputs.toml).

use crate::codec::to_hex;
use crate::pus::PusCodecError;
use mmic::cfdp::directive::{PduRepr, PromptFor};
use mmic::cfdp::tlv::Tlvs;
use mmic::cfdp::Pdu;
use serde_json::{json, Value};

/// Decodes one whole PDU and its directive.
pub fn decode(bytes: &[u8]) -> Result<Value, PusCodecError> {
    let refused = |e: mmic::cfdp::PduError| PusCodecError::Refused {
        name: e.name(),
        message: e.to_string(),
    };
    let pdu = Pdu::parse(bytes).map_err(refused)?;
    let repr = PduRepr::parse(&pdu).map_err(refused)?;
    Ok(json!({
        "header": serde_json::to_value(pdu.header()).unwrap_or(Value::Null),
        "data": to_hex(pdu.data()),
        "pdu": repr_json(&repr),
    }))
}

/// A PDU's fields as JSON: codes by name, octets in hex, names as text where they are UTF-8.
pub fn repr_json(repr: &PduRepr<'_>) -> Value {
    let name = |b: &[u8]| std::str::from_utf8(b).map_or_else(|_| json!(to_hex(b)), |s| json!(s));
    let tlvs = |t: &Tlvs<'_>| -> Vec<Value> {
        t.iter()
            .map(|t| json!({"type": t.kind, "value": to_hex(t.value)}))
            .collect()
    };
    match repr {
        PduRepr::Metadata(m) => json!({
            "type": "metadata",
            "closure_requested": m.closure_requested,
            "checksum_type": m.checksum.value(),
            "file_size": m.file_size,
            "source": name(m.source),
            "dest": name(m.dest),
            "options": tlvs(&m.options),
        }),
        PduRepr::FileData(f) => json!({
            "type": "file_data", "offset": f.offset, "len": f.data.len(), "data": to_hex(f.data),
        }),
        PduRepr::Eof(e) => json!({
            "type": "eof",
            "condition": e.condition.name(),
            "checksum": e.checksum,
            "file_size": e.file_size,
            "fault_location": e.fault_location,
        }),
        PduRepr::Finished(f) => json!({
            "type": "finished",
            "condition": f.condition.name(),
            "data_complete": f.data_complete,
            "file_status": f.status.name(),
            "filestore_responses": tlvs(&f.responses),
            "fault_location": f.fault_location,
        }),
        PduRepr::Ack(a) => json!({
            "type": "ack",
            "of": a.of.name(),
            "condition": a.condition.name(),
            "transaction_status": a.status.name(),
        }),
        PduRepr::Nak(n) => json!({
            "type": "nak",
            "scope": [n.start, n.end],
            "segments": n.segments.iter().map(|(s, e)| json!([s, e])).collect::<Vec<_>>(),
        }),
        PduRepr::Prompt(p) => json!({
            "type": "prompt",
            "response": match p { PromptFor::Nak => "nak", PromptFor::KeepAlive => "keep-alive" },
        }),
        PduRepr::KeepAlive { progress } => json!({"type": "keep_alive", "progress": progress}),
    }
}
