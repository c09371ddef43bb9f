//! TM transfer frames (CCSDS 132.0-B-3 §4.1): golden frames checked by hand, round trips, and
//! every check of `TmFrameError` refused by name. The FECFs were computed with a bitwise
//! CRC-16/CCITT-FALSE written from the definition (poly 0x1021, init 0xffff), independently of
//! the library.

use super::{alive, tm_bytes};
use mmic::link::tm_frame::{
    FirstHeaderPointer, TmEmitError, TmFrame, TmFrameError, TmFrameParams, TmFrameRepr,
    TM_DATA_LEN, TM_FRAME_LEN,
};

/// Robot 0x42's spacecraft ID (`spec/ccsds/link.toml`: 0x100 + n).
pub const SCID: u16 = 0x142;

/// The mission's parameters for [`SCID`].
pub fn params() -> TmFrameParams {
    TmFrameParams::mission(SCID).unwrap()
}

/// The CLCW of the reference frame: control word type 0, version 00, status 000, COP in
/// effect 01; VC 0; no flags; report value 0.
pub const CLCW: [u8; 4] = [0x01, 0x00, 0x00, 0x00];

/// The reference frame's data field: TM(17,2) (21 octets), then a 223-octet idle packet.
pub fn reference_data() -> Vec<u8> {
    let mut d = tm_bytes(&alive());
    assert_eq!(d.len(), 21);
    // APID 0x7FF, type TM, no secondary header; unsegmented, count 0; 223 - 7 = 216 = 0xd8.
    d.extend([0x07, 0xff, 0xc0, 0x00, 0x00, 0xd8]);
    d.extend([0x55; 223 - 6]);
    assert_eq!(d.len(), TM_DATA_LEN);
    d
}

/// The reference frame of `spec/ccsds/bad-inputs.toml`'s `tm-frame` rows: spacecraft 0x142,
/// VC 0, counts 0x12/0x34, first header pointer 0, [`reference_data`], [`CLCW`].
pub fn reference_frame() -> Vec<u8> {
    let data = reference_data();
    let repr = TmFrameRepr {
        spacecraft_id: SCID,
        vcid: 0,
        mc_frame_count: 0x12,
        vc_frame_count: 0x34,
        first_header_pointer: FirstHeaderPointer::Packet(0),
        data: &data,
        ocf: Some(CLCW),
    };
    let mut out = vec![0u8; TM_FRAME_LEN];
    assert_eq!(repr.emit(&params(), &mut out), Ok(TM_FRAME_LEN));
    out
}

// req: 132.0-B-3/TM-4, 132.0-B-3/TM-5, 132.0-B-3/TM-7, 132.0-B-3/TM-19, 132.0-B-3/TM-20
// req: 132.0-B-3/TM-50, 132.0-B-3/TM-51, 132.0-B-3/TM-53, 132.0-B-3/TM-54, 132.0-B-3/TM-55
// req: 132.0-B-3/TM-61, 132.0-B-3/TM-69, 132.0-B-3/TM-70, 132.0-B-3/TM-73, 132.0-B-3/TM-74
// req: 132.0-B-3/TM-75, 132.0-B-3/TM-77, 132.0-B-3/TM-79, 132.0-B-3/TM-80, 132.0-B-3/TM-81
// req: 132.0-B-3/TM-82, 132.0-B-3/TM-83, 132.0-B-3/TM-85
#[test]
#[allow(clippy::unusual_byte_groupings)] // grouped as the header's fields
fn reference_frame_bit_by_bit() {
    let f = reference_frame();
    #[rustfmt::skip]
    let header = [
        // 00 version | spacecraft ID 01 0100 0010 (0x142) | VCID 000 | OCF flag 1
        //   = 0001 0100 0010 0001
        0b00_010100, 0b0010_000_1,
        0x12, // master channel frame count
        0x34, // virtual channel frame count
        // 0 no secondary header | 0 synch | 0 packet order | 11 segment length ID |
        // first header pointer 000 0000 0000
        0b0_0_0_11_000, 0x00,
    ];
    assert_eq!(f[..6], header);
    assert_eq!(f[6..250], reference_data()[..]);
    assert_eq!(f[250..254], CLCW); // OCF: 6 + 244 = 250
    assert_eq!(f[254..], [0x17, 0x46]); // FECF over octets 0..254, high octet first
    let r = TmFrameRepr::parse(&f, &params()).unwrap();
    assert_eq!(r.first_header_pointer, FirstHeaderPointer::Packet(0));
    assert_eq!((r.mc_frame_count, r.vc_frame_count), (0x12, 0x34));
}

// req: 132.0-B-3/TM-53, 132.0-B-3/TM-56
#[test]
fn continuation_and_idle_frames_bit_by_bit() {
    // No packet starts: FHP 0x7FF, 000 11 111 1111 1111 = 0x1fff; counts 0xff / 0x00.
    let data = [0xaa; TM_DATA_LEN];
    let ocf = [0x01, 0x00, 0x84, 0x07];
    let repr = TmFrameRepr {
        spacecraft_id: SCID,
        vcid: 0,
        mc_frame_count: 0xff,
        vc_frame_count: 0x00,
        first_header_pointer: FirstHeaderPointer::NoPacketStart,
        data: &data,
        ocf: Some(ocf),
    };
    let mut f = [0u8; TM_FRAME_LEN];
    repr.emit(&params(), &mut f).unwrap();
    assert_eq!(f[..6], [0x14, 0x21, 0xff, 0x00, 0x1f, 0xff]);
    assert_eq!(f[250..], [0x01, 0x00, 0x84, 0x07, 0x12, 0x85]);
    assert_eq!(TmFrameRepr::parse(&f, &params()), Ok(repr));

    // Only idle data: FHP 0x7FE = 0x1ffe.
    let data = [0x55; TM_DATA_LEN];
    let repr = TmFrameRepr {
        mc_frame_count: 0,
        vc_frame_count: 0,
        first_header_pointer: FirstHeaderPointer::OnlyIdleData,
        data: &data,
        ocf: Some(CLCW),
        ..repr
    };
    repr.emit(&params(), &mut f).unwrap();
    assert_eq!(f[..6], [0x14, 0x21, 0x00, 0x00, 0x1f, 0xfe]);
    assert_eq!(f[254..], [0xa7, 0x24]);
    assert_eq!(TmFrameRepr::parse(&f, &params()), Ok(repr));
}

// req: 132.0-B-3/TM-41, 132.0-B-3/TM-51
#[test]
fn the_view_reads_every_field() {
    let f = reference_frame();
    let v = TmFrame::new_checked(&f, &params()).unwrap();
    assert_eq!((v.spacecraft_id(), v.vcid()), (SCID, 0));
    assert_eq!((v.mc_frame_count(), v.vc_frame_count()), (0x12, 0x34));
    assert_eq!(v.data(), &reference_data()[..]);
    assert_eq!(v.ocf(), Some(CLCW));
    assert_eq!(v.as_bytes(), &f[..]);
}

#[test]
#[cfg_attr(
    miri,
    ignore = "1,534 frames through the CRC: minutes under Miri (the golden frames run)"
)]
fn round_trips_over_every_field_value() {
    // Every spacecraft ID, VCID, count value and first header pointer, each with the others at
    // the reference's: emit → parse gives the repr back (parsed with the repr's own IDs).
    let data = reference_data();
    let frame = reference_frame();
    let base = TmFrameRepr::parse(&frame, &params()).unwrap();
    let mut out = [0u8; TM_FRAME_LEN];
    let mut n = 0;
    let mut check = |r: TmFrameRepr| {
        let p = TmFrameParams::new(TM_FRAME_LEN, r.spacecraft_id, r.vcid, true, true).unwrap();
        assert_eq!(r.emit(&p, &mut out), Ok(TM_FRAME_LEN));
        assert_eq!(TmFrameRepr::parse(&out, &p), Ok(r), "{r:?}");
        n += 1;
    };
    for s in 0..=0x3ff {
        check(TmFrameRepr {
            spacecraft_id: s,
            ..base
        });
    }
    for v in 0..=7 {
        check(TmFrameRepr { vcid: v, ..base });
    }
    for c in 0..=255 {
        check(TmFrameRepr {
            mc_frame_count: c,
            vc_frame_count: 255 - c,
            ..base
        });
    }
    for p in 0..TM_DATA_LEN as u16 {
        check(TmFrameRepr {
            first_header_pointer: FirstHeaderPointer::Packet(p),
            ..base
        });
    }
    for fhp in [
        FirstHeaderPointer::NoPacketStart,
        FirstHeaderPointer::OnlyIdleData,
    ] {
        check(TmFrameRepr {
            first_header_pointer: fhp,
            data: &data,
            ..base
        });
    }
    assert_eq!(n, 1024 + 8 + 256 + 244 + 2);
}

#[test]
fn other_frame_lengths_and_no_ocf_or_fecf() {
    // A 16-octet frame without OCF or FECF: a 10-octet data field.
    let p = TmFrameParams::new(16, 0x3ff, 7, false, false).unwrap();
    assert_eq!(p.data_len(), 10);
    let data = [1, 2, 3, 4, 5, 6, 7, 8, 9, 10];
    let r = TmFrameRepr {
        spacecraft_id: 0x3ff,
        vcid: 7,
        mc_frame_count: 1,
        vc_frame_count: 2,
        first_header_pointer: FirstHeaderPointer::Packet(9),
        data: &data,
        ocf: None,
    };
    let mut out = [0u8; 16];
    assert_eq!(r.emit(&p, &mut out), Ok(16));
    // 00 11 1111 1111 111 0 = 0x3ffe; status 0x1809.
    assert_eq!(out[..6], [0x3f, 0xfe, 1, 2, 0x18, 0x09]);
    assert_eq!(TmFrameRepr::parse(&out, &p), Ok(r));
    // FHP 10 is outside the 10-octet data field.
    let mut bad = out;
    bad[5] = 10;
    assert_eq!(
        TmFrameRepr::parse(&bad, &p),
        Err(TmFrameError::FirstHeaderPointer {
            data_len: 10,
            found: 10
        })
    );
}

#[test]
fn emit_refuses_what_the_frame_cannot_carry() {
    let data = reference_data();
    let frame = reference_frame();
    let base = TmFrameRepr::parse(&frame, &params()).unwrap();
    let mut out = [0u8; TM_FRAME_LEN];
    let p = params();
    assert_eq!(
        base.emit(&p, &mut out[..255]),
        Err(TmEmitError::BufferTooSmall {
            expected: 256,
            found: 255
        })
    );
    assert_eq!(
        TmFrameRepr {
            data: &data[1..],
            ..base
        }
        .emit(&p, &mut out),
        Err(TmEmitError::DataLength {
            expected: 244,
            found: 243
        })
    );
    assert_eq!(
        TmFrameRepr { ocf: None, ..base }.emit(&p, &mut out),
        Err(TmEmitError::Ocf {
            expected: true,
            found: false
        })
    );
    for (r, field) in [
        (
            TmFrameRepr {
                spacecraft_id: 0x400,
                ..base
            },
            "spacecraft ID",
        ),
        (TmFrameRepr { vcid: 8, ..base }, "VCID"),
        (
            TmFrameRepr {
                first_header_pointer: FirstHeaderPointer::Packet(244),
                ..base
            },
            "first header pointer",
        ),
    ] {
        assert!(
            matches!(r.emit(&p, &mut out), Err(TmEmitError::Field { field: f, .. }) if f == field)
        );
    }
}

/// `bytes` with its FECF rewritten.
fn reseal(mut bytes: Vec<u8>) -> Vec<u8> {
    let n = bytes.len();
    let crc = mmic::ccsds::pec(&bytes[..n - 2]);
    bytes[n - 2..].copy_from_slice(&crc.to_be_bytes());
    bytes
}

// req: 132.0-B-3/TM-63, 132.0-B-3/TM-64, 132.0-B-3/TM-67
#[test]
fn every_check_refuses_with_its_numbers() {
    let good = reference_frame();
    let p = params();
    let with = |at: usize, v: u8| {
        let mut b = good.clone();
        b[at] = v;
        reseal(b)
    };
    let cases: Vec<(Vec<u8>, TmFrameError)> = vec![
        (
            good[..255].to_vec(),
            TmFrameError::Length {
                expected: 256,
                found: 255,
            },
        ),
        (
            [good.clone(), vec![0]].concat(),
            TmFrameError::Length {
                expected: 256,
                found: 257,
            },
        ),
        (
            vec![],
            TmFrameError::Length {
                expected: 256,
                found: 0,
            },
        ),
        (
            with(0, 0xd4),
            TmFrameError::Version {
                expected: 0,
                found: 3,
            },
        ),
        (with(4, 0x98), TmFrameError::SecondaryHeaderFlag),
        (
            with(1, 0x20),
            TmFrameError::OcfFlag {
                expected: true,
                found: false,
            },
        ),
        (
            {
                let mut b = good.clone();
                b[100] ^= 1;
                b
            },
            TmFrameError::Fecf {
                carried: 0x1746,
                computed: mmic::ccsds::pec(
                    &{
                        let mut b = good.clone();
                        b[100] ^= 1;
                        b
                    }[..254],
                ),
            },
        ),
        (
            with(1, 0x31),
            TmFrameError::SpacecraftId {
                expected: 0x142,
                found: 0x143,
            },
        ),
        (
            with(1, 0x2f),
            TmFrameError::Vcid {
                expected: 0,
                found: 7,
            },
        ),
        (with(4, 0x58), TmFrameError::SynchFlag),
        (with(4, 0x38), TmFrameError::PacketOrderFlag),
        (
            with(4, 0x00),
            TmFrameError::SegmentLengthId {
                expected: 3,
                found: 0,
            },
        ),
        (
            with(5, 244),
            TmFrameError::FirstHeaderPointer {
                data_len: 244,
                found: 244,
            },
        ),
        (
            with(4, 0x1f),
            TmFrameError::FirstHeaderPointer {
                data_len: 244,
                found: 0x700,
            },
        ),
    ];
    let mut seen = std::collections::BTreeSet::new();
    for (bytes, e) in cases {
        assert_eq!(TmFrameRepr::parse(&bytes, &p), Err(e));
        assert_eq!(TmFrameError::NAMES[e.position()], e.name());
        assert!(!e.to_string().is_empty());
        seen.insert(e.name());
    }
    assert_eq!(seen.len(), TmFrameError::NAMES.len());
    // 0x7FE and 0x7FF pass the pointer check.
    let mut b = good.clone();
    b[4] = 0x1f;
    b[5] = 0xfe;
    assert!(TmFrameRepr::parse(&reseal(b.clone()), &p).is_ok());
    b[5] = 0xff;
    assert!(TmFrameRepr::parse(&reseal(b), &p).is_ok());
}

#[test]
fn the_first_failing_check_is_the_error() {
    // Defects in two fields: the earlier check in NAMES wins, whatever the bit order.
    let good = reference_frame();
    let mut b = good.clone();
    b[1] = 0x31; // spacecraft 0x143 (check 5)
    b[4] = 0x58; // synch flag (check 7)
    b[0] |= 0x40; // version 1 (check 1)
    let b = reseal(b);
    assert_eq!(
        TmFrameRepr::parse(&b, &params()).unwrap_err().name(),
        "version"
    );
    let mut b2 = b.clone();
    b2[0] &= !0x40;
    let b2 = reseal(b2);
    assert_eq!(
        TmFrameRepr::parse(&b2, &params()).unwrap_err().name(),
        "spacecraft-id"
    );
}
