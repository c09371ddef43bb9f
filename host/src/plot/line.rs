//! Line charts: one polyline per run of finite points of each series.

use super::axis::{bounds, clamp, Axis};
use super::frame::{frame_x, frame_y, header, legend, no_data, style};
use super::text::num;
use super::{escape, Area, LineOptions, Series, AREA, CHAR_W, SHORT, WIDTH};
use std::fmt::Write;

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

/// [`line_chart`] with [`LineOptions`].
pub fn line_chart_with(
    title: &str,
    x_label: &str,
    y_label: &str,
    opts: LineOptions,
    series: &[Series],
) -> String {
    let finite = || {
        series
            .iter()
            .flat_map(|s| s.points.iter())
            .filter(|(x, y)| x.is_finite() && y.is_finite())
            .map(|&(x, y)| (clamp(x), clamp(y)))
    };
    let xs = bounds(finite().map(|p| p.0));
    let ys = bounds(finite().map(|p| p.1));
    let legend_w = legend_width(series, opts.legend);
    let area = Area {
        x1: if legend_w > 0.0 {
            WIDTH - 12.0 - legend_w - 12.0
        } else {
            AREA.x1
        },
        ..AREA
    };
    let (xa, ya) = axes(area, opts, xs, ys);
    let mut s = header(title, area);
    frame_y(&mut s, area, &ya, y_label);
    frame_x(&mut s, area, &xa, x_label);
    let _ = writeln!(
        s,
        r#"<g clip-path="url(#plot-area)" fill="none" stroke-width="2">"#
    );
    for (i, ser) in series.iter().enumerate() {
        series_lines(&mut s, i, ser, &xa, &ya);
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

/// The legend's width (0: none): for more than one series, or for one if `wanted`; wide
/// enough for the longest (shortened) name.
fn legend_width(series: &[Series], wanted: bool) -> f64 {
    if series.len() > 1 || (wanted && !series.is_empty()) {
        let longest = series
            .iter()
            .map(|s| s.name.chars().count().min(SHORT))
            .max()
            .unwrap_or(0);
        36.0 + longest as f64 * CHAR_W
    } else {
        0.0
    }
}

/// The x and y axes over `area`, from the data's bounds `xs` and `ys` (`None`: no finite
/// point) and the options: x ending at the data or at whole ticks, y fixed when given.
fn axes(
    area: Area,
    opts: LineOptions,
    xs: Option<(f64, f64)>,
    ys: Option<(f64, f64)>,
) -> (Axis, Axis) {
    let xa = match (opts.x_at_data, xs) {
        (true, Some((lo, hi))) => Axis::fixed(lo, hi, area.x0, area.x1),
        _ => Axis::auto(xs.unwrap_or((0.0, 1.0)), area.x0, area.x1),
    };
    let ya = match opts.y_range {
        Some((a, b)) if a.is_finite() && b.is_finite() => {
            Axis::fixed(clamp(a.min(b)), clamp(a.max(b)), area.y1, area.y0)
        }
        _ => Axis::auto(ys.unwrap_or((0.0, 1.0)), area.y1, area.y0),
    };
    (xa, ya)
}

/// Series `i`: a group in its style with its name as tooltip, one polyline per run of finite
/// points, and a dot for a run of one point (a polyline of one point draws nothing).
fn series_lines(s: &mut String, i: usize, ser: &Series, xa: &Axis, ya: &Axis) {
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
