//! Harness for the CFDP PDU layer (`mmic::cfdp`): the PDU reader against the oracle of
//! `mmic_proofs::cfdp`, and parse → emit.
//!
//! It runs as a randomised test under `cargo test`, as a fuzz target under `cargo bolero
//! test`, and as a proof under `cargo kani --tests` (Kani not installed here: not run). Under
//! Kani the inputs are at most 24 octets (the mission's header is 12), so the longest loops, the
//! CRCs over the PDU (the library's and the oracle's bitwise one) and the copies, run at most
//! 24 times: unwind 26.

use mmic_proofs::cfdp::check_cfdp_parse;

/// Longest input of the harness.
#[cfg(not(kani))]
const MAX_LEN: usize = 80;
#[cfg(kani)]
const MAX_LEN: usize = 24;

/// Sampled values under `cargo test` (see `crate::ledger`).
#[cfg(not(any(kani, fuzzing)))]
const SAMPLED: u64 = 50_000;

/// The base PDUs of the exhaustive parts: YAMCS's EOF (no CRC), the same with the CRC flag
/// and its CRC, a file data PDU with 1-octet IDs and an 8-octet sequence number, and one with
/// 8-octet IDs and a 1-octet sequence number; `out` receives it, its length returned.
#[cfg(not(any(kani, fuzzing)))]
fn base(k: usize, out: &mut [u8]) -> usize {
    use mmic::cfdp::header::{Direction, Lengths, Mode, PduHeader, PduType};
    let header = |pdu_type, crc, entity, seq| PduHeader {
        pdu_type,
        direction: Direction::TowardReceiver,
        mode: Mode::Acknowledged,
        crc,
        segmentation: false,
        lengths: Lengths { entity, seq },
        data_len: 0,
        source: 0x18,
        seq: 1,
        dest: 0x15,
    };
    let eof = [0x04, 0x80, 0, 0, 0, 0, 0, 0, 0x65, 0xfc];
    let (h, data): (PduHeader, &[u8]) = match k {
        0 => (header(PduType::Directive, false, 2, 4), &eof),
        1 => (header(PduType::Directive, true, 2, 4), &eof),
        2 => (
            header(PduType::FileData, true, 1, 8),
            &[0, 0, 0, 0, b'm', b'm'],
        ),
        _ => (header(PduType::FileData, false, 8, 1), &[0, 0, 1, 0, 7]),
    };
    mmic::cfdp::emit(&h, data, out).expect("the base PDUs fit")
}

/// `Pdu::parse` of any octets gives exactly the oracle's verdict (check and numbers); accepted
/// PDUs re-emit to the same octets but for the version.
///
/// Under `cargo test`, exhaustive: every input of 0, 1 or 2 octets; every single-octet
/// substitution (each of the first 32 positions, modulo the length, each value) of the four
/// base PDUs; every prefix (0..=`MAX_LEN` octets, zero-padded) of each; then sampled inputs of
/// every length.
#[test]
#[cfg_attr(kani, kani::proof, kani::unwind(26))]
fn cfdp_parse_matches_oracle() {
    #[cfg(not(any(kani, fuzzing)))]
    {
        let name = "cfdp_parse_matches_oracle";
        crate::ledger::exhaustive(
            name,
            3 * 65_536,
            (0usize..3, bolero::produce::<[u8; 2]>()),
            |&(n, b)| {
                check_cfdp_parse(&b[..n]);
            },
        );
        crate::ledger::exhaustive(
            &format!("{name} (substitutions)"),
            4 * 32 * 256,
            (0usize..4, 0usize..32, bolero::produce::<u8>()),
            |&(k, at, v)| {
                let mut out = [0u8; MAX_LEN];
                let n = base(k, &mut out);
                out[at % n] = v;
                check_cfdp_parse(&out[..n]);
            },
        );
        crate::ledger::exhaustive(
            &format!("{name} (prefixes)"),
            4 * (MAX_LEN as u64 + 1),
            (0usize..4, 0usize..=MAX_LEN),
            |&(k, len)| {
                let mut out = [0u8; MAX_LEN];
                base(k, &mut out);
                check_cfdp_parse(&out[..len]);
            },
        );
        crate::ledger::sampled_with(
            name,
            SAMPLED,
            |seed, i| crate::ledger::sample_bytes(seed, i, MAX_LEN),
            |bytes| {
                check_cfdp_parse(bytes);
            },
        );
        return;
    }
    #[allow(unreachable_code)]
    bolero::check!()
        .with_max_len(MAX_LEN)
        .for_each(|bytes: &[u8]| {
            check_cfdp_parse(bytes);
        });
}
