//! The code equals spec/ccsds/: the function table (IDs, names, argument lengths, every range
//! bound accepted and one past it refused), the housekeeping layout, the failure codes and
//! event IDs.

use mmic::command::CommandKind;
use mmic::faults::Fault;
use mmic::pus::event::Event;
use mmic::pus::function::{self, FunctionError, FunctionId};
use mmic::pus::housekeeping::{FIELDS, REPORT_LEN};
use mmic::pus::request::{Request, RequestError};
use serde::Deserialize;
use std::path::PathBuf;

fn load<T: for<'de> Deserialize<'de>>(rel: &str) -> T {
    let p = PathBuf::from(crate::ROOT).join("spec").join(rel);
    let text = std::fs::read_to_string(&p).unwrap_or_else(|e| panic!("{}: {e}", p.display()));
    toml::from_str(&text).unwrap_or_else(|e| panic!("{}: {e}", p.display()))
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct Functions {
    function: Vec<FunctionRow>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct FunctionRow {
    id: u8,
    name: String,
    args: Vec<Arg>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct Arg {
    name: String,
    #[serde(rename = "type")]
    ty: String,
    range: [u32; 2],
    #[allow(dead_code)]
    unit: Option<String>,
    #[allow(dead_code)]
    meaning: String,
}

/// Valid arguments of each function (a command that exists), to vary one argument at a time.
fn base(f: FunctionId) -> Vec<u8> {
    match f {
        FunctionId::Arm | FunctionId::Gripper => vec![0, 2, 0x05, 0xDC],
        FunctionId::Hip => vec![4, 0, 0],
        FunctionId::Bolter => vec![0, 0],
        FunctionId::Primitive => vec![1, b'a'],
        FunctionId::Power => vec![0, 1],
        FunctionId::Reconfiguration => vec![b'd', b'a'],
        FunctionId::Mode => vec![1],
        _ => vec![],
    }
}

#[test]
fn functions_toml_is_the_function_table() {
    let spec: Functions = load("ccsds/functions.toml");
    assert_eq!(spec.function.len(), FunctionId::ALL.len());
    for (row, f) in spec.function.iter().zip(FunctionId::ALL) {
        assert_eq!((row.id, row.name.as_str()), (f.id(), f.name()));
        // Every function is a Table 1 kind (spec/commands.toml's names).
        assert!(
            CommandKind::ALL.iter().any(|k| k.name() == f.name()),
            "{}",
            f.name()
        );
        let len: usize = row
            .args
            .iter()
            .map(|a| if a.ty == "u16" { 2 } else { 1 })
            .sum();
        assert_eq!(len, f.args_len(), "{}", f.name());
        // Each argument's bounds: min and max accepted (with the others valid), one past
        // refused naming the argument (where the type has room).
        let mut at = 0;
        for a in &row.args {
            let w = if a.ty == "u16" { 2 } else { 1 };
            let put = |v: u32| {
                let mut d = vec![f.id()];
                d.extend(base(f));
                let bytes = v.to_be_bytes();
                d[1 + at..1 + at + w].copy_from_slice(&bytes[4 - w..]);
                d
            };
            // Where an argument only counts with another (a pulse with target 2, an angle
            // with target 4, a primitive's final state, a reconfiguration's pair of states),
            // the bounds are checked in the context `base` sets.
            let ok_at = |v: u32| function::decode(&put(v));
            for v in [a.range[0], a.range[1]] {
                let r = ok_at(v);
                // …or refused for another argument that must agree with it (a pulse given
                // with target 0), or as a whole (no such primitive or reconfiguration).
                let semantic = match r {
                    Err(FunctionError::Primitive(_) | FunctionError::Reconfiguration(_)) => true,
                    Err(FunctionError::OutOfRange { argument, .. }) => argument != a.name,
                    _ => false,
                };
                assert!(
                    r.is_ok() || semantic,
                    "{} {} = {v}: {r:?}",
                    f.name(),
                    a.name
                );
            }
            let max_of_type = if w == 2 { 0xFFFF } else { 0xFF };
            for v in [
                a.range[0].checked_sub(1),
                (a.range[1] < max_of_type).then_some(a.range[1] + 1),
            ]
            .into_iter()
            .flatten()
            {
                match ok_at(v) {
                    Err(FunctionError::OutOfRange {
                        argument, min, max, ..
                    }) => {
                        assert_eq!(argument, a.name, "{}", f.name());
                        assert_eq!(
                            [u32::from(min), u32::from(max)],
                            a.range,
                            "{} {}",
                            f.name(),
                            a.name
                        );
                    }
                    r => panic!("{} {} = {v}: {r:?}", f.name(), a.name),
                }
            }
            at += w;
        }
    }
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct Services {
    apid: toml::Value,
    tc: Vec<TcRow>,
    tm: Vec<toml::Value>,
    failure: Vec<FailureRow>,
    event: Vec<EventRow>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct TcRow {
    service: u8,
    subservice: u8,
    #[allow(dead_code)]
    name: String,
    #[allow(dead_code)]
    app_data: String,
    #[allow(dead_code)]
    reports: String,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct FailureRow {
    code: String,
    #[allow(dead_code)]
    meaning: String,
    #[allow(dead_code)]
    data: String,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct EventRow {
    id: String,
    name: String,
    #[allow(dead_code)]
    severity: toml::Value,
    #[allow(dead_code)]
    aux: String,
}

// req: PUS/ST[1].1, PUS/ST[1].2, PUS/ST[1].3, PUS/ST[1].4, PUS/ST[1].7, PUS/ST[1].8
// req: PUS/ST[3].5, PUS/ST[3].6, PUS/ST[3].25, PUS/ST[3].31, PUS/ST[5].1, PUS/ST[5].2
// req: PUS/ST[5].3, PUS/ST[5].4, PUS/ST[8].1, PUS/ST[17].1, PUS/ST[17].2
#[test]
fn services_toml_is_what_the_gateway_serves() {
    let spec: Services = load("ccsds/services.toml");
    assert_eq!(spec.apid["robot"].as_str(), Some("0x100 + n"));
    assert_eq!(mmic::pus::ROBOT_APID_BASE, 0x100);
    assert!(!spec.tm.is_empty());
    // Every TC row is served; every (service, subservice) not listed is refused by name.
    for s in 0..=255u8 {
        for ss in 0..=255u8 {
            let listed = spec.tc.iter().any(|t| (t.service, t.subservice) == (s, ss));
            match Request::parse(s, ss, &[]) {
                Err(RequestError::UnknownService { service }) => {
                    assert!(!listed && service == s && !spec.tc.iter().any(|t| t.service == s))
                }
                Err(RequestError::UnknownSubservice { .. }) => assert!(!listed, "({s},{ss})"),
                _ => assert!(listed, "({s},{ss}) served but not in services.toml"),
            }
        }
    }
    // Failure codes: each gateway refusal's code is listed.
    let codes: Vec<&str> = spec.failure.iter().map(|f| f.code.as_str()).collect();
    for e in [
        RequestError::UnknownService { service: 9 },
        RequestError::UnknownSubservice {
            service: 8,
            subservice: 2,
        },
        RequestError::Function(FunctionError::Empty),
        RequestError::Function(FunctionError::UnknownFunction { id: 0 }),
        RequestError::Function(FunctionError::NoFunction),
    ] {
        assert!(
            codes.contains(&format!("{:#06x}", e.code()).as_str()),
            "{e}"
        );
    }
    for c in [
        mmic::pus::verification::UNACKNOWLEDGED,
        mmic::pus::verification::ABANDONED,
        mmic::pus::verification::RESTARTED,
        mmic::pus::verification::QUEUE_FULL,
        mmic::pus::verification::KEY_REUSED,
    ] {
        assert!(codes.contains(&format!("{c:#06x}").as_str()), "{c:#06x}");
    }
    // Event IDs.
    let ids: Vec<(&str, &str)> = spec
        .event
        .iter()
        .map(|e| (e.id.as_str(), e.name.as_str()))
        .collect();
    assert_eq!(
        ids,
        [
            ("0x0001", "mode_changed"),
            ("0x0002", "bolting_attempt"),
            ("0x0003", "faults_cleared"),
            ("0x0004", "board_a_restarted"),
            ("0x0005", "link_stopped"),
            ("0x0200 + n", "sdls_refused"),
            ("0x0100 + n", "fault")
        ]
    );
    let e = Event::Fault {
        fault: Fault::SensorLoss,
        mode: mmic::mode::Mode::Safed,
    };
    assert_eq!(e.id(), 0x0100 + u16::from(Fault::SensorLoss.bit()));
}

#[derive(Deserialize, Debug, PartialEq)]
#[serde(deny_unknown_fields)]
struct HkRow {
    name: String,
    offset: usize,
    len: usize,
    unit: String,
    meaning: String,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct Hk {
    structure_id: u8,
    report_len: usize,
    parameter: Vec<HkRow>,
}

/// spec/ccsds/housekeeping.toml is written from `FIELDS` (MMIC_REGENERATE=1 rewrites it).
#[test]
fn housekeeping_toml_is_the_report_layout() {
    let mut text = String::from(
        "# ST[3] housekeeping report structure 1, TM(3,25): the heartbeat's content (Table 3).\n\
         # Source data: structure_id (u8) then each parameter, unsigned big-endian, at `offset`\n\
         # (from the start of the source data). Written from src/pus/housekeeping.rs FIELDS by\n\
         # `MMIC_REGENERATE=1 cargo test -p mmic --test library housekeeping_toml`; checked fresh by that test.\n\n",
    );
    text.push_str(&format!("structure_id = 1\nreport_len = {REPORT_LEN}\n"));
    let mut at = 1;
    for f in FIELDS {
        text.push_str(&format!(
            "\n[[parameter]]\nname = \"{}\"\noffset = {at}\nlen = {}\nunit = \"{}\"\nmeaning = \"{}\"\n",
            f.name, f.len, f.unit, f.meaning
        ));
        at += f.len;
    }
    let path = PathBuf::from(crate::ROOT).join("spec/ccsds/housekeeping.toml");
    if std::env::var_os("MMIC_REGENERATE").is_some() {
        std::fs::write(&path, &text).unwrap();
    }
    let committed = std::fs::read_to_string(&path).unwrap_or_default();
    assert_eq!(
        committed, text,
        "spec/ccsds/housekeeping.toml is stale: regenerate it"
    );
    let hk: Hk = toml::from_str(&committed).unwrap();
    assert_eq!(
        (hk.structure_id, hk.report_len, hk.parameter.len()),
        (1, REPORT_LEN, FIELDS.len())
    );
}

#[derive(Deserialize)]
struct TimingDoc {
    pus_timing: PusTiming,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct PusTiming {
    tc_timeout_ms: u32,
    tc_query_ms: u32,
    tc_max_attempts: u8,
    tc_max_attempts_under_cop1: u8,
    gateway_poll_ms: u32,
    gateway_visit_timeout_ms: u32,
}

#[test]
fn pus_timing_is_the_decision() {
    let t: TimingDoc = load("decisions.toml");
    let t = t.pus_timing;
    let g = mmic::node::ground::pus::Config::default();
    assert_eq!(
        (g.timeout_ms, g.query_ms, g.max_attempts),
        (t.tc_timeout_ms, t.tc_query_ms, t.tc_max_attempts)
    );
    let w = mmic::node::server::gateway::Config::default();
    assert_eq!(
        (w.poll_ms, w.uplink.timeout_ms),
        (t.gateway_poll_ms, t.gateway_visit_timeout_ms)
    );
    // Over frames the ground outlasts FOP-1: it gives up no sooner than the frame is.
    let fop = mmic::link::fop::FopConfig::MISSION;
    let f = g.under_cop1(&fop);
    assert_eq!(
        (f.timeout_ms, f.query_ms, f.max_attempts),
        (g.timeout_ms, g.query_ms, t.tc_max_attempts_under_cop1)
    );
    assert!(
        u64::from(f.max_attempts) * u64::from(f.timeout_ms)
            >= u64::from(fop.tx_limit) * u64::from(fop.t1_ms)
    );
    // Never fewer attempts than asked for, and no overflow on an extreme link.
    let many = mmic::node::ground::pus::Config {
        max_attempts: 200,
        ..g
    };
    assert_eq!(many.under_cop1(&fop).max_attempts, 200);
    let slow = mmic::link::fop::FopConfig {
        t1_ms: u32::MAX,
        tx_limit: 255,
        ..fop
    };
    assert_eq!(g.under_cop1(&slow).max_attempts, u8::MAX);
    let zero = mmic::node::ground::pus::Config { timeout_ms: 0, ..g };
    assert_eq!(zero.under_cop1(&fop).max_attempts, u8::MAX);
    // A resend means a loss: the ground waits longer than one visit and one poll period.
    assert!(t.tc_timeout_ms > t.gateway_visit_timeout_ms + t.gateway_poll_ms);
}
