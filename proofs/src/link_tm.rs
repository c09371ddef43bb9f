//! Properties of the TM side of the space data link (`mmic::link::{tm_frame, tm_framer,
//! extract}`), shared by the harnesses of `tests/harnesses/link_tm.rs` and the fuzz targets
//! `tm_frame_parser` and `tm_extractor`.
//!
//! The oracle, [`tm_frame_oracle`], is written from the bit positions of CCSDS 132.0-B-3
//! §4.1.2 and the documented check order (length → version → secondary header flag → OCF flag
//! → FECF → spacecraft ID → VCID → synch flag → packet order flag → segment length ID → first
//! header pointer), on raw octets with the bitwise CRC [`crate::crc16_bitwise`], sharing no
//! code with the library's parser. The link properties walk the frames' data fields on their
//! own ([`walk`]: packets end to end, each one's length from its primary header) to know which
//! packet touched which frame. Unlike the rest of this `no_std` crate they build `alloc`
//! vectors (frames and packet lists of any length): they are not sized for Kani.
//!
//! ```
//! use mmic_proofs::link_tm::{check_link, check_tm_frame_parse, reference_frame, PARAMS};
//!
//! assert!(check_tm_frame_parse(&reference_frame(), &PARAMS)); // accepted, re-emitted identically
//! assert!(!check_tm_frame_parse(&[0; 256], &PARAMS)); // refused as the oracle says
//! // Two packets of 300 and 7 octets, no frame lost: both out, whole, in order.
//! check_link(&[0, 0xff, 0x28], false);
//! ```

extern crate alloc;

use crate::crc16_bitwise;
use alloc::vec;
use alloc::vec::Vec;
use mmic::link::extract::Extractor;
use mmic::link::tm_frame::{FirstHeaderPointer, TmFrameError, TmFrameParams, TmFrameRepr};
use mmic::link::tm_framer::{PushError, TmFramer};

/// The parameters of the parse properties: the mission's for spacecraft 0x142.
pub const PARAMS: TmFrameParams = match TmFrameParams::mission(0x142) {
    Some(p) => p,
    None => panic!("0x142 fits 10 bits"),
};

/// The verdict the documented checks give `b` under `p`, worked out from the bit positions
/// of 132.0-B-3 §4.1.2.
pub fn tm_frame_oracle(b: &[u8], p: &TmFrameParams) -> Result<(), TmFrameError> {
    if b.len() != p.frame_len() {
        return Err(TmFrameError::Length {
            expected: p.frame_len(),
            found: b.len(),
        });
    }
    // Octet 0: VV SSSSSS; octet 1: SSSS VVV O; octets 4-5: S Y P LL FFFFFFFFFFF.
    if b[0] >> 6 != 0 {
        return Err(TmFrameError::Version {
            expected: 0,
            found: b[0] >> 6,
        });
    }
    if b[4] & 0x80 != 0 {
        return Err(TmFrameError::SecondaryHeaderFlag);
    }
    if (b[1] & 1 == 1) != p.ocf() {
        return Err(TmFrameError::OcfFlag {
            expected: p.ocf(),
            found: b[1] & 1 == 1,
        });
    }
    if p.fecf() {
        let n = b.len();
        let carried = (b[n - 2] as u16) << 8 | b[n - 1] as u16;
        let computed = crc16_bitwise(&b[..n - 2]);
        if carried != computed {
            return Err(TmFrameError::Fecf { carried, computed });
        }
    }
    let scid = ((b[0] & 0x3f) as u16) << 4 | (b[1] >> 4) as u16;
    if scid != p.spacecraft_id() {
        return Err(TmFrameError::SpacecraftId {
            expected: p.spacecraft_id(),
            found: scid,
        });
    }
    let vcid = (b[1] >> 1) & 7;
    if vcid != p.vcid() {
        return Err(TmFrameError::Vcid {
            expected: p.vcid(),
            found: vcid,
        });
    }
    if b[4] & 0x40 != 0 {
        return Err(TmFrameError::SynchFlag);
    }
    if b[4] & 0x20 != 0 {
        return Err(TmFrameError::PacketOrderFlag);
    }
    if (b[4] >> 3) & 3 != 3 {
        return Err(TmFrameError::SegmentLengthId {
            expected: 3,
            found: (b[4] >> 3) & 3,
        });
    }
    let fhp = ((b[4] & 7) as u16) << 8 | b[5] as u16;
    let data_len = b.len() - 6 - 4 * p.ocf() as usize - 2 * p.fecf() as usize;
    if fhp < 0x7fe && fhp as usize >= data_len {
        return Err(TmFrameError::FirstHeaderPointer {
            data_len,
            found: fhp,
        });
    }
    Ok(())
}

/// `TmFrameRepr::parse` of `b` under `p` gives exactly the oracle's verdict; an accepted frame
/// re-emits to the same octets. Whether it was accepted.
pub fn check_tm_frame_parse(b: &[u8], p: &TmFrameParams) -> bool {
    let ours = TmFrameRepr::parse(b, p);
    assert_eq!(ours.map(|_| ()), tm_frame_oracle(b, p), "{b:02x?}");
    match ours {
        Ok(r) => {
            let mut out = [0u8; 2048];
            assert_eq!(r.emit(p, &mut out), Ok(b.len()));
            assert_eq!(&out[..b.len()], b);
            true
        }
        Err(e) => {
            assert_eq!(e.name(), TmFrameError::NAMES[e.position()]);
            false
        }
    }
}

/// The FECF of `frame` rewritten (bitwise CRC).
pub fn reseal(frame: &mut [u8]) {
    let n = frame.len();
    if n >= 2 {
        let c = crc16_bitwise(&frame[..n - 2]);
        frame[n - 2] = (c >> 8) as u8;
        frame[n - 1] = c as u8;
    }
}

/// The reference frame of `spec/ccsds/bad-inputs.toml`'s `tm-frame` rows, built by hand here:
/// spacecraft 0x142, VC 0, counts 0x12/0x34, first header pointer 0, a 21-octet TM(17,2), a
/// 223-octet idle packet, CLCW `01 00 00 00`, FECF.
pub fn reference_frame() -> Vec<u8> {
    let mut f = vec![0x14, 0x21, 0x12, 0x34, 0x18, 0x00];
    f.extend([
        0x08, 0x42, 0xc0, 0x09, 0x00, 0x0e, 0x20, 0x11, 0x02, 0x00, 0x03, 0x00, 0x00, 0x00, 0x00,
        0x00, 0x5a, 0x80, 0x00, 0xef, 0x0f,
    ]);
    f.extend([0x07, 0xff, 0xc0, 0x00, 0x00, 0xd8]);
    f.extend([0x55; 217]);
    f.extend([0x01, 0, 0, 0, 0, 0]);
    reseal(&mut f);
    f
}

/// A frame repr from `seed` (spacecraft ID, VCID, counts, pointer, data fill, OCF) under the
/// parameters its IDs make with 13..=2048 octets, OCF and FECF flags from the seed: emit → parse
/// is the identity, the octets pass the oracle, and a parser expecting another spacecraft
/// refuses it by the spacecraft-id check.
pub fn check_tm_frame_round_trip(seed: &[u8; 12]) {
    let [s0, s1, vc, mc, vcc, f0, f1, fill, o0, flags, len, o1] = *seed;
    let scid = ((s0 as u16) << 8 | s1 as u16) & 0x3ff;
    let vcid = vc & 7;
    let (ocf, fecf) = (flags & 1 == 1, flags & 2 == 2);
    let frame_len = 13 + len as usize * 2035 / 255;
    let p = TmFrameParams::new(frame_len, scid, vcid, ocf, fecf).expect("13..=2048 octets");
    let d = p.data_len();
    let fhp = match ((f0 as u16) << 8 | f1 as u16) % (d as u16 + 2) {
        x if x as usize == d => FirstHeaderPointer::NoPacketStart,
        x if x as usize == d + 1 => FirstHeaderPointer::OnlyIdleData,
        x => FirstHeaderPointer::Packet(x),
    };
    let data: Vec<u8> = (0..d).map(|i| fill.wrapping_add(i as u8)).collect();
    let r = TmFrameRepr {
        spacecraft_id: scid,
        vcid,
        mc_frame_count: mc,
        vc_frame_count: vcc,
        first_header_pointer: fhp,
        data: &data,
        ocf: ocf.then_some([o0, o1, o0 ^ o1, 0x5a]),
    };
    let mut out = vec![0u8; frame_len];
    assert_eq!(r.emit(&p, &mut out), Ok(frame_len));
    assert_eq!(TmFrameRepr::parse(&out, &p), Ok(r));
    assert_eq!(tm_frame_oracle(&out, &p), Ok(()));
    let other = TmFrameParams::new(frame_len, scid ^ 1, vcid, ocf, fecf).expect("same shape");
    assert_eq!(
        TmFrameRepr::parse(&out, &other),
        Err(TmFrameError::SpacecraftId {
            expected: scid ^ 1,
            found: scid
        })
    );
}

/// A space packet of `len` octets: TM, APID 0x042, count `seq`, data numbered from `seq`.
pub fn packet(len: usize, seq: u16) -> Vec<u8> {
    let dl = (len - 7) as u16;
    let mut p = vec![0x08, 0x42, 0xc0 | ((seq >> 8) as u8 & 0x3f), seq as u8];
    p.extend(dl.to_be_bytes());
    p.extend((0..len - 6).map(|i| (i as u16).wrapping_add(seq) as u8));
    p
}

/// The frame parameters of a link run: the mission's (256 octets) for an even selector, else
/// a short frame of 13 + `(sel / 2) % 28` octets (data fields of 1..=28: packets span many
/// frames and idle packets spill over often; 55 gives 40 octets, a data field of 28).
pub fn link_params(sel: u8) -> TmFrameParams {
    let p = match sel % 2 {
        0 => TmFrameParams::mission(0x142),
        _ => TmFrameParams::new(13 + (sel / 2 % 28) as usize, 0x142, 0, true, true),
    };
    p.expect("valid parameters")
}

/// What one step octet of a link run means: below 40 a frame (a flush), else a packet of
/// 7..=300 octets.
pub fn step_len(b: u8) -> Option<usize> {
    (b >= 40).then(|| 7 + (b - 40) as usize * 293 / 215)
}

/// Packets through the framer (`steps`: [`step_len`]), drained into frames.
pub fn frame_run(p: TmFrameParams, steps: &[u8]) -> (Vec<Vec<u8>>, Vec<Vec<u8>>) {
    let mut framer = TmFramer::<1024>::new(p, 500);
    let mut sent = Vec::new();
    let mut frames = Vec::new();
    let make = |framer: &mut TmFramer<1024>, frames: &mut Vec<Vec<u8>>| {
        let mut out = vec![0u8; p.frame_len()];
        let n = frames.len();
        assert_eq!(
            framer.next_frame(n as u32 * 100, [1, 0, 0, n as u8], &mut out),
            Ok(p.frame_len())
        );
        frames.push(out);
    };
    for &b in steps {
        match step_len(b) {
            None => make(&mut framer, &mut frames),
            Some(len) => {
                let pk = packet(len, sent.len() as u16);
                loop {
                    match framer.push(&pk) {
                        Ok(()) => break,
                        Err(PushError::Full { .. }) => make(&mut framer, &mut frames),
                        Err(e) => panic!("{e}"),
                    }
                }
                sent.push(pk);
            }
        }
    }
    while framer.waiting() > 0 {
        make(&mut framer, &mut frames);
    }
    (sent, frames)
}

/// The independent walk of the frames' data fields: every whole packet of the stream (idle
/// ones included), with the frames it touches. Asserts the frame counts, the OCF, each first
/// header pointer against the stream, and that no octet lies outside a packet.
pub fn walk(p: &TmFrameParams, frames: &[Vec<u8>]) -> Vec<(Vec<u8>, Vec<usize>)> {
    let d = p.data_len();
    let mut stream = Vec::new();
    let mut owner = Vec::new();
    let mut bases = Vec::new();
    for (i, f) in frames.iter().enumerate() {
        assert_eq!(tm_frame_oracle(f, p), Ok(()));
        assert_eq!((f[2], f[3]), (i as u8, i as u8), "frame counts");
        assert_eq!(f[6 + d..10 + d], [1, 0, 0, i as u8], "OCF");
        let fhp = ((f[4] & 7) as usize) << 8 | f[5] as usize;
        if fhp == 0x7fe {
            continue;
        }
        bases.push((stream.len(), fhp));
        stream.extend_from_slice(&f[6..6 + d]);
        owner.extend(core::iter::repeat_n(i, d));
    }
    let mut out = Vec::new();
    let mut starts = Vec::new();
    let mut at = 0;
    while at + 6 <= stream.len() {
        let len = ((stream[at + 4] as usize) << 8 | stream[at + 5] as usize) + 7;
        starts.push(at);
        if at + len > stream.len() {
            break;
        }
        let mut touched = owner[at..at + len].to_vec();
        touched.dedup();
        out.push((stream[at..at + len].to_vec(), touched));
        at += len;
    }
    if at < stream.len() && starts.last() != Some(&at) {
        starts.push(at); // a spilled idle packet's first octets, its header cut
    }
    let whole: usize = out.iter().map(|(pk, _)| pk.len()).sum();
    assert!(stream.len() - whole < 7, "octets outside any packet");
    for (base, fhp) in bases {
        let want = starts
            .iter()
            .find(|&&s| s >= base && s < base + d)
            .map_or(0x7ff, |s| s - base);
        assert_eq!(
            fhp, want,
            "first header pointer of the frame at stream offset {base}"
        );
    }
    out
}

/// A run of the link from `input` (octet 0: [`link_params`]; with `loss`, octets 1..=8: a
/// 64-bit mask, frame `i` lost when bit `i % 64` is set; the rest: the steps): the framer's
/// frames hold every packet sent, in order, idle data between (walked independently); the
/// extractor, given the frames not lost, hands out exactly the packets that touch no lost
/// frame, whole and in order (none lost or duplicated across frame boundaries, none spliced),
/// counts every frame and every detectable lost one, and drops at most one packet per gap.
pub fn check_link(input: &[u8], loss: bool) {
    let (sel, rest) = input.split_first().map_or((0, &[][..]), |(s, r)| (*s, r));
    let (mask, steps) = if loss {
        let (m, s) = rest.split_at(rest.len().min(8));
        let mut b = [0u8; 8];
        b[..m.len()].copy_from_slice(m);
        (u64::from_le_bytes(b), s)
    } else {
        (0, rest)
    };
    let p = link_params(sel);
    let (sent, frames) = frame_run(p, steps);
    let packets = walk(&p, &frames);
    let is_idle = |pk: &[u8]| pk[0] & 7 == 7 && pk[1] == 0xff;
    let real: Vec<&(Vec<u8>, Vec<usize>)> = packets.iter().filter(|(pk, _)| !is_idle(pk)).collect();
    assert_eq!(real.len(), sent.len(), "the framer lost or added a packet");
    for (a, b) in real.iter().zip(&sent) {
        assert_eq!(&a.0, b);
    }
    let lost = |i: usize| mask >> (i % 64) & 1 == 1;
    let mut x = Extractor::<512>::new();
    let mut got = Vec::new();
    for (_, f) in frames.iter().enumerate().filter(|(i, _)| !lost(*i)) {
        let r = TmFrameRepr::parse(f, &p).expect("the framer's frames parse");
        x.frame(&r, |pk| got.push(pk.to_vec()));
    }
    let expected: Vec<&Vec<u8>> = real
        .iter()
        .filter(|(_, t)| !t.iter().any(|&i| lost(i)))
        .map(|(pk, _)| pk)
        .collect();
    assert_eq!(got.len(), expected.len(), "{:?}", x.counters());
    for (a, b) in got.iter().zip(&expected) {
        assert_eq!(&a, b, "a packet out differs from the one sent");
    }
    let c = x.counters();
    let received: Vec<usize> = (0..frames.len()).filter(|&i| !lost(i)).collect();
    assert_eq!(c.frames as usize, received.len());
    assert_eq!(
        (c.packets as usize, c.bad_fhp, c.too_long),
        (got.len(), 0, 0)
    );
    if let (Some(&f), Some(&l)) = (received.first(), received.last()) {
        if frames.len() < 256 {
            assert_eq!(c.lost_frames as usize, (f..l).filter(|&i| lost(i)).count());
        }
        let gaps = (f + 1..l).filter(|&i| lost(i) && !lost(i - 1)).count();
        assert!(c.dropped as usize <= gaps);
    }
    if !loss {
        assert_eq!((c.lost_frames, c.dropped), (0, 0));
    }
}

/// The fuzz target `tm_extractor`'s property: any octets cut into frames of `p`, each
/// through the parser and, when accepted, the extractor; every packet out is a whole packet
/// (its length field says its length), no longer than the buffer, never an idle one; the
/// counters add up.
pub fn check_extractor_stream(input: &[u8]) {
    let (sel, rest) = input.split_first().map_or((0, &[][..]), |(s, r)| (*s, r));
    let p = link_params(sel % 4);
    let mut x = Extractor::<64>::new();
    let mut accepted = 0u32;
    for chunk in rest.chunks(p.frame_len()) {
        let mut f = chunk.to_vec();
        f.resize(p.frame_len(), 0);
        // Make most frames pass: version, IDs, flags, pointer low bits kept from the input.
        f[0] = 0x14;
        f[1] = 0x21;
        f[4] = (f[4] & 0x07) | 0x18;
        reseal(&mut f);
        if let Ok(r) = TmFrameRepr::parse(&f, &p) {
            accepted += 1;
            x.frame(&r, |pk| {
                assert!(pk.len() >= 7 && pk.len() <= 64);
                let len = ((pk[4] as usize) << 8 | pk[5] as usize) + 7;
                assert_eq!(len, pk.len());
                assert!(!(pk[0] & 7 == 7 && pk[1] == 0xff), "an idle packet out");
            });
        }
    }
    assert_eq!(x.counters().frames, accepted);
}
