//! Harnesses for the PUS services layer (`mmic::pus`): the request parser (ST[8] functions,
//! ST[17], ST[3]), the housekeeping report and the ST[1] reports read every input one way or
//! refuse it by a named check (`mmic_proofs::pus`).
//!
//! Each runs as a randomised test under `cargo test`, as a fuzz target under `cargo bolero
//! test`, and as a proof under `cargo kani --tests` (Kani not installed here: not run). The
//! inputs are fixed-size arrays cut to a symbolic length, so the longest loop (the housekeeping
//! report's 33 fields, its 62 octets) bounds the unwinding: 64.

use mmic_proofs::pus::{check_housekeeping, check_request, check_verification};

/// Sampled values per harness under `cargo test` (see `crate::ledger`).
#[cfg(not(any(kani, fuzzing)))]
const SAMPLED: u64 = 100_000;

/// The property of [`request_parse_is_canonical_or_refused_by_name`] for one input.
fn request(&(s, ss, len, data): &(u8, u8, u8, [u8; 8])) {
    // Mostly the served services, so that the application data checks are reached.
    let (s, ss) = match s % 4 {
        0 => (8, 1),
        1 => (3, [5, 6, 31][usize::from(ss % 3)]),
        2 => (17, ss % 3),
        _ => (s, ss),
    };
    check_request(s, ss, &data[..usize::from(len % 9)]);
}

/// Any service, subservice and up to 8 octets of application data (the longest valid
/// application data is 6): refused by name, or read canonically.
///
/// Under `cargo test`: exhaustively, every service and subservice (all 65,536 pairs, straight
/// to `check_request`) with 0..=8 zero octets of data; and for each of the 7 served pairs the
/// generator aims at, every data length 0..=8 and every value of each data octet with the
/// others zero; then sampled inputs.
#[test]
#[cfg_attr(kani, kani::proof, kani::unwind(10))]
fn request_parse_is_canonical_or_refused_by_name() {
    #[cfg(not(any(kani, fuzzing)))]
    {
        let name = "request_parse_is_canonical_or_refused_by_name";
        crate::ledger::exhaustive(
            &format!("{name} (every service)"),
            65_536 * 9,
            (bolero::produce::<u8>(), bolero::produce::<u8>(), 0usize..9),
            |&(s, ss, len)| {
                check_request(s, ss, &[0; 8][..len]);
            },
        );
        crate::ledger::exhaustive(
            &format!("{name} (served)"),
            7 * 9 * 8 * 256,
            (0usize..7, 0u8..9, 0usize..8, bolero::produce::<u8>()),
            |&(pair, len, at, v)| {
                // (s % 4, ss) of the generator: (8,1), (3,5), (3,6), (3,31), (17,0..=2).
                let (s, ss) = [(0, 0), (1, 0), (1, 1), (1, 2), (2, 0), (2, 1), (2, 2)][pair];
                let mut data = [0u8; 8];
                data[at] = v;
                request(&(s, ss, len, data));
            },
        );
        crate::ledger::sampled(name, SAMPLED, request);
        return;
    }
    #[allow(unreachable_code)]
    bolero::check!()
        .with_type::<(u8, u8, u8, [u8; 8])>()
        .for_each(request);
}

/// The property of [`housekeeping_parse_is_canonical_or_refused`] for one input.
fn housekeeping(&(len, data): &(u8, [u8; 63])) {
    let n = 61 + usize::from(len % 3);
    let mut d = data;
    d[0] = 1; // the structure ID, so that the fields are reached
    check_housekeeping(&d[..n]);
}

/// Any TM(3,25) source data of the report's length or one off it: refused, or exactly the
/// report of the heartbeat it is read into.
///
/// Under `cargo test`: exhaustively, each of the three lengths with every value of each octet
/// after the structure ID, the others zero (every value of every one-octet field; each octet
/// of the wider ones), then sampled inputs.
#[test]
#[cfg_attr(kani, kani::proof, kani::unwind(64))]
fn housekeeping_parse_is_canonical_or_refused() {
    #[cfg(not(any(kani, fuzzing)))]
    {
        let name = "housekeeping_parse_is_canonical_or_refused";
        crate::ledger::exhaustive(
            name,
            3 * 62 * 256,
            (0u8..3, 1usize..63, bolero::produce::<u8>()),
            |&(len, at, v)| {
                let mut data = [0u8; 63];
                data[at] = v;
                housekeeping(&(len, data));
            },
        );
        crate::ledger::sampled(name, SAMPLED, housekeeping);
        return;
    }
    #[allow(unreachable_code)]
    bolero::check!()
        .with_type::<(u8, [u8; 63])>()
        .for_each(housekeeping);
}

/// The property of [`verification_parse_is_canonical_or_refused`] for one input.
fn verification(&(ss, len, data): &(u8, u8, [u8; 11])) {
    check_verification(ss % 10, &data[..usize::from(len % 12)]);
}

/// Any TM(1,x) source data: refused, or exactly the report it is read into.
///
/// Under `cargo test`: exhaustively, every subservice 0..=9, every length 0..=11 and every
/// value of each octet with the others zero; then sampled inputs.
#[test]
#[cfg_attr(kani, kani::proof, kani::unwind(12))]
fn verification_parse_is_canonical_or_refused() {
    #[cfg(not(any(kani, fuzzing)))]
    {
        let name = "verification_parse_is_canonical_or_refused";
        crate::ledger::exhaustive(
            name,
            10 * 12 * 11 * 256,
            (0u8..10, 0u8..12, 0usize..11, bolero::produce::<u8>()),
            |&(ss, len, at, v)| {
                let mut data = [0u8; 11];
                data[at] = v;
                verification(&(ss, len, data));
            },
        );
        crate::ledger::sampled(name, SAMPLED, verification);
        return;
    }
    #[allow(unreachable_code)]
    bolero::check!()
        .with_type::<(u8, u8, [u8; 11])>()
        .for_each(verification);
}
