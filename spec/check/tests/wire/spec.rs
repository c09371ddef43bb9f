//! The code equals spec/: every packet's offsets, sizes, units and the paper's grid labels;
//! the command set and its opcodes; the fault bits; the design decisions that have values.

use mmic::arbitrary::for_each_variant_class;
use mmic::bolter::{BolterStep, MuxLines};
use mmic::command::{BolterPair, HipTarget};
use mmic::faults::Fault;
use mmic::mode::Mode;
use mmic::units::{HipAngle, PulseWidth};
use mmic::wire::checksum::crc16;
use mmic::wire::opcode::{decode, encode, PARAM_LEN, PARAM_OFFSET};
use mmic::wire::PacketKind;
use serde::Deserialize;
use std::collections::BTreeMap;
use std::path::PathBuf;

fn spec_path(rel: &str) -> PathBuf {
    PathBuf::from(crate::ROOT).join("spec").join(rel)
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
    /// The decision that introduced a packet the paper does not have.
    decision: Option<String>,
    field: Vec<FieldRow>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct FieldRow {
    name: String,
    start: usize,
    len: usize,
    unit: String,
    meaning: String,
    /// The decision that says what a field holds beyond the paper's label.
    decision: Option<String>,
    /// What the project adds to the paper's label, with its decision (the review page marks it).
    #[serde(default)]
    additions: Vec<Addition>,
    /// The decision that chose the unit, which the paper does not give.
    unit_decision: Option<String>,
}

/// Something the project adds to a paper row (spec/packets, spec/commands.toml,
/// spec/faults.toml): what, its decision and, for a packet field, the bytes it concerns.
#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct Addition {
    #[allow(dead_code)]
    what: String,
    decision: String,
    bytes: Option<Vec<usize>>,
}

// req: T2/*, T3/*, T4/*, P3.12, P3.16, P4.7
#[test]
#[cfg_attr(
    miri,
    ignore = "spec/ text through toml and string scans: no library path Miri adds to; tens of minutes under Miri"
)]
fn packets_match_spec_field_by_field_and_cell_by_cell() {
    let mut checked_fields = 0;
    let mut checked_cells = 0;
    let decisions: Decisions = load("decisions.toml");
    let ids: Vec<&str> = decisions.decision.iter().map(|d| d.id.as_str()).collect();
    for kind in PacketKind::ALL {
        let spec: PacketSpec = load(&format!("packets/{}.toml", kind.name()));
        // A packet the paper has no table for is the project's, and says which decision.
        assert_eq!(
            spec.paper_cells.is_none(),
            spec.decision.is_some(),
            "{kind}"
        );
        for id in spec.decision.iter().chain(spec.field.iter().flat_map(|f| {
            f.decision
                .iter()
                .chain(&f.unit_decision)
                .chain(f.additions.iter().map(|a| &a.decision))
        })) {
            assert!(ids.contains(&id.as_str()), "{kind}: no decision {id}");
        }
        // An addition's bytes are bytes of its field.
        for f in &spec.field {
            for b in f.additions.iter().flat_map(|a| a.bytes.iter().flatten()) {
                assert!(
                    (f.start..f.start + f.len).contains(b),
                    "{kind}.{}: addition over byte {b}",
                    f.name
                );
            }
        }
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
    decision: String,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct OpcodeRow {
    opcode: u8,
    kind: String,
    variant: String,
    params: Vec<usize>,
    #[serde(default)]
    additions: Vec<Addition>,
}

// req: T1/*
#[test]
#[cfg_attr(
    miri,
    ignore = "spec/ text through toml and string scans: no library path Miri adds to; tens of minutes under Miri"
)]
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
    // Each kind not in Table 1 names the decision that added it, and that decision names it.
    let decisions: Decisions = load("decisions.toml");
    for e in &spec.extension {
        let d = decisions.decision.iter().find(|d| d.id == e.decision);
        let d = d.unwrap_or_else(|| panic!("{}: no decision {}", e.kind, e.decision));
        assert!(
            d.decision.contains(&e.kind),
            "decision {} names {}",
            d.id,
            e.kind
        );
    }
    let mut rows: BTreeMap<u8, &OpcodeRow> = BTreeMap::new();
    for r in &spec.opcode {
        for a in &r.additions {
            assert!(
                a.bytes.is_none(),
                "{:#04x}: bytes belong to packets",
                r.opcode
            );
            let d = decisions.decision.iter().find(|d| d.id == a.decision);
            assert!(d.is_some(), "{:#04x}: no decision {}", r.opcode, a.decision);
        }
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
            let (id, p) = encode(&c);
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
            assert_eq!(decode(id, p), Ok(c));
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
    table8: String,
    /// The decision that added a bit no Table 8 row has.
    decision: Option<String>,
    /// What the code adds to the Table 8 row's trigger.
    #[serde(default)]
    additions: Vec<Addition>,
}

// req: T8/*
#[test]
#[cfg_attr(
    miri,
    ignore = "spec/ text through toml and string scans: no library path Miri adds to; tens of minutes under Miri"
)]
fn fault_bits_match_spec() {
    let spec: Faults = load("faults.toml");
    let decisions: Decisions = load("decisions.toml");
    assert_eq!(spec.fault.len(), Fault::ALL.len());
    for (f, row) in Fault::ALL.iter().zip(&spec.fault) {
        assert_eq!((f.bit(), f.name()), (row.bit, row.name.as_str()));
        // A bit is the project's exactly when it has no Table 8 row, and then it names the
        // decision that added it, which names the fault.
        let own = f.table8().is_none();
        assert_eq!(row.table8.starts_with("none"), own, "{f}: table8");
        assert_eq!(row.decision.is_some(), own, "{f}: decision");
        if let Some(id) = &row.decision {
            let d = decisions.decision.iter().find(|d| &d.id == id);
            let d = d.unwrap_or_else(|| panic!("{f}: no decision {id}"));
            assert!(d.decision.contains(f.name()), "{f}: decision {id}");
        }
        // An addition to a Table 8 row names a decision that names the fault.
        for a in &row.additions {
            assert!(
                !own && a.bytes.is_none(),
                "{f}: additions are to Table 8 rows"
            );
            let d = decisions.decision.iter().find(|d| d.id == a.decision);
            let d = d.unwrap_or_else(|| panic!("{f}: no decision {}", a.decision));
            assert!(
                d.decision.contains(f.name()),
                "{f}: decision {}",
                a.decision
            );
        }
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
#[cfg_attr(
    miri,
    ignore = "spec/ text through toml and string scans: no library path Miri adds to; tens of minutes under Miri"
)]
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
#[cfg_attr(
    miri,
    ignore = "spec/ text through toml and string scans: no library path Miri adds to; tens of minutes under Miri"
)]
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

/// A byte or bit reference in prose: "byte N", "bytes N-M" (hyphen or en dash), likewise
/// "bit"/"bits"; `at..end` is where it stands in the text, `lo..=hi` what it names.
#[derive(Debug)]
struct Mention {
    at: usize,
    end: usize,
    lo: usize,
    hi: usize,
}

fn mentions(text: &str, word: &str) -> Vec<Mention> {
    let lower = text.to_ascii_lowercase();
    let bytes = lower.as_bytes();
    let number = |mut i: usize| {
        let start = i;
        while i < bytes.len() && bytes[i].is_ascii_digit() {
            i += 1;
        }
        (i > start).then(|| (lower[start..i].parse::<usize>().unwrap(), i))
    };
    let mut out = Vec::new();
    for (at, _) in lower.match_indices(word) {
        if at > 0 && (bytes[at - 1].is_ascii_alphanumeric() || bytes[at - 1] == b'-') {
            continue;
        }
        let mut i = at + word.len();
        if bytes.get(i) == Some(&b's') {
            i += 1;
        }
        if bytes.get(i) != Some(&b' ') {
            continue;
        }
        let Some((lo, mut end)) = number(i + 1) else {
            continue;
        };
        let mut hi = lo;
        for dash in ["-", "\u{2013}"] {
            if let Some((m, e)) = lower[end..]
                .strip_prefix(dash)
                .and_then(|_| number(end + dash.len()))
            {
                (hi, end) = (m, e);
            }
        }
        // "byte 0x05" or "bits 8b" name no byte or bit.
        if bytes.get(end).is_some_and(|b| b.is_ascii_alphanumeric()) {
            continue;
        }
        out.push(Mention { at, end, lo, hi });
    }
    out
}

/// The packet a reference means: the last one named before it in the same text.
fn packet_named_before(text: &str, at: usize) -> Option<&'static str> {
    const NAMES: [(&str, &str); 11] = [
        ("table 2", "command"),
        ("command packet", "command"),
        ("table 3", "heartbeat"),
        ("heartbeat", "heartbeat"),
        ("table 4", "internal-heartbeat"),
        ("internal heartbeat", "internal-heartbeat"),
        ("b's heartbeat", "internal-heartbeat"),
        ("b heartbeat", "internal-heartbeat"),
        ("a->b", "b-command"),
        ("a\u{2192}b", "b-command"),
        ("b command", "b-command"),
    ];
    let before = text[..at].to_lowercase();
    NAMES
        .iter()
        .flat_map(|(name, packet)| {
            before
                .match_indices(name)
                .map(move |(i, _)| (i + name.len(), usize::MAX - i, *packet))
        })
        .max()
        .map(|(_, _, p)| p)
}

/// The rest of the clause after a reference: up to the next `;`, `.` (not between digits),
/// `(`, `)` or reference to the same `word`.
fn clause_after<'t>(text: &'t str, end: usize, word: &str) -> &'t str {
    let rest = &text[end..];
    let b = rest.as_bytes();
    let next = mentions(rest, word).first().map_or(b.len(), |m| m.at);
    let stop = (0..next)
        .find(|&i| {
            matches!(b[i], b';' | b'(' | b')')
                || (b[i] == b'.' && !(i > 0 && b[i - 1].is_ascii_digit()))
        })
        .unwrap_or(next);
    &rest[..stop]
}

/// A quoted label right after a reference ("byte 54 'command complete'", "bytes 57-59 are
/// 'empty'"), if there is one.
fn quoted_after(text: &str, end: usize) -> Option<&str> {
    let rest = text[end..].trim_start_matches([' ', ':', ',']);
    let rest = rest
        .strip_prefix("is ")
        .or_else(|| rest.strip_prefix("are "))
        .unwrap_or(rest);
    let q = rest.chars().next().filter(|c| *c == '\'' || *c == '"')?;
    let body = &rest[1..];
    body.find(q).map(|i| &body[..i])
}

/// Prose that states which bytes or bits carry what: the decisions, the packet tables' field
/// meanings, the library's doc comments, the Markdown of spec/ and the README, and the comments
/// of the fault and mode tables. Each with its label, the packet it means when it names none,
/// and whether it quotes the paper (the decisions' `paper` fields).
fn prose_about_bytes() -> Vec<(String, String, Option<&'static str>, bool)> {
    let mut texts = Vec::new();
    let d: Decisions = load("decisions.toml");
    for x in &d.decision {
        texts.push((
            format!("decision {}", x.id),
            x.decision.clone(),
            None,
            false,
        ));
        texts.push((
            format!("decision {} (rationale)", x.id),
            x.rationale.clone(),
            None,
            false,
        ));
        // The `paper` field quotes the paper: its labels are checked, not its meaning.
        texts.push((
            format!("decision {} (paper)", x.id),
            x.paper.clone(),
            None,
            true,
        ));
    }
    for kind in PacketKind::ALL {
        let spec: PacketSpec = load(&format!("packets/{}.toml", kind.name()));
        for f in &spec.field {
            texts.push((
                format!("spec/packets/{}.toml {}", kind.name(), f.name),
                f.meaning.clone(),
                Some(kind.name()),
                false,
            ));
        }
    }
    // The library's doc comments, one block of consecutive lines at a time; a packet module's
    // blocks mean its own packet unless they name another.
    let mut files = vec![PathBuf::from(crate::ROOT).join("src")];
    while let Some(p) = files.pop() {
        if p.is_dir() {
            files.extend(std::fs::read_dir(&p).unwrap().map(|e| e.unwrap().path()));
            continue;
        }
        if p.extension().is_none_or(|e| e != "rs") {
            continue;
        }
        let default = match p.file_stem().and_then(|s| s.to_str()) {
            Some("heartbeat") => Some("heartbeat"),
            Some("internal_heartbeat") => Some("internal-heartbeat"),
            Some("b_command") => Some("b-command"),
            Some("command" | "opcode") if p.parent().is_some_and(|d| d.ends_with("wire")) => {
                Some("command")
            }
            // A packet's module split into a directory: its files speak of that packet.
            _ if p.parent().is_some_and(|d| d.ends_with("wire/opcode")) => Some("command"),
            _ if p.parent().is_some_and(|d| d.ends_with("wire/b_command")) => Some("b-command"),
            _ => None,
        };
        let raw = std::fs::read_to_string(&p).unwrap();
        let mut block: Vec<(usize, &str)> = Vec::new();
        for (n, line) in raw.lines().enumerate().chain([(usize::MAX, "")]) {
            let t = line.trim_start();
            if let Some(doc) = t.strip_prefix("///").or_else(|| t.strip_prefix("//!")) {
                block.push((n + 1, doc.trim()));
            } else if let Some(&(first, _)) = block.first() {
                let text: Vec<&str> = block.iter().map(|b| b.1).collect();
                let name = p.strip_prefix(crate::ROOT).unwrap_or(&p);
                texts.push((
                    format!("{}:{first}", name.display()),
                    text.join(" "),
                    default,
                    false,
                ));
                block.clear();
            }
        }
    }
    // The Markdown of spec/, docs/ and the README, a paragraph at a time.
    let root = PathBuf::from(crate::ROOT);
    let mut md = vec![root.join("README.md")];
    let mut dirs = vec![root.join("spec"), root.join("docs")];
    while let Some(d) = dirs.pop() {
        for e in std::fs::read_dir(&d).unwrap() {
            let p = e.unwrap().path();
            if p.is_dir() {
                dirs.push(p);
            } else if p.extension().is_some_and(|e| e == "md") {
                md.push(p);
            }
        }
    }
    for p in md {
        let raw = std::fs::read_to_string(&p).unwrap();
        let name = p.strip_prefix(&root).unwrap_or(&p).display().to_string();
        for (i, para) in raw.split("\n\n").enumerate() {
            texts.push((
                format!("{name} paragraph {}", i + 1),
                para.replace('\n', " "),
                None,
                false,
            ));
        }
    }
    for file in ["faults.toml", "modes.toml"] {
        let raw = std::fs::read_to_string(spec_path(file)).unwrap();
        let comments: Vec<&str> = raw
            .lines()
            .filter_map(|l| l.trim_start().strip_prefix('#'))
            .map(str::trim)
            .collect();
        texts.push((
            format!("spec/{file} comments"),
            comments.join(" "),
            None,
            false,
        ));
    }
    texts
}

/// Item 7 of issue 24: prose that names a byte range or a fault bit the packet tables
/// contradict fails here (it found "Bytes 25–33" for Table 4's 26–34 in a doc comment).
///
/// For every "byte N" / "bytes N-M" in [`prose_about_bytes`]: the packet it means is the last
/// one named before it in the same text (Table 2/3/4, command packet, (internal) heartbeat,
/// A->B; none named: it must hold in every packet); N must lie in that packet, and a range
/// must start and end on field boundaries of spec/packets; a label quoted right after it must
/// be the paper's cell of every byte (lowByte/highByte aside); a reference the same clause
/// calls empty, reserved or spare must name only reserved bytes. For every "bit N" / "bits
/// N-M": one called spare or reserved must name no fault bit (and lie in the 16-bit map); a
/// "fault bit N" must be a fault whose name the text also gives. What it cannot see: a
/// reference written another way ("the third fault byte", "bytes 6..=11").
#[test]
#[cfg_attr(
    miri,
    ignore = "spec/ text through toml and string scans: no library path Miri adds to; tens of minutes under Miri"
)]
fn prose_names_bytes_and_bits_as_the_packet_tables_do() {
    let packets: BTreeMap<&str, PacketSpec> = PacketKind::ALL
        .iter()
        .map(|k| (k.name(), load(&format!("packets/{}.toml", k.name()))))
        .collect();
    let mut errors = Vec::new();
    let mut checked = (0, 0);
    for (label, text, default, quotes_paper) in prose_about_bytes() {
        for m in mentions(&text, "byte") {
            checked.0 += 1;
            let near = &text[m.at..m.end];
            let named = packet_named_before(&text, m.at).or(default);
            let candidates: Vec<&str> = match named {
                Some(p) => vec![p],
                None => packets.keys().copied().collect(),
            };
            let mut found = Vec::new();
            for p in candidates {
                let spec = &packets[p];
                let starts: Vec<usize> = spec.field.iter().map(|f| f.start).collect();
                let ends: Vec<usize> = spec.field.iter().map(|f| f.start + f.len - 1).collect();
                let fields: Vec<&FieldRow> = spec
                    .field
                    .iter()
                    .filter(|f| f.start <= m.hi && m.lo < f.start + f.len)
                    .collect();
                let why = if m.hi >= spec.length || m.lo > m.hi {
                    Some(format!("the {p} packet has bytes 0-{}", spec.length - 1))
                } else if m.lo != m.hi && !(starts.contains(&m.lo) && ends.contains(&m.hi)) {
                    Some(format!(
                        "cuts a field of the {p} packet: {}",
                        fields
                            .iter()
                            .map(|f| format!("{} = {}-{}", f.name, f.start, f.start + f.len - 1))
                            .collect::<Vec<_>>()
                            .join(", ")
                    ))
                } else if let (Some(q), Some(cells)) =
                    (quoted_after(&text, m.end), &spec.paper_cells)
                {
                    (m.lo..=m.hi)
                        .find(|&i| {
                            let c = &cells[i];
                            *c != q && *c != format!("lowByte {q}") && *c != format!("highByte {q}")
                        })
                        .map(|i| format!("quotes '{q}', Table's byte {i} is '{}'", cells[i]))
                } else if !quotes_paper
                    && ["empty", "reserved", "spare", "emitted as 0", "unless 0"]
                        .iter()
                        .any(|w| clause_after(&text, m.end, "byte").contains(w))
                {
                    fields
                        .iter()
                        .find(|f| f.unit != "reserved")
                        .map(|f| format!("calls it empty, but {p}.{} is {}", f.name, f.unit))
                } else {
                    None
                };
                found.extend(why);
            }
            if !found.is_empty() {
                let hint = if named.is_none() {
                    " (it names no packet before it, so it must hold in every one)"
                } else {
                    ""
                };
                errors.push(format!("{label}: \"{near}\"{hint}: {}", found.join("; ")));
            }
        }
        for m in mentions(&text, "bit") {
            checked.1 += 1;
            let near = &text[m.at..m.end];
            let n = Fault::ALL.len();
            let clause = clause_after(&text, m.end, "bit");
            let before: Vec<char> = text[..m.at].to_lowercase().chars().collect();
            let before: String = before[before.len().saturating_sub(12)..].iter().collect();
            if clause.contains("spare") || clause.contains("reserved") {
                if m.lo < n || m.hi > 15 {
                    errors.push(format!(
                        "{label}: \"{near}\" called spare, but faults use bits 0-{} of 0-15",
                        n - 1
                    ));
                }
            } else if before.contains("fault") {
                if m.hi >= n {
                    errors.push(format!("{label}: \"{near}\": no fault has bit {}", m.hi));
                } else if m.lo == m.hi && !text.contains(Fault::ALL[m.lo].name()) {
                    errors.push(format!(
                        "{label}: \"{near}\" is {}, which the text does not name",
                        Fault::ALL[m.lo].name()
                    ));
                }
            }
        }
    }
    assert!(errors.is_empty(), "{}", errors.join("\n"));
    // The scan finds what it is for (so a change to the parsing cannot make it vacuous).
    assert!(checked.0 >= 150 && checked.1 >= 30, "{checked:?}");
}
