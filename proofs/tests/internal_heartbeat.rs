//! Harnesses for the 47-byte internal heartbeat (Table 4).
//!
//! Each runs as a randomised test under `cargo test`, as a fuzz target under `cargo bolero
//! test`, and as a proof under `cargo kani --tests` (unwind bound: the packet length plus two,
//! which covers the CRC loop over the body; see proofs/README.md).

use mmic::wire::internal_heartbeat::{InternalHeartbeatRepr, INTERNAL_HEARTBEAT_LEN};
use mmic_proofs::{check_parse, check_round_trip, check_round_trip_near_valid};

/// The arbitrary-length harness tries every length up to this many bytes.
const MAX_LEN: usize = 80;

/// `parse` of any INTERNAL_HEARTBEAT_LEN bytes returns, with the documented verdict (see `check_parse`).
#[test]
#[cfg_attr(kani, kani::proof, kani::unwind(49))]
fn internal_heartbeat_parse_never_panics() {
    bolero::check!()
        .with_type::<[u8; INTERNAL_HEARTBEAT_LEN]>()
        .for_each(|bytes| {
            check_parse::<InternalHeartbeatRepr>(bytes);
        });
}

/// `parse` of any slice of up to `MAX_LEN` bytes returns, with the documented verdict: a
/// length error naming both lengths unless the length is right, then header, checksum, fields.
#[test]
#[cfg_attr(kani, kani::proof, kani::unwind(49))]
fn internal_heartbeat_parse_never_panics_any_length() {
    bolero::check!()
        .with_max_len(MAX_LEN)
        .for_each(|bytes: &[u8]| {
            check_parse::<InternalHeartbeatRepr>(bytes);
        });
}

/// Any body with the right header and a correct checksum is accepted canonically
/// (`emit(parse(b)) == b`, `parse(emit(parse(b))) == parse(b)`) or refused by a field or
/// command check, never by the length, header or checksum check.
#[test]
#[cfg_attr(kani, kani::proof, kani::unwind(49))]
fn internal_heartbeat_round_trip() {
    bolero::check!()
        .with_type::<[u8; INTERNAL_HEARTBEAT_LEN]>()
        .for_each(|body| {
            check_round_trip::<InternalHeartbeatRepr>(body);
        });
}

/// A valid value built from any seed survives `parse(emit(x)) == x`; with up to two body
/// bytes then overwritten and the checksum rewritten, the near miss is accepted canonically or
/// refused by a field or command check (see `check_round_trip_near_valid`).
#[test]
#[cfg_attr(kani, kani::proof, kani::unwind(49))]
fn internal_heartbeat_round_trip_near_valid() {
    bolero::check!()
        .with_type::<([u8; INTERNAL_HEARTBEAT_LEN], u8, [[u8; 2]; 2])>()
        .for_each(|(seed, n, edits)| {
            check_round_trip_near_valid::<InternalHeartbeatRepr>(seed, &edits[..*n as usize % 3]);
        });
}
