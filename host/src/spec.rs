//! The reviewable tables of spec/ that the host tools read: the ST\[8\] argument table
//! (spec/ccsds/functions.toml), the services, failure codes and events
//! (spec/ccsds/services.toml), the fault names (spec/faults.toml), and what of the paper's
//! tables is the project's, with the decision that introduced it ([`origins`]: spec/faults.toml,
//! spec/commands.toml, spec/modes.toml, spec/packets/), which the review pages mark. They are
//! compiled in (`include_str!`) and parsed once, so the XTCE generator, the PUS codec and the
//! pages have no second copy of any of them; spec/check/tests/pus/spec.rs, spec/check/tests/wire/spec.rs and
//! spec/check/tests/safety/safety_spec.rs hold the library to the same files.

use mmic::faults::Fault;
use mmic::pus::function::FunctionId;
use mmic::pus::request::RequestError;
use mmic::pus::verification::{ABANDONED, KEY_REUSED, QUEUE_FULL, RESTARTED, UNACKNOWLEDGED};
use mmic::refusal::Refusal;
use serde::Deserialize;
use std::collections::BTreeMap;
use std::sync::OnceLock;

/// spec/ccsds/functions.toml.
pub const FUNCTIONS_TOML: &str = include_str!("../../spec/ccsds/functions.toml");
/// spec/ccsds/services.toml.
pub const SERVICES_TOML: &str = include_str!("../../spec/ccsds/services.toml");
/// spec/faults.toml.
pub const FAULTS_TOML: &str = include_str!("../../spec/faults.toml");
/// spec/commands.toml.
pub const COMMANDS_TOML: &str = include_str!("../../spec/commands.toml");
/// spec/boards.toml (the nodes' timing, the opsUI's serial line: [`crate::serial`]).
pub const BOARDS_TOML: &str = include_str!("../../spec/boards.toml");
/// spec/modes.toml.
pub const MODES_TOML: &str = include_str!("../../spec/modes.toml");
/// spec/packets/*.toml, by packet name.
pub const PACKET_TOMLS: [(&str, &str); 4] = [
    ("command", include_str!("../../spec/packets/command.toml")),
    (
        "heartbeat",
        include_str!("../../spec/packets/heartbeat.toml"),
    ),
    (
        "internal-heartbeat",
        include_str!("../../spec/packets/internal-heartbeat.toml"),
    ),
    (
        "b-command",
        include_str!("../../spec/packets/b-command.toml"),
    ),
];

/// One argument of an ST\[8\] function.
#[derive(Debug, Clone, Deserialize, PartialEq, Eq)]
pub struct Arg {
    /// Its name.
    pub name: String,
    /// `u8` or `u16`.
    #[serde(rename = "type")]
    pub ty: String,
    /// Inclusive range.
    pub range: [u32; 2],
    /// Unit, if any.
    #[serde(default)]
    pub unit: Option<String>,
    /// What it means.
    pub meaning: String,
}

impl Arg {
    /// Size in bits (8 or 16).
    pub fn bits(&self) -> u32 {
        match self.ty.as_str() {
            "u16" => 16,
            _ => 8,
        }
    }

    /// A motion state 'a'..='o' (Table 5), sent as its ASCII letter.
    pub fn is_state(&self) -> bool {
        self.range == [u32::from(b'a'), u32::from(b'o')]
    }
}

/// One ST\[8\] function.
#[derive(Debug, Clone, Deserialize, PartialEq, Eq)]
pub struct Function {
    /// Function ID.
    pub id: u8,
    /// Name (`FunctionId::name`).
    pub name: String,
    /// Arguments in order.
    pub args: Vec<Arg>,
}

#[derive(Deserialize)]
struct FunctionsFile {
    function: Vec<Function>,
}

/// One telecommand the robot serves.
#[derive(Debug, Clone, Deserialize, PartialEq, Eq)]
pub struct TcRow {
    /// Service type.
    pub service: u8,
    /// Subservice type.
    pub subservice: u8,
    /// Name.
    pub name: String,
    /// Application data, in words.
    pub app_data: String,
    /// The reports it gets.
    pub reports: String,
}

/// One telemetry packet type the robot sends.
#[derive(Debug, Clone, Deserialize, PartialEq, Eq)]
pub struct TmRow {
    /// Service type.
    pub service: u8,
    /// Its subservices.
    pub subservices: Vec<u8>,
    /// Name.
    pub name: String,
    /// Source data, in words.
    pub source_data: String,
}

/// One row of the ST\[1\] failure code table.
#[derive(Debug, Clone, Deserialize, PartialEq, Eq)]
pub struct FailureRow {
    /// A code (`0x0200`) or a family (`1..=255`, `0x0100 + n`).
    pub code: String,
    /// What it means.
    pub meaning: String,
    /// What its data word carries.
    pub data: String,
}

/// One ST\[5\] event definition.
#[derive(Debug, Clone, Deserialize, PartialEq)]
pub struct EventRow {
    /// Its ID (`0x0001`) or family (`0x0100 + n`).
    pub id: String,
    /// Name.
    pub name: String,
    /// Severity: a number or a sentence.
    pub severity: toml::Value,
    /// Its auxiliary data.
    pub aux: String,
}

/// spec/ccsds/services.toml.
#[derive(Debug, Clone, Deserialize)]
pub struct Services {
    /// Telecommands.
    pub tc: Vec<TcRow>,
    /// Telemetry.
    pub tm: Vec<TmRow>,
    /// Failure codes.
    pub failure: Vec<FailureRow>,
    /// Events.
    pub event: Vec<EventRow>,
}

/// One fault of spec/faults.toml.
#[derive(Debug, Clone, Deserialize)]
pub struct FaultRow {
    /// Its bit.
    pub bit: u8,
    /// Its name.
    pub name: String,
    /// The decision that added it, for a bit no Table 8 row has.
    #[serde(default)]
    pub decision: Option<String>,
}

#[derive(Deserialize)]
struct FaultsFile {
    fault: Vec<FaultRow>,
}

/// The functions of spec/ccsds/functions.toml, in file order.
pub fn functions() -> &'static [Function] {
    static F: OnceLock<Vec<Function>> = OnceLock::new();
    F.get_or_init(|| {
        toml::from_str::<FunctionsFile>(FUNCTIONS_TOML)
            .map(|f| f.function)
            .unwrap_or_default()
    })
}

/// The function named `name` (or with that ID).
pub fn function(id: FunctionId) -> Option<&'static Function> {
    functions().iter().find(|f| f.id == id.id())
}

/// spec/ccsds/services.toml.
pub fn services() -> &'static Services {
    static S: OnceLock<Services> = OnceLock::new();
    S.get_or_init(|| {
        toml::from_str(SERVICES_TOML).unwrap_or(Services {
            tc: Vec::new(),
            tm: Vec::new(),
            failure: Vec::new(),
            event: Vec::new(),
        })
    })
}

/// The faults of spec/faults.toml, in file order.
pub fn faults() -> &'static [FaultRow] {
    static F: OnceLock<Vec<FaultRow>> = OnceLock::new();
    F.get_or_init(|| {
        toml::from_str::<FaultsFile>(FAULTS_TOML)
            .map(|f| f.fault)
            .unwrap_or_default()
    })
}

/// The name of the telecommand (service, subservice), from services.toml.
pub fn tc_name(service: u8, subservice: u8) -> Option<&'static str> {
    services()
        .tc
        .iter()
        .find(|t| t.service == service && t.subservice == subservice)
        .map(|t| t.name.as_str())
}

/// An upper-case label for XTCE enumerations (`not_allowed_in_mode` → `NOT_ALLOWED_IN_MODE`).
pub fn label(name: &str) -> String {
    name.to_ascii_uppercase().replace(['-', ' '], "_")
}

fn parse_code(text: &str) -> Option<u16> {
    match text.strip_prefix("0x") {
        Some(h) => u16::from_str_radix(h, 16).ok(),
        None => text.parse().ok(),
    }
}

/// Every ST\[1\] failure code with its label, ascending: each row of services.toml's failure
/// table expanded (refusal codes with the library's refusal names, fault codes with the fault
/// names of spec/faults.toml, the single codes with the library's constants' names).
/// A row the generator cannot name is an error (services.toml grew a code: name it here).
pub fn failure_codes() -> Result<Vec<(u16, String)>, String> {
    let mut out = Vec::new();
    for row in &services().failure {
        match row.code.as_str() {
            "1..=255" => {
                for r in Refusal::ALL {
                    out.push((
                        u16::from(r.to_wire()),
                        format!("REFUSED_{}", label(r.name())),
                    ));
                }
            }
            "0x0100 + n" => {
                for f in faults() {
                    out.push((
                        0x0100 + u16::from(f.bit),
                        format!("FAULT_{}", label(&f.name)),
                    ));
                }
            }
            text => {
                let code = parse_code(text).ok_or(format!("failure code {text:?}"))?;
                let name = match code {
                    UNACKNOWLEDGED => "UNACKNOWLEDGED".to_string(),
                    ABANDONED => "ABANDONED".to_string(),
                    RESTARTED => "RESTARTED".to_string(),
                    QUEUE_FULL => "QUEUE_FULL".to_string(),
                    KEY_REUSED => "KEY_REUSED".to_string(),
                    0x0301..=0x0306 => RequestError::NAMES
                        .get(usize::from(code - 0x0301))
                        .map(|n| label(n))
                        .unwrap_or_default(),
                    _ => {
                        return Err(format!(
                            "failure code {text} has no name in host/src/spec.rs"
                        ))
                    }
                };
                out.push((code, name));
            }
        }
    }
    out.sort();
    Ok(out)
}

/// The label of a failure code, if it has one.
pub fn failure_label(code: u16) -> Option<String> {
    failure_codes()
        .ok()?
        .into_iter()
        .find(|(c, _)| *c == code)
        .map(|(_, l)| l)
}

/// Every event definition ID with its name, ascending: the single events of services.toml and
/// one `fault_<name>` per fault of spec/faults.toml for the `0x0100 + n` family.
pub fn event_ids() -> Result<Vec<(u16, String)>, String> {
    let mut out = Vec::new();
    for row in &services().event {
        if row.id == "0x0100 + n" {
            for f in faults() {
                out.push((
                    0x0100 + u16::from(f.bit),
                    format!("{}_{}", row.name, f.name),
                ));
            }
        } else if row.id == "0x0200 + n" {
            for (n, reason) in mmic::link::sdls::SdlsRefusal::NAMES.iter().enumerate() {
                out.push((
                    0x0200 + n as u16,
                    format!("{}_{}", row.name, reason.replace('-', "_")),
                ));
            }
        } else {
            let id = parse_code(&row.id).ok_or(format!("event ID {:?}", row.id))?;
            out.push((id, row.name.clone()));
        }
    }
    out.sort();
    Ok(out)
}

/// The fault of a bit, by the library.
pub fn fault_of_bit(bit: u8) -> Option<Fault> {
    Fault::ALL.into_iter().find(|f| f.bit() == bit)
}

/// What of the paper's tables is the project's, and the decision that introduced each: read
/// from spec/ for the review pages ([`crate::pages`]), which mark those rows.
#[derive(Debug, Clone, Default)]
pub struct Origins {
    /// Table 1's kinds with their "Command Type" cell, in the table's order.
    pub table1: Vec<(String, String)>,
    /// Command kinds not in Table 1 → decision.
    pub extensions: BTreeMap<String, String>,
    /// Table 7's command availability as printed, mode → kinds.
    pub table7_accepts: BTreeMap<String, Vec<String>>,
    /// A kind accepted beyond Table 7 → decision.
    pub accepts_decisions: BTreeMap<String, String>,
    /// Refusal code name → decision.
    pub refusal_decisions: BTreeMap<String, String>,
    /// A rule of spec/modes.toml `[rules]` that is the project's → decision.
    pub rule_decisions: BTreeMap<String, String>,
    /// Packet name → what of it is the project's.
    pub packets: BTreeMap<String, PacketOrigin>,
    /// Opcode → what its row adds to Table 1 (spec/commands.toml `additions`).
    pub opcode_additions: BTreeMap<u8, Vec<Addition>>,
    /// Fault name → what the code adds to its Table 8 row (spec/faults.toml `additions`).
    pub fault_additions: BTreeMap<String, Vec<Addition>>,
}

/// Something the project adds to a row or field of the paper's (the paper's label stands, the
/// project says more): what, and the decision that says it.
#[derive(Debug, Clone, Deserialize, PartialEq, Eq)]
#[serde(deny_unknown_fields)]
pub struct Addition {
    /// What is added, in a few words.
    pub what: String,
    /// The spec/decisions.toml entry.
    pub decision: String,
    /// For a packet field: the bytes it concerns, when not all of the field's.
    #[serde(default)]
    pub bytes: Option<Vec<usize>>,
}

/// What of one packet field is the project's.
#[derive(Debug, Clone, Default, PartialEq, Eq)]
pub struct FieldOrigin {
    /// The decision that says what the field holds instead of (or beyond) the paper's label.
    pub decision: Option<String>,
    /// What the project adds to the paper's label.
    pub additions: Vec<Addition>,
    /// The decision that chose the field's unit, which the paper does not give.
    pub unit_decision: Option<String>,
}

impl FieldOrigin {
    /// Whether byte `i` of the field carries something the paper's label does not say: the field's own decision, or an addition over that byte. A unit alone does
    /// not mark a byte (the unit column says it).
    pub fn marks_byte(&self, i: usize) -> bool {
        self.decision.is_some()
            || self
                .additions
                .iter()
                .any(|a| a.bytes.as_ref().is_none_or(|b| b.contains(&i)))
    }
}

/// What of one packet is the project's.
#[derive(Debug, Clone, Default, PartialEq, Eq)]
pub struct PacketOrigin {
    /// The decision that introduced a packet the paper does not have.
    pub decision: Option<String>,
    /// Field name → its origin (every field of the packet).
    pub fields: BTreeMap<String, FieldOrigin>,
}

#[derive(Deserialize)]
struct CommandsFile {
    table1: Vec<Table1Row>,
    extension: Vec<ExtensionRow>,
    opcode: Vec<OpcodeRow>,
}

#[derive(Deserialize)]
struct OpcodeRow {
    opcode: u8,
    #[serde(default)]
    additions: Vec<Addition>,
}

#[derive(Deserialize)]
struct FaultsAdditionsFile {
    fault: Vec<FaultAdditions>,
}

#[derive(Deserialize)]
struct FaultAdditions {
    name: String,
    #[serde(default)]
    additions: Vec<Addition>,
}

#[derive(Deserialize)]
struct Table1Row {
    command_type: String,
    kind: String,
}

#[derive(Deserialize)]
struct ExtensionRow {
    kind: String,
    decision: String,
}

#[derive(Deserialize)]
struct ModesFile {
    table7_accepts: BTreeMap<String, Vec<String>>,
    accepts_decisions: BTreeMap<String, String>,
    refusal_decisions: BTreeMap<String, String>,
    #[serde(default)]
    rule_decisions: BTreeMap<String, String>,
}

#[derive(Deserialize)]
struct PacketFile {
    #[serde(default)]
    decision: Option<String>,
    field: Vec<PacketField>,
}

#[derive(Deserialize)]
struct PacketField {
    name: String,
    #[serde(default)]
    decision: Option<String>,
    #[serde(default)]
    additions: Vec<Addition>,
    #[serde(default)]
    unit_decision: Option<String>,
}

fn read_origins() -> Result<Origins, toml::de::Error> {
    let c: CommandsFile = toml::from_str(COMMANDS_TOML)?;
    let m: ModesFile = toml::from_str(MODES_TOML)?;
    let mut packets = BTreeMap::new();
    for (name, text) in PACKET_TOMLS {
        let p: PacketFile = toml::from_str(text)?;
        let fields = p
            .field
            .into_iter()
            .map(|f| {
                let origin = FieldOrigin {
                    decision: f.decision,
                    additions: f.additions,
                    unit_decision: f.unit_decision,
                };
                (f.name, origin)
            })
            .collect();
        let origin = PacketOrigin {
            decision: p.decision,
            fields,
        };
        packets.insert(name.to_string(), origin);
    }
    let f: FaultsAdditionsFile = toml::from_str(FAULTS_TOML)?;
    Ok(Origins {
        table1: c
            .table1
            .into_iter()
            .map(|r| (r.kind, r.command_type))
            .collect(),
        extensions: c
            .extension
            .into_iter()
            .map(|e| (e.kind, e.decision))
            .collect(),
        table7_accepts: m.table7_accepts,
        accepts_decisions: m.accepts_decisions,
        refusal_decisions: m.refusal_decisions,
        rule_decisions: m.rule_decisions,
        packets,
        opcode_additions: c
            .opcode
            .into_iter()
            .filter(|o| !o.additions.is_empty())
            .map(|o| (o.opcode, o.additions))
            .collect(),
        fault_additions: f
            .fault
            .into_iter()
            .filter(|r| !r.additions.is_empty())
            .map(|r| (r.name, r.additions))
            .collect(),
    })
}

/// The project's additions to the paper's tables, from spec/ (empty if a file does not parse:
/// the pages then mark the project's rows with no decision, which their test refuses).
pub fn origins() -> &'static Origins {
    static O: OnceLock<Origins> = OnceLock::new();
    O.get_or_init(|| read_origins().unwrap_or_default())
}
