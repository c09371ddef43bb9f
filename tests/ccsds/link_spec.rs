//! spec/ccsds/link.toml against the code and the ground's configuration: every managed
//! parameter of the data link is the constant the library uses, YAMCS's frame links
//! (ground/yamcs/links/frames.yaml) are configured with the same numbers, and every row names
//! a decision of spec/decisions.toml.

use mmic::link::{fop, tc_frame, tm_frame, tm_framer};
use mmic::node::server::frames::{FrameConfig, GATHER_MS};
use mmic::units::BoardNumber;

use crate::ccsds::repo;

fn link() -> toml::Table {
    toml::from_str(&repo("spec/ccsds/link.toml")).unwrap()
}

fn int(t: &toml::Table, section: &str, key: &str) -> i64 {
    t[section][key]
        .as_integer()
        .unwrap_or_else(|| panic!("[{section}] {key}"))
}

fn boolean(t: &toml::Table, section: &str, key: &str) -> bool {
    t[section][key]
        .as_bool()
        .unwrap_or_else(|| panic!("[{section}] {key}"))
}

// req: 132.0-B-3/TM-58, 132.0-B-3/TM-69, 132.0-B-3/TM-71, 132.0-B-3/TM-73, 132.0-B-3/TM-75
// req: 132.0-B-3/TM-76, 132.0-B-3/TM-77, 132.0-B-3/TM-79, 132.0-B-3/TM-83, 132.0-B-3/TM-85
// req: 232.0-B-4/TC-7, 232.0-B-4/TC-37, 232.0-B-4/TC-39, 232.0-B-4/TC-41, 232.0-B-4/TC-43
// req: 232.0-B-4/TC-44, 232.0-B-4/TC-46, 232.0-B-4/TC-47, 232.1-B-2/FARM-4, 232.1-B-2/FOP-4
// req: 232.1-B-2/FOP-5, 232.1-B-2/FOP-6
#[test]
#[cfg_attr(miri, ignore = "the toml parser: minutes under Miri")]
fn the_managed_parameters_are_the_codes() {
    let t = link();
    // One spacecraft per robot: 0x100 + n, n the board number.
    assert_eq!(t["spacecraft"]["id"].as_str(), Some("0x100 + n"));
    assert_eq!(tc_frame::SPACECRAFT_ID_BASE, 0x100);
    for n in [1u8, 2, 255] {
        let b = BoardNumber::new(n).unwrap();
        assert_eq!(
            tc_frame::SpacecraftId::of_board(b).get(),
            0x100 + u16::from(n)
        );
        assert_eq!(
            mmic::pus::robot_apid(b),
            0x100 + u16::from(n),
            "the APID's value"
        );
    }
    // TC frames.
    assert_eq!(int(&t, "tc", "vcid"), i64::from(tc_frame::MISSION_VCID));
    assert_eq!(
        boolean(&t, "tc", "segment_header"),
        tc_frame::MISSION_SEGMENT_HEADER
    );
    assert_eq!(int(&t, "tc", "map_id"), i64::from(tc_frame::MISSION_MAP_ID));
    assert_eq!(
        int(&t, "tc", "max_frame_len"),
        tc_frame::MAX_FRAME_LEN as i64
    );
    assert_eq!(boolean(&t, "tc", "fecf"), tc_frame::MISSION_FECF);
    let cfg = tc_frame::mission(tc_frame::SpacecraftId::of_board(BoardNumber::ONE));
    assert_eq!(
        (cfg.max_frame_len, cfg.fecf),
        (tc_frame::MAX_FRAME_LEN, tc_frame::MISSION_FECF)
    );
    // COP-1.
    assert_eq!(
        int(&t, "cop1", "farm_window"),
        i64::from(mmic::link::farm::FARM_WINDOW)
    );
    assert_eq!(
        FrameConfig::default().farm_window.width(),
        mmic::link::farm::FARM_WINDOW
    );
    assert_eq!(int(&t, "cop1", "fop_window"), i64::from(fop::FOP_WINDOW));
    assert_eq!(int(&t, "cop1", "t1_ms"), i64::from(fop::T1_MS));
    assert_eq!(int(&t, "cop1", "tx_limit"), i64::from(fop::TX_LIMIT));
    let m = fop::FopConfig::MISSION;
    assert_eq!(
        (m.window, m.t1_ms, m.tx_limit),
        (fop::FOP_WINDOW, fop::T1_MS, fop::TX_LIMIT)
    );
    // K fits FARM-1's positive window: a compile-time assertion in link::fop.
    // TM frames.
    assert_eq!(int(&t, "tm", "vcid"), i64::from(tm_frame::TM_VCID));
    assert_eq!(int(&t, "tm", "frame_len"), tm_frame::TM_FRAME_LEN as i64);
    assert_eq!(boolean(&t, "tm", "ocf"), tm_frame::TM_OCF);
    assert_eq!(boolean(&t, "tm", "fecf"), tm_frame::TM_FECF);
    assert_eq!(
        boolean(&t, "tm", "secondary_header"),
        tm_frame::TM_SECONDARY_HEADER
    );
    assert_eq!(
        int(&t, "tm", "idle_period_ms"),
        i64::from(tm_framer::IDLE_PERIOD_MS)
    );
    assert_eq!(
        FrameConfig::default().idle_period_ms,
        tm_framer::IDLE_PERIOD_MS
    );
    assert_eq!(int(&t, "tm", "gather_ms"), i64::from(GATHER_MS));
    assert_eq!(FrameConfig::default().gather_ms, GATHER_MS);
    assert_eq!(
        t["tm"]["idle_fill"].as_str(),
        Some("idle packet, APID 0x7FF, octets 0x55")
    );
    assert_eq!((tm_framer::IDLE_APID, tm_framer::IDLE_OCTET), (0x7ff, 0x55));
    let p = tm_frame::TmFrameParams::mission(0x101).unwrap();
    assert_eq!(
        (p.frame_len(), p.vcid(), p.ocf(), p.fecf()),
        (256, 0, true, true)
    );
}

#[test]
#[cfg_attr(miri, ignore = "the toml parser: minutes under Miri")]
fn every_section_names_a_decision() {
    let t = link();
    crate::ccsds::assert_sections_name_decisions("spec/ccsds/link.toml", &t);
    assert_eq!(t.len(), 4);
}

/// The value of `key: value` on the first line of `text` after `after` that has the key.
fn yaml_value<'a>(text: &'a str, after: &str, key: &str) -> &'a str {
    let start = text.find(after).unwrap_or_else(|| panic!("{after}"));
    text[start..]
        .lines()
        .find_map(|l| {
            let l = l
                .split('#')
                .next()
                .unwrap_or("")
                .trim()
                .trim_start_matches("- ");
            l.strip_prefix(&format!("{key}:")).map(str::trim)
        })
        .unwrap_or_else(|| panic!("{key} after {after}"))
}

#[test]
fn yamcs_is_configured_with_the_same_numbers() {
    let y = repo("ground/yamcs/links/frames.yaml");
    // Against the constants, which the_managed_parameters_are_the_codes holds to the toml.
    let tm = "name: tm-frames";
    assert_eq!(yaml_value(&y, tm, "frameType"), "TM");
    assert_eq!(
        yaml_value(&y, tm, "frameLength"),
        tm_frame::TM_FRAME_LEN.to_string()
    );
    assert_eq!(yaml_value(&y, tm, "errorDetection"), "CRC16");
    assert_eq!(yaml_value(&y, tm, "vcId"), tm_frame::TM_VCID.to_string());
    assert_eq!(yaml_value(&y, tm, "clcwStream"), "clcw");
    let tc = "name: tc-frames";
    assert_eq!(
        yaml_value(&y, tc, "maxFrameLength"),
        tc_frame::MAX_FRAME_LEN.to_string()
    );
    assert_eq!(yaml_value(&y, tc, "errorDetection"), "CRC16");
    assert_eq!(
        yaml_value(&y, tc, "vcId"),
        tc_frame::MISSION_VCID.to_string()
    );
    assert_eq!(
        yaml_value(&y, tc, "mapId"),
        tc_frame::MISSION_MAP_ID.to_string()
    );
    assert_eq!(yaml_value(&y, tc, "useCop1"), "true");
    assert_eq!(yaml_value(&y, tc, "clcwStream"), "clcw");
    assert_eq!(
        yaml_value(&y, tc, "cop1T1"),
        (fop::T1_MS / 1000).to_string()
    );
    assert_eq!(yaml_value(&y, tc, "cop1TxLimit"), fop::TX_LIMIT.to_string());
    assert_eq!(
        yaml_value(&y, tc, "slidingWindowWidth"),
        fop::FOP_WINDOW.to_string()
    );
    assert_eq!(yaml_value(&y, tm, "spacecraftId"), "@SCID@");
}
