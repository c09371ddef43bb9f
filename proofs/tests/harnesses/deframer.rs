//! Harnesses for the stream deframer.
//!
//! Each runs as a randomised test under `cargo test`, as a fuzz target under `cargo bolero
//! test`, and as a proof under `cargo kani --tests`. Under Kani the streams are short (a few
//! bytes of garbage and the two short packets, command and B command) and the deframer has the
//! smallest legal buffer, 66 bytes; the unwind bound covers the longest loop, the header scan
//! and CRC over at most `KANI_STREAM` bytes (see proofs/README.md).

use mmic::wire::deframer::Deframer;
use mmic::wire::{PacketKind, MAX_PACKET_LEN};
use mmic_proofs::{build_stream, check_packet_after_garbage, run_deframer};

/// Longest stream (bytes) a harness builds.
#[cfg(not(kani))]
const STREAM: usize = 400;
#[cfg(kani)]
const STREAM: usize = 20;

/// Longest garbage before the packet in `deframer_finds_packet_after_garbage`.
#[cfg(not(kani))]
const MAX_GARBAGE: usize = 120;
#[cfg(kani)]
const MAX_GARBAGE: usize = 4;

/// Packet kinds that harness may place after the garbage: all four, or under Kani the two
/// short ones, which keep its streams within `STREAM` bytes.
#[cfg(not(kani))]
const KINDS: &[PacketKind] = &PacketKind::ALL;
#[cfg(kani)]
const KINDS: &[PacketKind] = &[PacketKind::Command, PacketKind::BCommand];

/// Bytes of chunk plan taken from the front of the input.
const PLAN: usize = 4;

/// Chunk plans of the exhaustive parts: the whole stream at once, then chunks of 1, 2, 13, 66
/// (the smallest legal buffer) and 70 bytes (more than the buffer: `push` takes part).
#[cfg(not(any(kani, fuzzing)))]
const PLANS: [&[u8]; 6] = [
    &[],
    &[0; PLAN],
    &[1; PLAN],
    &[12; PLAN],
    &[65; PLAN],
    &[69; PLAN],
];

/// Token `t` of the exhaustive streams, appended to `out`: 0–3 a packet of kind `ALL[t]` with
/// sound framing (zero body), 4–7 that kind's header alone, 8–11 the packet with its last
/// checksum byte flipped (a near miss), 12 one garbage byte.
#[cfg(not(any(kani, fuzzing)))]
fn token(t: usize, out: &mut Vec<u8>) {
    let kind = PacketKind::ALL[t % 4];
    let mut p = [0u8; MAX_PACKET_LEN];
    let p = &mut p[..kind.len()];
    mmic_proofs::seal(kind, p);
    match t {
        0..=3 => out.extend_from_slice(p),
        4..=7 => out.extend_from_slice(&kind.header()),
        8..=11 => {
            p[kind.len() - 1] ^= 1;
            out.extend_from_slice(p)
        }
        _ => out.push(0),
    }
}

/// Under `cargo test`, the exhaustive part of the two stream harnesses: every sequence of 4
/// tokens (see [`token`]: packets of every kind, bare headers, near misses, garbage, so every
/// way a packet can follow or cut into another) in each of the chunk plans [`PLANS`].
#[cfg(not(any(kani, fuzzing)))]
fn token_streams(name: &str, property: impl Fn(&[u8], &[u8]) + std::panic::RefUnwindSafe) {
    crate::ledger::exhaustive(
        name,
        6 * 13u64.pow(4),
        (0usize..6, crate::ledger::seq::<_, 4>(0usize..13)),
        |(plan, tokens)| {
            let mut stream = Vec::new();
            for &t in tokens {
                token(t, &mut stream);
            }
            property(PLANS[*plan], &stream);
        },
    );
}

/// Any bytes, pushed in any chunking (`push` takes what fits, `poll` until `None`, then
/// `resync` until `None`): every call returns, `push` never takes more than the free space,
/// and the loop ends with nothing buffered.
///
/// Under `cargo test`: the token streams exhaustively (see [`token_streams`]), then sampled
/// inputs of every length up to `PLAN + STREAM`.
// req: D:deframing
#[test]
#[cfg_attr(kani, kani::proof, kani::unwind(22))]
fn deframer_never_panics() {
    #[cfg(not(any(kani, fuzzing)))]
    {
        token_streams("deframer_never_panics", never_panics);
        crate::ledger::sampled_with(
            "deframer_never_panics",
            20_000,
            |seed, i| crate::ledger::sample_bytes(seed, i, PLAN + STREAM),
            |input| {
                let (plan, stream) = input.split_at(input.len().min(PLAN));
                never_panics(plan, stream);
            },
        );
        return;
    }
    #[allow(unreachable_code)]
    bolero::check!()
        .with_max_len(PLAN + STREAM)
        .for_each(|input: &[u8]| {
            let (plan, stream) = input.split_at(input.len().min(PLAN));
            never_panics(plan, stream);
        });
}

/// The property of [`deframer_never_panics`].
fn never_panics(plan: &[u8], stream: &[u8]) {
    let mut d = Deframer::<MAX_PACKET_LEN>::new();
    let mut rest = stream;
    let mut i = 0;
    while !rest.is_empty() {
        let want = mmic_proofs::chunk_len(plan, i, rest.len()).min(rest.len());
        i += 1;
        let free = d.free();
        let took = d.push(&rest[..want]);
        assert!(took <= free && took <= want);
        rest = &rest[took..];
        while d.poll().is_some() {}
    }
    while d.resync().is_some() {}
    assert_eq!(d.buffered(), 0);
}

/// For streams mixing garbage, packets with sound framing and near misses (see
/// `build_stream`) in any chunking: after every call, the bytes pushed equal the bytes
/// discarded plus the bytes delivered in frames plus the bytes buffered; every frame is the
/// stream's bytes at its offset; after `resync` nothing is left (see `run_deframer`).
///
/// Under `cargo test`: the token streams exhaustively (see [`token_streams`]), then sampled
/// inputs for `build_stream`.
// req: D:deframing
#[test]
#[cfg_attr(kani, kani::proof, kani::unwind(22))]
fn deframer_conserves_bytes() {
    #[cfg(not(any(kani, fuzzing)))]
    {
        token_streams("deframer_conserves_bytes", conserves);
        crate::ledger::sampled_with(
            "deframer_conserves_bytes",
            20_000,
            |seed, i| crate::ledger::sample_bytes(seed, i, PLAN + 2 * STREAM),
            |input| conserves_built(input),
        );
        return;
    }
    #[allow(unreachable_code)]
    bolero::check!()
        .with_max_len(PLAN + 2 * STREAM)
        .for_each(conserves_built);
}

/// [`conserves`] on the stream `build_stream` makes of `input` after its chunk plan.
fn conserves_built(input: &[u8]) {
    let (plan, input) = input.split_at(input.len().min(PLAN));
    let mut stream = [0u8; STREAM];
    let n = build_stream(input, &mut stream);
    conserves(plan, &stream[..n]);
}

/// The property of [`deframer_conserves_bytes`].
fn conserves(plan: &[u8], stream: &[u8]) {
    let run = run_deframer::<MAX_PACKET_LEN>(stream, plan, |_, _| {});
    assert_eq!(run.pushed, run.discarded + run.frame_bytes);
}

/// Arbitrary garbage (up to `MAX_GARBAGE` bytes, optionally with a full header spliced in,
/// the hard case), then a packet with sound framing, in any chunking, then `resync` until
/// `None`: the packet is delivered exactly once, byte-identical — unless a frame with sound
/// framing that starts in the garbage overlaps it (see `check_packet_after_garbage`).
///
/// Under `cargo test`: exhaustively, every kind, every garbage length 0..=`MAX_GARBAGE` of
/// zero bytes, every splice (none, or each kind's header at each of the 32 positions), pushed
/// whole, byte by byte and in 70-byte chunks; then sampled inputs.
// req: D:deframing
#[test]
#[cfg_attr(kani, kani::proof, kani::unwind(22))]
fn deframer_finds_packet_after_garbage() {
    #[cfg(not(any(kani, fuzzing)))]
    {
        crate::ledger::exhaustive(
            "deframer_finds_packet_after_garbage",
            4 * (MAX_GARBAGE as u64 + 1) * 129 * 3,
            (0u8..4, 0..=MAX_GARBAGE as u8, 0u8..129, 0usize..3),
            |&(kind, glen, splice, chunk)| {
                // 0: no splice; 1 + 4p + k: kind k's header at position p.
                let splice = if splice == 0 { 0 } else { 0x80 | (splice - 1) };
                let plan = [[0; PLAN], [0; PLAN], [69; PLAN]][chunk];
                let whole = chunk == 0;
                after_garbage(
                    if whole { &[] } else { &plan },
                    (kind, glen, splice),
                    &[0; MAX_GARBAGE],
                    &[0; MAX_PACKET_LEN],
                );
            },
        );
        crate::ledger::sampled::<(
            [u8; PLAN],
            (u8, u8, u8),
            [u8; MAX_GARBAGE],
            [u8; MAX_PACKET_LEN],
        )>(
            "deframer_finds_packet_after_garbage",
            20_000,
            |(plan, choice, garbage, body)| after_garbage(plan, *choice, garbage, body),
        );
        return;
    }
    #[allow(unreachable_code)]
    bolero::check!()
        .with_type::<(
            [u8; PLAN],
            (u8, u8, u8),
            [u8; MAX_GARBAGE],
            [u8; MAX_PACKET_LEN],
        )>()
        .for_each(|(plan, choice, garbage, body)| after_garbage(plan, *choice, garbage, body));
}

/// The property of [`deframer_finds_packet_after_garbage`].
fn after_garbage(
    plan: &[u8],
    (kind, glen, splice): (u8, u8, u8),
    garbage: &[u8; MAX_GARBAGE],
    body: &[u8; MAX_PACKET_LEN],
) {
    let kind = KINDS[kind as usize % KINDS.len()];
    let g = glen as usize % (MAX_GARBAGE + 1);
    let mut junk = *garbage;
    let junk = &mut junk[..g];
    // Splice a header (bit 7 set) of kind `splice & 3` at position `splice >> 2`.
    if splice & 0x80 != 0 {
        let h = PacketKind::ALL[(splice & 3) as usize].header();
        let at = ((splice >> 2) & 0x1f) as usize;
        for (j, b) in h.iter().enumerate() {
            if let Some(slot) = junk.get_mut(at + j) {
                *slot = *b;
            }
        }
    }
    check_packet_after_garbage::<MAX_PACKET_LEN, { MAX_GARBAGE + MAX_PACKET_LEN }>(
        junk, kind, body, plan,
    );
}
