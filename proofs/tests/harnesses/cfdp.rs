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

/// The LibreCube PDUs of `tests/ccsds/cfdp_directive.rs` (one of each directive and file data,
/// 0x0102 to 0x0304, transaction 0x0A0B0C0D): the bases of the directive harness.
#[cfg(not(any(kani, fuzzing)))]
const LIBRECUBE: [&str; 9] = [
    "20001f1301020a0b0c0d03040740000004d208706c616e2e7478740f2f726f626f742f706c616e2e747874",
    "3000091301020a0b0c0d03040000001068656c6c6f",
    "20000a1301020a0b0c0d03040400181c2015000004d2",
    "2800021301020a0b0c0d0304050a",
    "2800031301020a0b0c0d0304064001",
    "2000031301020a0b0c0d0304065102",
    "2800191301020a0b0c0d030408000000000000040000000000000000000000020000000300",
    "2000021301020a0b0c0d03040980",
    "2800051301020a0b0c0d03040c00000200",
];

/// A PDU from 0x0102 to 0x0304 whose data field is `data`, direction bit `dir`.
#[cfg(not(any(kani, fuzzing)))]
fn directive_pdu(dir: u8, data: &[u8], out: &mut [u8]) -> usize {
    let len = (data.len() as u16).to_be_bytes();
    let head = [
        0x20 | dir << 3,
        len[0],
        len[1],
        0x13,
        1,
        2,
        0xa,
        0xb,
        0xc,
        0xd,
        3,
        4,
    ];
    out[..12].copy_from_slice(&head);
    out[12..12 + data.len()].copy_from_slice(data);
    12 + data.len()
}

/// `PduRepr::parse` of any PDU the PDU layer accepts either refuses it by a directive check or
/// reads fields that re-emit to the same octets but for the spare bits, the ACK's subtype and
/// the version, and read back the same (`mmic_proofs::cfdp::check_cfdp_directive`).
///
/// Under `cargo test`, exhaustive: every data field of one or two octets, each direction
/// (every directive code with every next octet); every ACK (its two octets after the code,
/// each direction); every single-octet substitution of each of the nine LibreCube PDUs (each
/// of its first 48 positions, modulo its length, each value); then sampled data fields of up
/// to 60 octets after a valid header, the first octet a directive code half the time.
#[test]
#[cfg_attr(kani, kani::proof, kani::unwind(26))]
fn cfdp_directive_reads_back() {
    #[cfg(not(any(kani, fuzzing)))]
    {
        use mmic_proofs::cfdp::check_cfdp_directive;
        let name = "cfdp_directive_reads_back";
        crate::ledger::exhaustive(
            name,
            2 * 2 * 65_536,
            (0u8..2, 1usize..3, bolero::produce::<[u8; 2]>()),
            |&(dir, n, b)| {
                let mut out = [0u8; 16];
                let len = directive_pdu(dir, &b[..n], &mut out);
                check_cfdp_directive(&out[..len]);
            },
        );
        crate::ledger::exhaustive(
            &format!("{name} (ACK)"),
            2 * 65_536,
            (0u8..2, bolero::produce::<[u8; 2]>()),
            |&(dir, b)| {
                let mut out = [0u8; 16];
                let len = directive_pdu(dir, &[0x06, b[0], b[1]], &mut out);
                check_cfdp_directive(&out[..len]);
            },
        );
        crate::ledger::exhaustive(
            &format!("{name} (substitutions)"),
            9 * 48 * 256,
            (0usize..9, 0usize..48, bolero::produce::<u8>()),
            |&(k, at, v)| {
                let mut b = hex(LIBRECUBE[k]);
                let n = b.len();
                b[at % n] = v;
                check_cfdp_directive(&b);
            },
        );
        crate::ledger::sampled_with(
            name,
            SAMPLED,
            |seed, i| crate::ledger::sample_bytes(seed, i, 60),
            |data| {
                let mut d = data.clone();
                if let Some(first) = d.first_mut() {
                    if *first & 1 == 0 {
                        *first = [4, 5, 6, 7, 8, 9, 0x0c][usize::from(*first >> 1) % 7];
                    }
                }
                let mut out = [0u8; 80];
                let len = directive_pdu(u8::from(data.len() % 2 == 1), &d, &mut out);
                check_cfdp_directive(&out[..len]);
            },
        );
        return;
    }
    #[allow(unreachable_code)]
    bolero::check!()
        .with_max_len(MAX_LEN)
        .for_each(|bytes: &[u8]| {
            mmic_proofs::cfdp::check_cfdp_directive(bytes);
        });
}

/// Octets of a hex string.
#[cfg(not(any(kani, fuzzing)))]
fn hex(s: &str) -> Vec<u8> {
    (0..s.len())
        .step_by(2)
        .map(|i| u8::from_str_radix(&s[i..i + 2], 16).expect("hex"))
        .collect()
}

/// The receiver's gap list (`mmic::cfdp::received::Received`, two ranges kept) after any
/// sequence of adds is exactly a bit-per-octet model's: its ranges the model's runs, each
/// add's count of new octets, the progress, the gaps, completeness at its edges (no size, one
/// octet, the progress, one past it, 24); an add that would need a
/// third range is refused and changes nothing.
///
/// Under `cargo test`, exhaustive: every sequence of three adds in a 22-octet file, each add
/// one of 96 (start 0..16, length 0..6): 884,736 sequences; every sequence of four adds in a
/// 10-octet file, each one of 24 (start 0..8, length 0..3): 331,776. Under Kani, any
/// sequence of four adds of any start and length (unwind 6: the kept ranges and the gaps).
#[test]
#[cfg_attr(kani, kani::proof, kani::unwind(6))]
fn cfdp_received_matches_bitset() {
    #[cfg(not(any(kani, fuzzing)))]
    {
        let name = "cfdp_received_matches_bitset";
        crate::ledger::exhaustive(
            name,
            96u64.pow(3),
            (0u8..96, 0u8..96, 0u8..96),
            |&(a, b, c)| {
                check_received(&[a, b, c].map(|a| (u32::from(a % 16), u32::from(a / 16))));
            },
        );
        crate::ledger::exhaustive(
            &format!("{name} (four adds)"),
            24u64.pow(4),
            (0u8..24, 0u8..24, 0u8..24, 0u8..24),
            |&(a, b, c, d)| {
                check_received(&[a, b, c, d].map(|a| (u32::from(a % 8), u32::from(a / 8))));
            },
        );
        return;
    }
    #[allow(unreachable_code)]
    bolero::check!()
        .with_type::<[(u32, u32); 4]>()
        .for_each(|adds| check_received(adds));
}

/// One sequence of adds against the model (octets below 32 only: the model's bits).
fn check_received(adds: &[(u32, u32)]) {
    use mmic::cfdp::received::{Received, ReceivedError};
    let mut r = Received::<2>::new();
    let mut model: u64 = 0;
    for &(start, len) in adds {
        let before = r.clone();
        let got = r.add(start, len);
        let Some(end) = start.checked_add(len) else {
            assert_eq!(got, Err(ReceivedError::Overflow { start, len }));
            assert_eq!(r, before);
            continue;
        };
        if end > 40 {
            continue; // beyond the model (Kani's inputs only)
        }
        let bits = if len == 0 {
            0
        } else {
            ((1u64 << len) - 1) << start
        };
        let after = model | bits;
        if runs(after).len() > 2 {
            assert_eq!(got, Err(ReceivedError::Full { capacity: 2 }));
            assert_eq!(r, before);
            continue;
        }
        assert_eq!(got, Ok((after & !model).count_ones()));
        model = after;
        assert_eq!(r.ranges(), &runs(model)[..]);
        assert_eq!(r.progress(), model.trailing_ones());
        assert_eq!(r.total(), model.count_ones());
        // Completeness at its edges: none, the progress and one past it, the largest.
        let p = model.trailing_ones();
        for size in [0, 1, p, p + 1, 24] {
            let all = if size == 0 {
                0
            } else {
                u64::MAX >> (64 - size)
            };
            assert_eq!(r.is_complete(size), model & all == all);
        }
        let gaps: Vec<(u32, u32)> = r.gaps(20).collect();
        assert_eq!(gaps, runs(!model & ((1 << 20) - 1)));
    }
}

/// The runs of set bits of `m`, each `(start, end)`.
fn runs(m: u64) -> Vec<(u32, u32)> {
    let mut out = Vec::new();
    let mut i = 0;
    while i < 64 {
        if m >> i & 1 == 1 {
            let s = i;
            while i < 64 && m >> i & 1 == 1 {
                i += 1;
            }
            out.push((s, i));
        } else {
            i += 1;
        }
    }
    out
}
