//! Property tests over the `mmic::arbitrary` strategies (feature `proptest`, enabled for the
//! crate's own tests by the self dev-dependency in Cargo.toml):
//!
//! * `parse(emit(x)) == x` for every `Repr` (and `decode(encode(c)) == c` for every command);
//! * `emit(parse(b)) == b` for every byte string `parse` accepts, probed with valid packets whose
//!   body bytes were overwritten and whose checksum was rewritten (so they reach the field
//!   checks), and with sealed random bodies;
//! * `parse` of any bytes of any length returns, and when length, header or checksum is wrong
//!   it reports exactly the first failing check in the documented order (length, header,
//!   checksum, then fields), with the numbers the independent oracle of `common/` computes;
//! * the strategies reach every command opcode and both sides of every optional field
//!   (fixed-seed sample, so the check is deterministic);
//! * serde: every `Repr` survives JSON (feature `serde`).

use crate::common;

use common::{framing_error, seal};
use mmic::arbitrary::sealed_bytes;
use mmic::command::Command;
use mmic::wire::b_command::BCommandRepr;
use mmic::wire::command::CommandRepr;
use mmic::wire::heartbeat::HeartbeatRepr;
use mmic::wire::internal_heartbeat::InternalHeartbeatRepr;
use mmic::wire::opcode::{decode, encode};
use mmic::wire::{PacketKind, WireError, CHECKSUM_LEN, HEADER_LEN};
use proptest::prelude::*;
use proptest::strategy::ValueTree;
use proptest::test_runner::{Config, TestRunner};

/// Cases per property (proptest's default is 256).
const CASES: u32 = 2048;

/// Parses `bytes` as `kind` and returns the result with the value re-emitted.
fn parse_emit(kind: PacketKind, bytes: &[u8]) -> Result<Vec<u8>, WireError> {
    match kind {
        PacketKind::Command => CommandRepr::parse(bytes).map(|r| r.to_bytes().to_vec()),
        PacketKind::Heartbeat => HeartbeatRepr::parse(bytes).map(|r| r.to_bytes().to_vec()),
        PacketKind::InternalHeartbeat => {
            InternalHeartbeatRepr::parse(bytes).map(|r| r.to_bytes().to_vec())
        }
        PacketKind::BCommand => BCommandRepr::parse(bytes).map(|r| r.to_bytes().to_vec()),
    }
}

/// The shared verdict: framing errors exactly as the oracle says; with sound framing, accepted
/// canonically (`emit(parse(b)) == b`) or refused by a field or command check. Returns whether
/// `bytes` were accepted.
fn check_verdict(kind: PacketKind, bytes: &[u8]) -> Result<bool, TestCaseError> {
    let got = parse_emit(kind, bytes);
    match framing_error(kind, bytes) {
        Some(e) => {
            prop_assert_eq!(got, Err(e));
            Ok(false)
        }
        None => match got {
            Ok(again) => {
                prop_assert_eq!(&again[..], bytes, "emit(parse(b)) != b");
                Ok(true)
            }
            Err(e) => {
                prop_assert!(
                    matches!(e, WireError::Field { .. } | WireError::Command(_)),
                    "sound framing refused by the {} check: {:?}",
                    e.check(),
                    e
                );
                Ok(false)
            }
        },
    }
}

/// A valid packet of `kind` from the `Arbitrary` strategies.
fn valid_bytes(kind: PacketKind) -> BoxedStrategy<Vec<u8>> {
    match kind {
        PacketKind::Command => any::<CommandRepr>()
            .prop_map(|r| r.to_bytes().to_vec())
            .boxed(),
        PacketKind::Heartbeat => any::<HeartbeatRepr>()
            .prop_map(|r| r.to_bytes().to_vec())
            .boxed(),
        PacketKind::InternalHeartbeat => any::<InternalHeartbeatRepr>()
            .prop_map(|r| r.to_bytes().to_vec())
            .boxed(),
        PacketKind::BCommand => any::<BCommandRepr>()
            .prop_map(|r| r.to_bytes().to_vec())
            .boxed(),
    }
}

/// A valid packet with 1..=3 body bytes overwritten (any value, header and checksum spared)
/// and the checksum rewritten: near misses that exercise the field checks one byte at a time.
fn near_miss(kind: PacketKind) -> impl Strategy<Value = Vec<u8>> {
    let body = kind.len() - HEADER_LEN - CHECKSUM_LEN;
    (
        valid_bytes(kind),
        prop::collection::vec((0..body, any::<u8>()), 1..=3),
    )
        .prop_map(move |(mut bytes, edits)| {
            for (at, v) in edits {
                bytes[HEADER_LEN + at] = v;
            }
            seal(kind, &mut bytes);
            bytes
        })
}

/// Bytes that fail at each stage in turn: any length; the right length; the right length and
/// header; the right length, header and checksum (fields arbitrary).
fn any_bytes(kind: PacketKind) -> impl Strategy<Value = Vec<u8>> {
    let len = kind.len();
    prop_oneof![
        prop::collection::vec(any::<u8>(), 0..=80),
        prop::collection::vec(any::<u8>(), len..=len),
        prop::collection::vec(any::<u8>(), len..=len).prop_map(move |mut b| {
            b[..HEADER_LEN].copy_from_slice(&kind.header());
            b
        }),
        sealed_bytes(kind).prop_map(|b| b.to_vec()),
    ]
}

proptest! {
    #![proptest_config(common::prop::config(CASES))]

    // req: T1/*
    #[test]
    fn command_encode_decode_round_trips(c in any::<Command>()) {
        let (id, params) = encode(&c);
        prop_assert_eq!(decode(id, params), Ok(c));
    }

    // req: T2/*
    #[test]
    fn command_repr_parse_emit_round_trips(x in any::<CommandRepr>()) {
        prop_assert_eq!(CommandRepr::parse(&x.to_bytes()), Ok(x));
    }

    // req: T3/*
    #[test]
    fn heartbeat_repr_parse_emit_round_trips(x in any::<HeartbeatRepr>()) {
        prop_assert_eq!(HeartbeatRepr::parse(&x.to_bytes()), Ok(x));
    }

    // req: T4/*
    #[test]
    fn internal_heartbeat_repr_parse_emit_round_trips(x in any::<InternalHeartbeatRepr>()) {
        prop_assert_eq!(InternalHeartbeatRepr::parse(&x.to_bytes()), Ok(x));
    }

    #[test]
    fn b_command_repr_parse_emit_round_trips(x in any::<BCommandRepr>()) {
        prop_assert_eq!(BCommandRepr::parse(&x.to_bytes()), Ok(x));
    }

    #[test]
    fn accepted_bytes_are_canonical(
        (kind, bytes) in any::<PacketKind>().prop_flat_map(|k| (Just(k), near_miss(k)))
    ) {
        check_verdict(kind, &bytes)?;
    }

    #[test]
    fn parse_reports_the_first_failed_check(
        (kind, bytes) in any::<PacketKind>().prop_flat_map(|k| (Just(k), any_bytes(k)))
    ) {
        check_verdict(kind, &bytes)?;
    }

    #[test]
    #[cfg_attr(miri, ignore = "serde_json's code over the derived (safe) impls; 9 s under Miri")]
    fn every_repr_survives_json(
        c in any::<CommandRepr>(),
        h in any::<HeartbeatRepr>(),
        i in any::<InternalHeartbeatRepr>(),
        b in any::<BCommandRepr>(),
    ) {
        prop_assert_eq!(serde_json::from_str::<CommandRepr>(&serde_json::to_string(&c).unwrap()).unwrap(), c);
        prop_assert_eq!(serde_json::from_str::<HeartbeatRepr>(&serde_json::to_string(&h).unwrap()).unwrap(), h);
        prop_assert_eq!(serde_json::from_str::<InternalHeartbeatRepr>(&serde_json::to_string(&i).unwrap()).unwrap(), i);
        prop_assert_eq!(serde_json::from_str::<BCommandRepr>(&serde_json::to_string(&b).unwrap()).unwrap(), b);
    }
}

/// Draws `n` values from `strategy` with a fixed seed.
fn sample<S: Strategy>(strategy: S, n: usize) -> Vec<S::Value> {
    let mut runner = TestRunner::new_with_rng(
        Config::default(),
        proptest::test_runner::TestRng::deterministic_rng(
            proptest::test_runner::RngAlgorithm::ChaCha,
        ),
    );
    (0..n)
        .map(|_| strategy.new_tree(&mut runner).unwrap().current())
        .collect()
}

#[test]
#[cfg_attr(
    miri,
    ignore = "checks the strategies, not the library, over thousands of fixed-seed draws"
)]
fn command_strategy_reaches_every_opcode() {
    let mut seen = [false; 256];
    for c in sample(any::<Command>(), 20_000) {
        seen[encode(&c).0 as usize] = true;
    }
    let mut classes = 0;
    mmic::arbitrary::for_each_variant_class(
        mmic::units::PulseWidth::CENTER,
        mmic::units::HipAngle::ZERO,
        |c| {
            let id = encode(&c).0;
            assert!(seen[id as usize], "opcode {id:#04x} ({c:?}) never drawn");
            classes += 1;
        },
    );
    assert_eq!(classes, 61);
    assert_eq!(seen.iter().filter(|s| **s).count(), 61);
}

#[test]
#[cfg_attr(
    miri,
    ignore = "checks the strategies, not the library, over thousands of fixed-seed draws"
)]
fn repr_strategies_reach_both_sides_of_every_option_and_the_range_bounds() {
    let hb = sample(any::<HeartbeatRepr>(), 4_000);
    assert!(hb.iter().any(|h| h.target_state.is_none()));
    assert!(hb.iter().any(|h| h.target_state.is_some()));
    assert!(hb.iter().any(|h| h.active_bolter.is_none()));
    assert!(hb.iter().any(|h| h.active_bolter.is_some()));
    assert!(hb.iter().any(|h| h.faults.is_empty()));
    assert!(hb
        .iter()
        .any(|h| h.faults.bits() == mmic::faults::Faults::DEFINED));
    assert!(hb.iter().any(|h| h.refusal.is_none()));
    assert!(hb.iter().any(|h| h.refusal.is_some()));
    assert!(hb.iter().any(|h| h.board.get() == 1));
    assert!(hb.iter().any(|h| h.board.get() == 255));
    assert!(hb.iter().any(|h| h.arm_a_target.micros() == 500));
    assert!(hb.iter().any(|h| h.arm_a_target.micros() == 2500));
    assert!(hb.iter().any(|h| h.hip_now.centidegrees() == 0));
    assert!(hb.iter().any(|h| h.hip_now.centidegrees() == 35999));
    assert!(hb.iter().any(|h| h.bolter_attempt.get() == 3));
    let ih = sample(any::<InternalHeartbeatRepr>(), 4_000);
    assert!(ih.iter().any(|h| h.gravity.is_none()));
    assert!(ih.iter().any(|h| h.gravity.is_some()));
    assert!(ih.iter().any(|h| h.bolter_aux.step.is_none()));
    assert!(ih.iter().any(|h| h.bolter_aux.step.is_some()));
    assert!(ih.iter().any(|h| h.bolter_aux.pair.is_none()));
    assert!(ih.iter().any(|h| h.bolter_aux.pair.is_some()));
    assert!(ih.iter().any(|h| h.bolter_aux.direction.is_none()));
    assert!(ih.iter().any(|h| h.bolter_aux.direction.is_some()));
    assert!(ih.iter().any(|h| h.electrical_b.v_bat == u16::MAX));
    let bc = sample(any::<BCommandRepr>(), 4_000);
    assert!(bc.iter().any(|b| b.bolter.is_none()));
    assert!(bc.iter().any(|b| b.bolter.is_some()));
    assert!(bc.iter().any(|b| b.stop));
    assert!(bc.iter().any(|b| !b.stop));
}

#[test]
#[cfg_attr(
    miri,
    ignore = "checks the strategies, not the library, over thousands of fixed-seed draws"
)]
fn near_misses_reach_both_verdicts_for_every_packet() {
    // The canonicity property is only as good as the share of near misses `parse` accepts.
    for kind in PacketKind::ALL {
        let (mut ok, mut refused) = (0, 0);
        for b in sample(near_miss(kind), 2_000) {
            match parse_emit(kind, &b) {
                Ok(again) => {
                    assert_eq!(again, b);
                    ok += 1;
                }
                Err(_) => refused += 1,
            }
        }
        println!("{kind}: {ok} accepted, {refused} refused of 2000 near misses");
        assert!(
            ok >= 50 && refused >= 50,
            "{kind}: {ok} accepted, {refused} refused"
        );
    }
}

/// Exhaustive: every one of the 40,595 commands, sequenced with the smallest, a mixed-byte and
/// the largest sequence number (and unsequenced), survives emit → parse, and the sequence
/// number sits in the slot `seq_slot` names. Under Miri (.ci/miri), some 100x slower, every
/// opcode class once, at the top of the servos' shared travel and of the hip's circle (61).
#[test]
fn every_command_round_trips_with_its_sequence_number() {
    let board = mmic::units::BoardNumber::ONE;
    let mut n = 0u32;
    let each_command = |visit: &mut dyn FnMut(Command)| {
        if cfg!(miri) {
            mmic::arbitrary::for_each_variant_class(
                mmic::units::PulseWidth::new(2000).unwrap(),
                mmic::units::HipAngle::new(mmic::units::HipAngle::TURN - 1).unwrap(),
                visit,
            );
        } else {
            mmic::arbitrary::for_each_command(visit);
        }
    };
    each_command(&mut |command| {
        for seq in [0u16, 1, 0x0102, u16::MAX] {
            let repr = CommandRepr {
                board,
                command,
                seq,
            };
            let bytes = repr.to_bytes();
            let (id, _) = encode(&command);
            let at = 6 + mmic::wire::opcode::seq_slot(id).offset();
            assert_eq!(u16::from_le_bytes([bytes[at], bytes[at + 1]]), seq);
            assert_eq!(
                CommandRepr::parse(&bytes),
                Ok(repr),
                "{command:?} seq {seq}"
            );
            n += 1;
        }
    });
    assert_eq!(n, 4 * if cfg!(miri) { 61 } else { 40_595 });
}
