//! The code equals spec/: every packet's offsets, sizes, units and the paper's grid labels;
//! the command set and its opcodes; the fault bits; the design decisions that have values.

use mmic::bolter::{BolterStep, MuxLines};
use mmic::command::{
    for_each_variant_class, BolterPair, Command, HipTarget, PARAM_LEN, PARAM_OFFSET,
};
use mmic::faults::Fault;
use mmic::mode::Mode;
use mmic::units::{HipAngle, PulseWidth};
use mmic::wire::checksum::crc16;
use mmic::wire::PacketKind;
use serde::Deserialize;
use std::collections::BTreeMap;
use std::path::PathBuf;

fn spec_path(rel: &str) -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("spec")
        .join(rel)
}

fn load<T: for<'de> Deserialize<'de>>(rel: &str) -> T {
    let p = spec_path(rel);
    let text = std::fs::read_to_string(&p).unwrap_or_else(|e| panic!("{}: {e}", p.display()));
    toml::from_str(&text).unwrap_or_else(|e| panic!("{}: {e}", p.display()))
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct PacketSpec {
    packet: String,
    #[allow(dead_code)]
    paper_table: String,
    length: usize,
    header: String,
    #[allow(dead_code)]
    route: String,
    paper_cells: Option<Vec<String>>,
    field: Vec<FieldRow>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct FieldRow {
    name: String,
    start: usize,
    len: usize,
    unit: String,
    #[allow(dead_code)]
    meaning: String,
}

#[test]
fn packets_match_spec_field_by_field_and_cell_by_cell() {
    let mut checked_fields = 0;
    let mut checked_cells = 0;
    for kind in PacketKind::ALL {
        let spec: PacketSpec = load(&format!("packets/{}.toml", kind.name()));
        assert_eq!(spec.packet, kind.name());
        assert_eq!(spec.length, kind.len(), "{kind}: length");
        assert_eq!(spec.header.as_bytes(), kind.header(), "{kind}: header");
        let code = kind.fields();
        assert_eq!(code.len(), spec.field.len(), "{kind}: number of fields");
        for (c, s) in code.iter().zip(&spec.field) {
            assert_eq!(c.name, s.name, "{kind}: field order");
            assert_eq!(
                c.range,
                s.start..s.start + s.len,
                "{kind}.{}: byte range",
                s.name
            );
            assert_eq!(c.unit.name(), s.unit, "{kind}.{}: unit", s.name);
            checked_fields += 1;
        }
        // Fields tile the packet exactly.
        let mut next = 0;
        for c in code {
            assert_eq!(c.range.start, next, "{kind}.{}: gap or overlap", c.name);
            next = c.range.end;
        }
        assert_eq!(next, kind.len());
        if let Some(cells) = spec.paper_cells {
            assert_eq!(cells.len(), kind.len(), "{kind}: paper cells");
            for (i, want) in cells.iter().enumerate() {
                let f = code.iter().find(|f| f.range.contains(&i)).expect("tiled");
                let mut got = String::new();
                f.cell(i, &mut got).unwrap();
                assert_eq!(&got, want, "{kind} byte {i}: the paper's label");
                checked_cells += 1;
            }
        }
    }
    assert_eq!(checked_fields, 7 + 36 + 32 + 9);
    assert_eq!(checked_cells, 14 + 66 + 47);
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct Commands {
    table1: Vec<Table1Row>,
    extension: Vec<Extension>,
    opcode: Vec<OpcodeRow>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct Table1Row {
    #[allow(dead_code)]
    command_type: String,
    #[allow(dead_code)]
    modules_engaged: String,
    #[allow(dead_code)]
    explanation: String,
    kind: String,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct Extension {
    kind: String,
    #[allow(dead_code)]
    why: String,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct OpcodeRow {
    opcode: u8,
    kind: String,
    variant: String,
    params: Vec<usize>,
}

#[test]
fn command_set_matches_spec() {
    let spec: Commands = load("commands.toml");
    // Table 1's rows, in order, then the extension, are the code's command kinds.
    let kinds: Vec<&str> = spec
        .table1
        .iter()
        .map(|r| r.kind.as_str())
        .chain(spec.extension.iter().map(|e| e.kind.as_str()))
        .collect();
    let code: Vec<&str> = mmic::command::CommandKind::ALL
        .iter()
        .map(|k| k.name())
        .collect();
    assert_eq!(kinds, code);
    let mut rows: BTreeMap<u8, &OpcodeRow> = BTreeMap::new();
    for r in &spec.opcode {
        assert!(
            rows.insert(r.opcode, r).is_none(),
            "opcode {:#04x} listed twice",
            r.opcode
        );
    }
    let mut seen = 0;
    for_each_variant_class(
        PulseWidth::new(1500).unwrap(),
        HipAngle::new(9000).unwrap(),
        |c| {
            let (id, p) = c.encode();
            let row = rows
                .get(&id)
                .unwrap_or_else(|| panic!("{c:?}: opcode {id:#04x} not in spec/commands.toml"));
            assert_eq!(row.kind, c.kind().name(), "{id:#04x}");
            assert_eq!(row.variant, format!("{c:?}"), "{id:#04x}");
            let used: Vec<usize> = (0..PARAM_LEN)
                .filter(|&i| p[i] != 0)
                .map(|i| i + PARAM_OFFSET)
                .collect();
            assert_eq!(row.params, used, "{id:#04x}: parameter bytes");
            assert_eq!(Command::decode(id, p), Ok(c));
            seen += 1;
        },
    );
    assert_eq!(
        seen,
        spec.opcode.len(),
        "spec lists opcodes the code does not emit"
    );
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct Faults {
    fault: Vec<FaultRow>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct FaultRow {
    bit: u8,
    name: String,
    #[allow(dead_code)]
    table8: String,
}

#[test]
fn fault_bits_match_spec() {
    let spec: Faults = load("faults.toml");
    assert_eq!(spec.fault.len(), Fault::ALL.len());
    for (f, row) in Fault::ALL.iter().zip(&spec.fault) {
        assert_eq!((f.bit(), f.name()), (row.bit, row.name.as_str()));
    }
}

#[derive(Deserialize)]
struct Decisions {
    headers: BTreeMap<String, String>,
    checksum: Checksum,
    units: BTreeMap<String, Range>,
    modes: BTreeMap<String, u8>,
    hip_presets: BTreeMap<String, toml::Value>,
    mux: BTreeMap<String, Mux>,
    bolter_steps: BTreeMap<String, u8>,
    decision: Vec<Decision>,
}

#[derive(Deserialize)]
struct Checksum {
    poly: u16,
    init: u16,
    reflected: bool,
    xorout: u16,
    check: u16,
    table_bytes: usize,
    table_bytes_small: usize,
}

#[derive(Deserialize)]
struct Range {
    min: u32,
    max: u32,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct Mux {
    a0: bool,
    a1: bool,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct Decision {
    id: String,
    decision: String,
    rationale: String,
    paper: String,
}

#[test]
fn decisions_match_code() {
    let d: Decisions = load("decisions.toml");
    for kind in PacketKind::ALL {
        assert_eq!(d.headers[kind.name()].as_bytes(), kind.header(), "{kind}");
    }
    assert_eq!(d.headers.len(), 4);

    let alg = mmic::wire::checksum::CRC.algorithm;
    assert_eq!(
        (alg.poly, alg.init, alg.refin, alg.xorout, alg.check),
        (
            d.checksum.poly,
            d.checksum.init,
            d.checksum.reflected,
            d.checksum.xorout,
            d.checksum.check
        )
    );
    assert_eq!(crc16(b"123456789"), d.checksum.check);
    // Default build: slice-by-16; with the feature small-crc-table: one table.
    let t = mmic::wire::checksum::TABLE_BYTES;
    assert!(
        t == d.checksum.table_bytes || t == d.checksum.table_bytes_small,
        "{t}"
    );

    let pulse = &d.units["servo_pulse"];
    assert_eq!(
        (pulse.min, pulse.max),
        (PulseWidth::MIN_US as u32, PulseWidth::MAX_US as u32)
    );
    assert!(
        PulseWidth::new(pulse.min as u16 - 1).is_err()
            && PulseWidth::new(pulse.max as u16 + 1).is_err()
    );
    let hip = &d.units["hip_angle"];
    assert_eq!((hip.min, hip.max), (0, HipAngle::TURN as u32 - 1));
    assert!(HipAngle::new(hip.max as u16 + 1).is_err());
    assert_eq!(d.units["board_number"].min, 1);

    for m in Mode::ALL {
        assert_eq!(d.modes[m.name()], m.to_wire(), "{m}");
    }

    // Hip presets travel as opcodes; their angles are documented here and used by the motion code.
    for (name, preset) in [
        ("straight", HipTarget::Straight),
        ("right_angle_cw", HipTarget::RightAngleCw),
        ("right_angle_ccw", HipTarget::RightAngleCcw),
    ] {
        let angle = d.hip_presets[name].as_integer().unwrap();
        assert_eq!(
            Some(angle as u16),
            mmic::command::preset_angle(preset).map(HipAngle::centidegrees),
            "{name}"
        );
    }

    for p in BolterPair::ALL {
        let m = &d.mux[&format!("pair{}", p.number())];
        assert_eq!(
            MuxLines::for_pair(p),
            MuxLines { a0: m.a0, a1: m.a1 },
            "pair {}",
            p.number()
        );
    }
    let names = [
        "descend",
        "retract",
        "descend_engage",
        "rotate",
        "counter_rotate",
        "return_home",
        "done",
        "failed",
    ];
    for (step, name) in BolterStep::ALL.iter().zip(names) {
        assert_eq!(d.bolter_steps[name], step.to_wire(), "{name}");
    }
    assert_eq!(d.bolter_steps.len(), 8);

    let mut ids = std::collections::BTreeSet::new();
    for x in &d.decision {
        assert!(ids.insert(&x.id), "decision {} twice", x.id);
        assert!(
            !x.decision.is_empty() && !x.rationale.is_empty() && !x.paper.is_empty(),
            "{}",
            x.id
        );
    }
}

/// Each packet's `field` module names the same byte ranges as its `FIELDS` table.
#[test]
fn field_modules_agree_with_the_field_tables() {
    use mmic::wire::{b_command, heartbeat, internal_heartbeat};
    let range = |fields: &[mmic::wire::FieldSpec], name: &str| {
        fields
            .iter()
            .find(|f| f.name == name)
            .map(|f| f.range.clone())
            .unwrap_or_else(|| panic!("no field {name}"))
    };
    let hb = heartbeat::FIELDS;
    assert_eq!(heartbeat::field::MODE, range(hb, "mode"));
    assert_eq!(heartbeat::field::LAST_SEQ, range(hb, "last_seq"));
    assert_eq!(heartbeat::field::FAULTS, range(hb, "faults"));
    assert_eq!(
        heartbeat::field::ELECTRICAL_B_I_BO,
        range(hb, "electrical_b.i_bo")
    );
    let ih = internal_heartbeat::FIELDS;
    assert_eq!(
        internal_heartbeat::field::BOLTER_AUX_MUX,
        range(ih, "bolter_aux.mux")
    );
    assert_eq!(
        internal_heartbeat::field::ARM_CONTRACTED,
        range(ih, "arm_contracted")
    );
    assert_eq!(
        internal_heartbeat::field::ELECTRICAL_B_V_BAT,
        range(ih, "electrical_b.v_bat")
    );
    let bc = b_command::FIELDS;
    assert_eq!(b_command::field::FLAGS, range(bc, "flags"));
    assert_eq!(b_command::field::CHECKSUM, range(bc, "checksum"));
}
