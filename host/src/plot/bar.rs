//! Bar charts: one bar per category from zero, labelled with its value.

use super::axis::{bounds, clamp, Axis};
use super::frame::{frame_y, header, no_data};
use super::text::{exact, num, truncate, value_label};
use super::{escape, Area, AREA, CHAR_W, HEIGHT, PALETTE, ROTATE_DEG, SHORT, WIDTH};
use std::fmt::Write;

/// A bar chart: one bar per category from zero to its value (downwards when negative), each
/// with its value written at the bar's end and a tooltip with the full label.
///
/// The y axis always includes zero, so bar lengths compare. A non-finite value gets no bar and
/// the label `n/a`. Labels too wide to sit side by side are rotated and shortened.
pub fn bar_chart(title: &str, y_label: &str, bars: &[(&str, f64)]) -> String {
    let rotate = rotates(bars);
    let area = if rotate { rotated_area(bars) } else { AREA };
    let ya = Axis::auto(value_range(bars), area.y1, area.y0);
    let slot = (area.x1 - area.x0) / bars.len().max(1) as f64;
    let layout = Layout {
        area,
        slot,
        bar_w: slot * 0.7,
        zero: ya.pos(0.0),
        ya,
        rotate,
    };
    let mut s = header(title, area);
    frame_y(&mut s, area, &layout.ya, y_label);
    // The x axis: a line at zero, no ticks (categories are labelled under their bars).
    let _ = writeln!(
        s,
        r#"<line x1="{}" y1="{z}" x2="{}" y2="{z}" stroke="black"/>"#,
        num(area.x0),
        num(area.x1),
        z = num(layout.zero)
    );
    let _ = writeln!(s, r##"<g fill="{}">"##, PALETTE[0]);
    for (i, &(label, v)) in bars.iter().enumerate() {
        let cx = area.x0 + slot * (i as f64 + 0.5);
        if v.is_finite() {
            bar(&mut s, &layout, cx, label, v);
        }
        value_text(&mut s, &layout, cx, v);
        category_label(&mut s, &layout, cx, label);
    }
    let _ = writeln!(s, "</g>");
    if bars.is_empty() {
        no_data(&mut s, area);
    }
    s.push_str("</svg>\n");
    s
}

/// Where a bar chart's parts go.
struct Layout {
    /// The plot area.
    area: Area,
    /// Each category's width.
    slot: f64,
    /// A bar's width (narrower than its slot).
    bar_w: f64,
    /// The y axis.
    ya: Axis,
    /// Where zero is on it.
    zero: f64,
    /// Whether category labels are rotated (and shortened).
    rotate: bool,
}

/// The y range: the values' and zero, with headroom for the value labels at the bars' ends
/// (0..1 when every value is zero or none is finite).
fn value_range(bars: &[(&str, f64)]) -> (f64, f64) {
    let values = bars
        .iter()
        .map(|b| b.1)
        .filter(|v| v.is_finite())
        .map(clamp);
    let (lo, hi) = bounds(values).unwrap_or((0.0, 0.0));
    let (lo, hi) = (lo.min(0.0), hi.max(0.0));
    let pad = (hi - lo) * 0.06;
    match (lo < 0.0, hi > 0.0) {
        (false, false) => (0.0, 1.0),
        (neg, pos) => (
            if neg { lo - pad } else { lo },
            if pos { hi + pad } else { hi },
        ),
    }
}

/// Whether the category labels must be rotated: more than eight, or one wider than its slot.
fn rotates(bars: &[(&str, f64)]) -> bool {
    let n = bars.len().max(1) as f64;
    bars.len() > 8
        || bars
            .iter()
            .any(|b| b.0.chars().count() as f64 * CHAR_W > (AREA.x1 - AREA.x0) / n * 0.95)
}

/// The plot area with rotated labels: raised for the labels' height, and moved right until
/// the first label, which reaches `longest * cos` left of its bar's centre, starts inside the
/// chart: x0 + (x1 - x0) / 2n >= reach.
fn rotated_area(bars: &[(&str, f64)]) -> Area {
    let n = bars.len().max(1) as f64;
    let longest = bars
        .iter()
        .map(|b| b.0.chars().count().min(SHORT))
        .max()
        .unwrap_or(0) as f64
        * CHAR_W;
    let (sin, cos) = ROTATE_DEG.to_radians().sin_cos();
    let reach = longest * cos + 4.0;
    let half = 1.0 / (2.0 * n);
    Area {
        x0: ((reach - AREA.x1 * half) / (1.0 - half)).clamp(AREA.x0, WIDTH / 3.0),
        y1: HEIGHT - 28.0 - (longest * sin).min(HEIGHT / 3.0),
        ..AREA
    }
}

/// The bar of finite value `v` centred on `cx`, from zero, with its label and exact value as
/// tooltip.
fn bar(s: &mut String, l: &Layout, cx: f64, label: &str, v: f64) {
    let top = l.ya.pos(clamp(v));
    let (y, h) = if top < l.zero {
        (top, l.zero - top)
    } else {
        (l.zero, top - l.zero)
    };
    let _ = writeln!(
        s,
        r#"<rect x="{}" y="{}" width="{}" height="{}"><title>{}: {}</title></rect>"#,
        num(cx - l.bar_w / 2.0),
        num(y),
        num(l.bar_w),
        num(h),
        escape(label),
        exact(v)
    );
}

/// The value written at the bar's end (above, below a negative bar; `n/a` at zero for a
/// non-finite value), shrunk when wider than its slot.
fn value_text(s: &mut String, l: &Layout, cx: f64, v: f64) {
    let text = value_label(v);
    let ly = match v {
        v if !v.is_finite() => l.zero - 4.0,
        v if v < 0.0 => l.ya.pos(clamp(v)) + 14.0,
        v => l.ya.pos(clamp(v)) - 4.0,
    };
    let fit = 12.0 * l.slot * 0.98 / (text.chars().count() as f64 * CHAR_W);
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
}

/// The category's label under its bar: as it is, or rotated and shortened.
fn category_label(s: &mut String, l: &Layout, cx: f64, label: &str) {
    let ly = l.area.y1 + 16.0;
    if l.rotate {
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
