//! Golden byte vectors: one packet of each type written out byte by byte from the paper's
//! tables and the decisions of `spec/`, checked in both directions (`emit` gives exactly these
//! bytes, `parse` gives exactly this value).
//!
//! The checksum bytes were computed outside the library with a bitwise CRC-16/CCITT-FALSE (the
//! definition: poly 0x1021, init 0xFFFF, MSB first, no final xor, stored low byte first); the
//! same bitwise CRC lives in `common/` and is re-checked here against the catalogue check value
//! and against each vector, so a wrong table in the library's `crc` configuration cannot hide.
//! Neighbouring fields hold different values wherever their domains allow, so swapped or
//! shifted fields show.

use crate::common;

use common::crc16_bitwise;
use mmic::bolter::{BolterDirection, BolterStep, MuxLines};
use mmic::command::{BolterPair, Command, ServoTarget};
use mmic::faults::{Fault, Faults};
use mmic::mode::Mode;
use mmic::motion::{Primitive, State};
use mmic::refusal::Refusal;
use mmic::units::{Axis, BoardNumber, Electrical, Gravity, HipAngle, PulseWidth, Side, Sign};
use mmic::wire::b_command::{BCommandRepr, BPower, BolterOrder, B_COMMAND_LEN};
use mmic::wire::command::{CommandRepr, COMMAND_LEN};
use mmic::wire::heartbeat::{BolterAttempt, Boot, HeartbeatRepr, ResetCause, HEARTBEAT_LEN};
use mmic::wire::internal_heartbeat::{BolterAux, InternalHeartbeatRepr, INTERNAL_HEARTBEAT_LEN};
use mmic::wire::opcode::CommandError;
use mmic::wire::WireError;

fn pw(us: u16) -> PulseWidth {
    PulseWidth::new(us).unwrap()
}

fn deg(cdeg: u16) -> HipAngle {
    HipAngle::new(cdeg).unwrap()
}

/// The checksum of a vector agrees with the independent bitwise CRC of the bytes before it.
fn assert_crc(bytes: &[u8]) {
    let n = bytes.len();
    let carried = u16::from_le_bytes([bytes[n - 2], bytes[n - 1]]);
    assert_eq!(crc16_bitwise(&bytes[..n - 2]), carried, "vector checksum");
}

// req: D:checksum
#[test]
fn bitwise_crc_matches_the_catalogue_check_value() {
    // CRC-16/CCITT-FALSE ("CRC-16/IBM-3740" in the CRC catalogue): check = 0x29B1.
    assert_eq!(crc16_bitwise(b"123456789"), 0x29b1);
    assert_eq!(crc16_bitwise(b""), 0xffff);
    assert_eq!(mmic::wire::checksum::crc16(b"123456789"), 0x29b1);
}

/// Robot 7: move arm B to 1200 µs.
const COMMAND_ARM: [u8; COMMAND_LEN] = [
    b'M', b'I', b'C', b'M', // 0-3 header
    0x07, // 4 board 7
    0x26, // 5 opcode: arm (0x20) + side B (4) + position (2)
    0x00, 0x00, // 6-7 hip: unused, zero
    0x00, 0x00, // 8-9 arm A: unused, zero
    0xb0, 0x04, // 10-11 arm B: 1200 µs = 0x04b0, low byte first
    0xdf, 0xe6, // 12-13 CRC-16 0xe6df of bytes 0-11, low byte first
];

// req: P3.12, T1/arm
#[test]
fn golden_command_arm_position() {
    let repr = CommandRepr {
        board: BoardNumber::new(7).unwrap(),
        command: Command::Arm {
            side: Side::B,
            target: ServoTarget::Position(pw(1200)),
        },
        seq: 0,
    };
    assert_crc(&COMMAND_ARM);
    assert_eq!(repr.to_bytes(), COMMAND_ARM);
    assert_eq!(CommandRepr::parse(&COMMAND_ARM), Ok(repr));
}

/// Robot 255: reconfigure from state h to state n.
const COMMAND_RECONFIGURE: [u8; COMMAND_LEN] = [
    b'M', b'I', b'C', b'M', // 0-3 header
    0xff, // 4 board 255
    0x60, // 5 opcode: reconfigure
    0x00, 0x00, // 6-7 hip: unused, zero
    b'n', // 8 final (target) state 'n' = 0x6e
    b'h', // 9 initial state 'h' = 0x68
    0x00, 0x00, // 10-11 arm B: unused, zero
    0x8a, 0x5e, // 12-13 CRC-16 0x5e8a
];

// req: P3.12, T1/reconfiguration
#[test]
fn golden_command_reconfigure() {
    let repr = CommandRepr {
        board: BoardNumber::new(255).unwrap(),
        command: Command::reconfigure(State::H, State::N).unwrap(),
        seq: 0,
    };
    assert_crc(&COMMAND_RECONFIGURE);
    assert_eq!(repr.to_bytes(), COMMAND_RECONFIGURE);
    assert_eq!(CommandRepr::parse(&COMMAND_RECONFIGURE), Ok(repr));
}

/// Robot 2, sequenced command 0x0203: primitive 7 (backTurnCW) ending in state d. From e the
/// primitive reaches a or d (spec/motion/ambiguous-primitives.txt); byte 8 says which.
const COMMAND_PRIMITIVE: [u8; COMMAND_LEN] = [
    b'M', b'I', b'C', b'M', // 0-3 header
    0x02, // 4 board 2
    0x57, // 5 opcode: primitive (0x50) + 7
    0x00, 0x00, // 6-7 hip: unused, zero
    b'd', // 8 final state 'd' = 0x64
    0x00, // 9 initial state: not carried for a primitive, zero
    0x03, 0x02, // 10-11 sequence number 0x0203
    0xda, 0x2a, // 12-13 CRC-16 0x2ada
];

/// The same primitive in the layout before final states: byte 8 zero. Sealed correctly, but
/// no command: the move it meant is not known.
const COMMAND_PRIMITIVE_NO_STATE: [u8; COMMAND_LEN] = [
    b'M', b'I', b'C', b'M', // 0-3 header
    0x02, // 4 board 2
    0x57, // 5 opcode: primitive 7
    0x00, 0x00, // 6-7 hip: unused, zero
    0x00, // 8 final state: missing
    0x00, // 9 zero
    0x03, 0x02, // 10-11 sequence number 0x0203
    0xf9, 0xb9, // 12-13 CRC-16 0xb9f9
];

// req: P3.12, T1/primitive
#[test]
fn golden_command_primitive() {
    let repr = CommandRepr {
        board: BoardNumber::new(2).unwrap(),
        command: Command::primitive(Primitive::BackTurnCw, State::D).unwrap(),
        seq: 0x0203,
    };
    assert_crc(&COMMAND_PRIMITIVE);
    assert_eq!(repr.to_bytes(), COMMAND_PRIMITIVE);
    assert_eq!(CommandRepr::parse(&COMMAND_PRIMITIVE), Ok(repr));
    assert_crc(&COMMAND_PRIMITIVE_NO_STATE);
    assert_eq!(
        CommandRepr::parse(&COMMAND_PRIMITIVE_NO_STATE),
        Err(WireError::Command(CommandError::MissingState { index: 8 }))
    );
}

/// Exactly-once commanding (spec/protocol/README.md): the arm-B command above as sequenced
/// command 0x0102. Its pulse width holds bytes 10–11, so the sequence number takes the hip slot.
const COMMAND_ARM_SEQUENCED: [u8; COMMAND_LEN] = [
    b'M', b'I', b'C', b'M', // 0-3 header
    0x07, // 4 board 7
    0x26, // 5 opcode: arm B to a position
    0x02, 0x01, // 6-7 sequence number 0x0102 (the hip slot, unused by this opcode)
    0x00, 0x00, // 8-9 arm A: unused, zero
    0xb0, 0x04, // 10-11 arm B: 1200 µs
    0xce, 0xc7, // 12-13 CRC-16 0xc7ce
];

/// The reconfiguration above as sequenced command 65534: the sequence number takes bytes 10–11.
const COMMAND_RECONFIGURE_SEQUENCED: [u8; COMMAND_LEN] = [
    b'M', b'I', b'C', b'M', // 0-3 header
    0xff, // 4 board 255
    0x60, // 5 opcode: reconfigure
    0x00, 0x00, // 6-7 hip: unused, zero
    b'n', // 8 final (target) state
    b'h', // 9 initial state
    0xfe, 0xff, // 10-11 sequence number 65534
    0xb4, 0x70, // 12-13 CRC-16 0x70b4
];

// req: D:command-sequence-number
#[test]
fn golden_command_sequenced() {
    let arm = CommandRepr {
        board: BoardNumber::new(7).unwrap(),
        command: Command::Arm {
            side: Side::B,
            target: ServoTarget::Position(pw(1200)),
        },
        seq: 0x0102,
    };
    assert_crc(&COMMAND_ARM_SEQUENCED);
    assert_eq!(arm.to_bytes(), COMMAND_ARM_SEQUENCED);
    assert_eq!(CommandRepr::parse(&COMMAND_ARM_SEQUENCED), Ok(arm));
    let reconf = CommandRepr {
        board: BoardNumber::new(255).unwrap(),
        command: Command::reconfigure(State::H, State::N).unwrap(),
        seq: 65534,
    };
    assert_crc(&COMMAND_RECONFIGURE_SEQUENCED);
    assert_eq!(reconf.to_bytes(), COMMAND_RECONFIGURE_SEQUENCED);
    assert_eq!(
        CommandRepr::parse(&COMMAND_RECONFIGURE_SEQUENCED),
        Ok(reconf)
    );
}

/// Robot 3, Operational, bolting pair 2 (attempt 1) after reconfiguring towards m, with the
/// low-battery and arm-not-contracted faults latched, answering a command it refused for an
/// invalid parameter: the sequenced command 0x1234.
#[rustfmt::skip]
const HEARTBEAT: [u8; HEARTBEAT_LEN] = [
    b'M', b'I', b'H', b'B', // 0-3 header
    0x03,       // 4 board 3
    0x28, 0x23, // 5-6 hip target 9000 (90.00°)
    0x27, 0x23, // 7-8 hip now 8999
    0xe8, 0x03, // 9-10 arm A target 1000 µs
    0xe9, 0x03, // 11-12 arm A now 1001 µs
    0xdc, 0x05, // 13-14 arm B target 1500 µs
    0xdb, 0x05, // 15-16 arm B now 1499 µs
    0xd0, 0x07, // 17-18 gripper A target 2000 µs
    0xcf, 0x07, // 19-20 gripper A now 1999 µs
    0xf4, 0x01, // 21-22 gripper B target 500 µs
    0xc4, 0x09, // 23-24 gripper B now 2500 µs
    0xe8, 0x1c, // 25-26 V_batA 7400 mV
    0xb0, 0x04, // 27-28 I_batA 1200 mA
    0x2c, 0x01, // 29-30 I_locA 300 mA
    0x96, 0x00, // 31-32 I_gripA 150 mA
    0x50, 0x00, // 33-34 I_3v3A 80 mA
    0x70, 0x17, // 35-36 V_regA 6000 mV
    0x19, 0x00, // 37-38 I_boA 25 mA
    0xb6, 0x1c, // 39-40 V_batB 7350 mV
    0x4c, 0x04, // 41-42 I_batB 1100 mA
    0x36, 0x01, // 43-44 I_locB 310 mA
    0x8c, 0x00, // 45-46 I_gripB 140 mA
    0x4b, 0x00, // 47-48 I_3v3B 75 mA
    0x66, 0x17, // 49-50 V_regB 5990 mV
    0x1e, 0x00, // 51-52 I_boB 30 mA
    b'm',       // 53 target state m (0x6d)
    0x01,       // 54 command complete
    0x02,       // 55 active bolter: pair 2
    0x01,       // 56 bolter attempt 1
    0x34, 0x12, // 57-58 last sequenced command 0x1234 (paper: empty)
    0xa3,       // 59 boot: watchdog reset (5 << 5), boot count 3 (paper: empty)
    0x02, 0x08, // 60-61 faults: bit 1 (arm not contracted) | bit 11 (low battery)
    0x05,       // 62 outcome of the command reported on: 5, invalid parameter
    0x02,       // 63 mode: operational
    0x86, 0xb6, // 64-65 CRC-16 0xb686
];

// req: P3.16, T3/*
#[test]
fn golden_heartbeat() {
    let repr = HeartbeatRepr {
        board: BoardNumber::new(3).unwrap(),
        hip_target: deg(9000),
        hip_now: deg(8999),
        arm_a_target: pw(1000),
        arm_a_now: pw(1001),
        arm_b_target: pw(1500),
        arm_b_now: pw(1499),
        gripper_a_target: pw(2000),
        gripper_a_now: pw(1999),
        gripper_b_target: pw(500),
        gripper_b_now: pw(2500),
        electrical_a: Electrical {
            v_bat: 7400,
            i_bat: 1200,
            i_loc: 300,
            i_grip: 150,
            i_3v3: 80,
            v_reg: 6000,
            i_bo: 25,
        },
        electrical_b: Electrical {
            v_bat: 7350,
            i_bat: 1100,
            i_loc: 310,
            i_grip: 140,
            i_3v3: 75,
            v_reg: 5990,
            i_bo: 30,
        },
        target_state: Some(State::M),
        command_complete: true,
        active_bolter: Some(BolterPair::P2),
        bolter_attempt: BolterAttempt::new(1).unwrap(),
        faults: Faults::EMPTY
            .with(Fault::ArmNotContracted)
            .with(Fault::LowBattery),
        refusal: Some(Refusal::InvalidParameter),
        mode: Mode::Operational,
        last_seq: 0x1234,
        boot: Boot {
            cause: ResetCause::Watchdog,
            count: 3,
        },
    };
    assert_crc(&HEARTBEAT);
    assert_eq!(repr.to_bytes(), HEARTBEAT);
    assert_eq!(HeartbeatRepr::parse(&HEARTBEAT), Ok(repr));
}

/// Board B unbolting pair 3, the rotate step timed out, gravity along −Z, gripper current over
/// its idle limit, arm and bolter currents over their absolute limits; acknowledging A→B
/// command 43. Neighbouring flags alternate, so two swapped flags show.
#[rustfmt::skip]
const INTERNAL_HEARTBEAT: [u8; INTERNAL_HEARTBEAT_LEN] = [
    b'M', b'I', b'i', b'h', // 0-3 header
    0x08, 0x07, // 4-5 arm B target 1800 µs
    0xd6, 0x06, // 6-7 arm B now 1750 µs
    0x98, 0x08, // 8-9 gripper B target 2200 µs
    0x66, 0x08, // 10-11 gripper B now 2150 µs
    0xb6, 0x1c, // 12-13 V_batB 7350 mV
    0x4c, 0x04, // 14-15 I_batB 1100 mA
    0x36, 0x01, // 16-17 I_locB 310 mA
    0x8c, 0x00, // 18-19 I_gripB 140 mA
    0x4b, 0x00, // 20-21 I_3v3B 75 mA
    0x66, 0x17, // 22-23 V_regB 5990 mV
    0x1e, 0x00, // 24-25 I_boB 30 mA
    0x04,       // 26 bolter step 4 (rotate)
    0x2a,       // 27 sequence number of the order: 42
    0x03,       // 28 pair 3
    0x02,       // 29 direction: unbolt
    0x01,       // 30 threshold reached
    0x00,       // 31 not locked
    0x01,       // 32 timed out
    0x00,       // 33 not at home
    0x01,       // 34 mux: A0 high, A1 low (pair 3)
    0x2b,       // 35 command received: 43
    b'-',       // 36 gravity sign '-' (0x2d)
    b'Z',       // 37 gravity axis 'Z' (0x5a)
    0x00,       // 38 arm over idle
    0x01,       // 39 gripper over idle
    0x00,       // 40 bolter over idle
    0x01,       // 41 arm overcurrent
    0x00,       // 42 gripper overcurrent
    0x01,       // 43 bolter overcurrent
    0x00,       // 44 arm not contracted
    0xb3, 0xeb, // 45-46 CRC-16 0xebb3
];

// req: P4.7, T4/*
#[test]
fn golden_internal_heartbeat() {
    let repr = InternalHeartbeatRepr {
        arm_b_target: pw(1800),
        arm_b_now: pw(1750),
        gripper_b_target: pw(2200),
        gripper_b_now: pw(2150),
        electrical_b: Electrical {
            v_bat: 7350,
            i_bat: 1100,
            i_loc: 310,
            i_grip: 140,
            i_3v3: 75,
            v_reg: 5990,
            i_bo: 30,
        },
        bolter_aux: BolterAux {
            step: Some(BolterStep::Rotate),
            seq: 42,
            pair: Some(BolterPair::P3),
            direction: Some(BolterDirection::Unbolt),
            threshold_reached: true,
            locked: false,
            timed_out: true,
            at_home: false,
            mux: MuxLines::for_pair(BolterPair::P3),
        },
        command_received: 43,
        gravity: Some(Gravity {
            axis: Axis::Z,
            sign: Sign::Negative,
        }),
        arm_over_idle: false,
        gripper_over_idle: true,
        bolter_over_idle: false,
        arm_overcurrent: true,
        gripper_overcurrent: false,
        bolter_overcurrent: true,
        arm_contracted: false,
    };
    assert_crc(&INTERNAL_HEARTBEAT);
    assert_eq!(repr.to_bytes(), INTERNAL_HEARTBEAT);
    assert_eq!(InternalHeartbeatRepr::parse(&INTERNAL_HEARTBEAT), Ok(repr));
}

/// A orders B: command 42, regulator, arm and bolter powered, arm to 1800 µs, gripper to
/// 2200 µs, unbolt pair 3 with the rotate step.
#[rustfmt::skip]
const B_COMMAND: [u8; B_COMMAND_LEN] = [
    b'M', b'I', b'b', b'c', // 0-3 header
    0x2a,       // 4 sequence number 42
    0x0b,       // 5 flags: regulator (bit 0) | arm (bit 1) | bolter (bit 3); no stop
    0x08, 0x07, // 6-7 arm target 1800 µs
    0x98, 0x08, // 8-9 gripper target 2200 µs
    0x03,       // 10 bolter pair 3
    0x02,       // 11 direction: unbolt
    0x04,       // 12 step 4 (rotate)
    0xe4, 0x53, // 13-14 CRC-16 0x53e4
];

// req: D:b-command
#[test]
fn golden_b_command() {
    let repr = BCommandRepr {
        seq: 42,
        power: BPower {
            regulator: true,
            arm: true,
            gripper: false,
            bolter: true,
        },
        stop: false,
        arm_target: pw(1800),
        gripper_target: pw(2200),
        bolter: Some(BolterOrder {
            pair: BolterPair::P3,
            direction: BolterDirection::Unbolt,
            step: BolterStep::Rotate,
        }),
    };
    assert_crc(&B_COMMAND);
    assert_eq!(repr.to_bytes(), B_COMMAND);
    assert_eq!(BCommandRepr::parse(&B_COMMAND), Ok(repr));
}
