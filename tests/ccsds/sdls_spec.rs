//! spec/ccsds/sdls.toml against the code (src/link/sdls/) and YAMCS's SDLS configuration
//! (ground/yamcs/links/frames-sdls.yaml): the suite's sizes, the SPIs, the masks, the windows
//! and blocks, the events' ID and period; every section names a decision of spec/decisions.toml.

use mmic::link::sdls::{self, mask, mission};
use mmic::node::server::frames::SECURITY_EVENT_PERIOD_MS;
use mmic::pus::event::Event;
use mmic::units::BoardNumber;

use crate::ccsds::repo;

fn spec() -> toml::Table {
    toml::from_str(&repo("spec/ccsds/sdls.toml")).unwrap()
}

fn int(t: &toml::Table, section: &str, key: &str) -> i64 {
    t[section][key]
        .as_integer()
        .unwrap_or_else(|| panic!("[{section}] {key}"))
}

fn text<'a>(t: &'a toml::Table, section: &str, key: &str) -> &'a str {
    t[section][key]
        .as_str()
        .unwrap_or_else(|| panic!("[{section}] {key}"))
}

fn hex(bytes: &[u8]) -> String {
    bytes.iter().map(|b| format!("{b:02x}")).collect()
}

// req: 132.0-B-3/TM-103, 132.0-B-3/TM-104, 132.0-B-3/TM-105, 132.0-B-3/TM-106, 355.0-B-2/SDLS-1
// req: 355.0-B-2/SDLS-2, 355.0-B-2/SDLS-3, 355.0-B-2/SDLS-6, 355.0-B-2/SDLS-10
// req: 355.0-B-2/SDLS-11
#[test]
#[cfg_attr(miri, ignore = "the toml parser: minutes under Miri")]
fn the_choices_are_the_codes() {
    let t = spec();
    assert_eq!(int(&t, "suite", "iv_octets") as usize, sdls::IV_LEN);
    assert_eq!(int(&t, "suite", "mac_octets") as usize, sdls::MAC_LEN);
    assert_eq!(sdls::HEADER_LEN, 2 + sdls::IV_LEN);
    assert_eq!(sdls::KEY_LEN, 32, "AES-256");
    assert_eq!(text(&t, "sa", "tc_spi"), "0x100 + n");
    assert_eq!(text(&t, "sa", "tm_spi"), "0x200 + n");
    for n in [1u8, 2, 255] {
        let b = BoardNumber::new(n).unwrap();
        assert_eq!(mission::tc_spi(b), 0x100 + u16::from(n));
        assert_eq!(mission::tm_spi(b), 0x200 + u16::from(n));
        assert_eq!(
            mission::tc_spi(b),
            mmic::link::tc_frame::SpacecraftId::of_board(b).get(),
            "the TC SPI is the spacecraft ID"
        );
    }
    assert_eq!(text(&t, "mask", "tc"), hex(mask::TC.as_bytes()));
    assert_eq!(text(&t, "mask", "tm"), hex(mask::TM.as_bytes()));
    assert_eq!(
        int(&t, "counters", "tc_window"),
        i64::from(mission::TC_WINDOW)
    );
    assert_eq!(
        int(&t, "counters", "tc_rx_block"),
        i64::from(mission::TC_RX_BLOCK)
    );
    assert_eq!(
        int(&t, "counters", "tc_tx_block"),
        i64::from(mission::TC_TX_BLOCK)
    );
    assert_eq!(
        int(&t, "counters", "tm_tx_block"),
        i64::from(mission::TM_TX_BLOCK)
    );
    assert_eq!(
        int(&t, "counters", "tm_window"),
        i64::from(mission::TM_WINDOW)
    );
    assert_eq!(
        int(&t, "counters", "tm_rx_block"),
        i64::from(mission::TM_RX_BLOCK)
    );
    assert_eq!(
        int(&t, "events", "period_ms"),
        i64::from(SECURITY_EVENT_PERIOD_MS)
    );
    assert_eq!(text(&t, "events", "id"), "0x0200 + n");
    let e = Event::Security {
        reason: 5,
        refused: 1,
        spi: 257,
    };
    assert_eq!((e.id(), e.severity()), (0x0205, 3));
    assert_eq!(sdls::SdlsRefusal::NAMES[5], "bad-mac");
    let not_reserved = Event::Security {
        reason: 6,
        refused: 1,
        spi: 257,
    };
    assert_eq!(sdls::SdlsRefusal::NAMES[6], "not-reserved");
    assert_eq!(
        i64::from(not_reserved.severity()),
        int(&t, "events", "not_reserved_severity")
    );
    // The store's keys as spec/ writes them.
    use mmic::node::server::store;
    let b = BoardNumber::new(7).unwrap();
    assert_eq!(text(&t, "store", "fingerprint_key"), "0x1000 | SPI");
    assert_eq!(store::fingerprint_key(mission::tm_spi(b)), 0x1000 | 0x207);
    assert_eq!(text(&t, "store", "progress_key"), "0x2000 + n");
    assert_eq!(store::progress_key(b), 0x2007);
    assert_eq!(text(&t, "store", "kept_key"), "0x3000 + 4n + slot");
    assert_eq!(store::kept_key(b, 3), 0x3000 + 4 * 7 + 3);
    assert_eq!(text(&t, "sa", "keys_partition"), "mmic_keys");
    let names = |key: &str| -> Vec<String> {
        t["store"][key]
            .as_array()
            .unwrap()
            .iter()
            .map(|v| v.as_str().unwrap().to_string())
            .collect()
    };
    assert_eq!(names("keys_refusals"), store::keys::KeysError::NAMES);
    assert_eq!(
        names("link_stopped"),
        mmic::pus::event::LINK_STOPPED_REASONS
    );
    assert!(repo("firmware/server-ccsds/partitions.csv").contains("mmic_keys,"));
    assert_eq!(
        mmic::node::server::frames::FrameRefusal::Origin.name(),
        "bc-origin"
    );
}

#[test]
#[cfg_attr(miri, ignore = "the toml parser: minutes under Miri")]
fn every_section_names_a_decision() {
    let t = spec();
    crate::ccsds::assert_sections_name_decisions("spec/ccsds/sdls.toml", &t);
    assert!(crate::ccsds::repo("spec/decisions.toml").contains("id = \"sdls-scope\""));
    assert_eq!(t.len(), 8);
}

/// YAMCS's SDLS links: the same SPIs, masks and TM window; TM verified; the keys from files; the
/// counters in durable state files, reserved in the mission's blocks.
#[test]
fn yamcs_is_configured_with_the_same_choices() {
    let y = repo("ground/yamcs/links/frames-sdls.yaml");
    let one = BoardNumber::ONE;
    let mask_tm = format!("authMask: \"{}\"", hex(mask::TM.as_bytes()));
    let mask_tc = format!("authMask: \"{}\"", hex(mask::TC.as_bytes()));
    let tm = y.find("name: tm-frames").unwrap();
    let tc = y.find("name: tc-frames").unwrap();
    let (tm_part, tc_part) = if tm < tc {
        (&y[tm..tc], &y[tc..])
    } else {
        (&y[tm..], &y[tc..tm])
    };
    assert!(tm_part.contains(&format!("spi: {}", mission::tm_spi(one))));
    assert!(tm_part.contains(&mask_tm), "{tm_part}");
    assert!(tm_part.contains("verifySeqNum: true"));
    assert!(tm_part.contains(&format!("seqNumWindow: {}", mission::TM_WINDOW)));
    assert!(tm_part.contains(&format!("encryptionSpis: [{}]", mission::tm_spi(one))));
    assert!(tm_part.contains(&format!("spi-{}.key", mission::tm_spi(one))));
    assert!(tc_part.contains(&format!("spi: {}", mission::tc_spi(one))));
    assert!(tc_part.contains(&mask_tc), "{tc_part}");
    assert!(tc_part.contains(&format!("encryptionSpi: {}", mission::tc_spi(one))));
    assert!(tc_part.contains(&format!("spi-{}.key", mission::tc_spi(one))));
    // Both SAs are the plug-in's, its counters in durable state files reserved with the mission's
    // blocks: the ground's TC reservation and its TM floor (ground/yamcs-plugin/).
    let plugin = "class: org.mmic.yamcs.ReprotectingAes256Gcm128Factory";
    assert!(tm_part.contains(plugin) && tc_part.contains(plugin));
    assert!(tm_part.contains("stateFile: ") && tc_part.contains("stateFile: "));
    assert!(tm_part.contains(&format!("reserveBlock: {}", mission::TM_RX_BLOCK)));
    assert!(tc_part.contains(&format!("reserveBlock: {}", mission::TC_TX_BLOCK)));
    assert!(
        !y.contains("initialSeqNum:"),
        "the state file is the counter"
    );
}
