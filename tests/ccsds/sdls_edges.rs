//! SDLS (`mmic::link::sdls`) at the edges the protocol tests do not reach: the accessors, the
//! refusals of a misuse by the shell (a receiver asked to protect, a mask past the security
//! header, an unsegmented or a BC frame), and the counters' refusals of a value out of range.

use mmic::link::sdls::frames::{
    protect_tc, protect_tm, secured_tm_params, verify_tc, verify_tm, TC_MAX_DATA,
};
use mmic::link::sdls::key::Fingerprint;
use mmic::link::sdls::sa::MAX_MASK_LEN;
use mmic::link::sdls::{
    mask, AuthMask, Channel, Iv, Key256, ReplayWindow, Role, SaTable, SdlsError, SdlsRefusal,
    SecurityAssociation, TxCounter, HEADER_LEN, MAC_LEN,
};
use mmic::link::tc_frame::{
    MapId, SpacecraftId, TcContent, TcFrame, TcFrameConfig, TcFrameRepr, VcConfig, Vcid,
    MAX_FRAME_LEN, TC_PRIMARY_HEADER_LEN,
};
use mmic::link::tm_frame::{FirstHeaderPointer, TmFrameParams, TmFrameRepr, PRIMARY_HEADER_LEN};
use mmic::link::ControlCommand;

const CHANNEL: Channel = Channel {
    spacecraft_id: 0x101,
    vcid: 0,
};

fn key() -> Key256 {
    Key256::from_bytes([0x5a; 32])
}

/// A sender of `spi` whose first block of counters is reserved.
fn sender(spi: u16, mask: AuthMask) -> SecurityAssociation {
    let mut c = TxCounter::boot(None, 16);
    assert!(c.persisted(c.due().unwrap()));
    SecurityAssociation::new(spi, key(), CHANNEL, mask, Role::Send(c))
}

/// A receiver of `spi` whose window's floor is 8 past `last`.
fn receiver(spi: u16, last: u128) -> SecurityAssociation {
    let mut w = ReplayWindow::boot(Some(last), 64, 16);
    assert!(w.persisted(last + 8));
    SecurityAssociation::new(spi, key(), CHANNEL, mask::TC, Role::Receive(w))
}

/// A new receiver of `spi` (no frame seen yet) under `mask`, its first block reserved.
fn fresh_receiver(spi: u16, mask: AuthMask) -> SecurityAssociation {
    let mut w = ReplayWindow::boot(None, 64, 16);
    assert!(w.persisted(w.due().unwrap()));
    SecurityAssociation::new(spi, key(), CHANNEL, mask, Role::Receive(w))
}

/// An IV is below 2^96; its octets are the low 12 of the number.
#[test]
fn iv_out_of_range_and_its_octets() {
    assert_eq!(Iv::new(1 << 96), None);
    assert_eq!(Iv::new(u128::MAX), None);
    let iv = Iv::new((1 << 96) - 2).unwrap();
    assert_eq!(Iv::from_bytes(iv.to_bytes()), iv);
    let mut ones = [0xffu8; 12];
    ones[11] = 0xfe;
    assert_eq!(iv.to_bytes(), ones);
}

/// A mask is at most `MAX_MASK_LEN` octets: one of exactly that many is kept whole, a longer
/// one refused.
#[test]
fn mask_lengths() {
    let full = [0xa5u8; MAX_MASK_LEN];
    assert_eq!(AuthMask::new(&full).unwrap().as_bytes(), &full[..]);
    assert_eq!(AuthMask::new(&[0xff; MAX_MASK_LEN + 1]), None);
    assert_eq!(AuthMask::new(&[0xff; 3]).unwrap().as_bytes(), &[0xff; 3]);
}

/// A fingerprint read back from a store is the one written.
#[test]
fn fingerprint_round_trip() {
    let fp = key().fingerprint();
    assert_eq!(Fingerprint::from_bytes(fp.to_bytes()), fp);
    assert_ne!(Fingerprint::from_bytes([0; 8]), fp);
}

/// The association's accessors, and what a receiver refuses to do as a sender and the
/// reverse: nothing changes.
#[test]
fn association_roles_and_accessors() {
    let mut tx = sender(7, mask::TC);
    assert_eq!(tx.channel(), CHANNEL);
    assert_eq!(tx.mask(), &mask::TC);
    // A sender has no window to resume.
    assert!(!tx.resume(Iv::new(3).unwrap()));
    let mut rx = receiver(9, 100);
    let mut frame = vec![0u8; 6 + HEADER_LEN + 4 + MAC_LEN];
    let n = frame.len();
    let before = frame.clone();
    assert_eq!(
        rx.protect(&mut frame, 6, n),
        Err(SdlsError::NotSender { spi: 9 })
    );
    assert_eq!(frame, before);
}

/// A mask reaching past the security header's end is refused before anything is written.
#[test]
fn mask_past_the_security_header() {
    let mut tx = sender(7, AuthMask::new(&[0xff; 30]).unwrap());
    let mut frame = vec![0u8; 6 + HEADER_LEN + 4 + MAC_LEN];
    let n = frame.len();
    assert_eq!(
        tx.protect(&mut frame, 6, n),
        Err(SdlsError::MaskTooLong {
            mask: 30,
            header_end: 6 + HEADER_LEN
        })
    );
    assert_eq!(frame, vec![0u8; n]);
    // The counter was not used: the next frame under a fitting mask takes IV 0.
    let mut ok = sender(7, mask::TC);
    assert_eq!(ok.protect(&mut frame, 6, n).unwrap().get(), 0);
}

/// The window's width, and its refusals of a resume beyond the floor and of a floor out of
/// range or not further ahead.
#[test]
fn replay_window_refusals() {
    let mut w = ReplayWindow::boot(Some(100), 64, 16);
    assert_eq!(w.window(), 64);
    assert!(w.persisted(110));
    assert_eq!(w.floor().get(), 110);
    // Beyond the floor: nothing changes.
    assert!(!w.resume(Iv::new(111).unwrap()));
    assert_eq!((w.last().get(), w.floor().get()), (100, 110));
    // Not a counter, the same floor, a lower one: nothing changes.
    assert!(!w.persisted(1 << 96));
    assert!(!w.persisted(110));
    assert!(!w.persisted(105));
    assert_eq!(w.floor().get(), 110);
    // At the floor: resumes there.
    assert!(w.resume(Iv::new(104).unwrap()));
    assert_eq!((w.last().get(), w.floor().get()), (104, 110));
}

/// The table: an SPI is added once; its associations listed; a resume out of range and a
/// receiver's readiness to send refused.
#[test]
fn table_refusals() {
    let mut t: SaTable<3> = SaTable::new();
    t.add(sender(7, mask::TC)).unwrap();
    t.add(receiver(9, 100)).unwrap();
    let dup = t.add(receiver(7, 5)).unwrap_err();
    assert_eq!(dup.spi(), 7);
    assert!(matches!(t.get(7).unwrap().role(), Role::Send(_)));
    let spis: Vec<u16> = t.iter().map(|sa| sa.spi()).collect();
    assert_eq!(spis, [7, 9]);
    assert!(t.ready(7));
    assert!(!t.ready(9));
    assert!(!t.ready(8));
    assert!(!t.resume(9, 1 << 96));
    assert!(!t.resume(7, 3));
    assert!(t.resume(9, 104));
}

fn ping_frame(content: TcContent<'_>) -> TcFrameRepr<'_> {
    TcFrameRepr {
        spacecraft_id: SpacecraftId::new(0x101).unwrap(),
        vcid: Vcid::new(0).unwrap(),
        seq: 3,
        content,
    }
}

/// A frame without a segment header carries the security header right after the primary
/// header; it verifies back to its data. A BC frame is not protected.
#[test]
fn unsegmented_and_control_frames() {
    // The primary header and the SPI under the MAC (the mission's TC mask also covers the
    // segment header, which this frame has not).
    let unsegmented = AuthMask::new(&[0xff; TC_PRIMARY_HEADER_LEN + 2]).unwrap();
    let mut tx: SaTable<1> = SaTable::new();
    tx.add(sender(257, unsegmented)).unwrap();
    let data = *b"move";
    let repr = ping_frame(TcContent::Ad {
        map_id: None,
        data: &data,
    });
    let mut out = [0u8; MAX_FRAME_LEN];
    let n = protect_tc(&mut tx, 257, &repr, &mut out).unwrap();
    assert_eq!(n, TC_PRIMARY_HEADER_LEN + HEADER_LEN + 4 + MAC_LEN + 2);
    // The SPI right after the 5-octet primary header.
    assert_eq!(
        &out[TC_PRIMARY_HEADER_LEN..TC_PRIMARY_HEADER_LEN + 2],
        &[1, 1]
    );
    let mut rx: SaTable<1> = SaTable::new();
    let mut w = ReplayWindow::boot(None, 64, 16);
    assert!(w.persisted(w.due().unwrap()));
    rx.add(SecurityAssociation::new(
        257,
        key(),
        CHANNEL,
        unsegmented,
        Role::Receive(w),
    ))
    .unwrap();
    let vcs = [VcConfig {
        vcid: Vcid::new(0).unwrap(),
        segment_header: false,
        map_ids: 0,
    }];
    let config = TcFrameConfig {
        spacecraft_id: SpacecraftId::new(0x101).unwrap(),
        vcs: &vcs,
        fecf: true,
        max_frame_len: MAX_FRAME_LEN,
    };
    let frame = TcFrame::new_checked(&out[..n], &config).unwrap();
    let mut buf = [0u8; MAX_FRAME_LEN];
    let (verified, range) = verify_tc(&mut rx, &frame, &mut buf).unwrap();
    assert_eq!(verified.iv.get(), 0);
    assert_eq!(&buf[range], b"move");

    let bc = ping_frame(TcContent::Bc(ControlCommand::Unlock));
    assert_eq!(
        protect_tc(&mut tx, 257, &bc, &mut out),
        Err(SdlsError::ControlFrame)
    );
    // The refused BC frame used no counter.
    assert_eq!(protect_tc(&mut tx, 257, &repr, &mut out), Ok(n));
    assert_eq!(
        out[TC_PRIMARY_HEADER_LEN + 2..][..12],
        [0u8, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 1]
    );
}

/// A sender refuses a security header placed past the address space (its end would overflow)
/// and a frame whose IV the shell has not reserved yet; neither writes into the frame.
#[test]
fn layout_overflow_and_unreserved_counter() {
    let mut tx = sender(7, mask::TC);
    let mut frame = vec![0u8; 6 + HEADER_LEN + 4 + MAC_LEN];
    let n = frame.len();
    assert_eq!(
        tx.protect(&mut frame, usize::MAX, n),
        Err(SdlsError::Layout {
            sec_start: usize::MAX,
            mac_end: n,
            len: n
        })
    );
    // Booted, but its first block never confirmed durable.
    let unreserved = TxCounter::boot(Some(40), 16);
    let mut cold = SecurityAssociation::new(7, key(), CHANNEL, mask::TC, Role::Send(unreserved));
    assert_eq!(
        cold.protect(&mut frame, 6, n),
        Err(SdlsError::CounterNotReserved {
            next: 40,
            reserved: 40
        })
    );
    assert_eq!(frame, vec![0u8; n]);
}

fn segmented(data: &[u8]) -> TcFrameRepr<'_> {
    ping_frame(TcContent::Bd {
        map_id: Some(MapId::new(0).unwrap()),
        data,
    })
}

/// `protect_tc` refuses data that cannot fit a mission frame with SDLS, at each of the three
/// bounds (the scratch field, the field with its overhead, the frame in `out`), an unknown SPI
/// and a receiving one; only a frame it protects is counted.
#[test]
fn tc_protection_refusals() {
    let mut t: SaTable<2> = SaTable::new();
    t.add(sender(7, mask::TC)).unwrap();
    t.add(receiver(9, 100)).unwrap();
    let mut out = [0u8; MAX_FRAME_LEN];
    let too_long = |found| SdlsError::TooLong {
        max: TC_MAX_DATA,
        found,
    };
    // Past the scratch buffer after the security header.
    let huge = [0x11u8; MAX_FRAME_LEN - HEADER_LEN + 1];
    assert_eq!(
        protect_tc(&mut t, 7, &segmented(&huge), &mut out),
        Err(too_long(huge.len()))
    );
    // Fits the scratch buffer, not with the MAC after it.
    let long = [0x11u8; MAX_FRAME_LEN - HEADER_LEN - MAC_LEN + 1];
    assert_eq!(
        protect_tc(&mut t, 7, &segmented(&long), &mut out),
        Err(too_long(long.len()))
    );
    // The field fits, the frame (headers, FECF) not the 256 octets of `out`.
    let over = [0x11u8; TC_MAX_DATA + 1];
    assert_eq!(
        protect_tc(&mut t, 7, &segmented(&over), &mut out),
        Err(too_long(over.len()))
    );
    assert_eq!(out, [0u8; MAX_FRAME_LEN]);
    let fits = [0x11u8; TC_MAX_DATA];
    assert_eq!(
        protect_tc(&mut t, 7, &segmented(&fits), &mut out),
        Ok(MAX_FRAME_LEN)
    );
    assert_eq!(
        protect_tc(&mut t, 8, &segmented(b"move"), &mut out),
        Err(SdlsError::NoSuchSpi { spi: 8 })
    );
    assert_eq!(
        protect_tc(&mut t, 9, &segmented(b"move"), &mut out),
        Err(SdlsError::NotSender { spi: 9 })
    );
    assert_eq!(t.counters().protected, 1);
}

/// A TC channel without FECF: the MAC ends at the frame's end, and the frame verifies back to
/// its data.
#[test]
fn tc_frame_without_fecf() {
    let mut tx: SaTable<1> = SaTable::new();
    tx.add(sender(257, mask::TC)).unwrap();
    // The data field as SDLS lays it out: security header, plaintext, MAC.
    let mut field = [0u8; HEADER_LEN + 4 + MAC_LEN];
    field[HEADER_LEN..HEADER_LEN + 4].copy_from_slice(b"move");
    let repr = segmented(&field);
    let mut out = [0u8; MAX_FRAME_LEN];
    let n = repr.emit_with(false, &mut out).unwrap();
    assert_eq!(n, TC_PRIMARY_HEADER_LEN + 1 + field.len());
    let sec_start = TC_PRIMARY_HEADER_LEN + 1;
    assert_eq!(
        tx.protect(257, &mut out[..n], sec_start, n).unwrap().get(),
        0
    );
    let mut rx: SaTable<1> = SaTable::new();
    rx.add(fresh_receiver(257, mask::TC)).unwrap();
    let vcs = [VcConfig {
        vcid: Vcid::new(0).unwrap(),
        segment_header: true,
        map_ids: 1,
    }];
    let config = TcFrameConfig {
        spacecraft_id: SpacecraftId::new(0x101).unwrap(),
        vcs: &vcs,
        fecf: false,
        max_frame_len: MAX_FRAME_LEN,
    };
    let frame = TcFrame::new_checked(&out[..n], &config).unwrap();
    assert_eq!(frame.fecf(), None);
    let mut buf = [0u8; MAX_FRAME_LEN];
    let (verified, range) = verify_tc(&mut rx, &frame, &mut buf).unwrap();
    assert_eq!((verified.spi, verified.iv.get()), (257, 0));
    assert_eq!(range, sec_start + HEADER_LEN..n - MAC_LEN);
    assert_eq!(&buf[range], b"move");
}

/// A TM frame: protected without FECF (its last octets, the OCF, left as written), verified
/// back; refused when shorter than the channel's frames (to protect, to verify, or for the
/// verifier's buffer) or under an unknown SPI.
#[test]
fn tm_protection_and_its_refusals() {
    let params = secured_tm_params(TmFrameParams::new(64, 0x101, 0, true, false).unwrap()).unwrap();
    let len = params.frame_len();
    let data = vec![0x3cu8; params.data_len()];
    let repr = TmFrameRepr {
        spacecraft_id: 0x101,
        vcid: 0,
        mc_frame_count: 1,
        vc_frame_count: 1,
        first_header_pointer: FirstHeaderPointer::Packet(0),
        data: &data,
        ocf: Some([1, 2, 3, 4]),
    };
    let mut frame = vec![0u8; len];
    assert_eq!(repr.emit(&params, &mut frame), Ok(len));
    let mut t: SaTable<1> = SaTable::new();
    t.add(sender(7, mask::TM)).unwrap();
    assert_eq!(
        protect_tm(&mut t, 7, &params, &mut frame[..len - 1]),
        Err(SdlsError::Layout {
            sec_start: PRIMARY_HEADER_LEN,
            mac_end: params.ocf_start(),
            len
        })
    );
    assert_eq!(
        protect_tm(&mut t, 8, &params, &mut frame),
        Err(SdlsError::NoSuchSpi { spi: 8 })
    );
    assert_eq!(protect_tm(&mut t, 7, &params, &mut frame), Ok(()));
    // No FECF: the frame ends with the OCF, as written.
    assert_eq!(frame[len - 4..], [1, 2, 3, 4]);
    assert_ne!(frame[params.data_range()], data[..]);

    let parsed = TmFrameRepr::parse(&frame, &params).unwrap();
    let mut rx: SaTable<1> = SaTable::new();
    rx.add(fresh_receiver(7, mask::TM)).unwrap();
    let mut short = vec![0u8; len - 1];
    assert_eq!(
        verify_tm(&mut rx, &params, &parsed, &frame, &mut short).map(|_| ()),
        Err(SdlsRefusal::Truncated {
            needed: len,
            found: len - 1
        })
    );
    let mut buf = vec![0u8; len];
    assert_eq!(
        verify_tm(&mut rx, &params, &parsed, &frame[..len - 2], &mut buf).map(|_| ()),
        Err(SdlsRefusal::Truncated {
            needed: len,
            found: len - 2
        })
    );
    let (verified, plain) = verify_tm(&mut rx, &params, &parsed, &frame, &mut buf).unwrap();
    assert_eq!((verified.spi, verified.iv.get()), (7, 0));
    assert_eq!(plain.data, &data[..]);
    assert_eq!(plain.ocf, Some([1, 2, 3, 4]));
}
