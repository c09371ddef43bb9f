//! Primitive commands name their final state (issue 13, defect 6). From a turn state one
//! primitive reaches two states (spec/motion/ambiguous-primitives.txt); board A used to take
//! the first in Table 5 order, so the second could never be commanded. Here boards A and B run
//! linked, with a small plant (hip servo, arm switches), through every ambiguous pair: the
//! second target is commanded and reached, and a final state the primitive does not reach from
//! where the robot is gets refused without moving anything.

use mmic::command::{Command, PrimitiveMove};
use mmic::mode::Mode;
use mmic::motion::{map, route, Primitive, State};
use mmic::node::robot::board_a::{self, BoardA, Event, Inputs};
use mmic::node::robot::board_b::{self, BoardB};
use mmic::refusal::Refusal;
use mmic::units::{BoardNumber, Electrical, HipAngle, PulseWidth};
use mmic::wire::command::{CommandRepr, COMMAND_LEN};
use mmic::wire::heartbeat::HeartbeatRepr;

const TICK_MS: u32 = 10;
/// Longest a primitive may take: the sequencer's step timeouts (3 s grip, 15 s move, 1 s
/// confirm, 3 s grip) with room to spare.
const PRIMITIVE_MS: u32 = 30_000;

/// Boards A and B linked both ways every tick, and the plant between them: the continuous hip
/// servo (the simulator's gain: 10 × 0.01°/s per µs off 1500) and the arms' contraction
/// switches (closed within 15 µs of the contracted pulse).
struct Rig {
    a: BoardA,
    b: BoardB,
    t: u32,
    seq: u16,
    hip_cdeg: f64,
    hip_pulse: Option<PulseWidth>,
    arm_pulse: [Option<PulseWidth>; 2],
    to_b: Option<[u8; mmic::wire::b_command::B_COMMAND_LEN]>,
    to_a: Option<[u8; mmic::wire::internal_heartbeat::INTERNAL_HEARTBEAT_LEN]>,
}

impl Rig {
    /// Operational in state a, at rest.
    fn new() -> Rig {
        let cfg = board_a::Config::default();
        let mut rig = Rig {
            a: BoardA::in_state(cfg, State::A),
            b: BoardB::with_pose(
                board_b::Config::default(),
                cfg.arm.contracted,
                cfg.gripper.extended,
            ),
            t: 0,
            seq: 0,
            hip_cdeg: f64::from(HipAngle::STRAIGHT.centidegrees()),
            hip_pulse: None,
            arm_pulse: [None; 2],
            to_b: None,
            to_a: None,
        };
        let (refusal, _) = rig.send(Command::Mode(Mode::Operational));
        assert_eq!(refusal, None);
        rig.settle(2_000);
        rig
    }

    fn switch(&self, side: usize) -> bool {
        let contracted = board_a::Config::default().arm.contracted.micros();
        self.arm_pulse[side].is_none_or(|p| p.micros() <= contracted + 15)
    }

    /// One tick of both boards and the plant; board A's events.
    fn tick(&mut self, command: Option<Command>) -> (Option<HeartbeatRepr>, Vec<Event>) {
        let packet = command.map(|command| {
            self.seq += 1;
            CommandRepr {
                board: BoardNumber::ONE,
                command,
                seq: self.seq,
            }
            .to_bytes()
        });
        self.tick_bytes(packet)
    }

    /// One tick with these command bytes, if any.
    fn tick_bytes(
        &mut self,
        packet: Option<[u8; COMMAND_LEN]>,
    ) -> (Option<HeartbeatRepr>, Vec<Event>) {
        self.t += TICK_MS;
        if let Some(p) = self.hip_pulse {
            let speed = (f64::from(p.micros()) - 1500.0) * 10.0;
            self.hip_cdeg =
                (self.hip_cdeg + speed * f64::from(TICK_MS) / 1000.0).rem_euclid(36000.0);
        }
        let out_a = self.a.tick(
            self.t,
            &Inputs {
                command: packet,
                from_b: self.to_a.take(),
                hip: Some(HipAngle::wrapping(self.hip_cdeg as u16)),
                arm_contracted: self.switch(0),
                ..Inputs::at_home()
            },
        );
        let out_b = self.b.tick(
            self.t,
            &board_b::Inputs {
                command: self.to_b.take(),
                electrical: Electrical {
                    v_bat: 12_000,
                    v_reg: 7_400,
                    ..Electrical::default()
                },
                arm_contracted: self.switch(1),
                ..board_b::Inputs::default()
            },
        );
        self.hip_pulse = out_a.hip;
        self.arm_pulse = [out_a.arm, out_b.arm];
        self.to_b = out_a.to_b;
        self.to_a = out_b.heartbeat;
        let hb = out_a.heartbeat.map(|b| HeartbeatRepr::parse(&b).unwrap());
        (hb, out_a.events.iter().copied().collect())
    }

    /// Sends `command` and returns its refusal (from the answering heartbeat) and the events
    /// of that tick.
    fn send(&mut self, command: Command) -> (Option<Refusal>, Vec<Event>) {
        let (hb, events) = self.tick(Some(command));
        let hb = hb.expect("every command is answered");
        assert_eq!(hb.last_seq, self.seq);
        (hb.refusal, events)
    }

    /// Ticks for `ms` without commands; no state may be reached meanwhile.
    fn settle(&mut self, ms: u32) {
        for _ in 0..ms / TICK_MS {
            let (_, events) = self.tick(None);
            assert!(
                !events.iter().any(|e| matches!(e, Event::Reached(_))),
                "{events:?}"
            );
        }
    }

    /// Commands primitive `p` ending in `target`, which board A must accept, run and reach
    /// (and nothing else) with no fault.
    fn primitive(&mut self, p: Primitive, target: State) {
        let from = self.a.state();
        let c = Command::primitive(p, target).unwrap();
        let (refusal, _) = self.send(c);
        assert_eq!(refusal, None, "{from:?} by {p} to {target}");
        for _ in 0..PRIMITIVE_MS / TICK_MS {
            let (_, events) = self.tick(None);
            let reached: Vec<State> = events
                .iter()
                .filter_map(|e| match e {
                    Event::Reached(s) => Some(*s),
                    _ => None,
                })
                .collect();
            if !reached.is_empty() {
                assert_eq!(reached, [target], "{from:?} by {p}");
                assert_eq!(self.a.state(), Some(target));
                assert!(self.a.faults().is_empty(), "{:?}", self.a.faults());
                assert_eq!(self.a.mode(), Mode::Operational);
                // Rest (the servos settle, the next command is not refused as busy).
                self.settle(1_000);
                return;
            }
        }
        panic!(
            "{from:?} by {p} to {target}: not reached in {PRIMITIVE_MS} ms (faults {:?})",
            self.a.faults()
        );
    }

    /// Commands primitive `p` ending in `target`, which board A must refuse as not the move
    /// from where the robot is: nothing runs, the state stays.
    fn refused(&mut self, p: Primitive, target: State) {
        self.refused_with(p, target, Refusal::InitialStateMismatch);
    }

    /// Commands primitive `p` ending in `target`, which board A must refuse with `why`,
    /// moving nothing and raising no fault.
    fn refused_with(&mut self, p: Primitive, target: State, why: Refusal) {
        let before = self.a.state();
        let (refusal, events) = self.send(Command::primitive(p, target).unwrap());
        assert_eq!(refusal, Some(why), "{before:?} by {p} to {target}");
        assert!(
            events.iter().any(|e| matches!(
                e,
                Event::Executed {
                    refusal: Some(r),
                    ..
                } if *r == why
            )),
            "{events:?}"
        );
        self.settle(500);
        assert!(!self.a.in_motion(), "a refused primitive moved the robot");
        assert_eq!(self.a.state(), before);
        assert!(self.a.faults().is_empty());
    }

    /// From a, primitive by primitive along the shortest plan to `to`.
    fn go_to(&mut self, to: State) {
        let plan = route::lookup(State::A, to);
        for (p, next) in plan.primitives().iter().zip(plan.states()) {
            self.primitive(*p, *next);
        }
        assert_eq!(self.a.state(), Some(to));
    }
}

/// Every ambiguous (state, primitive) pair: the second target, which the old first-match
/// code could never reach, is commanded and run; a final state the primitive reaches only from
/// other states is refused first. Each pair starts from a fresh robot in state a.
// req: T1/primitive, D:primitive-final-state
#[test]
fn every_ambiguous_primitive_reaches_the_final_state_it_names() {
    let mut pairs = 0;
    for (from, p, first, second) in map::ambiguous() {
        let mut rig = Rig::new();
        rig.go_to(from);
        // A final state p reaches, but not from here: refused, nothing moves.
        let wrong = PrimitiveMove::all()
            .find(|m| m.primitive() == p && !m.is_move_from(from))
            .unwrap();
        rig.refused(p, wrong.target());
        // The second target: the move the first match used to shadow.
        rig.primitive(p, second);
        assert_ne!(second, first);
        pairs += 1;
    }
    assert_eq!(pairs, 12);
}

/// The first targets still work, named explicitly, and a primitive with no move from the
/// robot's state at all is refused as before.
#[test]
fn the_first_targets_run_too_and_no_move_is_refused() {
    for (from, p, first, _) in map::ambiguous().filter(|x| x.0 == State::E) {
        let mut rig = Rig::new();
        rig.go_to(from);
        rig.primitive(p, first);
    }
    let mut rig = Rig::new();
    // Primitive 1 (fwdContract) ends in m from d: from a it is no move.
    rig.refused(Primitive::FwdContract, State::M);
    // A primitive in the old layout (byte 8 zero, sealed): no command, refused as an invalid
    // parameter with its sequence number, and nothing moves.
    let mut old = CommandRepr {
        board: BoardNumber::ONE,
        command: Command::primitive(Primitive::BackExtend, State::D).unwrap(),
        seq: 900,
    }
    .to_bytes();
    old[8] = 0;
    let crc = mmic::wire::checksum::crc16(&old[..12]).to_le_bytes();
    old[12..].copy_from_slice(&crc);
    let (hb, _) = rig.tick_bytes(Some(old));
    let hb = hb.expect("ours: answered");
    assert_eq!(
        (hb.last_seq, hb.refusal),
        (900, Some(Refusal::InvalidParameter))
    );
    rig.settle(500);
    assert!(!rig.a.in_motion());
    assert_eq!(rig.a.state(), Some(State::A));
}

/// The geometric model's 12 turns between two right-angle states need a joint the robot does
/// not have (spec/decisions.toml, turn-to-turn-moves): from where each starts, board A refuses
/// it by that name, moves nothing and raises no fault; from another state the same command is
/// a wrong belief of where the robot is, as before. Fails with the map of before issue 24,
/// which ran them with the hip held.
// req: D:turn-to-turn-moves
#[test]
fn a_turn_without_the_hip_is_refused_by_name() {
    use mmic::motion::geometry::{model_moves, turns_without_hip};
    let mut n = 0;
    for (from, to, _, p) in model_moves().filter(|&(f, t, _, _)| turns_without_hip(f, t)) {
        let mut rig = Rig::new();
        rig.go_to(from);
        rig.refused_with(p, to, Refusal::TurnWithoutHip);
        // The robot still moves: back to a by its plan.
        let back = route::lookup(from, State::A);
        for (q, next) in back.primitives().iter().zip(back.states()) {
            rig.primitive(*q, *next);
        }
        n += 1;
    }
    assert_eq!(n, 12);
    // From a, where no such turn starts, the same command is a wrong initial state.
    let (from, to, _, p) = model_moves()
        .find(|&(f, t, _, _)| turns_without_hip(f, t))
        .unwrap();
    assert_ne!(from, State::A);
    Rig::new().refused(p, to);
}
