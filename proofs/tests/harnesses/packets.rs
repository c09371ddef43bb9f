//! Harnesses for the four packets (Tables 2–4 and the A→B command), written once and
//! instantiated per packet: `command::parse_never_panics`, `heartbeat::round_trip`, ...
//!
//! Each runs as a randomised test under `cargo test`, as a fuzz target under `cargo bolero
//! test`, and as a proof under `cargo kani --tests`. The unwind bound is the packet length
//! plus two, which covers the CRC loop over the body (see proofs/README.md); Kani needs it as a
//! literal, so each instantiation states it.

/// The arbitrary-length harness tries every length up to this many bytes.
const MAX_LEN: usize = 80;

/// Sampled values per harness under `cargo test` (see `crate::ledger`).
#[cfg(not(any(kani, fuzzing)))]
const SAMPLED: u64 = 20_000;

/// Bytes of seed the base packets of the exhaustive parts are built from.
#[cfg(not(any(kani, fuzzing)))]
const BASE_SEED: usize = 128;

/// Seeds of the four base packets the exhaustive parts sweep: all-zero choices (every field's
/// first value), all-one, alternating, all-0xff choices.
#[cfg(not(any(kani, fuzzing)))]
fn base_seed(k: usize) -> [u8; BASE_SEED] {
    core::array::from_fn(|i| match k {
        0 => 0,
        1 => 1,
        2 => (i as u8).wrapping_mul(0x55),
        _ => 0xff,
    })
}

macro_rules! packet_harnesses {
    ($(#[$doc:meta])* $module:ident: $repr:ty, $len:expr, unwind $unwind:literal) => {
        $(#[$doc])*
        mod $module {
            use mmic_proofs::{check_parse, check_round_trip, check_round_trip_near_valid};

            const LEN: usize = $len;

            /// Base packet `k` of the exhaustive parts: a valid value built from `base_seed(k)`.
            #[cfg(not(any(kani, fuzzing)))]
            fn base(k: usize) -> [u8; LEN] {
                use mmic_proofs::{Sample, Seed};
                let seed = super::base_seed(k);
                let r = <$repr as Sample>::sample(&mut Seed::new(&seed));
                let mut out = [0u8; LEN];
                out.copy_from_slice(r.to_bytes().as_ref());
                out
            }

            /// `parse` of any LEN bytes returns, with the documented verdict (see
            /// `check_parse`).
            ///
            /// Under `cargo test`: exhaustively, every single-byte substitution (each position,
            /// each of the 256 values) of four valid packets, checksum not rewritten: each
            /// header byte wrong in every way, every carried checksum, every body byte changed
            /// under a stale checksum, and the packet itself (accepted); then sampled arrays.
            #[test]
            #[cfg_attr(kani, kani::proof, kani::unwind($unwind))]
            fn parse_never_panics() {
                #[cfg(not(any(kani, fuzzing)))]
                {
                    let name = concat!(stringify!($module), "::parse_never_panics");
                    crate::ledger::exhaustive(
                        name,
                        4 * LEN as u64 * 256,
                        (0usize..4, 0usize..LEN, bolero::produce::<u8>()),
                        |&(k, at, v)| {
                            let mut b = base(k);
                            b[at] = v;
                            let accepted = check_parse::<$repr>(&b);
                            assert_eq!(accepted, v == base(k)[at], "byte {at} set to {v}");
                        },
                    );
                    crate::ledger::sampled::<[u8; LEN]>(name, super::SAMPLED, |bytes| {
                        check_parse::<$repr>(bytes);
                    });
                    return;
                }
                #[allow(unreachable_code)]
                bolero::check!()
                    .with_type::<[u8; LEN]>()
                    .for_each(|bytes| {
                        check_parse::<$repr>(bytes);
                    });
            }

            /// `parse` of any slice of up to `MAX_LEN` bytes returns, with the documented
            /// verdict: a length error naming both lengths unless the length is right, then
            /// header, checksum, fields.
            ///
            /// Under `cargo test`: exhaustively, every slice of 0, 1 or 2 bytes, and every
            /// prefix (0..=`MAX_LEN` bytes) of each base packet repeated: every length, and the
            /// packet itself at its own length; then sampled slices of every length.
            #[test]
            #[cfg_attr(kani, kani::proof, kani::unwind($unwind))]
            fn parse_never_panics_any_length() {
                #[cfg(not(any(kani, fuzzing)))]
                {
                    let name = concat!(stringify!($module), "::parse_never_panics_any_length");
                    crate::ledger::exhaustive(
                        name,
                        3 * 65_536,
                        (0usize..3, bolero::produce::<[u8; 2]>()),
                        |&(n, b)| {
                            check_parse::<$repr>(&b[..n]);
                        },
                    );
                    crate::ledger::exhaustive(
                        concat!(stringify!($module), "::parse_never_panics_any_length (prefixes)"),
                        4 * (super::MAX_LEN as u64 + 1),
                        (0usize..4, 0usize..=super::MAX_LEN),
                        |&(k, n)| {
                            let b: [u8; super::MAX_LEN] = core::array::from_fn(|i| base(k)[i % LEN]);
                            assert_eq!(check_parse::<$repr>(&b[..n]), n == LEN);
                        },
                    );
                    crate::ledger::sampled_with(
                        name,
                        super::SAMPLED,
                        |seed, i| crate::ledger::sample_bytes(seed, i, super::MAX_LEN),
                        |bytes| {
                            check_parse::<$repr>(bytes);
                        },
                    );
                    return;
                }
                #[allow(unreachable_code)]
                bolero::check!()
                    .with_max_len(super::MAX_LEN)
                    .for_each(|bytes: &[u8]| {
                        check_parse::<$repr>(bytes);
                    });
            }

            /// Any body with the right header and a correct checksum is accepted canonically
            /// (`emit(parse(b)) == b`, `parse(emit(parse(b))) == parse(b)`) or refused by a
            /// field or command check, never by the length, header or checksum check.
            ///
            /// Under `cargo test`: exhaustively, every value of every body byte (each position
            /// between header and checksum, each of the 256 values) in each of the four base
            /// packets, checksum rewritten: every value of every one-byte field (opcode,
            /// parameters, state, mode, faults, refusal, bolter bytes) with the other fields
            /// valid, and every value of each byte of the two-byte fields; then sampled bodies.
            // req: T2/*, T3/*, T4/*
            #[test]
            #[cfg_attr(kani, kani::proof, kani::unwind($unwind))]
            fn round_trip() {
                #[cfg(not(any(kani, fuzzing)))]
                {
                    use mmic::wire::{CHECKSUM_LEN, HEADER_LEN};
                    let name = concat!(stringify!($module), "::round_trip");
                    crate::ledger::exhaustive(
                        name,
                        4 * (LEN - HEADER_LEN - CHECKSUM_LEN) as u64 * 256,
                        (0usize..4, HEADER_LEN..LEN - CHECKSUM_LEN, bolero::produce::<u8>()),
                        |&(k, at, v)| {
                            let mut b = base(k);
                            b[at] = v;
                            let accepted = check_round_trip::<$repr>(&b);
                            assert!(accepted || v != base(k)[at], "a base packet refused");
                        },
                    );
                    crate::ledger::sampled::<[u8; LEN]>(name, super::SAMPLED, |body| {
                        check_round_trip::<$repr>(body);
                    });
                    return;
                }
                #[allow(unreachable_code)]
                bolero::check!()
                    .with_type::<[u8; LEN]>()
                    .for_each(|body| {
                        check_round_trip::<$repr>(body);
                    });
            }

            /// A valid value built from any seed survives `parse(emit(x)) == x`; with up to two
            /// body bytes then overwritten and the checksum rewritten, the near miss is accepted
            /// canonically or refused by a field or command check (see
            /// `check_round_trip_near_valid`).
            ///
            /// Under `cargo test`: exhaustively, every value of each seed byte with the others
            /// zero and no edit (every value of every one-byte choice `Seed` reads: board,
            /// opcode class, state, mode, refusal, bolter step, …), and every single edit
            /// (each of the 256 positions, taken modulo the body, and values) of the all-zero
            /// seed's packet; then sampled seeds and edits.
            // req: T2/*, T3/*, T4/*
            #[test]
            #[cfg_attr(kani, kani::proof, kani::unwind($unwind))]
            fn round_trip_near_valid() {
                #[cfg(not(any(kani, fuzzing)))]
                {
                    let name = concat!(stringify!($module), "::round_trip_near_valid");
                    crate::ledger::exhaustive(
                        concat!(stringify!($module), "::round_trip_near_valid (seeds)"),
                        LEN as u64 * 256,
                        (0usize..LEN, bolero::produce::<u8>()),
                        |&(at, v)| {
                            let mut seed = [0u8; LEN];
                            seed[at] = v;
                            assert!(check_round_trip_near_valid::<$repr>(&seed, &[]));
                        },
                    );
                    crate::ledger::exhaustive(
                        concat!(stringify!($module), "::round_trip_near_valid (edits)"),
                        65_536,
                        bolero::produce::<[u8; 2]>(),
                        |edit| {
                            check_round_trip_near_valid::<$repr>(&[0u8; LEN], &[*edit]);
                        },
                    );
                    crate::ledger::sampled::<([u8; LEN], u8, [[u8; 2]; 2])>(
                        name,
                        super::SAMPLED,
                        |(seed, n, edits)| {
                            check_round_trip_near_valid::<$repr>(seed, &edits[..*n as usize % 3]);
                        },
                    );
                    return;
                }
                #[allow(unreachable_code)]
                bolero::check!()
                    .with_type::<([u8; LEN], u8, [[u8; 2]; 2])>()
                    .for_each(|(seed, n, edits)| {
                        check_round_trip_near_valid::<$repr>(seed, &edits[..*n as usize % 3]);
                    });
            }
        }
    };
}

packet_harnesses! {
    /// The 14-byte command packet (Table 2).
    command: mmic::wire::command::CommandRepr, mmic::wire::command::COMMAND_LEN, unwind 16
}
packet_harnesses! {
    /// The 66-byte WiFi heartbeat (Table 3).
    heartbeat: mmic::wire::heartbeat::HeartbeatRepr, mmic::wire::heartbeat::HEARTBEAT_LEN, unwind 68
}
packet_harnesses! {
    /// The 47-byte internal heartbeat (Table 4).
    internal_heartbeat: mmic::wire::internal_heartbeat::InternalHeartbeatRepr,
        mmic::wire::internal_heartbeat::INTERNAL_HEARTBEAT_LEN, unwind 49
}
packet_harnesses! {
    /// The 15-byte A→B command.
    b_command: mmic::wire::b_command::BCommandRepr, mmic::wire::b_command::B_COMMAND_LEN, unwind 17
}
