//! SVG charts for the simulator's plots, written by hand (no plotting dependency): a line
//! chart for the WiFi efficiency over time (Figure 11) and a bar chart for the bolting
//! attempts (Figure 10).
//!
//! ```
//! use mmic_host::plot::{bar_chart, line_chart, Series};
//! let svg = line_chart("efficiency", "t (s)", "%", Some((0.0, 100.0)),
//!     &[Series { name: "robot 1", points: &[(0.0, 100.0), (1.2, 50.0)] }]);
//! assert!(svg.starts_with("<svg") && svg.trim_end().ends_with("</svg>"));
//! let bars = bar_chart("attempts", "pairs", &[("1st", 9.0), ("failed", 1.0)]);
//! assert!(bars.contains(">9<") && bars.contains("failed"));
//! ```

use std::fmt::Write as _;

/// A named series of (x, y) points.
#[derive(Debug, Clone, Copy)]
pub struct Series<'a> {
    /// Legend text.
    pub name: &'a str,
    /// Points, in x order.
    pub points: &'a [(f64, f64)],
}

const W: f64 = 720.0;
const H: f64 = 400.0;
const LEFT: f64 = 70.0;
const RIGHT: f64 = 20.0;
const TOP: f64 = 40.0;
const BOTTOM: f64 = 50.0;
const COLOURS: [&str; 6] = [
    "#1f77b4", "#d62728", "#2ca02c", "#ff7f0e", "#9467bd", "#8c564b",
];

/// Escapes text for SVG.
pub fn escape(s: &str) -> String {
    s.replace('&', "&amp;")
        .replace('<', "&lt;")
        .replace('>', "&gt;")
        .replace('"', "&quot;")
}

fn finite(v: f64) -> f64 {
    if v.is_finite() {
        v
    } else {
        0.0
    }
}

/// Rounds a tick value for printing.
fn label(v: f64) -> String {
    let v = finite(v);
    if (v - v.round()).abs() < 1e-9 {
        format!("{}", v.round() as i64)
    } else {
        format!("{v:.1}")
    }
}

fn head(out: &mut String, title: &str) {
    let _ = write!(
        out,
        "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"{W}\" height=\"{H}\" viewBox=\"0 0 {W} {H}\" font-family=\"sans-serif\" font-size=\"12\">\n\
         <rect width=\"{W}\" height=\"{H}\" fill=\"white\"/>\n\
         <text x=\"{}\" y=\"22\" text-anchor=\"middle\" font-size=\"15\">{}</text>\n",
        W / 2.0,
        escape(title)
    );
}

fn axes(out: &mut String, x_label: &str, y_label: &str) {
    let (x0, y0, x1, y1) = (LEFT, H - BOTTOM, W - RIGHT, TOP);
    let _ = write!(
        out,
        "<g stroke=\"black\"><line x1=\"{x0}\" y1=\"{y0}\" x2=\"{x1}\" y2=\"{y0}\"/><line x1=\"{x0}\" y1=\"{y0}\" x2=\"{x0}\" y2=\"{y1}\"/></g>\n\
         <text x=\"{}\" y=\"{}\" text-anchor=\"middle\">{}</text>\n\
         <text x=\"16\" y=\"{}\" text-anchor=\"middle\" transform=\"rotate(-90 16 {})\">{}</text>\n",
        (x0 + x1) / 2.0,
        H - 12.0,
        escape(x_label),
        (y0 + y1) / 2.0,
        (y0 + y1) / 2.0,
        escape(y_label)
    );
}

/// A line chart; `y_range` fixes the y axis (else it fits the data). Empty series draw axes
/// only; a single point draws a dot.
pub fn line_chart(
    title: &str,
    x_label: &str,
    y_label: &str,
    y_range: Option<(f64, f64)>,
    series: &[Series<'_>],
) -> String {
    let pts = series.iter().flat_map(|s| s.points.iter().copied());
    let (mut xmin, mut xmax, mut ymin, mut ymax) = (f64::MAX, f64::MIN, f64::MAX, f64::MIN);
    for (x, y) in pts.filter(|(x, y)| x.is_finite() && y.is_finite()) {
        xmin = xmin.min(x);
        xmax = xmax.max(x);
        ymin = ymin.min(y);
        ymax = ymax.max(y);
    }
    if xmin > xmax {
        (xmin, xmax, ymin, ymax) = (0.0, 1.0, 0.0, 1.0);
    }
    if let Some((lo, hi)) = y_range {
        (ymin, ymax) = (lo, hi);
    }
    if xmax - xmin < 1e-9 {
        xmax = xmin + 1.0;
    }
    if ymax - ymin < 1e-9 {
        ymax = ymin + 1.0;
    }
    let sx = |x: f64| LEFT + (x - xmin) / (xmax - xmin) * (W - LEFT - RIGHT);
    let sy = |y: f64| H - BOTTOM - (y - ymin) / (ymax - ymin) * (H - TOP - BOTTOM);
    let mut out = String::new();
    head(&mut out, title);
    axes(&mut out, x_label, y_label);
    out.push_str("<g fill=\"#444\">\n");
    for i in 0..=5 {
        let f = i as f64 / 5.0;
        let (xv, yv) = (xmin + f * (xmax - xmin), ymin + f * (ymax - ymin));
        let _ = writeln!(
            out,
            "<text x=\"{:.1}\" y=\"{:.1}\" text-anchor=\"middle\">{}</text><text x=\"{:.1}\" y=\"{:.1}\" text-anchor=\"end\">{}</text>",
            sx(xv),
            H - BOTTOM + 16.0,
            label(xv),
            LEFT - 6.0,
            sy(yv) + 4.0,
            label(yv)
        );
    }
    out.push_str("</g>\n");
    for (k, s) in series.iter().enumerate() {
        let c = COLOURS[k % COLOURS.len()];
        let good: Vec<(f64, f64)> = s
            .points
            .iter()
            .copied()
            .filter(|(x, y)| x.is_finite() && y.is_finite())
            .collect();
        if good.len() == 1 {
            let _ = writeln!(
                out,
                "<circle cx=\"{:.1}\" cy=\"{:.1}\" r=\"3\" fill=\"{c}\"/>",
                sx(good[0].0),
                sy(good[0].1)
            );
        } else if !good.is_empty() {
            let pts: Vec<String> = good
                .iter()
                .map(|&(x, y)| format!("{:.1},{:.1}", sx(x), sy(y)))
                .collect();
            let _ = writeln!(
                out,
                "<polyline fill=\"none\" stroke=\"{c}\" stroke-width=\"1.5\" points=\"{}\"/>",
                pts.join(" ")
            );
        }
        if series.len() > 1 {
            let y = TOP + 14.0 * k as f64;
            let _ = writeln!(
                out,
                "<rect x=\"{:.1}\" y=\"{:.1}\" width=\"10\" height=\"10\" fill=\"{c}\"/><text x=\"{:.1}\" y=\"{:.1}\">{}</text>",
                W - RIGHT - 150.0,
                y,
                W - RIGHT - 135.0,
                y + 9.0,
                escape(s.name)
            );
        }
    }
    out.push_str("</svg>\n");
    out
}

/// A bar chart with the value printed on each bar.
pub fn bar_chart(title: &str, y_label: &str, bars: &[(&str, f64)]) -> String {
    let ymax = bars
        .iter()
        .map(|b| finite(b.1))
        .fold(0.0f64, f64::max)
        .max(1.0);
    let mut out = String::new();
    head(&mut out, title);
    axes(&mut out, "", y_label);
    let slot = (W - LEFT - RIGHT) / bars.len().max(1) as f64;
    for (i, (name, v)) in bars.iter().enumerate() {
        let v = finite(*v).max(0.0);
        let h = v / ymax * (H - TOP - BOTTOM - 20.0);
        let x = LEFT + slot * i as f64 + slot * 0.2;
        let y = H - BOTTOM - h;
        let _ = writeln!(
            out,
            "<rect x=\"{x:.1}\" y=\"{y:.1}\" width=\"{:.1}\" height=\"{h:.1}\" fill=\"{}\"/>\n<text x=\"{:.1}\" y=\"{:.1}\" text-anchor=\"middle\">{}</text>\n<text x=\"{:.1}\" y=\"{:.1}\" text-anchor=\"middle\">{}</text>",
            slot * 0.6,
            COLOURS[i % COLOURS.len()],
            x + slot * 0.3,
            y - 5.0,
            label(v),
            x + slot * 0.3,
            H - BOTTOM + 16.0,
            escape(name)
        );
    }
    out.push_str("</svg>\n");
    out
}
