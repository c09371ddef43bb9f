//! Harnesses for the CCSDS/PUS wire layer (`mmic::ccsds`): the parsers against the oracle of
//! `mmic_proofs::ccsds`, emit → parse and parse → emit.
//!
//! Each runs as a randomised test under `cargo test`, as a fuzz target under `cargo bolero
//! test`, and as a proof under `cargo kani --tests` (Kani not installed here: not run). Under
//! Kani the inputs are short (`MAX_LEN` 24 octets: a TM without data is 21) and the sampled
//! data at most 4 octets, so the longest loops, the CRCs over the packet (the library's and the
//! oracle's bitwise one) and the copies, run at most 24 times: unwind 26.

use mmic::ccsds::primary::PacketType;
use mmic_proofs::ccsds::{check_pus_near_valid, check_pus_parse, check_pus_round_trip};

/// Longest input of the parse harnesses.
#[cfg(not(kani))]
const MAX_LEN: usize = 80;
#[cfg(kani)]
const MAX_LEN: usize = 24;

/// Octets of data the sampled packets draw their user data from.
#[cfg(not(kani))]
const DATA: usize = 48;
#[cfg(kani)]
const DATA: usize = 4;

/// Seed octets of a sampled packet (TM: 18 choices).
const SEED: usize = 20;

/// `TcRepr::parse` of any octets gives exactly the oracle's verdict (check and numbers);
/// accepted packets re-emit to the same octets.
#[test]
#[cfg_attr(kani, kani::proof, kani::unwind(26))]
fn pus_tc_parse_matches_oracle() {
    bolero::check!()
        .with_max_len(MAX_LEN)
        .for_each(|bytes: &[u8]| {
            check_pus_parse(PacketType::Tc, bytes);
        });
}

/// The same for `TmRepr::parse`.
#[test]
#[cfg_attr(kani, kani::proof, kani::unwind(26))]
fn pus_tm_parse_matches_oracle() {
    bolero::check!()
        .with_max_len(MAX_LEN)
        .for_each(|bytes: &[u8]| {
            check_pus_parse(PacketType::Tm, bytes);
        });
}

/// Any telecommand emits with its stated length and parses back to itself; with its APID
/// not accepted, it is refused by the APID check.
#[test]
#[cfg_attr(kani, kani::proof, kani::unwind(26))]
fn pus_tc_round_trip() {
    bolero::check!()
        .with_type::<([u8; SEED], [u8; DATA])>()
        .for_each(|(seed, data)| check_pus_round_trip(PacketType::Tc, seed, data));
}

/// The same for telemetry.
#[test]
#[cfg_attr(kani, kani::proof, kani::unwind(26))]
fn pus_tm_round_trip() {
    bolero::check!()
        .with_type::<([u8; SEED], [u8; DATA])>()
        .for_each(|(seed, data)| check_pus_round_trip(PacketType::Tm, seed, data));
}

/// A valid telecommand with up to two octets overwritten, its length field and CRC
/// rewritten or not: the oracle's verdict, and parse → emit identity when accepted.
#[test]
#[cfg_attr(kani, kani::proof, kani::unwind(26))]
fn pus_tc_near_valid() {
    bolero::check!()
        .with_type::<([u8; SEED], [u8; DATA], u8, [[u8; 2]; 2])>()
        .for_each(|(seed, data, n, edits)| {
            check_pus_near_valid(
                PacketType::Tc,
                seed,
                data,
                &edits[..*n as usize % 3],
                n & 0x80 == 0,
            );
        });
}

/// The same for telemetry.
#[test]
#[cfg_attr(kani, kani::proof, kani::unwind(26))]
fn pus_tm_near_valid() {
    bolero::check!()
        .with_type::<([u8; SEED], [u8; DATA], u8, [[u8; 2]; 2])>()
        .for_each(|(seed, data, n, edits)| {
            check_pus_near_valid(
                PacketType::Tm,
                seed,
                data,
                &edits[..*n as usize % 3],
                n & 0x80 == 0,
            );
        });
}
