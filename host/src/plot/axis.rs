//! Chart axes: a value range, "nice" tick values within it, and the mapping to positions.

use super::{FAR, LIMIT, TICKS};

/// An axis: its range, tick values, and the positions its ends map to.
pub(super) struct Axis {
    pub(super) lo: f64,
    pub(super) hi: f64,
    pub(super) step: f64,
    pub(super) ticks: Vec<f64>,
    /// Position of `lo`.
    pub(super) p0: f64,
    /// Position of `hi`.
    pub(super) p1: f64,
}

impl Axis {
    /// Range covering `lo..=hi`, extended to whole ticks.
    pub(super) fn auto((lo, hi): (f64, f64), p0: f64, p1: f64) -> Axis {
        let (lo, hi) = widen(lo, hi);
        let step = nice_step(hi - lo);
        let (lo2, hi2) = ((lo / step).floor() * step, (hi / step).ceil() * step);
        if lo2.is_finite() && hi2.is_finite() && lo2 < hi2 {
            Axis::with_ticks(lo2, hi2, step, p0, p1)
        } else {
            Axis::with_ticks(lo, hi, step, p0, p1)
        }
    }

    /// Exactly `lo..=hi`, ticks at the multiples of a nice step inside it.
    pub(super) fn fixed(lo: f64, hi: f64, p0: f64, p1: f64) -> Axis {
        let (lo, hi) = widen(lo, hi);
        Axis::with_ticks(lo, hi, nice_step(hi - lo), p0, p1)
    }

    fn with_ticks(lo: f64, hi: f64, step: f64, p0: f64, p1: f64) -> Axis {
        let first = (lo / step - 1e-9).ceil();
        let last = (hi / step + 1e-9).floor();
        let ticks = if first.is_finite() && last.is_finite() && last - first <= 50.0 {
            let mut k = first;
            let mut t = Vec::new();
            while k <= last {
                t.push(k * step);
                k += 1.0;
            }
            t
        } else {
            vec![lo, hi]
        };
        Axis {
            lo,
            hi,
            step,
            ticks,
            p0,
            p1,
        }
    }

    /// Where `v` goes: finite, far outside the view at worst.
    pub(super) fn pos(&self, v: f64) -> f64 {
        let frac = (clamp(v) - self.lo) / (self.hi - self.lo);
        (self.p0 + frac * (self.p1 - self.p0)).clamp(-FAR, FAR)
    }

    /// Tick labels: fixed-point with as many decimals as the step needs, or scientific for
    /// very large or very fine axes.
    pub(super) fn label(&self, v: f64) -> String {
        let v = if v.abs() < self.step * 1e-6 { 0.0 } else { v };
        let big = self.lo.abs().max(self.hi.abs());
        let step_exp = self.step.log10().floor();
        if big >= 1e7 || self.step < 1e-4 {
            if v == 0.0 {
                return "0".into();
            }
            let digits = (v.abs().log10().floor() - step_exp).clamp(0.0, 15.0) as usize;
            format!("{v:.digits$e}")
        } else {
            let decimals = (-step_exp).clamp(0.0, 10.0) as usize;
            format!("{v:.decimals$}")
        }
    }
}

/// A non-degenerate range: equal ends get a margin of 10 % (or 1 around zero).
pub(super) fn widen(lo: f64, hi: f64) -> (f64, f64) {
    let big = lo.abs().max(hi.abs());
    if hi - lo > big * 1e-12 && hi - lo > 1e-200 {
        (lo, hi)
    } else {
        let pad = if big > 1e-200 { big * 0.1 } else { 1.0 };
        (lo - pad, hi + pad)
    }
}

/// 1, 2 or 5 × 10ⁿ, giving about [`TICKS`] intervals over `span`.
pub(super) fn nice_step(span: f64) -> f64 {
    let raw = span / TICKS;
    let mag = 10f64.powf(raw.log10().floor());
    let norm = raw / mag;
    let m = if norm <= 1.0 {
        1.0
    } else if norm <= 2.0 {
        2.0
    } else if norm <= 5.0 {
        5.0
    } else {
        10.0
    };
    let step = m * mag;
    if step.is_finite() && step > 0.0 {
        step
    } else {
        span.max(1e-200)
    }
}

/// `v` within ±[`LIMIT`], so that spans and scales stay finite.
pub(super) fn clamp(v: f64) -> f64 {
    v.clamp(-LIMIT, LIMIT)
}

/// The least and greatest of `values`, if any.
pub(super) fn bounds(values: impl Iterator<Item = f64>) -> Option<(f64, f64)> {
    values.fold(None, |acc, v| match acc {
        None => Some((v, v)),
        Some((lo, hi)) => Some((lo.min(v), hi.max(v))),
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn nice_steps_are_1_2_5() {
        assert_eq!(nice_step(10.0), 2.0);
        assert_eq!(nice_step(1.0), 0.2);
        assert_eq!(nice_step(40.0), 10.0);
        assert_eq!(nice_step(20.0), 5.0);
    }

    #[test]
    fn auto_axes_round_outwards_to_ticks() {
        let a = Axis::auto((0.3, 9.7), 0.0, 100.0);
        assert_eq!((a.lo, a.hi), (0.0, 10.0));
        assert_eq!(a.ticks, [0.0, 2.0, 4.0, 6.0, 8.0, 10.0]);
        assert_eq!(a.pos(5.0), 50.0);
        let b = Axis::auto((0.0, 1.0), 0.0, 100.0);
        let labels: Vec<String> = b.ticks.iter().map(|&t| b.label(t)).collect();
        assert_eq!(labels, ["0.0", "0.2", "0.4", "0.6", "0.8", "1.0"]);
    }

    #[test]
    fn degenerate_ranges_widen() {
        for (lo, hi) in [(0.0, 0.0), (5.0, 5.0), (-1e300, -1e300), (1e-300, 1e-300)] {
            let a = Axis::auto((lo, hi), 0.0, 1.0);
            assert!(a.lo < a.hi && a.lo.is_finite() && a.hi.is_finite(), "{lo}");
            assert!(a.ticks.len() >= 2, "{lo}: {:?}", a.ticks);
        }
    }
}
