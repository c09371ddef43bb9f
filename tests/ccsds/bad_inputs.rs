//! Walks `spec/ccsds/bad-inputs.toml`: every row's packet (or TC or TM frame), through the
//! parser it names, must be refused with exactly the error it names; every check of
//! `PacketError::NAMES`, `RequestError::NAMES`, `TcFrameError::NAMES` and `TmFrameError::NAMES`
//! has a row.

use super::{hex, unhex};
use mmic::ccsds::tc::TcRepr;
use mmic::ccsds::tm::TmRepr;
use mmic::ccsds::PacketError;
use mmic::link::tc_frame::{TcFrame, TcFrameError};
use mmic::link::tm_frame::{TmFrameError, TmFrameRepr};
use mmic::pus::PusError;
use serde::Deserialize;
use std::collections::{BTreeMap, BTreeSet};
use std::path::PathBuf;
use std::sync::OnceLock;

#[derive(Debug, PartialEq, Eq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Table {
    pub parser: Parser,
    pub row: Vec<Row>,
}

#[derive(Debug, PartialEq, Eq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Parser {
    pub apids: Vec<u16>,
}

#[derive(Debug, PartialEq, Eq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Row {
    pub name: String,
    pub parser: String,
    pub hex: String,
    pub error: String,
    pub why: String,
}

fn table_text() -> (PathBuf, String) {
    let p = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("spec/ccsds/bad-inputs.toml");
    let text = std::fs::read_to_string(&p).unwrap_or_else(|e| panic!("{}: {e}", p.display()));
    (p, text)
}

/// The table, read once per test binary by the toml crate; under Miri by [`table_by_lines`]
/// (the toml parser takes about a minute of Miri's interpretation for this file).
pub fn table() -> &'static Table {
    static TABLE: OnceLock<Table> = OnceLock::new();
    TABLE.get_or_init(|| {
        if cfg!(miri) {
            // Compiled in: Miri's reading of the file through its shims and std's UTF-8
            // check took longer than the rows' checks.
            return table_by_lines(include_str!("../../spec/ccsds/bad-inputs.toml"));
        }
        let (p, text) = table_text();
        toml::from_str(&text).unwrap_or_else(|e| panic!("{}: {e}", p.display()))
    })
}

/// The table read line by line, in the file's own narrow format: `apids = [0x…, …]` and
/// `key = "value"` lines under `[[row]]`, comments and blank lines skipped; anything else
/// panics. `the_line_reader_reads_what_toml_reads` holds it equal to the toml crate's reading.
/// Byte by byte: this is Miri's reading (.ci/miri), where `str`'s pattern searchers
/// (`lines`, `split_once(" = ")`) took 32 s of interpretation over this 24 KB file.
pub fn table_by_lines(text: &str) -> Table {
    let utf8 = |b: &[u8]| String::from_utf8(b.to_vec()).expect("the file is UTF-8");
    let mut apids = None;
    let mut rows: Vec<BTreeMap<String, String>> = Vec::new();
    for line in text
        .as_bytes()
        .split(|&b| b == b'\n')
        .map(<[u8]>::trim_ascii)
    {
        if line.is_empty() || line[0] == b'#' || line == b"[parser]" {
            continue;
        }
        if line == b"[[row]]" {
            rows.push(BTreeMap::new());
            continue;
        }
        let at = line.windows(3).position(|w| w == b" = ");
        let at = at.unwrap_or_else(|| panic!("not `key = value`: {}", utf8(line)));
        let (key, value) = (&line[..at], &line[at + 3..]);
        if key == b"apids" {
            let list = value.strip_prefix(b"[").and_then(|v| v.strip_suffix(b"]"));
            let list = list.unwrap_or_else(|| panic!("apids: {}", utf8(value)));
            let apid = |a: &[u8]| {
                let a = a.trim_ascii();
                let a = a.strip_prefix(b"0x").unwrap_or(a);
                u16::from_str_radix(&utf8(a), 16)
            };
            apids = Some(
                list.split(|&b| b == b',')
                    .map(|a| apid(a).unwrap())
                    .collect(),
            );
            continue;
        }
        let value = value
            .strip_prefix(b"\"")
            .and_then(|v| v.strip_suffix(b"\""));
        let value = value.unwrap_or_else(|| panic!("not a plain string: {}", utf8(line)));
        assert!(
            !value.iter().any(|&b| b == b'"' || b == b'\\'),
            "escapes are toml's: {}",
            utf8(line)
        );
        let row = rows.last_mut().expect("a row key before [[row]]");
        assert!(
            row.insert(utf8(key), utf8(value)).is_none(),
            "{}",
            utf8(line)
        );
    }
    let row = |mut r: BTreeMap<String, String>| {
        let mut take = |k: &str| r.remove(k).unwrap_or_else(|| panic!("no {k}: {r:?}"));
        let row = Row {
            name: take("name"),
            parser: take("parser"),
            hex: take("hex"),
            error: take("error"),
            why: take("why"),
        };
        assert!(r.is_empty(), "unknown fields {r:?}");
        row
    };
    Table {
        parser: Parser {
            apids: apids.expect("apids"),
        },
        row: rows.into_iter().map(row).collect(),
    }
}

#[test]
#[cfg_attr(miri, ignore = "the toml parser: minutes under Miri")]
fn the_line_reader_reads_what_toml_reads() {
    let (_, text) = table_text();
    let by_toml: Table = toml::from_str(&text).unwrap();
    assert!(by_toml.row.len() >= 30);
    assert_eq!(table_by_lines(&text), by_toml);
}

/// The row's input through its parser: the refusing check's name, or `None` if accepted.
pub fn verdict(row: &Row, apids: &[u16]) -> Option<&'static str> {
    let bytes = unhex(&row.hex);
    let r: Result<(), PacketError> = match row.parser.as_str() {
        "tc" => TcRepr::parse(&bytes, apids).map(|_| ()),
        "tm" => TmRepr::parse(&bytes, apids).map(|_| ()),
        "tc-service" => return mmic::pus::read_tc(&bytes, apids).err().map(|e| e.name()),
        "tc-frame" => return tc_frame_verdict(&bytes).err().map(|e| e.name()),
        // The PDU's checks, then its directive's (mmic::cfdp::directive::PduRepr::parse).
        "cfdp" => {
            return mmic::cfdp::Pdu::parse(&bytes)
                .and_then(|p| mmic::cfdp::directive::PduRepr::parse(&p))
                .err()
                .map(|e| e.name())
        }
        // Under `TmFrameParams::mission(0x142)` (robot 0x42's spacecraft ID).
        "tm-frame" => {
            return TmFrameRepr::parse(&bytes, &super::tm_frame::params())
                .err()
                .map(|e| e.name())
        }
        other => panic!("row {}: no parser named {other:?}", row.name),
    };
    r.err().map(|e| {
        // A check's place in the order names it.
        assert_eq!(
            PacketError::NAMES[e.position()],
            e.name(),
            "row {}",
            row.name
        );
        PusError::from(e).name()
    })
}

/// A `tc-frame` row: the frame through `TcFrame::new_checked` with the mission's configuration
/// for spacecraft 0x101 (board 1's robot: VC 0, segment header, MAP 0, FECF, at most 256
/// octets), then an AD or BD frame's data through `TcFrame::packets`.
pub fn tc_frame_verdict(bytes: &[u8]) -> Result<(), TcFrameError> {
    let frame = TcFrame::new_checked(bytes, &super::tc_frame::config())?;
    frame.packets().try_for_each(|p| p.map(|_| ()))
}

// req: 133.0-B-2/SPP-21, 133.0-B-2/SPP-22, 132.0-B-3/TM-8, 132.0-B-3/TM-86
#[test]
fn every_bad_input_is_refused_by_name() {
    let t = table();
    let mut names = BTreeSet::new();
    let mut checks = BTreeSet::new();
    for row in &t.row {
        assert!(names.insert(&row.name), "duplicate row {}", row.name);
        assert!(!row.why.is_empty(), "row {}: no why", row.name);
        match verdict(row, &t.parser.apids) {
            Some(e) => assert_eq!(
                e, row.error,
                "row {} ({}): refused as {e}",
                row.name, row.hex
            ),
            None => panic!("row {} ({}) was accepted", row.name, row.hex),
        }
        // Keyed by parser: the frames' checks share names with the packets' (length, version).
        checks.insert((row.parser.as_str(), row.error.as_str()));
    }
    let packet_parsers = ["tc", "tm", "tc-service"];
    for name in PacketError::NAMES
        .iter()
        .chain(&mmic::pus::request::RequestError::NAMES)
    {
        assert!(
            packet_parsers.iter().any(|p| checks.contains(&(*p, *name))),
            "no row for the check {name}"
        );
    }
    for (parser, names) in [
        ("tc-frame", &TcFrameError::NAMES[..]),
        ("tm-frame", &TmFrameError::NAMES[..]),
        (
            "cfdp",
            &mmic::cfdp::PduError::NAMES[..mmic::cfdp::PduError::PARSE],
        ),
    ] {
        for name in names {
            assert!(
                checks.contains(&(parser, *name)),
                "no {parser} row for the check {name}"
            );
        }
    }
    println!("{} bad inputs refused by name", t.row.len());
}

#[test]
#[cfg_attr(
    miri,
    ignore = "compares the table's hex strings: no dependency's unsafe code for Miri to check"
)]
fn each_row_is_one_defect_away_from_a_valid_packet() {
    // The rows must test their own check, not stumble on another: with the defect undone (the
    // reference packet's octets put back where the row differs), the packet is valid.
    let t = table();
    let tc = hex(&super::tc_bytes(&super::ping()));
    let tm = hex(&super::tm_bytes(&super::alive()));
    for row in t
        .row
        .iter()
        .filter(|r| r.parser == "tc" || r.parser == "tm")
    {
        let reference = if row.parser == "tc" { &tc } else { &tm };
        let bytes = unhex(&row.hex);
        let good = unhex(reference);
        let differing = (0..bytes.len().max(good.len()))
            .filter(|&i| bytes.get(i) != good.get(i))
            .count();
        // The changed field, and the two CRC octets rewritten over it (a trailing or missing
        // octet counts once).
        assert!(
            (1..=3).contains(&differing),
            "row {}: {differing} octets differ from the reference",
            row.name
        );
    }
}

#[test]
fn services_rows_are_valid_packets_refused_for_their_request_only() {
    // Their defect is the services layer's: the packet itself passes every CCSDS/PUS check.
    let t = table();
    let rows: Vec<&Row> = t.row.iter().filter(|r| r.parser == "tc-service").collect();
    assert!(rows.len() >= mmic::pus::request::RequestError::NAMES.len());
    for row in rows {
        let bytes = unhex(&row.hex);
        assert!(
            TcRepr::parse(&bytes, &t.parser.apids).is_ok(),
            "row {}",
            row.name
        );
    }
}

#[test]
fn each_tc_frame_row_is_one_defect_away_from_a_valid_frame() {
    // As for the packets: with the defect undone, the frame is valid. A row changing a field
    // differs from its reference (the AD frame carrying the ping, or BC Set V(R) = 5, by the
    // flags in its first octet) in at most three octets: the field, the length field, the
    // FECF. The three rows whose defect is their length are checked for that defect alone.
    let t = table();
    let ad = super::tc_frame::AD_PING;
    let bc = super::tc_frame::BC_SET_VR_5;
    let rows: Vec<&Row> = t.row.iter().filter(|r| r.parser == "tc-frame").collect();
    assert!(rows.len() >= TcFrameError::NAMES.len());
    for row in rows {
        let bytes = unhex(&row.hex);
        match row.error.as_str() {
            // The same frame is valid for a channel that takes 1024-octet frames, and its
            // defect is its length alone.
            "too-long" => {
                let mut cfg = super::tc_frame::config();
                cfg.max_frame_len = 1024;
                assert!(
                    TcFrame::new_checked(&bytes[..], &cfg).is_ok(),
                    "{}",
                    row.name
                );
                assert_eq!(bytes.len(), 257);
            }
            // A prefix of the valid frame.
            "truncated" => assert!(unhex(ad).starts_with(&bytes), "{}", row.name),
            // A valid frame whose data does not end on a packet boundary.
            "packet-boundary" => {
                let cfg = super::tc_frame::config();
                assert!(
                    TcFrame::new_checked(&bytes[..], &cfg).is_ok(),
                    "{}",
                    row.name
                );
            }
            _ => {
                let reference = unhex(if bytes.first() == Some(&0x31) { bc } else { ad });
                let differing = (0..bytes.len().max(reference.len()))
                    .filter(|&i| bytes.get(i) != reference.get(i))
                    .count();
                assert!(
                    (1..=3).contains(&differing),
                    "row {}: {differing} octets differ from the reference",
                    row.name
                );
            }
        }
    }
}

#[test]
#[cfg_attr(
    miri,
    ignore = "the 256-octet rows against the reference: a minute under Miri (every_bad_input_is_refused_by_name runs them)"
)]
fn each_tm_frame_row_is_one_defect_away_from_the_reference_frame() {
    // As for the packets: the changed field (one or two octets: the data field status is
    // 16 bits) and the two FECF octets rewritten over it (a missing octet counts once).
    let t = table();
    let good = super::tm_frame::reference_frame();
    let rows: Vec<&Row> = t.row.iter().filter(|r| r.parser == "tm-frame").collect();
    assert!(rows.len() >= TmFrameError::NAMES.len());
    for row in rows {
        let bytes = unhex(&row.hex);
        let differing = (0..bytes.len().max(good.len()))
            .filter(|&i| bytes.get(i) != good.get(i))
            .count();
        assert!(
            (1..=4).contains(&differing),
            "row {}: {differing} octets differ from the reference frame",
            row.name
        );
    }
}
