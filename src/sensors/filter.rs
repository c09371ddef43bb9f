//! Moving averages with a running sum: O(1) per sample. [`MovingAverage`] is one channel;
//! [`Averages`] is `K` channels sampled together (a sensor front end's ADC or IMU), sharing
//! one slot index and count so a tick's samples cost one index update, not one per channel.
// req: P2.10, D:sensor-filtering

/// Mean of the last `N` samples (fewer before `N` have arrived), rounded down.
///
/// The running sum is a `u32`: `N` samples of at most 65535 fit while `N` ≤ 65537, which a
/// compile-time check enforces.
#[derive(Debug, Clone, PartialEq, Eq, Hash)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct MovingAverage<const N: usize> {
    window: [u16; N],
    next: usize,
    count: usize,
    sum: u32,
}

impl<const N: usize> Default for MovingAverage<N> {
    fn default() -> Self {
        Self::new()
    }
}

/// The longest window whose sum of u16 samples fits a u32: ⌊(2³² − 1) / (2¹⁶ − 1)⌋ (the
/// tests check the figure).
const MAX_WINDOW: usize = 65_537;

impl<const N: usize> MovingAverage<N> {
    const FITS: () = assert!(N >= 1 && N <= MAX_WINDOW, "window too large for a u32 sum");

    /// An empty filter.
    pub const fn new() -> Self {
        let () = Self::FITS;
        MovingAverage {
            window: [0; N],
            next: 0,
            count: 0,
            sum: 0,
        }
    }

    /// Adds a sample, dropping the oldest once the window is full. The slot index wraps by a
    /// comparison, not `%`: the division it replaces was a large part of every sample's cost
    /// in the fault swarm's profile (issue 40). The sum cannot overflow (the compile-time
    /// check above), so its wrapping arithmetic is exact and has no overflow check to panic.
    pub fn push(&mut self, sample: u16) {
        let full = self.count == N;
        if let Some(slot) = self.window.get_mut(self.next) {
            // The slot at `next` holds the oldest sample once the window is full.
            let old = if full { u32::from(*slot) } else { 0 };
            self.sum = self.sum.wrapping_sub(old).wrapping_add(u32::from(sample));
            *slot = sample;
        }
        if !full {
            // Below N here (not full): never saturates.
            self.count = self.count.saturating_add(1);
        }
        self.next = wrap_next::<N>(self.next);
    }

    /// The mean, or `None` before the first sample. Once the window is full (nearly always)
    /// the divisor is the constant `N`, which compiles to a multiplication.
    pub fn mean(&self) -> Option<u16> {
        mean_of::<N>(self.sum, self.count)
    }

    /// Samples in the window (≤ N).
    pub const fn len(&self) -> usize {
        self.count
    }

    /// No sample yet.
    pub const fn is_empty(&self) -> bool {
        self.count == 0
    }
}

/// The slot after `i` in a window of `N`, back to 0 after the last. The increment wraps, at
/// no cost: `i` < N, and even `usize::MAX` would wrap to slot 0, a slot.
const fn wrap_next<const N: usize>(i: usize) -> usize {
    let next = i.wrapping_add(1);
    if next < N {
        next
    } else {
        0
    }
}

/// `N` as the divisor of a full window's mean; a constant, so that its division compiles to a
/// multiplication (N ≤ [`MAX_WINDOW`] by `FITS`, so the conversion is exact).
fn full<const N: usize>() -> u32 {
    u32::try_from(N).unwrap_or(u32::MAX)
}

/// `sum / n`, the mean of `n` u16 samples summing to `sum`, as the u16 it always is (a mean
/// never exceeds its largest sample); `n` is never 0 (the callers match 0 first), which would
/// give 0.
fn mean_u16(sum: u32, n: u32) -> u16 {
    u16::try_from(sum.checked_div(n).unwrap_or(0)).unwrap_or(u16::MAX)
}

/// A partial window's count `c` (< N ≤ [`MAX_WINDOW`]) as a divisor: exact.
fn partial(c: usize) -> u32 {
    u32::try_from(c).unwrap_or(u32::MAX)
}

/// `sum / count` rounded down, or `None` when `count` is 0; the divisor is the constant `N`
/// when the window is full, so that common case needs no run-time division.
fn mean_of<const N: usize>(sum: u32, count: usize) -> Option<u16> {
    match count {
        0 => None,
        c if c == N => Some(mean_u16(sum, full::<N>())),
        c => Some(mean_u16(sum, partial(c))),
    }
}

/// The moving averages of `K` channels sampled together, each the mean of its last `N`
/// samples (fewer before `N` ticks), rounded down: per channel exactly what a
/// [`MovingAverage<N>`] fed the same samples gives (`tests` and the front end's proof hold
/// it to that), at one index update per tick instead of `K`.
#[derive(Debug, Clone, PartialEq, Eq, Hash)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Averages<const N: usize, const K: usize> {
    /// A tick's samples per slot.
    window: [[u16; K]; N],
    next: usize,
    count: usize,
    sum: [u32; K],
}

impl<const N: usize, const K: usize> Default for Averages<N, K> {
    fn default() -> Self {
        Self::new()
    }
}

impl<const N: usize, const K: usize> Averages<N, K> {
    /// Empty filters.
    pub const fn new() -> Self {
        let () = MovingAverage::<N>::FITS;
        Averages {
            window: [[0; K]; N],
            next: 0,
            count: 0,
            sum: [0; K],
        }
    }

    /// Adds one tick's samples, dropping the oldest tick's once the window is full.
    pub fn push(&mut self, samples: [u16; K]) {
        let full = self.count == N;
        if let Some(row) = self.window.get_mut(self.next) {
            // The row written in the same loop: `*row = samples` after it was a call of
            // `memcpy` per tick on RV32 (issue 40, `benches/rv32/README.md`).
            for ((sum, slot), new) in self.sum.iter_mut().zip(row.iter_mut()).zip(samples) {
                let old = if full { u32::from(*slot) } else { 0 };
                // Exact: a channel's sum never exceeds N × 65535 (FITS).
                *sum = sum.wrapping_sub(old).wrapping_add(u32::from(new));
                *slot = new;
            }
        }
        if !full {
            // Below N here (not full): never saturates.
            self.count = self.count.saturating_add(1);
        }
        self.next = wrap_next::<N>(self.next);
    }

    /// Every channel's mean, or `None` before the first tick's samples; as
    /// [`MovingAverage::mean`], a constant divisor once the window is full.
    pub fn means(&self) -> Option<[u16; K]> {
        match self.count {
            0 => None,
            _ => Some(self.means_or([0; K])),
        }
    }

    /// Every channel's mean, or `empty` before the first tick's samples: [`means`](Self::means)
    /// without the `Option`, whose array the caller copied out again (through `memcpy` on
    /// RV32, about 100 instructions a tick).
    pub fn means_or(&self, empty: [u16; K]) -> [u16; K] {
        match self.count {
            0 => empty,
            c if c == N => self.sum.map(|s| mean_u16(s, full::<N>())),
            c => {
                let c = partial(c);
                self.sum.map(|s| mean_u16(s, c))
            }
        }
    }

    /// Ticks in the window (≤ N).
    pub const fn len(&self) -> usize {
        self.count
    }

    /// No sample yet.
    pub const fn is_empty(&self) -> bool {
        self.count == 0
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// `Default` is the empty filter `new` gives (clippy's new_without_default asks for both).
    #[test]
    fn default_is_new() {
        assert_eq!(MovingAverage::<4>::default(), MovingAverage::<4>::new());
        assert_eq!(Averages::<4, 3>::default(), Averages::<4, 3>::new());
    }

    // req: P2.10
    #[test]
    fn max_window_is_the_largest_that_fits() {
        let max = u64::try_from(MAX_WINDOW).unwrap();
        assert!(max * u64::from(u16::MAX) <= u64::from(u32::MAX));
        assert!((max + 1) * u64::from(u16::MAX) > u64::from(u32::MAX));
    }

    /// Per channel, [`Averages`] gives what a [`MovingAverage`] gives, before and after the
    /// window fills and across its wrap, with the extreme samples.
    // req: P2.10
    #[test]
    fn averages_equal_one_moving_average_per_channel() {
        let mut all = Averages::<5, 3>::new();
        let mut one: [MovingAverage<5>; 3] = core::array::from_fn(|_| MovingAverage::new());
        assert_eq!(all.means(), None);
        assert_eq!(all.means_or([7; 3]), [7; 3]);
        let mut x: u32 = 0x1234_5678;
        for t in 0..40u32 {
            x ^= x << 13;
            x ^= x >> 17;
            x ^= x << 5;
            let samples = match t % 4 {
                0 => [u16::MAX; 3],
                1 => [0, u16::MAX, 1],
                _ => [x as u16, (x >> 16) as u16, (x >> 8) as u16],
            };
            all.push(samples);
            for (f, &s) in one.iter_mut().zip(samples.iter()) {
                f.push(s);
            }
            let want = one.each_ref().map(|f| f.mean().unwrap_or(0));
            assert_eq!(all.means(), Some(want), "t = {t}");
            assert_eq!(all.means_or([7; 3]), want, "t = {t}");
            assert_eq!(all.len(), one[0].len());
        }
    }

    /// Empty until the first sample, whichever filter.
    #[test]
    fn empty_until_the_first_sample() {
        let mut m = MovingAverage::<4>::new();
        let mut a = Averages::<4, 2>::new();
        assert!(m.is_empty() && a.is_empty());
        m.push(7);
        a.push([7, 8]);
        assert!(!m.is_empty() && !a.is_empty());
        assert_eq!((m.len(), a.len()), (1, 1));
    }
}
