//! Harnesses for the PUS services layer (`mmic::pus`): the request parser (ST[8] functions,
//! ST[17], ST[3]), the housekeeping report and the ST[1] reports read every input one way or
//! refuse it by a named check (`mmic_proofs::pus`).
//!
//! Each runs as a randomised test under `cargo test`, as a fuzz target under `cargo bolero
//! test`, and as a proof under `cargo kani --tests` (Kani not installed here: not run). The
//! inputs are fixed-size arrays cut to a symbolic length, so the longest loop (the housekeeping
//! report's 33 fields, its 62 octets) bounds the unwinding: 64.

use mmic_proofs::pus::{check_housekeeping, check_request, check_verification};

/// Any service, subservice and up to 8 octets of application data (the longest valid
/// application data is 6): refused by name, or read canonically.
#[test]
#[cfg_attr(kani, kani::proof, kani::unwind(10))]
fn request_parse_is_canonical_or_refused_by_name() {
    bolero::check!()
        .with_type::<(u8, u8, u8, [u8; 8])>()
        .for_each(|(s, ss, len, data)| {
            // Mostly the served services, so that the application data checks are reached.
            let (s, ss) = match s % 4 {
                0 => (8, 1),
                1 => (3, [5, 6, 31][usize::from(*ss % 3)]),
                2 => (17, *ss % 3),
                _ => (*s, *ss),
            };
            check_request(s, ss, &data[..usize::from(*len % 9)]);
        });
}

/// Any TM(3,25) source data of the report's length or one off it: refused, or exactly the
/// report of the heartbeat it is read into.
#[test]
#[cfg_attr(kani, kani::proof, kani::unwind(64))]
fn housekeeping_parse_is_canonical_or_refused() {
    bolero::check!()
        .with_type::<(u8, [u8; 63])>()
        .for_each(|(len, data)| {
            let n = 61 + usize::from(*len % 3);
            let mut d = *data;
            d[0] = 1; // the structure ID, so that the fields are reached
            check_housekeeping(&d[..n]);
        });
}

/// Any TM(1,x) source data: refused, or exactly the report it is read into.
#[test]
#[cfg_attr(kani, kani::proof, kani::unwind(12))]
fn verification_parse_is_canonical_or_refused() {
    bolero::check!()
        .with_type::<(u8, u8, [u8; 11])>()
        .for_each(|(ss, len, data)| {
            check_verification(*ss % 10, &data[..usize::from(*len % 12)]);
        });
}
