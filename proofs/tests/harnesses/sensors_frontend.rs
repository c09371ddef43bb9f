//! The sensor front end (Section 2's 50-sample averaging of every raw channel) never panics,
//! keeps every reading within its channel's full scale, and averages the signed accelerations
//! exactly: the offset into the unsigned filter and back equals the floor of the signed mean.
//! Random under `cargo test`, fuzzed under `cargo bolero test`; under `cargo kani --tests` a
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

#[test]
#[cfg_attr(kani, kani::proof, kani::unwind(10))]
fn frontend_stays_in_range_and_averages_signed_accelerations_exactly() {
    bolero::check!()
        .with_type::<([[u16; 8]; LEN], [i16; LEN], u16)>()
        .for_each(|(codes, ax, zero)| {
            let s = Scaling::default();
            let mut f = Frontend::<N>::new(Config {
                scaling: s,
                encoder_zero: *zero,
            });
            for i in 0..LEN {
                let out = f.push(&Raw {
                    adc: codes[i],
                    accel: Some([ax[i], 0, 0]),
                    encoder: codes[i][0],
                });
                let e = out.electrical;
                let fs = s.full_scale;
                assert!(e.v_bat <= fs[0] && e.i_bat <= fs[1] && e.i_loc <= fs[2]);
                assert!(e.i_grip <= fs[3] && e.i_3v3 <= fs[4] && e.v_reg <= fs[5]);
                assert!(e.i_bo <= fs[6]);
                // The X acceleration's signed mean decides gravity's sign on X (the other axes
                // are zero): positive mean → +X, negative → −X, zero → no gravity.
                let start = (i + 1).saturating_sub(N);
                let mut sum: i64 = 0;
                for &a in &ax[start..=i] {
                    sum += a as i64;
                }
                let mean = sum.div_euclid((i + 1 - start) as i64);
                match out.gravity {
                    None => assert_eq!(mean, 0),
                    Some(g) => {
                        assert_eq!(g.axis, mmic::units::Axis::X);
                        assert_eq!(g.sign == mmic::units::Sign::Positive, mean > 0);
                        assert_ne!(mean, 0);
                    }
                }
            }
        });
}
