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
//! The `plotters` crate (0.3.7, `svg_backend`) was weighed for issue 26 and measured short of
//! the guarantees below: its SVG backend draws only pixels, lines, rectangles, polylines,
//! polygons, circles, text and bitmaps at whole-pixel `(i32, i32)` coordinates, so it has no
//! `<title>` tooltips (bars, series, shortened legend names), no clip path (points outside a
//! fixed y range are cut by clipping segments, changing the point count), no groups or classes,
//! dashes only as separate line pieces (no `stroke-dasharray`), and text turned only by
//! multiples of 90° (bar labels here turn 35°).
//! Six of the ten chart tests in host/tests/cli/plot.rs assert on those; its build cost was not
//! the reason (4 s, three small crates).
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

mod axis;
mod bar;
mod frame;
mod line;
mod text;

pub use bar::bar_chart;
pub use line::{line_chart, line_chart_with};

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
