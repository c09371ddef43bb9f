//! Coverage-guided fuzz targets, one per parser and one for the deframer. Each checks the
//! shared properties of `mmic-proofs`:
//!
//! * `<packet>_parser`: the input as it is must get the documented verdict from `parse`
//!   (`check_parse`: framing errors exactly as the independent oracle says, in the order
//!   length → header → checksum; otherwise canonical acceptance or a field/command error);
//!   then its first `LEN` bytes with the right header and a correct checksum written over them
//!   must be accepted canonically or refused on a field (`check_round_trip`), which lets the
//!   fuzzer mutate the fields of a seed packet without every mutation dying at the checksum.
//! * `pus_tc_parser`, `pus_tm_parser`: the input (cut to `MAX_PACKET` octets) must get
//!   exactly the oracle's verdict from the CCSDS/PUS parser (`check_pus_parse`), and when
//!   accepted re-emit identically; then, if long enough, the same octets with the length field
//!   and CRC rewritten over them (`reseal`) and their own APID accepted, which lets mutations
//!   reach the checks after the checksum.
//! * `tc_frame_parser`: the input (cut to 1024 octets) must get exactly the TC frame oracle's
//!   verdict (`mmic_proofs::link::check_tc_frame_parse`, two channels), and when accepted split
//!   into packets as the oracle does and re-emit identically; then, if long enough, the same
//!   octets with the frame length field and FECF rewritten, on the channel of the frame's own
//!   spacecraft, which lets mutations reach the addressing and content checks.
//! * `pus_request`: service, subservice and application data through the services layer's
//!   `Request::parse` (`mmic_proofs::pus::check_request`): refused by a named check, or read
//!   canonically (an accepted function encodes back to the same octets).
//! * `pus_housekeeping`, `pus_verification`, `pus_event`: TM(3,25), TM(1,x) and TM(5,x) source
//!   data through the ground side's readers: refused, or read into a value that writes back exactly the input.
//! * `tm_frame_parser`: the input (cut to 300 octets) through the TM frame parser under the
//!   mission's parameters, exactly the oracle's verdict (`check_tm_frame_parse`); then its
//!   first 256 octets with the spacecraft ID set and the FECF rewritten (the later checks).
//! * `tm_extractor`: the input as a framer → extractor run with frame loss (`check_link`) and
//!   as a stream of arbitrary frames through the parser and the extractor.
//! * `deframer_stream`: four bytes of chunk plan, then the stream, fed as it is to deframers
//!   with the smallest (66) and a larger (256) buffer, and once more after `build_stream` has
//!   turned it into packets with sound framing, garbage and near misses; `run_deframer` checks
//!   byte conservation, frame contents and offsets, and that nothing is left after `resync`.
//! * `sdls_tc_verify`, `sdls_tm_verify`: Space Data Link Security (`mmic_proofs::sdls`): any
//!   octets through a secured gateway's `tc_frame` and through the receiving `SaTable`
//!   directly, and through a secured ground link's `tm_frame`, as they are and with the frame
//!   checks' fields and FECF written over them: refused and counted, nothing changed, no
//!   packet handed on, unless exactly a frame the (fixed, test) key's holder protected.
//! * `server_store`: the server board's durable store (`mmic_proofs::store`): a selector
//!   octet, then 20 octets as a flash log record, any octets as the `mmic_keys` partition, or a
//!   robot, a slot and 12 octets as a queue slot: refused by name, or read exactly as written.
//! * `link_clcw`, `link_cop`: COP-1 of the space data link (`mmic_proofs::link_cop`): the
//!   CLCW's verdict and round trip; FARM-1 taking AD frames once and in order, FOP-1 keeping
//!   its window and confirming in order, over any sequence of events.

use mmic::ccsds::primary::{PacketType, PrimaryHeader};
use mmic::wire::b_command::BCommandRepr;
use mmic::wire::command::CommandRepr;
use mmic::wire::heartbeat::HeartbeatRepr;
use mmic::wire::internal_heartbeat::InternalHeartbeatRepr;
use mmic::wire::MAX_PACKET_LEN;
use mmic_proofs::ccsds::{check_pus_parse, check_pus_parse_with, min_len, reseal, MAX_PACKET};
use mmic_proofs::{build_stream, check_parse, check_round_trip, run_deframer, Repr};

/// Random inputs each target runs under plain `cargo test`, after its committed corpus and
/// crashes: a fixed count (bolero's default is as many as fit in one second, a count that
/// changes with the machine's load), so that the README's command does the same work on every
/// run. The fuzzing itself is `cargo bolero test` (CI's fuzz step and the campaigns, README),
/// where this count does not apply; `BOLERO_RANDOM_ITERATIONS=N cargo test -p mmic-fuzz` runs
/// N instead.
const RANDOM_INPUTS: usize = 10_000;

fn parser<R: Repr>(input: &[u8]) {
    check_parse::<R>(input);
    check_round_trip::<R>(input);
}

fn pus_parser(kind: PacketType, input: &[u8]) {
    let input = &input[..input.len().min(MAX_PACKET)];
    check_pus_parse(kind, input);
    if input.len() >= min_len(kind) {
        let mut buf = [0u8; MAX_PACKET];
        let packet = &mut buf[..input.len()];
        packet.copy_from_slice(input);
        reseal(packet);
        let apid = PrimaryHeader::read(packet).map_or(0, |h| h.apid);
        check_pus_parse_with(kind, packet, &[apid]);
    }
}

/// A TC transfer frame (cut to `MAX_FRAME` octets) through `TcFrameRepr::parse` on both of the
/// oracle's channels (`check_tc_frame_parse`); then, if long enough, the same octets with the
/// length field and FECF rewritten, on the FECF channel of the frame's own spacecraft with
/// frames up to 1024 octets, which lets mutations reach the checks after the FECF.
fn tc_frame_parser_property(input: &[u8]) {
    use mmic::link::tc_frame::{SpacecraftId, TcFrameConfig, TcPrimaryHeader};
    use mmic_proofs::link::{check_tc_frame_parse, check_tc_frame_parse_with, CONFIGS, MAX_FRAME};
    let input = &input[..input.len().min(MAX_FRAME)];
    check_tc_frame_parse(input);
    if input.len() >= 8 {
        let mut buf = [0u8; MAX_FRAME];
        let frame = &mut buf[..input.len()];
        frame.copy_from_slice(input);
        mmic_proofs::link::reseal(frame, true);
        let scid = TcPrimaryHeader::read(frame).map_or(0, |h| h.spacecraft_id);
        let cfg = TcFrameConfig {
            spacecraft_id: SpacecraftId::new(scid).expect("10 bits"),
            max_frame_len: MAX_FRAME,
            ..CONFIGS[0]
        };
        check_tc_frame_parse_with(frame, &cfg);
    }
}

#[test]
fn tc_frame_parser() {
    bolero::check!()
        .with_iterations(RANDOM_INPUTS)
        .for_each(tc_frame_parser_property);
}

#[test]
fn pus_tc_parser() {
    bolero::check!()
        .with_iterations(RANDOM_INPUTS)
        .for_each(|input: &[u8]| pus_parser(PacketType::Tc, input));
}

#[test]
fn pus_tm_parser() {
    bolero::check!()
        .with_iterations(RANDOM_INPUTS)
        .for_each(|input: &[u8]| pus_parser(PacketType::Tm, input));
}

/// The services layer: two octets of service and subservice, then the application data.
#[test]
fn pus_request() {
    bolero::check!()
        .with_iterations(RANDOM_INPUTS)
        .for_each(|input: &[u8]| {
            if let [service, subservice, data @ ..] = input {
                mmic_proofs::pus::check_request(*service, *subservice, data);
            }
        });
}

/// TM(3,25) source data through `housekeeping::parse`.
#[test]
fn pus_housekeeping() {
    bolero::check!()
        .with_iterations(RANDOM_INPUTS)
        .for_each(|input: &[u8]| {
            mmic_proofs::pus::check_housekeeping(input);
        });
}

/// A subservice octet, then TM(1,x) source data through `verification::Report::parse`.
#[test]
fn pus_verification() {
    bolero::check!()
        .with_iterations(RANDOM_INPUTS)
        .for_each(|input: &[u8]| {
            if let [subservice, data @ ..] = input {
                mmic_proofs::pus::check_verification(*subservice, data);
            }
        });
}

/// A subservice octet, then TM(5,x) source data through `event::Event::parse`.
#[test]
fn pus_event() {
    bolero::check!()
        .with_iterations(RANDOM_INPUTS)
        .for_each(|input: &[u8]| {
            if let [subservice, data @ ..] = input {
                mmic_proofs::pus::check_event(*subservice, data);
            }
        });
}

/// The TM frame parser: the input (cut to 300 octets) under the mission's parameters must get
/// exactly the oracle's verdict (`check_tm_frame_parse`); then, if long enough, its first 256
/// octets with the IDs and fixed flags set and the FECF rewritten, which reaches the checks
/// after the FECF and acceptance.
#[test]
fn tm_frame_parser() {
    use mmic_proofs::link_tm::{check_tm_frame_parse, reseal, PARAMS};
    bolero::check!()
        .with_iterations(RANDOM_INPUTS)
        .for_each(|input: &[u8]| {
            let input = &input[..input.len().min(300)];
            check_tm_frame_parse(input, &PARAMS);
            if input.len() >= 256 {
                let mut f = input[..256].to_vec();
                // Spacecraft 0x142 and segment length ID 11 set; version, VCID, OCF flag, the
                // other flags and the pointer left as the input has them (each check reachable).
                f[0] = (f[0] & 0xc0) | 0x14;
                f[1] = (f[1] & 0x0f) | 0x20;
                f[4] |= 0x18;
                reseal(&mut f);
                check_tm_frame_parse(&f, &PARAMS);
            }
        });
}

/// The TM link: the input as a run of the framer and the extractor with frame loss
/// (`check_link`, the input cut to 80 octets: at most 71 steps), and as a stream of arbitrary
/// frames through the parser and the extractor (`check_extractor_stream`).
#[test]
fn tm_extractor() {
    use mmic_proofs::link_tm::{check_extractor_stream, check_link};
    bolero::check!()
        .with_iterations(RANDOM_INPUTS)
        .for_each(|input: &[u8]| {
            check_link(&input[..input.len().min(80)], true);
            check_extractor_stream(input);
        });
}

#[test]
fn command_parser() {
    bolero::check!()
        .with_iterations(RANDOM_INPUTS)
        .for_each(parser::<CommandRepr>);
}

#[test]
fn heartbeat_parser() {
    bolero::check!()
        .with_iterations(RANDOM_INPUTS)
        .for_each(parser::<HeartbeatRepr>);
}

#[test]
fn internal_heartbeat_parser() {
    bolero::check!()
        .with_iterations(RANDOM_INPUTS)
        .for_each(parser::<InternalHeartbeatRepr>);
}

#[test]
fn b_command_parser() {
    bolero::check!()
        .with_iterations(RANDOM_INPUTS)
        .for_each(parser::<BCommandRepr>);
}

#[test]
fn deframer_stream() {
    bolero::check!()
        .with_iterations(RANDOM_INPUTS)
        .for_each(|input: &[u8]| {
            let (plan, stream) = input.split_at(input.len().min(4));
            run_deframer::<MAX_PACKET_LEN>(stream, plan, |_, _| {});
            run_deframer::<256>(stream, plan, |_, _| {});
            let mut built = [0u8; 4096];
            let n = build_stream(stream, &mut built);
            run_deframer::<MAX_PACKET_LEN>(&built[..n], plan, |_, _| {});
        });
}

/// Four octets (zero-padded) through `Clcw::parse`: the verdict of the CLCW's bit table, the
/// fields where it puts them, `emit` back to the same octets
/// (`mmic_proofs::link_cop::check_clcw_word`); any other length refused by the length check.
#[test]
fn link_clcw() {
    bolero::check!()
        .with_iterations(RANDOM_INPUTS)
        .for_each(|input: &[u8]| {
            let mut w = [0u8; 4];
            let n = input.len().min(4);
            w[..n].copy_from_slice(&input[..n]);
            mmic_proofs::link_cop::check_clcw_word(u32::from_be_bytes(w));
            if input.len() != 4 {
                let e = mmic::link::clcw::Clcw::parse(input).err().map(|e| e.name());
                assert_eq!(e, Some("length"));
            }
        });
}

/// Octet 0 even: FARM-1 (octet 1 the window, then events of three octets) through
/// `check_farm_events`; odd: FOP-1 (octet 1 its options, then inputs of two octets) through
/// `check_fop_inputs`. At most 64 events.
#[test]
fn link_cop() {
    bolero::check!()
        .with_iterations(RANDOM_INPUTS)
        .for_each(|input: &[u8]| {
            let [which, param, rest @ ..] = input else {
                return;
            };
            if which % 2 == 0 {
                let evs: Vec<(u8, u8, bool)> = rest
                    .chunks_exact(3)
                    .take(64)
                    .map(|c| (c[0], c[1], c[2] & 1 == 1))
                    .collect();
                mmic_proofs::link_cop::check_farm_events(*param, &evs);
            } else {
                let inputs: Vec<(u8, u8)> = rest
                    .chunks_exact(2)
                    .take(64)
                    .map(|c| (c[0], c[1]))
                    .collect();
                mmic_proofs::link_cop::check_fop_inputs(*param, &inputs);
            }
        });
}

/// SDLS on the uplink: the octets (cut to 264) through a fresh secured `FrameGateway`'s
/// `tc_frame` and through its receiving `SaTable` directly (`check_secured_tc_frame`), as they
/// are and with spacecraft, VC, length field and FECF written over them (past the frame
/// checks, into SDLS's). The keys are fixed test keys made at run time
/// (`mmic_proofs::sdls::test_key`), not secrets.
#[test]
fn sdls_tc_verify() {
    bolero::check!()
        .with_iterations(RANDOM_INPUTS)
        .for_each(|input: &[u8]| {
            mmic_proofs::sdls::check_secured_tc_frame(input);
            mmic_proofs::sdls::check_secured_tc_frame_resealed(input);
        });
}

/// SDLS on the downlink: the octets (cut to 300) through a fresh secured `GroundLink`'s
/// `tm_frame` (`check_secured_tm_frame`), then their first 256 with spacecraft 0x101 and the
/// FECF written over them.
#[test]
fn sdls_tm_verify() {
    bolero::check!()
        .with_iterations(RANDOM_INPUTS)
        .for_each(|input: &[u8]| {
            let input = &input[..input.len().min(300)];
            mmic_proofs::sdls::check_secured_tm_frame(input);
            mmic_proofs::sdls::check_secured_tm_frame_resealed(input);
        });
}

/// The server board's durable store (issue 38): a selector octet, then the input of one of its
/// readers (`mmic_proofs::store`): a flash log record, the keys partition, a queue slot.
#[test]
fn server_store() {
    bolero::check!()
        .with_iterations(RANDOM_INPUTS)
        .for_each(|input: &[u8]| match input {
            [0, rest @ ..] if rest.len() >= 20 => {
                let mut r = [0u8; 20];
                r.copy_from_slice(&rest[..20]);
                mmic_proofs::store::check_log_record(&r);
            }
            [1, rest @ ..] => {
                mmic_proofs::store::check_keys_partition(&rest[..rest.len().min(600)]);
            }
            [2, board, slot, rest @ ..] if rest.len() >= 12 => {
                if let Ok(b) = mmic::units::BoardNumber::new(*board) {
                    let mut v = [0u8; 16];
                    v[4..].copy_from_slice(&rest[..12]);
                    mmic_proofs::store::check_queue_value(b, *slot % 16, u128::from_be_bytes(v));
                }
            }
            _ => {}
        });
}

/// A CFDP PDU (cut to `MAX_PDU` octets) through `cfdp::Pdu::parse`: exactly the oracle's verdict
/// (`mmic_proofs::cfdp::check_cfdp_parse`), and an accepted PDU re-emits to the same octets
/// but for the version; then its data field through `cfdp::directive::PduRepr::parse`: refused
/// by a directive check, or fields that re-emit to the same octets but for the spare bits
/// (`mmic_proofs::cfdp::check_cfdp_directive`).
#[test]
fn cfdp_pdu() {
    bolero::check!()
        .with_iterations(RANDOM_INPUTS)
        .for_each(|input: &[u8]| {
            let input = &input[..input.len().min(mmic_proofs::cfdp::MAX_PDU)];
            mmic_proofs::cfdp::check_cfdp_parse(input);
            mmic_proofs::cfdp::check_cfdp_directive(input);
        });
}
