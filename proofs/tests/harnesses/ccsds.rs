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

/// Sampled values per harness under `cargo test` (see `crate::ledger`).
#[cfg(not(any(kani, fuzzing)))]
const SAMPLED: u64 = 50_000;

/// Seed and data of base packet `k` of the exhaustive parts: all-zero choices (no data), all
/// one (one octet), alternating, all-0xff (ten octets: 255 % 49); data octets 0, 1, 2, ….
#[cfg(not(any(kani, fuzzing)))]
fn base(kind: PacketType, k: usize, out: &mut [u8]) -> usize {
    let seed: [u8; SEED] = core::array::from_fn(|i| match k {
        0 => 0,
        1 => 1,
        2 => (i as u8).wrapping_mul(0x55),
        _ => 0xff,
    });
    let data: [u8; DATA] = core::array::from_fn(|i| i as u8);
    mmic_proofs::ccsds::emit_sample(kind, &seed, &data, out).0
}

/// Under `cargo test`, the exhaustive parts of the two parse harnesses: every input of 0, 1 or
/// 2 octets; every single-octet substitution (each of the first 32 positions, modulo the
/// length, each value) of four valid packets, with the length field and CRC left (the length
/// and checksum checks) or rewritten (the checks after them: pus-version, APID, …); every
/// prefix (0..=`MAX_LEN` octets, zero-padded) of each.
#[cfg(not(any(kani, fuzzing)))]
fn parse_exhaustive(name: &str, kind: PacketType) {
    use mmic_proofs::ccsds::reseal;
    crate::ledger::exhaustive(
        name,
        3 * 65_536,
        (0usize..3, bolero::produce::<[u8; 2]>()),
        |&(n, b)| {
            check_pus_parse(kind, &b[..n]);
        },
    );
    crate::ledger::exhaustive(
        &format!("{name} (substitutions)"),
        4 * 32 * 256 * 2,
        (
            0usize..4,
            0usize..32,
            bolero::produce::<u8>(),
            bolero::produce::<bool>(),
        ),
        |&(k, at, v, reseal_it)| {
            let mut out = [0u8; MAX_LEN];
            let n = base(kind, k, &mut out);
            let p = &mut out[..n];
            p[at % n] = v;
            if reseal_it {
                reseal(p);
            }
            check_pus_parse(kind, p);
        },
    );
    crate::ledger::exhaustive(
        &format!("{name} (prefixes)"),
        4 * (MAX_LEN as u64 + 1),
        (0usize..4, 0usize..=MAX_LEN),
        |&(k, len)| {
            let mut out = [0u8; MAX_LEN];
            let n = base(kind, k, &mut out);
            let _ = n;
            check_pus_parse(kind, &out[..len]);
        },
    );
}

/// `TcRepr::parse`/`Tc::new_checked` of any octets give exactly the oracle's verdict (check
/// and numbers); accepted packets re-emit to the same octets.
///
/// Under `cargo test`: see [`parse_exhaustive`], then sampled inputs of every length.
#[test]
#[cfg_attr(kani, kani::proof, kani::unwind(26))]
fn pus_tc_parse_matches_oracle() {
    #[cfg(not(any(kani, fuzzing)))]
    {
        parse_exhaustive("pus_tc_parse_matches_oracle", PacketType::Tc);
        crate::ledger::sampled_with(
            "pus_tc_parse_matches_oracle",
            SAMPLED,
            |seed, i| crate::ledger::sample_bytes(seed, i, MAX_LEN),
            |bytes| {
                check_pus_parse(PacketType::Tc, bytes);
            },
        );
        return;
    }
    #[allow(unreachable_code)]
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
    #[cfg(not(any(kani, fuzzing)))]
    {
        parse_exhaustive("pus_tm_parse_matches_oracle", PacketType::Tm);
        crate::ledger::sampled_with(
            "pus_tm_parse_matches_oracle",
            SAMPLED,
            |seed, i| crate::ledger::sample_bytes(seed, i, MAX_LEN),
            |bytes| {
                check_pus_parse(PacketType::Tm, bytes);
            },
        );
        return;
    }
    #[allow(unreachable_code)]
    bolero::check!()
        .with_max_len(MAX_LEN)
        .for_each(|bytes: &[u8]| {
            check_pus_parse(PacketType::Tm, bytes);
        });
}

/// Under `cargo test`, the exhaustive part of the two round-trip harnesses: every value of
/// each seed octet with the others zero (every value of every one-octet choice: ack flags,
/// service, subservice, time reference, data length 0..=48, and of each octet of the
/// two-octet ones: APID, count, source/destination, time), data octets 0, 1, 2, ….
#[cfg(not(any(kani, fuzzing)))]
fn round_trip_exhaustive(name: &str, kind: PacketType) {
    crate::ledger::exhaustive(
        name,
        SEED as u64 * 256,
        (0usize..SEED, bolero::produce::<u8>()),
        |&(at, v)| {
            let mut seed = [0u8; SEED];
            seed[at] = v;
            let data: [u8; DATA] = core::array::from_fn(|i| i as u8);
            check_pus_round_trip(kind, &seed, &data);
        },
    );
}

/// Any telecommand emits with its stated length and parses back to itself; with its APID
/// not accepted, it is refused by the APID check.
///
/// Under `cargo test`: see [`round_trip_exhaustive`], then sampled seeds and data.
#[test]
#[cfg_attr(kani, kani::proof, kani::unwind(26))]
fn pus_tc_round_trip() {
    #[cfg(not(any(kani, fuzzing)))]
    {
        round_trip_exhaustive("pus_tc_round_trip", PacketType::Tc);
        crate::ledger::sampled::<([u8; SEED], [u8; DATA])>(
            "pus_tc_round_trip",
            SAMPLED,
            |(seed, data)| check_pus_round_trip(PacketType::Tc, seed, data),
        );
        return;
    }
    #[allow(unreachable_code)]
    bolero::check!()
        .with_type::<([u8; SEED], [u8; DATA])>()
        .for_each(|(seed, data)| check_pus_round_trip(PacketType::Tc, seed, data));
}

/// The same for telemetry.
#[test]
#[cfg_attr(kani, kani::proof, kani::unwind(26))]
fn pus_tm_round_trip() {
    #[cfg(not(any(kani, fuzzing)))]
    {
        round_trip_exhaustive("pus_tm_round_trip", PacketType::Tm);
        crate::ledger::sampled::<([u8; SEED], [u8; DATA])>(
            "pus_tm_round_trip",
            SAMPLED,
            |(seed, data)| check_pus_round_trip(PacketType::Tm, seed, data),
        );
        return;
    }
    #[allow(unreachable_code)]
    bolero::check!()
        .with_type::<([u8; SEED], [u8; DATA])>()
        .for_each(|(seed, data)| check_pus_round_trip(PacketType::Tm, seed, data));
}

/// The property of the near-valid harnesses for one input.
fn near_valid(
    kind: PacketType,
    (seed, data, n, edits): &([u8; SEED], [u8; DATA], u8, [[u8; 2]; 2]),
) {
    check_pus_near_valid(kind, seed, data, &edits[..*n as usize % 3], n & 0x80 == 0);
}

/// Under `cargo test`, the exhaustive part of the two near-valid harnesses: every single edit
/// (each of the first 64 positions, modulo the length, each value), length field and CRC
/// rewritten or not, of the four base packets' seeds.
#[cfg(not(any(kani, fuzzing)))]
fn near_valid_exhaustive(name: &str, kind: PacketType) {
    crate::ledger::exhaustive(
        name,
        4 * 64 * 256 * 2,
        (
            0u8..4,
            0u8..64,
            bolero::produce::<u8>(),
            bolero::produce::<bool>(),
        ),
        |&(k, at, v, reseal_it)| {
            let seed: [u8; SEED] = core::array::from_fn(|i| match k {
                0 => 0,
                1 => 1,
                2 => (i as u8).wrapping_mul(0x55),
                _ => 0xff,
            });
            let data: [u8; DATA] = core::array::from_fn(|i| i as u8);
            // One edit (n % 3 == 1); bit 7 clear = reseal. (0x81 would be no edit at all:
            // 0x81 % 3 == 0, which left the unsealed half of this part unedited until issue 27.)
            let n = if reseal_it { 1 } else { 0x82 };
            near_valid(kind, &(seed, data, n, [[at, v], [0, 0]]));
        },
    );
}

/// A valid telecommand with up to two octets overwritten, its length field and CRC
/// rewritten or not: the oracle's verdict, and parse → emit identity when accepted.
///
/// Under `cargo test`: see [`near_valid_exhaustive`], then sampled inputs.
#[test]
#[cfg_attr(kani, kani::proof, kani::unwind(26))]
fn pus_tc_near_valid() {
    #[cfg(not(any(kani, fuzzing)))]
    {
        near_valid_exhaustive("pus_tc_near_valid", PacketType::Tc);
        crate::ledger::sampled("pus_tc_near_valid", SAMPLED, |x| {
            near_valid(PacketType::Tc, x)
        });
        return;
    }
    #[allow(unreachable_code)]
    bolero::check!()
        .with_type::<([u8; SEED], [u8; DATA], u8, [[u8; 2]; 2])>()
        .for_each(|x| near_valid(PacketType::Tc, x));
}

/// The same for telemetry.
#[test]
#[cfg_attr(kani, kani::proof, kani::unwind(26))]
fn pus_tm_near_valid() {
    #[cfg(not(any(kani, fuzzing)))]
    {
        near_valid_exhaustive("pus_tm_near_valid", PacketType::Tm);
        crate::ledger::sampled("pus_tm_near_valid", SAMPLED, |x| {
            near_valid(PacketType::Tm, x)
        });
        return;
    }
    #[allow(unreachable_code)]
    bolero::check!()
        .with_type::<([u8; SEED], [u8; DATA], u8, [[u8; 2]; 2])>()
        .for_each(|x| near_valid(PacketType::Tm, x));
}
