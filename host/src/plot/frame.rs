//! The parts every chart shares: the SVG header and title, the axes' frames, the legend and
//! the series' styles.

use super::axis::Axis;
use super::text::{num, truncate};
use super::{escape, Area, Series, DASHES, HEIGHT, PALETTE, SHORT, WIDTH};
use std::fmt::Write;

/// Colour and dash attribute of series `i`.
pub(super) fn style(i: usize) -> (&'static str, String) {
    let colour = PALETTE[i % PALETTE.len()];
    let dash = DASHES[(i / PALETTE.len()) % DASHES.len()];
    let dash = if dash.is_empty() {
        String::new()
    } else {
        format!(r#" stroke-dasharray="{dash}""#)
    };
    (colour, dash)
}

/// The `<svg>` element's start, the title, the background and the plot area's clip path.
pub(super) fn header(title: &str, area: Area) -> String {
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
pub(super) fn frame_x(s: &mut String, area: Area, xa: &Axis, x_label: &str) {
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
pub(super) fn frame_y(s: &mut String, area: Area, ya: &Axis, y_label: &str) {
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

/// "no data" in the middle of the plot area.
pub(super) fn no_data(s: &mut String, area: Area) {
    let _ = writeln!(
        s,
        r##"<text x="{}" y="{}" text-anchor="middle" fill="#7f7f7f" font-size="16">no data</text>"##,
        num((area.x0 + area.x1) / 2.0),
        num((area.y0 + area.y1) / 2.0)
    );
}

/// A boxed legend of width `w` at (`x`, `y`); entries shrink to fit the chart's height.
pub(super) fn legend(s: &mut String, series: &[Series], x: f64, y: f64, w: f64) {
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
