//! `mmic xtce`: the XTCE 1.2 mission database of the robot's PUS-C packets, generated from the
//! library and spec/ — the TM(3,25) layout from `mmic::pus::housekeeping::FIELDS`, the ST\[8\]
//! functions and their argument ranges from spec/ccsds/functions.toml, the failure codes and
//! events from spec/ccsds/services.toml, the fault names from spec/faults.toml, modes,
//! refusals and states from the library. The committed copy is spec/ccsds/mmic.xtce.xml
//! (a test fails when it is stale); ground/README.md records which constructs YAMCS 5.12.8
//! takes. Also the ccsdspy field list of TM(3,25) ([`ccsdspy_csv`],
//! spec/ccsds/hk-3-25.ccsdspy.csv).
//!
//! The output is deterministic: no date, tables in their files' order.

use crate::pus::ATTEMPT_RESULTS;
use crate::spec::{self, label, Arg};
use mmic::ccsds::tm::{field as tm_field, TM_HEADER_LEN};
use mmic::mode::Mode;
use mmic::motion::State;
use mmic::pus::housekeeping::{self, Field, FIELDS, MAX_INTERVAL_MS, MIN_INTERVAL_MS, ROBOT_SID};
use mmic::pus::ROBOT_APID_BASE;
use mmic::refusal::Refusal;
use std::fmt::Write;

/// First robot APID (robot 1) and last (robot 255): the range the containers restrict to.
const APID_MIN: u16 = ROBOT_APID_BASE + 1;
const APID_MAX: u16 = ROBOT_APID_BASE + 255;

/// How long each ST\[1\] stage may take after the command's release (ISO 8601 durations). All
/// windows are relative to the release: a window relative to the last verifier opens only once
/// that verifier passed, too late for reports sent together (TC(3,x): TM(1,1), (1,3), (1,7) at once).
const ACCEPT_WINDOW: &str = "PT10S";
const START_WINDOW: &str = "PT30S";
const COMPLETE_WINDOW: &str = "PT300S";
const FAILED_WINDOW: &str = "PT600S";

/// XML-escapes text for attributes and element content.
fn esc(s: &str) -> String {
    s.replace('&', "&amp;")
        .replace('<', "&lt;")
        .replace('>', "&gt;")
        .replace('"', "&quot;")
}

/// The parameter type of a housekeeping field (by its unit, or its name for enumerations).
pub fn hk_type(f: &Field) -> Result<String, String> {
    let bits = f.len * 8;
    Ok(match (f.unit, f.name) {
        ("number", _) => format!("uint{bits}"),
        ("enum", "mode") => "mode_type".into(),
        ("enum", "refusal") => "refusal_type".into(),
        ("enum", "active_bolter") => "bolter_pair_type".into(),
        ("bitmap", "faults") => "faults_type".into(),
        ("state", _) => "state_type".into(),
        ("bool", _) => "bool_type".into(),
        ("mV", _) => format!("millivolts_u{bits}"),
        ("mA", _) => format!("milliamps_u{bits}"),
        ("us", _) => format!("microseconds_u{bits}"),
        ("0.01 deg", _) => format!("centidegrees_u{bits}"),
        (u, n) => {
            return Err(format!(
                "housekeeping field {n}: no XTCE type for unit {u:?} (host/src/xtce.rs)"
            ))
        }
    })
}

struct Xml {
    s: String,
}

impl Xml {
    fn line(&mut self, depth: usize, text: &str) {
        let _ = writeln!(self.s, "{}{}", "  ".repeat(depth), text);
    }
}

fn int_ptype(x: &mut Xml, name: &str, bits: usize, unit: Option<(&str, &str)>, desc: Option<&str>) {
    let d = desc.map_or(String::new(), |d| {
        format!(" shortDescription=\"{}\"", esc(d))
    });
    x.line(
        3,
        &format!("<IntegerParameterType name=\"{name}\" signed=\"false\"{d}>"),
    );
    if let Some((u, ud)) = unit {
        x.line(
            4,
            &format!(
                "<UnitSet><Unit description=\"{}\">{}</Unit></UnitSet>",
                esc(ud),
                esc(u)
            ),
        );
    }
    x.line(4, &format!("<IntegerDataEncoding sizeInBits=\"{bits}\" />"));
    x.line(3, "</IntegerParameterType>");
}

fn enum_type(
    x: &mut Xml,
    kind: &str,
    name: &str,
    bits: usize,
    values: &[(u32, String)],
    desc: &str,
) {
    x.line(
        3,
        &format!(
            "<Enumerated{kind}Type name=\"{name}\" shortDescription=\"{}\">",
            esc(desc)
        ),
    );
    x.line(4, &format!("<IntegerDataEncoding sizeInBits=\"{bits}\" />"));
    x.line(4, "<EnumerationList>");
    for (v, l) in values {
        x.line(
            5,
            &format!("<Enumeration value=\"{v}\" label=\"{}\" />", esc(l)),
        );
    }
    x.line(4, "</EnumerationList>");
    x.line(3, &format!("</Enumerated{kind}Type>"));
}

fn modes() -> Vec<(u32, String)> {
    Mode::ALL
        .iter()
        .map(|m| (u32::from(m.to_wire()), label(m.name())))
        .collect()
}

fn states(none: bool) -> Vec<(u32, String)> {
    let mut v: Vec<(u32, String)> = if none {
        vec![(0, "NONE".into())]
    } else {
        Vec::new()
    };
    v.extend(
        State::ALL
            .iter()
            .map(|s| (u32::from(s.to_wire()), char::from(s.to_wire()).to_string())),
    );
    v
}

fn param(x: &mut Xml, name: &str, ty: &str, desc: &str) {
    x.line(
        3,
        &format!(
            "<Parameter name=\"{name}\" parameterTypeRef=\"{ty}\" shortDescription=\"{}\" />",
            esc(desc)
        ),
    );
}

fn entries(x: &mut Xml, names: &[&str]) {
    x.line(3, "<EntryList>");
    for n in names {
        x.line(4, &format!("<ParameterRefEntry parameterRef=\"{n}\" />"));
    }
    x.line(3, "</EntryList>");
}

fn cond(param: &str, op: &str, value: u32) -> String {
    format!(
        "<Condition><ParameterInstanceRef parameterRef=\"{param}\" /><ComparisonOperator>{}</ComparisonOperator><Value>{value}</Value></Condition>",
        esc(op)
    )
}

/// A container with entries, deriving from `base` under a restriction (comparisons ANDed).
fn container(
    x: &mut Xml,
    name: &str,
    desc: &str,
    names: &[&str],
    base: &str,
    cmp: &[(&str, &str, u32)],
    or: Option<(&str, &[u32])>,
) {
    x.line(
        2,
        &format!(
            "<SequenceContainer name=\"{name}\" shortDescription=\"{}\">",
            esc(desc)
        ),
    );
    entries(x, names);
    x.line(3, &format!("<BaseContainer containerRef=\"{base}\">"));
    x.line(4, "<RestrictionCriteria>");
    match or {
        None => {
            x.line(5, "<ComparisonList>");
            for (p, op, v) in cmp {
                let attr = if *op == "==" {
                    String::new()
                } else {
                    format!(" comparisonOperator=\"{}\"", esc(op))
                };
                x.line(6, &format!("<Comparison parameterRef=\"{p}\" value=\"{v}\"{attr} useCalibratedValue=\"false\" />"));
            }
            x.line(5, "</ComparisonList>");
        }
        Some((p, values)) => {
            x.line(5, "<BooleanExpression>");
            x.line(6, "<ANDedConditions>");
            for (q, op, v) in cmp {
                x.line(7, &cond(q, op, *v));
            }
            x.line(7, "<ORedConditions>");
            for v in values {
                x.line(8, &cond(p, "==", *v));
            }
            x.line(7, "</ORedConditions>");
            x.line(6, "</ANDedConditions>");
            x.line(5, "</BooleanExpression>");
        }
    }
    x.line(4, "</RestrictionCriteria>");
    x.line(3, "</BaseContainer>");
    x.line(2, "</SequenceContainer>");
}

fn arg_type_name(function: &str, a: &Arg) -> String {
    format!("{function}_{}_type", a.name)
}

/// One ST\[1\] verifier of `pus-tc`: a `java-expression` algorithm (compiled by YAMCS with its
/// bundled Janino) that passes on a report of one of `subservices` whose request ID is the TC's
/// (APID argument, sequence count the postprocessor published) and returns nothing on any other
/// packet. Not a `BooleanExpression`: YAMCS 5.12.8 gives each such verifier its own subscription in
/// `ParameterProcessorManager` and drops it on the timer thread when it matched, while the TM
/// thread may be dispatching the next packet to it: `sendToProcessor(null)` throws
/// (NullPointerException at ParameterProcessorManager.java:263) and every later verifier misses
/// that packet. The gateway sends TM(1,1), (1,3), (1,7) back to back, so `Started` lost its (1,3)
/// (issue 24). Algorithm verifiers get TM through the AlgorithmManager's one subscription, taken at
/// start and never dropped, and their per-command contexts are copy-on-write lists.
/// The failure verifier returns `failure_code` of that report as the return value (the command's
/// error `Verifier Failed return: <code>`); a `ReturnParmRef` would read the last value cache,
/// which YAMCS updates only after the algorithms ran: the previous failure's code.
fn verifier(
    x: &mut Xml,
    element: &str,
    name: Option<&str>,
    subservices: &[u32],
    window: &str,
    fail_on_timeout: bool,
    ret: bool,
) {
    let n = name.map_or(String::new(), |n| format!(" name=\"{n}\""));
    let stage = name.unwrap_or(element.trim_end_matches("Verifier"));
    x.line(4, &format!("<{element}{n}>"));
    x.line(
        5,
        &format!(
            "<CustomAlgorithm name=\"st1_{}\" shortDescription=\"TM(1,{}) with the TC's request ID\">",
            stage.to_lowercase(),
            subservices.iter().map(u32::to_string).collect::<Vec<_>>().join("/")
        ),
    );
    // An input the packet at hand lacks keeps an earlier packet's value: hence `service == 1`,
    // which makes every request-ID field one of this packet (the verification-report container).
    let matches = subservices
        .iter()
        .map(|s| format!("s == {s}"))
        .collect::<Vec<_>>()
        .join(" || ");
    let result = if ret {
        "new org.yamcs.commanding.VerificationResult(true, null, failure_code.getEngValue())"
    } else {
        "Boolean.TRUE"
    };
    let text = format!(
        "if (apid == null || seq_count == null || service == null || subservice == null || req_type == null || req_apid == null || req_seq_count == null{}) return null; \
         if (service.getEngValue().toLong() != 1 || req_type.getEngValue().toLong() != 1 || req_apid.getEngValue().toLong() != apid.getEngValue().toLong() || req_seq_count.getEngValue().toLong() != seq_count.getEngValue().toLong()) return null; \
         long s = subservice.getEngValue().toLong(); \
         if ({matches}) return {result}; \
         return null;",
        if ret { " || failure_code == null" } else { "" },
    );
    x.line(
        6,
        &format!(
            "<AlgorithmText language=\"java-expression\">{}</AlgorithmText>",
            esc(&text)
        ),
    );
    x.line(6, "<InputSet>");
    let mut inputs = vec![
        ("/yamcs/cmd/arg/apid", "apid"),
        ("/yamcs/cmdHist/ccsds-seqcount", "seq_count"),
        ("/MMIC/service", "service"),
        ("/MMIC/subservice", "subservice"),
        ("/MMIC/req_type", "req_type"),
        ("/MMIC/req_apid", "req_apid"),
        ("/MMIC/req_seq_count", "req_seq_count"),
    ];
    if ret {
        inputs.push(("/MMIC/failure_code", "failure_code"));
    }
    // TM inputs are `instance="1"`: in 5.12.8 an input's instance 0 falls back to the last value
    // cache when the delivery at hand lacks it, and YAMCS re-reads every input of the command's
    // algorithms on each command-history update of the command, on the thread that published it
    // (e.g. `Acknowledge_Sent`, by the TC link, while the TM thread handles the TM(1,1)): the cache's
    // older values overwrote the report's between the algorithm's update and its run, and `Accepted`
    // missed its report. An instance above 0 never reads the cache (`ProcessingContext.get`,
    // PACKET_START_ACROSS_PACKETS) and, for a parameter the delivery has once, is that value
    // (`ParameterValueList.get(p, n)` returns the last one found).
    for (p, i) in inputs {
        let instance = if p.starts_with("/MMIC/") {
            " instance=\"1\""
        } else {
            ""
        };
        x.line(
            7,
            &format!(
                "<InputParameterInstanceRef parameterRef=\"{p}\"{instance} inputName=\"{i}\" />"
            ),
        );
    }
    x.line(6, "</InputSet>");
    x.line(5, "</CustomAlgorithm>");
    x.line(
        5,
        &format!(
            "<CheckWindow timeToStopChecking=\"{window}\" timeWindowIsRelativeTo=\"commandRelease\" />"
        ),
    );
    if fail_on_timeout {
        x.line(5, "<AncillaryDataSet><AncillaryData name=\"yamcs.onTimeout\">FAIL</AncillaryData></AncillaryDataSet>");
    }
    x.line(4, &format!("</{element}>"));
}

/// The whole mission database.
pub fn generate() -> Result<String, String> {
    let svc = spec::services();
    let functions = spec::functions();
    if functions.is_empty() || svc.tc.is_empty() || spec::faults().is_empty() {
        return Err(
            "spec/ccsds/functions.toml, services.toml or spec/faults.toml did not parse".into(),
        );
    }
    let mut x = Xml { s: String::new() };
    x.line(0, "<?xml version=\"1.0\" encoding=\"UTF-8\"?>");
    x.line(0, "<!--");
    x.line(
        0,
        "  Generated by `mmic xtce` (host/src/xtce.rs) from the library and spec/: do not edit.",
    );
    x.line(
        0,
        "  Regenerate: mmic xtce, written to spec/ccsds/mmic.xtce.xml (see mmic xtce -h).",
    );
    x.line(0, "  PUS-C (ECSS-E-ST-70-41C) over CCSDS 133.0-B-2 space packets, big-endian; APID 0x100 + n for robot n");
    x.line(0, "  (257..=511). TM secondary header: PUS version 2, time reference status, service, subservice,");
    x.line(0, "  message type counter, destination ID, CUC time 4 + 2 octets (implicit P-field 0x2E) since the");
    x.line(0, "  gateway's power-on. Every packet ends with the CRC-16/CCITT-FALSE packet error control, checked by");
    x.line(0, "  YAMCS's PusPacketPreprocessor and written by its PusCommandPostprocessor (ground/README.md).");
    x.line(0, "-->");
    x.line(
        0,
        "<SpaceSystem name=\"MMIC\" xmlns=\"http://www.omg.org/spec/XTCE/20180204\"",
    );
    x.line(
        0,
        "             xmlns:xsi=\"http://www.w3.org/2001/XMLSchema-instance\"",
    );
    x.line(0, "             xsi:schemaLocation=\"http://www.omg.org/spec/XTCE/20180204 https://www.omg.org/spec/XTCE/20180204/SpaceSystem.xsd\">");
    x.line(1, "<Header validationStatus=\"Working\" version=\"1\" />");
    x.line(1, "<TelemetryMetaData>");
    x.line(2, "<ParameterTypeSet>");
    for bits in [1, 2, 3, 4, 8, 11, 14, 16, 24, 32] {
        int_ptype(&mut x, &format!("uint{bits}"), bits, None, None);
    }
    int_ptype(
        &mut x,
        "met_coarse_type",
        32,
        Some(("s", "second")),
        Some("CUC coarse time: whole seconds since the gateway's power-on"),
    );
    int_ptype(
        &mut x,
        "met_fine_type",
        16,
        Some(("2^-16 s", "1/65536 s")),
        Some("CUC fine time"),
    );
    let mut units: Vec<(String, usize, &str, &str)> = Vec::new();
    for f in FIELDS.iter() {
        let t = hk_type(f)?;
        let (u, d) = match f.unit {
            "mV" => ("mV", "millivolt"),
            "mA" => ("mA", "milliampere"),
            "us" => ("us", "microsecond (servo pulse width)"),
            "0.01 deg" => ("0.01 deg", "hundredth of a degree"),
            _ => continue,
        };
        if !units.iter().any(|(n, ..)| *n == t) {
            units.push((t, f.len * 8, u, d));
        }
    }
    for (name, bits, u, d) in &units {
        int_ptype(&mut x, name, *bits, Some((u, d)), None);
    }
    enum_type(
        &mut x,
        "Parameter",
        "mode_type",
        8,
        &modes(),
        "operating mode (spec/modes.toml)",
    );
    let mut refusals = vec![(0, "ACCEPTED".to_string())];
    refusals.extend(
        Refusal::ALL
            .iter()
            .map(|r| (u32::from(r.to_wire()), label(r.name()))),
    );
    enum_type(
        &mut x,
        "Parameter",
        "refusal_type",
        8,
        &refusals,
        "heartbeat byte 62: the outcome of the command the heartbeat reports on, 0 = accepted, else its refusal code (spec/modes.toml)",
    );
    let mut pairs = vec![(0, "NONE".to_string())];
    pairs.extend((1..=4).map(|p| (p, format!("PAIR_{p}"))));
    enum_type(
        &mut x,
        "Parameter",
        "bolter_pair_type",
        8,
        &pairs,
        "fastener pair",
    );
    enum_type(
        &mut x,
        "Parameter",
        "state_type",
        8,
        &states(true),
        "motion state a..o (Table 5), ASCII; 0 none",
    );
    enum_type(
        &mut x,
        "Parameter",
        "bool_type",
        8,
        &[(0, "FALSE".into()), (1, "TRUE".into())],
        "0 false, 1 true",
    );
    let bits: Vec<String> = spec::faults()
        .iter()
        .map(|f| format!("bit {} {}", f.bit, f.name))
        .collect();
    int_ptype(
        &mut x,
        "faults_type",
        32,
        None,
        Some(&format!(
            "latched fault map (spec/faults.toml): {}",
            bits.join(", ")
        )),
    );
    let codes: Vec<(u32, String)> = spec::failure_codes()?
        .into_iter()
        .map(|(c, l)| (u32::from(c), l))
        .collect();
    enum_type(
        &mut x,
        "Parameter",
        "failure_code_type",
        16,
        &codes,
        "ST[1] failure code (spec/ccsds/services.toml)",
    );
    let events: Vec<(u32, String)> = spec::event_ids()?
        .into_iter()
        .map(|(c, l)| (u32::from(c), label(&l)))
        .collect();
    enum_type(
        &mut x,
        "Parameter",
        "event_id_type",
        16,
        &events,
        "ST[5] event definition ID (spec/ccsds/services.toml)",
    );
    let results: Vec<(u32, String)> = ATTEMPT_RESULTS
        .iter()
        .map(|(r, n)| (*r as u32, label(n)))
        .collect();
    enum_type(
        &mut x,
        "Parameter",
        "attempt_result_type",
        8,
        &results,
        "how a bolting attempt ended",
    );
    x.line(2, "</ParameterTypeSet>");

    x.line(2, "<ParameterSet>");
    let header: [(&str, &str, &str); 15] = [
        ("ccsds_version", "uint3", "packet version number"),
        ("ccsds_type", "uint1", "packet type (0 TM)"),
        ("ccsds_sec_hdr", "uint1", "secondary header flag"),
        ("ccsds_apid", "uint11", "APID: 0x100 + robot number"),
        ("ccsds_seq_flags", "uint2", "sequence flags (3 unsegmented)"),
        (
            "ccsds_seq_count",
            "uint14",
            "packet sequence count (per APID)",
        ),
        ("ccsds_length", "uint16", "packet data length (octets - 7)"),
        ("pus_version", "uint4", "PUS version number (2, PUS-C)"),
        (
            "time_ref_status",
            "uint4",
            "spacecraft time reference status",
        ),
        ("service", "uint8", "service type"),
        ("subservice", "uint8", "message subtype"),
        (
            "msg_type_counter",
            "uint16",
            "message type counter (per APID and type)",
        ),
        (
            "destination_id",
            "uint16",
            "destination ID: the source ID of the TC answered, 0 unsolicited",
        ),
        ("met_coarse", "met_coarse_type", "CUC coarse time"),
        ("met_fine", "met_fine_type", "CUC fine time"),
    ];
    for (n, t, d) in header {
        param(&mut x, n, t, d);
    }
    param(&mut x, "hk_sid", "uint8", "housekeeping structure ID (1)");
    for f in FIELDS.iter() {
        param(&mut x, f.name, &hk_type(f)?, f.meaning);
    }
    let req: [(&str, &str, &str); 6] = [
        (
            "req_version",
            "uint3",
            "request ID: the TC's packet version",
        ),
        ("req_type", "uint1", "request ID: packet type (1 TC)"),
        ("req_sec_hdr", "uint1", "request ID: secondary header flag"),
        ("req_apid", "uint11", "request ID: the TC's APID"),
        ("req_seq_flags", "uint2", "request ID: sequence flags"),
        (
            "req_seq_count",
            "uint14",
            "request ID: the TC's sequence count",
        ),
    ];
    for (n, t, d) in req {
        param(&mut x, n, t, d);
    }
    param(
        &mut x,
        "failure_code",
        "failure_code_type",
        "ST[1] failure code",
    );
    param(
        &mut x,
        "failure_data",
        "uint32",
        "ST[1] failure data (spec/ccsds/services.toml)",
    );
    param(
        &mut x,
        "event_id",
        "event_id_type",
        "ST[5] event definition ID",
    );
    param(
        &mut x,
        "event_mode_from",
        "mode_type",
        "mode_changed: mode before",
    );
    param(
        &mut x,
        "event_mode_to",
        "mode_type",
        "mode_changed: mode after",
    );
    param(
        &mut x,
        "event_pair",
        "uint8",
        "bolting_attempt: fastener pair 1..=4",
    );
    param(
        &mut x,
        "event_attempt",
        "uint8",
        "bolting_attempt: attempt 1..=3",
    );
    param(
        &mut x,
        "event_result",
        "attempt_result_type",
        "bolting_attempt: how it ended",
    );
    param(
        &mut x,
        "event_cleared_faults",
        "faults_type",
        "faults_cleared: the cleared fault map",
    );
    param(
        &mut x,
        "event_fault_mode",
        "mode_type",
        "fault: the mode after it",
    );
    param(&mut x, "event_spare8", "uint8", "zero");
    param(&mut x, "event_spare16", "uint16", "zero");
    param(&mut x, "event_spare24", "uint24", "zero");
    x.line(2, "</ParameterSet>");

    x.line(2, "<ContainerSet>");
    x.line(2, "<SequenceContainer name=\"pus-tm\" abstract=\"true\" shortDescription=\"every PUS-C TM packet: primary and secondary header\">");
    let names: Vec<&str> = header.iter().map(|h| h.0).collect();
    entries(&mut x, &names);
    x.line(2, "</SequenceContainer>");
    let robot = [
        ("ccsds_apid", ">=", u32::from(APID_MIN)),
        ("ccsds_apid", "<=", u32::from(APID_MAX)),
    ];
    let with =
        |more: &[(&'static str, &'static str, u32)]| -> Vec<(&'static str, &'static str, u32)> {
            robot.iter().copied().chain(more.iter().copied()).collect()
        };
    let mut hk: Vec<&str> = vec!["hk_sid"];
    hk.extend(FIELDS.iter().map(|f| f.name));
    container(
        &mut x,
        "hk-report",
        "TM(3,25) housekeeping parameter report, structure 1: the heartbeat",
        &hk,
        "pus-tm",
        &with(&[("service", "==", 3), ("subservice", "==", 25)]),
        None,
    );
    let req_names: Vec<&str> = req.iter().map(|r| r.0).collect();
    container(
        &mut x,
        "verification-report",
        "TM(1,x) ST[1] report: the request ID",
        &req_names,
        "pus-tm",
        &with(&[("service", "==", 1)]),
        None,
    );
    let fail_subs: Vec<u32> = svc
        .tm
        .iter()
        .filter(|t| t.service == 1 && t.name == "verification_failure")
        .flat_map(|t| t.subservices.iter().map(|s| u32::from(*s)))
        .collect();
    container(
        &mut x,
        "verification-failure",
        "TM(1,2/4/8): failure code and data after the request ID",
        &["failure_code", "failure_data"],
        "verification-report",
        &[],
        Some(("subservice", &fail_subs)),
    );
    let event_subs: Vec<u32> = svc
        .tm
        .iter()
        .filter(|t| t.service == 5)
        .flat_map(|t| t.subservices.iter().map(|s| u32::from(*s)))
        .collect();
    container(
        &mut x,
        "event-report",
        "TM(5,1..4) event report: the event definition ID (subservice = severity)",
        &["event_id"],
        "pus-tm",
        &with(&[("service", "==", 5)]),
        Some(("subservice", &event_subs)),
    );
    container(
        &mut x,
        "event-mode-changed",
        "event 0x0001 mode_changed",
        &["event_mode_from", "event_mode_to", "event_spare16"],
        "event-report",
        &[("event_id", "==", 1)],
        None,
    );
    container(
        &mut x,
        "event-bolting-attempt",
        "event 0x0002 bolting_attempt",
        &[
            "event_pair",
            "event_attempt",
            "event_result",
            "event_spare8",
        ],
        "event-report",
        &[("event_id", "==", 2)],
        None,
    );
    container(
        &mut x,
        "event-faults-cleared",
        "event 0x0003 faults_cleared",
        &["event_cleared_faults"],
        "event-report",
        &[("event_id", "==", 3)],
        None,
    );
    container(
        &mut x,
        "event-fault",
        "events 0x0100 + n: fault n raised",
        &["event_fault_mode", "event_spare24"],
        "event-report",
        &[("event_id", ">=", 0x100), ("event_id", "<=", 0x1FF)],
        None,
    );
    container(
        &mut x,
        "are-you-alive-report",
        "TM(17,2) are-you-alive report (no data)",
        &[],
        "pus-tm",
        &with(&[("service", "==", 17), ("subservice", "==", 2)]),
        None,
    );
    x.line(2, "</ContainerSet>");
    x.line(1, "</TelemetryMetaData>");

    x.line(1, "<CommandMetaData>");
    x.line(2, "<ArgumentTypeSet>");
    for (n, bits) in [("uint4", 4), ("uint8", 8), ("uint16", 16)] {
        x.line(3, &format!("<IntegerArgumentType name=\"{n}\" signed=\"false\"><IntegerDataEncoding sizeInBits=\"{bits}\" /></IntegerArgumentType>"));
    }
    x.line(3, "<IntegerArgumentType name=\"apid_type\" signed=\"false\" shortDescription=\"robot n's APID: 0x100 + n\">");
    x.line(4, "<IntegerDataEncoding sizeInBits=\"11\" />");
    x.line(4, &format!("<ValidRangeSet><ValidRange minInclusive=\"{APID_MIN}\" maxInclusive=\"{APID_MAX}\" /></ValidRangeSet>"));
    x.line(3, "</IntegerArgumentType>");
    x.line(
        3,
        "<IntegerArgumentType name=\"interval_ms_type\" signed=\"false\">",
    );
    x.line(
        4,
        "<UnitSet><Unit description=\"millisecond\">ms</Unit></UnitSet>",
    );
    x.line(4, "<IntegerDataEncoding sizeInBits=\"32\" />");
    x.line(4, &format!("<ValidRangeSet><ValidRange minInclusive=\"{MIN_INTERVAL_MS}\" maxInclusive=\"{MAX_INTERVAL_MS}\" /></ValidRangeSet>"));
    x.line(3, "</IntegerArgumentType>");
    for f in functions {
        for a in &f.args {
            let name = arg_type_name(&f.name, a);
            if a.is_state() {
                let values: Vec<(u32, String)> = states(false)
                    .into_iter()
                    .filter(|(v, _)| (a.range[0]..=a.range[1]).contains(v))
                    .collect();
                enum_type(
                    &mut x,
                    "Argument",
                    &name,
                    a.bits() as usize,
                    &values,
                    &a.meaning,
                );
            } else {
                x.line(3, &format!("<IntegerArgumentType name=\"{name}\" signed=\"false\" shortDescription=\"{}\">", esc(&a.meaning)));
                if let Some(u) = &a.unit {
                    x.line(4, &format!("<UnitSet><Unit>{}</Unit></UnitSet>", esc(u)));
                }
                x.line(
                    4,
                    &format!("<IntegerDataEncoding sizeInBits=\"{}\" />", a.bits()),
                );
                x.line(4, &format!("<ValidRangeSet><ValidRange minInclusive=\"{}\" maxInclusive=\"{}\" /></ValidRangeSet>", a.range[0], a.range[1]));
                x.line(3, "</IntegerArgumentType>");
            }
        }
    }
    x.line(2, "</ArgumentTypeSet>");

    x.line(2, "<MetaCommandSet>");
    x.line(2, "<MetaCommand name=\"pus-tc\" abstract=\"true\" shortDescription=\"every PUS-C TC to a robot; YAMCS's PusCommandPostprocessor fills in length, sequence count and CRC\">");
    x.line(3, "<ArgumentList>");
    x.line(
        4,
        &format!(
            "<Argument name=\"apid\" argumentTypeRef=\"apid_type\" initialValue=\"{APID_MIN}\" />"
        ),
    );
    x.line(
        4,
        "<Argument name=\"ack_flags\" argumentTypeRef=\"uint4\" initialValue=\"15\" />",
    );
    x.line(4, "<Argument name=\"service\" argumentTypeRef=\"uint8\" />");
    x.line(
        4,
        "<Argument name=\"subservice\" argumentTypeRef=\"uint8\" />",
    );
    x.line(
        4,
        "<Argument name=\"source_id\" argumentTypeRef=\"uint16\" initialValue=\"0\" />",
    );
    x.line(3, "</ArgumentList>");
    x.line(3, "<CommandContainer name=\"pus-tc\">");
    x.line(4, "<EntryList>");
    for l in [
        "<FixedValueEntry name=\"ccsds_version\" binaryValue=\"00\" sizeInBits=\"3\" />",
        "<FixedValueEntry name=\"ccsds_type_tc\" binaryValue=\"01\" sizeInBits=\"1\" />",
        "<FixedValueEntry name=\"ccsds_sec_hdr\" binaryValue=\"01\" sizeInBits=\"1\" />",
        "<ArgumentRefEntry argumentRef=\"apid\" />",
        "<FixedValueEntry name=\"ccsds_seq_flags\" binaryValue=\"03\" sizeInBits=\"2\" />",
        "<FixedValueEntry name=\"ccsds_seq_count\" binaryValue=\"0000\" sizeInBits=\"14\" />",
        "<FixedValueEntry name=\"ccsds_length\" binaryValue=\"0000\" sizeInBits=\"16\" />",
        "<FixedValueEntry name=\"pus_version\" binaryValue=\"02\" sizeInBits=\"4\" />",
        "<ArgumentRefEntry argumentRef=\"ack_flags\" />",
        "<ArgumentRefEntry argumentRef=\"service\" />",
        "<ArgumentRefEntry argumentRef=\"subservice\" />",
        "<ArgumentRefEntry argumentRef=\"source_id\" />",
    ] {
        x.line(5, l);
    }
    x.line(4, "</EntryList>");
    x.line(3, "</CommandContainer>");
    x.line(3, "<!-- ST[1]: matched on the request ID (the TC's APID and sequence count) by algorithms, not BooleanExpression (issue 24, host/src/xtce.rs); success reports need their ack flag (default 15: all) -->");
    x.line(3, "<VerifierSet>");
    verifier(
        &mut x,
        "AcceptedVerifier",
        None,
        &[1],
        ACCEPT_WINDOW,
        true,
        false,
    );
    verifier(
        &mut x,
        "ExecutionVerifier",
        Some("Started"),
        &[3],
        START_WINDOW,
        true,
        false,
    );
    verifier(
        &mut x,
        "CompleteVerifier",
        None,
        &[7],
        COMPLETE_WINDOW,
        true,
        false,
    );
    verifier(
        &mut x,
        "FailedVerifier",
        None,
        &fail_subs,
        FAILED_WINDOW,
        false,
        true,
    );
    x.line(3, "</VerifierSet>");
    x.line(2, "</MetaCommand>");

    let base = |x: &mut Xml, service: u8, subservice: u8| {
        x.line(3, "<BaseMetaCommand metaCommandRef=\"pus-tc\">");
        x.line(4, "<ArgumentAssignmentList>");
        x.line(
            5,
            &format!("<ArgumentAssignment argumentName=\"service\" argumentValue=\"{service}\" />"),
        );
        x.line(
            5,
            &format!(
                "<ArgumentAssignment argumentName=\"subservice\" argumentValue=\"{subservice}\" />"
            ),
        );
        x.line(4, "</ArgumentAssignmentList>");
        x.line(3, "</BaseMetaCommand>");
    };
    for f in functions {
        x.line(
            2,
            &format!(
                "<MetaCommand name=\"{}\" shortDescription=\"TC(8,1) function {}: {}\">",
                f.name,
                f.id,
                esc(&f.name)
            ),
        );
        base(&mut x, 8, 1);
        if !f.args.is_empty() {
            x.line(3, "<ArgumentList>");
            for a in &f.args {
                x.line(
                    4,
                    &format!(
                        "<Argument name=\"{}\" argumentTypeRef=\"{}\" shortDescription=\"{}\" />",
                        a.name,
                        arg_type_name(&f.name, a),
                        esc(&a.meaning)
                    ),
                );
            }
            x.line(3, "</ArgumentList>");
        }
        x.line(3, &format!("<CommandContainer name=\"{}\">", f.name));
        x.line(4, "<EntryList>");
        x.line(
            5,
            &format!(
                "<FixedValueEntry name=\"function_id\" binaryValue=\"{:02x}\" sizeInBits=\"8\" />",
                f.id
            ),
        );
        for a in &f.args {
            x.line(
                5,
                &format!("<ArgumentRefEntry argumentRef=\"{}\" />", a.name),
            );
        }
        x.line(4, "</EntryList>");
        x.line(4, "<BaseContainer containerRef=\"pus-tc\" />");
        x.line(3, "</CommandContainer>");
        x.line(2, "</MetaCommand>");
    }
    for t in svc.tc.iter().filter(|t| t.service != 8) {
        x.line(
            2,
            &format!(
                "<MetaCommand name=\"{}\" shortDescription=\"TC({},{}): {}\">",
                t.name,
                t.service,
                t.subservice,
                esc(&t.app_data)
            ),
        );
        base(&mut x, t.service, t.subservice);
        let interval = (t.service, t.subservice) == (3, 31);
        if interval {
            x.line(3, "<ArgumentList><Argument name=\"interval_ms\" argumentTypeRef=\"interval_ms_type\" /></ArgumentList>");
        }
        x.line(3, &format!("<CommandContainer name=\"{}\">", t.name));
        x.line(4, "<EntryList>");
        if t.service == 3 {
            x.line(
                5,
                "<FixedValueEntry name=\"n\" binaryValue=\"01\" sizeInBits=\"8\" />",
            );
            x.line(5, &format!("<FixedValueEntry name=\"structure_id\" binaryValue=\"{ROBOT_SID:02x}\" sizeInBits=\"8\" />"));
        }
        if interval {
            x.line(5, "<ArgumentRefEntry argumentRef=\"interval_ms\" />");
        }
        x.line(4, "</EntryList>");
        x.line(4, "<BaseContainer containerRef=\"pus-tc\" />");
        x.line(3, "</CommandContainer>");
        x.line(2, "</MetaCommand>");
    }
    x.line(2, "</MetaCommandSet>");
    x.line(1, "</CommandMetaData>");
    x.line(0, "</SpaceSystem>");
    Ok(x.s)
}

/// The ccsdspy field list of TM(3,25): `name,byte_offset,bit_offset,data_type,bit_length`,
/// offsets from the packet's first octet (primary header included), the secondary header's
/// fields, the structure ID, every [`FIELDS`] parameter and the CRC.
pub fn ccsdspy_csv() -> String {
    let mut s = String::from("name,byte_offset,bit_offset,data_type,bit_length\n");
    let t = |r: std::ops::Range<usize>| (r.start, (r.end - r.start) * 8);
    let v = tm_field::VERSION_TIME_REF.start;
    let _ = writeln!(s, "pus_version,{v},0,uint,4\ntime_ref_status,{v},4,uint,4");
    for (name, (at, bits)) in [
        ("service", t(tm_field::SERVICE)),
        ("subservice", t(tm_field::SUBSERVICE)),
        ("msg_type_counter", t(tm_field::COUNTER)),
        ("destination_id", t(tm_field::DESTINATION_ID)),
    ] {
        let _ = writeln!(s, "{name},{at},0,uint,{bits}");
    }
    let time = tm_field::TIME.start;
    let _ = writeln!(
        s,
        "met_coarse,{time},0,uint,32\nmet_fine,{},0,uint,16",
        time + 4
    );
    let mut at = TM_HEADER_LEN;
    let _ = writeln!(s, "hk_sid,{at},0,uint,8");
    at += 1;
    for f in FIELDS.iter() {
        let _ = writeln!(s, "{},{at},0,uint,{}", f.name, f.len * 8);
        at += f.len;
    }
    let _ = writeln!(s, "crc,{at},0,uint,16");
    debug_assert_eq!(at, TM_HEADER_LEN + housekeeping::REPORT_LEN);
    s
}
