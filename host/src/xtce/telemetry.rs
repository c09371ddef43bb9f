//! The `TelemetryMetaData` of the mission database: the TM header and every report's
//! parameters, their types, and the containers that place them by APID, service and subservice.

use super::model::{
    BaseContainer, Comparison, Container, DataType, EnumeratedType, IntegerType, Op, Parameter,
    Restriction, Role, Telemetry, Unit,
};
use super::{XtceError, APID_MAX, APID_MIN};
use crate::pus::ATTEMPT_RESULTS;
use crate::spec::{self, label};
use mmic::mode::Mode;
use mmic::motion::State;
use mmic::pus::housekeeping::{Field, FIELDS};
use mmic::refusal::Refusal;

/// The widths of the plain `uintN` parameter types (header fields, request ID, spare octets).
const UINT_BITS: [usize; 10] = [1, 2, 3, 4, 8, 11, 14, 16, 24, 32];

/// The TM packet header's parameters, in wire order: (name, type, description).
const HEADER: [(&str, &str, &str); 15] = [
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

/// The ST\[1\] request ID (the TC's primary header without its length), in wire order.
const REQUEST_ID: [(&str, &str, &str); 6] = [
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

/// The ST\[1\] failure report's and the ST\[5\] event reports' parameters after their headers.
const REPORT_DATA: [(&str, &str, &str); 18] = [
    ("failure_code", "failure_code_type", "ST[1] failure code"),
    (
        "failure_data",
        "uint32",
        "ST[1] failure data (spec/ccsds/services.toml)",
    ),
    ("event_id", "event_id_type", "ST[5] event definition ID"),
    ("event_mode_from", "mode_type", "mode_changed: mode before"),
    ("event_mode_to", "mode_type", "mode_changed: mode after"),
    (
        "event_pair",
        "uint8",
        "bolting_attempt: fastener pair 1..=4",
    ),
    ("event_attempt", "uint8", "bolting_attempt: attempt 1..=3"),
    (
        "event_result",
        "attempt_result_type",
        "bolting_attempt: how it ended",
    ),
    (
        "event_cleared_faults",
        "faults_type",
        "faults_cleared: the cleared fault map",
    ),
    ("event_fault_mode", "mode_type", "fault: the mode after it"),
    (
        "event_boot",
        "uint8",
        "board_a_restarted: the new boot byte (reset cause in bits 7..5, boot count modulo 32)",
    ),
    (
        "event_link_board",
        "uint8",
        "link_stopped: the robot whose link did not start",
    ),
    (
        "event_link_reason",
        "uint8",
        "link_stopped: 0 unprovisioned, 1 other-key, 2 no-counter, 3 weak-key, 4 no-keys, 5 no-store, 6 not-served",
    ),
    (
        "event_sdls_refused",
        "uint16",
        "sdls_refused: TC frames refused for this reason since the last such report",
    ),
    (
        "event_sdls_spi",
        "uint16",
        "sdls_refused: the last refused frame's SPI",
    ),
    ("event_spare8", "uint8", "zero"),
    ("event_spare16", "uint16", "zero"),
    ("event_spare24", "uint24", "zero"),
];

/// The parameter type of a housekeeping field (by its unit, or its name for enumerations).
pub fn hk_type(f: &Field) -> Result<String, XtceError> {
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
        (unit, field) => {
            return Err(XtceError::NoType {
                field: field.into(),
                unit: unit.into(),
            })
        }
    })
}

/// The whole `TelemetryMetaData`.
pub fn telemetry() -> Result<Telemetry, XtceError> {
    Ok(Telemetry {
        types: parameter_types()?,
        parameters: parameters()?,
        containers: containers(),
    })
}

/// A parameter's integer type.
fn uint(name: &str, bits: usize, unit: Option<Unit>, description: Option<String>) -> DataType {
    DataType::Integer(IntegerType {
        role: Role::Parameter,
        name: name.into(),
        description,
        unit,
        bits,
        range: None,
    })
}

/// A parameter's enumerated type.
pub(super) fn enumerated(
    role: Role,
    name: &str,
    bits: usize,
    values: Vec<(u32, String)>,
    description: &str,
) -> DataType {
    DataType::Enumerated(EnumeratedType {
        role,
        name: name.into(),
        description: description.into(),
        bits,
        values,
    })
}

/// Every parameter type: plain integers, the CUC time's, the housekeeping units', then the
/// enumerations and the fault map.
fn parameter_types() -> Result<Vec<DataType>, XtceError> {
    let mut types: Vec<DataType> = UINT_BITS
        .iter()
        .map(|&bits| uint(&format!("uint{bits}"), bits, None, None))
        .collect();
    types.extend(time_types());
    types.extend(unit_types()?);
    types.extend(library_enumerations());
    types.push(faults_type());
    types.extend(spec_enumerations()?);
    Ok(types)
}

/// The CUC time's two parts.
fn time_types() -> [DataType; 2] {
    let unit = |symbol: &str, description| Unit {
        symbol: symbol.into(),
        description: Some(description),
    };
    [
        uint(
            "met_coarse_type",
            32,
            Some(unit("s", "second")),
            Some("CUC coarse time: whole seconds since the gateway's power-on".into()),
        ),
        uint(
            "met_fine_type",
            16,
            Some(unit("2^-16 s", "1/65536 s")),
            Some("CUC fine time".into()),
        ),
    ]
}

/// One type per (unit, width) of the housekeeping fields, in the fields' order.
fn unit_types() -> Result<Vec<DataType>, XtceError> {
    let mut types: Vec<DataType> = Vec::new();
    for f in FIELDS.iter() {
        let name = hk_type(f)?;
        let (symbol, description) = match f.unit {
            "mV" => ("mV", "millivolt"),
            "mA" => ("mA", "milliampere"),
            "us" => ("us", "microsecond (servo pulse width)"),
            "0.01 deg" => ("0.01 deg", "hundredth of a degree"),
            _ => continue,
        };
        let known = types
            .iter()
            .any(|t| matches!(t, DataType::Integer(i) if i.name == name));
        if !known {
            let unit = Unit {
                symbol: symbol.into(),
                description: Some(description),
            };
            types.push(uint(&name, f.len * 8, Some(unit), None));
        }
    }
    Ok(types)
}

/// The modes' wire values and labels.
pub(super) fn modes() -> Vec<(u32, String)> {
    Mode::ALL
        .iter()
        .map(|m| (u32::from(m.to_wire()), label(m.name())))
        .collect()
}

/// The motion states' wire values (ASCII letters) and labels (the letters), `NONE` (0) first
/// if `none`.
pub(super) fn states(none: bool) -> Vec<(u32, String)> {
    let zero = none.then(|| (0, "NONE".to_string()));
    zero.into_iter()
        .chain(
            State::ALL
                .iter()
                .map(|s| (u32::from(s.to_wire()), char::from(s.to_wire()).to_string())),
        )
        .collect()
}

/// The enumerations the library defines: mode, refusal, bolter pair, state, boolean.
fn library_enumerations() -> [DataType; 5] {
    let p = Role::Parameter;
    let refusals = std::iter::once((0, "ACCEPTED".to_string()))
        .chain(
            Refusal::ALL
                .iter()
                .map(|r| (u32::from(r.to_wire()), label(r.name()))),
        )
        .collect();
    let pairs = std::iter::once((0, "NONE".to_string()))
        .chain((1..=4).map(|p| (p, format!("PAIR_{p}"))))
        .collect();
    let booleans = vec![(0, "FALSE".into()), (1, "TRUE".into())];
    [
        enumerated(p, "mode_type", 8, modes(), "operating mode (spec/modes.toml)"),
        enumerated(
            p,
            "refusal_type",
            8,
            refusals,
            "heartbeat byte 62: the outcome of the command the heartbeat reports on, 0 = accepted, else its refusal code (spec/modes.toml)",
        ),
        enumerated(p, "bolter_pair_type", 8, pairs, "fastener pair"),
        enumerated(
            p,
            "state_type",
            8,
            states(true),
            "motion state a..o (Table 5), ASCII; 0 none",
        ),
        enumerated(p, "bool_type", 8, booleans, "0 false, 1 true"),
    ]
}

/// The latched fault map: a 32-bit integer whose bits spec/faults.toml names.
fn faults_type() -> DataType {
    let bits: Vec<String> = spec::faults()
        .iter()
        .map(|f| format!("bit {} {}", f.bit, f.name))
        .collect();
    let description = format!("latched fault map (spec/faults.toml): {}", bits.join(", "));
    uint("faults_type", 32, None, Some(description))
}

/// The enumerations spec/ccsds/services.toml and the bolting results define.
fn spec_enumerations() -> Result<[DataType; 3], XtceError> {
    let p = Role::Parameter;
    let codes = spec::failure_codes()
        .map_err(XtceError::Spec)?
        .into_iter()
        .map(|(c, l)| (u32::from(c), l))
        .collect();
    let events = spec::event_ids()
        .map_err(XtceError::Spec)?
        .into_iter()
        .map(|(c, l)| (u32::from(c), label(&l)))
        .collect();
    let results = ATTEMPT_RESULTS
        .iter()
        .map(|(r, n)| (*r as u32, label(n)))
        .collect();
    Ok([
        enumerated(
            p,
            "failure_code_type",
            16,
            codes,
            "ST[1] failure code (spec/ccsds/services.toml)",
        ),
        enumerated(
            p,
            "event_id_type",
            16,
            events,
            "ST[5] event definition ID (spec/ccsds/services.toml)",
        ),
        enumerated(
            p,
            "attempt_result_type",
            8,
            results,
            "how a bolting attempt ended",
        ),
    ])
}

/// Every parameter: the header, the housekeeping structure, the request ID, the reports' data.
fn parameters() -> Result<Vec<Parameter>, XtceError> {
    let p = |(name, ty, description): (&str, &str, &str)| Parameter {
        name: name.into(),
        type_ref: ty.into(),
        description: description.into(),
    };
    let mut all: Vec<Parameter> = HEADER.into_iter().map(p).collect();
    all.push(p(("hk_sid", "uint8", "housekeeping structure ID (1)")));
    for f in FIELDS.iter() {
        all.push(p((f.name, &hk_type(f)?, f.meaning)));
    }
    all.extend(REQUEST_ID.into_iter().chain(REPORT_DATA).map(p));
    Ok(all)
}

/// The subservices of spec/ccsds/services.toml's TM rows that `keep` selects.
pub(super) fn tm_subservices(keep: impl Fn(&spec::TmRow) -> bool) -> Vec<u32> {
    spec::services()
        .tm
        .iter()
        .filter(|t| keep(t))
        .flat_map(|t| t.subservices.iter().map(|s| u32::from(*s)))
        .collect()
}

/// The subservices of TM(1,x) failure reports (2, 4, 8).
pub(super) fn failure_subservices() -> Vec<u32> {
    tm_subservices(|t| t.service == 1 && t.name == "verification_failure")
}

/// A container with its entries.
fn container(
    name: &str,
    description: &str,
    entries: &[&str],
    base: Option<BaseContainer>,
) -> Container {
    Container {
        name: name.into(),
        is_abstract: false,
        description: description.into(),
        entries: entries.iter().map(|e| e.to_string()).collect(),
        base,
    }
}

/// Derives from `base` when all of `all` hold.
fn when(base: &str, all: Vec<Comparison>) -> Option<BaseContainer> {
    Some(BaseContainer {
        container: base.into(),
        restriction: Restriction::All(all),
    })
}

/// Derives from `base` when all of `all` hold and `parameter` is one of `values`.
fn when_one_of(
    base: &str,
    all: Vec<Comparison>,
    parameter: &str,
    values: &[u32],
) -> Option<BaseContainer> {
    let any = values
        .iter()
        .map(|&v| Comparison::new(parameter, Op::Eq, v))
        .collect();
    Some(BaseContainer {
        container: base.into(),
        restriction: Restriction::AllAndAny { all, any },
    })
}

/// A robot's packet (APID range) of the given service and, if given, subservice.
fn robot_tm(service: u32, subservice: Option<u32>) -> Vec<Comparison> {
    let mut c = vec![
        Comparison::new("ccsds_apid", Op::Ge, u32::from(APID_MIN)),
        Comparison::new("ccsds_apid", Op::Le, u32::from(APID_MAX)),
        Comparison::new("service", Op::Eq, service),
    ];
    c.extend(subservice.map(|s| Comparison::new("subservice", Op::Eq, s)));
    c
}

/// Event `id`'s report.
fn event_is(id: u32) -> Vec<Comparison> {
    vec![Comparison::new("event_id", Op::Eq, id)]
}

/// Every container: the abstract header, housekeeping, ST\[1\] reports, events, are-you-alive.
fn containers() -> Vec<Container> {
    let header: Vec<&str> = HEADER.iter().map(|h| h.0).collect();
    let mut hk: Vec<&str> = vec!["hk_sid"];
    hk.extend(FIELDS.iter().map(|f| f.name));
    let request: Vec<&str> = REQUEST_ID.iter().map(|r| r.0).collect();
    let mut all = vec![
        Container {
            is_abstract: true,
            ..container(
                "pus-tm",
                "every PUS-C TM packet: primary and secondary header",
                &header,
                None,
            )
        },
        container(
            "hk-report",
            "TM(3,25) housekeeping parameter report, structure 1: the heartbeat",
            &hk,
            when("pus-tm", robot_tm(3, Some(25))),
        ),
        container(
            "verification-report",
            "TM(1,x) ST[1] report: the request ID",
            &request,
            when("pus-tm", robot_tm(1, None)),
        ),
        container(
            "verification-failure",
            "TM(1,2/4/8): failure code and data after the request ID",
            &["failure_code", "failure_data"],
            when_one_of(
                "verification-report",
                vec![],
                "subservice",
                &failure_subservices(),
            ),
        ),
    ];
    all.extend(event_containers());
    all.push(container(
        "are-you-alive-report",
        "TM(17,2) are-you-alive report (no data)",
        &[],
        when("pus-tm", robot_tm(17, Some(2))),
    ));
    all
}

/// The ST\[5\] event report and one container per event's auxiliary data.
fn event_containers() -> [Container; 8] {
    let severities = tm_subservices(|t| t.service == 5);
    let fault = vec![
        Comparison::new("event_id", Op::Ge, 0x100),
        Comparison::new("event_id", Op::Le, 0x1FF),
    ];
    let sdls = vec![
        Comparison::new("event_id", Op::Ge, 0x200),
        Comparison::new("event_id", Op::Le, 0x2FF),
    ];
    [
        container(
            "event-report",
            "TM(5,1..4) event report: the event definition ID (subservice = severity)",
            &["event_id"],
            when_one_of("pus-tm", robot_tm(5, None), "subservice", &severities),
        ),
        container(
            "event-mode-changed",
            "event 0x0001 mode_changed",
            &["event_mode_from", "event_mode_to", "event_spare16"],
            when("event-report", event_is(1)),
        ),
        container(
            "event-bolting-attempt",
            "event 0x0002 bolting_attempt",
            &[
                "event_pair",
                "event_attempt",
                "event_result",
                "event_spare8",
            ],
            when("event-report", event_is(2)),
        ),
        container(
            "event-faults-cleared",
            "event 0x0003 faults_cleared",
            &["event_cleared_faults"],
            when("event-report", event_is(3)),
        ),
        container(
            "event-board-a-restarted",
            "event 0x0004 board_a_restarted",
            &["event_boot", "event_spare24"],
            when("event-report", event_is(4)),
        ),
        container(
            "event-link-stopped",
            "event 0x0005 link_stopped",
            &["event_link_board", "event_link_reason", "event_spare16"],
            when("event-report", event_is(5)),
        ),
        container(
            "event-fault",
            "events 0x0100 + n: fault n raised",
            &["event_fault_mode", "event_spare24"],
            when("event-report", fault),
        ),
        container(
            "event-sdls-refused",
            "events 0x0200 + n: the server board's SDLS refused TC frames for reason n",
            &["event_sdls_refused", "event_sdls_spi"],
            when("event-report", sdls),
        ),
    ]
}
