//! Against the `spacepackets` crate (0.19), written by others from the same standards:
//! packets we emit parse there with equal fields, packets it creates parse here with equal
//! fields, and which of our bad inputs its reader accepts (measured on the rows of
//! `spec/ccsds/bad-inputs.toml`).

use super::bad_inputs::{table, verdict};
use super::{tc_bytes, tm_bytes, unhex};
use arbitrary_int::{u11, u14};
use mmic::ccsds::cuc::Cuc;
use mmic::ccsds::primary::{Apid, SeqCount};
use mmic::ccsds::tc::TcRepr;
use mmic::ccsds::tc_header::{AckFlags, TcSecondaryHeader};
use mmic::ccsds::tm::TmRepr;
use mmic::ccsds::tm_header::TmSecondaryHeader;
use proptest::prelude::*;
use spacepackets::ecss::tc::{
    GenericPusTcSecondaryHeader, PusTcCreator, PusTcReader, PusTcSecondaryHeader,
};
use spacepackets::ecss::tm::{
    GenericPusTmSecondaryHeader, PusTmCreator, PusTmReader, PusTmSecondaryHeader,
};
use spacepackets::ecss::{CreatorConfig, MessageTypeId, PusPacket};
use spacepackets::{CcsdsPacket, SpHeader};

fn tc_parts() -> impl Strategy<Value = (Apid, SeqCount, TcSecondaryHeader, Vec<u8>)> {
    (
        any::<Apid>(),
        any::<SeqCount>(),
        any::<TcSecondaryHeader>(),
        proptest::collection::vec(any::<u8>(), 0..64),
    )
}

fn tm_parts() -> impl Strategy<Value = (Apid, SeqCount, TmSecondaryHeader, Vec<u8>)> {
    (
        any::<Apid>(),
        any::<SeqCount>(),
        any::<TmSecondaryHeader>(),
        proptest::collection::vec(any::<u8>(), 0..64),
    )
}

proptest! {
    #![proptest_config(crate::common::prop::config(512))]

    /// Our telecommands read in spacepackets with the same fields.
    #[test]
    fn our_tc_parses_in_spacepackets((apid, seq_count, header, data) in tc_parts()) {
        let repr = TcRepr { apid, seq_count, header, app_data: &data };
        let bytes = tc_bytes(&repr);
        let theirs = PusTcReader::new(&bytes).expect("spacepackets reads our TC");
        prop_assert_eq!(theirs.apid().value(), apid.get());
        prop_assert_eq!(theirs.seq_count().value(), seq_count.get());
        prop_assert_eq!(PusPacket::service_type_id(&theirs), header.service);
        prop_assert_eq!(PusPacket::message_subtype_id(&theirs), header.subservice);
        prop_assert_eq!(theirs.source_id(), header.source_id);
        // The nibble as sent (spacepackets names its bits in the other order, see
        // `ack_flags_bit_order_differs`).
        prop_assert_eq!(theirs.ack_flags().raw_value().value(), header.ack.bits());
        prop_assert_eq!(theirs.app_data(), &data[..]);
        prop_assert_eq!(theirs.len_packed(), bytes.len());
    }

    /// spacepackets' telecommands parse here with the same fields.
    #[test]
    fn spacepackets_tc_parses_here((apid, seq_count, header, data) in tc_parts()) {
        let sph = SpHeader::new_for_unseg_tc(u11::new(apid.get()), u14::new(seq_count.get()), 0);
        let sec = PusTcSecondaryHeader::new(
            MessageTypeId::new(header.service, header.subservice),
            spacepackets::ecss::tc::AckFlags::new_with_raw_value(arbitrary_int::u4::new(header.ack.bits())),
            header.source_id,
        );
        let bytes = PusTcCreator::new(sph, sec, &data, CreatorConfig::default()).to_vec().unwrap();
        let ours = TcRepr::parse(&bytes, &[apid.get()]);
        prop_assert_eq!(ours, Ok(TcRepr { apid, seq_count, header, app_data: &data }));
        prop_assert_eq!(tc_bytes(&ours.unwrap()), bytes);
    }

    /// Our telemetry reads in spacepackets (6-octet time field) with the same fields.
    #[test]
    fn our_tm_parses_in_spacepackets((apid, seq_count, header, data) in tm_parts()) {
        let repr = TmRepr { apid, seq_count, header, source_data: &data };
        let bytes = tm_bytes(&repr);
        let theirs = PusTmReader::new(&bytes, 6).expect("spacepackets reads our TM");
        prop_assert_eq!(theirs.apid().value(), apid.get());
        prop_assert_eq!(theirs.seq_count().value(), seq_count.get());
        prop_assert_eq!(PusPacket::service_type_id(&theirs), header.service);
        prop_assert_eq!(PusPacket::message_subtype_id(&theirs), header.subservice);
        prop_assert_eq!(theirs.msg_type_counter(), header.counter);
        prop_assert_eq!(theirs.dest_id(), header.destination_id);
        prop_assert_eq!(theirs.sc_time_ref_status().value(), header.time_ref_status.get());
        prop_assert_eq!(theirs.timestamp(), &header.time.to_bytes()[..]);
        prop_assert_eq!(theirs.source_data(), &data[..]);
    }

    /// spacepackets' telemetry parses here with the same fields.
    #[test]
    fn spacepackets_tm_parses_here((apid, seq_count, header, data) in tm_parts()) {
        let sph = SpHeader::new_for_unseg_tm(u11::new(apid.get()), u14::new(seq_count.get()), 0);
        let stamp = header.time.to_bytes();
        let mut sec = PusTmSecondaryHeader::new(
            MessageTypeId::new(header.service, header.subservice),
            header.counter,
            header.destination_id,
            &stamp,
        );
        sec.sc_time_ref_status = arbitrary_int::u4::new(header.time_ref_status.get());
        let bytes = PusTmCreator::new(sph, sec, &data, CreatorConfig::default()).to_vec().unwrap();
        let ours = TmRepr::parse(&bytes, &[apid.get()]);
        prop_assert_eq!(ours, Ok(TmRepr { apid, seq_count, header, source_data: &data }));
        prop_assert_eq!(tm_bytes(&ours.unwrap()), bytes);
    }
}

// req: 133.0-B-2/SPP-14, 133.0-B-2/SPP-17, 133.0-B-2/SPP-18
#[test]
fn the_golden_ping_is_byte_identical_in_spacepackets() {
    let sph = SpHeader::new_for_unseg_tc(u11::new(super::APID), u14::new(7), 0);
    let theirs = PusTcCreator::new_no_app_data(
        sph,
        PusTcSecondaryHeader::new_simple(MessageTypeId::new(17, 1)),
        CreatorConfig::default(),
    )
    .to_vec()
    .unwrap();
    assert_eq!(theirs, tc_bytes(&super::ping()));
    let stamp = Cuc::from_millis(90_500).to_bytes();
    let sph = SpHeader::new_for_unseg_tm(u11::new(super::APID), u14::new(9), 0);
    let theirs = PusTmCreator::new_no_source_data(
        sph,
        PusTmSecondaryHeader::new(MessageTypeId::new(17, 2), 3, 0, &stamp),
        CreatorConfig::default(),
    )
    .to_vec()
    .unwrap();
    assert_eq!(theirs, tm_bytes(&super::alive()));
}

/// The Rust spacepackets names the acknowledgement bits the other way round from ECSS
/// (and from the Python `spacepackets` and FSFW): its `acceptance` is the nibble's most
/// significant bit. Measured here so that a change on either side is noticed.
#[test]
fn ack_flags_bit_order_differs() {
    let theirs = spacepackets::ecss::tc::AckFlags::builder()
        .with_acceptance(true)
        .with_start(false)
        .with_progress(false)
        .with_completion(false)
        .build();
    assert_eq!(theirs.raw_value().value(), 0b1000);
    let ours = AckFlags {
        acceptance: true,
        ..AckFlags::NONE
    };
    assert_eq!(ours.bits(), 0b0001);
    assert!(AckFlags::from_bits(0b1000).completion);
}

/// The bad inputs of `spec/ccsds/bad-inputs.toml` that spacepackets 0.19's readers
/// (`PusTcReader::new`, `PusTmReader::new(_, 6)`) accept, all of which ours refuses.
/// Measured by running every row through both (2026-11-23: 16 of the 22 rows); the list is
/// asserted so that a change in either reader shows. spacepackets refuses only the truncated
/// packets, a data length field longer than the buffer, and a wrong CRC. The foreign APID is
/// no fault of its reader (it takes no APID set); the other 14 are: it never looks at the
/// version, type bit, secondary header flag, sequence flags or PUS version, and reads a packet
/// from the front of a longer buffer without a word about the octets after it.
const SPACEPACKETS_ACCEPTS: &[&str] = &[
    "tc-version-1",
    "tc-type-tm",
    "tc-no-secondary-header",
    "tc-first-segment",
    "tc-continuation-segment",
    "tc-length-says-shorter",
    "tc-pus-a",
    "tc-foreign-apid",
    "tm-version-1",
    "tm-type-tc",
    "tm-no-secondary-header",
    "tm-first-segment",
    "tm-continuation-segment",
    "tm-length-says-shorter",
    "tm-pus-a",
    "tm-foreign-apid",
];

#[test]
fn spacepackets_accepts_bad_inputs_that_we_refuse() {
    let t = table();
    let mut accepted = Vec::new();
    for row in &t.row {
        let bytes = unhex(&row.hex);
        let theirs_ok = match row.parser.as_str() {
            "tc" => PusTcReader::new(&bytes).is_ok(),
            "tm" => PusTmReader::new(&bytes, 6).is_ok(),
            _ => continue,
        };
        assert!(verdict(row, &t.parser.apids).is_some(), "{}", row.name);
        if theirs_ok {
            accepted.push(row.name.as_str());
        }
    }
    println!(
        "spacepackets 0.19 accepts {} of {} bad inputs: {accepted:?}",
        accepted.len(),
        t.row.len()
    );
    assert_eq!(accepted, SPACEPACKETS_ACCEPTS);
}
