//! A board's millisecond clock: the wrapping [`Instant`] and the [`Duration`] between two.

/// A moment on a board's millisecond clock, which wraps after 2³² ms (49.7 days): the time
/// every `tick(now, ..)` of the library receives, as a type (after smoltcp's `time::Instant`).
/// Differences are taken on the wrapping clock, so timers work across the wrap.
///
/// ```
/// use mmic::units::{Duration, Instant};
/// let t = Instant::from_millis(u32::MAX - 5);
/// let later = Instant::from_millis(4); // 10 ms later, across the wrap
/// assert_eq!(later.since(t), Duration::from_millis(10));
/// assert_eq!(t.since(later), Duration::ZERO); // the clock went backwards: no time passed
/// ```
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Default)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Instant(u32);

/// A span of milliseconds between two [`Instant`]s.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord, Default)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Duration(u32);

/// Half the clock's wrap, 2³¹ − 1 ms: a later moment is at most this far ahead.
const HALF_WRAP: u32 = i32::MAX.unsigned_abs();

impl Instant {
    /// The clock's zero.
    pub const ZERO: Instant = Instant(0);

    /// The moment `ms` milliseconds after the clock's zero (modulo the wrap).
    pub const fn from_millis(ms: u32) -> Instant {
        Instant(ms)
    }

    /// Milliseconds since the clock's zero, as the board reads it.
    pub const fn millis(self) -> u32 {
        self.0
    }

    /// The moment `d` after this one, on the wrapping clock.
    pub const fn after(self, d: Duration) -> Instant {
        Instant(self.0.wrapping_add(d.0))
    }

    /// Whether `deadline` has come (`self` is at or after it on the wrapping clock, within
    /// half the wrap).
    ///
    /// ```
    /// use mmic::units::Instant;
    /// let t = |ms| Instant::from_millis(ms);
    /// assert!(t(10).reached(t(10)) && t(11).reached(t(10)) && !t(9).reached(t(10)));
    /// assert!(t(5).reached(t(u32::MAX - 5))); // across the wrap
    /// ```
    pub const fn reached(self, deadline: Instant) -> bool {
        self.0.wrapping_sub(deadline.0) <= HALF_WRAP
    }

    /// Time from `earlier` to `self` on the wrapping clock; zero if `self` is earlier (a
    /// difference of more than half the wrap is read as the clock having gone backwards).
    pub const fn since(self, earlier: Instant) -> Duration {
        let d = self.0.wrapping_sub(earlier.0);
        if d > HALF_WRAP {
            Duration(0)
        } else {
            Duration(d)
        }
    }
}

impl Duration {
    /// No time.
    pub const ZERO: Duration = Duration(0);

    /// `ms` milliseconds.
    pub const fn from_millis(ms: u32) -> Duration {
        Duration(ms)
    }

    /// Milliseconds.
    pub const fn millis(self) -> u32 {
        self.0
    }
}
