//! [`proptest`] strategies for every `Repr` and every type they are built from (feature
//! `proptest`), so that users' own property tests can say `any::<HeartbeatRepr>()`.
//!
//! ```
//! use mmic::wire::command::CommandRepr;
//! use proptest::prelude::*;
//!
//! proptest!(|(repr in any::<CommandRepr>())| {
//!     prop_assert_eq!(CommandRepr::parse(&repr.to_bytes()), Ok(repr));
//! });
//! ```
//!
//! Every value is built through the type's own checked constructor (`BoardNumber::new`,
//! `PulseWidth::new`, `Reconfiguration::new`, `PrimitiveMove::new`, `Faults::from_wire`, …), so a strategy can only
//! produce values the library itself would accept; nothing here bypasses a range check.
//! Numeric ranges are drawn uniformly with their bounds over-weighted, because off-by-one
//! mistakes live at the bounds (500 and 2500 µs, an arm's 900 and 2100, 0 and 35999
//! centidegrees, board 1 and 255).
//! Sum types pick each variant with equal weight, so no variant is starved.
//!
//! The ranged quantities (`PulseWidth`, `HipAngle`, `BolterAttempt`, the CCSDS fields) get
//! theirs from the `ranged!` macro that declares them, with the same weighting.
//!
//! The CCSDS/PUS headers' strategies are here too (`ccsds.rs`), and the space data link's value
//! types' (`link.rs`: `FrameKind`, `ControlCommand`), and so are the exhaustive
//! enumerations of the command set ([`enumerate`]): everything the checks use and the robot
//! does not, in one place behind one feature.
//!
//! Besides the [`Arbitrary`] impls, [`sealed_bytes`] draws byte strings with a packet's length,
//! header and a correct checksum but arbitrary body bytes: inputs that reach the field checks.
//!
//! The strategies are a feature of the library crate rather than a test helper so that they
//! stay next to the types they must cover. A variant added without a strategy arm is caught by
//! `tests/wire/round_trip.rs` in the repository, which draws a fixed-seed sample and requires every
//! one of the 61 command opcodes (and every optional field, both ways) to appear in it.

mod ccsds;
pub mod enumerate;
mod link;

pub use enumerate::{for_each_command, for_each_variant_class};

use crate::bolter::BolterAttempt;
use crate::bolter::{BolterAux, BolterOrder};
use crate::bolter::{BolterDirection, BolterStep, MuxLines};
use crate::command::{
    BolterCommand, BolterPair, Command, CommandKind, Fasteners, HipTarget, PowerTarget,
    PrimitiveMove, Reconfiguration, ServoTarget, Travel,
};
use crate::faults::{Fault, Faults};
use crate::mode::Mode;
use crate::pose::{Primitive, State, StateKind};
use crate::refusal::Refusal;
use crate::units::{
    Axis, BoardNumber, Electrical, Gravity, HipAngle, Module, PulseWidth, Side, Sign,
};
use crate::wire::b_command::{BCommandRepr, BPower};
use crate::wire::command::CommandRepr;
use crate::wire::heartbeat::HeartbeatRepr;
use crate::wire::internal_heartbeat::InternalHeartbeatRepr;
use crate::wire::{PacketKind, MAX_PACKET_LEN};
use proptest::arbitrary::{any, Arbitrary};
use proptest::array::{uniform4, uniform7};
use proptest::collection::vec;
use proptest::option;
use proptest::prop_oneof;
use proptest::sample::{select, Select};
use proptest::strategy::{BoxedStrategy, Just, Strategy};

/// One of the values of a `const ALL` table, uniformly.
fn pick<T: Clone + core::fmt::Debug + 'static, const N: usize>(all: &'static [T; N]) -> Select<T> {
    select(&all[..])
}

/// Any `u16`, with 0 and `u16::MAX` over-weighted (raw wire quantities: mV, mA).
pub fn wire_u16() -> impl Strategy<Value = u16> {
    prop_oneof![1 => Just(0u16), 1 => Just(u16::MAX), 8 => any::<u16>()]
}

/// Implements `Arbitrary` for a unit enum with a `const ALL` table.
macro_rules! arbitrary_from_all {
    ($($t:ty),* $(,)?) => {$(
        impl Arbitrary for $t {
            type Parameters = ();
            type Strategy = Select<$t>;
            fn arbitrary_with((): ()) -> Self::Strategy {
                pick(&<$t>::ALL)
            }
        }
    )*};
}

arbitrary_from_all!(
    Side,
    Module,
    Axis,
    Mode,
    State,
    Primitive,
    Fault,
    BolterStep,
    BolterPair,
    PacketKind,
    CommandKind,
    Refusal
);

/// Implements `Arbitrary` as a boxed strategy built by `$body`.
macro_rules! arbitrary_boxed {
    ($t:ty, $body:expr) => {
        impl Arbitrary for $t {
            type Parameters = ();
            type Strategy = BoxedStrategy<$t>;
            fn arbitrary_with((): ()) -> Self::Strategy {
                $body.boxed()
            }
        }
    };
}

arbitrary_boxed!(
    Sign,
    prop_oneof![Just(Sign::Positive), Just(Sign::Negative)]
);
arbitrary_boxed!(
    BolterDirection,
    prop_oneof![Just(BolterDirection::Bolt), Just(BolterDirection::Unbolt)]
);
arbitrary_boxed!(
    StateKind,
    prop_oneof![
        Just(StateKind::Matched),
        Just(StateKind::Stretch),
        Just(StateKind::Turn)
    ]
);
arbitrary_boxed!(
    BoardNumber,
    prop_oneof![1 => Just(1u8), 1 => Just(u8::MAX), 8 => 1..=u8::MAX]
        .prop_filter_map("board 1..=255", |n| BoardNumber::new(n).ok())
);
arbitrary_boxed!(
    Gravity,
    (any::<Axis>(), any::<Sign>()).prop_map(|(axis, sign)| Gravity { axis, sign })
);
arbitrary_boxed!(
    MuxLines,
    (any::<bool>(), any::<bool>()).prop_map(|(a0, a1)| MuxLines { a0, a1 })
);
arbitrary_boxed!(
    Electrical,
    [
        wire_u16(),
        wire_u16(),
        wire_u16(),
        wire_u16(),
        wire_u16(),
        wire_u16(),
        wire_u16()
    ]
    .prop_map(
        |[v_bat, i_bat, i_loc, i_grip, i_3v3, v_reg, i_bo]| Electrical {
            v_bat,
            i_bat,
            i_loc,
            i_grip,
            i_3v3,
            v_reg,
            i_bo,
        }
    )
);
arbitrary_boxed!(
    Faults,
    // Empty and full sets over-weighted; otherwise any subset of the 13 defined faults.
    prop_oneof![1 => Just(0u32), 1 => Just(Faults::DEFINED), 8 => 0..=Faults::DEFINED]
        .prop_filter_map("defined fault bits only", |raw| {
            let b = raw.to_le_bytes();
            Faults::from_wire([b[0], b[1]]).ok()
        })
);

// --- Command (Table 1) ---

arbitrary_boxed!(
    ServoTarget,
    prop_oneof![
        Just(ServoTarget::Contract),
        Just(ServoTarget::Extend),
        any::<PulseWidth>().prop_map(ServoTarget::Position),
    ]
);
/// A target of a servo with `travel`: contract, extend, or a position within the travel (its
/// ends over-weighted), as the commands accept (`Travel::check`).
pub fn servo_target(travel: Travel) -> impl Strategy<Value = ServoTarget> {
    let (min, max) = (travel.min().micros(), travel.max().micros());
    let position = prop_oneof![1 => Just(min), 1 => Just(max), 8 => min..=max]
        .prop_filter_map("a pulse width", |us| PulseWidth::new(us).ok())
        .prop_map(ServoTarget::Position);
    prop_oneof![
        Just(ServoTarget::Contract),
        Just(ServoTarget::Extend),
        position,
    ]
}

arbitrary_boxed!(
    HipTarget,
    prop_oneof![
        Just(HipTarget::Home),
        Just(HipTarget::Straight),
        Just(HipTarget::RightAngleCw),
        Just(HipTarget::RightAngleCcw),
        any::<HipAngle>().prop_map(HipTarget::Angle),
    ]
);
arbitrary_boxed!(
    Fasteners,
    prop_oneof![
        4 => any::<BolterPair>().prop_map(Fasteners::Pair),
        1 => Just(Fasteners::All),
    ]
);
arbitrary_boxed!(
    BolterCommand,
    prop_oneof![
        any::<Fasteners>().prop_map(BolterCommand::Bolt),
        any::<Fasteners>().prop_map(BolterCommand::Unbolt),
        Just(BolterCommand::Down),
    ]
);
arbitrary_boxed!(
    PowerTarget,
    prop_oneof![
        7 => any::<Module>().prop_map(PowerTarget::Module),
        1 => Just(PowerTarget::All),
    ]
);
arbitrary_boxed!(
    Reconfiguration,
    // 15 × 6 pairs, of which the 6 with initial == target are refused by the constructor.
    (any::<State>(), pick(&State::MATCHED)).prop_filter_map(
        "initial == target is no reconfiguration",
        |(initial, target)| Reconfiguration::new(initial, target).ok()
    )
);
arbitrary_boxed!(
    PrimitiveMove,
    // Each primitive equally likely, then each final state it reaches equally likely (3 for
    // primitives 1-4, 12 for 5-8: both divide 12). Every draw is a valid command.
    (any::<Primitive>(), 0..12usize).prop_filter_map(
        "every primitive reaches some state",
        |(p, i)| {
            let of_p = move || PrimitiveMove::all().filter(move |m| m.primitive() == p);
            // No state (never: every primitive reaches some) gives `None`, as before.
            i.checked_rem(of_p().count()).and_then(|r| of_p().nth(r))
        }
    )
);
arbitrary_boxed!(
    Command,
    // Thirteen variants, equally likely: the five parameterless ones share one arm of weight 5.
    prop_oneof![
        5 => pick(&[
            Command::Heartbeat,
            Command::Stop,
            Command::Reset,
            Command::SystemFault,
            Command::ClearFaults,
        ]),
        1 => any::<Mode>().prop_map(Command::Mode),
        1 => (any::<Side>(), servo_target(Travel::ARM))
            .prop_map(|(side, target)| Command::Arm { side, target }),
        1 => (any::<Side>(), servo_target(Travel::GRIPPER))
            .prop_map(|(side, target)| Command::Gripper { side, target }),
        1 => any::<HipTarget>().prop_map(Command::Hip),
        1 => any::<BolterCommand>().prop_map(Command::Bolter),
        1 => any::<PrimitiveMove>().prop_map(Command::Primitive),
        1 => any::<Reconfiguration>().prop_map(Command::Reconfigure),
        1 => (any::<PowerTarget>(), any::<bool>())
            .prop_map(|(target, on)| Command::Power { target, on }),
    ]
);

// --- Packets ---

arbitrary_boxed!(
    CommandRepr,
    (any::<BoardNumber>(), any::<Command>(), any::<u16>()).prop_map(|(board, command, seq)| {
        CommandRepr {
            board,
            command,
            seq,
        }
    })
);
arbitrary_boxed!(
    HeartbeatRepr,
    (
        (any::<BoardNumber>(), any::<HipAngle>(), any::<HipAngle>()),
        [
            any::<PulseWidth>(),
            any::<PulseWidth>(),
            any::<PulseWidth>(),
            any::<PulseWidth>(),
            any::<PulseWidth>(),
            any::<PulseWidth>(),
            any::<PulseWidth>(),
            any::<PulseWidth>(),
        ],
        (any::<Electrical>(), any::<Electrical>(), any::<u16>(), any::<u8>()),
        (
            option::of(any::<State>()),
            any::<bool>(),
            option::of(any::<BolterPair>()),
            any::<BolterAttempt>(),
            any::<Faults>(),
            option::of(any::<Refusal>()),
            any::<Mode>(),
        ),
    )
        .prop_map(
            |(
                (board, hip_target, hip_now),
                [arm_a_target, arm_a_now, arm_b_target, arm_b_now, gripper_a_target, gripper_a_now, gripper_b_target, gripper_b_now],
                (electrical_a, electrical_b, last_seq, boot),
                (target_state, command_complete, active_bolter, bolter_attempt, faults, refusal, mode),
            )| HeartbeatRepr {
                board,
                hip_target,
                hip_now,
                arm_a_target,
                arm_a_now,
                arm_b_target,
                arm_b_now,
                gripper_a_target,
                gripper_a_now,
                gripper_b_target,
                gripper_b_now,
                electrical_a,
                electrical_b,
                target_state,
                command_complete,
                active_bolter,
                bolter_attempt,
                faults,
                refusal,
                mode,
                last_seq,
                boot: crate::restart::Boot::from_wire(boot),
            }
        )
);
arbitrary_boxed!(
    BolterAux,
    (
        option::of(any::<BolterStep>()),
        any::<u8>(),
        option::of(any::<BolterPair>()),
        option::of(any::<BolterDirection>()),
        [any::<bool>(), any::<bool>(), any::<bool>(), any::<bool>()],
        any::<MuxLines>(),
    )
        .prop_map(
            |(step, seq, pair, direction, [threshold_reached, locked, timed_out, at_home], mux)| {
                BolterAux {
                    step,
                    seq,
                    pair,
                    direction,
                    threshold_reached,
                    locked,
                    timed_out,
                    at_home,
                    mux,
                }
            }
        )
);
arbitrary_boxed!(
    InternalHeartbeatRepr,
    (
        [
            any::<PulseWidth>(),
            any::<PulseWidth>(),
            any::<PulseWidth>(),
            any::<PulseWidth>(),
        ],
        any::<Electrical>(),
        any::<BolterAux>(),
        any::<u8>(),
        option::of(any::<Gravity>()),
        uniform7(any::<bool>()),
    )
        .prop_map(
            |(
                [arm_b_target, arm_b_now, gripper_b_target, gripper_b_now],
                electrical_b,
                bolter_aux,
                command_received,
                gravity,
                [arm_over_idle, gripper_over_idle, bolter_over_idle, arm_overcurrent, gripper_overcurrent, bolter_overcurrent, arm_contracted],
            )| InternalHeartbeatRepr {
                arm_b_target,
                arm_b_now,
                gripper_b_target,
                gripper_b_now,
                electrical_b,
                bolter_aux,
                command_received,
                gravity,
                arm_over_idle,
                gripper_over_idle,
                bolter_over_idle,
                arm_overcurrent,
                gripper_overcurrent,
                bolter_overcurrent,
                arm_contracted,
            }
        )
);
arbitrary_boxed!(
    BPower,
    uniform4(any::<bool>()).prop_map(|[regulator, arm, gripper, bolter]| BPower {
        regulator,
        arm,
        gripper,
        bolter,
    })
);
arbitrary_boxed!(
    BolterOrder,
    (
        any::<BolterPair>(),
        any::<BolterDirection>(),
        any::<BolterStep>()
    )
        .prop_map(|(pair, direction, step)| BolterOrder {
            pair,
            direction,
            step
        })
);
arbitrary_boxed!(
    BCommandRepr,
    (
        any::<u8>(),
        any::<BPower>(),
        any::<bool>(),
        any::<PulseWidth>(),
        any::<PulseWidth>(),
        option::of(any::<BolterOrder>()),
    )
        .prop_map(
            |(seq, power, stop, arm_target, gripper_target, bolter)| BCommandRepr {
                seq,
                power,
                stop,
                arm_target,
                gripper_target,
                bolter,
            }
        )
);

/// Byte strings of `kind`'s length with its header and a correct checksum around arbitrary
/// body bytes: they pass the length, header and checksum checks, so `parse` decides on the
/// fields alone. Most are refused (a random heartbeat body is rarely all in range); use them to
/// check that whatever `parse` accepts is canonical (`emit(parse(b)) == b`).
pub fn sealed_bytes(kind: PacketKind) -> BoxedStrategy<heapless::Vec<u8, MAX_PACKET_LEN>> {
    let len = kind.len();
    vec(any::<u8>(), len..=len)
        .prop_map(move |body| {
            let mut out = heapless::Vec::<u8, MAX_PACKET_LEN>::new();
            for b in body.iter().take(MAX_PACKET_LEN) {
                // Cannot fail: at most MAX_PACKET_LEN bytes are taken.
                let _ = out.push(*b);
            }
            crate::wire::seal(kind, &mut out);
            out
        })
        .boxed()
}
