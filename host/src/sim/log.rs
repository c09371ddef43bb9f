//! The JSON-lines log: one object per packet and per event, in the order they happened.
//!
//! Every record has `t_ms` (simulated time) and `kind`. Packets: `{"kind":"packet","link":
//! "wifi","from":"server","to":"robot","fate":"delivered","hex":"4d49..","packet":{..}}`,
//! with `fate` one of `delivered`, `lost` (injected loss), `cut` (the link is cut: board B cut
//! off, or a cut of the virtual-time engine's link model), `unconnected` (a heartbeat with no
//! server connection to carry it), `duplicated` (a copy the virtual-time engine's link made,
//! logged after the original) or `closed` (written to a connection the other end had
//! closed), and `packet_kind` one of
//! the legacy kinds (`command`, `heartbeat`, `internal_heartbeat`, `b_command`) or, with
//! `--protocol pus`, `tc` or `tm` (`packet` then holds the headers and what the service data
//! reads as: the function or request, the ST\[1\] report, the event, the housekeeping
//! heartbeat). Events come from the nodes: `{"kind":"event","node":"board_a","event":{..}}`.

use serde_json::{json, Value};
use std::io::Write;
use std::sync::mpsc::{Receiver, Sender};
use std::sync::{Arc, Mutex};

/// One record.
pub type Record = Value;

/// A cloneable handle to the log: it sends records to a writer thread (the realtime engine's
/// nodes, on threads of their own), or keeps them in memory in the order they are made (the
/// virtual-time engine, one thread: [`Log::memory`]).
#[derive(Clone)]
pub struct Log {
    sink: Sink,
    /// The run's space data link is secured with SDLS: TC data frames and TM frames are
    /// decoded as far as they are in clear ([`decode_secured`]).
    sdls: bool,
}

#[derive(Clone)]
enum Sink {
    Channel(Sender<Record>),
    Memory(Arc<Mutex<Vec<Record>>>),
}

impl Log {
    /// A log and the receiving end for [`write_all`].
    pub fn new() -> (Log, Receiver<Record>) {
        let (tx, rx) = std::sync::mpsc::channel();
        (
            Log {
                sink: Sink::Channel(tx),
                sdls: false,
            },
            rx,
        )
    }

    /// A log kept in memory; [`Log::take`] hands its records over.
    pub fn memory() -> Log {
        Log {
            sink: Sink::Memory(Arc::new(Mutex::new(Vec::new()))),
            sdls: false,
        }
    }

    /// The same log, its frames decoded as SDLS-protected ones when `sdls`.
    pub fn secured(mut self, sdls: bool) -> Log {
        self.sdls = sdls;
        self
    }

    /// The records of a memory log so far, oldest first (none for a channel's).
    pub fn take(&self) -> Vec<Record> {
        match &self.sink {
            Sink::Channel(_) => Vec::new(),
            Sink::Memory(m) => std::mem::take(&mut *m.lock().unwrap_or_else(|e| e.into_inner())),
        }
    }

    /// Logs a packet on a link.
    pub fn packet(&self, t_ms: u32, link: &str, from: &str, to: &str, fate: &str, bytes: &[u8]) {
        let (kind, decoded) = if self.sdls {
            decode_secured(bytes)
        } else {
            decode(bytes)
        };
        self.send(record([
            ("t_ms", t_ms.into()),
            ("kind", "packet".into()),
            ("link", link.into()),
            ("from", from.into()),
            ("to", to.into()),
            ("fate", fate.into()),
            ("packet_kind", kind.into()),
            ("hex", hex(bytes).into()),
            ("packet", decoded),
        ]));
    }

    /// Logs a node's event.
    pub fn event(&self, t_ms: u32, node: &str, event: Value) {
        self.send(record([
            ("t_ms", t_ms.into()),
            ("kind", "event".into()),
            ("node", node.into()),
            ("event", event),
        ]));
    }

    /// Logs any record.
    pub fn send(&self, r: Record) {
        match &self.sink {
            // The writer outlives every node; a send after it stopped has nowhere to go.
            Sink::Channel(tx) => {
                let _ = tx.send(r);
            }
            Sink::Memory(m) => m.lock().unwrap_or_else(|e| e.into_inner()).push(r),
        }
    }
}

/// A record of these fields, in this order: what `json!` makes of them, without its
/// serialising each value again (`json!` turns an expression into a value through
/// `serde_json::to_value`, which copies a `Value` field by field: most of a logged event's
/// cost in the fault swarm, which logs every event of every run).
fn record<const N: usize>(fields: [(&str, Value); N]) -> Record {
    let mut m = serde_json::Map::new();
    for (k, v) in fields {
        m.insert(k.to_string(), v);
    }
    Value::Object(m)
}

/// A packet's kind and its JSON form: a legacy packet by its header, else a PUS telecommand
/// or telemetry packet of a robot's APID; `unknown` and null for anything else.
pub fn decode(bytes: &[u8]) -> (&'static str, Value) {
    use mmic::wire::PacketKind;
    let legacy = bytes
        .get(..mmic::wire::HEADER_LEN)
        .and_then(PacketKind::from_header);
    if let Some(k) = legacy {
        let name = match k {
            PacketKind::Command => "command",
            PacketKind::Heartbeat => "heartbeat",
            PacketKind::InternalHeartbeat => "internal_heartbeat",
            PacketKind::BCommand => "b_command",
        };
        let v = crate::codec::decode_value(bytes).unwrap_or(Value::Null);
        return (name, v);
    }
    pus(bytes)
        .or_else(|| frame(bytes))
        .unwrap_or(("unknown", Value::Null))
}

/// A TC or TM transfer frame (`--link frames`) as JSON, `mmic decode tc-frame|tm-frame`'s:
/// a TM frame is the mission's length, anything else is tried as a TC frame.
fn frame(bytes: &[u8]) -> Option<(&'static str, Value)> {
    let options = crate::link::FrameOptions::default();
    if bytes.len() == mmic::link::tm_frame::TM_FRAME_LEN {
        if let Ok(v) = crate::link::decode_tm_frame(bytes, &options) {
            return Some(("tm_frame", v));
        }
    }
    crate::link::decode_tc_frame(bytes, &options)
        .ok()
        .map(|v| ("tc_frame", v))
}

/// A packet's kind and JSON form on a link secured with SDLS: TC data frames and TM frames by
/// what is in clear (their headers, the security header, and a TM frame's CLCW: the OCF is
/// outside the MAC), never the ciphertext read as packets; anything else as [`decode`] does.
pub fn decode_secured(bytes: &[u8]) -> (&'static str, Value) {
    let legacy = bytes
        .get(..mmic::wire::HEADER_LEN)
        .and_then(mmic::wire::PacketKind::from_header)
        .is_some();
    if legacy {
        return decode(bytes);
    }
    secured_frame(bytes).unwrap_or_else(|| decode(bytes))
}

/// The security header of a protected TC data frame or TM frame as JSON: its SPI and IV (the
/// IV is the anti-replay counter, sent in clear), and the length of the ciphertext between it
/// and the MAC. Null for anything else (a BC frame, which goes in clear).
pub fn sdls_header(bytes: &[u8]) -> Value {
    use mmic::link::sdls::{HEADER_LEN, MAC_LEN, SPI_LEN};
    let start = if bytes.len() == mmic::link::tm_frame::TM_FRAME_LEN {
        mmic::link::tm_frame::PRIMARY_HEADER_LEN
    } else {
        match mmic::link::tc_frame::TcPrimaryHeader::read(bytes) {
            Some(h) if !h.control => {
                mmic::link::tc_frame::TC_PRIMARY_HEADER_LEN
                    + mmic::link::tc_frame::SEGMENT_HEADER_LEN
            }
            _ => return Value::Null,
        }
    };
    // The MAC ends before the OCF and the FECF of a TM frame, before the FECF of a TC frame.
    let trailer = if start == mmic::link::tm_frame::PRIMARY_HEADER_LEN {
        mmic::link::tm_frame::OCF_LEN + mmic::link::tm_frame::FECF_LEN
    } else {
        mmic::link::tc_frame::FECF_LEN
    };
    let Some(h) = bytes.get(start..start + HEADER_LEN) else {
        return Value::Null;
    };
    let spi = u16::from_be_bytes([h[0], h[1]]);
    let ciphertext = bytes
        .len()
        .saturating_sub(start + HEADER_LEN + MAC_LEN + trailer);
    json!({"spi": spi, "iv": hex(&h[SPI_LEN..]), "ciphertext_len": ciphertext})
}

fn secured_frame(bytes: &[u8]) -> Option<(&'static str, Value)> {
    let options = crate::link::FrameOptions::default();
    if bytes.len() == mmic::link::tm_frame::TM_FRAME_LEN {
        // The frame's fields by the mission's TM layout with room for SDLS.
        let id = u16::from_be_bytes([*bytes.first()?, *bytes.get(1)?]);
        let params = mmic::link::tm_frame::TmFrameParams::mission((id >> 4) & 0x3ff)?
            .with_security(
                mmic::link::sdls::HEADER_LEN as u8,
                mmic::link::sdls::MAC_LEN as u8,
            )?;
        let mut v = crate::link::decode_tm_with(bytes, &params).ok()?;
        v["data"] = Value::Null;
        v["sdls"] = sdls_header(bytes);
        return Some(("tm_frame", v));
    }
    let header = mmic::link::tc_frame::TcPrimaryHeader::read(bytes)?;
    if header.control {
        return None; // a BC frame: in clear
    }
    // The header fields by the plain decoder over a frame whose data it does not read as
    // packets: the frame check needs only the header, the length and the FECF.
    let mut v = crate::link::decode_tc_frame(bytes, &options).unwrap_or_else(|_| {
        // The decoder refused the ciphertext as packets: the header alone.
        json!({
            "kind": if header.bypass { "bd" } else { "ad" },
            "spacecraft_id": header.spacecraft_id, "vcid": header.vcid,
            "length": header.frame_length, "seq": header.seq, "len": bytes.len(),
        })
    });
    for k in ["data_field", "data", "packets"] {
        if v.get(k).is_some() {
            v[k] = Value::Null;
        }
    }
    v["sdls"] = sdls_header(bytes);
    Some(("tc_frame", v))
}

/// Every robot's APID.
fn robot_apids() -> Vec<u16> {
    (1..=255u8)
        .filter_map(|n| mmic::units::BoardNumber::new(n).ok())
        .map(mmic::pus::robot_apid)
        .collect()
}

/// A PUS packet as JSON.
fn pus(bytes: &[u8]) -> Option<(&'static str, Value)> {
    use mmic::ccsds::tc::TcRepr;
    use mmic::ccsds::tm::TmRepr;
    use mmic::pus::request::Request;
    let apids = robot_apids();
    if let Ok(tc) = TcRepr::parse(bytes, &apids) {
        let h = tc.header;
        let request = match Request::parse(h.service, h.subservice, tc.app_data) {
            Ok(Request::Function(c)) => json!({"function": c}),
            Ok(q) => json!(format!("{q:?}")),
            Err(e) => json!({"refused": e.to_string()}),
        };
        return Some((
            "tc",
            json!({
                "apid": tc.apid.get(), "seq_count": tc.seq_count.get(),
                "service": h.service, "subservice": h.subservice, "source_id": h.source_id,
                "ack": h.ack.bits(), "request": request,
            }),
        ));
    }
    let tm = TmRepr::parse(bytes, &apids).ok()?;
    let h = tm.header;
    let data = tm.source_data;
    let content = match h.service {
        1 => match mmic::pus::verification::Report::parse(h.subservice, data) {
            Ok(r) => json!({
                "stage": format!("{:?}", r.stage).to_lowercase(),
                "seq_count": r.request.seq_count,
                "failure": r.failure.map(|f| json!({"code": f.code, "data": f.data})),
            }),
            Err(e) => json!({"unreadable": e.to_string()}),
        },
        3 => match mmic::pus::housekeeping::parse(data) {
            Ok(hb) => json!({"housekeeping": hb}),
            Err(e) => json!({"unreadable": e.to_string()}),
        },
        5 => json!({
            "event_id": data.get(..2).map(|b| u16::from_be_bytes([b[0], b[1]])),
            "aux": hex(data.get(2..).unwrap_or(&[])),
        }),
        _ => json!({"data": hex(data)}),
    };
    Some((
        "tm",
        json!({
            "apid": tm.apid.get(), "seq_count": tm.seq_count.get(),
            "service": h.service, "subservice": h.subservice, "counter": h.counter,
            "destination_id": h.destination_id, "report": content,
        }),
    ))
}

/// Lowercase hex.
pub fn hex(bytes: &[u8]) -> String {
    crate::codec::to_hex(bytes)
}

/// Writes records as JSON lines, one per line.
pub fn write_lines(records: &[Record], out: &mut dyn Write) -> std::io::Result<()> {
    for r in records {
        serde_json::to_writer(&mut *out, r)?;
        out.write_all(b"\n")?;
    }
    out.flush()
}

/// Writes every record until all senders are gone; returns the records for the report.
///
/// The output is flushed whenever the writer has caught up with the nodes (nothing waiting in
/// the channel): a run that is killed (an external ground's robot, stopped by its test) leaves
/// its log complete up to that moment, and a reader can follow it while it runs; a busy run
/// still writes in large blocks.
pub fn write_all(rx: Receiver<Record>, out: &mut dyn Write) -> std::io::Result<Vec<Record>> {
    let mut all = Vec::new();
    loop {
        let r = match rx.try_recv() {
            Ok(r) => r,
            Err(std::sync::mpsc::TryRecvError::Empty) => {
                out.flush()?;
                match rx.recv() {
                    Ok(r) => r,
                    Err(_) => break,
                }
            }
            Err(std::sync::mpsc::TryRecvError::Disconnected) => break,
        };
        serde_json::to_writer(&mut *out, &r)?;
        out.write_all(b"\n")?;
        all.push(r);
    }
    out.flush()?;
    Ok(all)
}
