//! The sensor front end (Section 2's 50-sample averaging of every raw channel) never panics,
//! keeps every reading within its channel's full scale, and averages the signed accelerations
//! exactly: the offset into the unsigned filter and back equals the floor of the signed mean.
//! With readings missing at random (each device on its own), a device is lost exactly when its
//! silence reaches `loss_ticks` (or it has not answered yet), a stale IMU average is dropped
//! then, and a missing encoder reading is no hip angle. Random under `cargo test`, fuzzed under `cargo bolero test`; under `cargo kani --tests` a
//! proof for a window of 4 over 6 ticks.

use mmic::sensors::adc::Scaling;
use mmic::sensors::frontend::{Config, Frontend, Raw};

#[cfg(not(kani))]
const N: usize = 50;
#[cfg(kani)]
const N: usize = 4;
#[cfg(not(kani))]
const LEN: usize = 80;
#[cfg(kani)]
const LEN: usize = 6;

/// Under `cargo test`: exhaustively, every presence pattern of the three devices over 5 ticks
/// (8^5) with every loss limit 0..=6 ticks (silences shorter than, equal to and longer than
/// it, and "never heard"), three acceleration sequences (all i16::MIN, all i16::MAX, and
/// alternating +1/−1: a mean at each extreme and one that floors towards −∞), ADC codes
/// alternating 0 and 0xffff, and encoder zeros 0 and 0xffff; then sampled inputs over 80
/// ticks.
// req: P2.10
#[test]
#[cfg_attr(kani, kani::proof, kani::unwind(10))]
fn frontend_stays_in_range_and_averages_signed_accelerations_exactly() {
    #[cfg(not(any(kani, fuzzing)))]
    {
        const T: usize = 5;
        const AX: [[i16; T]; 3] = [[i16::MIN; T], [i16::MAX; T], [1, -1, 1, -1, 1]];
        let codes: [[u16; 8]; T] =
            core::array::from_fn(|i| [if i % 2 == 0 { 0 } else { 0xffff }; 8]);
        let name = "frontend_stays_in_range_and_averages_signed_accelerations_exactly";
        crate::ledger::exhaustive(
            name,
            8u64.pow(5) * 7 * 3 * 2,
            (
                crate::ledger::seq::<_, T>(0u8..8),
                0u8..7,
                0usize..3,
                bolero::produce::<bool>(),
            ),
            |&(present, loss, ax, zero)| {
                let zero = if zero { 0xffff } else { 0 };
                frontend(&codes, &AX[ax], &present, zero, loss);
            },
        );
        crate::ledger::sampled::<([[u16; 8]; LEN], [i16; LEN], [u8; LEN], u16, u8)>(
            name,
            10_000,
            |(codes, ax, present, zero, loss)| frontend(codes, ax, present, *zero, *loss),
        );
        return;
    }
    #[allow(unreachable_code)]
    bolero::check!()
        .with_type::<([[u16; 8]; LEN], [i16; LEN], [u8; LEN], u16, u8)>()
        .for_each(|(codes, ax, present, zero, loss)| frontend(codes, ax, present, *zero, *loss));
}

/// The property of [`frontend_stays_in_range_and_averages_signed_accelerations_exactly`] over
/// `present.len()` ticks (`codes` and `ax` at least as long).
fn frontend(codes: &[[u16; 8]], ax: &[i16], present: &[u8], zero: u16, loss: u8) {
    let (zero, loss) = (&zero, &loss);
    {
        let s = Scaling::default();
        let loss_ticks = u16::from(*loss % (LEN as u8 + 2));
        let mut f = Frontend::<N>::new(Config {
            scaling: s,
            encoder_zero: *zero,
            hip_encoder: true,
            loss_ticks,
        });
        // The oracle: silence per device (ADC, IMU, encoder; "not yet" counts as long
        // silence) and the accelerations the IMU average holds.
        let mut silent = [u16::MAX; 3];
        let mut held: [i16; LEN] = [0; LEN];
        let mut n_held = 0usize;
        for i in 0..present.len() {
            let has = [
                present[i] & 1 != 0,
                present[i] & 2 != 0,
                present[i] & 4 != 0,
            ];
            for d in 0..3 {
                silent[d] = if has[d] {
                    0
                } else {
                    silent[d].saturating_add(1)
                };
            }
            if has[1] {
                held[n_held] = ax[i];
                n_held += 1;
            } else if silent[1] >= loss_ticks {
                n_held = 0;
            }
            let out = f.push(&Raw {
                adc: has[0].then_some(codes[i]),
                accel: has[1].then_some([ax[i], 0, 0]),
                encoder: has[2].then_some(codes[i][0]),
            });
            assert_eq!(out.lost.adc, silent[0] >= loss_ticks);
            assert_eq!(out.lost.encoder, silent[2] >= loss_ticks);
            assert_eq!(out.hip.is_some(), has[2]);
            let e = out.electrical;
            let fs = s.full_scale;
            assert!(e.v_bat <= fs[0] && e.i_bat <= fs[1] && e.i_loc <= fs[2]);
            assert!(e.i_grip <= fs[3] && e.i_3v3 <= fs[4] && e.v_reg <= fs[5]);
            assert!(e.i_bo <= fs[6]);
            // The X acceleration's signed mean decides gravity's sign on X (the other axes
            // are zero): positive mean → +X, negative → −X, zero → no gravity.
            let start = n_held.saturating_sub(N);
            let mut sum: i64 = 0;
            for &a in &held[start..n_held] {
                sum += a as i64;
            }
            let mean = sum.div_euclid((n_held - start).max(1) as i64);
            match out.gravity {
                None => assert!(mean == 0 || n_held == 0),
                Some(g) => {
                    assert_eq!(g.axis, mmic::units::Axis::X);
                    assert_eq!(g.sign == mmic::units::Sign::Positive, mean > 0);
                    assert_ne!(mean, 0);
                    assert!(n_held > 0);
                }
            }
        }
    }
}
