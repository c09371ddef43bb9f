//! PUS-C packets as JSON, for `mmic encode pus-tc|pus-tm` and `mmic decode pus-tc|pus-tm`:
//! the library's parsers and emitters (`mmic::ccsds`, `mmic::pus`) with the argument table
//! of spec/ccsds/functions.toml ([`crate::spec`]) for argument names.
//!
//! A refused packet is a [`PusCodecError::Refused`] naming the failed check
//! ([`mmic::pus::PusError::name`] for telecommands; for telemetry the wire check's name, or
//! `unknown-service`, `unknown-subservice`, `source-data`); bad JSON or hex is
//! [`PusCodecError::Input`].
//!
//! Telecommand JSON (`encode pus-tc`; every key but the request is optional: APID 257 =
//! robot 1, sequence count 0, source ID 0, ack "all"):
//!
//! ```json
//! {"apid":257,"seq_count":1,"source_id":0,"ack":"all","function":"reconfiguration","args":{"initial":"a","target":"m"}}
//! {"service":17,"subservice":1}
//! {"service":3,"subservice":31,"interval_ms":2000}
//! ```
//!
//! `decode pus-tc` prints those keys and what follows from them (`service`, `subservice`,
//! `request`, `function_id`, `command`, `app_data`, `len`); `encode pus-tc` takes that output
//! back, checking that every derived key it is given agrees.

use crate::exit::{EXIT_INPUT, EXIT_INVALID_PACKET};
use crate::spec;
use mmic::ccsds::cuc::Cuc;
use mmic::ccsds::primary::{Apid, SeqCount};
use mmic::ccsds::tc::TcRepr;
use mmic::ccsds::tc_header::{AckFlags, TcSecondaryHeader};
use mmic::ccsds::tm::TmRepr;
use mmic::ccsds::tm_header::{TimeRefStatus, TmSecondaryHeader};
use mmic::ccsds::MAX_PACKET_LEN;
use mmic::pus::event::{AttemptResult, Event};
use mmic::pus::function::FunctionId;
use mmic::pus::housekeeping;
use mmic::pus::request::Request;
use mmic::pus::verification::{Failure, Report, RequestId, Stage};
use mmic::pus::PusError;
use mmic::pus::{read_tc, ROBOT_APID_BASE};
use mmic::wire::heartbeat::HeartbeatRepr;
use serde_json::{json, Map, Value};

/// Why a PUS codec call (or a transfer frame codec call, [`crate::link`]) failed.
#[derive(Debug, thiserror::Error, PartialEq, Eq)]
pub enum PusCodecError {
    /// The JSON (or hex) is not a packet description: which key and why.
    #[error("invalid {what}: {reason}")]
    Input {
        /// `pus-tc JSON`, `pus-tm JSON`, ...
        what: &'static str,
        /// Why.
        reason: String,
    },
    /// The packet (or frame) is refused: the failed check's name and the library's message.
    #[error("{name} check failed: {message}")]
    Refused {
        /// The check's name (spec/ccsds/bad-inputs.toml).
        name: &'static str,
        /// The library's message with its numbers.
        message: String,
    },
}

impl PusCodecError {
    /// [`EXIT_INVALID_PACKET`] for a refused packet, [`EXIT_INPUT`] for bad input.
    pub fn exit_code(&self) -> u8 {
        match self {
            PusCodecError::Input { .. } => EXIT_INPUT,
            PusCodecError::Refused { .. } => EXIT_INVALID_PACKET,
        }
    }
}

/// How a bolting attempt ended, with its name (spec/ccsds/services.toml, event 0x0002).
pub const ATTEMPT_RESULTS: [(AttemptResult, &str); 4] = [
    (AttemptResult::Done, "done"),
    (AttemptResult::Failed, "failed"),
    (AttemptResult::GaveUp, "gave_up"),
    (AttemptResult::Interrupted, "interrupted"),
];

fn tc_input(reason: impl Into<String>) -> PusCodecError {
    PusCodecError::Input {
        what: "pus-tc JSON",
        reason: reason.into(),
    }
}

fn tm_input(reason: impl Into<String>) -> PusCodecError {
    PusCodecError::Input {
        what: "pus-tm JSON",
        reason: reason.into(),
    }
}

fn refused(e: PusError) -> PusCodecError {
    PusCodecError::Refused {
        name: e.name(),
        message: e.to_string(),
    }
}

/// Every robot's APID, 0x101..=0x1FF: what `decode pus-tc|pus-tm` accept without `--apid`.
pub fn robot_apids() -> Vec<u16> {
    (ROBOT_APID_BASE + 1..=ROBOT_APID_BASE + 255).collect()
}

/// An APID from the command line: decimal or `0x` hex, 0..=0x7FF.
pub fn parse_apid(text: &str) -> Result<u16, String> {
    let v = match text.strip_prefix("0x").or_else(|| text.strip_prefix("0X")) {
        Some(h) => u16::from_str_radix(h, 16),
        None => text.parse(),
    }
    .map_err(|e| format!("APID {text:?}: {e}"))?;
    if v > 0x7FF {
        return Err(format!("APID {v} is more than 11 bits (0..=2047)"));
    }
    Ok(v)
}

fn hex(bytes: &[u8]) -> String {
    crate::codec::to_hex(bytes)
}

// ---- telecommands ------------------------------------------------------------------------

const TC_KEYS: [&str; 15] = [
    "apid",
    "seq_count",
    "source_id",
    "ack",
    "function",
    "args",
    "service",
    "subservice",
    "interval_ms",
    // derived keys of the decoded form, checked when given
    "request",
    "function_id",
    "command",
    "app_data",
    "len",
    "ack_bits",
];

pub(crate) fn uint(
    v: &Value,
    key: &str,
    max: u64,
    err: fn(String) -> PusCodecError,
) -> Result<u64, PusCodecError> {
    let n = v
        .as_u64()
        .ok_or_else(|| err(format!("{key}: expected an unsigned integer, found {v}")))?;
    if n > max {
        return Err(err(format!("{key} = {n}: at most {max}")));
    }
    Ok(n)
}

fn ack_of(v: &Value) -> Result<AckFlags, PusCodecError> {
    match v {
        Value::String(s) if s == "all" => Ok(AckFlags::ALL),
        Value::String(s) if s == "none" => Ok(AckFlags::NONE),
        Value::Number(_) => Ok(AckFlags::from_bits(
            uint(v, "ack", 15, tc_input)? as u8,
        )),
        Value::Object(_) => serde_json::from_value(v.clone()).map_err(|e| tc_input(format!("ack: {e}"))),
        _ => Err(tc_input(format!(
            "ack: expected \"all\", \"none\", 0..=15 (bit 0 acceptance, 1 start, 2 progress, 3 completion) or {{\"acceptance\":..}}, found {v}"
        ))),
    }
}

/// The application data of `function` with `args` (names of spec/ccsds/functions.toml).
fn function_data(name: &str, args: Option<&Value>) -> Result<Vec<u8>, PusCodecError> {
    let f = spec::functions()
        .iter()
        .find(|f| f.name == name)
        .ok_or_else(|| {
            let names: Vec<&str> = spec::functions().iter().map(|f| f.name.as_str()).collect();
            tc_input(format!(
                "unknown function {name:?}; functions: {}",
                names.join(", ")
            ))
        })?;
    let empty = Map::new();
    let given = match args {
        None | Some(Value::Null) => &empty,
        Some(Value::Object(m)) => m,
        Some(v) => return Err(tc_input(format!("args: expected an object, found {v}"))),
    };
    if let Some(k) = given.keys().find(|k| !f.args.iter().any(|a| &a.name == *k)) {
        let names: Vec<&str> = f.args.iter().map(|a| a.name.as_str()).collect();
        return Err(tc_input(format!(
            "function {name} has no argument {k:?}; its arguments: [{}]",
            names.join(", ")
        )));
    }
    let mut data = vec![f.id];
    for a in &f.args {
        let v = given
            .get(&a.name)
            .ok_or_else(|| tc_input(format!("function {name}: argument {:?} missing", a.name)))?;
        let max = if a.bits() == 16 { 0xFFFF } else { 0xFF };
        let n = match v {
            Value::String(s) if s.chars().count() == 1 && s.is_ascii() => {
                u64::from(s.as_bytes()[0])
            }
            _ => uint(v, &a.name, max, tc_input)?,
        };
        if a.bits() == 16 {
            data.extend_from_slice(&(n as u16).to_be_bytes());
        } else {
            data.push(n as u8);
        }
    }
    Ok(data)
}

/// The JSON object of `json`, every key one of `keys`.
pub(crate) fn object(
    json: &str,
    keys: &[&str],
    err: fn(String) -> PusCodecError,
) -> Result<serde_json::Map<String, Value>, PusCodecError> {
    let v: Value = serde_json::from_str(json).map_err(|e| err(e.to_string()))?;
    let Value::Object(m) = v else {
        return Err(err("expected a JSON object".into()));
    };
    if let Some(k) = m.keys().find(|k| !keys.contains(&k.as_str())) {
        return Err(err(format!("unknown key {k:?}; keys: {}", keys.join(", "))));
    }
    Ok(m)
}

/// Encodes a telecommand from its JSON form; a packet the robot would refuse is refused here
/// too, by the same check.
pub fn encode_tc(json: &str) -> Result<Vec<u8>, PusCodecError> {
    let m = &object(json, &TC_KEYS, tc_input)?;
    let get = |k: &str, default: u64, max: u64| -> Result<u64, PusCodecError> {
        m.get(k).map_or(Ok(default), |v| uint(v, k, max, tc_input))
    };
    let apid = get("apid", u64::from(ROBOT_APID_BASE + 1), 0x7FF)? as u16;
    let seq = get("seq_count", 0, 0x3FFF)? as u16;
    let source_id = get("source_id", 0, 0xFFFF)? as u16;
    let ack = m.get("ack").map_or(Ok(AckFlags::ALL), ack_of)?;
    let (service, subservice, data) = match m.get("function") {
        Some(Value::String(name)) => {
            let d = function_data(name, m.get("args"))?;
            (8, 1, d)
        }
        Some(other) => {
            return Err(tc_input(format!(
                "function: expected a name, found {other}"
            )))
        }
        None => {
            if m.contains_key("args") {
                return Err(tc_input("args without function"));
            }
            let service = get("service", 0, 255)? as u8;
            let subservice = get("subservice", 0, 255)? as u8;
            if !m.contains_key("service") || !m.contains_key("subservice") {
                return Err(tc_input(
                    "give \"function\" (TC(8,1)) or \"service\" and \"subservice\"",
                ));
            }
            let data = match (service, subservice) {
                (3, 5) | (3, 6) => vec![1, housekeeping::ROBOT_SID],
                (3, 31) => {
                    let ms = m
                        .get("interval_ms")
                        .ok_or_else(|| tc_input("TC(3,31): interval_ms missing"))?;
                    let ms = uint(ms, "interval_ms", u64::from(u32::MAX), tc_input)? as u32;
                    let mut d = vec![1, housekeeping::ROBOT_SID];
                    d.extend_from_slice(&ms.to_be_bytes());
                    d
                }
                _ => Vec::new(),
            };
            (service, subservice, data)
        }
    };
    if m.contains_key("interval_ms") && (service, subservice) != (3, 31) {
        return Err(tc_input("interval_ms belongs to TC(3,31) only"));
    }
    let tc = TcRepr {
        apid: Apid::new(apid).map_err(|e| tc_input(e.to_string()))?,
        seq_count: SeqCount::new(seq).map_err(|e| tc_input(e.to_string()))?,
        header: TcSecondaryHeader {
            ack,
            service,
            subservice,
            source_id,
        },
        app_data: &data,
    };
    let mut buf = vec![0u8; tc.len()];
    tc.emit(&mut buf).map_err(|e| tc_input(e.to_string()))?;
    let decoded = decode_tc(&buf, &[apid])?;
    check_derived(
        m,
        &decoded,
        &[
            "service",
            "subservice",
            "request",
            "function_id",
            "command",
            "app_data",
            "len",
            "ack_bits",
        ],
        tc_input,
    )?;
    Ok(buf)
}

/// The keys of `given` among `derived` must equal the decoded packet's.
pub(crate) fn check_derived(
    given: &Map<String, Value>,
    decoded: &Value,
    derived: &[&str],
    err: fn(String) -> PusCodecError,
) -> Result<(), PusCodecError> {
    for k in derived {
        if let Some(v) = given.get(*k) {
            let d = decoded.get(*k).unwrap_or(&Value::Null);
            if v != d {
                return Err(err(format!(
                    "{k} = {v} disagrees with the packet, which has {d}"
                )));
            }
        }
    }
    Ok(())
}

fn args_json(f: FunctionId, data: &[u8]) -> Value {
    let mut out = Map::new();
    let Some(row) = spec::function(f) else {
        return Value::Object(out);
    };
    let mut at = 1;
    for a in &row.args {
        let n = (a.bits() / 8) as usize;
        let v = data.get(at..at + n).map_or(0, |b| {
            b.iter().fold(0u32, |acc, x| acc << 8 | u32::from(*x))
        });
        at += n;
        let value = if a.is_state() {
            json!(char::from(v as u8).to_string())
        } else {
            json!(v)
        };
        out.insert(a.name.clone(), value);
    }
    Value::Object(out)
}

/// Decodes a telecommand (accepted APIDs `apids`) to its JSON form.
pub fn decode_tc(bytes: &[u8], apids: &[u16]) -> Result<Value, PusCodecError> {
    let (tc, request) = read_tc(bytes, apids).map_err(refused)?;
    let h = tc.header;
    let mut m = Map::new();
    m.insert("apid".into(), json!(tc.apid.get()));
    m.insert("seq_count".into(), json!(tc.seq_count.get()));
    m.insert("source_id".into(), json!(h.source_id));
    m.insert(
        "ack".into(),
        serde_json::to_value(h.ack).unwrap_or(Value::Null),
    );
    m.insert("ack_bits".into(), json!(h.ack.bits()));
    m.insert("service".into(), json!(h.service));
    m.insert("subservice".into(), json!(h.subservice));
    m.insert(
        "request".into(),
        json!(spec::tc_name(h.service, h.subservice).unwrap_or("unknown")),
    );
    match request {
        Request::Function(c) => {
            let f = FunctionId::of(&c);
            if let Some(f) = f {
                m.insert("function".into(), json!(f.name()));
                m.insert("function_id".into(), json!(f.id()));
                m.insert("args".into(), args_json(f, tc.app_data));
            }
            m.insert(
                "command".into(),
                serde_json::to_value(c).unwrap_or(Value::Null),
            );
        }
        Request::HkInterval { ms } => {
            m.insert("interval_ms".into(), json!(ms));
        }
        Request::AreYouAlive | Request::HkEnable | Request::HkDisable => {}
    }
    m.insert("app_data".into(), json!(hex(tc.app_data)));
    m.insert("len".into(), json!(bytes.len()));
    Ok(Value::Object(m))
}

// ---- telemetry ---------------------------------------------------------------------------

const TM_KEYS: [&str; 14] = [
    "apid",
    "seq_count",
    "time_ref_status",
    "service",
    "subservice",
    "counter",
    "destination_id",
    "time",
    "source_data",
    "housekeeping",
    "report",
    // derived keys of the decoded form, checked when given
    "parameters",
    "event",
    "len",
];

fn tm_refused(name: &'static str, message: String) -> PusCodecError {
    PusCodecError::Refused { name, message }
}

fn stage_name(s: Stage) -> &'static str {
    match s {
        Stage::Acceptance => "acceptance",
        Stage::Start => "start",
        Stage::Completion => "completion",
    }
}

fn report_json(r: &Report) -> Value {
    json!({
        "stage": stage_name(r.stage),
        "success": r.failure.is_none(),
        "request": {"apid": r.request.apid, "seq_count": r.request.seq_count},
        "failure": r.failure.map(|f| json!({
            "code": f.code,
            "data": f.data,
            "name": spec::failure_label(f.code),
        })),
    })
}

fn report_of(v: &Value) -> Result<(u8, Vec<u8>), PusCodecError> {
    let stage = match v.get("stage").and_then(Value::as_str) {
        Some("acceptance") => Stage::Acceptance,
        Some("start") => Stage::Start,
        Some("completion") => Stage::Completion,
        _ => return Err(tm_input("report.stage: acceptance, start or completion")),
    };
    let req = v
        .get("request")
        .ok_or_else(|| tm_input("report.request missing"))?;
    let field = |k: &str, max| {
        req.get(k)
            .ok_or_else(|| tm_input(format!("report.request.{k} missing")))
            .and_then(|x| uint(x, k, max, tm_input))
    };
    let request = RequestId {
        apid: field("apid", 0x7FF)? as u16,
        seq_count: field("seq_count", 0x3FFF)? as u16,
    };
    let failure = match v.get("failure") {
        None | Some(Value::Null) => None,
        Some(f) => Some(Failure {
            code: f
                .get("code")
                .map_or(Err(tm_input("report.failure.code missing")), |x| {
                    uint(x, "code", 0xFFFF, tm_input)
                })? as u16,
            data: f
                .get("data")
                .map_or(Ok(0), |x| uint(x, "data", u64::from(u32::MAX), tm_input))?
                as u32,
        }),
    };
    let r = Report {
        stage,
        request,
        failure,
    };
    let mut b = [0u8; 16];
    let n = r.emit(&mut b);
    Ok((r.subservice(), b.get(..n).unwrap_or(&[]).to_vec()))
}

/// The event of TM(5,`subservice`) source data, read by the library (`Event::parse`: the
/// bytes `Event::to_bytes` writes, in the event's severity).
fn event_json(subservice: u8, data: &[u8]) -> Result<Value, PusCodecError> {
    let event = Event::parse(subservice, data)
        .map_err(|e| tm_refused("source-data", format!("TM(5,{subservice}): {e}")))?;
    let id = event.id();
    let extra = match event {
        Event::ModeChanged { from, to } => json!({"from": from.name(), "to": to.name()}),
        Event::Attempt {
            pair,
            attempt,
            result,
        } => json!({"pair": pair.number(), "attempt": attempt,
                    "result": ATTEMPT_RESULTS.iter().find(|(r, _)| *r == result).map(|(_, n)| *n)}),
        Event::Cleared(f) => json!({"faults": f.iter().map(|x| x.name()).collect::<Vec<_>>()}),
        Event::Fault { fault, mode } => json!({"fault": fault.name(), "mode": mode.name()}),
        Event::Restarted(b) => json!({"cause": b.cause.name(), "count": b.count}),
        Event::LinkStopped { board, reason } => json!({"board": board,
            "reason": mmic::pus::event::LINK_STOPPED_REASONS.get(usize::from(reason))}),
        Event::Security {
            reason,
            refused,
            spi,
        } => json!({"reason": mmic::link::sdls::SdlsRefusal::NAMES.get(usize::from(reason)),
                    "refused": refused, "spi": spi}),
    };
    let name = spec::event_ids()
        .ok()
        .and_then(|ids| ids.into_iter().find(|(i, _)| *i == id).map(|(_, n)| n));
    let mut v = json!({"id": id, "name": name, "severity": subservice});
    if let (Value::Object(m), Value::Object(x)) = (&mut v, extra) {
        m.extend(x);
    }
    Ok(v)
}

/// Decodes a telemetry packet (accepted APIDs `apids`) to its JSON form: every header field
/// and the report, housekeeping parameters or event it carries.
pub fn decode_tm(bytes: &[u8], apids: &[u16]) -> Result<Value, PusCodecError> {
    let tm = TmRepr::parse(bytes, apids).map_err(|e| refused(e.into()))?;
    let h = tm.header;
    let d = tm.source_data;
    let mut m = Map::new();
    m.insert("apid".into(), json!(tm.apid.get()));
    m.insert("seq_count".into(), json!(tm.seq_count.get()));
    m.insert("time_ref_status".into(), json!(h.time_ref_status.get()));
    m.insert("service".into(), json!(h.service));
    m.insert("subservice".into(), json!(h.subservice));
    m.insert("counter".into(), json!(h.counter));
    m.insert("destination_id".into(), json!(h.destination_id));
    m.insert(
        "time".into(),
        json!({"coarse": h.time.coarse, "fine": h.time.fine}),
    );
    m.insert("source_data".into(), json!(hex(d)));
    m.insert("len".into(), json!(bytes.len()));
    let known = spec::services()
        .tm
        .iter()
        .filter(|t| t.service == h.service)
        .collect::<Vec<_>>();
    if known.is_empty() {
        return Err(tm_refused(
            "unknown-service",
            format!(
                "TM({},{}): the robot sends services 1, 3, 5 and 17",
                h.service, h.subservice
            ),
        ));
    }
    if !known.iter().any(|t| t.subservices.contains(&h.subservice)) {
        return Err(tm_refused(
            "unknown-subservice",
            format!(
                "TM({},{}) is no report the robot sends",
                h.service, h.subservice
            ),
        ));
    }
    let source = |e: String| {
        tm_refused(
            "source-data",
            format!("TM({},{}): {e}", h.service, h.subservice),
        )
    };
    match h.service {
        1 => {
            let r = Report::parse(h.subservice, d).map_err(|e| source(e.to_string()))?;
            m.insert("report".into(), report_json(&r));
        }
        3 => {
            let hb = housekeeping::parse(d).map_err(|e| source(e.to_string()))?;
            let params: Map<String, Value> = housekeeping::FIELDS
                .iter()
                .zip(housekeeping::values(&hb))
                .map(|(f, v)| (f.name.to_string(), json!(v)))
                .collect();
            m.insert(
                "housekeeping".into(),
                serde_json::to_value(hb).unwrap_or(Value::Null),
            );
            m.insert("parameters".into(), Value::Object(params));
        }
        5 => {
            m.insert("event".into(), event_json(h.subservice, d)?);
        }
        _ => {
            if !d.is_empty() {
                return Err(source(format!("{} octets, expected none", d.len())));
            }
        }
    }
    Ok(Value::Object(m))
}

/// Encodes a telemetry packet from its JSON form: the header keys (APID 257, counts 0,
/// time 0 unless given) and the source data as `source_data` (hex), `housekeeping` (a
/// heartbeat's JSON, TM(3,25)) or `report` (ST\[1\]), the first of these given; the packet must
/// decode (the robot's TM only), and every other key given must agree with it (so `decode
/// pus-tm`'s output encodes back to the same bytes).
pub fn encode_tm(json: &str) -> Result<Vec<u8>, PusCodecError> {
    let m = &object(json, &TM_KEYS, tm_input)?;
    let get = |k: &str, default: u64, max: u64| -> Result<u64, PusCodecError> {
        m.get(k).map_or(Ok(default), |v| uint(v, k, max, tm_input))
    };
    let apid = get("apid", u64::from(ROBOT_APID_BASE + 1), 0x7FF)? as u16;
    let source_key = ["source_data", "housekeeping", "report"]
        .into_iter()
        .find(|k| m.contains_key(*k))
        .unwrap_or("");
    let (mut service, mut subservice, data) = if let Some(s) = m.get("source_data") {
        let text = s
            .as_str()
            .ok_or_else(|| tm_input("source_data: expected hex"))?;
        let d = crate::codec::from_hex(text).map_err(|e| tm_input(format!("source_data: {e}")))?;
        (None, None, d)
    } else if let Some(hb) = m.get("housekeeping") {
        let hb: HeartbeatRepr = serde_json::from_value(hb.clone())
            .map_err(|e| tm_input(format!("housekeeping: {e}")))?;
        let mut b = [0u8; housekeeping::REPORT_LEN];
        housekeeping::emit(&hb, &mut b);
        (Some(3), Some(25), b.to_vec())
    } else if let Some(r) = m.get("report") {
        let (sub, d) = report_of(r)?;
        (Some(1), Some(sub), d)
    } else {
        (None, None, Vec::new())
    };
    if m.contains_key("service") || service.is_none() {
        service = Some(get("service", 0, 255)? as u8);
    }
    if m.contains_key("subservice") || subservice.is_none() {
        subservice = Some(get("subservice", 0, 255)? as u8);
    }
    let time = match m.get("time") {
        None => Cuc::default(),
        Some(t) => serde_json::from_value(t.clone()).map_err(|e| tm_input(format!("time: {e}")))?,
    };
    let tm = TmRepr {
        apid: Apid::new(apid).map_err(|e| tm_input(e.to_string()))?,
        seq_count: SeqCount::new(get("seq_count", 0, 0x3FFF)? as u16)
            .map_err(|e| tm_input(e.to_string()))?,
        header: TmSecondaryHeader {
            time_ref_status: TimeRefStatus::new(get("time_ref_status", 0, 15)? as u8)
                .map_err(|e| tm_input(e.to_string()))?,
            service: service.unwrap_or(0),
            subservice: subservice.unwrap_or(0),
            counter: get("counter", 0, 0xFFFF)? as u16,
            destination_id: get("destination_id", 0, 0xFFFF)? as u16,
            time,
        },
        source_data: &data,
    };
    let mut buf = vec![0u8; tm.len().min(MAX_PACKET_LEN)];
    tm.emit(&mut buf).map_err(|e| tm_input(e.to_string()))?;
    let decoded = decode_tm(&buf, &[apid])?;
    let derived: Vec<&str> = [
        "service",
        "subservice",
        "source_data",
        "housekeeping",
        "report",
        "parameters",
        "event",
        "len",
    ]
    .into_iter()
    .filter(|k| *k != source_key)
    .collect();
    check_derived(m, &decoded, &derived, tm_input)?;
    Ok(buf)
}
