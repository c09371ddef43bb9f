//! The TM link end to end: packets through `TmFramer` into frames, the frames (some lost)
//! through `TmFrameRepr::parse` into `Extractor`, packets out. An independent walk of the
//! frames' data fields (from the standard's rules: packets end to end, each one's length in
//! its primary header) tells which packet touched which frame.

use super::tm_frame::{params, SCID};
use mmic::link::extract::{ExtractCounters, Extractor};
use mmic::link::tm_frame::{FirstHeaderPointer, TmFrameParams, TmFrameRepr, TM_FRAME_LEN};
use mmic::link::tm_framer::{PushError, TmFramer};
use proptest::prelude::*;

/// A space packet of `len` octets (7..=65542): TM, APID 0x042, sequence count `seq`, data
/// octets numbered from `seq`.
pub fn packet(len: usize, seq: u16) -> Vec<u8> {
    let dl = (len - 7) as u16;
    let mut p = vec![0x08, 0x42, 0xc0 | (seq >> 8) as u8 & 0x3f, seq as u8];
    p.extend(dl.to_be_bytes());
    p.extend((0..len - 6).map(|i| (i as u16).wrapping_add(seq) as u8));
    p
}

/// One step of a run: push a packet of this length, or ask for a frame (a flush).
#[derive(Debug, Clone, Copy)]
pub enum Step {
    Push(usize),
    Frame,
}

/// A run: the packets sent and the frames made, in order (the framer drained at the end:
/// frames until nothing waits).
pub struct Run {
    pub sent: Vec<Vec<u8>>,
    pub frames: Vec<Vec<u8>>,
}

pub fn run<const N: usize>(p: TmFrameParams, steps: &[Step]) -> Run {
    let mut framer = TmFramer::<N>::new(p, 500);
    let mut sent = Vec::new();
    let mut frames = Vec::new();
    let mut t = 0u32;
    let mut frame = |framer: &mut TmFramer<N>, frames: &mut Vec<Vec<u8>>| {
        let mut out = vec![0u8; p.frame_len()];
        t = t.wrapping_add(100);
        let clcw = [0x01, 0, 0, frames.len() as u8];
        assert_eq!(framer.next_frame(t, clcw, &mut out), Ok(p.frame_len()));
        frames.push(out);
    };
    for &s in steps {
        match s {
            Step::Frame => frame(&mut framer, &mut frames),
            Step::Push(len) => {
                let pk = packet(len, sent.len() as u16);
                loop {
                    match framer.push(&pk) {
                        Ok(()) => break,
                        Err(PushError::Full { needed, free }) => {
                            assert_eq!((needed, free), (len, framer.free()));
                            frame(&mut framer, &mut frames);
                        }
                        Err(e) => panic!("{e}"),
                    }
                }
                sent.push(pk);
            }
        }
    }
    while framer.waiting() > 0 {
        frame(&mut framer, &mut frames);
    }
    Run { sent, frames }
}

/// The independent walk: for every packet of the run's stream (idle ones included), its
/// octets and the frames it touches. The stream is the data fields of the frames that are not
/// only-idle-data, end to end, starting at the first frame's first header pointer (0: the
/// framer starts with a packet); each frame's first header pointer is checked against it.
pub fn walk(p: &TmFrameParams, frames: &[Vec<u8>]) -> Vec<(Vec<u8>, Vec<usize>)> {
    let d = p.data_len();
    let mut stream = Vec::new();
    let mut owner = Vec::new(); // frame index of each stream octet
    let mut fhps = Vec::new();
    for (i, f) in frames.iter().enumerate() {
        let r = TmFrameRepr::parse(f, p).expect("the framer's frames parse");
        assert_eq!(r.vc_frame_count, i as u8);
        assert_eq!(r.mc_frame_count, i as u8);
        assert_eq!(r.ocf, Some([0x01, 0, 0, i as u8]));
        if r.first_header_pointer == FirstHeaderPointer::OnlyIdleData {
            assert!(r.data.iter().all(|&b| b == 0x55));
            continue;
        }
        fhps.push((stream.len(), r.first_header_pointer));
        stream.extend_from_slice(r.data);
        owner.extend(std::iter::repeat_n(i, d));
    }
    let mut out = Vec::new();
    let mut starts = Vec::new();
    let mut at = 0;
    while at + 6 <= stream.len() {
        let len = u16::from_be_bytes([stream[at + 4], stream[at + 5]]) as usize + 7;
        if at + len > stream.len() {
            break; // the last idle packet's spilled tail never went
        }
        starts.push(at);
        let mut touched: Vec<usize> = owner[at..at + len].to_vec();
        touched.dedup();
        out.push((stream[at..at + len].to_vec(), touched));
        at += len;
    }
    assert!(stream.len() - at < 7, "octets outside any packet");
    // Each frame's pointer: the first packet start inside its data field, or 0x7FF.
    for (base, fhp) in fhps {
        let first = starts.iter().find(|&&s| s >= base && s < base + d);
        let want = match first {
            Some(&s) => FirstHeaderPointer::Packet((s - base) as u16),
            None => FirstHeaderPointer::NoPacketStart,
        };
        // The spilled idle packet after the walk's end starts in a frame too.
        if first.is_none() && at >= base && at < base + d && at < stream.len() {
            assert_eq!(fhp, FirstHeaderPointer::Packet((at - base) as u16));
            continue;
        }
        assert_eq!(fhp, want, "frame at stream offset {base}");
    }
    out
}

fn is_idle(p: &[u8]) -> bool {
    u16::from_be_bytes([p[0], p[1]]) & 0x7ff == 0x7ff
}

/// Feeds the frames not in `lost` to an extractor; the packets out and its counters.
pub fn extract<const N: usize>(
    p: &TmFrameParams,
    frames: &[Vec<u8>],
    lost: &[bool],
) -> (Vec<Vec<u8>>, ExtractCounters) {
    let mut x = Extractor::<N>::new();
    let mut got = Vec::new();
    for (i, f) in frames.iter().enumerate() {
        if lost.get(i).copied().unwrap_or(false) {
            continue;
        }
        let r = TmFrameRepr::parse(f, p).unwrap();
        x.frame(&r, |pk| got.push(pk.to_vec()));
    }
    (got, *x.counters())
}

/// The run's properties, with the frames of `lost` missing.
pub fn check(p: &TmFrameParams, r: &Run, lost: &[bool]) {
    let packets = walk(p, &r.frames);
    let real: Vec<&(Vec<u8>, Vec<usize>)> = packets.iter().filter(|(pk, _)| !is_idle(pk)).collect();
    // The framer: every packet sent, in order, idle data between.
    assert_eq!(real.len(), r.sent.len());
    for (a, b) in real.iter().zip(&r.sent) {
        assert_eq!(&a.0, b);
    }
    let is_lost = |i: &usize| lost.get(*i).copied().unwrap_or(false);
    let (got, c) = extract::<512>(p, &r.frames, lost);
    let expected: Vec<&Vec<u8>> = real
        .iter()
        .filter(|(_, touched)| !touched.iter().any(is_lost))
        .map(|(pk, _)| pk)
        .collect();
    // Exactly the packets touching no lost frame, whole and in order: nothing spliced.
    assert_eq!(got.len(), expected.len(), "{c:?}");
    for (a, b) in got.iter().zip(&expected) {
        assert_eq!(&a, b);
    }
    let received = (0..r.frames.len()).filter(|i| !is_lost(i)).count() as u32;
    // Losses show between the first and the last frame received.
    let first = (0..r.frames.len()).find(|i| !is_lost(i));
    let last = (0..r.frames.len()).rev().find(|i| !is_lost(i));
    let detectable = match (first, last) {
        (Some(f), Some(l)) => (f..l).filter(|i| is_lost(i)).count() as u32,
        _ => 0,
    };
    assert_eq!(c.frames, received);
    assert_eq!(c.packets, got.len() as u32);
    assert_eq!(c.bad_fhp, 0);
    assert_eq!(c.too_long, 0);
    if r.frames.len() < 256 {
        assert_eq!(c.lost_frames, detectable);
    }
    // The dropped count: at most one packet in reassembly per gap the extractor saw (a run of
    // lost frames between two received ones), and each a sent packet that is missing.
    let gaps = match (first, last) {
        (Some(f), Some(l)) => (f + 1..l)
            .filter(|&i| is_lost(&i) && !is_lost(&(i - 1)))
            .count(),
        _ => 0,
    };
    let missing = real.len() - got.len();
    assert!(c.dropped as usize <= gaps, "{c:?}, {gaps} gaps");
    assert!(
        c.dropped as usize <= missing + (packets.len() - real.len()),
        "{c:?}"
    );
}

// req: 133.0-B-2/SPP-1, 133.0-B-2/SPP-10, 133.0-B-2/SPP-11, 133.0-B-2/SPP-20, 133.0-B-2/SPP-26
// req: 132.0-B-3/TM-1, 132.0-B-3/TM-6, 132.0-B-3/TM-34, 132.0-B-3/TM-35, 132.0-B-3/TM-56
// req: 132.0-B-3/TM-57, 132.0-B-3/TM-59, 132.0-B-3/TM-62
#[test]
#[cfg_attr(
    miri,
    ignore = "122,488 framer runs: hours under Miri (the hand-built streams run)"
)]
fn every_length_at_every_offset() {
    // Every packet length 7..=2 × 244 + 20 starting at every offset of a data field, then
    // flushed (so the idle packet after it fills every possible room, spilling over when the
    // room is below 7 octets), then a 7-octet packet: all out, in order, idle data removed.
    let p = params();
    let d = p.data_len();
    let mut runs = 0;
    let t = std::time::Instant::now();
    for offset in 0..d {
        for len in 7..=2 * d + 20 {
            let mut steps = Vec::new();
            match offset {
                0 => {}
                1..7 => steps.push(Step::Push(d + offset)),
                _ => steps.push(Step::Push(offset)),
            }
            steps.extend([Step::Push(len), Step::Frame, Step::Push(7), Step::Frame]);
            let r = run::<2048>(p, &steps);
            check(&p, &r, &[]);
            runs += 1;
        }
    }
    println!(
        "{runs} runs (lengths 7..=508 × offsets 0..244) in {:.2?}",
        t.elapsed()
    );
    assert_eq!(runs, 244 * 502);
}

// req: 132.0-B-3/TM-63, 132.0-B-3/TM-88
#[test]
fn a_lost_frame_drops_only_the_packets_it_touches() {
    // Every single lost frame of a run with packets of several lengths around the data field's.
    let p = params();
    let steps: Vec<Step> = [7, 243, 244, 245, 300, 13, 488, 489, 100, 7, 7, 250]
        .into_iter()
        .map(Step::Push)
        .collect();
    let r = run::<4096>(p, &steps);
    // Under Miri the first, a middle and the last frame lost (the extractor's code paths: a
    // packet cut at either end and within); natively every frame.
    let n = r.frames.len();
    for i in (0..n).filter(|i| !cfg!(miri) || [0, n / 2, n - 1].contains(i)) {
        let mut lost = vec![false; r.frames.len()];
        lost[i] = true;
        check(&p, &r, &lost);
    }
}

#[test]
#[cfg_attr(
    miri,
    ignore = "300 frames framed, walked and extracted: many minutes under Miri"
)]
fn only_idle_frames_between_bursts_and_the_count_wrap() {
    // 300 frames: the counts wrap; idle frames in between are dropped unseen.
    let p = params();
    let mut steps = Vec::new();
    for k in 0..150 {
        steps.push(Step::Push(7 + k * 2));
        steps.extend([Step::Frame, Step::Frame]);
    }
    let r = run::<4096>(p, &steps);
    assert!(r.frames.len() > 256);
    check(&p, &r, &[]);
    let (_, c) = extract::<512>(&p, &r.frames, &[]);
    assert!(c.idle_frames > 50, "{c:?}");
}

// req: 132.0-B-3/TM-87
#[test]
fn too_long_packets_are_skipped_and_counted() {
    let p = params();
    let r = run::<4096>(p, &[Step::Push(600), Step::Push(100), Step::Push(300)]);
    let (got, c) = extract::<256>(&p, &r.frames, &[]);
    assert_eq!(got, vec![r.sent[1].clone()]);
    assert_eq!((c.too_long, c.packets, c.dropped), (2, 1, 0));
}

#[test]
fn the_framer_refuses_what_it_cannot_take() {
    let p = params();
    let mut f = TmFramer::<64>::new(p, 500);
    assert_eq!(f.push(&packet(60, 0)), Ok(()));
    assert_eq!(
        f.push(&packet(7, 1)),
        Err(PushError::Full { needed: 7, free: 4 })
    );
    assert_eq!(f.waiting(), 60);
    let mut bad = packet(20, 2);
    bad.pop();
    assert_eq!(
        f.push(&bad),
        Err(PushError::NotAPacket {
            expected: 20,
            found: 19
        })
    );
    assert_eq!(
        f.push(&[0x08, 0x42]),
        Err(PushError::NotAPacket {
            expected: 0,
            found: 2
        })
    );
    let mut small = [0u8; TM_FRAME_LEN - 1];
    assert!(f.next_frame(0, [0; 4], &mut small).is_err());
    assert_eq!(f.waiting(), 60);
}

// req: 132.0-B-3/TM-40, 132.0-B-3/TM-57
#[test]
fn frames_are_due_when_full_or_after_the_idle_period() {
    let p = params();
    let mut f = TmFramer::<1024>::new(p, 500);
    assert!(f.frame_due(0)); // none sent yet
    let mut out = [0u8; TM_FRAME_LEN];
    f.next_frame(u32::MAX - 100, [0; 4], &mut out).unwrap();
    assert!(!f.frame_due(u32::MAX));
    assert!(!f.frame_due(398)); // 499 ms after, across the wrap
    assert!(f.frame_due(399));
    f.push(&packet(243, 0)).unwrap();
    assert!(!f.frame_due(0));
    f.push(&packet(7, 1)).unwrap();
    assert!(f.frame_due(0)); // 250 octets wait: a data field's worth
}

#[test]
fn the_spilled_idle_packet_points_the_next_frame_past_it() {
    // 240 octets: 4 left, an idle packet's first 4 octets; the next frame starts with its
    // last 3, and a packet waiting then starts at octet 3.
    let p = params();
    let mut f = TmFramer::<1024>::new(p, 500);
    f.push(&packet(240, 0)).unwrap();
    let mut out = [0u8; TM_FRAME_LEN];
    f.next_frame(0, [0; 4], &mut out).unwrap();
    let r = TmFrameRepr::parse(&out, &p).unwrap();
    assert_eq!(r.data[240..], [0x07, 0xff, 0xc0, 0x00]);
    f.push(&packet(9, 1)).unwrap();
    f.next_frame(1, [0; 4], &mut out).unwrap();
    let r = TmFrameRepr::parse(&out, &p).unwrap();
    assert_eq!(r.first_header_pointer, FirstHeaderPointer::Packet(3));
    assert_eq!(r.data[..3], [0x00, 0x00, 0x55]);
    assert_eq!(r.data[3..12], packet(9, 1)[..]);
    assert_eq!(SCID, r.spacecraft_id);
}

fn steps() -> impl Strategy<Value = Vec<Step>> {
    prop::collection::vec(
        prop_oneof![
            4 => (7usize..=300).prop_map(Step::Push),
            1 => Just(Step::Frame),
        ],
        0..40,
    )
}

proptest! {
    #![proptest_config(crate::common::prop::config(2000))]

    // req: 133.0-B-2/SPP-1, 133.0-B-2/SPP-10, 133.0-B-2/SPP-11, 133.0-B-2/SPP-25
    // req: 132.0-B-3/TM-62
    #[test]
    fn any_packets_come_out_identical_and_in_order(s in steps()) {
        let p = params();
        let r = run::<1024>(p, &s);
        check(&p, &r, &[]);
    }

    #[test]
    fn with_lost_frames_every_packet_out_is_intact(s in steps(), lost in prop::collection::vec(prop::bool::weighted(0.2), 0..80)) {
        let p = params();
        let r = run::<1024>(p, &s);
        check(&p, &r, &lost);
    }

    #[test]
    fn short_frames_too(s in steps(), lost in prop::collection::vec(prop::bool::weighted(0.2), 0..400), len in 13usize..40) {
        // Data fields of 1..=28 octets: packets span many frames, idle packets spill often.
        let p = TmFrameParams::new(len, SCID, 0, true, true).unwrap();
        let r = run::<1024>(p, &s);
        check(&p, &r, &lost);
    }
}

/// A frame repr of VC count `count` over `data` (the extractor reads no other field).
fn repr(count: u8, fhp: FirstHeaderPointer, data: &[u8]) -> TmFrameRepr<'_> {
    TmFrameRepr {
        spacecraft_id: SCID,
        vcid: 0,
        mc_frame_count: count,
        vc_frame_count: count,
        first_header_pointer: fhp,
        data,
        ocf: None,
    }
}

/// Feeds `frames` to a fresh extractor (`Default`, the empty extractor `new` gives: the
/// tests above start from `new`): the packets out and the counters.
fn feed(frames: &[TmFrameRepr]) -> (Vec<Vec<u8>>, ExtractCounters) {
    let mut x = Extractor::<64>::default();
    assert!(!x.in_packet());
    let mut got = Vec::new();
    for f in frames {
        x.frame(f, |p| got.push(p.to_vec()));
    }
    (got, *x.counters())
}

#[test]
fn a_pointer_past_the_packet_end_delivers_it_and_resumes_at_the_pointer() {
    // Frame 0: a 12-octet packet starts at 0 and runs 8 octets into frame 1; frame 1 says the
    // next packet starts at 10, not 8: the packet is whole (delivered), octets 8..10 skipped.
    let (a, b) = (packet(12, 1), packet(7, 2));
    let d0 = a[..4].to_vec();
    let mut d1 = a[4..].to_vec();
    d1.extend([0xee, 0xee]);
    d1.extend(&b);
    let (got, c) = feed(&[
        repr(0, FirstHeaderPointer::Packet(0), &d0),
        repr(1, FirstHeaderPointer::Packet(10), &d1),
    ]);
    assert_eq!(got, vec![a, b]);
    assert_eq!((c.bad_fhp, c.dropped, c.packets), (1, 0, 2));
}

#[test]
fn a_pointer_inside_the_packet_drops_it() {
    // The packet needs 8 more octets, the pointer says a packet starts at 3: dropped, never
    // spliced; the packet at 3 comes out.
    let (a, b) = (packet(12, 1), packet(9, 2));
    let d0 = a[..4].to_vec();
    let mut d1 = a[4..7].to_vec();
    d1.extend(&b);
    let (got, c) = feed(&[
        repr(7, FirstHeaderPointer::Packet(0), &d0),
        repr(8, FirstHeaderPointer::Packet(3), &d1),
    ]);
    assert_eq!(got, vec![b]);
    assert_eq!((c.bad_fhp, c.dropped, c.packets), (1, 1, 1));
}

#[test]
fn no_packet_start_where_one_is_due_is_a_bad_pointer() {
    // Frame 0 ends exactly with its packet: frame 1 must start one at octet 0.
    let a = packet(8, 1);
    let (got, c) = feed(&[
        repr(0, FirstHeaderPointer::Packet(0), &a),
        repr(1, FirstHeaderPointer::NoPacketStart, &[0; 8]),
        repr(2, FirstHeaderPointer::Packet(0), &a),
    ]);
    assert_eq!(got, vec![a.clone(), a]);
    assert_eq!((c.bad_fhp, c.dropped), (1, 0));
}

#[test]
fn an_only_idle_frame_keeps_the_packet_in_reassembly() {
    // As YAMCS's VcTmPacketHandler: the idle frame counts, the packet continues after it.
    let (a, b) = (packet(12, 1), packet(7, 2));
    let d2 = [&a[5..], &b[..]].concat();
    let (got, c) = feed(&[
        repr(0, FirstHeaderPointer::Packet(0), &a[..5]),
        repr(1, FirstHeaderPointer::OnlyIdleData, &[0x55; 5]),
        repr(2, FirstHeaderPointer::Packet(7), &d2),
    ]);
    assert_eq!(got, vec![a, b]);
    assert_eq!((c.idle_frames, c.lost_frames, c.dropped), (1, 0, 0));
}

#[test]
fn a_repeated_or_overtaken_frame_is_skipped_whole() {
    // The count does not move (a copy), or moves back (a frame overtaken in transport): the
    // frame is skipped, the packet in reassembly kept, nothing delivered twice or out of order.
    let a = packet(12, 1);
    let (got, c) = feed(&[
        repr(5, FirstHeaderPointer::Packet(0), &a[..6]),
        repr(5, FirstHeaderPointer::Packet(0), &a[..6]),
        repr(6, FirstHeaderPointer::NoPacketStart, &a[6..]),
    ]);
    assert_eq!(got, vec![a.clone()]);
    assert_eq!((c.lost_frames, c.dropped, c.repeated), (0, 0, 1));
    // 7 arrives before 6: 6 is lost to the extractor (the gap), and late when it comes.
    let b = packet(7, 2);
    let (got, c) = feed(&[
        repr(5, FirstHeaderPointer::Packet(0), &a),
        repr(7, FirstHeaderPointer::Packet(0), &b),
        repr(6, FirstHeaderPointer::Packet(0), &a),
    ]);
    assert_eq!(got, vec![a.clone(), b]);
    assert_eq!((c.lost_frames, c.repeated), (1, 1));
    // 128 behind is a loss, not a late frame.
    let (got, c) = feed(&[
        repr(200, FirstHeaderPointer::Packet(0), &a),
        repr(72, FirstHeaderPointer::Packet(0), &a),
    ]);
    assert_eq!(got.len(), 2);
    assert_eq!((c.lost_frames, c.repeated), (127, 0));
}

#[test]
fn a_lost_frame_inside_a_header_drops_the_header() {
    // The header is cut after 3 octets, the next frame is lost: the 3 octets are dropped;
    // the next frame's pointer (a packet at 2) is where extraction resumes.
    let a = packet(7, 1);
    let b = packet(7, 2);
    let mut d2 = vec![0xee, 0xee];
    d2.extend(&b);
    let (got, c) = feed(&[
        repr(0, FirstHeaderPointer::Packet(0), &a[..3]),
        repr(2, FirstHeaderPointer::Packet(2), &d2),
    ]);
    assert_eq!(got, vec![b]);
    assert_eq!((c.lost_frames, c.dropped, c.bad_fhp), (1, 1, 0));
}
