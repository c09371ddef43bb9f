//! SVG charts: well-formed XML, escaped text, finite numbers, and lines that carry exactly
//! their input points, whatever the input.

use mmic_host::plot::{bar_chart, line_chart, line_chart_with, LineOptions, Series, PALETTE};

/// A tiny XML well-formedness check, enough for what the charts write: one root element, tags
/// balanced and properly nested, attributes `name="value"` without duplicates, no raw `<` in
/// attribute values, and every `&` starting a known entity. Returns the root's tag name.
fn check_xml(doc: &str) -> String {
    fn check_entities(s: &str, ctx: &str) {
        let mut rest = s;
        while let Some(i) = rest.find('&') {
            rest = &rest[i..];
            let end = rest
                .find(';')
                .unwrap_or_else(|| panic!("bare & in {ctx}: {s:?}"));
            let ent = &rest[1..end];
            let ok = matches!(ent, "amp" | "lt" | "gt" | "quot" | "apos")
                || ent
                    .strip_prefix('#')
                    .is_some_and(|n| !n.is_empty() && n.bytes().all(|b| b.is_ascii_digit()));
            assert!(ok, "unknown entity &{ent}; in {ctx}");
            rest = &rest[end..];
        }
    }
    fn check_attrs(mut a: &str, tag: &str) {
        let mut seen = Vec::new();
        loop {
            a = a.trim_start();
            if a.is_empty() {
                return;
            }
            let eq = a
                .find('=')
                .unwrap_or_else(|| panic!("attribute without = in <{tag}>"));
            let name = a[..eq].trim();
            assert!(
                !name.is_empty() && !name.contains(char::is_whitespace),
                "bad attribute name {name:?} in <{tag}>"
            );
            assert!(!seen.contains(&name), "duplicate {name} in <{tag}>");
            seen.push(name);
            let rest = a[eq + 1..].trim_start();
            let q = rest.chars().next().expect("attribute value");
            assert!(q == '"' || q == '\'', "unquoted {name} in <{tag}>");
            let close = rest[1..]
                .find(q)
                .unwrap_or_else(|| panic!("unclosed {name}"))
                + 1;
            let value = &rest[1..close];
            assert!(!value.contains('<'), "raw < in {name} of <{tag}>");
            check_entities(value, name);
            a = &rest[close + 1..];
        }
    }
    let mut stack: Vec<String> = Vec::new();
    let mut root: Option<String> = None;
    let mut rest = doc;
    while let Some(i) = rest.find('<') {
        let text = &rest[..i];
        if stack.is_empty() {
            assert!(text.trim().is_empty(), "text outside the root: {text:?}");
        }
        check_entities(text, "text");
        rest = &rest[i..];
        let (tag, after) = if let Some(r) = rest.strip_prefix("<!--") {
            let end = r.find("-->").expect("closed comment");
            rest = &r[end + 3..];
            continue;
        } else {
            let end = rest.find('>').expect("closed tag");
            (&rest[1..end], &rest[end + 1..])
        };
        rest = after;
        if let Some(name) = tag.strip_prefix('/') {
            let open = stack
                .pop()
                .unwrap_or_else(|| panic!("</{name}> closes nothing"));
            assert_eq!(open, name.trim(), "mis-nested tags");
            continue;
        }
        let (body, self_closing) = match tag.strip_suffix('/') {
            Some(b) => (b, true),
            None => (tag, false),
        };
        let name_end = body.find(char::is_whitespace).unwrap_or(body.len());
        let name = &body[..name_end];
        assert!(
            !name.is_empty()
                && name
                    .chars()
                    .all(|c| c.is_alphanumeric() || c == '-' || c == ':'),
            "bad tag name {name:?}"
        );
        check_attrs(&body[name_end..], name);
        if stack.is_empty() {
            assert!(root.is_none(), "second root element <{name}>");
            root = Some(name.to_string());
        }
        if !self_closing {
            stack.push(name.to_string());
        }
    }
    assert!(rest.trim().is_empty(), "text after the root: {rest:?}");
    assert!(stack.is_empty(), "unclosed: {stack:?}");
    root.expect("a root element")
}

/// Everything a chart must satisfy whatever its input.
fn check_chart(svg: &str) {
    assert_eq!(check_xml(svg), "svg");
    assert!(svg.starts_with("<svg "));
    assert!(svg.trim_end().ends_with("</svg>"));
    assert!(svg.contains(r#"width="720" height="400""#));
    assert_eq!(svg.matches("<g").count(), svg.matches("</g>").count());
    for bad in ["NaN", "inf", "Inf"] {
        assert!(!svg.contains(bad), "{bad} in\n{svg}");
    }
}

/// The point lists of every polyline, as (x, y) pairs.
fn polylines(svg: &str) -> Vec<Vec<(f64, f64)>> {
    svg.split("<polyline points=\"")
        .skip(1)
        .map(|s| {
            let pts = &s[..s.find('"').expect("closing quote")];
            pts.split_whitespace()
                .map(|p| {
                    let (x, y) = p.split_once(',').expect("x,y");
                    (x.parse().expect("x"), y.parse().expect("y"))
                })
                .collect()
        })
        .collect()
}

/// The text of every `<text>` element.
fn texts(svg: &str) -> Vec<&str> {
    svg.split("<text")
        .skip(1)
        .map(|s| {
            let s = &s[s.find('>').expect("tag end") + 1..];
            &s[..s.find("</text>").expect("closed text")]
        })
        .collect()
}

#[test]
fn the_checker_refuses_malformed_xml() {
    for bad in [
        "<svg><g></svg>",
        "<svg></g></svg>",
        "<svg><text>a & b</text></svg>",
        "<svg a=\"1\" a=\"2\"/>",
        "<svg a=1/>",
        "<svg/><svg/>",
        "<svg><g></g>",
    ] {
        assert!(
            std::panic::catch_unwind(|| check_xml(bad)).is_err(),
            "{bad}"
        );
    }
    assert_eq!(
        check_xml("<svg a=\"&lt;\"><!-- c --><g>x &amp; y</g><g/></svg>\n"),
        "svg"
    );
}

#[test]
fn a_line_chart_has_axes_ticks_and_one_polyline_point_per_input_point() {
    let pts: Vec<(f64, f64)> = (0..=50).map(|i| (i as f64 * 0.2, (i * 2) as f64)).collect();
    let svg = line_chart(
        "Hip",
        "t (s)",
        "angle",
        None,
        &[Series {
            name: "hip",
            points: &pts,
        }],
    );
    check_chart(&svg);
    let lines = polylines(&svg);
    assert_eq!(lines.len(), 1);
    assert_eq!(lines[0].len(), pts.len());
    // Auto ranges round outwards to ticks: x 0..10, y 0..100, all inside the plot area.
    for &(x, y) in &lines[0] {
        assert!(
            (72.0..=696.0).contains(&x) && (44.0..=344.0).contains(&y),
            "{x},{y}"
        );
    }
    assert_eq!(lines[0][0], (72.0, 344.0));
    assert_eq!(lines[0][50], (696.0, 44.0));
    let t = texts(&svg);
    for label in ["0", "20", "40", "60", "80", "100", "2", "4", "6", "8", "10"] {
        assert!(t.contains(&label), "tick {label} in {t:?}");
    }
    assert!(t.contains(&"t (s)") && t.contains(&"angle") && t.contains(&"Hip"));
    assert!(
        !svg.contains("class=\"legend\""),
        "no legend for one series"
    );
}

#[test]
fn several_series_get_a_legend_and_distinct_colours() {
    let data: Vec<Vec<(f64, f64)>> = (0..10)
        .map(|i| (0..5).map(|x| (x as f64, (x * i) as f64)).collect())
        .collect();
    let names: Vec<String> = (0..10).map(|i| format!("s{i}")).collect();
    let series: Vec<Series> = data
        .iter()
        .zip(&names)
        .map(|(p, n)| Series { name: n, points: p })
        .collect();
    let svg = line_chart("many", "x", "y", None, &series);
    check_chart(&svg);
    assert_eq!(svg.matches("class=\"legend\"").count(), 1);
    for (i, c) in PALETTE.iter().enumerate() {
        assert!(svg.contains(&format!("<g stroke=\"{c}\">")), "series {i}");
    }
    let distinct: std::collections::HashSet<_> = PALETTE.iter().collect();
    assert_eq!(distinct.len(), PALETTE.len());
    let t = texts(&svg);
    for n in &names {
        assert!(t.contains(&n.as_str()), "legend entry {n}");
    }
    // Past ten series the colours repeat, dashed.
    let more: Vec<Series> = (0..12).map(|_| series[0]).collect();
    let svg = line_chart("more", "x", "y", None, &more);
    check_chart(&svg);
    assert_eq!(svg.matches("stroke-dasharray").count(), 2 * 2); // lines and legend swatches
}

#[test]
fn text_is_escaped_everywhere() {
    let nasty = "a < b && c > \"d\" 'e'";
    let escaped = "a &lt; b &amp;&amp; c &gt; &quot;d&quot; &apos;e&apos;";
    let pts = [(0.0, 1.0), (1.0, 2.0)];
    let svg = line_chart(
        nasty,
        nasty,
        nasty,
        None,
        &[
            Series {
                name: nasty,
                points: &pts,
            },
            Series {
                name: "<b>",
                points: &pts,
            },
        ],
    );
    check_chart(&svg);
    assert!(!svg.contains(nasty));
    assert!(!svg.contains("<b>"));
    // Title element, heading, both axis labels, the legend and the series' tooltip.
    assert_eq!(svg.matches(escaped).count(), 6, "{svg}");
    let svg = bar_chart(nasty, nasty, &[(nasty, 1.0), ("x&y", 2.0)]);
    check_chart(&svg);
    assert!(!svg.contains(nasty) && !svg.contains("x&y"));
    assert!(svg.contains("x&amp;y"));
    // Control characters are not XML: replaced.
    let svg = bar_chart("bell\u{7}", "y", &[]);
    check_chart(&svg);
    assert!(!svg.contains('\u{7}'));
}

#[test]
fn degenerate_input_stays_finite_and_well_formed() {
    let one = [(3.0, 7.0)];
    let flat = [(0.0, 5.0), (1.0, 5.0), (2.0, 5.0)];
    let vertical = [(2.0, 0.0), (2.0, 9.0)];
    let huge = [(-1e308, f64::MAX), (1e308, -f64::MAX), (0.0, 0.0)];
    let tiny = [(0.0, 1e-310), (1e-310, -1e-310)];
    let gaps = [
        (0.0, 0.0),
        (1.0, 1.0),
        (f64::NAN, 2.0),
        (3.0, f64::INFINITY),
        (4.0, 4.0),
        (5.0, f64::NEG_INFINITY),
    ];
    let all_bad = [(f64::NAN, f64::NAN), (f64::INFINITY, 0.0)];
    let cases: [&[(f64, f64)]; 8] = [&[], &one, &flat, &vertical, &huge, &tiny, &gaps, &all_bad];
    for pts in cases {
        for y_range in [
            None,
            Some((0.0, 10.0)),
            Some((10.0, 0.0)),
            Some((4.0, 4.0)),
            Some((f64::NAN, 1.0)),
            Some((-f64::MAX, f64::MAX)),
        ] {
            let svg = line_chart(
                "t",
                "x",
                "y",
                y_range,
                &[Series {
                    name: "s",
                    points: pts,
                }],
            );
            check_chart(&svg);
            let t = texts(&svg);
            // At least two ticks with labels on each axis, whatever the data.
            assert!(t.len() >= 4 + 3, "{pts:?} {y_range:?}: {t:?}");
        }
    }
    let svg = line_chart("none", "x", "y", None, &[]);
    check_chart(&svg);
    assert!(texts(&svg).contains(&"no data"));
    let empty = Series {
        name: "e",
        points: &[],
    };
    let svg = line_chart("empty", "x", "y", None, &[empty, empty]);
    check_chart(&svg);
    assert!(polylines(&svg).is_empty());
    assert!(texts(&svg).contains(&"no data"));
}

#[test]
fn gaps_split_lines_and_single_points_get_a_dot() {
    let gaps = [
        (0.0, 0.0),
        (1.0, 1.0),
        (f64::NAN, 2.0),
        (3.0, 3.0),
        (4.0, f64::INFINITY),
        (5.0, 5.0),
        (6.0, 6.0),
        (7.0, 7.0),
    ];
    let svg = line_chart(
        "gaps",
        "x",
        "y",
        None,
        &[Series {
            name: "s",
            points: &gaps,
        }],
    );
    check_chart(&svg);
    let lens: Vec<usize> = polylines(&svg).iter().map(Vec::len).collect();
    assert_eq!(lens, [2, 1, 3]);
    assert_eq!(svg.matches("<circle").count(), 1);
    let one = [(3.0, 7.0)];
    let svg = line_chart(
        "one",
        "x",
        "y",
        None,
        &[Series {
            name: "s",
            points: &one,
        }],
    );
    check_chart(&svg);
    let lines = polylines(&svg);
    assert_eq!(lines.len(), 1);
    assert_eq!(lines[0].len(), 1);
    // The lone point sits inside the plot area, not on its edge.
    let (x, y) = lines[0][0];
    assert!(x > 72.0 && x < 696.0 && y > 44.0 && y < 344.0, "{x},{y}");
}

#[test]
fn a_fixed_y_range_is_kept_and_points_outside_are_clipped() {
    let pts = [(0.0, -50.0), (1.0, 5.0), (2.0, 50.0)];
    let svg = line_chart(
        "clip",
        "x",
        "y",
        Some((0.0, 10.0)),
        &[Series {
            name: "s",
            points: &pts,
        }],
    );
    check_chart(&svg);
    assert!(svg.contains("clip-path=\"url(#plot-area)\""));
    let lines = polylines(&svg);
    assert_eq!(lines[0].len(), 3);
    assert_eq!(lines[0][1].1, (44.0 + 344.0) / 2.0, "y = 5 is mid-height");
    let t = texts(&svg);
    for label in ["0", "2", "4", "6", "8", "10"] {
        assert!(t.contains(&label), "{label}: {t:?}");
    }
}

#[test]
fn a_bar_chart_labels_each_bar_with_its_value() {
    let bars = [
        ("standby", 5.0),
        ("operational", 10.0),
        ("safed", 0.0),
        ("loss", -2.5),
    ];
    let svg = bar_chart("Commands", "count", &bars);
    check_chart(&svg);
    let t = texts(&svg);
    for label in [
        "standby",
        "operational",
        "safed",
        "loss",
        "5",
        "10",
        "0",
        "-2.5",
    ] {
        assert!(t.contains(&label), "{label}: {t:?}");
    }
    // Heights are proportional to the values; the negative bar hangs below the zero line.
    // Bars are the rects with a tooltip: (y, height) of each.
    let bars_only: Vec<(f64, f64)> = svg
        .split("<rect ")
        .skip(1)
        .filter(|r| r[r.find('>').expect("tag end")..].starts_with("><title>"))
        .map(|r| {
            let attr = |name: &str| -> f64 {
                let s = &r[r.find(&format!(" {name}=\"")).expect(name) + name.len() + 3..];
                s[..s.find('"').expect("quote")].parse().expect("number")
            };
            (attr("y"), attr("height"))
        })
        .collect();
    assert_eq!(bars_only.len(), 4, "{bars_only:?}");
    let h: Vec<f64> = bars_only.iter().map(|r| r.1).collect();
    assert!((h[1] - 2.0 * h[0]).abs() < 0.02, "{h:?}");
    assert_eq!(h[2], 0.0);
    assert!((h[0] - 2.0 * h[3]).abs() < 0.02, "{h:?}");
    let zero = bars_only[0].0 + bars_only[0].1;
    assert!(
        (bars_only[3].0 - zero).abs() < 0.01,
        "negative bar starts at zero"
    );
}

#[test]
fn bar_charts_handle_empty_odd_and_crowded_input() {
    let svg = bar_chart("empty", "y", &[]);
    check_chart(&svg);
    assert!(texts(&svg).contains(&"no data"));
    let svg = bar_chart(
        "odd",
        "y",
        &[
            ("nan", f64::NAN),
            ("unbounded", f64::INFINITY),
            ("zero", 0.0),
            ("big", 1e308),
            ("tiny", -1e-9),
        ],
    );
    check_chart(&svg);
    assert_eq!(texts(&svg).iter().filter(|t| **t == "n/a").count(), 2);
    let svg = bar_chart("zeros", "y", &[("a", 0.0), ("b", 0.0)]);
    check_chart(&svg);
    let labels: Vec<String> = (0..20)
        .map(|i| format!("a rather long category {i}"))
        .collect();
    let many: Vec<(&str, f64)> = labels.iter().map(|l| (l.as_str(), 1.5)).collect();
    let svg = bar_chart("crowded", "y", &many);
    check_chart(&svg);
    assert_eq!(svg.matches("rotate(-35").count(), 20);
    assert_eq!(svg.matches("<title>a rather long category").count(), 20);
}

#[test]
fn a_time_series_ends_at_its_data_with_headroom_and_a_legend() {
    // The WiFi efficiency at 0 % loss: 100 % from 1.2 s to 127.6 s.
    let pts: Vec<(f64, f64)> = (0..=105).map(|i| (1.2 + i as f64 * 1.2, 100.0)).collect();
    let last_x = pts.last().unwrap().0;
    let svg = line_chart_with(
        "WiFi",
        "simulated time (s)",
        "efficiency (%)",
        LineOptions {
            y_range: Some((0.0, 110.0)),
            x_at_data: true,
            legend: true,
        },
        &[Series {
            name: "robot 1",
            points: &pts,
        }],
    );
    check_chart(&svg);
    let lines = polylines(&svg);
    let right = lines[0].iter().map(|p| p.0).fold(f64::MIN, f64::max);
    let left = lines[0].iter().map(|p| p.0).fold(f64::MAX, f64::min);
    // The legend takes the right margin; the axis spans exactly the data's x range: the first
    // and last points sit on the plot area's left and right edges (its clip rectangle).
    let clip = svg
        .split("<clipPath id=\"plot-area\"><rect ")
        .nth(1)
        .unwrap();
    let attr = |name: &str| -> f64 {
        clip.split(&format!("{name}=\""))
            .nth(1)
            .unwrap()
            .split('"')
            .next()
            .unwrap()
            .parse()
            .unwrap()
    };
    let (x0, x1) = (attr("x"), attr("x") + attr("width"));
    assert!(
        (left - x0).abs() < 0.01,
        "first point at the axis start: {left} vs {x0}"
    );
    assert!(
        (right - x1).abs() < 0.01,
        "last point at the axis end: {right} vs {x1}"
    );
    // No tick label past the data (the axis used to run on to the next round tick).
    let ticks: Vec<f64> = texts(&svg).iter().filter_map(|t| t.parse().ok()).collect();
    assert!(ticks.iter().all(|&t| t <= last_x), "{ticks:?}");
    // 100 % is drawn below the top border (y = 44), not on it.
    assert!(
        lines[0].iter().all(|p| p.1 > 44.0 + 10.0),
        "{:?}",
        &lines[0][..2]
    );
    assert!(
        svg.contains("class=\"legend\""),
        "a legend names the single series"
    );
    assert!(texts(&svg).contains(&"robot 1"));
}

/// (element name, its direct text) of every element of `svg`, read by quick-xml (a full XML
/// parser: end tags must match, attributes must be well-formed, entities known).
fn parsed(svg: &str) -> Vec<(String, String)> {
    use quick_xml::events::Event;
    let mut reader = quick_xml::Reader::from_str(svg);
    let (mut out, mut open): (Vec<(String, String)>, Vec<usize>) = (Vec::new(), Vec::new());
    loop {
        match reader.read_event().unwrap_or_else(|e| panic!("{e}: {svg}")) {
            Event::Start(e) => {
                open.push(out.len());
                out.push((
                    String::from_utf8_lossy(e.name().as_ref()).into(),
                    String::new(),
                ));
            }
            Event::Empty(e) => {
                for a in e.attributes() {
                    a.unwrap_or_else(|err| panic!("{err}: {svg}"));
                }
                out.push((
                    String::from_utf8_lossy(e.name().as_ref()).into(),
                    String::new(),
                ));
            }
            Event::End(_) => {
                open.pop().expect("balanced");
            }
            Event::Text(t) => {
                let text = t.decode().unwrap();
                match open.last() {
                    Some(&i) => out[i].1 += &text,
                    None => assert!(text.trim().is_empty(), "text outside the root: {text:?}"),
                }
            }
            Event::GeneralRef(r) => {
                let name = r.decode().unwrap();
                let c = quick_xml::escape::resolve_predefined_entity(&name).expect("known entity");
                let i = *open.last().expect("entity inside the root");
                out[i].1 += c;
            }
            Event::Eof => break,
            _ => {}
        }
    }
    assert!(open.is_empty(), "unclosed elements");
    out
}

/// Every chart, whatever its input, is XML a real parser takes; its root is `svg`, its first
/// child the `<title>` with the chart's title (unescaped back), and the title, axis labels and
/// series names are texts of it.
#[test]
fn charts_parse_as_xml_with_their_title_labels_and_series() {
    let nasty = "a < b && c > \"d\" 'e'";
    let gaps = [
        (0.0, 1.0),
        (f64::NAN, 2.0),
        (3.0, 3.0),
        (4.0, f64::INFINITY),
    ];
    let ramp: Vec<(f64, f64)> = (0..20).map(|i| (f64::from(i), f64::from(i * i))).collect();
    let series = [
        Series {
            name: nasty,
            points: &gaps,
        },
        Series {
            name: "ramp",
            points: &ramp,
        },
    ];
    let labels: Vec<String> = (0..12).map(|i| format!("category {i}")).collect();
    let crowded: Vec<(&str, f64)> = labels.iter().map(|l| (l.as_str(), -1.5)).collect();
    let charts = [
        (line_chart(nasty, "x <s>", "y & z", None, &series), true),
        (
            line_chart(nasty, "x <s>", "y & z", Some((0.0, 5.0)), &series),
            true,
        ),
        (line_chart(nasty, "x <s>", "y & z", None, &[]), false),
        (bar_chart(nasty, "y & z", &crowded), false),
        (bar_chart(nasty, "y & z", &[]), false),
    ];
    for (svg, has_series) in &charts {
        let elements = parsed(svg);
        assert_eq!(elements[0].0, "svg");
        assert_eq!(elements[1], ("title".to_string(), nasty.to_string()));
        let texts: Vec<&str> = elements
            .iter()
            .filter(|e| e.0 == "text")
            .map(|e| e.1.as_str())
            .collect();
        assert!(
            texts.contains(&nasty) && texts.contains(&"y & z"),
            "{texts:?}"
        );
        if *has_series {
            assert!(
                texts.contains(&"x <s>") && texts.contains(&"ramp"),
                "{texts:?}"
            );
            assert_eq!(elements.iter().filter(|e| e.0 == "polyline").count(), 3);
        }
    }
    let bar_labels = parsed(&charts[3].0);
    for l in &labels {
        assert!(bar_labels.iter().any(|e| e.0 == "text" && e.1 == *l), "{l}");
    }
}
