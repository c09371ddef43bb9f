//! Harnesses for Space Data Link Security (`mmic::link::sdls`): changed frames refused, the
//! round trip, the anti-replay window against an oracle, the sender's counter across
//! restarts, and arbitrary octets through a secured gateway (`mmic_proofs::sdls`).
//!
//! Each runs as a randomised test under `cargo test`, as a fuzz target under `cargo bolero
//! test`, and as a proof under `cargo kani --tests` (Kani not installed here: not run). Under
//! Kani the frames carry at most 4 octets of data and arbitrary inputs are at most 24 octets,
//! the op sequences 6 long; the longest loops are then the CRC over a frame (≤ 40 octets), the
//! mask and IV copies (≤ 32) and AES-GCM's blocks (≤ 3): unwind 42. (AES-GCM under Kani is
//! costly: these bounds are a start, not a measured fit.)

use mmic_proofs::sdls::{
    check_changed_frame_refused, check_round_trip, check_secured_tc_frame,
    check_secured_tc_frame_resealed, check_tx_ops, check_window, IV_SPACE,
};

/// Octets of data a sampled frame draws from.
#[cfg(not(kani))]
const DATA: usize = 32;
#[cfg(kani)]
const DATA: usize = 4;

/// Longest arbitrary input.
#[cfg(not(kani))]
const MAX_LEN: usize = 17 + 218;
#[cfg(kani)]
const MAX_LEN: usize = 24;

/// Operations in a sampled (and Kani) run of the sender.
#[cfg(not(kani))]
const OPS: usize = 24;
#[cfg(kani)]
const OPS: usize = 6;

/// 2^95.
const HALF: u128 = IV_SPACE / 2;

/// The changed-frame harness's sampled input: IV, BD, N(S), data and its length, the octet
/// changed, the XOR, reseal.
type Changed = (u128, bool, u8, [u8; DATA], u8, u16, u8, bool);

fn changed(v: &Changed) -> &'static str {
    let (iv, bd, seq, data, len, at, delta, reseal) = *v;
    let len = len as usize % (DATA + 1);
    check_changed_frame_refused(iv, bd, seq, &data[..len], at as usize, delta, reseal)
}

/// A TC frame protected under any IV, with any one octet changed by any XOR (every single-bit
/// flip and every other value of the octet), its FECF written again over the change or not:
/// refused by the frame checks or by SDLS, never verified; the receiving table refuses it in
/// place leaving the frame and its window unchanged and counting the refusal once (only a
/// change in the FECF, outside the MAC, passes SDLS alone: the frame layer refuses it); the
/// frame as sent is then accepted with its data.
///
/// Under `cargo test`: exhaustively, every octet × every XOR 1..=255 × reseal or not, of an AD
/// frame with the ping under IV 5 and a BD frame with it under IV 2^96 − 1 (51 octets each);
/// then sampled inputs (any IV, data of 0..=32 octets).
// req: 355.0-B-2/SDLS-14
#[test]
#[cfg_attr(kani, kani::proof, kani::unwind(42))]
fn sdls_verify_never_accepts_a_changed_frame() {
    #[cfg(not(any(kani, fuzzing)))]
    {
        let name = "sdls_verify_never_accepts_a_changed_frame";
        let ping = mmic_proofs::sdls::ping(7);
        let refused = std::sync::Mutex::new(std::collections::BTreeMap::new());
        crate::ledger::exhaustive(
            name,
            2 * 51 * 255 * 2,
            (0usize..2, 0usize..51, 1u8..=255, bolero::produce::<bool>()),
            |&(k, at, delta, reseal)| {
                let (iv, bd) = [(5, false), (IV_SPACE - 1, true)][k];
                let r = check_changed_frame_refused(iv, bd, 3, &ping, at, delta, reseal);
                *refused.lock().unwrap().entry(r).or_insert(0u32) += 1;
            },
        );
        // Every refusal the SDLS layer can give a changed authentic frame was reached.
        let refused = refused.into_inner().unwrap();
        println!("{name}: table verdicts {refused:?}");
        for r in [
            "unknown-spi",
            "wrong-channel",
            "replay",
            "too-far-ahead",
            "bad-mac",
            "fecf",
        ] {
            assert!(refused.contains_key(r), "{r} never reached");
        }
        crate::ledger::sampled::<Changed>(name, 20_000, |v| {
            changed(v);
        });
        return;
    }
    #[allow(unreachable_code)]
    bolero::check!().with_type::<Changed>().for_each(|v| {
        changed(v);
    });
}

/// Input of the round trip: 16 octets of IV, a flag octet (bit 0: BD), N(S), then the data.
fn round_trip(input: &[u8]) {
    let mut iv = [0u8; 16];
    let k = input.len().min(16);
    iv[..k].copy_from_slice(&input[..k]);
    let flags = input.get(16).copied().unwrap_or(0);
    let seq = input.get(17).copied().unwrap_or(0);
    let data = input.get(18..).unwrap_or(&[]);
    check_round_trip(u128::from_le_bytes(iv), flags & 1 == 1, seq, data);
}

/// Protect then verify gives the data back, for any IV and any data length (TC: 0..=218
/// octets, the most a protected 256-octet frame holds; TM: the 214-octet packet zone): the
/// frame passes the frame checks, carries the SPI and IV, hides the data, verifies once (then
/// a replay), and a TM frame keeps its fields and OCF.
///
/// Under `cargo test`: exhaustively, every TC data length 0..=218 × IVs 0, 1, 2^95, 2^96 − 1
/// × AD/BD (data 0, 1, 2, …); then sampled inputs.
#[test]
#[cfg_attr(kani, kani::proof, kani::unwind(42))]
fn sdls_round_trip() {
    #[cfg(not(any(kani, fuzzing)))]
    {
        let name = "sdls_round_trip";
        let data: Vec<u8> = (0..=255u8).collect();
        crate::ledger::exhaustive(
            name,
            219 * 4 * 2,
            (0usize..=218, 0usize..4, bolero::produce::<bool>()),
            |&(len, k, bd)| {
                let iv = [0, 1, HALF, IV_SPACE - 1][k];
                check_round_trip(iv, bd, len as u8, &data[..len]);
            },
        );
        crate::ledger::sampled_with(
            name,
            20_000,
            |seed, i| crate::ledger::sample_bytes(seed, i, MAX_LEN),
            |b| round_trip(b),
        );
        return;
    }
    #[allow(unreachable_code)]
    bolero::check!().with_max_len(MAX_LEN).for_each(round_trip);
}

/// The window harness's sampled input: fresh, last, floor ahead, W, the IV's distance from
/// last, whether that distance is used, else the IV.
type WindowCase = (bool, u128, u8, u8, i8, bool, u128);

fn window(v: &WindowCase) -> &'static str {
    let (fresh, last, ahead, w, delta, near, iv) = *v;
    let iv = if near {
        (last % IV_SPACE).wrapping_add_signed(delta as i128) % IV_SPACE
    } else {
        iv
    };
    check_window(fresh, last, u128::from(ahead), u32::from(w), iv)
}

/// `ReplayWindow::admit` against the oracle written with signed distances: accepted iff the
/// IV is 1..=W ahead of the last and at or below the durable floor; refused as a replay (the
/// same or older: half the space or more ahead), too far ahead, or not reserved (then the
/// next floor due covers it, and it is accepted once written); an accepted IV becomes the
/// last with the floor in place, a refused one changes nothing.
///
/// Under `cargo test`: exhaustively, W 1..=4 × 11 lasts (a fresh window; 0, 1, 2, 2^95 − 2,
/// 2^95 − 1, 2^95, 2^95 + 1, 2^96 − 3, 2^96 − 2, 2^96 − 1) × floor 0..=5 ahead × 17 IVs
/// (last − 6 ..= last + 6, last ± 2^95, last + 2^95 ± 1); then sampled inputs.
// req: 355.0-B-2/SDLS-12
#[test]
#[cfg_attr(kani, kani::proof, kani::unwind(14))]
fn sdls_window_matches_oracle() {
    #[cfg(not(any(kani, fuzzing)))]
    {
        let name = "sdls_window_matches_oracle";
        let lasts = [
            None,
            Some(0),
            Some(1),
            Some(2),
            Some(HALF - 2),
            Some(HALF - 1),
            Some(HALF),
            Some(HALF + 1),
            Some(IV_SPACE - 3),
            Some(IV_SPACE - 2),
            Some(IV_SPACE - 1),
        ];
        let verdicts = std::sync::Mutex::new(std::collections::BTreeMap::new());
        crate::ledger::exhaustive(
            name,
            4 * 11 * 6 * 17,
            (1u32..=4, 0usize..11, 0u8..6, 0usize..17),
            |&(w, l, ahead, d)| {
                let last = lasts[l];
                let base = last.unwrap_or(IV_SPACE - 1);
                let delta: i128 = match d {
                    0..=12 => d as i128 - 6,
                    13 => HALF as i128,
                    14 => -(HALF as i128),
                    15 => HALF as i128 - 1,
                    _ => HALF as i128 + 1,
                };
                let iv = (base as i128 + delta).rem_euclid(IV_SPACE as i128) as u128;
                let v = check_window(last.is_none(), base, u128::from(ahead), w, iv);
                *verdicts.lock().unwrap().entry(v).or_insert(0u32) += 1;
            },
        );
        let verdicts = verdicts.into_inner().unwrap();
        println!("{name}: verdicts {verdicts:?}");
        assert_eq!(verdicts.len(), 4, "every verdict reached: {verdicts:?}");
        crate::ledger::sampled::<WindowCase>(name, 200_000, |v| {
            window(v);
        });
        return;
    }
    #[allow(unreachable_code)]
    bolero::check!().with_type::<WindowCase>().for_each(|v| {
        window(v);
    });
}

/// The sender's counter input: start, near the end of the IV space, block − 1, operations.
type TxCase = (u128, bool, u8, [u8; OPS]);

/// A sender never takes an IV twice, across restarts that lose or keep the write in flight,
/// stale confirmations and exhaustion at 2^96: IVs strictly increase, each below the durable
/// store, and a refused `take` moves nothing.
///
/// Under `cargo test`: exhaustively, every sequence of 7 operations of the 6 (take, start a
/// write, confirm it, confirm the stored value again, restart losing the write, restart
/// keeping it) × block 1 and 2 × a new association and one 2 short of 2^96; then sampled
/// inputs (24 operations, any start, any block 1..=256).
// req: 355.0-B-2/SDLS-3
#[test]
#[cfg_attr(kani, kani::proof, kani::unwind(8))]
fn sdls_tx_counter_never_reuses() {
    #[cfg(not(any(kani, fuzzing)))]
    {
        let name = "sdls_tx_counter_never_reuses";
        let most = std::sync::atomic::AtomicUsize::new(0);
        crate::ledger::exhaustive(
            name,
            6u64.pow(7) * 4,
            (
                crate::ledger::seq::<_, 7>(0u8..6),
                0u8..2,
                bolero::produce::<bool>(),
            ),
            |&(ops, block, near_end)| {
                let k = check_tx_ops(1, near_end, block, &ops);
                most.fetch_max(k, std::sync::atomic::Ordering::Relaxed);
            },
        );
        assert!(most.into_inner() >= 3, "runs take several IVs");
        crate::ledger::sampled::<TxCase>(name, 200_000, |(start, near, block, ops)| {
            check_tx_ops(*start, *near, *block, ops);
        });
        return;
    }
    #[allow(unreachable_code)]
    bolero::check!()
        .with_type::<TxCase>()
        .for_each(|(start, near, block, ops)| {
            check_tx_ops(*start, *near, *block, ops);
        });
}

/// The base frames of the gateway harness's exhaustive part, each whole: a protected AD
/// frame with the ping under IV 0 (the fresh gateway's next), a protected BD frame under IV 3,
/// BC Unlock (in clear), and the AD frame with the ping in clear (not protected).
#[cfg(not(any(kani, fuzzing)))]
fn gateway_bases() -> Vec<Vec<u8>> {
    use mmic::link::tc_frame::{MapId, SpacecraftId, TcContent, TcFrameRepr, Vcid};
    use mmic::link::ControlCommand;
    use mmic_proofs::sdls::{ping, protected_tc};
    let mut out = Vec::new();
    let mut buf = [0u8; 256];
    let n = protected_tc(0, false, 0, &ping(1), &mut buf);
    out.push(buf[..n].to_vec());
    let n = protected_tc(3, true, 0, &ping(2), &mut buf);
    out.push(buf[..n].to_vec());
    let p = ping(3);
    for content in [
        TcContent::Bc(ControlCommand::Unlock),
        TcContent::Ad {
            map_id: MapId::new(0).ok(),
            data: &p,
        },
    ] {
        let repr = TcFrameRepr {
            spacecraft_id: SpacecraftId::new(0x101).unwrap(),
            vcid: Vcid::new(0).unwrap(),
            seq: 0,
            content,
        };
        let n = repr.emit(&mut buf).unwrap();
        out.push(buf[..n].to_vec());
    }
    out
}

/// Any octets through a secured gateway's `tc_frame`: it returns; a refusal is counted under
/// its check (the frame's, or SDLS's reason) and moves nothing else; nothing reaches FARM-1
/// or the PUS gateway unless it is a BC frame (in clear by design, no packets) or exactly a
/// frame the key's holder protected; the SDLS layer alone refuses the octets in place,
/// unchanged.
///
/// Under `cargo test`: exhaustively, every single-octet change (XOR 1..=255) of each base
/// frame (51 + 51 + 8 + 21 octets), FECF written again or not, and every strict prefix of
/// each (nothing may run: no input is a frame the ground protected); then sampled octets of
/// any length 0..=235, each as it is and with the frame checks' fields
/// (spacecraft, VC, length, FECF) written over it.
#[test]
#[cfg_attr(kani, kani::proof, kani::unwind(42))]
fn sdls_verify_tc_arbitrary_bytes_never_panics() {
    #[cfg(not(any(kani, fuzzing)))]
    {
        let name = "sdls_verify_tc_arbitrary_bytes_never_panics";
        let bases = gateway_bases();
        let lens: Vec<usize> = bases.iter().map(|b| b.len()).collect();
        assert_eq!(lens, [51, 51, 8, 21]);
        // Case i: an edit of base frame b at octet `at`, or (delta 0) its prefix of `at` octets.
        let cases: Vec<(usize, usize)> = (0..4)
            .flat_map(|b| (0..lens[b]).map(move |at| (b, at)))
            .collect();
        assert_eq!(cases.len(), 131);
        // The frames as sent run (the genuine ones: the property's other branch).
        for b in &bases[..2] {
            assert!(check_secured_tc_frame(b), "the protected frame runs");
        }
        crate::ledger::exhaustive(
            name,
            131 * (255 * 2 + 1),
            (0usize..131, 0u16..=510),
            |&(c, e)| {
                let (b, at) = cases[c];
                let mut f = bases[b].clone();
                if e == 510 {
                    f.truncate(at);
                } else {
                    f[at] ^= (e % 255) as u8 + 1;
                    if e >= 255 && at < f.len() - 2 {
                        mmic_proofs::sdls::refresh_fecf(&mut f);
                    }
                }
                assert!(!check_secured_tc_frame(&f), "a changed frame ran");
            },
        );
        crate::ledger::sampled_with(
            name,
            20_000,
            |seed, i| crate::ledger::sample_bytes(seed, i, MAX_LEN),
            |b| {
                assert!(!check_secured_tc_frame(b));
                assert!(!check_secured_tc_frame_resealed(b));
            },
        );
        return;
    }
    #[allow(unreachable_code)]
    bolero::check!().with_max_len(MAX_LEN).for_each(|b| {
        check_secured_tc_frame(b);
        check_secured_tc_frame_resealed(b);
    });
}
