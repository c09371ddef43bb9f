//! The TC transfer frame (CCSDS 232.0-B-4 §4.1, `mmic::link::tc_frame`): golden frames worked
//! out by hand from the standard's bit layout, round trips, each check's error, the packets of
//! a data field, and every 1-, 2- and 3-bit error of a reference frame refused.

use super::{hex, ping, tc_bytes, unhex};
use mmic::ccsds::pec;
use mmic::link::tc_frame::{
    mission, MapId, Packets, SpacecraftId, TcContent, TcEmitError, TcFrame, TcFrameConfig,
    TcFrameError, TcFrameRepr, VcConfig, Vcid, FECF_LEN, MAX_FRAME_LEN, SEGMENT_HEADER_LEN,
    TC_MAX_FRAME_LEN, TC_PRIMARY_HEADER_LEN,
};
use mmic::link::{ControlCommand, FrameKind};
use std::collections::BTreeMap;

/// The reference robot's spacecraft ID: board 1's, 0x100 + 1.
pub const SCID: u16 = 0x101;

/// The mission's configuration for [`SCID`].
pub fn config() -> TcFrameConfig<'static> {
    mission(SpacecraftId::new(SCID).unwrap())
}

/// A frame of `SCID` on VC 0 with N(S) `seq` and `content`.
pub fn frame(seq: u8, content: TcContent<'_>) -> TcFrameRepr<'_> {
    TcFrameRepr {
        spacecraft_id: SpacecraftId::new(SCID).unwrap(),
        vcid: Vcid::new(0).unwrap(),
        seq,
        content,
    }
}

fn map0() -> Option<MapId> {
    Some(MapId::new(0).unwrap())
}

/// The frame's octets.
pub fn frame_bytes(r: &TcFrameRepr) -> Vec<u8> {
    let mut out = vec![0u8; r.len()];
    assert_eq!(r.emit(&mut out), Ok(out.len()));
    out
}

/// Rewrites the frame length field for the frame's length and the FECF over the rest.
pub fn reseal(f: &mut [u8]) {
    let n = f.len();
    let l = (n - 1) as u16;
    f[2] = (f[2] & 0xfc) | (l >> 8) as u8;
    f[3] = l as u8;
    let crc = pec(&f[..n - 2]);
    f[n - 2..].copy_from_slice(&crc.to_be_bytes());
}

// The golden frames, bit by bit (232.0-B-4 §4.1.2; FECF = CRC-16/CCITT-FALSE of every octet
// before it, computed independently by a bitwise CRC in Python and cross-checked below):
//
// AD, spacecraft 0x101, VC 0, N(S) 0, segment header MAP 0, the 13-octet ping:
//   length 5 + 1 + 13 + 2 = 21 octets, field 20 = 0b00_0001_0100
//   octet 0: version 00 | bypass 0 | control 0 | spare 00 | SCID bits 9-8 = 01  -> 0000_0001 = 0x01
//   octet 1: SCID bits 7-0 = 0x01                                                -> 0x01
//   octet 2: VCID 000000 | length bits 9-8 = 00                                  -> 0x00
//   octet 3: length bits 7-0 = 0x14                                              -> 0x14
//   octet 4: N(S) = 0                                                            -> 0x00
//   octet 5: segment header: sequence flags 11 | MAP ID 000000                   -> 0xc0
//   octets 6-18: the ping 1842c00700062f1101000012d0; octets 19-20: FECF 0x6a5a
// BD: as AD with bypass 1 -> octet 0 = 0010_0001 = 0x21; FECF 0x0ae0
// BC Unlock: bypass 1, control 1 -> octet 0 = 0011_0001 = 0x31; 5 + 1 + 2 = 8 octets, field 7;
//   data field 0x00 (no segment header in a BC frame); FECF 0x4bfd
// BC Set V(R) = 5: 5 + 3 + 2 = 10 octets, field 9; data field 0x82 0x00 0x05; FECF 0x25b3
//
// Interoperation: no library at hand encodes TC transfer frames to compare with (checked
// 2026-11-26: Python spacepackets 0.32 has TM frames and USLP only, the Rust spacepackets 0.19
// USLP only, Python ccsds-cop 0.1.2 the CLCW only). The four FECFs were also recomputed with
// fastcrc 0.3.6's CRC-16/IBM-3740 (CCITT-FALSE's other name; spacepackets' CRC dependency):
// 0x6a5a, 0x0ae0, 0x4bfd, 0x25b3, and each whole frame's CRC is 0 (the residue check).
pub const AD_PING: &str = "0101001400c01842c00700062f1101000012d06a5a";
pub const BD_PING: &str = "2101001400c01842c00700062f1101000012d00ae0";
pub const BC_UNLOCK: &str = "3101000700004bfd";
pub const BC_SET_VR_5: &str = "310100090082000525b3";

// req: 232.0-B-4/TC-4, 232.0-B-4/TC-7, 232.0-B-4/TC-19, 232.0-B-4/TC-20, 232.0-B-4/TC-21
// req: 232.0-B-4/TC-22, 232.0-B-4/TC-23, 232.0-B-4/TC-38, 232.0-B-4/TC-42, 232.0-B-4/TC-45
// req: 232.0-B-4/TC-46, 232.0-B-4/TC-47
#[test]
fn golden_frames_are_the_standards_bits() {
    let p = tc_bytes(&ping());
    let cases = [
        (
            frame(
                0,
                TcContent::Ad {
                    map_id: map0(),
                    data: &p,
                },
            ),
            AD_PING,
            FrameKind::Ad,
        ),
        (
            frame(
                0,
                TcContent::Bd {
                    map_id: map0(),
                    data: &p,
                },
            ),
            BD_PING,
            FrameKind::Bd,
        ),
        (
            frame(0, TcContent::Bc(ControlCommand::Unlock)),
            BC_UNLOCK,
            FrameKind::Bc,
        ),
        (
            frame(0, TcContent::Bc(ControlCommand::SetVr(5))),
            BC_SET_VR_5,
            FrameKind::Bc,
        ),
    ];
    for (r, golden, kind) in cases {
        let bytes = frame_bytes(&r);
        assert_eq!(hex(&bytes), golden, "{r:?}");
        // The FECF by the library's CRC agrees with the hand-computed one.
        let n = bytes.len();
        assert_eq!(pec(&bytes[..n - 2]).to_be_bytes(), bytes[n - 2..]);
        let back = TcFrameRepr::parse(&bytes, &config()).unwrap();
        assert_eq!(back, r);
        assert_eq!(back.kind(), kind);
        let view = TcFrame::new_checked(&bytes[..], &config()).unwrap();
        assert_eq!(view.kind(), kind);
        assert_eq!(view.spacecraft_id().get(), SCID);
        assert_eq!(
            view.fecf(),
            Some(u16::from_be_bytes([bytes[n - 2], bytes[n - 1]]))
        );
        assert_eq!(view.repr(), r);
    }
    let view = TcFrame::new_checked(unhex(AD_PING), &config()).unwrap();
    assert_eq!(view.segment(), Some((0b11, MapId::new(0).unwrap())));
    assert_eq!(view.data(), &p[..]);
    assert_eq!(view.data_field().len(), SEGMENT_HEADER_LEN + p.len());
    assert_eq!(view.control_command(), None);
    assert_eq!(
        view.into_inner(),
        unhex(AD_PING),
        "the buffer back, unchanged"
    );
    let unlock = TcFrame::new_checked(unhex(BC_UNLOCK), &config()).unwrap();
    assert_eq!(unlock.segment(), None);
    assert_eq!(unlock.control_command(), Some(ControlCommand::Unlock));
    assert_eq!(unlock.packets().count(), 0);
}

// req: 232.0-B-4/TC-37, 232.0-B-4/TC-38, 232.0-B-4/TC-39, 232.0-B-4/TC-41, 232.0-B-4/TC-43
// req: 232.0-B-4/TC-44, 232.0-B-4/TC-47, 232.0-B-4/TC-48
#[test]
fn constants_are_the_standards_and_the_missions() {
    assert_eq!(
        (
            TC_PRIMARY_HEADER_LEN,
            SEGMENT_HEADER_LEN,
            FECF_LEN,
            TC_MAX_FRAME_LEN
        ),
        (5, 1, 2, 1024)
    );
    assert_eq!(MAX_FRAME_LEN, 256);
    let c = config();
    assert_eq!((c.fecf, c.max_frame_len, c.vcs.len()), (true, 256, 1));
    assert_eq!(c.vcs[0].vcid.get(), 0);
    assert!(c.vcs[0].segment_header);
    assert_eq!(c.vcs[0].map_ids, 1);
    let board = mmic::units::BoardNumber::new(0xff).unwrap();
    assert_eq!(SpacecraftId::of_board(board).get(), 0x1ff);
}

#[test]
fn n_s_and_every_field_round_trip() {
    let p = tc_bytes(&ping());
    // N(S) 5 changes octet 4 and the FECF only.
    let r = frame(
        5,
        TcContent::Ad {
            map_id: map0(),
            data: &p,
        },
    );
    let b = frame_bytes(&r);
    assert_eq!(hex(&b), "0101001405c01842c00700062f1101000012d05f14");
    // Every spacecraft ID, VCID, MAP ID and N(S) extreme, with matching configurations.
    for scid in [0u16, 0x101, 0x2aa, 0x3ff] {
        for vcid in [0u8, 1, 0x2a, 0x3f] {
            for map in [0u8, 0x15, 0x3f] {
                for seq in [0u8, 1, 0xff] {
                    let vcs = [VcConfig {
                        vcid: Vcid::new(vcid).unwrap(),
                        segment_header: true,
                        map_ids: 1 << map,
                    }];
                    let cfg = TcFrameConfig {
                        spacecraft_id: SpacecraftId::new(scid).unwrap(),
                        vcs: &vcs,
                        fecf: true,
                        max_frame_len: TC_MAX_FRAME_LEN,
                    };
                    let map_id = Some(MapId::new(map).unwrap());
                    for content in [
                        TcContent::Ad { map_id, data: &p },
                        TcContent::Bd { map_id, data: &p },
                        TcContent::Bc(ControlCommand::Unlock),
                        TcContent::Bc(ControlCommand::SetVr(seq)),
                    ] {
                        let r = TcFrameRepr {
                            spacecraft_id: cfg.spacecraft_id,
                            vcid: vcs[0].vcid,
                            seq,
                            content,
                        };
                        let b = frame_bytes(&r);
                        assert_eq!(TcFrameRepr::parse(&b, &cfg), Ok(r));
                    }
                }
            }
        }
    }
}

#[test]
fn without_segment_header_or_fecf() {
    let p = tc_bytes(&ping());
    let vcs = [VcConfig {
        vcid: Vcid::new(3).unwrap(),
        segment_header: false,
        map_ids: 0,
    }];
    let cfg = TcFrameConfig {
        spacecraft_id: SpacecraftId::new(SCID).unwrap(),
        vcs: &vcs,
        fecf: false,
        max_frame_len: TC_MAX_FRAME_LEN,
    };
    let r = TcFrameRepr {
        spacecraft_id: cfg.spacecraft_id,
        vcid: vcs[0].vcid,
        seq: 9,
        content: TcContent::Ad {
            map_id: None,
            data: &p,
        },
    };
    let mut buf = [0u8; 64];
    let n = r.emit_with(false, &mut buf).unwrap();
    assert_eq!(n, 5 + 13);
    assert_eq!(n, r.len_with(false));
    // octet 2: VCID 3 = 000011, length 17 -> 0000_1100 = 0x0c, octet 3 = 0x11.
    assert_eq!(buf[..5], [0x01, 0x01, 0x0c, 0x11, 0x09]);
    assert_eq!(TcFrameRepr::parse(&buf[..n], &cfg), Ok(r));
    let view = TcFrame::new_checked(&buf[..n], &cfg).unwrap();
    assert_eq!((view.fecf(), view.segment()), (None, None));
}

#[test]
fn emit_refuses_what_does_not_fit() {
    let big = [0u8; 1100];
    let r = frame(
        0,
        TcContent::Ad {
            map_id: map0(),
            data: &big[..1016],
        },
    );
    let mut buf = [0u8; 1100];
    assert_eq!(r.emit(&mut buf), Ok(1024));
    let r = frame(
        0,
        TcContent::Ad {
            map_id: map0(),
            data: &big[..1017],
        },
    );
    assert_eq!(
        r.emit(&mut buf),
        Err(TcEmitError::FrameTooLong {
            max: 1024,
            found: 1025
        })
    );
    let r = frame(0, TcContent::Bc(ControlCommand::SetVr(1)));
    assert_eq!(
        r.emit(&mut buf[..9]),
        Err(TcEmitError::BufferTooSmall {
            expected: 10,
            found: 9
        })
    );
}

/// One refused frame per check, each one defect away from a golden frame (the length field
/// and FECF rewritten, so that each reaches its own check), with the exact error.
// req: 232.0-B-4/TC-32, 232.0-B-4/TC-33
#[test]
fn every_check_refuses_with_its_numbers() {
    let cfg = config();
    let ad = unhex(AD_PING);
    let with = |f: &dyn Fn(&mut Vec<u8>)| {
        let mut b = ad.clone();
        f(&mut b);
        reseal(&mut b);
        b
    };
    let cases: Vec<(Vec<u8>, TcFrameError)> = vec![
        (
            ad[..7].to_vec(),
            TcFrameError::Truncated {
                expected: 8,
                found: 7,
            },
        ),
        (
            with(&|b| b[0] |= 0x40),
            TcFrameError::Version {
                expected: 0,
                found: 1,
            },
        ),
        (
            with(&|b| b[0] |= 0x10),
            TcFrameError::Flags {
                bypass: 0,
                control: 1,
            },
        ),
        (
            with(&|b| b[0] |= 0x08),
            TcFrameError::Spare {
                expected: 0,
                found: 2,
            },
        ),
        (
            {
                let mut b = ad.clone();
                b.push(0);
                b
            },
            TcFrameError::Length {
                expected: 21,
                found: 22,
            },
        ),
        (
            with(&|b| b.splice(6..6, [0u8; 236]).for_each(drop)),
            TcFrameError::TooLong {
                max: 256,
                found: 257,
            },
        ),
        (
            {
                let mut b = ad.clone();
                b[20] ^= 1;
                b
            },
            TcFrameError::Fecf {
                carried: 0x6a5b,
                computed: 0x6a5a,
            },
        ),
        (
            with(&|b| b[1] = 0x02),
            TcFrameError::SpacecraftId {
                expected: 0x101,
                found: 0x102,
            },
        ),
        (with(&|b| b[2] |= 0x04), TcFrameError::Vcid { found: 1 }),
        (
            with(&|b| b[5] = 0x40),
            TcFrameError::SequenceFlags {
                expected: 0b11,
                found: 0b01,
            },
        ),
        (
            with(&|b| b[5] = 0xc1),
            TcFrameError::MapId { vcid: 0, found: 1 },
        ),
        (
            {
                let mut b = unhex(BC_SET_VR_5);
                b[6] = 0x01;
                reseal(&mut b);
                b
            },
            TcFrameError::ControlCommand {
                len: 3,
                head: [0x82, 0x01, 0x05],
            },
        ),
    ];
    let mut seen = Vec::new();
    for (bytes, want) in cases {
        assert_eq!(
            TcFrameRepr::parse(&bytes, &cfg),
            Err(want),
            "{}",
            hex(&bytes)
        );
        assert_eq!(TcFrame::new_checked(&bytes[..], &cfg).err(), Some(want));
        seen.push(want.name());
    }
    // Every check but the packets' (below) in order.
    assert_eq!(seen, TcFrameError::NAMES[..12]);
    // Other control commands: empty is too short for any frame; these are refused by name.
    for field in [
        &[0x01][..],
        &[0x82, 0x00],
        &[0x00, 0x00],
        &[0x82, 0x00, 0x05, 0x00],
    ] {
        let mut b = vec![0x31, 0x01, 0, 0, 0];
        b.extend_from_slice(field);
        b.extend_from_slice(&[0, 0]);
        reseal(&mut b);
        let e = TcFrameRepr::parse(&b, &cfg).unwrap_err();
        assert_eq!(e.name(), "control-command", "{}", hex(&b));
    }
    assert_eq!(
        ControlCommand::parse(&[]),
        Err(TcFrameError::ControlCommand {
            len: 0,
            head: [0; 3]
        })
    );
}

// req: 232.0-B-4/TC-1, 232.0-B-4/TC-5, 232.0-B-4/TC-24, 232.0-B-4/TC-30
#[test]
fn the_packets_of_a_data_field() {
    let p = tc_bytes(&ping());
    let mut two = p.clone();
    two.extend_from_slice(&p);
    let r = frame(
        1,
        TcContent::Ad {
            map_id: map0(),
            data: &two,
        },
    );
    let b = frame_bytes(&r);
    let view = TcFrame::new_checked(&b[..], &config()).unwrap();
    let got: Vec<_> = view.packets().collect();
    assert_eq!(got, vec![Ok(&p[..]), Ok(&p[..])]);
    // A packet cut short, and a header cut short: refused by name, once, then the end.
    let cut = &two[..20];
    let got: Vec<_> = Packets::new(cut).collect();
    assert_eq!(
        got,
        vec![
            Ok(&p[..]),
            Err(TcFrameError::PacketBoundary {
                at: 13,
                needed: 13,
                left: 7
            })
        ]
    );
    let got: Vec<_> = Packets::new(&two[..17]).collect();
    assert_eq!(
        got[1],
        Err(TcFrameError::PacketBoundary {
            at: 13,
            needed: 6,
            left: 4
        })
    );
    assert_eq!(got[1].unwrap_err().name(), "packet-boundary");
    assert_eq!(Packets::new(&[]).count(), 0);
}

// ---- Every 1-, 2- and 3-bit error of the reference AD frame ----

/// The heaviest error weight flipped: 3, or 1 under Miri.
const MAX_WEIGHT: u64 = if cfg!(miri) { 1 } else { 3 };

fn choose(n: u64, k: u64) -> u64 {
    (0..k).fold(1, |acc, i| acc * (n - i) / (i + 1))
}

/// The refusal predicted for an error flipping `bits` of [`AD_PING`] (0 = most significant bit
/// of octet 0). The fixed-value fields before the FECF check: version (bits 0-1), the flags
/// (bits 2-3: only control 1 with bypass 0 is no frame type, so only a flip of bit 3 without
/// bit 2 is refused there; a flip of bit 2, or of both, makes a BD or BC frame that the FECF
/// refuses), the spare (bits 4-5) and the frame length (bits 22-31). Everything else (the
/// spacecraft ID, VCID, N(S), segment header, packet, FECF) is the FECF's: CRC-16/CCITT-FALSE
/// has Hamming distance 4 at this length, and the addressing and segment checks run after it.
fn predicted(bits: &[usize]) -> &'static str {
    let has = |b: usize| bits.contains(&b);
    if has(0) || has(1) {
        "version"
    } else if has(3) && !has(2) {
        "flags"
    } else if has(4) || has(5) {
        "spare"
    } else if bits.iter().any(|b| (22..=31).contains(b)) {
        "length"
    } else {
        "fecf"
    }
}

fn flip(bytes: &mut [u8], bit: usize) {
    bytes[bit / 8] ^= 0x80 >> (bit % 8);
}

#[test]
fn every_1_2_3_bit_error_of_a_tc_frame_is_refused() {
    let t = std::time::Instant::now();
    let cfg = config();
    let frame = unhex(AD_PING);
    assert!(TcFrameRepr::parse(&frame, &cfg).is_ok());
    let n = frame.len() * 8;
    let mut buf = frame.clone();
    let mut tally: BTreeMap<&str, u64> = BTreeMap::new();
    let mut judge = |buf: &[u8], bits: &[usize]| {
        let e = TcFrameRepr::parse(buf, &cfg).expect_err("a corrupted frame was accepted");
        assert_eq!(e.name(), predicted(bits), "bits {bits:?}: {e}");
        *tally.entry(e.name()).or_insert(0) += 1;
    };
    for i in 0..n {
        flip(&mut buf, i);
        judge(&buf, &[i]);
        for j in (i + 1..n).filter(|_| MAX_WEIGHT >= 2) {
            flip(&mut buf, j);
            judge(&buf, &[i, j]);
            for k in (j + 1..n).filter(|_| MAX_WEIGHT >= 3) {
                flip(&mut buf, k);
                judge(&buf, &[i, j, k]);
                flip(&mut buf, k);
            }
            flip(&mut buf, j);
        }
        flip(&mut buf, i);
    }
    assert_eq!(buf, frame);
    let total: u64 = tally.values().sum();
    println!(
        "TC frame, {n} bits: {total} corruptions in {:.2?}: {tally:?}",
        t.elapsed()
    );
    // C(168,1) + C(168,2) + C(168,3) = 168 + 14,028 + 776,216.
    assert_eq!(total, if cfg!(miri) { 168 } else { 790_412 });
    assert_eq!(total, (1..=MAX_WEIGHT).map(|w| choose(168, w)).sum::<u64>());
    // No corruption reaches the addressing or content checks: all are corruption.
    for name in [
        "spacecraft-id",
        "vcid",
        "sequence-flags",
        "map-id",
        "control-command",
    ] {
        assert!(!tally.contains_key(name), "{name}");
    }
}

// ---- Property: any frame round-trips (proptest, the strategies of mmic::arbitrary) ----

use proptest::prelude::*;

proptest! {
    #![proptest_config(crate::common::prop::config(512))]

    /// Any frame (any spacecraft ID, VCID, N(S), AD/BD with or without a segment header and
    /// 0..=64 octets of data, BC with any control command) emits and parses back to itself on
    /// a channel that agrees with it, with or without the FECF.
    #[test]
    fn any_frame_round_trips(
        spacecraft_id in any::<SpacecraftId>(),
        vcid in any::<Vcid>(),
        seq in any::<u8>(),
        kind in any::<FrameKind>(),
        map_id in proptest::option::of(any::<MapId>()),
        data in proptest::collection::vec(any::<u8>(), 1..64),
        command in any::<ControlCommand>(),
        fecf in any::<bool>(),
    ) {
        let content = match kind {
            FrameKind::Ad => TcContent::Ad { map_id, data: &data },
            FrameKind::Bd => TcContent::Bd { map_id, data: &data },
            FrameKind::Bc => TcContent::Bc(command),
        };
        let r = TcFrameRepr { spacecraft_id, vcid, seq, content };
        let vcs = [VcConfig {
            vcid,
            segment_header: map_id.is_some(),
            map_ids: map_id.map_or(0, |m| 1 << m.get()),
        }];
        let cfg = TcFrameConfig { spacecraft_id, vcs: &vcs, fecf, max_frame_len: TC_MAX_FRAME_LEN };
        let mut buf = [0u8; 128];
        let n = r.emit_with(fecf, &mut buf).unwrap();
        prop_assert_eq!(n, r.len_with(fecf));
        prop_assert_eq!(TcFrameRepr::parse(&buf[..n], &cfg), Ok(r));
        prop_assert_eq!(TcFrame::new_checked(&buf[..n], &cfg).unwrap().kind(), kind);
    }
}
