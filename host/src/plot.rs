//! Line and bar charts as standalone SVG text, written by hand so that host tools can draw
//! telemetry and benchmark results without a plotting dependency.
//!
//! ```
//! use mmic_host::plot::{bar_chart, line_chart, Series};
//!
//! let hip = [(0.0, 0.0), (1.0, 10.0), (2.0, 20.0), (3.0, 28.5)];
//! let target = [(0.0, 30.0), (3.0, 30.0)];
//! let svg = line_chart(
//!     "Hip angle <run 1>",
//!     "time (s)",
//!     "angle (°)",
//!     Some((0.0, 40.0)),
//!     &[Series { name: "measured", points: &hip }, Series { name: "target", points: &target }],
//! );
//! assert!(svg.starts_with("<svg") && svg.trim_end().ends_with("</svg>"));
//! assert!(svg.contains("Hip angle &lt;run 1&gt;")); // text is XML-escaped
//!
//! let bars = bar_chart("Commands per mode", "count", &[("standby", 3.0), ("operational", 12.0)]);
//! assert!(bars.contains(">12<")); // each bar carries its value label
//! ```
//!
//! # Why by hand
//!
//! The charts are small (one plot area, a few series) and their output is reviewed, committed
//! and diffed, so a few hundred lines of deterministic string building beat a dependency tree:
//! the same input always gives the same bytes, and the file opens in any browser.
//!
//! # What the output guarantees
//!
//! * 720 × 400 user units, white background, a `<title>` element with the chart's title.
//! * About five ticks per axis at "nice" values (1, 2 or 5 × 10ⁿ), each with a label.
//! * Every text escaped (`&`, `<`, `>`, `"`, `'`), so titles and names may hold anything.
//! * No `NaN` or `inf` anywhere: empty input draws the axes and "no data"; a single point, or
//!   points that all share a value, get a widened range; non-finite input points are gaps.
//! * One `<polyline>` per run of finite points, with exactly those points, so a series without
//!   gaps has one polyline with as many points as its input. Isolated points also get a dot.
//! * A legend right of the plot area (never over the data) when there is more than one
//!   series; ten distinct colours, then the same colours dashed.
//! * Bar labels that do not fit side by side are rotated and shortened; every bar has a
//!   tooltip with its full label and value.

use std::fmt::Write;

/// Width of every chart, user units (pixels at 100 %).
pub const WIDTH: f64 = 720.0;
/// Height of every chart.
pub const HEIGHT: f64 = 400.0;

/// Series colours, in order (the "category10" palette: distinct, and readable when printed).
pub const PALETTE: [&str; 10] = [
    "#1f77b4", "#ff7f0e", "#2ca02c", "#d62728", "#9467bd", "#8c564b", "#e377c2", "#7f7f7f",
    "#bcbd22", "#17becf",
];
/// Dash patterns for series 10–19, 20–29, ...: once the colours repeat, the dashes differ.
const DASHES: [&str; 4] = ["", "6 3", "2 3", "8 3 2 3"];

/// Roughly how many ticks an axis gets.
const TICKS: f64 = 5.0;
/// Input values are clamped to ±this, so that spans and scales stay finite.
const LIMIT: f64 = 1e300;
/// Mapped coordinates are clamped to ±this: far outside the 720 × 400 view, and finite.
const FAR: f64 = 1e6;
/// Approximate width of a 12-unit sans-serif character, for sizing legends and labels.
const CHAR_W: f64 = 7.5;
/// Legend names and rotated bar labels are cut to this many characters (the full text stays
/// in a tooltip).
const SHORT: usize = 24;
/// Bar labels are rotated by this many degrees when they do not fit side by side.
const ROTATE_DEG: f64 = 35.0;

/// The plot area inside the chart: left, right, top and bottom edges.
#[derive(Debug, Clone, Copy)]
struct Area {
    x0: f64,
    x1: f64,
    y0: f64,
    y1: f64,
}

/// Room for the title above, tick labels and axis labels left and below.
const AREA: Area = Area {
    x0: 72.0,
    x1: WIDTH - 24.0,
    y0: 44.0,
    y1: HEIGHT - 56.0,
};

/// One named line of a [`line_chart`].
#[derive(Debug, Clone, Copy)]
pub struct Series<'a> {
    /// Legend name.
    pub name: &'a str,
    /// (x, y) points, drawn in the given order. Non-finite points break the line.
    pub points: &'a [(f64, f64)],
}

/// `s` with `& < > " '` replaced by entities, safe in both text and attribute values.
pub fn escape(s: &str) -> String {
    let mut out = String::with_capacity(s.len());
    for c in s.chars() {
        match c {
            '&' => out.push_str("&amp;"),
            '<' => out.push_str("&lt;"),
            '>' => out.push_str("&gt;"),
            '"' => out.push_str("&quot;"),
            '\'' => out.push_str("&apos;"),
            // Control characters other than tab and newlines are not allowed in XML 1.0.
            c if c.is_control() && !matches!(c, '\t' | '\n' | '\r') => out.push('\u{fffd}'),
            c => out.push(c),
        }
    }
    out
}

/// A line chart of `series`, with axis labels, ticks and, for more than one series, a legend
/// to the right of the plot area (so that it never hides data).
///
/// The x range always comes from the data. The y range is `y_range` when both ends are finite
/// (swapped if reversed, widened if equal; points outside are clipped), otherwise from the data.
pub fn line_chart(
    title: &str,
    x_label: &str,
    y_label: &str,
    y_range: Option<(f64, f64)>,
    series: &[Series],
) -> String {
    line_chart_with(
        title,
        x_label,
        y_label,
        LineOptions {
            y_range,
            ..LineOptions::default()
        },
        series,
    )
}

/// How [`line_chart_with`] lays out its axes and legend.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct LineOptions {
    /// The y range when both ends are finite (as in [`line_chart`]); otherwise from the data.
    /// Give headroom above a bound the data can reach (a 100 % line drawn on the top border
    /// merges with it and is half clipped).
    pub y_range: Option<(f64, f64)>,
    /// End the x axis exactly at the data's first and last x (ticks inside) instead of rounding
    /// outwards to whole ticks: for time series, whose axis should stop where the run did.
    pub x_at_data: bool,
    /// Draw the legend even for a single series (it then names what the line is).
    pub legend: bool,
}

/// [`line_chart`] with [`LineOptions`].
pub fn line_chart_with(
    title: &str,
    x_label: &str,
    y_label: &str,
    opts: LineOptions,
    series: &[Series],
) -> String {
    let y_range = opts.y_range;
    let finite = || {
        series
            .iter()
            .flat_map(|s| s.points.iter())
            .filter(|(x, y)| x.is_finite() && y.is_finite())
            .map(|&(x, y)| (clamp(x), clamp(y)))
    };
    let xs = bounds(finite().map(|p| p.0));
    let ys = bounds(finite().map(|p| p.1));
    let legend_w = if series.len() > 1 || (opts.legend && !series.is_empty()) {
        let longest = series
            .iter()
            .map(|s| s.name.chars().count().min(SHORT))
            .max()
            .unwrap_or(0);
        36.0 + longest as f64 * CHAR_W
    } else {
        0.0
    };
    let area = Area {
        x1: if legend_w > 0.0 {
            WIDTH - 12.0 - legend_w - 12.0
        } else {
            AREA.x1
        },
        ..AREA
    };
    let xa = match (opts.x_at_data, xs) {
        (true, Some((lo, hi))) => Axis::fixed(lo, hi, area.x0, area.x1),
        _ => Axis::auto(xs.unwrap_or((0.0, 1.0)), area.x0, area.x1),
    };
    let ya = match y_range {
        Some((a, b)) if a.is_finite() && b.is_finite() => {
            Axis::fixed(clamp(a.min(b)), clamp(a.max(b)), area.y1, area.y0)
        }
        _ => Axis::auto(ys.unwrap_or((0.0, 1.0)), area.y1, area.y0),
    };

    let mut s = header(title, area);
    frame_y(&mut s, area, &ya, y_label);
    frame_x(&mut s, area, &xa, x_label);
    let _ = writeln!(
        s,
        r#"<g clip-path="url(#plot-area)" fill="none" stroke-width="2">"#
    );
    for (i, ser) in series.iter().enumerate() {
        let (colour, dash) = style(i);
        let _ = writeln!(
            s,
            r#"<g stroke="{colour}"{dash}><title>{}</title>"#,
            escape(ser.name)
        );
        for run in ser.points.split(|(x, y)| !(x.is_finite() && y.is_finite())) {
            if run.is_empty() {
                continue;
            }
            let pts: Vec<String> = run
                .iter()
                .map(|&(x, y)| format!("{},{}", num(xa.pos(x)), num(ya.pos(y))))
                .collect();
            let _ = writeln!(s, r#"<polyline points="{}"/>"#, pts.join(" "));
            if let [(x, y)] = run {
                let _ = writeln!(
                    s,
                    r#"<circle cx="{}" cy="{}" r="3" fill="{colour}" stroke="none"/>"#,
                    num(xa.pos(*x)),
                    num(ya.pos(*y))
                );
            }
        }
        let _ = writeln!(s, "</g>");
    }
    let _ = writeln!(s, "</g>");
    if xs.is_none() {
        no_data(&mut s, area);
    }
    if legend_w > 0.0 {
        legend(&mut s, series, area.x1 + 12.0, area.y0, legend_w);
    }
    s.push_str("</svg>\n");
    s
}

/// A bar chart: one bar per category from zero to its value (downwards when negative), each
/// with its value written at the bar's end and a tooltip with the full label.
///
/// The y axis always includes zero, so bar lengths compare. A non-finite value gets no bar and
/// the label `n/a`. Labels too wide to sit side by side are rotated and shortened.
pub fn bar_chart(title: &str, y_label: &str, bars: &[(&str, f64)]) -> String {
    let values = || {
        bars.iter()
            .map(|b| b.1)
            .filter(|v| v.is_finite())
            .map(clamp)
    };
    let (lo, hi) = bounds(values()).unwrap_or((0.0, 0.0));
    let (lo, hi) = (lo.min(0.0), hi.max(0.0));
    // Headroom for the value labels at the bars' ends.
    let pad = (hi - lo) * 0.06;
    let range = match (lo < 0.0, hi > 0.0) {
        (false, false) => (0.0, 1.0),
        (neg, pos) => (
            if neg { lo - pad } else { lo },
            if pos { hi + pad } else { hi },
        ),
    };
    let n = bars.len().max(1) as f64;
    let rotate = bars.len() > 8
        || bars
            .iter()
            .any(|b| b.0.chars().count() as f64 * CHAR_W > (AREA.x1 - AREA.x0) / n * 0.95);
    let area = if rotate {
        let longest = bars
            .iter()
            .map(|b| b.0.chars().count().min(SHORT))
            .max()
            .unwrap_or(0) as f64
            * CHAR_W;
        let (sin, cos) = ROTATE_DEG.to_radians().sin_cos();
        // Move the plot right until the first label, which reaches `longest * cos` left of
        // its bar's centre, starts inside the chart: x0 + (x1 - x0) / 2n >= reach.
        let reach = longest * cos + 4.0;
        let half = 1.0 / (2.0 * n);
        Area {
            x0: ((reach - AREA.x1 * half) / (1.0 - half)).clamp(AREA.x0, WIDTH / 3.0),
            y1: HEIGHT - 28.0 - (longest * sin).min(HEIGHT / 3.0),
            ..AREA
        }
    } else {
        AREA
    };
    let slot = (area.x1 - area.x0) / n;
    let ya = Axis::auto(range, area.y1, area.y0);
    let bar_w = slot * 0.7;

    let mut s = header(title, area);
    frame_y(&mut s, area, &ya, y_label);
    // The x axis: a line at zero, no ticks (categories are labelled under their bars).
    let zero = ya.pos(0.0);
    let _ = writeln!(
        s,
        r#"<line x1="{}" y1="{z}" x2="{}" y2="{z}" stroke="black"/>"#,
        num(area.x0),
        num(area.x1),
        z = num(zero)
    );
    let _ = writeln!(s, r##"<g fill="{}">"##, PALETTE[0]);
    for (i, &(label, v)) in bars.iter().enumerate() {
        let cx = area.x0 + slot * (i as f64 + 0.5);
        let text = value_label(v);
        if v.is_finite() {
            let top = ya.pos(clamp(v));
            let (y, h) = if top < zero {
                (top, zero - top)
            } else {
                (zero, top - zero)
            };
            let _ = writeln!(
                s,
                r#"<rect x="{}" y="{}" width="{}" height="{}"><title>{}: {}</title></rect>"#,
                num(cx - bar_w / 2.0),
                num(y),
                num(bar_w),
                num(h),
                escape(label),
                exact(v)
            );
        }
        let ly = match v {
            v if !v.is_finite() => zero - 4.0,
            v if v < 0.0 => ya.pos(clamp(v)) + 14.0,
            v => ya.pos(clamp(v)) - 4.0,
        };
        // Shrink a value label that is wider than its slot.
        let fit = 12.0 * slot * 0.98 / (text.chars().count() as f64 * CHAR_W);
        let size = if fit < 12.0 {
            format!(r#" font-size="{}""#, num(fit.max(6.0)))
        } else {
            String::new()
        };
        let _ = writeln!(
            s,
            r#"<text x="{}" y="{}" text-anchor="middle" fill="black"{size}>{}</text>"#,
            num(cx),
            num(ly),
            escape(&text)
        );
        let ly = area.y1 + 16.0;
        if rotate {
            let _ = writeln!(
                s,
                r#"<text x="{x}" y="{y}" text-anchor="end" fill="black" transform="rotate(-{ROTATE_DEG} {x} {y})">{}</text>"#,
                escape(&truncate(label, SHORT)),
                x = num(cx),
                y = num(ly)
            );
        } else {
            let _ = writeln!(
                s,
                r#"<text x="{}" y="{}" text-anchor="middle" fill="black">{}</text>"#,
                num(cx),
                num(ly),
                escape(label)
            );
        }
    }
    let _ = writeln!(s, "</g>");
    if bars.is_empty() {
        no_data(&mut s, area);
    }
    s.push_str("</svg>\n");
    s
}

/// An axis: its range, tick values, and the positions its ends map to.
struct Axis {
    lo: f64,
    hi: f64,
    step: f64,
    ticks: Vec<f64>,
    /// Position of `lo`.
    p0: f64,
    /// Position of `hi`.
    p1: f64,
}

impl Axis {
    /// Range covering `lo..=hi`, extended to whole ticks.
    fn auto((lo, hi): (f64, f64), p0: f64, p1: f64) -> Axis {
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
    fn fixed(lo: f64, hi: f64, p0: f64, p1: f64) -> Axis {
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
    fn pos(&self, v: f64) -> f64 {
        let frac = (clamp(v) - self.lo) / (self.hi - self.lo);
        (self.p0 + frac * (self.p1 - self.p0)).clamp(-FAR, FAR)
    }

    /// Tick labels: fixed-point with as many decimals as the step needs, or scientific for
    /// very large or very fine axes.
    fn label(&self, v: f64) -> String {
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
fn widen(lo: f64, hi: f64) -> (f64, f64) {
    let big = lo.abs().max(hi.abs());
    if hi - lo > big * 1e-12 && hi - lo > 1e-200 {
        (lo, hi)
    } else {
        let pad = if big > 1e-200 { big * 0.1 } else { 1.0 };
        (lo - pad, hi + pad)
    }
}

/// 1, 2 or 5 × 10ⁿ, giving about [`TICKS`] intervals over `span`.
fn nice_step(span: f64) -> f64 {
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

fn clamp(v: f64) -> f64 {
    v.clamp(-LIMIT, LIMIT)
}

fn bounds(values: impl Iterator<Item = f64>) -> Option<(f64, f64)> {
    values.fold(None, |acc, v| match acc {
        None => Some((v, v)),
        Some((lo, hi)) => Some((lo.min(v), hi.max(v))),
    })
}

/// Colour and dash attribute of series `i`.
fn style(i: usize) -> (&'static str, String) {
    let colour = PALETTE[i % PALETTE.len()];
    let dash = DASHES[(i / PALETTE.len()) % DASHES.len()];
    let dash = if dash.is_empty() {
        String::new()
    } else {
        format!(r#" stroke-dasharray="{dash}""#)
    };
    (colour, dash)
}

/// A coordinate: two decimals, never `NaN` or `inf`, no `-0`.
fn num(v: f64) -> String {
    let v = if v.is_finite() { v } else { 0.0 };
    let s = format!("{v:.2}");
    let s = s.trim_end_matches('0').trim_end_matches('.');
    match s {
        "-0" | "" => "0".into(),
        s => s.into(),
    }
}

/// A bar's value: integers as such, others with up to 3 decimals, extremes in scientific form.
fn value_label(v: f64) -> String {
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
fn exact(v: f64) -> String {
    let a = v.abs();
    if a >= 1e15 || (a != 0.0 && a < 1e-6) {
        format!("{v:e}")
    } else {
        format!("{v}")
    }
}

/// `s` cut to `max` characters by an ellipsis in the middle: the ends of names ("... 12",
/// "... side B") are what tells them apart.
fn truncate(s: &str, max: usize) -> String {
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

fn header(title: &str, area: Area) -> String {
    let mut s = String::new();
    let _ = writeln!(
        s,
        r#"<svg xmlns="http://www.w3.org/2000/svg" width="{WIDTH}" height="{HEIGHT}" viewBox="0 0 {WIDTH} {HEIGHT}" font-family="sans-serif" font-size="12">"#
    );
    let t = escape(title);
    let _ = writeln!(s, "<title>{t}</title>");
    let _ = writeln!(
        s,
        r#"<rect x="0" y="0" width="{WIDTH}" height="{HEIGHT}" fill="white"/>"#
    );
    let _ = writeln!(
        s,
        r#"<text x="{}" y="26" text-anchor="middle" font-size="16" font-weight="bold">{t}</text>"#,
        WIDTH / 2.0
    );
    let _ = writeln!(
        s,
        r#"<defs><clipPath id="plot-area"><rect x="{}" y="{}" width="{}" height="{}"/></clipPath></defs>"#,
        num(area.x0),
        num(area.y0),
        num(area.x1 - area.x0),
        num(area.y1 - area.y0)
    );
    s
}

/// The x axis of a line chart: grid lines, ticks, tick labels and the axis label.
fn frame_x(s: &mut String, area: Area, xa: &Axis, x_label: &str) {
    let (y0, y1) = (num(area.y0), num(area.y1));
    let _ = writeln!(s, r#"<g class="x-axis" text-anchor="middle">"#);
    for &t in &xa.ticks {
        let x = num(xa.pos(t));
        let _ = writeln!(
            s,
            r##"<line x1="{x}" y1="{y0}" x2="{x}" y2="{y1}" stroke="#e0e0e0"/><line x1="{x}" y1="{y1}" x2="{x}" y2="{}" stroke="black"/><text x="{x}" y="{}">{}</text>"##,
            num(area.y1 + 5.0),
            num(area.y1 + 18.0),
            escape(&xa.label(t))
        );
    }
    let _ = writeln!(
        s,
        r#"<line x1="{}" y1="{y1}" x2="{}" y2="{y1}" stroke="black"/>"#,
        num(area.x0),
        num(area.x1)
    );
    let _ = writeln!(
        s,
        r#"<text x="{}" y="{}">{}</text>"#,
        num((area.x0 + area.x1) / 2.0),
        num(HEIGHT - 14.0),
        escape(x_label)
    );
    let _ = writeln!(s, "</g>");
}

/// The y axis: grid lines, ticks, tick labels and the rotated axis label.
fn frame_y(s: &mut String, area: Area, ya: &Axis, y_label: &str) {
    let (x0, x1) = (num(area.x0), num(area.x1));
    let _ = writeln!(s, r#"<g class="y-axis" text-anchor="end">"#);
    for &t in &ya.ticks {
        let y = num(ya.pos(t));
        let _ = writeln!(
            s,
            r##"<line x1="{x0}" y1="{y}" x2="{x1}" y2="{y}" stroke="#e0e0e0"/><line x1="{}" y1="{y}" x2="{x0}" y2="{y}" stroke="black"/><text x="{}" y="{y}" dy="4">{}</text>"##,
            num(area.x0 - 5.0),
            num(area.x0 - 8.0),
            escape(&ya.label(t))
        );
    }
    let _ = writeln!(
        s,
        r#"<line x1="{x0}" y1="{}" x2="{x0}" y2="{}" stroke="black"/>"#,
        num(area.y0),
        num(area.y1)
    );
    let (x, y) = (18.0, num((area.y0 + area.y1) / 2.0));
    let _ = writeln!(
        s,
        r#"<text x="{x}" y="{y}" text-anchor="middle" transform="rotate(-90 {x} {y})">{}</text>"#,
        escape(y_label)
    );
    let _ = writeln!(s, "</g>");
}

fn no_data(s: &mut String, area: Area) {
    let _ = writeln!(
        s,
        r##"<text x="{}" y="{}" text-anchor="middle" fill="#7f7f7f" font-size="16">no data</text>"##,
        num((area.x0 + area.x1) / 2.0),
        num((area.y0 + area.y1) / 2.0)
    );
}

/// A boxed legend of width `w` at (`x`, `y`); entries shrink to fit the chart's height.
fn legend(s: &mut String, series: &[Series], x: f64, y: f64, w: f64) {
    let n = series.len() as f64;
    let row = ((HEIGHT - y - 16.0) / n).min(18.0);
    let font = (row - 2.0).clamp(4.0, 12.0);
    let _ = writeln!(s, r#"<g class="legend" font-size="{}">"#, num(font));
    let _ = writeln!(
        s,
        r##"<rect x="{}" y="{}" width="{}" height="{}" fill="white" stroke="#bbbbbb"/>"##,
        num(x),
        num(y),
        num(w),
        num(8.0 + row * n)
    );
    for (i, ser) in series.iter().enumerate() {
        let (colour, dash) = style(i);
        let short = truncate(ser.name, SHORT);
        // A shortened name keeps its full text as a tooltip.
        let full = if short == ser.name {
            String::new()
        } else {
            format!("<title>{}</title>", escape(ser.name))
        };
        let ly = y + 4.0 + row * (i as f64 + 0.5);
        let _ = writeln!(
            s,
            r#"<line x1="{}" y1="{ly}" x2="{}" y2="{ly}" stroke="{colour}" stroke-width="2"{dash}/><text x="{}" y="{}">{}{}</text>"#,
            num(x + 6.0),
            num(x + 26.0),
            num(x + 32.0),
            num(ly + font / 3.0),
            escape(&short),
            full,
            ly = num(ly)
        );
    }
    let _ = writeln!(s, "</g>");
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
