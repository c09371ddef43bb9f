//! Harnesses for the TM side of the space data link (`mmic::link::{tm_frame, tm_framer,
//! extract}`): the frame parser against the oracle of `mmic_proofs::link_tm`, emit → parse,
//! and the framer → extractor chain with and without lost frames.
//!
//! Each runs as a randomised test under `cargo test`, as a fuzz target under `cargo bolero
//! test`, and would run under `cargo kani --tests` (Kani not installed here: not run; the
//! link harnesses build `Vec`s and CRC whole 256-octet frames, far beyond what Kani's bounded
//! model checking handles in reasonable time, so they are not sized for it).

use mmic_proofs::link_tm::{
    check_link, check_tm_frame_parse, check_tm_frame_round_trip, reference_frame, reseal, PARAMS,
};

/// Sampled values per harness under `cargo test` (see `crate::ledger`).
#[cfg(not(any(kani, fuzzing)))]
const SAMPLED: u64 = 20_000;

/// Sampled runs of the link harnesses (each frames up to 64 packets: about 0.25 ms a run).
#[cfg(not(any(kani, fuzzing)))]
const SAMPLED_RUNS: u64 = 5_000;

/// Steps of the exhaustive link runs: packets of 7, 8, 237, 238, 243, 244, 245, 250, 300 and
/// about 488 octets (below, at and above one and two data fields of 244, and the 7-octet
/// room that makes an idle packet spill over), and a flush. As step octets for `check_link`.
#[cfg(not(any(kani, fuzzing)))]
const STEPS: [u8; 11] = [40, 41, 214, 215, 219, 220, 221, 225, 255, 254, 0];

/// `TmFrameRepr::parse`/`TmFrame::new_checked` of any octets under the mission's parameters
/// gives exactly the oracle's verdict (check and numbers, documented order); accepted frames
/// re-emit to the same octets.
///
/// Under `cargo test`: every single-octet substitution (256 positions × 256 values) of the
/// reference frame, FECF left or rewritten (every value of every header field octet, so every
/// check); every length 0..=300 (the reference cut or zero-extended); then sampled frames:
/// 256 random octets, FECF rewritten for half of them.
#[test]
#[cfg_attr(kani, kani::proof, kani::unwind(260))]
fn tm_frame_parse_matches_oracle() {
    #[cfg(not(any(kani, fuzzing)))]
    {
        let good = reference_frame();
        crate::ledger::exhaustive(
            "tm_frame_parse_matches_oracle",
            256 * 256 * 2,
            (
                0usize..256,
                bolero::produce::<u8>(),
                bolero::produce::<bool>(),
            ),
            |&(at, v, reseal_it)| {
                let mut f = good.clone();
                f[at] = v;
                if reseal_it {
                    reseal(&mut f);
                }
                check_tm_frame_parse(&f, &PARAMS);
            },
        );
        crate::ledger::exhaustive(
            "tm_frame_parse_matches_oracle (lengths)",
            301,
            0usize..=300,
            |&len| {
                let mut f = good.clone();
                f.resize(len, 0);
                check_tm_frame_parse(&f, &PARAMS);
            },
        );
        crate::ledger::sampled_with(
            "tm_frame_parse_matches_oracle",
            SAMPLED,
            |seed, i| crate::ledger::bytes(seed, i, 257),
            |b| {
                let mut f = b[1..].to_vec();
                if b[0] & 1 == 1 {
                    f[0] = 0x14;
                    f[1] = 0x21;
                    f[4] = 0x18 | (f[4] & 7);
                    reseal(&mut f);
                }
                check_tm_frame_parse(&f, &PARAMS);
            },
        );
        return;
    }
    #[allow(unreachable_code)]
    bolero::check!().with_max_len(300).for_each(|bytes: &[u8]| {
        check_tm_frame_parse(bytes, &PARAMS);
    });
}

/// Any frame built from a seed (spacecraft ID, VCID, counts, pointer, data, OCF, frame length
/// 13..=2048, OCF and FECF present or not) emits with its length and parses back to itself;
/// the oracle accepts it; a parser for another spacecraft refuses it by the spacecraft-id
/// check.
///
/// Under `cargo test`: every value of each of the 12 seed octets, the others zero; then
/// sampled seeds.
// req: 132.0-B-3/TM-51
#[test]
#[cfg_attr(kani, kani::proof, kani::unwind(260))]
fn tm_frame_round_trip() {
    #[cfg(not(any(kani, fuzzing)))]
    {
        crate::ledger::exhaustive(
            "tm_frame_round_trip",
            12 * 256,
            (0usize..12, bolero::produce::<u8>()),
            |&(at, v)| {
                let mut seed = [0u8; 12];
                seed[at] = v;
                check_tm_frame_round_trip(&seed);
            },
        );
        crate::ledger::sampled::<[u8; 12]>("tm_frame_round_trip", SAMPLED, |seed| {
            check_tm_frame_round_trip(seed)
        });
        return;
    }
    #[allow(unreachable_code)]
    bolero::check!()
        .with_type::<[u8; 12]>()
        .for_each(check_tm_frame_round_trip);
}

/// No frame lost: every packet pushed into the framer (any sequence of lengths 7..=300 and
/// flushes, on the mission's 256-octet frames or short ones of 13..=40 octets) comes out of
/// the extractor exactly once, whole, in order, idle data removed — none lost or duplicated
/// across frame boundaries; the frames' pointers and counts agree with an independent walk.
///
/// Under `cargo test`: every sequence of 4 steps of [`STEPS`] on the 256-octet frame and on a
/// 40-octet one (data field 28); then sampled frame lengths and sequences of up to 64 steps.
// req: 132.0-B-3/TM-62
#[test]
#[cfg_attr(kani, kani::proof, kani::unwind(10))]
fn tm_extractor_loses_nothing_without_frame_loss() {
    #[cfg(not(any(kani, fuzzing)))]
    {
        crate::ledger::exhaustive(
            "tm_extractor_loses_nothing_without_frame_loss",
            2 * 11u64.pow(4),
            (
                bolero::produce::<bool>(),
                crate::ledger::seq::<_, 4>(0usize..11),
            ),
            |&(short, steps)| {
                let mut input = vec![if short { 55 } else { 0 }];
                input.extend(steps.iter().map(|&s| STEPS[s]));
                check_link(&input, false);
            },
        );
        crate::ledger::sampled_with(
            "tm_extractor_loses_nothing_without_frame_loss",
            SAMPLED_RUNS,
            |seed, i| crate::ledger::sample_bytes(seed, i, 65),
            |b| check_link(b, false),
        );
        return;
    }
    #[allow(unreachable_code)]
    bolero::check!()
        .with_max_len(80)
        .for_each(|bytes: &[u8]| check_link(bytes, false));
}

/// Frames lost (by the gap in the VC frame count): every packet the extractor hands out is
/// one that was sent, whole (never spliced from two packets' octets); exactly the packets
/// that touch no lost frame come out, in order; the lost frames between the first and last
/// received are counted, and at most one packet in reassembly is dropped per gap.
///
/// Under `cargo test`: every sequence of 3 steps of [`STEPS`] on the 256-octet and the
/// 40-octet frame, with every single lost frame of the first 8 and every pair of lost frames
/// among the first 6 (8 + 15 masks); then sampled inputs with random loss masks.
// req: 132.0-B-3/TM-88
#[test]
#[cfg_attr(kani, kani::proof, kani::unwind(10))]
fn tm_extractor_never_splices() {
    #[cfg(not(any(kani, fuzzing)))]
    {
        let masks: Vec<u64> = (0..8)
            .map(|i| 1u64 << i)
            .chain((0..6).flat_map(|i| (i + 1..6).map(move |j| 1u64 << i | 1 << j)))
            .collect();
        assert_eq!(masks.len(), 23);
        crate::ledger::exhaustive(
            "tm_extractor_never_splices",
            2 * 11u64.pow(3) * 23,
            (
                bolero::produce::<bool>(),
                crate::ledger::seq::<_, 3>(0usize..11),
                0usize..23,
            ),
            |&(short, steps, m)| {
                let mut input = vec![if short { 55 } else { 0 }];
                input.extend(masks[m].to_le_bytes());
                input.extend(steps.iter().map(|&s| STEPS[s]));
                check_link(&input, true);
            },
        );
        crate::ledger::sampled_with(
            "tm_extractor_never_splices",
            SAMPLED_RUNS,
            |seed, i| crate::ledger::sample_bytes(seed, i, 73),
            |b| check_link(b, true),
        );
        return;
    }
    #[allow(unreachable_code)]
    bolero::check!()
        .with_max_len(80)
        .for_each(|bytes: &[u8]| check_link(bytes, true));
}
