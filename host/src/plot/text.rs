//! How numbers and names are written in charts: short, finite, and cut in the middle when long.

/// A coordinate: two decimals, never `NaN` or `inf`, no `-0`.
pub(super) fn num(v: f64) -> String {
    let v = if v.is_finite() { v } else { 0.0 };
    let s = format!("{v:.2}");
    let s = s.trim_end_matches('0').trim_end_matches('.');
    match s {
        "-0" | "" => "0".into(),
        s => s.into(),
    }
}

/// A bar's value: integers as such, others with up to 3 decimals, extremes in scientific form.
pub(super) fn value_label(v: f64) -> String {
    if !v.is_finite() {
        return "n/a".into();
    }
    let a = v.abs();
    if a != 0.0 && !(1e-3..1e6).contains(&a) {
        let sci = format!("{v:.3e}");
        let (mantissa, exp) = sci.split_once('e').unwrap_or((&sci, "0"));
        let mantissa = mantissa.trim_end_matches('0').trim_end_matches('.');
        return format!("{mantissa}e{exp}");
    }
    let s = format!("{v:.3}");
    let s = s.trim_end_matches('0').trim_end_matches('.');
    if s == "-0" {
        "0".into()
    } else {
        s.into()
    }
}

/// A finite value in full, for tooltips.
pub(super) fn exact(v: f64) -> String {
    let a = v.abs();
    if a >= 1e15 || (a != 0.0 && a < 1e-6) {
        format!("{v:e}")
    } else {
        format!("{v}")
    }
}

/// `s` cut to `max` characters by an ellipsis in the middle: the ends of names ("... 12",
/// "... side B") are what tells them apart.
pub(super) fn truncate(s: &str, max: usize) -> String {
    let n = s.chars().count();
    if n <= max {
        return s.into();
    }
    let tail = (max - 1) / 2;
    let head = max - 1 - tail;
    let mut t: String = s.chars().take(head).collect();
    t.push('…');
    t.extend(s.chars().skip(n - tail));
    t
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn numbers_are_short_and_finite() {
        assert_eq!(num(f64::NAN), "0");
        assert_eq!(num(-0.001), "0");
        assert_eq!(num(12.5), "12.5");
        assert_eq!(value_label(12.0), "12");
        assert_eq!(value_label(0.125), "0.125");
        assert_eq!(value_label(2.5e12), "2.5e12");
        assert_eq!(value_label(-1.0e-9), "-1e-9");
        assert_eq!(value_label(1_000_000.0), "1e6");
        assert_eq!(exact(1e300), "1e300");
        assert_eq!(exact(0.1), "0.1");
        assert_eq!(truncate("series number 12", 9), "seri…r 12");
        assert_eq!(truncate("short", 9), "short");
    }
}
