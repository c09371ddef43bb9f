//! The properties of COP-1 (`mmic::link`: the CLCW, FARM-1, FOP-1), shared by the harnesses
//! of `tests/harnesses/link_cop.rs` and the fuzz targets `link_clcw` and `link_cop`: plain
//! functions that panic when a property fails.

use mmic::link::clcw::{Clcw, ClcwVcid};
use mmic::link::farm::{Farm, FarmEvent, FarmState, FarmWindow, Verdict};
use mmic::link::fop::{Directive, Fop, FopConfig, FopOutput, FopState, FrameData, TimeoutType};
use mmic::link::{ControlCommand, FrameKind};

/// FOP-1's outputs of one step (no allocation: this crate is `no_std`).
#[derive(Default)]
struct Outputs {
    items: [Option<FopOutput<u8>>; 32],
    len: usize,
}

impl Outputs {
    fn push(&mut self, o: FopOutput<u8>) {
        assert!(self.len < 32, "more than 32 outputs in one step");
        self.items[self.len] = Some(o);
        self.len += 1;
    }

    fn iter(&self) -> impl Iterator<Item = &FopOutput<u8>> {
        self.items[..self.len].iter().flatten()
    }
}

/// One FARM-1 event from three octets: a selector, an N(S) (or V*(R)) and the buffer flag.
pub fn farm_event(sel: u8, ns: u8, buffer_ready: bool) -> FarmEvent {
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

/// FARM-1 takes each AD frame at most once and in order (the property of the harness
/// `farm_accepts_each_frame_once_in_order`): every accepted AD frame has N(S) = V(R), so the
/// accepted N(S) run without gap or repeat until a Set V(R) starts a new run; V(R) moves only
/// so; no AD frame is accepted in Wait or Lockout or without a buffer; the CLCW reports the
/// state and round-trips. `w` is made a legal window (even, 2..=254); each event is
/// [`farm_event`] of its three octets.
pub fn check_farm_events(w: u8, evs: &[(u8, u8, bool)]) {
    let width = (w % 127 + 1) * 2; // 2..=254, even
    let window = FarmWindow::new(width).expect("an even width in 2..=254");
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
pub fn check_clcw_word(w: u32) {
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

/// One FOP-1 input from two octets: a selector (requests, CLCWs around NN(R), time, T1's
/// expiry, directives, a BD frame, the window) and a value.
fn fop_step(fop: &mut Fop<u8, 4>, now: &mut u32, sel: u8, v: u8, out: &mut Outputs) {
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

/// FOP-1 keeps its books whatever arrives (the property of the harness
/// `fop_keeps_its_window_and_confirms_in_order`): new AD frames numbered V(S) in sequence;
/// every AD frame sent lies in NN(R)..V(S); confirmations in order from NN(R), each once;
/// V(S) − NN(R) is the sent queue (≤ K) while the service runs; nothing outstanding after an
/// alert or while initialising; with `restart_t1_after_wait`, T1 runs while frames are
/// outstanding outside Retransmit with Wait. `t`'s bits pick the timeout type (bit 0), whether
/// the service starts running (bit 1) and the restart (bit 2); each input is a selector and a
/// value (see the harness).
pub fn check_fop_inputs(t: u8, inputs: &[(u8, u8)]) {
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
    let mut out = Outputs::default();
    if t & 2 == 0 {
        fop.directive(Directive::InitiateWithoutClcw, now, &mut |o| out.push(o));
    }
    for &(sel, v) in inputs {
        let (nnr, vs) = (fop.nnr(), fop.vs());
        out = Outputs::default();
        fop_step(&mut fop, &mut now, sel, v, &mut out);
        let mut confirmed = nnr;
        let mut new_ns = vs;
        let stopped = out
            .iter()
            .any(|o| matches!(o, FopOutput::Alert(_) | FopOutput::Suspended));
        for o in out.iter() {
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
                // proofs/tests/protocol/cop1.rs, case d).
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
