//! How every harness runs under plain `cargo test` (not fuzzing, not Kani): an **exhaustive**
//! part, bolero's exhaustive engine walking every value of a bounded generator (the count is
//! asserted against the domain size the ledger in proofs/README.md states), and a **sampled**
//! part of the harness's own input type: a fixed count of values, the `i`-th built by bolero's
//! generator for the type from the bytes of a SplitMix64 stream seeded with `seed` and `i`.
//! Both are reproducible: a failure prints the case (exhaustive) or the index (sampled), and
//! `sample::<T>(seed, i)` rebuilds the sampled value. Each part prints its count and time
//! (`cargo test -p mmic-proofs -- --nocapture`).
//!
//! Under `cargo bolero test` (`cfg(fuzzing)`) and `cargo kani` (`cfg(kani)`) the harnesses do
//! not call these: they run their plain `bolero::check!()` over the whole input type.

use bolero::generator::bolero_generator::driver::{ByteSliceDriver, Options};
use bolero::{TypeGenerator, ValueGenerator};
use core::fmt::Debug;
use std::panic::RefUnwindSafe;
use std::sync::atomic::{AtomicU64, Ordering};
use std::time::Instant;

/// The seed of every sampled part (the harnesses differ by name, mixed in by [`seed_of`]).
pub const SEED: u64 = 0x6d6d_6963_2d31_3731; // "mmic-171"

/// The seed of harness `name`: [`SEED`] mixed with the name's FNV-1a hash, so that two
/// harnesses with the same input type do not test the same values.
pub fn seed_of(name: &str) -> u64 {
    let mut h: u64 = 0xcbf2_9ce4_8422_2325;
    for b in name.bytes() {
        h = (h ^ b as u64).wrapping_mul(0x0000_0100_0000_01b3);
    }
    SEED ^ h
}

/// SplitMix64: the `k`-th output of the stream that starts at `state`.
fn splitmix(state: u64, k: u64) -> u64 {
    let mut z = state.wrapping_add(k.wrapping_add(1).wrapping_mul(0x9e37_79b9_7f4a_7c15));
    z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
    z ^ (z >> 31)
}

/// `n` pseudo-random bytes, the stream of `(seed, i)`.
pub fn bytes(seed: u64, i: u64, n: usize) -> Vec<u8> {
    let state = splitmix(seed, i);
    (0..n.div_ceil(8) as u64)
        .flat_map(|k| splitmix(state, k).to_le_bytes())
        .take(n)
        .collect()
}

/// The `i`-th sampled value of `T` for `seed`: bolero's generator for `T` reading the bytes of
/// `(seed, i)` (the byte-slice driver libFuzzer uses, so the values are distributed as a fuzz
/// run's).
pub fn sample<T: TypeGenerator>(seed: u64, i: u64) -> T {
    let b = bytes(seed, i, 2 * core::mem::size_of::<T>() + 64);
    let mut d = ByteSliceDriver::new(&b, &Options::default());
    T::generate(&mut d).expect("bolero generates every type from any bytes")
}

/// The `i`-th sampled byte string of at most `max_len` bytes for `seed`: a length uniform in
/// `0..=max_len`, then that many bytes.
pub fn sample_bytes(seed: u64, i: u64, max_len: usize) -> Vec<u8> {
    let b = bytes(seed, i, max_len + 8);
    let len = u64::from_le_bytes(b[..8].try_into().expect("8 bytes")) % (max_len as u64 + 1);
    b[8..8 + len as usize].to_vec()
}

/// Runs `property` on every value `generator` produces, with bolero's exhaustive engine, and
/// asserts that there were exactly `domain` of them (the size the ledger states).
pub fn exhaustive<G>(
    name: &str,
    domain: u64,
    generator: G,
    property: impl Fn(&G::Output) + RefUnwindSafe,
) where
    G: ValueGenerator,
    G::Output: Debug,
{
    let n = AtomicU64::new(0);
    let t = Instant::now();
    let body = |v: &G::Output| {
        n.fetch_add(1, Ordering::Relaxed);
        property(v)
    };
    // Behind `dyn`: bolero's engine (its runner, panic catcher and shrinker, some 6,400 lines of
    // LLVM IR a copy: cargo-llvm-lines, 1.19 M lines for 140 copies, 0.56 M for 42) is then built once per generator type, not once per harness's closure.
    let body: &(dyn Fn(&G::Output) + RefUnwindSafe) = &body;
    bolero::check!()
        .with_generator(generator)
        .exhaustive()
        .for_each(body);
    let n = n.into_inner();
    println!("{name}: exhaustive, {n} cases in {:.2?}", t.elapsed());
    assert_eq!(
        n, domain,
        "{name}: the exhaustive part walked {n} cases, the ledger says {domain}"
    );
}

/// Runs `property` on the sampled values `0..count` of `T` for [`seed_of`]`(name)` (see
/// [`sample`]).
pub fn sampled<T>(name: &str, count: u64, property: impl Fn(&T) + RefUnwindSafe)
where
    T: TypeGenerator + Debug,
{
    sampled_with(name, count, |seed, i| sample::<T>(seed, i), property);
}

/// Runs `property` on `make(seed, i)` for `i` in `0..count`, `seed` = [`seed_of`]`(name)`;
/// a failure names the index.
pub fn sampled_with<T: Debug>(
    name: &str,
    count: u64,
    make: impl Fn(u64, u64) -> T + RefUnwindSafe,
    property: impl Fn(&T) + RefUnwindSafe,
) {
    let seed = seed_of(name);
    let t = Instant::now();
    let n = AtomicU64::new(0);
    let body = |i: &u64| {
        n.fetch_add(1, Ordering::Relaxed);
        property(&make(seed, *i))
    };
    // Behind `dyn`, as in `exhaustive`: one bolero engine for every sampled part.
    let body: &(dyn Fn(&u64) + RefUnwindSafe) = &body;
    bolero::check!()
        .with_generator(0..count)
        .exhaustive()
        .for_each(body);
    let n = n.into_inner();
    println!(
        "{name}: sampled, {n} values, seed {seed:#018x}, in {:.2?}",
        t.elapsed()
    );
    assert_eq!(n, count);
}

/// `N` copies of `generator`: the generator of a sequence of `N` independent choices.
pub fn seq<G: Clone, const N: usize>(generator: G) -> [G; N] {
    core::array::from_fn(|_| generator.clone())
}
