//! The JSON-lines log: one object per packet and per event, in the order they happened.
//!
//! Every record has `t_ms` (simulated time) and `kind`. Packets: `{"kind":"packet","link":
//! "wifi","from":"server","to":"robot","fate":"delivered","hex":"4d49..","packet":{..}}`,
//! with `fate` one of `delivered`, `lost` (injected loss), `cut` (board B cut off) or
//! `unconnected` (a heartbeat with no server connection to carry it). Events come from the
//! nodes: `{"kind":"event","node":"board_a","event":{..}}`.

use serde_json::{json, Value};
use std::io::Write;
use std::sync::mpsc::{Receiver, Sender};

/// One record.
pub type Record = Value;

/// A cloneable handle that sends records to the writer thread.
#[derive(Clone)]
pub struct Log {
    tx: Sender<Record>,
}

impl Log {
    /// A log and the receiving end for [`write_all`].
    pub fn new() -> (Log, Receiver<Record>) {
        let (tx, rx) = std::sync::mpsc::channel();
        (Log { tx }, rx)
    }

    /// Logs a packet on a link.
    pub fn packet(&self, t_ms: u32, link: &str, from: &str, to: &str, fate: &str, bytes: &[u8]) {
        let decoded = crate::codec::decode_any(bytes)
            .and_then(|s| serde_json::from_str::<Value>(&s).ok())
            .unwrap_or(Value::Null);
        self.send(json!({
            "t_ms": t_ms, "kind": "packet", "link": link, "from": from, "to": to,
            "fate": fate, "hex": hex(bytes), "packet": decoded,
        }));
    }

    /// Logs a node's event.
    pub fn event(&self, t_ms: u32, node: &str, event: Value) {
        self.send(json!({"t_ms": t_ms, "kind": "event", "node": node, "event": event}));
    }

    /// Logs any record.
    pub fn send(&self, r: Record) {
        // The writer outlives every node; a send after it stopped has nowhere to go.
        let _ = self.tx.send(r);
    }
}

/// Lowercase hex.
pub fn hex(bytes: &[u8]) -> String {
    crate::codec::to_hex(bytes)
}

/// Writes every record until all senders are gone; returns the records for the report.
pub fn write_all(rx: Receiver<Record>, out: &mut dyn Write) -> std::io::Result<Vec<Record>> {
    let mut all = Vec::new();
    for r in rx {
        serde_json::to_writer(&mut *out, &r)?;
        out.write_all(b"\n")?;
        all.push(r);
    }
    out.flush()?;
    Ok(all)
}
