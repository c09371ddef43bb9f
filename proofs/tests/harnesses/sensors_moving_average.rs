//! The running-sum moving average equals the naive mean of the last N samples after every
//! push, for every sample sequence (before and after the window fills). Random under
//! `cargo test`, fuzzed under `cargo bolero test`; under `cargo kani --tests` a proof for
//! windows of 4 over 8 arbitrary samples (the window is 50 in the firmware; the code does not
//! depend on N beyond the compile-time overflow check).

use mmic::sensors::MovingAverage;

#[cfg(not(kani))]
const N: usize = 50;
#[cfg(kani)]
const N: usize = 4;
#[cfg(not(kani))]
const LEN: usize = 120;
#[cfg(kani)]
const LEN: usize = 8;

#[test]
#[cfg_attr(kani, kani::proof, kani::unwind(10))]
fn moving_average_equals_naive_mean() {
    bolero::check!()
        .with_type::<[u16; LEN]>()
        .for_each(|samples| {
            let mut f = MovingAverage::<N>::new();
            for i in 0..LEN {
                f.push(samples[i]);
                let start = (i + 1).saturating_sub(N);
                let window = &samples[start..=i];
                let mut sum: u64 = 0;
                for &s in window {
                    sum += s as u64;
                }
                assert_eq!(f.mean(), Some((sum / window.len() as u64) as u16));
            }
        });
}
