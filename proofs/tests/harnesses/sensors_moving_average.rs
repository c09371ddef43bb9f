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

/// Under `cargo test`: exhaustively, window 50 over 120 samples all equal to each u16 value
/// (the largest sums the 50-sample window holds, every quotient), and window 3 over every
/// sequence of 7 samples from 0, 1, 32767, 32768, 65534 and 65535 (filling, sliding, and the
/// sums' carries; the code does not depend on N beyond its compile-time overflow check); then
/// sampled inputs at window 50.
// req: P2.10
#[test]
#[cfg_attr(kani, kani::proof, kani::unwind(10))]
fn moving_average_equals_naive_mean() {
    #[cfg(not(any(kani, fuzzing)))]
    {
        const V: [u16; 6] = [0, 1, 32767, 32768, 65534, 65535];
        let name = "moving_average_equals_naive_mean";
        crate::ledger::exhaustive(
            &format!("{name} (constant, window 50)"),
            65_536,
            bolero::produce::<u16>(),
            |&v| moving_average::<N>(&[v; LEN]),
        );
        crate::ledger::exhaustive(
            &format!("{name} (window 3)"),
            6u64.pow(7),
            crate::ledger::seq::<_, 7>(0usize..6),
            |s| moving_average::<3>(&s.map(|k| V[k])),
        );
        crate::ledger::sampled::<[u16; LEN]>(name, 20_000, |s| moving_average::<N>(s));
        return;
    }
    #[allow(unreachable_code)]
    bolero::check!()
        .with_type::<[u16; LEN]>()
        .for_each(|samples| moving_average::<N>(samples));
}

/// The property of [`moving_average_equals_naive_mean`] for a window of `W`.
fn moving_average<const W: usize>(samples: &[u16]) {
    let mut f = MovingAverage::<W>::new();
    for i in 0..samples.len() {
        f.push(samples[i]);
        let start = (i + 1).saturating_sub(W);
        let window = &samples[start..=i];
        let mut sum: u64 = 0;
        for &s in window {
            sum += s as u64;
        }
        assert_eq!(f.mean(), Some((sum / window.len() as u64) as u16));
    }
}
