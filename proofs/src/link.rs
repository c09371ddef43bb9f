//! Properties of the TC transfer frame (`mmic::link::tc_frame`), shared by the harnesses of
//! `tests/harnesses/link_tc.rs` and the fuzz target `tc_frame_parser`.
//!
//! The oracle, [`tc_frame_oracle`], is written from the bit positions of CCSDS 232.0-B-4 §4.1
//! and the documented check order (truncated → version → flags → spare → length → too-long →
//! fecf → spacecraft-id → vcid → sequence-flags → map-id → control-command), on raw octets and
//! with the bitwise CRC [`crate::crc16_bitwise`], sharing no code with the library's parser;
//! [`oracle_packets`] splits a data field into packets by octets 4–5 of each packet.
//!
//! ```
//! use mmic_proofs::link::{check_tc_frame_parse, tc_frame_oracle, CONFIGS};
//!
//! let ad = [
//!     0x01, 0x01, 0x00, 0x14, 0x00, 0xc0, 0x18, 0x42, 0xc0, 0x07, 0x00, 0x06, 0x2f, 0x11, 0x01,
//!     0x00, 0x00, 0x12, 0xd0, 0x6a, 0x5a,
//! ];
//! assert!(tc_frame_oracle(&ad, &CONFIGS[0]).is_ok());
//! assert!(check_tc_frame_parse(&ad)); // accepted with CONFIGS[0], re-emitted identically
//! ```

use crate::{crc16_bitwise, Seed};
use mmic::link::tc_frame::{
    MapId, SpacecraftId, TcContent, TcFrame, TcFrameConfig, TcFrameError, TcFrameRepr, VcConfig,
    Vcid,
};
use mmic::link::{ControlCommand, FrameKind};

/// Longest input the parse properties take (and frame they emit into their buffers).
pub const MAX_FRAME: usize = 1024;

/// The virtual channels of the harnesses' channel: VC 0 with a segment header and MAPs 0 and
/// 63, VC 1 without one, VC 63 with one and every MAP.
pub const VCS: [VcConfig; 3] = [
    VcConfig {
        vcid: match Vcid::new(0) {
            Ok(v) => v,
            Err(_) => panic!(),
        },
        segment_header: true,
        map_ids: 1 | 1 << 63,
    },
    VcConfig {
        vcid: match Vcid::new(1) {
            Ok(v) => v,
            Err(_) => panic!(),
        },
        segment_header: false,
        map_ids: 0,
    },
    VcConfig {
        vcid: match Vcid::new(63) {
            Ok(v) => v,
            Err(_) => panic!(),
        },
        segment_header: true,
        map_ids: u64::MAX,
    },
];

const SCID: SpacecraftId = match SpacecraftId::new(0x101) {
    Ok(s) => s,
    Err(_) => panic!(),
};

/// The two channels the parse properties check every input against: with the FECF and
/// frames of at most 64 octets (so that inputs of up to 80 reach `too-long`), and without the
/// FECF (so that random octets reach the addressing and content checks).
pub const CONFIGS: [TcFrameConfig<'static>; 2] = [
    TcFrameConfig {
        spacecraft_id: SCID,
        vcs: &VCS,
        fecf: true,
        max_frame_len: 64,
    },
    TcFrameConfig {
        spacecraft_id: SCID,
        vcs: &VCS,
        fecf: false,
        max_frame_len: 1024,
    },
];

/// An accepted frame as the oracle reads it.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct OracleFrame {
    /// From bits 2–3.
    pub kind: FrameKind,
    /// Bits 6–15.
    pub spacecraft_id: u16,
    /// Bits 16–21.
    pub vcid: u8,
    /// Octet 4.
    pub seq: u8,
    /// The segment header's MAP ID, if the frame has one.
    pub map_id: Option<u8>,
    /// Where the data (after the segment header) starts and ends.
    pub data: (usize, usize),
    /// A BC frame's command.
    pub control: Option<ControlCommand>,
}

/// The verdict the documented checks give `b` as a TC frame of the channel `cfg`, worked out
/// from the bit positions of CCSDS 232.0-B-4 §4.1.2.
pub fn tc_frame_oracle(b: &[u8], cfg: &TcFrameConfig<'_>) -> Result<OracleFrame, TcFrameError> {
    let n = b.len();
    let f = if cfg.fecf { 2 } else { 0 };
    if n < 5 + 1 + f {
        return Err(TcFrameError::Truncated {
            expected: 5 + 1 + f,
            found: n,
        });
    }
    if b[0] >> 6 != 0 {
        return Err(TcFrameError::Version {
            expected: 0,
            found: b[0] >> 6,
        });
    }
    let (bypass, control) = ((b[0] >> 5) & 1, (b[0] >> 4) & 1);
    let kind = match (bypass, control) {
        (0, 0) => FrameKind::Ad,
        (1, 0) => FrameKind::Bd,
        (1, 1) => FrameKind::Bc,
        _ => return Err(TcFrameError::Flags { bypass, control }),
    };
    if (b[0] >> 2) & 3 != 0 {
        return Err(TcFrameError::Spare {
            expected: 0,
            found: (b[0] >> 2) & 3,
        });
    }
    let declared = (((b[2] & 3) as usize) << 8 | b[3] as usize) + 1;
    if declared != n {
        return Err(TcFrameError::Length {
            expected: declared,
            found: n,
        });
    }
    let max = if cfg.max_frame_len < 1024 {
        cfg.max_frame_len
    } else {
        1024
    };
    if n > max {
        return Err(TcFrameError::TooLong { max, found: n });
    }
    if cfg.fecf {
        let carried = (b[n - 2] as u16) << 8 | b[n - 1] as u16;
        let computed = crc16_bitwise(&b[..n - 2]);
        if carried != computed {
            return Err(TcFrameError::Fecf { carried, computed });
        }
    }
    let scid = ((b[0] & 3) as u16) << 8 | b[1] as u16;
    if scid != cfg.spacecraft_id.get() {
        return Err(TcFrameError::SpacecraftId {
            expected: cfg.spacecraft_id.get(),
            found: scid,
        });
    }
    let vcid = b[2] >> 2;
    let mut vc = None;
    for v in cfg.vcs {
        if v.vcid.get() == vcid {
            vc = Some(*v);
            break;
        }
    }
    let Some(vc) = vc else {
        return Err(TcFrameError::Vcid { found: vcid });
    };
    let field = (5, n - f);
    let mut out = OracleFrame {
        kind,
        spacecraft_id: scid,
        vcid,
        seq: b[4],
        map_id: None,
        data: field,
        control: None,
    };
    if kind == FrameKind::Bc {
        let d = &b[field.0..field.1];
        out.control = Some(if d.len() == 1 && d[0] == 0 {
            ControlCommand::Unlock
        } else if d.len() == 3 && d[0] == 0x82 && d[1] == 0 {
            ControlCommand::SetVr(d[2])
        } else {
            let mut head = [0u8; 3];
            let k = d.len().min(3);
            head[..k].copy_from_slice(&d[..k]);
            return Err(TcFrameError::ControlCommand { len: d.len(), head });
        });
    } else if vc.segment_header {
        let s = b[5];
        if s >> 6 != 3 {
            return Err(TcFrameError::SequenceFlags {
                expected: 3,
                found: s >> 6,
            });
        }
        let map = s & 0x3f;
        if (vc.map_ids >> map) & 1 == 0 {
            return Err(TcFrameError::MapId { vcid, found: map });
        }
        out.map_id = Some(map);
        out.data = (6, n - f);
    }
    Ok(out)
}

/// The packets of an AD or BD frame's data by the oracle: the number of whole packets, each
/// `((octet 4 << 8) | octet 5) + 7` octets long, or the boundary error.
pub fn oracle_packets(data: &[u8]) -> Result<usize, TcFrameError> {
    let (mut at, mut count) = (0, 0);
    while at < data.len() {
        let left = data.len() - at;
        if left < 6 {
            return Err(TcFrameError::PacketBoundary {
                at,
                needed: 6,
                left,
            });
        }
        let len = ((data[at + 4] as usize) << 8 | data[at + 5] as usize) + 7;
        if len > left {
            return Err(TcFrameError::PacketBoundary {
                at,
                needed: len,
                left,
            });
        }
        at += len;
        count += 1;
    }
    Ok(count)
}

/// Writes the frame length field for the frame's length and, with `fecf`, the FECF over the
/// rest (bitwise), leaving every other octet as it is. `frame` must be 4..=1024 octets long
/// (at least 6 with `fecf`).
pub fn reseal(frame: &mut [u8], fecf: bool) {
    let n = frame.len();
    let l = (n - 1) as u16;
    frame[2] = (frame[2] & 0xfc) | (l >> 8) as u8 & 3;
    frame[3] = l as u8;
    if fecf {
        let crc = crc16_bitwise(&frame[..n - 2]);
        frame[n - 2..].copy_from_slice(&crc.to_be_bytes());
    }
}

/// Parses `bytes` with `cfg` and asserts the oracle's verdict, exactly (check and numbers).
/// When accepted: the checked view and the `Repr` agree with the oracle's reading, the data's
/// packets are split as the oracle splits them, and emitting the `Repr` gives `bytes` back
/// (parse → emit identity). Returns whether it was accepted.
pub fn check_tc_frame_parse_with(bytes: &[u8], cfg: &TcFrameConfig<'_>) -> bool {
    check_tc_frame_verdict(bytes, cfg).is_none()
}

/// [`check_tc_frame_parse_with`], returning the refusing check's name (`None`: accepted), so
/// that the harnesses can count which checks their inputs reach.
pub fn check_tc_frame_verdict(bytes: &[u8], cfg: &TcFrameConfig<'_>) -> Option<&'static str> {
    assert!(
        bytes.len() <= MAX_FRAME,
        "inputs are at most MAX_FRAME octets"
    );
    let expected = tc_frame_oracle(bytes, cfg);
    let got = TcFrameRepr::parse(bytes, cfg);
    let view = TcFrame::new_checked(bytes, cfg);
    match (got, expected) {
        (Ok(r), Ok(o)) => {
            let view = view.expect("the view accepts what the Repr accepts");
            assert_eq!(view.repr(), r);
            assert_eq!(r.kind(), o.kind);
            assert_eq!(r.spacecraft_id.get(), o.spacecraft_id);
            assert_eq!(r.vcid.get(), o.vcid);
            assert_eq!(r.seq, o.seq);
            assert_eq!(view.map_id().map(MapId::get), o.map_id);
            let odata = &bytes[o.data.0..o.data.1];
            match r.content {
                TcContent::Ad { data, .. } | TcContent::Bd { data, .. } => {
                    assert_eq!(data, odata);
                    let split = view.packets().try_fold(0, |c, p| p.map(|_| c + 1));
                    assert_eq!(split, oracle_packets(odata));
                }
                TcContent::Bc(c) => {
                    assert_eq!(Some(c), o.control);
                    assert_eq!(view.packets().count(), 0);
                }
            }
            let mut out = [0u8; MAX_FRAME];
            let n = r
                .emit_with(cfg.fecf, &mut out)
                .expect("an accepted frame fits the buffer it came in");
            assert_eq!(&out[..n], bytes, "parse -> emit is not the identity");
            None
        }
        (got, expected) => {
            assert_eq!(
                got.map(|_| ()),
                expected.map(|_| ()),
                "verdict differs from the oracle"
            );
            assert_eq!(view.err(), got.err());
            got.err().map(|e| e.name())
        }
    }
}

/// [`check_tc_frame_parse_with`] for both [`CONFIGS`]; whether the first accepted.
pub fn check_tc_frame_parse(bytes: &[u8]) -> bool {
    check_tc_frame_verdicts(bytes)[0].is_none()
}

/// [`check_tc_frame_verdict`] for both [`CONFIGS`].
pub fn check_tc_frame_verdicts(bytes: &[u8]) -> [Option<&'static str>; 2] {
    [
        check_tc_frame_verdict(bytes, &CONFIGS[0]),
        check_tc_frame_verdict(bytes, &CONFIGS[1]),
    ]
}

/// A frame built from seed choices (data a prefix of `data`) and the one-VC channel that
/// accepts it: any spacecraft ID, VCID, N(S), kind, MAP (or none), control command, FECF or
/// not.
pub fn sample_tc_frame<'a>(s: &mut Seed<'_>, data: &'a [u8]) -> (TcFrameRepr<'a>, VcConfig, bool) {
    let spacecraft_id = SpacecraftId::new(s.u16() & 0x3ff).expect("10 bits");
    let vcid = Vcid::new(s.u8() & 0x3f).expect("6 bits");
    let seq = s.u8();
    let choice = s.u8();
    let map = s.u8();
    let map_id = match map & 0x80 {
        0 => Some(MapId::new(map & 0x3f).expect("6 bits")),
        _ => None,
    };
    let mut len = s.u8() as usize % (data.len() + 1);
    if map_id.is_none() && len == 0 {
        len = 1.min(data.len()); // the data field holds at least one octet
    }
    let d = &data[..len];
    let v = s.u8();
    let content = match choice % 4 {
        0 => TcContent::Ad { map_id, data: d },
        1 => TcContent::Bd { map_id, data: d },
        2 => TcContent::Bc(ControlCommand::Unlock),
        _ => TcContent::Bc(ControlCommand::SetVr(v)),
    };
    let vc = VcConfig {
        vcid,
        segment_header: map_id.is_some(),
        map_ids: map_id.map_or(0, |m| 1 << m.get()),
    };
    let fecf = s.bool();
    (
        TcFrameRepr {
            spacecraft_id,
            vcid,
            seq,
            content,
        },
        vc,
        fecf,
    )
}

/// Emit → parse: any frame built from `seed` (and a prefix of `data`, which must hold at
/// least one octet) is emitted with the length [`TcFrameRepr::len_with`] says, parses back to
/// itself on the channel built for it, passes [`check_tc_frame_parse_with`], and is refused
/// by the spacecraft ID check on another spacecraft's channel.
pub fn check_tc_frame_round_trip(seed: &[u8], data: &[u8]) {
    let (r, vc, fecf) = sample_tc_frame(&mut Seed::new(seed), data);
    let vcs = [vc];
    let cfg = TcFrameConfig {
        spacecraft_id: r.spacecraft_id,
        vcs: &vcs,
        fecf,
        max_frame_len: MAX_FRAME,
    };
    let mut out = [0u8; MAX_FRAME];
    let n = r.emit_with(fecf, &mut out).expect("fits");
    assert_eq!(n, r.len_with(fecf));
    assert_eq!(TcFrameRepr::parse(&out[..n], &cfg), Ok(r));
    assert!(check_tc_frame_parse_with(&out[..n], &cfg));
    let other = TcFrameConfig {
        spacecraft_id: SpacecraftId::new(r.spacecraft_id.get() ^ 1).expect("10 bits"),
        ..cfg
    };
    assert_eq!(
        TcFrameRepr::parse(&out[..n], &other),
        Err(TcFrameError::SpacecraftId {
            expected: r.spacecraft_id.get() ^ 1,
            found: r.spacecraft_id.get()
        })
    );
}

/// A valid frame built from `seed`, then up to two octets overwritten (`[index, value]`, the
/// index taken modulo the length) and, if `reseal_it`, the length field and FECF rewritten:
/// near misses that reach every check. The verdict must be the oracle's, on the channel built
/// for the sample; returns the refusing check's name (`None`: accepted).
pub fn check_tc_frame_near_valid(
    seed: &[u8],
    data: &[u8],
    edits: &[[u8; 2]],
    reseal_it: bool,
) -> Option<&'static str> {
    let (r, vc, fecf) = sample_tc_frame(&mut Seed::new(seed), data);
    let vcs = [vc];
    let cfg = TcFrameConfig {
        spacecraft_id: r.spacecraft_id,
        vcs: &vcs,
        fecf,
        max_frame_len: MAX_FRAME,
    };
    let mut out = [0u8; MAX_FRAME];
    let n = r.emit_with(fecf, &mut out).expect("fits");
    let frame = &mut out[..n];
    for [at, value] in edits {
        frame[*at as usize % n] = *value;
    }
    if reseal_it {
        reseal(frame, fecf);
    }
    check_tc_frame_verdict(frame, &cfg)
}
