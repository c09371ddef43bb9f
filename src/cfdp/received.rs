//! What a receiving entity has of a file: the octet ranges received so far, sorted, disjoint
//! and merged, at most `N` of them (a const capacity, no allocation). From them come the
//! receiver's progress (the Keep Alive's), its gaps (the NAK's segment requests) and whether
//! the file is complete. A range that would need an `(N+1)`th entry is refused and changes
//! nothing: class 2 asks for it again once earlier gaps are filled.
//!
//! ```
//! use mmic::cfdp::received::Received;
//!
//! let mut r = Received::<4>::new();
//! assert_eq!(r.add(0, 10), Ok(10));
//! assert_eq!(r.add(20, 5), Ok(5));
//! assert_eq!(r.add(5, 10), Ok(5)); // octets 5..10 were there already
//! assert_eq!(r.progress(), 15);
//! let gaps: Vec<(u32, u32)> = r.gaps(30).collect();
//! assert_eq!(gaps, [(15, 20), (25, 30)]);
//! assert!(!r.is_complete(25));
//! ```

use heapless::Vec;

/// Why a range could not be added; nothing changed.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, thiserror::Error)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum ReceivedError {
    /// The range ends beyond 2³² octets.
    #[error("octets {start}..+{len} end beyond 4 GiB")]
    Overflow {
        /// Its start.
        start: u32,
        /// Its length.
        len: u32,
    },
    /// The range would be one more than the `capacity` kept.
    #[error("a gap more than the {capacity} ranges kept")]
    Full {
        /// Ranges kept at most.
        capacity: usize,
    },
}

/// The ranges received, each `(start, end)`, end excluded.
#[derive(Debug, Clone, PartialEq, Eq, Hash)]
pub struct Received<const N: usize> {
    ranges: Vec<(u32, u32), N>,
}

impl<const N: usize> Default for Received<N> {
    fn default() -> Self {
        Self::new()
    }
}

impl<const N: usize> Received<N> {
    /// Nothing received.
    pub const fn new() -> Self {
        Received { ranges: Vec::new() }
    }

    /// Adds octets `start..start + len`: how many of them were new.
    pub fn add(&mut self, start: u32, len: u32) -> Result<u32, ReceivedError> {
        let end = start
            .checked_add(len)
            .ok_or(ReceivedError::Overflow { start, len })?;
        if len == 0 {
            return Ok(0);
        }
        // The ranges touching or overlapping start..end merge with it into one.
        let first = self.ranges.iter().position(|&(_, e)| e >= start);
        let first = first.unwrap_or(self.ranges.len());
        let past = self
            .ranges
            .iter()
            .position(|&(s, _)| s > end)
            .unwrap_or(self.ranges.len());
        let merged = past.saturating_sub(first);
        if merged == 0 && self.ranges.is_full() {
            return Err(ReceivedError::Full { capacity: N });
        }
        let touched = self.ranges.get(first..past).unwrap_or(&[]);
        let had: u32 = touched
            .iter()
            .map(|&(s, e)| e.min(end).saturating_sub(s.max(start)))
            .fold(0, u32::saturating_add);
        let lo = touched.first().map_or(start, |&(s, _)| s.min(start));
        let hi = touched.last().map_or(end, |&(_, e)| e.max(end));
        self.replace(first, past, (lo, hi));
        Ok(len.saturating_sub(had))
    }

    /// Puts `range` where `first..past` were (at least one slot free when they are none).
    fn replace(&mut self, first: usize, past: usize, range: (u32, u32)) {
        let mut next: Vec<(u32, u32), N> = Vec::new();
        let before = self.ranges.get(..first).unwrap_or(&[]);
        let after = self.ranges.get(past..).unwrap_or(&[]);
        for r in before.iter().chain(&[range]).chain(after) {
            // Never full: the ranges are one fewer than before, or as many with a free slot.
            let _ = next.push(*r);
        }
        self.ranges = next;
    }

    /// Octets received without a gap from the start of the file.
    pub fn progress(&self) -> u32 {
        match self.ranges.first() {
            Some(&(0, e)) => e,
            _ => 0,
        }
    }

    /// Octets received in all.
    pub fn total(&self) -> u32 {
        self.ranges
            .iter()
            .map(|&(s, e)| e.saturating_sub(s))
            .fold(0, u32::saturating_add)
    }

    /// Whether every octet of a file of `size` octets is here.
    pub fn is_complete(&self, size: u32) -> bool {
        size == 0 || self.progress() >= size
    }

    /// The missing ranges below `upto`, in order, each `(start, end)`.
    pub fn gaps(&self, upto: u32) -> impl Iterator<Item = (u32, u32)> + '_ {
        let starts = core::iter::once(0).chain(self.ranges.iter().map(|&(_, e)| e));
        let ends = self
            .ranges
            .iter()
            .map(|&(s, _)| s)
            .chain(core::iter::once(upto));
        starts
            .zip(ends)
            .map(move |(s, e)| (s.min(upto), e.min(upto)))
            .filter(|&(s, e)| s < e)
    }

    /// The ranges received, in order.
    pub fn ranges(&self) -> &[(u32, u32)] {
        &self.ranges
    }
}
