//! The opcode encoding, exhaustively: every command round-trips, no two variant classes share
//! an opcode, unused bytes must be zero, range errors name the byte.

use mmic::arbitrary::{for_each_command, for_each_variant_class};
use mmic::command::*;
use mmic::pose::{Primitive, State};
use mmic::units::{HipAngle, PulseWidth};
use mmic::wire::opcode::*;

/// The commands the exhaustive checks below walk, and how many: every command
/// (`for_each_command`), 40,595. Under Miri, which interprets each step some 100x slower
/// (.ci/miri), every opcode class once, at the top of the travel the arm and gripper servos
/// share (2000 µs) and of the hip's circle (359.99°): 61.
fn each_command_checked(visit: impl FnMut(Command)) -> usize {
    if cfg!(miri) {
        let (pw, angle) = (PulseWidth::new(2000), HipAngle::new(HipAngle::TURN - 1));
        for_each_variant_class(pw.unwrap(), angle.unwrap(), visit);
        61
    } else {
        for_each_command(visit);
        // 61 classes; 2 positional arm classes × 1201 widths (the arms' travel,
        // 900..=2100), 2 gripper classes × 1001 (1000..=2000), 36000 angles, 60 primitive
        // commands (8 classes), 84 reconfigurations.
        61 - 4 - 1 - 8 - 1 + 2 * 1201 + 2 * 1001 + 36000 + 60 + (15 * 6 - 6)
    }
}

// req: T1/*
#[test]
fn every_command_round_trips_through_its_encoding() {
    let mut n = 0;
    let expected = each_command_checked(|c| {
        let (id, p) = encode(&c);
        assert_eq!(decode(id, p), Ok(c), "{c:?}");
        n += 1;
    });
    assert_eq!(n, expected);
    assert_eq!(expected, if cfg!(miri) { 61 } else { 40_595 });
}

// req: D:command-sequence-number
#[test]
fn no_command_uses_its_sequence_slot() {
    // The exactly-once sequence number may take `seq_slot(id)`: exhaustive over all commands.
    let mut n = 0;
    let expected = each_command_checked(|c| {
        let (id, p) = encode(&c);
        let at = seq_slot(id).offset();
        assert_eq!((p[at], p[at + 1]), (0, 0), "{c:?}");
        n += 1;
    });
    assert_eq!(n, expected);
}

// req: T1/*, D:opcodes
#[test]
fn opcodes_are_distinct_per_variant_class() {
    let mut seen = [false; 256];
    let mut classes = 0;
    for_each_variant_class(PulseWidth::CENTER, HipAngle::ZERO, |c| {
        let (id, _) = encode(&c);
        assert!(!seen[id as usize], "opcode {id:#04x} used twice");
        seen[id as usize] = true;
        classes += 1;
    });
    assert_eq!(classes, 61);
    // Every other opcode is refused, whatever the parameters.
    for id in 0..=255u8 {
        if !seen[id as usize] {
            assert_eq!(decode(id, [0; 6]), Err(CommandError::UnknownId { id }));
        }
    }
}

// req: P3.13
#[test]
fn unused_parameter_bytes_must_be_zero() {
    for_each_variant_class(PulseWidth::CENTER, HipAngle::ZERO, |c| {
        let (id, p) = encode(&c);
        for i in 0..PARAM_LEN {
            let mut q = p;
            q[i] ^= 0x01;
            // Either the byte was unused (refused as such) or it was a value: then it must
            // decode to a different command or be refused; never to the same command.
            assert_ne!(decode(id, q), Ok(c), "{c:?} byte {i}");
        }
    });
}

// req: P6.4
#[test]
fn range_errors_name_the_byte() {
    let bad = 2501u16.to_le_bytes();
    assert_eq!(
        decode(0x26, [0, 0, 0, 0, bad[0], bad[1]]),
        Err(CommandError::PulseWidth {
            index: 10,
            found: 2501
        })
    );
    let bad = 36000u16.to_le_bytes();
    assert_eq!(
        decode(0x34, [bad[0], bad[1], 0, 0, 0, 0]),
        Err(CommandError::HipAngle {
            index: 6,
            found: 36000
        })
    );
    assert_eq!(
        decode(0x60, [0, 0, b'z', b'a', 0, 0]),
        Err(CommandError::State {
            index: 8,
            found: b'z'
        })
    );
    assert_eq!(
        decode(0x60, [0, 0, b'd', b'a', 0, 0]),
        Err(CommandError::Reconfiguration(
            ReconfigurationError::TargetNotMatched { target: State::D }
        ))
    );
    assert_eq!(
        decode(0x60, [0, 0, b'a', b'a', 0, 0]),
        Err(CommandError::Reconfiguration(
            ReconfigurationError::SameState { state: State::A }
        ))
    );
    assert_eq!(
        decode(0x60, [0, 0, b'm', 0, 0, 0]),
        Err(CommandError::MissingState { index: 9 })
    );
}

// req: D:primitive-final-state
#[test]
fn a_primitive_names_its_final_state_in_byte_8() {
    // 7 (backTurnCW): e -> a and e -> d; both commandable, each its own bytes.
    for (target, byte) in [(State::A, b'a'), (State::D, b'd')] {
        let c = Command::primitive(Primitive::BackTurnCw, target);
        assert_eq!(c.map(|c| encode(&c)), Ok((0x57, [0, 0, byte, 0, 0, 0])));
        assert_eq!(
            decode(0x57, [0, 0, byte, 0, 0, 0]),
            c.map_err(CommandError::from)
        );
    }
    // The old layout (no final state), a non-letter, a state the primitive reaches from
    // nowhere, and an initial state in byte 9 (not carried for a primitive).
    assert_eq!(
        decode(0x57, [0; 6]),
        Err(CommandError::MissingState { index: 8 })
    );
    assert_eq!(
        decode(0x57, [0, 0, b'p', 0, 0, 0]),
        Err(CommandError::State {
            index: 8,
            found: b'p'
        })
    );
    assert_eq!(
        decode(0x57, [0, 0, b'm', 0, 0, 0]),
        Err(CommandError::Primitive(PrimitiveMoveError::Unreachable {
            primitive: Primitive::BackTurnCw,
            target: State::M
        }))
    );
    assert_eq!(
        decode(0x57, [0, 0, b'd', b'e', 0, 0]),
        Err(CommandError::UnusedNotZero {
            id: 0x57,
            index: 9,
            found: b'e'
        })
    );
}

// req: P6.9
#[test]
fn every_move_of_the_model_is_one_primitive_command() {
    // 72 moves of the model, 60 commands: a command is (primitive, final state); the
    // robot's state supplies the row. Each command is the move of exactly the rows it
    // names: 60 moves of the map (run), 12 turns without a hip rotation (refused by name).
    let (mut moves, mut hipless) = (0, 0);
    for m in PrimitiveMove::all() {
        for from in State::ALL {
            let cell = mmic::pose::map::primitive(from, m.target());
            assert_eq!(m.is_move_from(from), cell == Some(m.primitive()));
            let model = mmic::pose::geometry::single_move(from, m.target());
            assert_eq!(
                m.turns_without_hip_from(from),
                model.map(|x| x.1) == Some(m.primitive()) && cell.is_none(),
                "{m:?} from {from}"
            );
            assert!(!(m.is_move_from(from) && m.turns_without_hip_from(from)));
            moves += usize::from(m.is_move_from(from));
            hipless += usize::from(m.turns_without_hip_from(from));
        }
    }
    assert_eq!((PrimitiveMove::all().count(), moves, hipless), (60, 60, 12));
    for (from, to, p) in mmic::pose::map::moves() {
        assert!(PrimitiveMove::new(p, to).is_ok_and(|m| m.is_move_from(from)));
    }
}
