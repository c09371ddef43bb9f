//! Coverage-guided fuzz targets, one per parser and one for the deframer. Each checks the
//! shared properties of `mmic-proofs`:
//!
//! * `<packet>_parser`: the input as it is must get the documented verdict from `parse`
//!   (`check_parse`: framing errors exactly as the independent oracle says, in the order
//!   length → header → checksum; otherwise canonical acceptance or a field/command error);
//!   then its first `LEN` bytes with the right header and a correct checksum written over them
//!   must be accepted canonically or refused on a field (`check_round_trip`), which lets the
//!   fuzzer mutate the fields of a seed packet without every mutation dying at the checksum.
//! * `deframer_stream`: four bytes of chunk plan, then the stream, fed as it is to deframers
//!   with the smallest (66) and a larger (256) buffer, and once more after `build_stream` has
//!   turned it into packets with sound framing, garbage and near misses; `run_deframer` checks
//!   byte conservation, frame contents and offsets, and that nothing is left after `resync`.

use mmic::wire::b_command::BCommandRepr;
use mmic::wire::command::CommandRepr;
use mmic::wire::heartbeat::HeartbeatRepr;
use mmic::wire::internal_heartbeat::InternalHeartbeatRepr;
use mmic::wire::MAX_PACKET_LEN;
use mmic_proofs::{build_stream, check_parse, check_round_trip, run_deframer, Repr};

fn parser<R: Repr>(input: &[u8]) {
    check_parse::<R>(input);
    check_round_trip::<R>(input);
}

#[test]
fn command_parser() {
    bolero::check!().for_each(parser::<CommandRepr>);
}

#[test]
fn heartbeat_parser() {
    bolero::check!().for_each(parser::<HeartbeatRepr>);
}

#[test]
fn internal_heartbeat_parser() {
    bolero::check!().for_each(parser::<InternalHeartbeatRepr>);
}

#[test]
fn b_command_parser() {
    bolero::check!().for_each(parser::<BCommandRepr>);
}

#[test]
fn deframer_stream() {
    bolero::check!().for_each(|input: &[u8]| {
        let (plan, stream) = input.split_at(input.len().min(4));
        run_deframer::<MAX_PACKET_LEN>(stream, plan, |_, _| {});
        run_deframer::<256>(stream, plan, |_, _| {});
        let mut built = [0u8; 4096];
        let n = build_stream(stream, &mut built);
        run_deframer::<MAX_PACKET_LEN>(&built[..n], plan, |_, _| {});
    });
}
