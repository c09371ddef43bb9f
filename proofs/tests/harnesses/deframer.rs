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

/// Any bytes, pushed in any chunking (`push` takes what fits, `poll` until `None`, then
/// `resync` until `None`): every call returns, `push` never takes more than the free space,
/// and the loop ends with nothing buffered.
#[test]
#[cfg_attr(kani, kani::proof, kani::unwind(22))]
fn deframer_never_panics() {
    bolero::check!()
        .with_max_len(PLAN + STREAM)
        .for_each(|input: &[u8]| {
            let (plan, stream) = input.split_at(input.len().min(PLAN));
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
        });
}

/// For streams mixing garbage, packets with sound framing and near misses (see
/// `build_stream`) in any chunking: after every call, the bytes pushed equal the bytes
/// discarded plus the bytes delivered in frames plus the bytes buffered; every frame is the
/// stream's bytes at its offset; after `resync` nothing is left (see `run_deframer`).
#[test]
#[cfg_attr(kani, kani::proof, kani::unwind(22))]
fn deframer_conserves_bytes() {
    bolero::check!()
        .with_max_len(PLAN + 2 * STREAM)
        .for_each(|input: &[u8]| {
            let (plan, input) = input.split_at(input.len().min(PLAN));
            let mut stream = [0u8; STREAM];
            let n = build_stream(input, &mut stream);
            let run = run_deframer::<MAX_PACKET_LEN>(&stream[..n], plan, |_, _| {});
            assert_eq!(run.pushed, run.discarded + run.frame_bytes);
        });
}

/// Arbitrary garbage (up to `MAX_GARBAGE` bytes, optionally with a full header spliced in,
/// the hard case), then a packet with sound framing, in any chunking, then `resync` until
/// `None`: the packet is delivered exactly once, byte-identical — unless a frame with sound
/// framing that starts in the garbage overlaps it (see `check_packet_after_garbage`).
#[test]
#[cfg_attr(kani, kani::proof, kani::unwind(22))]
fn deframer_finds_packet_after_garbage() {
    bolero::check!()
        .with_type::<(
            [u8; PLAN],
            (u8, u8, u8),
            [u8; MAX_GARBAGE],
            [u8; MAX_PACKET_LEN],
        )>()
        .for_each(|(plan, (kind, glen, splice), garbage, body)| {
            let kind = KINDS[*kind as usize % KINDS.len()];
            let g = *glen as usize % (MAX_GARBAGE + 1);
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
        });
}
