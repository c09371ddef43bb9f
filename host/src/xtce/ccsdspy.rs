//! The ccsdspy field list of TM(3,25) (spec/ccsds/hk-3-25.ccsdspy.csv), for the ground
//! interop tests that decode the robot's housekeeping with NASA's ccsdspy.

use mmic::ccsds::tm::{field as tm_field, TM_HEADER_LEN};
use mmic::pus::housekeeping::{self, FIELDS};
use std::fmt::Write;

/// The ccsdspy field list of TM(3,25): `name,byte_offset,bit_offset,data_type,bit_length`,
/// offsets from the packet's first octet (primary header included), the secondary header's
/// fields, the structure ID, every [`FIELDS`] parameter and the CRC.
pub fn ccsdspy_csv() -> String {
    let mut s = String::from("name,byte_offset,bit_offset,data_type,bit_length\n");
    let t = |r: std::ops::Range<usize>| (r.start, (r.end - r.start) * 8);
    let v = tm_field::VERSION_TIME_REF.start;
    let _ = writeln!(s, "pus_version,{v},0,uint,4\ntime_ref_status,{v},4,uint,4");
    for (name, (at, bits)) in [
        ("service", t(tm_field::SERVICE)),
        ("subservice", t(tm_field::SUBSERVICE)),
        ("msg_type_counter", t(tm_field::COUNTER)),
        ("destination_id", t(tm_field::DESTINATION_ID)),
    ] {
        let _ = writeln!(s, "{name},{at},0,uint,{bits}");
    }
    let time = tm_field::TIME.start;
    let _ = writeln!(
        s,
        "met_coarse,{time},0,uint,32\nmet_fine,{},0,uint,16",
        time + 4
    );
    let mut at = TM_HEADER_LEN;
    let _ = writeln!(s, "hk_sid,{at},0,uint,8");
    at += 1;
    for f in FIELDS.iter() {
        let _ = writeln!(s, "{},{at},0,uint,{}", f.name, f.len * 8);
        at += f.len;
    }
    let _ = writeln!(s, "crc,{at},0,uint,16");
    debug_assert_eq!(at, TM_HEADER_LEN + housekeeping::REPORT_LEN);
    s
}
