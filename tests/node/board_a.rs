//! Board A's own effect on the actuators of both sides when a Stop arrives or the robot enters
//! Safed mid-motion (Table 1's Stop, Table 7's Safed: every actuator holds where it is): side
//! A's arm, gripper and hip outputs, side A's bolter and the multiplexer, and what the A→B
//! commands tell board B (stop flag, arm and gripper targets, bolter order) — and, through
//! board B, B's own servo and bolter outputs. Boards A and B are linked tick by tick, at rest in
//! state a and Operational before each motion.

use mmic::bolter::Drive;
use mmic::command::{BolterCommand, Command, ServoTarget};
use mmic::command::{BolterPair, Fasteners};
use mmic::mode::Mode;
use mmic::motion::State;
use mmic::node::board_a::{self, BoardA, Inputs};
use mmic::node::board_b::{self, BoardB};
use mmic::units::{BoardNumber, Electrical, Side};
use mmic::wire::b_command::BCommandRepr;
use mmic::wire::command::CommandRepr;
use mmic::wire::heartbeat::HeartbeatRepr;

struct Rig {
    a: BoardA,
    b: BoardB,
    now: u32,
    seq: u16,
    to_b: Option<[u8; mmic::wire::b_command::B_COMMAND_LEN]>,
    to_a: Option<[u8; mmic::wire::internal_heartbeat::INTERNAL_HEARTBEAT_LEN]>,
    /// The last A→B command sent.
    last_b: Option<BCommandRepr>,
}

/// What both boards drove in one tick.
#[derive(Debug, Clone)]
struct Tick {
    a: board_a::Outputs,
    b: board_b::Outputs,
    hb: Option<HeartbeatRepr>,
}

impl Rig {
    /// Linked, Operational, at rest in state a.
    fn operational() -> Rig {
        let mut r = Rig {
            a: BoardA::in_state(board_a::Config::default(), State::A),
            b: BoardB::with_pose(
                board_b::Config::default(),
                board_a::Config::default().arm.contracted,
                board_a::Config::default().gripper.extended,
            ),
            now: 0,
            seq: 0,
            to_b: None,
            to_a: None,
            last_b: None,
        };
        r.send(Command::Mode(Mode::Operational));
        r.run(150);
        assert_eq!(r.a.mode(), Mode::Operational);
        assert!(!r.a.in_motion() && r.a.faults().is_empty());
        r
    }

    fn tick(&mut self, command: Option<Command>) -> Tick {
        self.now += 10;
        let packet = command.map(|command| {
            self.seq += 1;
            CommandRepr {
                board: BoardNumber::ONE,
                command,
                seq: self.seq,
            }
            .to_bytes()
        });
        let a = self.a.tick(
            self.now,
            &Inputs {
                command: packet,
                from_b: self.to_a,
                ..Inputs::at_home()
            },
        );
        let b = self.b.tick(
            self.now,
            &board_b::Inputs {
                command: self.to_b,
                electrical: Electrical {
                    v_bat: 12_000,
                    v_reg: 7_400,
                    ..Electrical::default()
                },
                arm_contracted: true,
                ..board_b::Inputs::default()
            },
        );
        self.to_b = a.to_b;
        self.to_a = b.heartbeat;
        if let Some(bytes) = a.to_b {
            self.last_b = Some(BCommandRepr::parse(&bytes).unwrap());
        }
        Tick {
            a: a.clone(),
            b,
            hb: a.heartbeat.map(|h| HeartbeatRepr::parse(&h).unwrap()),
        }
    }

    fn send(&mut self, c: Command) -> Tick {
        let t = self.tick(Some(c));
        assert_eq!(t.hb.and_then(|h| h.refusal), None, "{c:?} refused");
        t
    }

    fn run(&mut self, ticks: u32) -> Tick {
        let mut last = self.tick(None);
        for _ in 1..ticks {
            last = self.tick(None);
        }
        last
    }
}

/// After `stopper` mid-motion, for 2 s: every output of both sides stays where it was when
/// the stop arrived, and the A→B command says hold, with B's targets where B is.
fn assert_frozen(r: &mut Rig, at_stop: &Tick, what: &str) {
    let b_cmd = r.last_b.expect("A commands B");
    assert!(b_cmd.stop, "{what}: B told to hold");
    assert_eq!(b_cmd.bolter, None, "{what}: no bolter order to B");
    let held = b_cmd;
    for _ in 0..200 {
        let t = r.tick(None);
        assert_eq!(t.a.arm, at_stop.a.arm, "{what}: arm A moved");
        assert_eq!(t.a.gripper, at_stop.a.gripper, "{what}: gripper A moved");
        assert_eq!(t.a.bolter, Drive::Idle, "{what}: bolter A driven");
        assert_eq!(t.b.bolter, Drive::Idle, "{what}: bolter B driven");
        assert_eq!(t.b.arm, at_stop.b.arm, "{what}: arm B moved");
        assert_eq!(t.b.gripper, at_stop.b.gripper, "{what}: gripper B moved");
        let b_cmd = r.last_b.expect("A commands B");
        assert!(b_cmd.stop, "{what}: B released");
        // The targets A sends B stay put (where B last reported itself when the hold began),
        // and B obeys the hold flag over them.
        assert_eq!(
            (b_cmd.arm_target, b_cmd.gripper_target),
            (held.arm_target, held.gripper_target),
            "{what}: B's targets changed during the hold"
        );
        assert_eq!(b_cmd.bolter, None);
    }
}

fn arm(side: Side, target: ServoTarget) -> Command {
    Command::Arm { side, target }
}

#[test]
fn stop_mid_motion_freezes_both_arms_and_keeps_the_motion_for_reset() {
    for side in [Side::A, Side::B] {
        let mut r = Rig::operational();
        let rest = r.tick(None);
        r.send(arm(side, ServoTarget::Extend));
        r.run(30);
        let moving = r.tick(None);
        let (before, now) = match side {
            Side::A => (rest.a.arm, moving.a.arm),
            Side::B => (rest.b.arm, moving.b.arm),
        };
        assert_ne!(before, now, "arm {side:?} is on its way");
        assert!(r.a.in_motion());
        let at_stop = r.send(Command::Stop);
        // B applies the hold one link period later: take its outputs once it has.
        let at_stop = Tick {
            b: r.run(10).b,
            ..at_stop
        };
        assert!(r.a.paused(), "the stopped motion is kept for Reset");
        assert_frozen(&mut r, &at_stop, &format!("Stop, arm {side:?}"));
        assert_eq!(r.a.mode(), Mode::Operational);
        // Reset resumes it: the arm moves on to its target.
        r.send(Command::Reset);
        let after = r.run(300);
        let (stopped, now) = match side {
            Side::A => (at_stop.a.arm, after.a.arm),
            Side::B => (at_stop.b.arm, after.b.arm),
        };
        assert_ne!(stopped, now, "Reset resumed arm {side:?}");
    }
}

#[test]
fn entering_safed_mid_motion_freezes_both_sides_and_drops_the_motion() {
    for side in [Side::A, Side::B] {
        let mut r = Rig::operational();
        r.send(arm(side, ServoTarget::Extend));
        r.run(30);
        assert!(r.a.in_motion());
        let at_stop = r.send(Command::Mode(Mode::Safed));
        let at_stop = Tick {
            b: r.run(10).b,
            ..at_stop
        };
        assert_eq!(r.a.mode(), Mode::Safed);
        assert!(!r.a.paused(), "a mode change keeps nothing for Reset");
        assert!(at_stop.a.regulator, "Safed keeps the regulator on");
        assert_frozen(&mut r, &at_stop, &format!("Safed, arm {side:?}"));
    }
}

#[test]
fn stop_and_safed_end_a_bolting_job_on_both_sides() {
    for stopper in [Command::Stop, Command::Mode(Mode::Safed)] {
        let mut r = Rig::operational();
        r.send(Command::Bolter(BolterCommand::Bolt(Fasteners::Pair(
            BolterPair::P2,
        ))));
        let running = r.run(20);
        assert_eq!(running.a.bolter, Drive::Down, "bolter A descends");
        assert_eq!(running.b.bolter, Drive::Down, "bolter B descends");
        assert!(r.last_b.unwrap().bolter.is_some());
        let at_stop = r.send(stopper);
        assert_eq!(
            at_stop.a.bolter,
            Drive::Idle,
            "{stopper:?}: bolter A idle at once"
        );
        let at_stop = Tick {
            b: r.run(10).b,
            ..at_stop
        };
        assert_frozen(&mut r, &at_stop, &format!("{stopper:?} during bolting"));
    }
}

#[test]
fn stop_mid_turn_holds_the_hip_where_it_is_read() {
    let mut r = Rig::operational();
    let rest = r.tick(None);
    // The hip reads 180° throughout (the rig's encoder): ordered to 90°, it is driven.
    r.send(Command::Hip(mmic::command::HipTarget::RightAngleCw));
    let turning = r.run(5);
    assert_ne!(turning.a.hip, rest.a.hip, "the hip is driven towards 90°");
    r.send(Command::Stop);
    // Held at its reading: driven as at rest there.
    for _ in 0..50 {
        let t = r.tick(None);
        assert_eq!(t.a.hip, rest.a.hip, "the hip holds at its reading");
    }
}
