//! src/safety/ equals spec/modes.toml: Table 7's acceptance and power, Table 8's modes,
//! deferral and kinds, refusal codes and threshold defaults.

use mmic::command::CommandKind;
use mmic::faults::{Fault, Table8};
use mmic::mode::Mode;
use mmic::refusal::Refusal;
use mmic::safety::detect::Config;
use mmic::safety::policy::{accepts, fault_action, is_condition, powered, regulator_on};
use mmic::safety::supervisor::{Input, Supervisor};
use mmic::safety::ModuleSet;
use mmic::units::Module;
use serde::Deserialize;
use std::collections::BTreeMap;

#[derive(Deserialize)]
struct Spec {
    moving: Vec<String>,
    table7: BTreeMap<String, Vec<String>>,
    accepts: BTreeMap<String, Vec<String>>,
    table7_accepts: BTreeMap<String, Vec<String>>,
    accepts_decisions: BTreeMap<String, String>,
    refusal_decisions: BTreeMap<String, String>,
    power: Power,
    fault: Vec<FaultRow>,
    refusals: BTreeMap<String, u8>,
    thresholds: Thresholds,
    inconsistency: Vec<BTreeMap<String, String>>,
}

#[derive(Deserialize)]
struct Power {
    standby: Vec<String>,
    safed: Vec<String>,
    operational: Vec<String>,
    regulator: BTreeMap<String, bool>,
}

#[derive(Deserialize)]
struct FaultRow {
    name: String,
    table8: String,
    mode: String,
    deferred: bool,
    kind: String,
}

#[derive(Deserialize)]
struct Limits {
    locomotion: u16,
    gripper: u16,
    bolter: u16,
}

#[derive(Deserialize)]
struct Thresholds {
    low_battery_mv: u16,
    low_battery_ms: u32,
    comm_timeout_ms: u32,
    comm_max_unacked: u8,
    bolting_max_attempts: u8,
    idle: Limits,
    absolute: Limits,
    hip_home: u16,
    hip_tolerance: u16,
}

fn spec() -> Spec {
    let p = concat!(env!("CARGO_MANIFEST_DIR"), "/../../spec/modes.toml");
    toml::from_str(&std::fs::read_to_string(p).unwrap()).unwrap()
}

fn module_name(m: Module) -> &'static str {
    match m {
        Module::Hip => "hip",
        Module::ArmA => "arm_a",
        Module::ArmB => "arm_b",
        Module::GripperA => "gripper_a",
        Module::GripperB => "gripper_b",
        Module::BolterA => "bolter_a",
        Module::BolterB => "bolter_b",
    }
}

// req: P7.4
#[test]
fn the_moving_command_kinds_equal_spec() {
    let got: Vec<&str> = CommandKind::ALL
        .iter()
        .filter(|k| k.moves())
        .map(|k| k.name())
        .collect();
    assert_eq!(got, spec().moving, "spec/modes.toml `moving`");
}

/// Section 7: the robot starts in Standby with nothing powered and the regulator off, and a
/// first step without any input leaves it there.
// req: P7.2, P7.3, T7/entry
#[test]
fn the_robot_starts_in_standby_with_nothing_powered() {
    let mut s = Supervisor::new();
    assert_eq!(s.mode(), Mode::Standby);
    let out = s.step(&Input::quiet());
    assert_eq!(out.mode, Mode::Standby);
    assert!(out.powered.is_empty() && !out.regulator && out.faults.is_empty());
}

// req: T7/*, P7.1, P7.3, P7.4, P7.5, P7.8
#[test]
fn table7_acceptance_and_power_equal_spec() {
    let s = spec();
    for row in ["entry", "power", "commands", "exit"] {
        assert_eq!(s.table7[row].len(), 3, "table7.{row}");
    }
    for mode in Mode::ALL {
        let want: Vec<&str> = s.accepts[mode.name()].iter().map(String::as_str).collect();
        let got: Vec<&str> = CommandKind::ALL
            .iter()
            .filter(|k| accepts(mode, **k))
            .map(|k| k.name())
            .collect();
        assert_eq!(got, want, "{mode}: accepted command kinds");
        let want = match mode {
            Mode::Standby => &s.power.standby,
            Mode::Safed => &s.power.safed,
            Mode::Operational => &s.power.operational,
        };
        let got: Vec<&str> = powered(mode, ModuleSet::ALL)
            .iter()
            .map(module_name)
            .collect();
        assert_eq!(got, *want, "{mode}: powered");
        assert_eq!(
            regulator_on(mode),
            s.power.regulator[mode.name()],
            "{mode}: regulator"
        );
    }
}

// req: T8/*, P7.7, P7.9, P7.13, P7.14
#[test]
fn table8_modes_deferral_and_kinds_equal_spec() {
    let s = spec();
    assert_eq!(s.fault.len(), Fault::ALL.len());
    for (f, row) in Fault::ALL.iter().zip(&s.fault) {
        assert_eq!(f.name(), row.name);
        // spec/modes.toml writes "none" for the project's own motion timeout.
        assert_eq!(
            f.table8().map_or("none", Table8::title),
            row.table8,
            "{f}: Table 8 row"
        );
        let a = fault_action(*f);
        assert_eq!(a.mode.name(), row.mode, "{f}: mode");
        assert_eq!(a.deferred, row.deferred, "{f}: deferred");
        assert_eq!(
            if is_condition(*f) {
                "condition"
            } else {
                "event"
            },
            row.kind,
            "{f}: kind"
        );
    }
    assert!(s.inconsistency.len() >= 2);
    // Ten rows: every row has a bit, the overcurrent rows two (idle and operational checks),
    // and each row's name is its operational bit's name or its only bit's.
    assert_eq!(Table8::ALL.len(), 10);
    for r in Table8::ALL {
        let bits: Vec<Fault> = Fault::ALL
            .into_iter()
            .filter(|f| f.table8() == Some(r))
            .collect();
        assert!(bits.iter().any(|f| f.name() == r.name()), "{r}: {bits:?}");
        let expected = if r.name().ends_with("_overcurrent") {
            2
        } else {
            1
        };
        assert_eq!(bits.len(), expected, "{r}: {bits:?}");
    }
}

// req: P7.11, P7.17
#[test]
fn refusal_codes_and_thresholds_equal_spec() {
    let s = spec();
    assert_eq!(s.refusals.len(), Refusal::ALL.len());
    for r in Refusal::ALL {
        assert_eq!(s.refusals[r.name()], r.to_wire(), "{r}");
    }
    let c = Config::default();
    let t = &s.thresholds;
    assert_eq!(
        (
            c.low_battery_mv,
            c.low_battery_ms,
            c.comm_timeout_ms,
            c.comm_max_unacked,
            c.hip_home.centidegrees(),
            c.hip_tolerance
        ),
        (
            t.low_battery_mv,
            t.low_battery_ms,
            t.comm_timeout_ms,
            t.comm_max_unacked,
            t.hip_home,
            t.hip_tolerance
        )
    );
    assert_eq!(c.bolting_max_attempts, t.bolting_max_attempts);
    assert_eq!(
        (c.idle.locomotion, c.idle.gripper, c.idle.bolter),
        (t.idle.locomotion, t.idle.gripper, t.idle.bolter)
    );
    assert_eq!(
        (c.absolute.locomotion, c.absolute.gripper, c.absolute.bolter),
        (t.absolute.locomotion, t.absolute.gripper, t.absolute.bolter)
    );
}

/// The decisions of spec/decisions.toml: id -> decision text.
fn decisions() -> BTreeMap<String, String> {
    #[derive(Deserialize)]
    struct File {
        decision: Vec<Entry>,
    }
    #[derive(Deserialize)]
    struct Entry {
        id: String,
        decision: String,
    }
    let p = concat!(env!("CARGO_MANIFEST_DIR"), "/../../spec/decisions.toml");
    let f: File = toml::from_str(&std::fs::read_to_string(p).unwrap()).unwrap();
    f.decision.into_iter().map(|e| (e.id, e.decision)).collect()
}

/// Asserts that decision `id` exists and names `what` (so it is the one that introduced it),
/// in any case ("Reset" names `reset`).
fn assert_introduces(decisions: &BTreeMap<String, String>, id: &str, what: &str) {
    let text = decisions
        .get(id)
        .unwrap_or_else(|| panic!("{what}: no decision {id} in spec/decisions.toml"));
    assert!(
        text.to_lowercase().contains(what),
        "decision {id} does not name {what}"
    );
}

/// What the code accepts beyond Table 7 as printed is the project's, and each such kind names
/// the decision that added it: the code takes every kind Table 7 lets a mode take (Operational:
/// every Table 1 kind), and each kind taken beyond that has an entry in [accepts_decisions]
/// whose decision names it. No entry is left over.
// req: T7/commands, D:commands-in-every-mode
#[test]
fn acceptance_beyond_table7_is_a_recorded_decision() {
    let s = spec();
    let d = decisions();
    #[derive(Deserialize)]
    struct Commands {
        table1: Vec<Row>,
    }
    #[derive(Deserialize)]
    struct Row {
        kind: String,
    }
    let p = concat!(env!("CARGO_MANIFEST_DIR"), "/../../spec/commands.toml");
    let c: Commands = toml::from_str(&std::fs::read_to_string(p).unwrap()).unwrap();
    let table1: Vec<String> = c.table1.into_iter().map(|r| r.kind).collect();
    assert_eq!(
        s.table7_accepts["operational"], table1,
        "Table 7: Operational takes all"
    );
    let mut used = std::collections::BTreeSet::new();
    for mode in Mode::ALL {
        let printed = &s.table7_accepts[mode.name()];
        for k in CommandKind::ALL {
            let in_table7 = printed.iter().any(|p| p == k.name());
            if in_table7 {
                assert!(
                    accepts(mode, k),
                    "{mode}: Table 7 takes {k}, the code refuses it"
                );
            } else if accepts(mode, k) {
                let id = s.accepts_decisions.get(k.name());
                let id = id.unwrap_or_else(|| panic!("{mode} takes {k}: no decision"));
                assert_introduces(&d, id, k.name());
                used.insert(k.name());
            }
        }
    }
    let listed: std::collections::BTreeSet<&str> =
        s.accepts_decisions.keys().map(String::as_str).collect();
    assert_eq!(listed, used, "[accepts_decisions] lists kinds no mode adds");
}

/// None of the refusal codes is the paper's: each names the decision that introduced it.
// req: D:heartbeat-byte-62
#[test]
fn every_refusal_code_names_the_decision_that_introduced_it() {
    let s = spec();
    let d = decisions();
    assert_eq!(s.refusal_decisions.len(), Refusal::ALL.len());
    for r in Refusal::ALL {
        assert_introduces(&d, &s.refusal_decisions[r.name()], r.name());
    }
}

/// The default supervisor is the one at startup: Standby, every module enabled, no fault.
#[test]
fn the_default_supervisor_is_the_startup_one() {
    use mmic::safety::supervisor::Supervisor;
    let s = Supervisor::default();
    assert_eq!(s, Supervisor::new());
    assert_eq!(s.mode(), Mode::Standby);
    assert_eq!(s.enabled(), ModuleSet::ALL);
    assert!(s.faults().is_empty() && !s.stopped() && !s.standby_pending());
}
