//! The CCSDS/PUS wire layer against the `spacepackets` crate (0.19), in one run, on identical
//! octets: telecommand parse+validate and telemetry build (issue 15). Run:
//! `cargo bench -p mmic-benches --bench ccsds` (about 30 s). Results: benches/README.md.

use arbitrary_int::{u11, u14};
use criterion::{criterion_group, criterion_main, Criterion};
use mmic::ccsds::cuc::Cuc;
use mmic::ccsds::primary::{Apid, SeqCount};
use mmic::ccsds::tc::TcRepr;
use mmic::ccsds::tc_header::{AckFlags, TcSecondaryHeader};
use mmic::ccsds::tm::TmRepr;
use mmic::ccsds::tm_header::{TimeRefStatus, TmSecondaryHeader};
use spacepackets::ecss::tc::{PusTcCreator, PusTcReader, PusTcSecondaryHeader};
use spacepackets::ecss::tm::{PusTmCreator, PusTmSecondaryHeader};
use spacepackets::ecss::{CreatorConfig, MessageTypeId};
use spacepackets::SpHeader;
use std::hint::black_box;
use std::time::Duration;

const APID: u16 = 0x042;
/// A function-management telecommand's arguments (TC(8,1)), 3 octets.
const APP_DATA: [u8; 3] = [0x60, b'm', b'a'];
/// A housekeeping report's parameters, the size of the legacy heartbeat's body (60 octets).
const HK: [u8; 60] = [0x5a; 60];

fn tc_repr() -> TcRepr<'static> {
    TcRepr {
        apid: Apid::new(APID).unwrap(),
        seq_count: SeqCount::new(7).unwrap(),
        header: TcSecondaryHeader {
            ack: AckFlags::ALL,
            service: 8,
            subservice: 1,
            source_id: 1,
        },
        app_data: &APP_DATA,
    }
}

fn tm_repr() -> TmRepr<'static> {
    TmRepr {
        apid: Apid::new(APID).unwrap(),
        seq_count: SeqCount::new(9).unwrap(),
        header: TmSecondaryHeader {
            time_ref_status: TimeRefStatus::default(),
            service: 3,
            subservice: 25,
            counter: 3,
            destination_id: 1,
            time: Cuc::from_millis(90_500),
        },
        source_data: &HK,
    }
}

fn tc_parse(c: &mut Criterion) {
    let r = tc_repr();
    let mut ours = vec![0u8; r.len()];
    r.emit(&mut ours).unwrap();
    // The same packet built by spacepackets: the octets must be identical.
    let sph = SpHeader::new_for_unseg_tc(u11::new(APID), u14::new(7), 0);
    let theirs = PusTcCreator::new(
        sph,
        PusTcSecondaryHeader::new(MessageTypeId::new(8, 1), spacepackets::ecss::tc::ACK_ALL, 1),
        &APP_DATA,
        CreatorConfig::default(),
    )
    .to_vec()
    .unwrap();
    assert_eq!(ours, theirs, "both sides must parse the same octets");
    let mut g = c.benchmark_group("pus-tc-parse (16 B)");
    g.bench_function("spacepackets PusTcReader::new", |b| {
        b.iter(|| PusTcReader::new(black_box(&ours)).is_ok())
    });
    g.bench_function("mmic TcRepr::parse", |b| {
        b.iter(|| TcRepr::parse(black_box(&ours), black_box(&[APID])).is_ok())
    });
    g.finish();
}

fn tm_build(c: &mut Criterion) {
    let r = tm_repr();
    let stamp = r.header.time.to_bytes();
    let build_theirs = |out: &mut [u8]| {
        let sph = SpHeader::new_for_unseg_tm(u11::new(APID), u14::new(9), 0);
        let sec = PusTmSecondaryHeader::new(MessageTypeId::new(3, 25), 3, 1, &stamp);
        PusTmCreator::new(sph, sec, &HK, CreatorConfig::default()).write_to_slice(out)
    };
    let mut ours = [0u8; 128];
    let mut theirs = [0u8; 128];
    let n = r.emit(&mut ours).unwrap();
    assert_eq!(build_theirs(&mut theirs).unwrap(), n);
    assert_eq!(
        ours[..n],
        theirs[..n],
        "both sides must build the same octets"
    );
    let mut g = c.benchmark_group("pus-tm-build (81 B)");
    g.bench_function("spacepackets PusTmCreator::write_to_slice", |b| {
        let mut out = [0u8; 128];
        b.iter(|| build_theirs(black_box(&mut out)).is_ok())
    });
    g.bench_function("mmic TmRepr::emit", |b| {
        let mut out = [0u8; 128];
        b.iter(|| black_box(&r).emit(black_box(&mut out)).is_ok())
    });
    g.finish();
}

criterion_group! {
    name = benches;
    config = Criterion::default().measurement_time(Duration::from_secs(2)).warm_up_time(Duration::from_millis(500)).sample_size(50);
    targets = tc_parse, tm_build
}
criterion_main!(benches);
