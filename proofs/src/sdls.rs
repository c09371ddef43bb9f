//! The properties of Space Data Link Security (`mmic::link::sdls`), shared by the harnesses of
//! `tests/harnesses/sdls.rs` and the fuzz targets `sdls_tc_verify` and `sdls_tm_verify`: plain
//! functions that panic when a property fails.
//!
//! The keys are the fixed test keys of [`test_key`], computed at run time from a rule: they
//! are not secrets (the project's keys are made at run time, outside the tree), only fixed so
//! that a fuzz run, a seed and a sampled case can be replayed.

use mmic::link::sdls::frames::{protect_tc, protect_tm, verify_tc, verify_tm};
use mmic::link::sdls::{
    mission, Channel, Iv, Key256, ReplayWindow, Role, SaTable, SdlsRefusal, SecurityAssociation,
    TxCounter, HEADER_LEN, MAC_LEN,
};
use mmic::link::tc_frame::{
    self, MapId, SpacecraftId, TcContent, TcFrame, TcFrameRepr, TcPrimaryHeader, Vcid, FECF_LEN,
    MAX_FRAME_LEN,
};
use mmic::link::tm_frame::{FirstHeaderPointer, TmFrameParams, TmFrameRepr, TM_FRAME_LEN};
use mmic::link::FrameKind;
use mmic::node::ground::frames::{GroundLink, TmRefusal};
use mmic::node::server::frames::{FrameConfig, FrameGateway, FrameRefusal, Stored};
use mmic::units::BoardNumber;

/// 2^96: the IV space.
pub const IV_SPACE: u128 = 1 << 96;
/// Half of it: a counter this far ahead of the last or further is behind (a replay).
pub const HALF: u128 = IV_SPACE / 2;
/// The robot of every property: robot 1, spacecraft 0x101.
pub const BOARD: BoardNumber = BoardNumber::ONE;
/// Its TC association's SPI (257) and its TM association's (513).
pub const TC_SPI: u16 = mission::tc_spi(BOARD);
/// Its TM association's SPI.
pub const TM_SPI: u16 = mission::tm_spi(BOARD);
/// Where a mission TC frame's security header starts: primary header and segment header.
pub const TC_SEC_START: usize = tc_frame::TC_PRIMARY_HEADER_LEN + tc_frame::SEGMENT_HEADER_LEN;

/// The secured gateway of the properties: one robot, the gateway's default queues.
pub type Gateway = FrameGateway<1, 4, 8, 1024>;
/// The secured ground link of the properties.
pub type Ground = GroundLink<10, 8, 512>;

/// Fixed test key `which` (0: the TC association's, 1: the TM association's), computed from
/// a rule at run time. Not a secret: fixed so that every run can be replayed.
pub fn test_key(which: u8) -> Key256 {
    Key256::from_bytes(core::array::from_fn(|i| {
        (i as u8).wrapping_mul(0x9d) ^ which.wrapping_mul(0x5b) ^ 0xa7
    }))
}

fn channel(scid: u16, vcid: u8) -> Channel {
    Channel {
        spacecraft_id: scid,
        vcid,
    }
}

/// The TC channel of [`BOARD`].
pub fn tc_channel() -> Channel {
    channel(SpacecraftId::of_board(BOARD).get(), tc_frame::MISSION_VCID)
}

/// `iv` below 2^96: the arbitrary number folded into the IV space.
pub fn fold_iv(iv: u128) -> u128 {
    iv % IV_SPACE
}

/// A table with `sa`, its durable number written (every number due confirmed once).
fn with_reservation(sa: SecurityAssociation) -> SaTable<1> {
    let mut t = SaTable::new();
    assert!(t.add(sa).is_ok());
    let due: Option<(u16, u128)> = t.due().next();
    if let Some((spi, v)) = due {
        t.persisted(spi, v);
    }
    t
}

/// The ground's TC association whose next IV is `iv` (its reservation written).
pub fn tc_sender(iv: u128) -> SaTable<1> {
    with_reservation(mission::tc_sender(BOARD, test_key(0), Some(fold_iv(iv))))
}

/// The board's TC association ready for IV `iv` next: its last IV `iv − 1` (none for 0), its
/// floor a block ahead.
pub fn tc_receiver(iv: u128) -> SaTable<1> {
    let iv = fold_iv(iv);
    let stored = iv.checked_sub(1);
    with_reservation(mission::tc_receiver(BOARD, test_key(0), stored))
}

/// The board's TM association whose next IV is `iv`.
pub fn tm_sender(iv: u128) -> SaTable<1> {
    with_reservation(mission::tm_sender(BOARD, test_key(1), Some(fold_iv(iv))))
}

/// The ground's TM association ready for IV `iv` next.
pub fn tm_receiver(iv: u128) -> SaTable<1> {
    let iv = fold_iv(iv);
    with_reservation(mission::tm_receiver(BOARD, test_key(1), iv.checked_sub(1)))
}

/// The mission's TM parameters with room for SDLS.
pub fn tm_params() -> TmFrameParams {
    TmFrameParams::mission(SpacecraftId::of_board(BOARD).get())
        .and_then(|p| p.with_security(HEADER_LEN as u8, MAC_LEN as u8))
        .expect("the mission's TM frame has room for SDLS")
}

/// A TC(17,1) are-you-alive for robot 1 (APID 0x101), sequence count `seq`: 13 octets.
pub fn ping(seq: u16) -> [u8; 13] {
    use mmic::ccsds::primary::{Apid, SeqCount};
    use mmic::ccsds::tc::TcRepr;
    use mmic::ccsds::tc_header::{AckFlags, TcSecondaryHeader};
    let mut p = [0u8; 13];
    let n = TcRepr {
        apid: Apid::new(0x101).expect("11 bits"),
        seq_count: SeqCount::new(seq & 0x3fff).expect("14 bits"),
        header: TcSecondaryHeader {
            ack: AckFlags::ALL,
            service: 17,
            subservice: 1,
            source_id: 0,
        },
        app_data: &[],
    }
    .emit(&mut p)
    .expect("13 octets");
    assert_eq!(n, 13);
    p
}

/// Writes the FECF over the rest of `frame`, with the bitwise CRC (the oracle's).
pub fn refresh_fecf(frame: &mut [u8]) {
    let n = frame.len();
    if n >= FECF_LEN {
        let crc = crate::crc16_bitwise(&frame[..n - FECF_LEN]);
        frame[n - FECF_LEN..].copy_from_slice(&crc.to_be_bytes());
    }
}

/// A mission TC frame (AD, or BD when `bd`; N(S) `seq`; MAP 0) carrying `data` (cut to what a
/// protected frame holds), protected under IV `iv` by the ground's association, into `out`:
/// its length.
pub fn protected_tc(iv: u128, bd: bool, seq: u8, data: &[u8], out: &mut [u8]) -> usize {
    let data = &data[..data.len().min(mmic::link::sdls::frames::TC_MAX_DATA)];
    let map_id = MapId::new(tc_frame::MISSION_MAP_ID).ok();
    let content = if bd {
        TcContent::Bd { map_id, data }
    } else {
        TcContent::Ad { map_id, data }
    };
    let repr = TcFrameRepr {
        spacecraft_id: SpacecraftId::of_board(BOARD),
        vcid: Vcid::new(tc_frame::MISSION_VCID).expect("VC 0"),
        seq,
        content,
    };
    let mut tx = tc_sender(iv);
    let n = protect_tc(&mut tx, TC_SPI, &repr, out).expect("a reserved IV and a frame that fits");
    assert_eq!(tx.counters().protected, 1);
    n
}

/// The channel a TC frame's header names (what the gateway passes to SDLS).
fn header_channel(frame: &[u8]) -> Channel {
    let h = TcPrimaryHeader::read(frame).expect("5 octets");
    channel(h.spacecraft_id, h.vcid)
}

/// The receiving association's direction and counter (its whole state but the key).
fn role_of(t: &SaTable<1>, spi: u16) -> Role {
    t.get(spi).expect("the association").role().clone()
}

/// A receiving association's last IV and floor.
fn last_and_floor(role: &Role) -> Option<(Iv, Iv)> {
    match role {
        Role::Receive(w) => Some((w.last(), w.floor())),
        Role::Send(_) => None,
    }
}

/// Property of the harness `sdls_verify_never_accepts_a_changed_frame`: a TC frame protected
/// under IV `iv` (AD or BD, N(S) `seq`, carrying `data`), with octet `at` (mod its length)
/// XORed with `delta` (1 when 0: always a change) and, when `reseal`, its FECF written again
/// over the change (unless the change is in the FECF itself), is refused:
///
/// * through the frame layer: refused by a frame check (the FECF, the addressing), or by SDLS
///   ([`verify_tc`]): never verified;
/// * by the receiving [`SaTable`] directly, in place: refused, the frame left octet for
///   octet as it came, the association's window as it was, the refusal counted once;
///
/// and the unchanged frame is then accepted with its data back (the receiver was ready: the
/// refusal was the change's). Returns the refusal's name at the table.
pub fn check_changed_frame_refused(
    iv: u128,
    bd: bool,
    seq: u8,
    data: &[u8],
    at: usize,
    delta: u8,
    reseal: bool,
) -> &'static str {
    let iv = fold_iv(iv);
    let mut sent = [0u8; MAX_FRAME_LEN];
    let n = protected_tc(iv, bd, seq, data, &mut sent);
    let sent = &sent[..n];
    let mut frame = [0u8; MAX_FRAME_LEN];
    frame[..n].copy_from_slice(sent);
    let frame = &mut frame[..n];
    let at = at % n;
    frame[at] ^= delta.max(1);
    if reseal && at < n - FECF_LEN {
        refresh_fecf(frame);
    }
    assert_ne!(&frame[..], sent, "the frame was changed");
    let mut rx = tc_receiver(iv);
    let role = role_of(&rx, TC_SPI);
    // The frame layer, as the gateway runs it: frame checks, then SDLS on a copy.
    let config = tc_frame::mission(SpacecraftId::of_board(BOARD));
    if let Ok(f) = TcFrame::new_checked(&frame[..], &config) {
        if f.kind() != FrameKind::Bc {
            let mut buf = [0u8; MAX_FRAME_LEN];
            let got = verify_tc(&mut rx, &f, &mut buf);
            assert!(got.is_err(), "a changed frame verified: {got:?}");
            assert_eq!(role_of(&rx, TC_SPI), role, "a refusal moved the window");
        }
    }
    // The table, in place.
    let mut rx = tc_receiver(iv);
    let before = *rx.counters();
    let mut copy = [0u8; MAX_FRAME_LEN];
    copy[..n].copy_from_slice(frame);
    let copy = &mut copy[..n];
    let got = rx.verify(copy, TC_SEC_START, n - FECF_LEN, header_channel(frame));
    let refusal = match got {
        Ok(v) => {
            // Only a change in the FECF (outside the MAC, the frame layer's to check).
            assert!(at >= n - FECF_LEN, "a change at octet {at} verified: {v:?}");
            "fecf"
        }
        Err(e) => {
            assert_eq!(&copy[..], &frame[..], "a refused frame was changed");
            assert_eq!(role_of(&rx, TC_SPI), role, "a refusal moved the window");
            let after = rx.counters();
            assert_eq!(after.accepted, before.accepted);
            assert_eq!(after.refused_total(), before.refused_total() + 1);
            assert_eq!(
                after.refused_for(e.name()),
                before.refused_for(e.name()) + 1
            );
            e.name()
        }
    };
    // The frame as sent is accepted, its data back.
    let mut rx = tc_receiver(iv);
    let mut copy = [0u8; MAX_FRAME_LEN];
    copy[..n].copy_from_slice(sent);
    let v = rx
        .verify(&mut copy[..n], TC_SEC_START, n - FECF_LEN, tc_channel())
        .expect("the frame as sent verifies");
    assert_eq!(v.iv.get(), iv);
    let len = data.len().min(mmic::link::sdls::frames::TC_MAX_DATA);
    assert_eq!(&copy[TC_SEC_START + HEADER_LEN..][..len], &data[..len]);
    refusal
}

/// Property of the harness `sdls_round_trip`, for any IV, data and frame fields:
///
/// * TC: the frame [`protect_tc`] writes passes the frame checks (FECF, addressing), carries
///   the SPI and the IV in its security header, hides the data (when 8 octets or more), and
///   [`verify_tc`] gives exactly the data back under that IV; the same frame again is refused
///   as a replay and counted;
/// * TM: a 256-octet frame whose packet zone is `data` (zero-padded, cut to 214 octets),
///   protected by [`protect_tm`], parses, and [`verify_tm`] gives the zone back with the
///   frame's fields and its OCF (outside the MAC) as they were.
pub fn check_round_trip(iv: u128, bd: bool, seq: u8, data: &[u8]) {
    let iv = fold_iv(iv);
    let mut frame = [0u8; MAX_FRAME_LEN];
    let n = protected_tc(iv, bd, seq, data, &mut frame);
    let frame = &frame[..n];
    let data = &data[..data.len().min(mmic::link::sdls::frames::TC_MAX_DATA)];
    assert_eq!(
        n,
        TC_SEC_START + HEADER_LEN + data.len() + MAC_LEN + FECF_LEN
    );
    assert_eq!(frame[TC_SEC_START..][..2], TC_SPI.to_be_bytes());
    assert_eq!(
        frame[TC_SEC_START + 2..][..12],
        Iv::new(iv).expect("below 2^96").to_bytes()
    );
    let body = TC_SEC_START + HEADER_LEN;
    if data.len() >= 8 {
        assert_ne!(&frame[body..body + data.len()], data, "the data in clear");
    }
    let config = tc_frame::mission(SpacecraftId::of_board(BOARD));
    let f = TcFrame::new_checked(frame, &config).expect("a sound frame");
    assert_eq!(f.kind(), if bd { FrameKind::Bd } else { FrameKind::Ad });
    assert_eq!(f.seq(), seq);
    let mut rx = tc_receiver(iv);
    let mut buf = [0u8; MAX_FRAME_LEN];
    let (v, range) = verify_tc(&mut rx, &f, &mut buf).expect("the frame verifies");
    assert_eq!((v.spi, v.iv.get()), (TC_SPI, iv));
    assert_eq!(&buf[range], data);
    let again = verify_tc(&mut rx, &f, &mut buf).map(|(v, _)| v);
    assert_eq!(again.map_err(|e| e.name()), Err("replay"));
    assert_eq!(rx.counters().accepted, 1);
    assert_eq!(rx.counters().refused_for("replay"), 1);

    // TM.
    let params = tm_params();
    let mut zone = [0u8; TM_FRAME_LEN];
    let zone = &mut zone[..params.data_len()];
    let k = data.len().min(zone.len());
    zone[..k].copy_from_slice(&data[..k]);
    let ocf = [0x01, 0x00, 0x00, seq];
    let repr = TmFrameRepr {
        spacecraft_id: params.spacecraft_id(),
        vcid: params.vcid(),
        mc_frame_count: seq,
        vc_frame_count: seq.wrapping_add(1),
        first_header_pointer: FirstHeaderPointer::OnlyIdleData,
        data: zone,
        ocf: Some(ocf),
    };
    let mut tm = [0u8; TM_FRAME_LEN];
    assert_eq!(repr.emit(&params, &mut tm), Ok(TM_FRAME_LEN));
    let mut tx = tm_sender(iv);
    protect_tm(&mut tx, TM_SPI, &params, &mut tm).expect("a reserved IV");
    assert_eq!(tm[6..8], TM_SPI.to_be_bytes());
    let parsed = TmFrameRepr::parse(&tm, &params).expect("a sound frame");
    let mut rx = tm_receiver(iv);
    let mut plain = [0u8; TM_FRAME_LEN];
    let (v, got) = verify_tm(&mut rx, &params, &parsed, &tm, &mut plain).expect("it verifies");
    assert_eq!((v.spi, v.iv.get()), (TM_SPI, iv));
    assert_eq!(got.data, &zone[..]);
    assert_eq!(got.ocf, Some(ocf));
    assert_eq!(
        (
            got.mc_frame_count,
            got.vc_frame_count,
            got.first_header_pointer
        ),
        (seq, seq.wrapping_add(1), FirstHeaderPointer::OnlyIdleData)
    );
}

/// The window's verdict, written from the definition with signed numbers (no modular
/// arithmetic): `s` is the IV's distance from the last accepted one, taken in
/// [−2^95, 2^95); `ahead`, how far the durable floor is beyond the last.
pub fn window_oracle(s: i128, window: u32, ahead: u128) -> &'static str {
    if s <= 0 {
        "replay"
    } else if s > i128::from(window) {
        "too-far-ahead"
    } else if s as u128 > ahead {
        "not-reserved"
    } else {
        "accept"
    }
}

/// The signed distance of `iv` from `last`, both below 2^96, in [−2^95, 2^95).
pub fn signed_distance(iv: u128, last: u128) -> i128 {
    let (space, half) = (IV_SPACE as i128, HALF as i128);
    let mut s = iv as i128 - last as i128; // in (−2^96, 2^96)
    if s >= half {
        s -= space;
    } else if s < -half {
        s += space;
    }
    s
}

/// Property of the harness `sdls_window_matches_oracle`: a window (W = `window` folded into
/// 1..=2^32 − 1) whose last IV is `last` and whose durable floor is `ahead` beyond it (folded
/// below 2^95), or a fresh window (nothing accepted yet, no floor) when `fresh`, admits `iv`
/// exactly when [`window_oracle`] says so, and refuses it with the oracle's reason:
///
/// * accepted: the last IV is the frame's, the floor where it was;
/// * refused as a replay or too far ahead: the window is unchanged, `due` too;
/// * refused as not reserved (authentic, beyond the floor): last and floor unchanged, and the
///   next floor `due` covers the IV: written, the same IV is then accepted.
///
/// Returns the verdict's name.
pub fn check_window(fresh: bool, last: u128, ahead: u128, window: u32, iv: u128) -> &'static str {
    let window = window.max(1);
    let (last, iv) = (fold_iv(last), fold_iv(iv));
    let mut w = if fresh {
        ReplayWindow::boot(None, window, 1)
    } else {
        ReplayWindow::boot(Some(last), window, 1)
    };
    let last = w.last().get();
    let ahead = if fresh { 0 } else { ahead % HALF };
    if ahead > 0 {
        assert!(w.persisted(Iv::wrapping(last + ahead).get()));
    }
    assert_eq!(w.floor(), Iv::wrapping(last + ahead));
    let before = w.clone();
    let expected = window_oracle(signed_distance(iv, last), window, ahead);
    let got = match w.admit(Iv::wrapping(iv)) {
        Ok(()) => "accept",
        Err(e) => e.name(),
    };
    assert_eq!(
        got, expected,
        "W {window}, last {last:#x}, floor +{ahead}, IV {iv:#x}"
    );
    match got {
        "accept" => {
            assert_eq!(w.last().get(), iv);
            assert_eq!(w.floor(), before.floor());
        }
        "not-reserved" => {
            assert_eq!((w.last(), w.floor()), (before.last(), before.floor()));
            let due = w.due().expect("a floor covering the IV is due");
            assert!(w.persisted(due));
            assert!(
                Iv::wrapping(iv).ahead_of(w.last()) <= w.floor().ahead_of(w.last()),
                "the floor written does not cover the IV"
            );
            assert_eq!(w.admit(Iv::wrapping(iv)), Ok(()));
        }
        _ => assert_eq!(w, before, "a refusal changed the window"),
    }
    got
}

/// At most this many IVs taken in one run of [`check_tx_ops`].
pub const MAX_TX_OPS: usize = 24;

/// Property of the harness `sdls_tx_counter_never_reuses`: a sender from any start (a new
/// association, or one restarted with the stored reservation `start`, near 2^96 when
/// `near_end`) with any block (1..=256), through any sequence of operations, each octet of
/// `ops` one of: take an IV for a frame; the shell starts writing the reservation `due`
/// asks for; the write becomes durable and is confirmed (`persisted`); a stale or replayed
/// confirmation of the stored value; a restart that loses the write in flight; a restart
/// after the write in flight became durable (but before its confirmation):
///
/// * no IV is ever taken twice, across restarts; IVs strictly increase;
/// * every IV taken is below the durable store (what a restart continues from) and below
///   2^96; once 2^96 is reached, the sender refuses with `CounterExhausted` for good;
/// * `take` fails only for want of a confirmed reservation or when exhausted, and never
///   moves the counter when it fails.
///
/// Returns how many IVs were taken.
pub fn check_tx_ops(start: u128, near_end: bool, block: u8, ops: &[u8]) -> usize {
    let block = u32::from(block) + 1;
    let start = if near_end {
        IV_SPACE - 1 - start % 8
    } else {
        start % IV_SPACE
    };
    let mut stored: Option<u128> = if start == 0 && !near_end {
        None
    } else {
        Some(start)
    };
    let mut pending: Option<u128> = None;
    let mut c = TxCounter::boot(stored, block);
    let mut taken = [0u128; MAX_TX_OPS];
    let mut k = 0;
    for &op in ops.iter().take(MAX_TX_OPS) {
        match op % 6 {
            0 => {
                let before = c.clone();
                match c.take() {
                    Ok(iv) => {
                        let iv = iv.get();
                        assert!(iv < IV_SPACE);
                        assert!(
                            iv < stored.unwrap_or(0),
                            "IV {iv:#x} not below the store {stored:?}"
                        );
                        assert!(!taken[..k].contains(&iv), "IV {iv:#x} taken twice");
                        if k > 0 {
                            assert!(iv > taken[k - 1], "IVs not increasing");
                        }
                        taken[k] = iv;
                        k += 1;
                    }
                    Err(e) => {
                        assert_eq!(c, before, "a refused take moved the counter");
                        match e {
                            mmic::link::sdls::SdlsError::CounterExhausted => {
                                assert_eq!(c.next(), IV_SPACE)
                            }
                            mmic::link::sdls::SdlsError::CounterNotReserved { next, reserved } => {
                                assert!(next >= reserved && next < IV_SPACE)
                            }
                            other => panic!("take refused with {other:?}"),
                        }
                    }
                }
            }
            1 => {
                if pending.is_none() {
                    pending = c.due();
                }
            }
            2 => {
                if let Some(v) = pending.take() {
                    assert!(v <= IV_SPACE);
                    stored = Some(v);
                    c.persisted(v);
                }
            }
            3 => {
                if let Some(v) = stored {
                    assert!(!c.persisted(v) || c.reserved() == v);
                }
            }
            4 => {
                pending = None;
                c = TxCounter::boot(stored, block);
            }
            _ => {
                if let Some(v) = pending.take() {
                    stored = Some(v);
                }
                c = TxCounter::boot(stored, block);
            }
        }
        assert!(
            c.reserved() <= stored.unwrap_or(0),
            "a reservation not in the store"
        );
        assert!(c.next() <= IV_SPACE && c.reserved() <= IV_SPACE);
    }
    k
}

/// A fresh secured gateway for [`BOARD`]: the TC window and the TM counter new, their first
/// durable numbers written.
pub fn secured_gateway() -> Gateway {
    let mut g = Gateway::new(FrameConfig::default());
    assert!(g.add(BOARD));
    assert!(g
        .secure(BOARD, test_key(0), test_key(1), Stored::default())
        .is_ok());
    let mut due = [(0u16, 0u128); 4];
    let mut n = 0;
    for d in g.due() {
        due[n] = d;
        n += 1;
    }
    for &(spi, v) in &due[..n] {
        assert!(g.persisted(spi, v));
    }
    g
}

/// The IV of the security header at `sec_start` of `frame` (0 when too short).
fn iv_at(frame: &[u8], sec_start: usize) -> u128 {
    frame
        .get(sec_start + 2..sec_start + HEADER_LEN)
        .and_then(|b| <[u8; 12]>::try_from(b).ok())
        .map_or(0, |b| Iv::from_bytes(b).get())
}

/// Whether `frame` is exactly what the key's holder would send: its data decrypted by a
/// receiver, then protected again under the same IV, gives the same octets (the FECF too
/// when `fecf`; the SDLS layer alone does not see it). An accepted frame must be one.
fn genuine_tc(frame: &[u8], fecf: bool) -> bool {
    let n = frame.len();
    if n < TC_SEC_START + HEADER_LEN + MAC_LEN + FECF_LEN {
        return false;
    }
    let mut copy = [0u8; MAX_FRAME_LEN];
    copy[..n].copy_from_slice(frame);
    let copy = &mut copy[..n];
    // A receiver ready for the frame's own IV (the frame may be beyond a fresh one's floor).
    let mut rx = tc_receiver(iv_at(frame, TC_SEC_START));
    let Ok(v) = rx.verify(copy, TC_SEC_START, n - FECF_LEN, header_channel(frame)) else {
        return false;
    };
    let mut tx = tc_sender(v.iv.get());
    if tx
        .protect(TC_SPI, copy, TC_SEC_START, n - FECF_LEN)
        .is_err()
    {
        return false;
    }
    refresh_fecf(copy);
    if fecf {
        copy == frame
    } else {
        copy[..n - FECF_LEN] == frame[..n - FECF_LEN]
    }
}

/// Property of the harness `sdls_verify_tc_arbitrary_bytes_never_panics` and the fuzz target
/// `sdls_tc_verify`: any octets through a fresh [`secured_gateway`]'s `tc_frame` return, and
///
/// * a refusal by a frame check is counted in the gateway's `refused` under its check;
///   one by SDLS in the robot's SDLS counters under its reason; nothing else moves: no TC
///   frame counted by the link, no packet reaches the PUS gateway;
/// * a frame that gets past SDLS is a BC frame (in clear by design, `sdls-clear-bc`: no
///   packet), or exactly a frame the key's holder protected (`genuine_tc`);
/// * the same octets through the receiving table directly (the SDLS layer alone, the
///   security header after the segment header, the MAC before the last two octets) are
///   refused, the octets left as they came and the window as it was, unless genuine.
///
/// Returns whether the gateway handed packets on (only for genuine frames).
pub fn check_secured_tc_frame(bytes: &[u8]) -> bool {
    let bytes = &bytes[..bytes.len().min(MAX_FRAME_LEN + 8)];
    let mut g = secured_gateway();
    let link_before = *g.counters(BOARD).expect("served");
    let sec_before = *g.security(BOARD).expect("secured");
    let refused_before = *g.refused();
    let r = g.tc_frame(0, bytes);
    let link = *g.counters(BOARD).expect("served");
    let sec = *g.security(BOARD).expect("secured");
    let executed = r.accepted > 0;
    match r.verdict {
        Err(FrameRefusal::Frame(e)) => {
            let mut want = refused_before;
            want[e.position()] += 1;
            assert_eq!(
                *g.refused(),
                want,
                "a frame refusal counted under {}",
                e.name()
            );
            assert_eq!(sec, sec_before);
            assert_eq!(link, link_before);
            assert_eq!((r.accepted, r.refused), (0, 0));
        }
        Err(FrameRefusal::Security(e)) => {
            assert_eq!(*g.refused(), refused_before);
            assert_eq!(sec.refused_total(), sec_before.refused_total() + 1);
            assert_eq!(
                sec.refused_for(e.name()),
                sec_before.refused_for(e.name()) + 1
            );
            assert_eq!(sec.accepted, sec_before.accepted);
            assert_eq!(link, link_before, "an SDLS refusal reached FARM-1");
            assert_eq!((r.accepted, r.refused), (0, 0));
        }
        Err(FrameRefusal::Origin) => {
            panic!("a frame from the ground's address refused for its origin")
        }
        Ok(_) => {
            let control = TcPrimaryHeader::read(bytes).is_some_and(|h| h.control);
            if control {
                assert_eq!(sec, sec_before, "a BC frame went through SDLS");
                assert_eq!(r.accepted, 0, "a BC frame carried packets");
            } else {
                assert_eq!(sec.accepted, sec_before.accepted + 1);
                assert!(
                    genuine_tc(bytes, true),
                    "a frame nobody protected passed SDLS"
                );
            }
        }
    }
    assert!(
        !executed || genuine_tc(bytes, true),
        "packets of a forged frame ran"
    );
    // The SDLS layer alone, in place.
    let n = bytes.len();
    if n >= TC_PRIMARY_HEADER_LEN_AND_FECF {
        let mut rx = with_reservation(mission::tc_receiver(BOARD, test_key(0), None));
        let role = role_of(&rx, TC_SPI);
        let mut copy = [0u8; MAX_FRAME_LEN + 8];
        copy[..n].copy_from_slice(bytes);
        let copy = &mut copy[..n];
        match rx.verify(copy, TC_SEC_START, n - FECF_LEN, header_channel(bytes)) {
            Ok(_) => assert!(
                genuine_tc(bytes, false),
                "a frame nobody protected verified"
            ),
            Err(e) => {
                assert_eq!(&copy[..], bytes, "a refused frame was changed");
                if let SdlsRefusal::NotReserved { .. } = e {
                    // After the MAC verified: authentic, beyond the floor. It asks for the
                    // next floor (documented), and moves neither last nor floor.
                    assert!(genuine_tc(bytes, false), "a forged frame got past the MAC");
                    assert_eq!(last_and_floor(&role_of(&rx, TC_SPI)), last_and_floor(&role));
                } else {
                    assert_eq!(role_of(&rx, TC_SPI), role, "a refusal moved the window");
                }
                assert_eq!(rx.counters().refused_for(e.name()), 1);
                assert_eq!(rx.counters().accepted, 0);
            }
        }
    }
    executed
}

/// [`check_secured_tc_frame`] of `bytes` made to pass the frame checks' first gates (when at
/// least 8 octets, cut to 256): spacecraft 0x101, VC 0, the length field and the FECF
/// written over the rest, so that arbitrary octets reach FARM-1's and SDLS's checks.
pub fn check_secured_tc_frame_resealed(bytes: &[u8]) -> bool {
    let n = bytes.len().min(MAX_FRAME_LEN);
    if n < 8 {
        return check_secured_tc_frame(bytes);
    }
    let mut f = [0u8; MAX_FRAME_LEN];
    f[..n].copy_from_slice(&bytes[..n]);
    let f = &mut f[..n];
    f[0] = (f[0] & 0xfc) | 0x01; // spacecraft 0x101: its two high bits
    f[1] = 0x01;
    f[2] &= 0x03; // VC 0
    crate::link::reseal(f, true);
    check_secured_tc_frame(f)
}

/// The shortest octets the SDLS layer is given a header channel for: a primary header and an
/// FECF.
const TC_PRIMARY_HEADER_LEN_AND_FECF: usize = tc_frame::TC_PRIMARY_HEADER_LEN + FECF_LEN;

/// A fresh secured ground link for [`BOARD`], its first durable numbers written.
pub fn secured_ground() -> Ground {
    let mut g = Ground::new(BOARD);
    g.secure(test_key(0), test_key(1), (None, None));
    let mut due = [(0u16, 0u128); 4];
    let mut n = 0;
    for d in g.due() {
        due[n] = d;
        n += 1;
    }
    for &(spi, v) in &due[..n] {
        assert!(g.persisted(spi, v));
    }
    g
}

/// A TM frame of the mission, its packet zone `zone` (zero-padded), protected under IV `iv`
/// by the board's TM association.
pub fn protected_tm(iv: u128, zone: &[u8], ocf: [u8; 4]) -> [u8; TM_FRAME_LEN] {
    let params = tm_params();
    let mut data = [0u8; TM_FRAME_LEN];
    let k = zone.len().min(params.data_len());
    data[..k].copy_from_slice(&zone[..k]);
    let repr = TmFrameRepr {
        spacecraft_id: params.spacecraft_id(),
        vcid: params.vcid(),
        mc_frame_count: 0,
        vc_frame_count: 0,
        first_header_pointer: if k == 0 {
            FirstHeaderPointer::OnlyIdleData
        } else {
            FirstHeaderPointer::Packet(0)
        },
        data: &data[..params.data_len()],
        ocf: Some(ocf),
    };
    let mut tm = [0u8; TM_FRAME_LEN];
    assert_eq!(repr.emit(&params, &mut tm), Ok(TM_FRAME_LEN));
    let mut tx = tm_sender(iv);
    protect_tm(&mut tx, TM_SPI, &params, &mut tm).expect("a reserved IV");
    tm
}

/// Whether a TM frame is exactly what the board's TM association would send (see
/// `genuine_tc`).
fn genuine_tm(frame: &[u8]) -> bool {
    let params = tm_params();
    let Ok(parsed) = TmFrameRepr::parse(frame, &params) else {
        return false;
    };
    let mut rx = tm_receiver(iv_at(frame, mmic::link::tm_frame::PRIMARY_HEADER_LEN));
    let mut plain = [0u8; TM_FRAME_LEN];
    let Ok((v, _)) = verify_tm(&mut rx, &params, &parsed, frame, &mut plain) else {
        return false;
    };
    let mut tx = tm_sender(v.iv.get());
    if protect_tm(&mut tx, TM_SPI, &params, &mut plain).is_err() {
        return false;
    }
    plain[..] == *frame
}

/// Property of the fuzz target `sdls_tm_verify`: any octets through a fresh
/// [`secured_ground`]'s `tm_frame` return, and unless they are exactly a frame the board's TM
/// association protected (`genuine_tm`): refused (by a frame check, counted in
/// `tm_refused`, or by SDLS, counted under its reason), no packet handed on, no CLCW given to
/// FOP-1, no TC frame sent. Returns whether the frame was taken.
pub fn check_secured_tm_frame(bytes: &[u8]) -> bool {
    let mut g = secured_ground();
    let before = *g.counters();
    let sec_before = *g.security().expect("secured");
    let (mut packets, mut emitted) = (0usize, 0usize);
    let r = g.tm_frame(0, bytes, &mut |_: &[u8]| emitted += 1, &mut |_: &[u8]| {
        packets += 1
    });
    let sec = *g.security().expect("secured");
    match r {
        Ok(()) => {
            assert!(genuine_tm(bytes), "a TM frame nobody protected was taken");
            assert_eq!(sec.accepted, sec_before.accepted + 1);
            true
        }
        Err(e) => {
            match e {
                TmRefusal::Frame(_) => {
                    assert_eq!(g.counters().tm_refused, before.tm_refused + 1);
                    assert_eq!(sec, sec_before);
                }
                TmRefusal::Security(s) => {
                    assert_eq!(g.counters().tm_refused, before.tm_refused);
                    assert_eq!(
                        sec.refused_for(s.name()),
                        sec_before.refused_for(s.name()) + 1
                    );
                    assert_eq!(sec.refused_total(), sec_before.refused_total() + 1);
                }
            }
            assert_eq!((packets, emitted), (0, 0));
            assert_eq!(
                g.counters().clcws,
                before.clcws,
                "a refused frame's CLCW was used"
            );
            assert_eq!(g.extract_counters(), &Default::default());
            false
        }
    }
}

/// [`check_secured_tm_frame`] of the first 256 of `bytes` (when there are that many) made to
/// pass the frame checks' first gates: spacecraft 0x101, segment length ID 11, the FECF
/// written over the rest (version, VC, OCF flag and pointer left as the octets have them, so
/// that each check stays reachable); then SDLS's checks see arbitrary octets.
pub fn check_secured_tm_frame_resealed(bytes: &[u8]) -> bool {
    let Some(head) = bytes.get(..TM_FRAME_LEN) else {
        return check_secured_tm_frame(bytes);
    };
    let mut f = [0u8; TM_FRAME_LEN];
    f.copy_from_slice(head);
    f[0] = (f[0] & 0xc0) | 0x10;
    f[1] = (f[1] & 0x0f) | 0x10;
    f[4] |= 0x18;
    crate::link_tm::reseal(&mut f);
    check_secured_tm_frame(&f)
}
