//! ST[3] housekeeping: the report is the heartbeat, every field at its bounds, and a report
//! with any field out of range is refused naming it.

use mmic::pus::housekeeping::{self, HousekeepingError, FIELDS, REPORT_LEN, ROBOT_SID};
use mmic::wire::heartbeat::HeartbeatRepr;
use proptest::prelude::*;

proptest! {
    #![proptest_config(crate::common::prop::config(512))]
    #[test]
    fn every_heartbeat_is_a_report_and_back(hb in any::<HeartbeatRepr>()) {
        let mut buf = [0u8; REPORT_LEN];
        housekeeping::emit(&hb, &mut buf);
        prop_assert_eq!(housekeeping::parse(&buf), Ok(hb));
        // Field by field, at the offsets the table gives, big-endian.
        let mut at = 1;
        for (f, v) in FIELDS.iter().zip(housekeeping::values(&hb)) {
            let mut got = 0u32;
            for b in &buf[at..at + f.len] {
                got = got << 8 | u32::from(*b);
            }
            prop_assert_eq!(got, v, "{}", f.name);
            at += f.len;
        }
        prop_assert_eq!(at, REPORT_LEN);
    }
}

#[test]
fn a_field_out_of_range_is_refused_by_name() {
    let hb = HeartbeatRepr::default();
    let mut good = [0u8; REPORT_LEN];
    housekeeping::emit(&hb, &mut good);
    assert_eq!(
        housekeeping::parse(&good[..REPORT_LEN - 1]),
        Err(HousekeepingError::Length {
            expected: REPORT_LEN,
            found: REPORT_LEN - 1
        })
    );
    let mut b = good;
    b[0] = 2;
    assert_eq!(
        housekeeping::parse(&b),
        Err(HousekeepingError::StructureId {
            expected: ROBOT_SID,
            found: 2
        })
    );
    // Every field set to all ones: refused by its name unless all ones is in range
    // (the currents and voltages, the sequence number, robot 255, the boot byte: every value
    // is a reset cause and a count).
    let mut at = 1;
    for f in FIELDS {
        let mut b = good;
        b[at..at + f.len].fill(0xFF);
        let free = f.unit == "mV"
            || f.unit == "mA"
            || f.name == "last_seq"
            || f.name == "board"
            || f.name == "boot";
        match housekeeping::parse(&b) {
            Ok(_) => assert!(free, "{} accepted all ones", f.name),
            Err(HousekeepingError::Parameter { name, .. }) => {
                assert!(!free, "{name}");
                assert_eq!(name, f.name);
            }
            Err(e) => panic!("{}: {e}", f.name),
        }
        at += f.len;
    }
}
