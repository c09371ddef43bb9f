//! The `Repr` trait's own `emit` and the command packet's read-only accessors: what generic
//! code over packets (and a board answering a packet whose opcode does not decode) calls.

use crate::common::prop::config;
use mmic::command::Command;
use mmic::units::BoardNumber;
use mmic::wire::b_command::BCommandRepr;
use mmic::wire::command::{CommandPacket, CommandRepr};
use mmic::wire::heartbeat::HeartbeatRepr;
use mmic::wire::internal_heartbeat::InternalHeartbeatRepr;
use mmic::wire::{check, Repr};
use proptest::prelude::*;

/// `Repr::emit` into a buffer of garbage writes the whole packet: the same bytes as
/// `to_bytes`, parsed back to the value.
fn emits_whole<R: Repr<Bytes = [u8; N]>, const N: usize>(r: R) -> Result<(), TestCaseError> {
    let mut out = [0xa5u8; N];
    <R as Repr>::emit(&r, &mut out);
    prop_assert_eq!(out, r.to_bytes());
    prop_assert_eq!(R::parse(&out), Ok(r));
    Ok(())
}

proptest! {
    #![proptest_config(config(64))]

    #[test]
    fn the_trait_emit_writes_every_packet_whole(
        c in any::<CommandRepr>(),
        h in any::<HeartbeatRepr>(),
        i in any::<InternalHeartbeatRepr>(),
        b in any::<BCommandRepr>(),
    ) {
        emits_whole(c)?;
        emits_whole(h)?;
        emits_whole(i)?;
        emits_whole(b)?;
    }
}

/// A checked command packet's opcode and number, read without decoding it.
#[test]
fn a_checked_command_packet_shows_its_opcode_and_number() {
    for (command, opcode) in [(Command::Stop, 0x02), (Command::Heartbeat, 0x01)] {
        let bytes = CommandRepr {
            board: BoardNumber::ONE,
            command,
            seq: 0x1234,
        }
        .to_bytes();
        let p: &CommandPacket = check(&bytes).unwrap();
        assert_eq!((p.opcode(), p.seq()), (opcode, 0x1234), "{command:?}");
    }
}
