//! The bolter state machines under arbitrary inputs: any order bytes, any bolter current and
//! home switch, any side-B report (corrupted, stale or forged), any tick times with clock wrap.
//! Random under `cargo test`, Kani-ready (`cargo kani --tests`: proofs over a few ticks; not run
//! here).
//!
//! - `BolterSide`: never panics; reports exactly the order it adopted and the mux lines of that
//!   pair; drives the motor only while its step is neither ended nor timed out; a current-sensed
//!   step whose end signal never came is timed out once more than its limit has elapsed; while
//!   a step runs, its end flag latches exactly when I_bo ≥ the step's threshold (descents: the
//!   push threshold; Rotate: the lock threshold) or, for the home flag, the switch is closed,
//!   and no current latches anything in a step that is not current-sensed. The current is
//!   drawn mostly one mA either side of a threshold, where an off-by-one would show.
//! - `Coordinator`: never panics; while running, the attempt is 1..=3 and the heartbeat's
//!   attempt byte equals it; every new sequence number comes with an order whose content
//!   differs from the previous one (the side executors' resend filter relies on it); a job ends
//!   in Done, BoltingFailure or MotionTimeout (side B never reported) only, and stays ended.
//!
//! The sequence-level protocol (lossy links, every interleaving) is model-checked exhaustively
//! in `tests/control/bolter_handshake.rs`.

use mmic::bolter::{
    BolterDirection, BolterSide, BolterStep, Config, Coordinator, Drive, Job, MuxLines, Sensed,
    Status,
};
use mmic::command::{BolterPair, Fasteners};
use mmic::faults::Fault;
use mmic::wire::b_command::BolterOrder;
use mmic::wire::internal_heartbeat::BolterAux;

#[cfg(not(kani))]
const TICKS: usize = 24;
#[cfg(kani)]
const TICKS: usize = 6;

fn order_from(bytes: (u8, u8, u8)) -> Option<BolterOrder> {
    Some(BolterOrder {
        pair: BolterPair::from_number(bytes.0 % 5)?,
        direction: BolterDirection::from_wire(bytes.1 % 3)?,
        step: BolterStep::from_wire(bytes.2 % 9)?,
    })
}

fn aux_from(b: (u8, u8, u8, u8, u8)) -> BolterAux {
    let o = order_from((b.0, b.1, b.2));
    BolterAux {
        step: o.map(|o| o.step),
        seq: b.3,
        pair: o.map(|o| o.pair),
        direction: o.map(|o| o.direction),
        threshold_reached: b.4 & 1 != 0,
        locked: b.4 & 2 != 0,
        timed_out: b.4 & 4 != 0,
        at_home: b.4 & 8 != 0,
        mux: MuxLines::from_wire(b.4 >> 4 & 3).unwrap_or_default(),
    }
}

/// The bolter current of one tick: `sel` picks one mA below, at, or one mA above the push or
/// the lock threshold, or the arbitrary `raw`.
fn current(cfg: &mmic::bolter::SideConfig, sel: u8, raw: u16) -> u16 {
    let t = if sel & 1 == 0 {
        cfg.push_threshold_ma
    } else {
        cfg.lock_threshold_ma
    };
    match sel >> 1 & 3 {
        0 => t.saturating_sub(1),
        1 => t,
        2 => t.saturating_add(1),
        _ => raw,
    }
}

/// Under `cargo test`: exhaustively, every order the generator's bytes distinguish (pair
/// byte 0..5, direction byte 0..3, step byte 0..9: 135, the invalid ones included) given at
/// the first tick from a clock 1000 ms before the u32 wrap, then 2 ticks each with every
/// current selector (one mA below, at, one above the push or the lock threshold, or 0 mA) ×
/// home switch, after 0, 4000 or 4001 ms (the sensed-step limit and one past); then sampled
/// inputs.
// req: P5.11
#[test]
#[cfg_attr(kani, kani::proof, kani::unwind(8))]
fn bolter_side_reports_what_it_runs() {
    #[cfg(not(any(kani, fuzzing)))]
    {
        const DT: [u16; 3] = [0, 4000, 4001];
        let name = "bolter_side_reports_what_it_runs";
        crate::ledger::exhaustive(
            name,
            135 * 16 * (16 * 3) * (16 * 3),
            (
                (0u8..5, 0u8..3, 0u8..9),
                0u8..16,
                crate::ledger::seq::<_, 2>((0u8..16, 0usize..3)),
            ),
            |&(order, sig, ticks)| {
                let events = [
                    (true, 1, order, sig, 0, 0),
                    (false, 0, (0, 0, 0), ticks[0].0, 0, DT[ticks[0].1]),
                    (false, 0, (0, 0, 0), ticks[1].0, 0, DT[ticks[1].1]),
                ];
                bolter_side(u32::MAX - 1000, &events);
            },
        );
        crate::ledger::sampled::<(u32, [(bool, u8, (u8, u8, u8), u8, u16, u16); TICKS])>(
            name,
            100_000,
            |(t0, events)| bolter_side(*t0, events),
        );
        return;
    }
    #[allow(unreachable_code)]
    bolero::check!()
        .with_type::<(u32, [(bool, u8, (u8, u8, u8), u8, u16, u16); TICKS])>()
        .for_each(|(t0, events)| bolter_side(*t0, events));
}

/// The property of [`bolter_side_reports_what_it_runs`].
#[allow(clippy::type_complexity)]
fn bolter_side(t0: u32, events: &[(bool, u8, (u8, u8, u8), u8, u16, u16)]) {
    let t0 = &t0;
    let cfg = mmic::bolter::Config::default().side;
    let mut side = BolterSide::new();
    let mut now = *t0;
    let mut adopted: Option<(u8, BolterOrder)> = None;
    let mut since = now;
    for &(new_order, seq, bytes, sig, raw, dt) in events.iter() {
        now = now.wrapping_add(dt as u32);
        if new_order {
            let o = order_from(bytes);
            if adopted.map(|(_, a)| a) != o {
                adopted = o.map(|o| (seq, o));
                since = now;
            }
            side.order(seq, o, now);
        }
        let s = Sensed {
            i_bo: current(&cfg, sig, raw),
            at_home: sig & 8 != 0,
        };
        let before = side.aux();
        let running = side.drive() != Drive::Idle;
        side.tick(&cfg, now, s);
        let aux = side.aux();
        assert_eq!(aux.step, adopted.map(|(_, o)| o.step));
        assert_eq!(aux.seq, adopted.map_or(0, |(s, _)| s));
        assert_eq!(aux.pair, adopted.map(|(_, o)| o.pair));
        assert_eq!(aux.direction, adopted.map(|(_, o)| o.direction));
        assert_eq!(
            aux.mux,
            adopted.map_or(MuxLines::default(), |(_, o)| MuxLines::for_pair(o.pair))
        );
        let Some((_, o)) = adopted else {
            assert_eq!(side.drive(), Drive::Idle);
            continue;
        };
        // The decision: while the step runs, a flag latches exactly on its reading;
        // once the step has ended or timed out, nothing changes.
        let descent = matches!(o.step, BolterStep::Descend | BolterStep::DescendEngage);
        let rotate = o.step == BolterStep::Rotate;
        let (push, lock) = (cfg.push_threshold_ma, cfg.lock_threshold_ma);
        let latch = |was: bool, now: bool| was || (running && now);
        assert_eq!(
            aux.threshold_reached,
            latch(before.threshold_reached, descent && s.i_bo >= push),
            "push threshold {push} mA, I_bo {} mA in {:?}",
            s.i_bo,
            o.step
        );
        assert_eq!(
            aux.locked,
            latch(before.locked, rotate && s.i_bo >= lock),
            "lock threshold {lock} mA, I_bo {} mA in {:?}",
            s.i_bo,
            o.step
        );
        assert_eq!(aux.at_home, latch(before.at_home, s.at_home));
        if !descent {
            assert!(!aux.threshold_reached, "push flag outside a descent");
        }
        if !rotate {
            assert!(!aux.locked, "lock flag outside Rotate");
        }
        let ended = match o.step {
            BolterStep::Descend | BolterStep::DescendEngage => aux.threshold_reached,
            BolterStep::Rotate => aux.locked,
            BolterStep::Done | BolterStep::Failed => true,
            _ => aux.at_home,
        };
        assert_eq!(
            side.drive() == Drive::Idle,
            ended || aux.timed_out,
            "motor driven after the step ended, or idle while it runs: {aux:?}"
        );
        let sensed = descent || rotate;
        // Every tick here is at most 65,535 ms after the last, so the elapsed total is
        // exact while it stays below the clock's half range.
        if sensed && !ended && now.wrapping_sub(since) > cfg.sensed_ms {
            assert!(aux.timed_out, "sensed step past its limit not timed out");
        }
        assert!(
            !(aux.timed_out && ended),
            "a timeout with the end signal latched"
        );
    }
}

/// Under `cargo test`: exhaustively, every job (4 pairs and all fasteners × bolt and unbolt)
/// from a clock 1000 ms before the u32 wrap, with every sequence of 9 ticks over 4 letters:
/// both sides report the current order ended, side A reports it timed out, no report from B
/// after 5001 ms (past the 5000 ms motion limit), reports for no order; long enough for a pair
/// to succeed, fail an attempt, and for a job to fail or time out; then sampled inputs.
// req: P5.9
#[test]
#[cfg_attr(kani, kani::proof, kani::unwind(8))]
fn coordinator_bounded_and_orders_change() {
    #[cfg(not(any(kani, fuzzing)))]
    {
        // (sel, dt): 0 ended, 1 A timed out, 3 B silent (5001 ms), 2 arbitrary (zero) reports.
        const LETTER: [(u8, u16); 4] = [(0, 0), (1, 0), (3, 5001), (2, 0)];
        let name = "coordinator_bounded_and_orders_change";
        crate::ledger::exhaustive(
            name,
            10 * 4u64.pow(9),
            (
                0u8..5,
                bolero::produce::<bool>(),
                crate::ledger::seq::<_, 9>(0usize..4),
            ),
            |&(pair, unbolt, letters)| {
                let ticks =
                    letters.map(|l| ((0, 0, 0, 0, 0), (0, 0, 0, 0, 0), LETTER[l].0, LETTER[l].1));
                coordinator((pair, unbolt, u32::MAX - 1000), &ticks);
            },
        );
        crate::ledger::sampled::<(
            (u8, bool, u32),
            [((u8, u8, u8, u8, u8), (u8, u8, u8, u8, u8), u8, u16); TICKS],
        )>(name, 100_000, |(job, ticks)| coordinator(*job, ticks));
        return;
    }
    #[allow(unreachable_code)]
    bolero::check!()
        .with_type::<(
            (u8, bool, u32),
            [((u8, u8, u8, u8, u8), (u8, u8, u8, u8, u8), u8, u16); TICKS],
        )>()
        .for_each(|(job, ticks)| coordinator(*job, ticks));
}

/// The property of [`coordinator_bounded_and_orders_change`].
#[allow(clippy::type_complexity)]
fn coordinator(
    (pair, unbolt, t0): (u8, bool, u32),
    ticks: &[((u8, u8, u8, u8, u8), (u8, u8, u8, u8, u8), u8, u16)],
) {
    let (pair, unbolt, t0) = (&pair, &unbolt, &t0);
    let cfg = Config::default();
    let mut c = Coordinator::new();
    let fasteners = match BolterPair::from_number(pair % 5) {
        Some(p) => Fasteners::Pair(p),
        None => Fasteners::All,
    };
    let direction = if *unbolt {
        BolterDirection::Unbolt
    } else {
        BolterDirection::Bolt
    };
    let mut now = *t0;
    c.start(
        Job {
            direction,
            fasteners,
        },
        now,
    );
    let mut prev = c.order();
    let mut ended: Option<Status> = None;
    for &(a, b, sel, dt) in ticks.iter() {
        now = now.wrapping_add(dt as u32);
        // The selector picks the reports: 0 both sides report the current order ended,
        // 1 side A reports it timed out, 2 arbitrary (stale, forged) reports, 3 no
        // report from B. Directed this way, random runs reach every attempt.
        let (mut a, mut b) = (aux_from(a), aux_from(b));
        if let (Some((seq, o)), 0 | 1) = (c.order(), sel % 4) {
            for x in [&mut a, &mut b] {
                x.seq = seq;
                x.step = Some(o.step);
                x.pair = Some(o.pair);
                x.direction = Some(o.direction);
                x.threshold_reached = sel % 4 == 0;
                x.locked = sel % 4 == 0;
                x.at_home = sel % 4 == 0;
                x.timed_out = false;
            }
            a.timed_out = sel % 4 == 1;
        }
        let out = c.step(&cfg, now, &a, (sel % 4 != 3).then_some(&b));
        if let Some(e) = ended {
            assert_eq!(out.status, e, "an ended job changed status");
            assert_eq!(out.order, None);
            continue;
        }
        match out.status {
            Status::Running => {
                let (seq, o) = out.order.expect("a running job orders a step");
                assert!((1..=3).contains(&c.attempt()));
                assert_eq!(out.attempt.get(), c.attempt());
                assert_eq!(out.active, Some(o.pair));
                assert_eq!(o.direction, direction);
                assert!(!matches!(o.step, BolterStep::Done | BolterStep::Failed));
                if let Some((pseq, po)) = prev {
                    if pseq != seq {
                        assert_ne!(po, o, "new sequence number, same order");
                        assert_eq!(seq, pseq.wrapping_add(1));
                    } else {
                        assert_eq!(po, o, "order changed without a new number");
                    }
                }
                prev = out.order;
            }
            Status::Done
            | Status::Failed(Fault::BoltingFailure)
            | Status::Failed(Fault::MotionTimeout) => {
                assert_eq!(out.order, None);
                assert_eq!(out.active, None);
                ended = Some(out.status);
            }
            s => panic!("unexpected status {s:?}"),
        }
    }
}
