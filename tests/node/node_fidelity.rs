//! Boards A and B against the paper where one board alone shows it (issue 13, defects 10 and
//! 11; the whole-robot defects are checked in host/tests/fidelity.rs).

use mmic::command::Command;
use mmic::faults::{Fault, Faults};
use mmic::mode::Mode;
use mmic::motion::State;
use mmic::node::robot::board_a::{self, BoardA, Inputs};
use mmic::node::robot::board_b::{self, BoardB};
use mmic::units::{BoardNumber, Electrical};
use mmic::wire::b_command::BCommandRepr;
use mmic::wire::command::CommandRepr;
use mmic::wire::internal_heartbeat::InternalHeartbeatRepr;

/// Defect 10: board B starts with its servos at home, as board A does (it used to start at
/// 1500 µs, so entering Operational drove B's arm and gripper to mid-travel first).
// req: D:b-starts-at-home
#[test]
fn board_b_starts_at_home_like_board_a() {
    let a_cfg = board_a::Config::default();
    let b = BoardB::new(board_b::Config::default());
    let hb = b.report(&board_b::Inputs::default());
    assert_eq!(
        (hb.arm_b_now, hb.arm_b_target),
        (a_cfg.arm.contracted, a_cfg.arm.contracted)
    );
    assert_eq!(
        (hb.gripper_b_now, hb.gripper_b_target),
        (a_cfg.gripper.extended, a_cfg.gripper.extended)
    );
}

/// Board A in Operational hearing board B report `hb` every 50 ms for `ms` (acknowledging
/// the A->B commands as they come).
fn hearing(mut hb: InternalHeartbeatRepr, ms: u32) -> BoardA {
    let mut a = BoardA::in_state(board_a::Config::default(), State::A);
    let op = CommandRepr {
        board: BoardNumber::ONE,
        command: Command::Mode(Mode::Operational),
        seq: 1,
    };
    for t in (0..ms).step_by(10) {
        let out = a.tick(
            t,
            &Inputs {
                command: (t == 0).then(|| op.to_bytes()),
                from_b: (t % 50 == 0 && t > 0).then(|| hb.to_bytes()),
                ..Inputs::at_home()
            },
        );
        if let Some(c) = out.to_b.and_then(|b| BCommandRepr::parse(&b).ok()) {
            hb.command_received = c.seq;
        }
    }
    a
}

/// Defect 11: board A takes side B's overcurrent verdicts as board B reports them (Table 4
/// bytes 41–43, B's own limits), instead of recomputing them from B's currents: a flag with
/// quiet currents is a fault, and high currents B did not flag are not.
// req: P4.7
#[test]
fn board_a_takes_side_b_overcurrent_as_b_judged_it() {
    let a_cfg = board_a::Config::default();
    let at_rest = InternalHeartbeatRepr {
        arm_b_now: a_cfg.arm.contracted,
        arm_b_target: a_cfg.arm.contracted,
        gripper_b_now: a_cfg.gripper.extended,
        gripper_b_target: a_cfg.gripper.extended,
        electrical_b: Inputs::at_home().electrical,
        arm_contracted: true,
        ..Default::default()
    };
    let quiet = hearing(at_rest, 1_000);
    assert_eq!(
        (quiet.mode(), quiet.faults()),
        (Mode::Operational, Faults::EMPTY)
    );
    let flagged = hearing(
        InternalHeartbeatRepr {
            bolter_overcurrent: true,
            ..at_rest
        },
        1_000,
    );
    assert!(flagged.faults().contains(Fault::BolterOvercurrent));
    assert_eq!(flagged.mode(), Mode::Safed);
    let unflagged = hearing(
        InternalHeartbeatRepr {
            electrical_b: Electrical {
                i_bo: 2_500,
                ..Inputs::at_home().electrical
            },
            ..at_rest
        },
        1_000,
    );
    assert_eq!(unflagged.faults(), Faults::EMPTY, "B did not flag it");
}
