//! The `CommandMetaData` of the mission database: the abstract `pus-tc` (the TC header, filled
//! in by YAMCS's PusCommandPostprocessor, and the ST\[1\] verifiers), one TC(8,1) meta-command
//! per function of spec/ccsds/functions.toml, and the other TCs of spec/ccsds/services.toml.

use super::model::{
    Argument, BaseMetaCommand, CommandContainer, CommandEntry, Commands, DataType, IntegerType,
    MetaCommand, Role, Unit,
};
use super::telemetry::{enumerated, failure_subservices, states};
use super::verifier::verifiers;
use super::{APID_MAX, APID_MIN};
use crate::spec::{self, Arg, Function, TcRow};
use mmic::pus::housekeeping::{MAX_INTERVAL_MS, MIN_INTERVAL_MS, ROBOT_SID};

/// Why the verifiers are algorithms, in the file beside them.
const VERIFIER_NOTE: &str = " ST[1]: matched on the request ID (the TC's APID and sequence count) by algorithms, not BooleanExpression (issue 24, host/src/xtce/verifier.rs); success reports need their ack flag (default 15: all) ";

/// The whole `CommandMetaData`.
pub fn commands() -> Commands {
    let functions = spec::functions();
    let mut meta_commands = vec![pus_tc()];
    meta_commands.extend(functions.iter().map(function_command));
    meta_commands.extend(
        spec::services()
            .tc
            .iter()
            .filter(|t| t.service != 8)
            .map(service_command),
    );
    Commands {
        types: argument_types(functions),
        meta_commands,
    }
}

/// An argument's unsigned integer type.
fn uint(
    name: &str,
    bits: usize,
    description: Option<&str>,
    unit: Option<Unit>,
    range: Option<(u32, u32)>,
) -> DataType {
    DataType::Integer(IntegerType {
        role: Role::Argument,
        name: name.into(),
        description: description.map(Into::into),
        unit,
        bits,
        range,
    })
}

/// The argument types: the header's, the HK interval's, then each function argument's.
fn argument_types(functions: &[Function]) -> Vec<DataType> {
    let mut types: Vec<DataType> = [("uint4", 4), ("uint8", 8), ("uint16", 16)]
        .into_iter()
        .map(|(name, bits)| uint(name, bits, None, None, None))
        .collect();
    let apids = (u32::from(APID_MIN), u32::from(APID_MAX));
    types.push(uint(
        "apid_type",
        11,
        Some("robot n's APID: 0x100 + n"),
        None,
        Some(apids),
    ));
    let ms = Unit {
        symbol: "ms".into(),
        description: Some("millisecond"),
    };
    let interval = (MIN_INTERVAL_MS, MAX_INTERVAL_MS);
    types.push(uint("interval_ms_type", 32, None, Some(ms), Some(interval)));
    for f in functions {
        types.extend(f.args.iter().map(|a| function_argument_type(f, a)));
    }
    types
}

/// The name of a function argument's type.
fn arg_type_name(function: &str, a: &Arg) -> String {
    format!("{function}_{}_type", a.name)
}

/// A function argument's type: the states its range allows, or an integer within its range.
fn function_argument_type(f: &Function, a: &Arg) -> DataType {
    let name = arg_type_name(&f.name, a);
    let bits = a.bits() as usize;
    if a.is_state() {
        let allowed = a.range[0]..=a.range[1];
        let values = states(false)
            .into_iter()
            .filter(|(v, _)| allowed.contains(v))
            .collect();
        return enumerated(Role::Argument, &name, bits, values, &a.meaning);
    }
    let unit = a.unit.as_ref().map(|u| Unit {
        symbol: u.clone(),
        description: None,
    });
    let range = Some((a.range[0], a.range[1]));
    uint(&name, bits, Some(&a.meaning), unit, range)
}

/// An argument with a type and, if given, an initial value.
fn argument(name: &str, type_ref: &str, initial: Option<&str>) -> Argument {
    Argument {
        name: name.into(),
        type_ref: type_ref.into(),
        initial: initial.map(Into::into),
        description: None,
    }
}

/// A constant of `bits` bits, `hex` its octets.
fn fixed(name: &'static str, hex: &str, bits: usize) -> CommandEntry {
    CommandEntry::Fixed {
        name,
        hex: hex.into(),
        bits,
    }
}

/// The abstract `pus-tc`: the TC's primary and secondary header, and the ST\[1\] verifiers.
fn pus_tc() -> MetaCommand {
    let apid_min = APID_MIN.to_string();
    let arg = |name: &str| CommandEntry::Argument(name.into());
    MetaCommand {
        name: "pus-tc".into(),
        is_abstract: true,
        description: "every PUS-C TC to a robot; YAMCS's PusCommandPostprocessor fills in length, sequence count and CRC".into(),
        base: None,
        arguments: vec![
            argument("apid", "apid_type", Some(&apid_min)),
            argument("ack_flags", "uint4", Some("15")),
            argument("service", "uint8", None),
            argument("subservice", "uint8", None),
            argument("source_id", "uint16", Some("0")),
        ],
        container: CommandContainer {
            name: "pus-tc".into(),
            entries: vec![
                fixed("ccsds_version", "00", 3),
                fixed("ccsds_type_tc", "01", 1),
                fixed("ccsds_sec_hdr", "01", 1),
                arg("apid"),
                fixed("ccsds_seq_flags", "03", 2),
                fixed("ccsds_seq_count", "0000", 14),
                fixed("ccsds_length", "0000", 16),
                fixed("pus_version", "02", 4),
                arg("ack_flags"),
                arg("service"),
                arg("subservice"),
                arg("source_id"),
            ],
            base: None,
        },
        verifier_note: Some(VERIFIER_NOTE),
        verifiers: verifiers(&failure_subservices()),
    }
}

/// A concrete TC(service, subservice): derives from `pus-tc`, whose container it continues.
fn concrete(name: &str, description: String, service: u8, subservice: u8) -> MetaCommand {
    let assign = |n: &str, v: u8| (n.to_string(), v.to_string());
    MetaCommand {
        name: name.into(),
        is_abstract: false,
        description,
        base: Some(BaseMetaCommand {
            meta_command: "pus-tc".into(),
            assignments: vec![assign("service", service), assign("subservice", subservice)],
        }),
        arguments: Vec::new(),
        container: CommandContainer {
            name: name.into(),
            entries: Vec::new(),
            base: Some("pus-tc".into()),
        },
        verifier_note: None,
        verifiers: Vec::new(),
    }
}

/// TC(8,1) of a function: its ID, then its arguments.
fn function_command(f: &Function) -> MetaCommand {
    let description = format!("TC(8,1) function {}: {}", f.id, f.name);
    let mut c = concrete(&f.name, description, 8, 1);
    c.arguments = f
        .args
        .iter()
        .map(|a| Argument {
            description: Some(a.meaning.clone()),
            ..argument(&a.name, &arg_type_name(&f.name, a), None)
        })
        .collect();
    c.container
        .entries
        .push(fixed("function_id", &format!("{:02x}", f.id), 8));
    let args = f
        .args
        .iter()
        .map(|a| CommandEntry::Argument(a.name.clone()));
    c.container.entries.extend(args);
    c
}

/// A TC other than ST\[8\]: ST\[3\]'s name the robot's housekeeping structure (one of it), and
/// TC(3,31) carries the new interval.
fn service_command(t: &TcRow) -> MetaCommand {
    let description = format!("TC({},{}): {}", t.service, t.subservice, t.app_data);
    let mut c = concrete(&t.name, description, t.service, t.subservice);
    if t.service == 3 {
        let sid = format!("{ROBOT_SID:02x}");
        c.container.entries.push(fixed("n", "01", 8));
        c.container.entries.push(fixed("structure_id", &sid, 8));
    }
    if (t.service, t.subservice) == (3, 31) {
        c.arguments
            .push(argument("interval_ms", "interval_ms_type", None));
        c.container
            .entries
            .push(CommandEntry::Argument("interval_ms".into()));
    }
    c
}
