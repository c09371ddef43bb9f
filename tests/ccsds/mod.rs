//! CCSDS space packets and PUS-C headers (issue 15's wire layer): golden bytes checked by hand
//! against the standards, the bad-input table of spec/ccsds/, every 1–3-bit corruption, and
//! interoperation with the `spacepackets` crate; the conformance statements (PICS) of the CCSDS
//! books and the PUS-C tailoring held to the code and its tests (`pics`).

mod bad_inputs;
mod cfdp;
mod cfdp_concurrent;
mod cfdp_directive;
mod cfdp_edges;
mod cfdp_entity;
mod corruption;
mod farm_table;
mod golden;
mod interop_spacepackets;
mod link_spec;
mod pics;
mod sdls;
mod sdls_edges;
mod sdls_spec;
mod shared_link;
mod store;
mod tc_frame;
mod tm_frame;
mod tm_link;

use mmic::ccsds::primary::{Apid, SeqCount};
use mmic::ccsds::tc::TcRepr;
use mmic::ccsds::tc_header::{AckFlags, TcSecondaryHeader};
use mmic::ccsds::tm::TmRepr;
use mmic::ccsds::tm_header::{TimeRefStatus, TmSecondaryHeader};

/// A file of the repository.
pub fn repo(path: &str) -> String {
    let p = std::path::PathBuf::from(env!("CARGO_MANIFEST_DIR")).join(path);
    std::fs::read_to_string(&p).unwrap_or_else(|e| panic!("{}: {e}", p.display()))
}

/// Every section of the spec table `t` (`file`) names a decision of spec/decisions.toml.
pub fn assert_sections_name_decisions(file: &str, t: &toml::Table) {
    let decisions: toml::Table = toml::from_str(&repo("spec/decisions.toml")).unwrap();
    let ids: Vec<&str> = decisions["decision"]
        .as_array()
        .unwrap()
        .iter()
        .filter_map(|d| d["id"].as_str())
        .collect();
    for (section, v) in t {
        let d = v["decision"]
            .as_str()
            .unwrap_or_else(|| panic!("{file} [{section}] has no decision"));
        assert!(
            ids.contains(&d),
            "{file} [{section}] names {d}, which decisions.toml lacks"
        );
    }
}

/// The APID of the reference packets.
pub const APID: u16 = 0x042;

/// TC(17,1) are-you-alive to APID 0x042, count 7, every report asked for, source 0.
pub fn ping() -> TcRepr<'static> {
    TcRepr {
        apid: Apid::new(APID).unwrap(),
        seq_count: SeqCount::new(7).unwrap(),
        header: TcSecondaryHeader {
            ack: AckFlags::ALL,
            service: 17,
            subservice: 1,
            source_id: 0,
        },
        app_data: &[],
    }
}

/// TM(17,2) I-am-alive from APID 0x042, count 9, message counter 3, at 90.5 s.
pub fn alive() -> TmRepr<'static> {
    TmRepr {
        apid: Apid::new(APID).unwrap(),
        seq_count: SeqCount::new(9).unwrap(),
        header: TmSecondaryHeader {
            time_ref_status: TimeRefStatus::default(),
            service: 17,
            subservice: 2,
            counter: 3,
            destination_id: 0,
            time: mmic::ccsds::cuc::Cuc::from_millis(90_500),
        },
        source_data: &[],
    }
}

/// Hex of `bytes`.
pub fn hex(bytes: &[u8]) -> String {
    bytes.iter().map(|b| format!("{b:02x}")).collect()
}

/// Bytes of `hex`.
pub fn unhex(hex: &str) -> Vec<u8> {
    assert!(hex.len().is_multiple_of(2), "odd hex length: {hex}");
    (0..hex.len())
        .step_by(2)
        .map(|i| u8::from_str_radix(&hex[i..i + 2], 16).unwrap_or_else(|e| panic!("{hex}: {e}")))
        .collect()
}

/// The packet as a vector.
pub fn tc_bytes(r: &TcRepr) -> Vec<u8> {
    let mut out = vec![0u8; r.len()];
    assert_eq!(r.emit(&mut out), Ok(out.len()));
    out
}

/// The packet as a vector.
pub fn tm_bytes(r: &TmRepr) -> Vec<u8> {
    let mut out = vec![0u8; r.len()];
    assert_eq!(r.emit(&mut out), Ok(out.len()));
    out
}
