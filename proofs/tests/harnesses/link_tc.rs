//! Harnesses for the TC transfer frame (`mmic::link::tc_frame`): the parser against the oracle
//! of `mmic_proofs::link`, emit → parse and parse → emit.
//!
//! Each runs as a randomised test under `cargo test`, as a fuzz target under `cargo bolero
//! test`, and as a proof under `cargo kani --tests` (Kani not installed here: not run). Under
//! Kani the inputs are short (`MAX_LEN` 24 octets: the AD frame carrying the ping is 21) and the
//! sampled data at most 4 octets, so the longest loops (the CRCs, the copies, the packet split)
//! run at most 24 times: unwind 26.

use mmic_proofs::link::{
    check_tc_frame_near_valid, check_tc_frame_parse, check_tc_frame_round_trip,
};

/// Longest input of the parse harness.
#[cfg(not(kani))]
const MAX_LEN: usize = 80;
#[cfg(kani)]
const MAX_LEN: usize = 24;

/// Octets of data the sampled frames draw their data from.
#[cfg(not(kani))]
const DATA: usize = 48;
#[cfg(kani)]
const DATA: usize = 4;

/// Seed octets of a sampled frame (9 choices).
const SEED: usize = 10;

/// Sampled values per harness under `cargo test` (see `crate::ledger`).
#[cfg(not(any(kani, fuzzing)))]
const SAMPLED: u64 = 50_000;

/// Data octets of the sampled frames: the ping (a whole packet), then 0, 1, 2, ….
#[cfg(not(any(kani, fuzzing)))]
fn data() -> [u8; DATA] {
    const PING: [u8; 13] = [
        0x18, 0x42, 0xc0, 0x07, 0x00, 0x06, 0x2f, 0x11, 0x01, 0x00, 0x00, 0x12, 0xd0,
    ];
    core::array::from_fn(|i| PING.get(i).copied().unwrap_or(i as u8))
}

/// Seed of base frame `k` of the exhaustive parts: all-zero choices (AD, MAP 0, no data),
/// all one, alternating, all-0xff (BC Set V(R), no segment header).
#[cfg(not(any(kani, fuzzing)))]
fn base_seed(k: usize) -> [u8; SEED] {
    core::array::from_fn(|i| match k {
        0 => 0,
        1 => 1,
        2 => (i as u8).wrapping_mul(0x55),
        _ => 0xff,
    })
}

/// The five base frames of the parse harness's exhaustive part: frames of `CONFIGS`'s
/// channel (spacecraft 0x101, VC 0, MAP 0, FECF): AD with the ping, BD with the ping, BC
/// Unlock, BC Set V(R) = 5, and AD with five pings (73 octets: longer than `CONFIGS[0]`'s 64).
#[cfg(not(any(kani, fuzzing)))]
fn base_frame(k: usize, out: &mut [u8]) -> usize {
    use mmic::link::tc_frame::{MapId, SpacecraftId, TcContent, TcFrameRepr, Vcid};
    use mmic::link::ControlCommand;
    let d = data();
    let pings: [u8; 65] = core::array::from_fn(|i| d[i % 13]);
    let map_id = Some(MapId::new(0).expect("6 bits"));
    let content = match k {
        4 => TcContent::Ad {
            map_id,
            data: &pings,
        },
        0 => TcContent::Ad {
            map_id,
            data: &d[..13],
        },
        1 => TcContent::Bd {
            map_id,
            data: &d[..13],
        },
        2 => TcContent::Bc(ControlCommand::Unlock),
        _ => TcContent::Bc(ControlCommand::SetVr(5)),
    };
    let r = TcFrameRepr {
        spacecraft_id: SpacecraftId::new(0x101).expect("10 bits"),
        vcid: Vcid::new(0).expect("6 bits"),
        seq: k as u8,
        content,
    };
    r.emit(out).expect("fits")
}

/// `TcFrameRepr::parse` and `TcFrame::new_checked` of any 0..=80 octets give exactly the
/// oracle's verdict (check and numbers) on both of the oracle's channels; accepted frames
/// split into packets as the oracle splits them and re-emit to the same octets.
///
/// Under `cargo test`: every input of ≤ 2 octets; every single-octet substitution (each of the
/// first 32 positions, modulo the length, each value) of the five base frames, length field
/// and FECF left or rewritten; every prefix (0..=`MAX_LEN` octets, zero-padded) of each (the
/// last two parts must reach every check of the frame and acceptance); then sampled inputs of
/// every length.
#[test]
#[cfg_attr(kani, kani::proof, kani::unwind(26))]
fn tc_frame_parse_matches_oracle() {
    #[cfg(not(any(kani, fuzzing)))]
    {
        let name = "tc_frame_parse_matches_oracle";
        let reached = std::sync::Mutex::new(std::collections::BTreeSet::new());
        crate::ledger::exhaustive(
            name,
            3 * 65_536,
            (0usize..3, bolero::produce::<[u8; 2]>()),
            |&(n, b)| {
                check_tc_frame_parse(&b[..n]);
            },
        );
        crate::ledger::exhaustive(
            &format!("{name} (substitutions)"),
            5 * 32 * 256 * 2,
            (
                0usize..5,
                0usize..32,
                bolero::produce::<u8>(),
                bolero::produce::<bool>(),
            ),
            |&(k, at, v, reseal_it)| {
                let mut out = [0u8; MAX_LEN];
                let n = base_frame(k, &mut out);
                let f = &mut out[..n];
                f[at % n] = v;
                if reseal_it {
                    mmic_proofs::link::reseal(f, true);
                }
                let mut reached = reached.lock().expect("not poisoned");
                reached.extend(
                    mmic_proofs::link::check_tc_frame_verdicts(f).map(|v| v.unwrap_or("accepted")),
                );
            },
        );
        crate::ledger::exhaustive(
            &format!("{name} (prefixes)"),
            5 * (MAX_LEN as u64 + 1),
            (0usize..5, 0usize..=MAX_LEN),
            |&(k, len)| {
                let mut out = [0u8; MAX_LEN];
                base_frame(k, &mut out);
                let mut reached = reached.lock().expect("not poisoned");
                reached.extend(
                    mmic_proofs::link::check_tc_frame_verdicts(&out[..len])
                        .map(|v| v.unwrap_or("accepted")),
                );
            },
        );
        // The substitutions and prefixes reach every check of the frame (the packets' is not
        // the parser's) and acceptance.
        let reached = reached.into_inner().expect("not poisoned");
        for name in mmic::link::tc_frame::TcFrameError::NAMES[..12]
            .iter()
            .chain(&["accepted"])
        {
            assert!(
                reached.contains(name),
                "no substitution or prefix reached {name}"
            );
        }
        crate::ledger::sampled_with(
            name,
            SAMPLED,
            |seed, i| crate::ledger::sample_bytes(seed, i, MAX_LEN),
            |bytes| {
                check_tc_frame_parse(bytes);
            },
        );
        return;
    }
    #[allow(unreachable_code)]
    bolero::check!()
        .with_max_len(MAX_LEN)
        .for_each(|bytes: &[u8]| {
            check_tc_frame_parse(bytes);
        });
}

/// Any frame built from a seed (any spacecraft ID, VCID, N(S), kind, MAP or none, control
/// command, FECF or not, data a prefix of 48 octets) emits with its stated length and parses
/// back to itself on its channel (emit → parse), passes the oracle property, and is refused by
/// the spacecraft ID check on another spacecraft's channel.
///
/// Under `cargo test`: every value of each seed octet, others zero; then sampled seeds and data.
// req: 232.0-B-4/TC-19, 232.0-B-4/TC-20
#[test]
#[cfg_attr(kani, kani::proof, kani::unwind(26))]
fn tc_frame_round_trip() {
    #[cfg(not(any(kani, fuzzing)))]
    {
        let name = "tc_frame_round_trip";
        crate::ledger::exhaustive(
            name,
            SEED as u64 * 256,
            (0usize..SEED, bolero::produce::<u8>()),
            |&(at, v)| {
                let mut seed = [0u8; SEED];
                seed[at] = v;
                check_tc_frame_round_trip(&seed, &data());
            },
        );
        crate::ledger::sampled::<([u8; SEED], [u8; DATA])>(name, SAMPLED, |(seed, data)| {
            check_tc_frame_round_trip(seed, data)
        });
        return;
    }
    #[allow(unreachable_code)]
    bolero::check!()
        .with_type::<([u8; SEED], [u8; DATA])>()
        .for_each(|(seed, data)| check_tc_frame_round_trip(seed, data));
}

/// The property of the near-valid harness for one input.
fn near_valid(
    (seed, data, n, edits): &([u8; SEED], [u8; DATA], u8, [[u8; 2]; 2]),
) -> Option<&'static str> {
    check_tc_frame_near_valid(seed, data, &edits[..*n as usize % 3], n & 0x80 == 0)
}

/// A valid frame with up to two octets overwritten, its length field and FECF rewritten or
/// not: the oracle's verdict on the frame's channel, parse → emit identity when accepted.
///
/// Under `cargo test`: every single edit (each of the first 64 positions, modulo the length,
/// each value), resealed or not, of the four base seeds' frames, which must reach every check
/// but `truncated` and `too-long` (a channel of 1024-octet frames) and acceptance; then
/// sampled inputs.
#[test]
#[cfg_attr(kani, kani::proof, kani::unwind(26))]
fn tc_frame_near_valid() {
    #[cfg(not(any(kani, fuzzing)))]
    {
        let name = "tc_frame_near_valid";
        let reached = std::sync::Mutex::new(std::collections::BTreeSet::new());
        crate::ledger::exhaustive(
            name,
            4 * 64 * 256 * 2,
            (
                0usize..4,
                0u8..64,
                bolero::produce::<u8>(),
                bolero::produce::<bool>(),
            ),
            |&(k, at, v, reseal_it)| {
                // One edit (n % 3 = 1); bit 7 clear: reseal.
                let n = if reseal_it { 1 } else { 0x82 };
                let verdict = near_valid(&(base_seed(k), data(), n, [[at, v], [0, 0]]));
                let mut reached = reached.lock().expect("not poisoned");
                reached.insert(verdict.unwrap_or("accepted"));
            },
        );
        let reached = reached.into_inner().expect("not poisoned");
        println!("{name}: the exhaustive part reached {reached:?}");
        for name in [
            "version",
            "flags",
            "spare",
            "spacecraft-id",
            "vcid",
            "fecf",
            "length",
            "sequence-flags",
            "map-id",
            "control-command",
            "accepted",
        ] {
            assert!(reached.contains(name), "no single edit reached {name}");
        }
        crate::ledger::sampled(name, SAMPLED, |x| {
            near_valid(x);
        });
        return;
    }
    #[allow(unreachable_code)]
    bolero::check!()
        .with_type::<([u8; SEED], [u8; DATA], u8, [[u8; 2]; 2])>()
        .for_each(|x| {
            near_valid(x);
        });
}
