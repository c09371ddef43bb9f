//! Moving average with a running sum: O(1) per sample.

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

impl<const N: usize> MovingAverage<N> {
    const FITS: () = assert!(
        N >= 1 && (N as u64) * (u16::MAX as u64) <= u32::MAX as u64,
        "window too large for a u32 sum"
    );

    /// An empty filter.
    pub const fn new() -> Self {
        #[allow(clippy::let_unit_value)]
        let () = Self::FITS;
        MovingAverage {
            window: [0; N],
            next: 0,
            count: 0,
            sum: 0,
        }
    }

    /// Adds a sample, dropping the oldest once the window is full.
    pub fn push(&mut self, sample: u16) {
        if self.count == N {
            // The slot at `next` holds the oldest sample.
            self.sum -= self.window[self.next % N] as u32;
        } else {
            self.count += 1;
        }
        self.window[self.next % N] = sample;
        self.sum += sample as u32;
        self.next = (self.next + 1) % N;
    }

    /// The mean, or `None` before the first sample.
    pub fn mean(&self) -> Option<u16> {
        if self.count == 0 {
            None
        } else {
            Some((self.sum / self.count as u32) as u16)
        }
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
