//! JSON ⇄ packet bytes for the four packet kinds, and hex parsing with positioned errors.

use crate::exit::{EXIT_INPUT, EXIT_INVALID_PACKET};
use mmic::wire::b_command::BCommandRepr;
use mmic::wire::command::CommandRepr;
use mmic::wire::heartbeat::HeartbeatRepr;
use mmic::wire::internal_heartbeat::InternalHeartbeatRepr;
use mmic::wire::{PacketKind, Repr, WireError};

/// Why a codec call failed.
#[derive(Debug, thiserror::Error)]
pub enum CodecError {
    /// The JSON is not a valid `Repr` of the kind.
    #[error("invalid {kind} JSON: {source}")]
    Json {
        /// Kind being encoded.
        kind: PacketKind,
        /// serde_json's message (line, column, field).
        source: serde_json::Error,
    },
    /// The hex text is malformed.
    #[error("invalid hex at character {position} (counting from 0): {reason}")]
    Hex {
        /// 0-based character index in the argument.
        position: usize,
        /// What is wrong.
        reason: &'static str,
    },
    /// The packet could not be written as JSON (serde_json's message).
    #[error("cannot print {kind} as JSON: {source}")]
    Print {
        /// Kind being decoded.
        kind: PacketKind,
        /// serde_json's message.
        source: serde_json::Error,
    },
    /// The bytes are not a valid packet: the failed check and its numbers, and which kind
    /// they look like when their header names another one.
    #[error("{check} check failed: {source}{}", looks_like_text(*looks_like))]
    Packet {
        /// length, header, checksum, field or command.
        check: &'static str,
        /// The wire error.
        source: WireError,
        /// The kind whose header the bytes start with, when it is not the kind asked for.
        looks_like: Option<PacketKind>,
    },
}

impl CodecError {
    /// Process exit code: [`EXIT_INVALID_PACKET`] (1) for an invalid packet, [`EXIT_INPUT`] (2)
    /// for bad input (JSON, hex).
    pub fn exit_code(&self) -> u8 {
        match self {
            CodecError::Packet { .. } => EXIT_INVALID_PACKET,
            CodecError::Json { .. } | CodecError::Hex { .. } | CodecError::Print { .. } => {
                EXIT_INPUT
            }
        }
    }
}

fn looks_like_text(kind: Option<PacketKind>) -> String {
    match kind {
        Some(k) => format!(
            "; this looks like a {k} packet ({}): try `mmic decode {} <hex>`",
            String::from_utf8_lossy(&k.header()),
            k.name()
        ),
        None => String::new(),
    }
}

/// The error for `bytes` refused as a `kind` packet, with the kind their header names when a
/// length or header failure suggests the user picked the wrong kind.
fn packet_err(kind: PacketKind, bytes: &[u8], source: WireError) -> CodecError {
    let looks_like = match source {
        WireError::Length { .. } | WireError::Header { .. } => bytes
            .get(..mmic::wire::HEADER_LEN)
            .and_then(PacketKind::from_header)
            .filter(|&other| other != kind),
        _ => None,
    };
    CodecError::Packet {
        check: source.check(),
        source,
        looks_like,
    }
}

/// Runs the generic function `$f::<R>(args)` with `R` the `Repr` of `$kind`: the one place
/// the four kinds are listed.
macro_rules! by_kind {
    ($kind:expr, $f:ident($($arg:expr),*)) => {
        match $kind {
            PacketKind::Command => $f::<CommandRepr>($($arg),*),
            PacketKind::Heartbeat => $f::<HeartbeatRepr>($($arg),*),
            PacketKind::InternalHeartbeat => $f::<InternalHeartbeatRepr>($($arg),*),
            PacketKind::BCommand => $f::<BCommandRepr>($($arg),*),
        }
    };
}

/// Encodes the JSON form of a `kind` packet to its bytes.
pub fn encode(kind: PacketKind, json: &str) -> Result<Vec<u8>, CodecError> {
    by_kind!(kind, encode_as(json))
}

fn encode_as<R: Repr + serde::de::DeserializeOwned>(json: &str) -> Result<Vec<u8>, CodecError> {
    let repr: R = serde_json::from_str(json).map_err(|source| CodecError::Json {
        kind: R::KIND,
        source,
    })?;
    Ok(repr.to_bytes().as_ref().to_vec())
}

/// Decodes `bytes` as a `kind` packet to its JSON form (one line, every field).
pub fn decode(kind: PacketKind, bytes: &[u8]) -> Result<String, CodecError> {
    by_kind!(kind, decode_as(bytes))
}

fn decode_as<R: Repr + serde::Serialize>(bytes: &[u8]) -> Result<String, CodecError> {
    let repr = R::parse(bytes).map_err(|e| packet_err(R::KIND, bytes, e))?;
    serde_json::to_string(&repr).map_err(|source| CodecError::Print {
        kind: R::KIND,
        source,
    })
}

fn value_as<R: Repr + serde::Serialize>(bytes: &[u8]) -> Option<serde_json::Value> {
    serde_json::to_value(R::parse(bytes).ok()?).ok()
}

/// [`decode_any`] as a JSON value (what [`decode_any`] prints, without printing it: the
/// simulator logs every packet this way).
pub fn decode_value(bytes: &[u8]) -> Option<serde_json::Value> {
    let kind = PacketKind::from_header(bytes.get(..mmic::wire::HEADER_LEN)?)?;
    by_kind!(kind, value_as(bytes))
}

/// Decodes a packet of whichever kind its header names; none if it is no valid packet.
pub fn decode_any(bytes: &[u8]) -> Option<String> {
    let kind = PacketKind::from_header(bytes.get(..mmic::wire::HEADER_LEN)?)?;
    decode(kind, bytes).ok()
}

/// Lowercase hex, no separators.
pub fn to_hex(bytes: &[u8]) -> String {
    const DIGITS: &[u8; 16] = b"0123456789abcdef";
    let mut s = String::with_capacity(bytes.len() * 2);
    for b in bytes {
        s.push(DIGITS[(b >> 4) as usize] as char);
        s.push(DIGITS[(b & 0xf) as usize] as char);
    }
    s
}

/// Parses hex; accepts an optional `0x` prefix per byte group and spaces, colons, commas or
/// dashes between bytes.
pub fn from_hex(text: &str) -> Result<Vec<u8>, CodecError> {
    let chars: Vec<char> = text.chars().collect();
    let mut out = Vec::new();
    let mut i = 0;
    while i < chars.len() {
        let c = chars[i];
        if c.is_whitespace() || matches!(c, ':' | ',' | '-') {
            i += 1;
            continue;
        }
        if c == '0' && matches!(chars.get(i + 1), Some('x' | 'X')) {
            i += 2;
            continue;
        }
        let hi = c.to_digit(16).ok_or(CodecError::Hex {
            position: i,
            reason: "not a hex digit",
        })?;
        let lo = match chars.get(i + 1) {
            None => {
                return Err(CodecError::Hex {
                    position: i,
                    reason: "odd number of hex digits",
                })
            }
            Some(d) => d.to_digit(16).ok_or(CodecError::Hex {
                position: i + 1,
                reason: "not a hex digit (bytes are two digits)",
            })?,
        };
        out.push((hi * 16 + lo) as u8);
        i += 2;
    }
    Ok(out)
}
