//! Walks `spec/ccsds/bad-inputs.toml`: every row's packet, through the parser it names, must be
//! refused with exactly the error it names; every check of `PacketError::NAMES` has a row.

use super::{hex, unhex};
use mmic::ccsds::tc::TcRepr;
use mmic::ccsds::tm::TmRepr;
use mmic::ccsds::{PacketError, PusError};
use serde::Deserialize;
use std::collections::BTreeSet;
use std::path::PathBuf;

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Table {
    pub parser: Parser,
    pub row: Vec<Row>,
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Parser {
    pub apids: Vec<u16>,
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Row {
    pub name: String,
    pub parser: String,
    pub hex: String,
    pub error: String,
    pub why: String,
}

pub fn table() -> Table {
    let p = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("spec/ccsds/bad-inputs.toml");
    let text = std::fs::read_to_string(&p).unwrap_or_else(|e| panic!("{}: {e}", p.display()));
    toml::from_str(&text).unwrap_or_else(|e| panic!("{}: {e}", p.display()))
}

/// The row's packet through its parser: the error, or `None` if accepted.
pub fn verdict(row: &Row, apids: &[u16]) -> Option<PusError> {
    let bytes = unhex(&row.hex);
    let r: Result<(), PacketError> = match row.parser.as_str() {
        "tc" => TcRepr::parse(&bytes, apids).map(|_| ()),
        "tm" => TmRepr::parse(&bytes, apids).map(|_| ()),
        "tc-service" => return mmic::pus::read_tc(&bytes, apids).err(),
        other => panic!("row {}: no parser named {other:?}", row.name),
    };
    r.err().map(PusError::from)
}

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
                e.name(),
                row.error,
                "row {} ({}): refused as {e}",
                row.name,
                row.hex
            ),
            None => panic!("row {} ({}) was accepted", row.name, row.hex),
        }
        checks.insert(row.error.as_str());
    }
    for name in PacketError::NAMES
        .iter()
        .chain(&mmic::pus::request::RequestError::NAMES)
    {
        assert!(checks.contains(name), "no row for the check {name}");
    }
    println!("{} bad inputs refused by name", t.row.len());
}

#[test]
fn each_row_is_one_defect_away_from_a_valid_packet() {
    // The rows must test their own check, not stumble on another: with the defect undone (the
    // reference packet's octets put back where the row differs), the packet is valid.
    let t = table();
    let tc = hex(&super::tc_bytes(&super::ping()));
    let tm = hex(&super::tm_bytes(&super::alive()));
    for row in t.row.iter().filter(|r| r.parser != "tc-service") {
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
