//! The space data link (issue 27) against the packets it carries, in one run: a TC frame
//! carrying one PUS telecommand parsed (`TcFrame::new_checked` + `packets()`) and built
//! (`TcFrameRepr::emit`) against the bare packet's `TcRepr::parse` / `TcRepr::emit`; the
//! mission's 256-octet TM frame parsed and built; the on-board framer (`TmFramer::push` of one
//! TM(3,25) + `next_frame`) and the ground's extractor (`Extractor::frame`) per frame. Run:
//! `cargo bench -p mmic-benches --bench link` (about 30 s). Results: benches/README.md.

use criterion::{criterion_group, criterion_main, BatchSize, Criterion, Throughput};
use mmic::ccsds::cuc::Cuc;
use mmic::ccsds::primary::{Apid, SeqCount};
use mmic::ccsds::tc::TcRepr;
use mmic::ccsds::tc_header::{AckFlags, TcSecondaryHeader};
use mmic::ccsds::tm::TmRepr;
use mmic::ccsds::tm_header::{TimeRefStatus, TmSecondaryHeader};
use mmic::link::extract::Extractor;
use mmic::link::tc_frame::{mission, MapId, SpacecraftId, TcContent, TcFrame, TcFrameRepr, Vcid};
use mmic::link::tm_frame::{FirstHeaderPointer, TmFrameParams, TmFrameRepr, TM_FRAME_LEN};
use mmic::link::tm_framer::TmFramer;
use std::hint::black_box;
use std::time::Duration;

/// Board 0x42's robot: APID 0x042 in the packets of benches/ccsds.rs, spacecraft 0x142.
const APID: u16 = 0x042;
const SCID: u16 = 0x142;
/// benches/ccsds.rs's TC(8,1) arguments, 3 octets: a 16-octet telecommand.
const APP_DATA: [u8; 3] = [0x60, b'm', b'a'];
/// A housekeeping report's parameters (benches/ccsds.rs): an 81-octet TM(3,25).
const HK: [u8; 60] = [0x5a; 60];
/// The CLCW every TM frame carries: COP-1, VC 0, report value 7.
const CLCW: [u8; 4] = [0x01, 0x00, 0x00, 0x07];

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

fn hk_packet(seq: u16) -> Vec<u8> {
    let r = TmRepr {
        apid: Apid::new(APID).unwrap(),
        seq_count: SeqCount::new(seq & 0x3fff).unwrap(),
        header: TmSecondaryHeader {
            time_ref_status: TimeRefStatus::default(),
            service: 3,
            subservice: 25,
            counter: seq,
            destination_id: 1,
            time: Cuc::from_millis(90_500),
        },
        source_data: &HK,
    };
    let mut out = vec![0u8; r.len()];
    r.emit(&mut out).unwrap();
    out
}

fn tc_frame(c: &mut Criterion) {
    let tc = tc_repr();
    let mut packet = vec![0u8; tc.len()];
    tc.emit(&mut packet).unwrap();
    assert_eq!(packet.len(), 16);
    let spacecraft_id = SpacecraftId::new(SCID).unwrap();
    let frame_repr = TcFrameRepr {
        spacecraft_id,
        vcid: Vcid::new(0).unwrap(),
        seq: 3,
        content: TcContent::Ad {
            map_id: Some(MapId::new(0).unwrap()),
            data: &packet,
        },
    };
    let mut frame = [0u8; 64];
    let n = frame_repr.emit(&mut frame).unwrap();
    assert_eq!(n, 5 + 1 + 16 + 2);
    let frame = &frame[..n];
    let config = mission(spacecraft_id);
    // The frame's one packet is the bare packet, which parses.
    let f = TcFrame::new_checked(frame, &config).unwrap();
    let got: Vec<&[u8]> = f.packets().map(Result::unwrap).collect();
    assert_eq!(got, [&packet[..]]);

    let mut g = c.benchmark_group("tc-parse");
    g.bench_function("bare TC(8,1) 16 B: TcRepr::parse", |b| {
        b.iter(|| TcRepr::parse(black_box(&packet), black_box(&[APID])).is_ok())
    });
    g.bench_function("AD frame 24 B: TcFrame::new_checked + packets()", |b| {
        b.iter(|| {
            let f = TcFrame::new_checked(black_box(frame), black_box(&config));
            f.map(|f| f.packets().map(|p| p.map_or(0, <[u8]>::len)).sum::<usize>())
                .unwrap_or(0)
        })
    });
    g.bench_function("AD frame 24 B: frame + packets + TcRepr::parse", |b| {
        b.iter(|| {
            let f = TcFrame::new_checked(black_box(frame), black_box(&config));
            f.map(|f| {
                f.packets()
                    .filter(|p| p.is_ok_and(|p| TcRepr::parse(p, &[APID]).is_ok()))
                    .count()
            })
            .unwrap_or(0)
        })
    });
    g.finish();

    let mut g = c.benchmark_group("tc-build");
    g.bench_function("bare TC(8,1) 16 B: TcRepr::emit", |b| {
        let mut out = [0u8; 64];
        b.iter(|| black_box(&tc).emit(black_box(&mut out)).is_ok())
    });
    g.bench_function("AD frame 24 B: TcFrameRepr::emit", |b| {
        let mut out = [0u8; 64];
        b.iter(|| black_box(&frame_repr).emit(black_box(&mut out)).is_ok())
    });
    g.finish();
}

fn tm_frame(c: &mut Criterion) {
    let params = TmFrameParams::mission(SCID).unwrap();
    let hk = hk_packet(9);
    assert_eq!(hk.len(), 81);

    // One TM(3,25) per frame, the rest idle: what the robot sends between bursts.
    let mut framer = TmFramer::<1024>::new(params, 500);
    framer.push(&hk).unwrap();
    let mut frame = [0u8; TM_FRAME_LEN];
    framer.next_frame(0, CLCW, &mut frame).unwrap();
    let repr = TmFrameRepr::parse(&frame, &params).unwrap();
    assert_eq!(repr.first_header_pointer, FirstHeaderPointer::Packet(0));
    let data = repr.data.to_vec();

    let mut g = c.benchmark_group("tm-frame (256 B)");
    g.bench_function("TmFrameRepr::parse", |b| {
        b.iter(|| TmFrameRepr::parse(black_box(&frame), black_box(&params)).is_ok())
    });
    g.bench_function("TmFrameRepr::emit", |b| {
        // (Every field spelt out: `..repr` here made rustc 1.95 crash, an ICE in borrowck.)
        let r = TmFrameRepr {
            spacecraft_id: repr.spacecraft_id,
            vcid: repr.vcid,
            mc_frame_count: repr.mc_frame_count,
            vc_frame_count: repr.vc_frame_count,
            first_header_pointer: repr.first_header_pointer,
            data: &data,
            ocf: repr.ocf,
        };
        let mut out = [0u8; TM_FRAME_LEN];
        b.iter(|| {
            black_box(&r)
                .emit(black_box(&params), black_box(&mut out))
                .is_ok()
        })
    });
    g.bench_function("bare TM(3,25) 81 B: TmRepr::emit (reference)", |b| {
        let r = TmRepr::parse(&hk, &[APID]).unwrap();
        let mut out = [0u8; 128];
        b.iter(|| black_box(&r).emit(black_box(&mut out)).is_ok())
    });
    g.bench_function("TmFramer::push TM(3,25) + next_frame", |b| {
        let mut framer = TmFramer::<1024>::new(params, 500);
        let mut out = [0u8; TM_FRAME_LEN];
        let mut t = 0u32;
        b.iter(|| {
            t = t.wrapping_add(500);
            let _ = framer.push(black_box(&hk));
            framer.next_frame(t, CLCW, black_box(&mut out)).is_ok()
        })
    });
    g.finish();

    // The extractor over a stream of 256 full frames (counts 0..=255): 81-octet TM(3,25)s
    // back to back, so that packets span frames; per iteration a fresh extractor reads all 256.
    let mut framer = TmFramer::<4096>::new(params, 500);
    let mut frames = Vec::new();
    let mut seq = 0u16;
    while frames.len() < 256 {
        while framer.push(&hk_packet(seq)).is_ok() {
            seq = seq.wrapping_add(1);
        }
        let mut f = [0u8; TM_FRAME_LEN];
        framer.next_frame(0, CLCW, &mut f).unwrap();
        frames.push(f);
    }
    let reprs: Vec<TmFrameRepr<'_>> = frames
        .iter()
        .map(|f| TmFrameRepr::parse(f, &params).unwrap())
        .collect();
    let mut check = Extractor::<512>::new();
    let mut n = 0;
    for r in &reprs {
        check.frame(r, |p| {
            assert_eq!(p.len(), 81);
            n += 1;
        });
    }
    assert_eq!(check.counters().lost_frames, 0);
    assert_eq!(check.counters().dropped, 0);
    assert!(n >= 256 * 244 / 81 - 1, "{n} packets");

    let mut g = c.benchmark_group("tm-extract (256 frames)");
    g.throughput(Throughput::Elements(256));
    g.bench_function("Extractor::frame x 256", |b| {
        b.iter_batched(
            Extractor::<512>::new,
            |mut e| {
                let mut bytes = 0usize;
                for r in &reprs {
                    e.frame(r, |p| bytes += p.len());
                }
                black_box(bytes)
            },
            BatchSize::SmallInput,
        )
    });
    g.bench_function("TmFrameRepr::parse + Extractor::frame x 256", |b| {
        b.iter_batched(
            Extractor::<512>::new,
            |mut e| {
                let mut bytes = 0usize;
                for f in &frames {
                    if let Ok(r) = TmFrameRepr::parse(black_box(f), &params) {
                        e.frame(&r, |p| bytes += p.len());
                    }
                }
                black_box(bytes)
            },
            BatchSize::SmallInput,
        )
    });
    g.finish();
}

criterion_group! {
    name = benches;
    config = Criterion::default().measurement_time(Duration::from_secs(2)).warm_up_time(Duration::from_millis(500)).sample_size(50);
    targets = tc_frame, tm_frame
}
criterion_main!(benches);
