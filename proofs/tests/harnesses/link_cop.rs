//! COP-1 of the space data link (`mmic::link`): FARM-1 over any sequence of frames and
//! events, FOP-1 over any sequence of requests, CLCWs and timer expiries, and the CLCW's
//! parse/emit. Under `cargo test`: an exhaustive part over every short sequence from a
//! distinguished alphabet, then sampled inputs; `cargo bolero test`: fuzzing; `cargo kani
//! --tests`: proofs over all inputs of the fixed length (Kani not installed here: not run).

use mmic::link::clcw::{Clcw, ClcwVcid};
use mmic::link::farm::{Farm, FarmEvent, FarmState, FarmWindow, Verdict};
use mmic::link::fop::{Directive, Fop, FopConfig, FopOutput, FopState, FrameData, TimeoutType};
use mmic::link::{ControlCommand, FrameKind};

/// Events per sampled (and Kani) run.
const N: usize = 12;

/// One FARM-1 event from three octets: a selector, an N(S) (or V*(R)) and the buffer flag.
fn farm_event(sel: u8, ns: u8, buffer_ready: bool) -> FarmEvent {
    match sel % 8 {
        0..=3 => FarmEvent::Ad { ns, buffer_ready },
        4 => FarmEvent::Bd,
        5 => FarmEvent::Bc(if buffer_ready {
            ControlCommand::Unlock
        } else {
            ControlCommand::SetVr(ns)
        }),
        6 => FarmEvent::Invalid,
        _ => FarmEvent::BufferRelease,
    }
}

/// The distinguished alphabet of the exhaustive part (17 events, window W = 20, V(R) from 0):
/// AD frames with N(S) 0, 1, 2, 3 (expected, ahead, behind), 11 (the positive window's edge
/// from V(R) 1 and 2) and 200 (the lockout area), each with and without a buffer; a BD frame;
/// Unlock; Set V(R) to 1; an invalid frame; a buffer release.
const ALPHABET: [(u8, u8, bool); 17] = [
    (0, 0, true),
    (0, 0, false),
    (0, 1, true),
    (0, 1, false),
    (0, 2, true),
    (0, 2, false),
    (0, 3, true),
    (0, 3, false),
    (0, 11, true),
    (0, 11, false),
    (0, 200, true),
    (0, 200, false),
    (4, 0, true),
    (5, 0, true),
    (5, 1, false),
    (6, 0, true),
    (7, 0, true),
];

/// FARM-1 takes each AD frame at most once and in order: every accepted AD frame has
/// N(S) = V(R) (then V(R) + 1), so the accepted N(S) run 0, 1, 2, … without gap or repeat
/// until a Set V(R) starts a new run at V*(R); V(R) moves only so; no AD frame is accepted in
/// Wait or Lockout; the CLCW reports the state (Lockout flag ⇔ S3, Wait flag in S2, Wait ⇒
/// Retransmit, report value V(R)).
///
/// Under `cargo test`: exhaustively, every sequence of 5 events of [`ALPHABET`] (17^5); then
/// sampled sequences of 12 events with any N(S) and V*(R), from any window.
#[test]
#[cfg_attr(kani, kani::proof, kani::unwind(14))]
fn farm_accepts_each_frame_once_in_order() {
    #[cfg(not(any(kani, fuzzing)))]
    {
        let name = "farm_accepts_each_frame_once_in_order";
        crate::ledger::exhaustive(
            name,
            17u64.pow(5),
            crate::ledger::seq::<_, 5>(0usize..17),
            |ks| {
                let evs: [(u8, u8, bool); 5] = core::array::from_fn(|i| ALPHABET[ks[i]]);
                farm_once_in_order(20, &evs);
            },
        );
        crate::ledger::sampled::<(u8, [(u8, u8, bool); N])>(name, 200_000, |(w, evs)| {
            farm_once_in_order(*w, evs)
        });
        return;
    }
    #[allow(unreachable_code)]
    bolero::check!()
        .with_type::<(u8, [(u8, u8, bool); N])>()
        .for_each(|(w, evs)| farm_once_in_order(*w, evs));
}

/// The property of [`farm_accepts_each_frame_once_in_order`]; `w` is made a legal window.
fn farm_once_in_order(w: u8, evs: &[(u8, u8, bool)]) {
    let width = (w % 127 + 1) * 2; // 2..=254, even
    let Ok(window) = FarmWindow::new(width) else {
        panic!("window {width}")
    };
    let mut farm = Farm::new(window);
    let mut next: u8 = 0; // the model's V(R)
    let mut run_len: u16 = 0; // AD frames accepted since the run began
    for &(sel, ns, flag) in evs {
        let ev = farm_event(sel, ns, flag);
        let before = farm.state();
        let v = farm.step(ev);
        match (ev, v) {
            (FarmEvent::Ad { ns, buffer_ready }, Verdict::Accept) => {
                assert_eq!(before, FarmState::Open, "AD accepted outside Open");
                assert!(buffer_ready, "AD accepted without a buffer");
                assert_eq!(ns, next, "AD accepted out of order");
                next = next.wrapping_add(1);
                run_len += 1;
                assert!(run_len < 256, "a run never repeats an N(S)");
            }
            (FarmEvent::Ad { .. }, Verdict::Discard(_)) => {}
            (FarmEvent::Bd, Verdict::Accept) => {}
            (
                FarmEvent::Bc(ControlCommand::SetVr(x)),
                Verdict::Control {
                    executed: true,
                    command,
                },
            ) => {
                assert_eq!(command, ControlCommand::SetVr(x));
                assert_ne!(before, FarmState::Lockout, "Set V(R) obeyed in Lockout");
                next = x;
                run_len = 0;
            }
            (FarmEvent::Bc(c), Verdict::Control { command, executed }) => {
                assert_eq!(command, c);
                assert!(executed || before == FarmState::Lockout);
            }
            (FarmEvent::Invalid, Verdict::Discard(_)) => {}
            (FarmEvent::BufferRelease, Verdict::Released) => {}
            other => panic!("verdict {other:?}"),
        }
        assert_eq!(
            farm.vr(),
            next,
            "V(R) moved other than by an accept or Set V(R)"
        );
        let c = farm.clcw(ClcwVcid::ZERO, false, false);
        assert_eq!(c.report_value, farm.vr());
        assert_eq!(c.lockout, farm.state() == FarmState::Lockout);
        assert!(farm.state() != FarmState::Wait || c.wait);
        assert!(farm.state() != FarmState::Open || !c.wait);
        assert!(!c.wait || c.retransmit, "Wait comes with Retransmit");
        assert_eq!(Clcw::parse(&c.emit()), Ok(c));
    }
}

/// The CLCW's verdict on any 32-bit word, from the bit table of 232.0-B-4 §4.2 (the checks in
/// order: control word type, version, COP in effect, spare bits): refused by the first that
/// fails, else parsed to fields that emit the same word.
fn clcw_verdict(w: u32) {
    let expected = if w >> 31 != 0 {
        Some("control-word-type")
    } else if (w >> 29) & 3 != 0 {
        Some("clcw-version")
    } else if (w >> 24) & 3 != 1 {
        Some("cop-in-effect")
    } else if w & 0x0003_0100 != 0 {
        Some("reserved-spare")
    } else {
        None
    };
    let got = Clcw::parse(&w.to_be_bytes());
    assert_eq!(got.err().map(|e| e.name()), expected, "{w:#010x}");
    if let Ok(c) = got {
        assert_eq!(c.emit(), w.to_be_bytes());
        assert_eq!(c.report_value as u32, w & 0xff);
        assert_eq!(c.vcid.get() as u32, (w >> 18) & 0x3f);
        assert_eq!(c.status.get() as u32, (w >> 26) & 7);
        assert_eq!(c.farm_b_counter.get() as u32, (w >> 9) & 3);
        let flags = [
            c.no_rf_available,
            c.no_bit_lock,
            c.lockout,
            c.wait,
            c.retransmit,
        ];
        for (i, f) in flags.into_iter().enumerate() {
            assert_eq!(f, (w >> (15 - i)) & 1 == 1, "flag {i} of {w:#010x}");
        }
    }
}

/// `Clcw::parse` of any four octets gives the verdict of the bit table (check by name, in
/// order); what it accepts emits back to the same octets, field by field where the table
/// puts them.
///
/// Under `cargo test`: exhaustively, every value of octets 0 and 2 (type, version, status,
/// COP; the flags, FARM-B counter and spare bits) with octets 1 and 3 each 0x00, 0xa5 and
/// 0xff; then sampled words.
#[test]
#[cfg_attr(kani, kani::proof, kani::unwind(8))]
fn clcw_round_trip() {
    #[cfg(not(any(kani, fuzzing)))]
    {
        let name = "clcw_round_trip";
        crate::ledger::exhaustive(
            name,
            65_536 * 3,
            (bolero::produce::<u8>(), bolero::produce::<u8>(), 0usize..3),
            |&(o0, o2, k)| {
                let o13 = [0x00u32, 0xa5, 0xff][k];
                clcw_verdict(((o0 as u32) << 24) | (o13 << 16) | ((o2 as u32) << 8) | o13)
            },
        );
        crate::ledger::sampled::<u32>(name, 200_000, |w| clcw_verdict(*w));
        return;
    }
    #[allow(unreachable_code)]
    bolero::check!()
        .with_type::<u32>()
        .for_each(|w| clcw_verdict(*w));
}

/// One FOP-1 input from two octets: a selector and a value.
fn fop_step(fop: &mut Fop<u8, 4>, now: &mut u32, sel: u8, v: u8, out: &mut Vec<FopOutput<u8>>) {
    let mut push = |o| out.push(o);
    match sel % 10 {
        0 | 1 => {
            let _ = fop.transfer_ad(v, *now, &mut push);
        }
        2..=4 => {
            // A CLCW: N(R) near NN(R), flags from v's high bits.
            let c = Clcw {
                report_value: fop.nnr().wrapping_add(v % 8).wrapping_sub(1),
                retransmit: v & 0x10 != 0,
                wait: v & 0x20 != 0,
                lockout: v & 0xc0 == 0xc0,
                ..Clcw::default()
            };
            fop.clcw(&c, *now, &mut push);
        }
        5 => {
            *now = now.wrapping_add(v as u32 * 10);
            fop.tick(*now, &mut push);
        }
        6 => fop.expire_timer(*now, &mut push),
        7 => {
            let d = match v % 8 {
                0 => Directive::InitiateWithoutClcw,
                1 => Directive::InitiateWithClcw,
                2 => Directive::InitiateWithUnlock,
                3 => Directive::InitiateWithSetVr(v),
                4 => Directive::Terminate,
                5 => Directive::Resume,
                6 => Directive::SetVs(v),
                _ => Directive::SetTxLimit(v % 4),
            };
            fop.directive(d, *now, &mut push);
        }
        8 => fop.transfer_bd(v, &mut push),
        _ => {
            fop.directive(Directive::SetWindow(v % 6), *now, &mut push);
        }
    }
}

/// FOP-1 keeps its books whatever arrives: at most K frames unacknowledged; V(S) − NN(R) is
/// the sent queue's length while the service runs; new AD frames go out numbered V(S) in
/// sequence; every AD frame transmitted lies in NN(R)..V(S); frames are confirmed in order
/// N(S) = NN(R), NN(R) + 1, … each once; an alert or a terminate leaves nothing outstanding;
/// T1 runs whenever frames are unacknowledged in Active or Retransmit without Wait.
///
/// Under `cargo test`: exhaustively, every sequence of 5 inputs of 20 (requests, CLCWs with
/// and without each flag at several N(R), T1's expiry, the initiate directives, terminate);
/// then sampled sequences of 12 of any inputs.
#[test]
#[cfg_attr(kani, kani::proof, kani::unwind(14))]
fn fop_keeps_its_window_and_confirms_in_order() {
    #[cfg(not(any(kani, fuzzing)))]
    {
        const A: [(u8, u8); 20] = [
            (0, 1),    // request
            (0, 2),    // request
            (2, 1),    // CLCW N(R) = NN(R)
            (2, 2),    // N(R) = NN(R) + 1
            (2, 3),    // N(R) = NN(R) + 2
            (2, 0),    // N(R) = NN(R) − 1
            (2, 0x11), // Retransmit, N(R) = NN(R)
            (2, 0x12), // Retransmit, N(R) = NN(R) + 1
            (2, 0x31), // Retransmit and Wait
            (2, 0x21), // Wait
            (2, 0xc1), // Lockout
            (6, 0),    // T1 expires
            (5, 200),  // 2 s later
            (7, 0),    // initiate without CLCW
            (7, 1),    // initiate with CLCW
            (7, 2),    // initiate with Unlock
            (7, 3),    // initiate with Set V(R) 3
            (7, 4),    // terminate
            (7, 5),    // resume
            (8, 9),    // BD frame
        ];
        let name = "fop_keeps_its_window_and_confirms_in_order";
        crate::ledger::exhaustive(
            name,
            20u64.pow(5),
            crate::ledger::seq::<_, 5>(0usize..20),
            |ks| {
                let inputs: [(u8, u8); 5] = core::array::from_fn(|i| A[ks[i]]);
                fop_books(0, &inputs);
            },
        );
        crate::ledger::sampled::<(u8, [(u8, u8); N])>(name, 200_000, |(t, inputs)| {
            fop_books(*t, inputs)
        });
        return;
    }
    #[allow(unreachable_code)]
    bolero::check!()
        .with_type::<(u8, [(u8, u8); N])>()
        .for_each(|(t, inputs)| fop_books(*t, inputs));
}

/// The property of [`fop_keeps_its_window_and_confirms_in_order`]; `t` picks the timeout
/// type and whether the service starts running.
fn fop_books(t: u8, inputs: &[(u8, u8)]) {
    let config = FopConfig {
        window: 3,
        t1_ms: 1000,
        tx_limit: 3,
        timeout_type: if t & 1 == 0 {
            TimeoutType::Alert
        } else {
            TimeoutType::Suspend
        },
        restart_t1_after_wait: t & 4 == 0,
    };
    let mut fop: Fop<u8, 4> = Fop::new(config);
    let mut now = 0u32;
    let mut out = Vec::new();
    if t & 2 == 0 {
        fop.directive(Directive::InitiateWithoutClcw, now, &mut |o| out.push(o));
    }
    for &(sel, v) in inputs {
        let (nnr, vs) = (fop.nnr(), fop.vs());
        out.clear();
        fop_step(&mut fop, &mut now, sel, v, &mut out);
        let mut confirmed = nnr;
        let mut new_ns = vs;
        let stopped = out
            .iter()
            .any(|o| matches!(o, FopOutput::Alert(_) | FopOutput::Suspended));
        for o in &out {
            match *o {
                FopOutput::Transmit(f) => match (f.kind, f.data) {
                    (FrameKind::Ad, FrameData::Fdu(_)) => {
                        // A first transmission takes the next V(S); a retransmission was
                        // outstanding.
                        if f.ns.wrapping_sub(nnr) >= vs.wrapping_sub(nnr) {
                            assert_eq!(f.ns, new_ns, "a new AD frame is numbered V(S)");
                            new_ns = new_ns.wrapping_add(1);
                        }
                        if !stopped {
                            let d = f.ns.wrapping_sub(fop.nnr());
                            assert!(
                                d < fop.vs().wrapping_sub(fop.nnr()),
                                "AD frame {} outside NN(R)..V(S)",
                                f.ns
                            );
                        }
                    }
                    (FrameKind::Bc, FrameData::Control(_)) => {}
                    (FrameKind::Bd, FrameData::Fdu(_)) => {}
                    other => panic!("frame {other:?}"),
                },
                FopOutput::Confirmed { ns } => {
                    assert_eq!(ns, confirmed, "confirmed out of order");
                    confirmed = confirmed.wrapping_add(1);
                }
                _ => {}
            }
        }
        if new_ns != vs {
            assert_eq!(fop.vs(), new_ns, "V(S) counts the new frames");
        }
        if confirmed != nnr {
            assert_eq!(fop.nnr(), confirmed, "NN(R) is past the confirmed frames");
        }
        let outstanding = fop.vs().wrapping_sub(fop.nnr()) as usize;
        assert!(fop.sent_len() <= 4);
        match fop.state() {
            FopState::Active | FopState::RetransmitWithoutWait | FopState::RetransmitWithWait => {
                assert_eq!(
                    outstanding,
                    fop.sent_len(),
                    "V(S) − NN(R) is the sent queue"
                );
                assert!(outstanding <= 4);
                // With `restart_t1_after_wait` T1 runs while frames are outstanding outside
                // Retransmit with Wait (without it, leaving that state can leave T1 stopped:
                // host/tests/protocol/cop1.rs, case d).
                if fop.sent_len() > 0 && fop.state() != FopState::RetransmitWithWait && t & 4 == 0 {
                    assert!(
                        fop.timer_deadline().is_some(),
                        "frames outstanding, T1 stopped"
                    );
                }
            }
            FopState::Initial => {
                if fop.suspend_state() == 0 {
                    assert_eq!(fop.sent_len(), 0, "nothing outstanding after an alert");
                    assert!(!fop.waiting());
                }
            }
            FopState::InitialisingWithoutBc | FopState::InitialisingWithBc => {
                assert_eq!(fop.sent_len(), 0);
            }
        }
    }
}
