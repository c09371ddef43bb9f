//! Writes the [model](super::model) as XTCE XML through quick-xml's indenting [`Writer`]: it
//! escapes every attribute and text, nests and indents (two spaces, `<empty />` with a space as
//! the file always had), so each function here only says which element holds what.

use super::model::{
    Algorithm, Argument, BaseContainer, BaseMetaCommand, CommandContainer, CommandEntry, Commands,
    Comparison, Container, DataType, EnumeratedType, IntegerType, MetaCommand, Op, Parameter,
    Restriction, Role, SpaceSystem, Telemetry, Verifier,
};
use quick_xml::events::{BytesDecl, BytesText, Event};
use quick_xml::Writer;
use std::io;

/// The writer, into memory.
type Xml = Writer<Vec<u8>>;
/// What every writing step returns (only the `Vec`'s allocation can fail).
type Step = io::Result<()>;

/// XTCE 1.2's namespace.
const XTCE_NS: &str = "http://www.omg.org/spec/XTCE/20180204";
/// The XML Schema instance namespace (for `schemaLocation`).
const XSI_NS: &str = "http://www.w3.org/2001/XMLSchema-instance";
/// Where XTCE 1.2's schema is, for validating editors.
const SCHEMA_LOCATION: &str =
    "http://www.omg.org/spec/XTCE/20180204 https://www.omg.org/spec/XTCE/20180204/SpaceSystem.xsd";

/// The whole document: declaration, preamble comment, `SpaceSystem`; ends with a newline.
pub fn document(s: &SpaceSystem) -> io::Result<String> {
    let mut w = Writer::new_with_indent(Vec::new(), b' ', 2);
    w.config_mut().add_space_before_slash_in_empty_elements = true;
    w.write_event(Event::Decl(BytesDecl::new("1.0", Some("UTF-8"), None)))?;
    w.write_event(Event::Comment(BytesText::from_escaped(s.preamble)))?;
    w.create_element("SpaceSystem")
        .with_attribute(("name", s.name))
        .with_attribute(("xmlns", XTCE_NS))
        .new_line()
        .with_attribute(("xmlns:xsi", XSI_NS))
        .new_line()
        .with_attribute(("xsi:schemaLocation", SCHEMA_LOCATION))
        .write_inner_content(|w| {
            empty(
                w,
                "Header",
                &[("validationStatus", "Working"), ("version", "1")],
            )?;
            telemetry(w, &s.telemetry)?;
            commands(w, &s.commands)
        })?;
    let mut text = String::from_utf8(w.into_inner())
        .map_err(|e| io::Error::new(io::ErrorKind::InvalidData, e))?;
    text.push('\n');
    Ok(text)
}

/// `<name attrs />`.
fn empty(w: &mut Xml, name: &str, attrs: &[(&str, &str)]) -> Step {
    w.create_element(name)
        .with_attributes(attrs.iter().copied())
        .write_empty()?;
    Ok(())
}

/// `<name attrs>text</name>`.
fn text(w: &mut Xml, name: &str, attrs: &[(&str, &str)], text: &str) -> Step {
    w.create_element(name)
        .with_attributes(attrs.iter().copied())
        .write_text_content(BytesText::new(text))?;
    Ok(())
}

/// `<name attrs>` what `inner` writes `</name>`.
fn parent(
    w: &mut Xml,
    name: &str,
    attrs: &[(&str, &str)],
    inner: impl FnOnce(&mut Xml) -> Step,
) -> Step {
    w.create_element(name)
        .with_attributes(attrs.iter().copied())
        .write_inner_content(inner)?;
    Ok(())
}

/// `list` inside `<name>`.
fn each<T>(w: &mut Xml, name: &str, list: &[T], item: impl Fn(&mut Xml, &T) -> Step) -> Step {
    parent(w, name, &[], |w| list.iter().try_for_each(|t| item(w, t)))
}

/// `TelemetryMetaData`.
fn telemetry(w: &mut Xml, t: &Telemetry) -> Step {
    parent(w, "TelemetryMetaData", &[], |w| {
        each(w, "ParameterTypeSet", &t.types, data_type)?;
        each(w, "ParameterSet", &t.parameters, parameter)?;
        each(w, "ContainerSet", &t.containers, container)
    })
}

/// `CommandMetaData`.
fn commands(w: &mut Xml, c: &Commands) -> Step {
    parent(w, "CommandMetaData", &[], |w| {
        each(w, "ArgumentTypeSet", &c.types, data_type)?;
        each(w, "MetaCommandSet", &c.meta_commands, meta_command)
    })
}

/// `name`, then `shortDescription` if there is one.
fn named<'a>(name: &'a str, description: Option<&'a str>) -> Vec<(&'a str, &'a str)> {
    let mut attrs = vec![("name", name)];
    attrs.extend(description.map(|d| ("shortDescription", d)));
    attrs
}

/// The element of a data type of `kind` (`Integer`, `Enumerated`) for `role`.
fn type_element(kind: &str, role: Role) -> String {
    let role = match role {
        Role::Parameter => "Parameter",
        Role::Argument => "Argument",
    };
    format!("{kind}{role}Type")
}

/// A parameter or argument type.
fn data_type(w: &mut Xml, t: &DataType) -> Step {
    match t {
        DataType::Integer(i) => integer_type(w, i),
        DataType::Enumerated(e) => enumerated_type(w, e),
    }
}

/// `IntegerDataEncoding` of `bits` bits (unsigned, XTCE's default encoding).
fn encoding(w: &mut Xml, bits: usize) -> Step {
    empty(
        w,
        "IntegerDataEncoding",
        &[("sizeInBits", &bits.to_string())],
    )
}

/// An unsigned integer type: unit, encoding, valid range.
fn integer_type(w: &mut Xml, t: &IntegerType) -> Step {
    let mut attrs = vec![("name", t.name.as_str()), ("signed", "false")];
    attrs.extend(t.description.as_deref().map(|d| ("shortDescription", d)));
    parent(w, &type_element("Integer", t.role), &attrs, |w| {
        if let Some(u) = &t.unit {
            let attrs: Vec<_> = u
                .description
                .map(|d| ("description", d))
                .into_iter()
                .collect();
            parent(w, "UnitSet", &[], |w| text(w, "Unit", &attrs, &u.symbol))?;
        }
        encoding(w, t.bits)?;
        match t.range {
            Some((min, max)) => parent(w, "ValidRangeSet", &[], |w| {
                let (min, max) = (min.to_string(), max.to_string());
                empty(
                    w,
                    "ValidRange",
                    &[("minInclusive", &min), ("maxInclusive", &max)],
                )
            }),
            None => Ok(()),
        }
    })
}

/// An enumerated type: encoding and labels.
fn enumerated_type(w: &mut Xml, t: &EnumeratedType) -> Step {
    let attrs = named(&t.name, Some(&t.description));
    parent(w, &type_element("Enumerated", t.role), &attrs, |w| {
        encoding(w, t.bits)?;
        each(w, "EnumerationList", &t.values, |w, (value, label)| {
            empty(
                w,
                "Enumeration",
                &[("value", &value.to_string()), ("label", label)],
            )
        })
    })
}

/// A `Parameter`.
fn parameter(w: &mut Xml, p: &Parameter) -> Step {
    let attrs = [
        ("name", p.name.as_str()),
        ("parameterTypeRef", &p.type_ref),
        ("shortDescription", &p.description),
    ];
    empty(w, "Parameter", &attrs)
}

/// `name`, `abstract="true"` if it is, `shortDescription`.
fn maybe_abstract<'a>(
    name: &'a str,
    is_abstract: bool,
    description: &'a str,
) -> Vec<(&'a str, &'a str)> {
    let mut attrs = vec![("name", name)];
    if is_abstract {
        attrs.push(("abstract", "true"));
    }
    attrs.push(("shortDescription", description));
    attrs
}

/// A `SequenceContainer`: its entries, then its base and restriction.
fn container(w: &mut Xml, c: &Container) -> Step {
    let attrs = maybe_abstract(&c.name, c.is_abstract, &c.description);
    parent(w, "SequenceContainer", &attrs, |w| {
        each(w, "EntryList", &c.entries, |w, p| {
            empty(w, "ParameterRefEntry", &[("parameterRef", p)])
        })?;
        match &c.base {
            Some(b) => base_container(w, b),
            None => Ok(()),
        }
    })
}

/// `BaseContainer` with its `RestrictionCriteria`.
fn base_container(w: &mut Xml, b: &BaseContainer) -> Step {
    parent(w, "BaseContainer", &[("containerRef", &b.container)], |w| {
        parent(w, "RestrictionCriteria", &[], |w| match &b.restriction {
            Restriction::All(all) => each(w, "ComparisonList", all, comparison),
            Restriction::AllAndAny { all, any } => parent(w, "BooleanExpression", &[], |w| {
                parent(w, "ANDedConditions", &[], |w| {
                    all.iter().try_for_each(|c| condition(w, c))?;
                    each(w, "ORedConditions", any, condition)
                })
            }),
        })
    })
}

/// A `Comparison` of the raw value (`==` is XTCE's default and left out).
fn comparison(w: &mut Xml, c: &Comparison) -> Step {
    let value = c.value.to_string();
    let mut attrs = vec![("parameterRef", c.parameter.as_str()), ("value", &value)];
    if c.op != Op::Eq {
        attrs.push(("comparisonOperator", c.op.text()));
    }
    attrs.push(("useCalibratedValue", "false"));
    empty(w, "Comparison", &attrs)
}

/// A `Condition` of a `BooleanExpression`.
fn condition(w: &mut Xml, c: &Comparison) -> Step {
    parent(w, "Condition", &[], |w| {
        empty(w, "ParameterInstanceRef", &[("parameterRef", &c.parameter)])?;
        text(w, "ComparisonOperator", &[], c.op.text())?;
        text(w, "Value", &[], &c.value.to_string())
    })
}

/// A `MetaCommand`: base, arguments, container, verifiers.
fn meta_command(w: &mut Xml, m: &MetaCommand) -> Step {
    let attrs = maybe_abstract(&m.name, m.is_abstract, &m.description);
    parent(w, "MetaCommand", &attrs, |w| {
        if let Some(b) = &m.base {
            base_meta_command(w, b)?;
        }
        if !m.arguments.is_empty() {
            each(w, "ArgumentList", &m.arguments, argument)?;
        }
        command_container(w, &m.container)?;
        if let Some(note) = m.verifier_note {
            // A comment is not escaped: its text goes as it is.
            w.write_event(Event::Comment(BytesText::from_escaped(note)))?;
        }
        if !m.verifiers.is_empty() {
            each(w, "VerifierSet", &m.verifiers, verifier)?;
        }
        Ok(())
    })
}

/// `BaseMetaCommand` with its argument assignments.
fn base_meta_command(w: &mut Xml, b: &BaseMetaCommand) -> Step {
    parent(
        w,
        "BaseMetaCommand",
        &[("metaCommandRef", &b.meta_command)],
        |w| {
            each(
                w,
                "ArgumentAssignmentList",
                &b.assignments,
                |w, (name, value)| {
                    empty(
                        w,
                        "ArgumentAssignment",
                        &[("argumentName", name), ("argumentValue", value)],
                    )
                },
            )
        },
    )
}

/// An `Argument`.
fn argument(w: &mut Xml, a: &Argument) -> Step {
    let mut attrs = vec![("name", a.name.as_str()), ("argumentTypeRef", &a.type_ref)];
    attrs.extend(a.initial.as_deref().map(|v| ("initialValue", v)));
    attrs.extend(a.description.as_deref().map(|d| ("shortDescription", d)));
    empty(w, "Argument", &attrs)
}

/// A `CommandContainer`: entries, then the container it continues.
fn command_container(w: &mut Xml, c: &CommandContainer) -> Step {
    parent(w, "CommandContainer", &[("name", &c.name)], |w| {
        each(w, "EntryList", &c.entries, command_entry)?;
        match &c.base {
            Some(b) => empty(w, "BaseContainer", &[("containerRef", b)]),
            None => Ok(()),
        }
    })
}

/// A fixed value or an argument in a command container.
fn command_entry(w: &mut Xml, e: &CommandEntry) -> Step {
    match e {
        CommandEntry::Fixed { name, hex, bits } => {
            let bits = bits.to_string();
            let attrs = [("name", *name), ("binaryValue", hex), ("sizeInBits", &bits)];
            empty(w, "FixedValueEntry", &attrs)
        }
        CommandEntry::Argument(a) => empty(w, "ArgumentRefEntry", &[("argumentRef", a)]),
    }
}

/// A verifier: its algorithm, window and time-out behaviour.
fn verifier(w: &mut Xml, v: &Verifier) -> Step {
    let attrs: Vec<_> = v.stage.name().map(|n| ("name", n)).into_iter().collect();
    parent(w, v.stage.element(), &attrs, |w| {
        algorithm(w, &v.algorithm)?;
        let window = [
            ("timeToStopChecking", v.window),
            ("timeWindowIsRelativeTo", "commandRelease"),
        ];
        empty(w, "CheckWindow", &window)?;
        if v.fail_on_timeout {
            parent(w, "AncillaryDataSet", &[], |w| {
                text(w, "AncillaryData", &[("name", "yamcs.onTimeout")], "FAIL")
            })?;
        }
        Ok(())
    })
}

/// A `CustomAlgorithm`: its text and inputs.
fn algorithm(w: &mut Xml, a: &Algorithm) -> Step {
    let attrs = named(&a.name, Some(&a.description));
    parent(w, "CustomAlgorithm", &attrs, |w| {
        text(w, "AlgorithmText", &[("language", a.language)], &a.text)?;
        each(w, "InputSet", &a.inputs, |w, i| {
            let instance = i.instance.map(|n| n.to_string());
            let mut attrs = vec![("parameterRef", i.parameter)];
            attrs.extend(instance.as_deref().map(|n| ("instance", n)));
            attrs.push(("inputName", i.name));
            empty(w, "InputParameterInstanceRef", &attrs)
        })
    })
}
