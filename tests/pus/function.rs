//! ST[8] functions: every valid command is a function and back, exhaustively; every short
//! application data (all 1-, 2- and 3-byte strings) decodes to a command whose encoding is
//! exactly those bytes, or is refused — nothing is read two ways.

use mmic::command::{
    BolterCommand, BolterPair, Command, Fasteners, HipTarget, PowerTarget, PrimitiveMove,
    Reconfiguration, ServoTarget,
};
use mmic::control::interp::Travel;
use mmic::mode::Mode;
use mmic::motion::State;
use mmic::pus::function::{self, FunctionError, FunctionId, MAX_LEN};
use mmic::units::{HipAngle, Module, PulseWidth, Side};

/// Every command the library can build (Heartbeat aside): 44,194 of them.
fn every_command() -> Vec<Command> {
    let mut all = vec![
        Command::Stop,
        Command::Reset,
        Command::SystemFault,
        Command::ClearFaults,
    ];
    // Every target of each servo's travel (the commands refuse a position outside it).
    let servo = |t: Travel| {
        let mut v = vec![ServoTarget::Contract, ServoTarget::Extend];
        v.extend(
            (t.min().micros()..=t.max().micros())
                .filter_map(|p| PulseWidth::new(p).ok().map(ServoTarget::Position)),
        );
        v
    };
    for side in [Side::A, Side::B] {
        for target in servo(Travel::ARM) {
            all.push(Command::Arm { side, target });
        }
        for target in servo(Travel::GRIPPER) {
            all.push(Command::Gripper { side, target });
        }
    }
    all.extend(
        [
            HipTarget::Home,
            HipTarget::Straight,
            HipTarget::RightAngleCw,
            HipTarget::RightAngleCcw,
        ]
        .map(Command::Hip),
    );
    all.extend(
        (0..HipAngle::TURN)
            .filter_map(|a| HipAngle::new(a).ok())
            .map(|a| Command::Hip(HipTarget::Angle(a))),
    );
    let mut fasteners = vec![Fasteners::All];
    fasteners.extend(BolterPair::ALL.map(Fasteners::Pair));
    for f in fasteners {
        all.push(Command::Bolter(BolterCommand::Bolt(f)));
        all.push(Command::Bolter(BolterCommand::Unbolt(f)));
    }
    all.push(Command::Bolter(BolterCommand::Down));
    all.extend(PrimitiveMove::all().map(Command::Primitive));
    for i in State::ALL {
        for t in State::ALL {
            if let Ok(r) = Reconfiguration::new(i, t) {
                all.push(Command::Reconfigure(r));
            }
        }
    }
    let mut targets = vec![PowerTarget::All];
    targets.extend(Module::ALL.map(PowerTarget::Module));
    for target in targets {
        for on in [false, true] {
            all.push(Command::Power { target, on });
        }
    }
    all.extend(Mode::ALL.map(Command::Mode));
    all
}

// req: PUS/ST[8].1
#[test]
fn every_command_is_a_function_and_back() {
    let all = every_command();
    assert_eq!(
        all.len(),
        // Contract, extend and every position of the travel: arms 1201, grippers 1001.
        4 + 2 * (1203 + 1003) + 4 + 36_000 + 11 + 60 + (15 * 6 - 6) + 16 + 3
    );
    let mut seen = std::collections::HashSet::new();
    for c in &all {
        let mut buf = [0u8; MAX_LEN];
        let n = function::encode(c, &mut buf).unwrap_or_else(|e| panic!("{c:?}: {e}"));
        let f = FunctionId::of(c).unwrap();
        assert_eq!((buf[0], n), (f.id(), 1 + f.args_len()), "{c:?}");
        assert_eq!(function::decode(&buf[..n]), Ok(*c), "{c:?}");
        assert!(
            seen.insert(buf[..n].to_vec()),
            "two commands encode alike: {c:?}"
        );
        // A buffer one byte short is refused, not cut.
        assert_eq!(
            function::encode(c, &mut buf[..n - 1]),
            Err(FunctionError::Buffer {
                needed: n,
                found: n - 1
            })
        );
    }
    assert_eq!(
        function::encode(&Command::Heartbeat, &mut [0; 8]),
        Err(FunctionError::NoFunction)
    );
}

/// All 16.8 million application data strings of 1 to 3 bytes: each decodes to a command whose
/// encoding gives the same bytes back, or is refused; and the number accepted equals the
/// number of commands whose encoding is that short.
#[test]
fn every_short_application_data_is_read_one_way_or_refused() {
    let short = every_command()
        .iter()
        .filter(|c| FunctionId::of(c).is_some_and(|f| f.args_len() <= 2))
        .count();
    let mut accepted = 0usize;
    let mut buf = [0u8; MAX_LEN];
    for len in 1..=3usize {
        for v in 0..(1u32 << (8 * len)) {
            let bytes = &v.to_be_bytes()[4 - len..];
            if let Ok(c) = function::decode(bytes) {
                accepted += 1;
                let n = function::encode(&c, &mut buf).unwrap();
                assert_eq!(&buf[..n], bytes, "{c:?}");
            }
        }
    }
    assert_eq!(accepted, short);
}

#[test]
fn each_bad_input_is_refused_by_name() {
    use FunctionError::*;
    let cases: [(&[u8], FunctionError); 14] = [
        (&[], Empty),
        (&[0], UnknownFunction { id: 0 }),
        (&[13], UnknownFunction { id: 13 }),
        (
            &[6, 0],
            Length {
                function: 6,
                expected: 1,
                found: 2,
            },
        ),
        (
            &[1, 0, 2, 0x01],
            Length {
                function: 1,
                expected: 5,
                found: 4,
            },
        ),
        (
            &[1, 2, 2, 0x05, 0xDC],
            OutOfRange {
                function: 1,
                argument: "side",
                value: 2,
                min: 0,
                max: 1,
            },
        ),
        (
            &[1, 0, 0, 0x05, 0xDC],
            OutOfRange {
                function: 1,
                argument: "pulse",
                value: 1500,
                min: 0,
                max: 0,
            },
        ),
        // A gripper position outside the grippers' travel (2001 µs), an arm's outside the
        // arms' (899 µs), a pulse no servo takes (2501 µs): each named with its travel.
        (
            &[2, 0, 2, 0x07, 0xD1],
            OutOfRange {
                function: 2,
                argument: "pulse",
                value: 2001,
                min: 1000,
                max: 2000,
            },
        ),
        (
            &[1, 1, 2, 0x03, 0x83],
            OutOfRange {
                function: 1,
                argument: "pulse",
                value: 899,
                min: 900,
                max: 2100,
            },
        ),
        (
            &[2, 0, 2, 0x09, 0xC5],
            OutOfRange {
                function: 2,
                argument: "pulse",
                value: 2501,
                min: 1000,
                max: 2000,
            },
        ),
        (
            &[3, 4, 0x8C, 0xA0],
            OutOfRange {
                function: 3,
                argument: "angle",
                value: 36000,
                min: 0,
                max: 35999,
            },
        ),
        (
            &[4, 2, 1],
            OutOfRange {
                function: 4,
                argument: "pair",
                value: 1,
                min: 0,
                max: 0,
            },
        ),
        (
            &[9, b'a', b'd'],
            Reconfiguration(mmic::command::ReconfigurationError::TargetNotMatched {
                target: State::D,
            }),
        ),
        (
            &[10, 0],
            OutOfRange {
                function: 10,
                argument: "mode",
                value: 0,
                min: 1,
                max: 3,
            },
        ),
    ];
    for (bytes, want) in cases {
        let got = function::decode(bytes);
        assert_eq!(got, Err(want), "{bytes:02x?}");
        // The message names the check and its numbers.
        assert!(!want.to_string().is_empty());
    }
    assert!(matches!(
        function::decode(&[5, 3, b'a']),
        Err(FunctionError::Primitive(_))
    ));
}
