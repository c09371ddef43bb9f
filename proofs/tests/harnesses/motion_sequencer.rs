//! The primitive sequencer under arbitrary signals and clock jumps (wrap included): the robot
//! always holds the structure with at least one closed gripper, the holding side's gripper never
//! opens, and after a timeout the targets never change again. Random under `cargo test`,
//! fuzzed under `cargo bolero test`, a proof over 8-tick sequences under `cargo kani --tests`.

use mmic::command::ServoTarget;
use mmic::motion::sequencer::{Config, Feedback, Sequencer, Status, Targets};
use mmic::motion::{map, State};
use mmic::units::{PerSide, Side};

const TICKS: usize = 8;

/// Under `cargo test`: exhaustively, every pair of states (all 225; the map's moves run, the
/// others are skipped as by the generator) from 2000 ms before the u32 wrap, and every
/// sequence of 3 ticks over 8 feedback words (none, all, each kind of signal on both sides,
/// all of side A's, all of side B's) × 4 steps (0 ms, and past the 1000 ms confirmation, the
/// 3000 ms gripper and the 15,000 ms move limits); then sampled inputs.
// req: P6.6
#[test]
#[cfg_attr(kani, kani::proof, kani::unwind(10))]
fn sequencer_always_holds_with_one_closed_gripper() {
    #[cfg(not(any(kani, fuzzing)))]
    {
        // Bits: 0-1 arm done A/B, 2-3 gripper done A/B, 4 hip done, 5-6 arm switch A/B.
        const BITS: [u8; 8] = [0, 0x7f, 0x03, 0x0c, 0x10, 0x60, 0x25, 0x4a];
        const DT: [u16; 4] = [0, 1001, 3001, 15001];
        let name = "sequencer_always_holds_with_one_closed_gripper";
        crate::ledger::exhaustive(
            name,
            225 * 32u64.pow(3),
            (
                0u8..15,
                0u8..15,
                crate::ledger::seq::<_, 3>((0usize..8, 0usize..4)),
            ),
            |&(pf, pt, ticks)| {
                sequencer(
                    pf,
                    pt,
                    u32::MAX - 2000,
                    &ticks.map(|(b, d)| (BITS[b], DT[d])),
                );
            },
        );
        crate::ledger::sampled::<(u8, u8, u32, [(u8, u16); TICKS])>(
            name,
            200_000,
            |(pf, pt, start, ticks)| sequencer(*pf, *pt, *start, ticks),
        );
        return;
    }
    #[allow(unreachable_code)]
    bolero::check!()
        .with_type::<(u8, u8, u32, [(u8, u16); TICKS])>()
        .for_each(|(pf, pt, start, ticks)| sequencer(*pf, *pt, *start, ticks));
}

/// The property of [`sequencer_always_holds_with_one_closed_gripper`].
fn sequencer(pf: u8, pt: u8, start: u32, ticks: &[(u8, u16)]) {
    let (pf, pt, start) = (&pf, &pt, &start);
    {
        // Pick the move by index, not by walking `map::moves()`: the walk's 15 × 15 loop
        // would need an unwind bound above 15 under Kani; the only loop left is the ticks.
        let (Some(from), Some(to)) = (
            State::from_index(*pf as usize % 15),
            State::from_index(*pt as usize % 15),
        ) else {
            return;
        };
        if map::primitive(from, to).is_none() {
            return;
        }
        let Ok(mut s) = Sequencer::start(Config::default(), from, to, Targets::home(), *start)
        else {
            panic!("a map move must start");
        };
        let o = if s.side() == Side::A {
            Side::B
        } else {
            Side::A
        };
        let mut now = *start;
        let mut ended: Option<(Status, Targets)> = None;
        for &(bits, dt) in ticks.iter() {
            now = now.wrapping_add(dt as u32);
            let b = |i: u8| bits & (1 << i) != 0;
            let fb = Feedback {
                arm_done: PerSide::new(b(0), b(1)),
                gripper_done: PerSide::new(b(2), b(3)),
                hip_done: b(4),
                arm_switch: PerSide::new(b(5), b(6)),
            };
            let st = s.step(now, &fb);
            let t = s.targets();
            assert!(t.holds());
            assert_eq!(t.gripper[o], ServoTarget::Extend);
            if let Some(e) = ended {
                assert_eq!((st, t), e);
            } else if st != Status::Running {
                ended = Some((st, t));
            }
        }
    }
}
