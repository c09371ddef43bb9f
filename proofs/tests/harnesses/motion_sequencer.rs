//! The primitive sequencer under arbitrary signals and clock jumps (wrap included): the robot
//! always holds the structure with at least one closed gripper, the holding side's gripper never
//! opens, and after a timeout the targets never change again. Random under `cargo test`,
//! fuzzed under `cargo bolero test`, a proof over 8-tick sequences under `cargo kani --tests`.

use mmic::command::ServoTarget;
use mmic::motion::sequencer::{Config, Feedback, Sequencer, Status, Targets};
use mmic::motion::{map, State};
use mmic::units::{PerSide, Side};

const TICKS: usize = 8;

#[test]
#[cfg_attr(kani, kani::proof, kani::unwind(10))]
fn sequencer_always_holds_with_one_closed_gripper() {
    bolero::check!()
        .with_type::<(u8, u8, u32, [(u8, u16); TICKS])>()
        .for_each(|(pf, pt, start, ticks)| {
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
        });
}
