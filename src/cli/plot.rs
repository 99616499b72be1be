//! Small SVG charts of experiment results (plotters): points and lines on linear or
//! logarithmic axes.

use super::Failure;
use plotters::prelude::*;
use std::path::Path;

/// One series of a chart.
pub struct Series {
    /// The legend's name.
    pub name: String,
    /// The points, in data units.
    pub points: Vec<(f64, f64)>,
    /// Drawn as a line through the points (otherwise as dots).
    pub line: bool,
    /// Index of its colour in the palette: a volume type's points and fitted line share
    /// one.
    pub colour: usize,
    /// A label written beside each point (none if empty).
    pub labels: Vec<String>,
}

/// A chart to draw.
pub struct Chart<'a> {
    pub title: &'a str,
    pub x_label: &'a str,
    pub y_label: &'a str,
    pub log_x: bool,
    pub log_y: bool,
    pub series: Vec<Series>,
}

/// The series' colours: one per volume type in `BvKind::ALL` order, then the rest.
const COLOURS: [RGBColor; 6] = [
    RGBColor(31, 119, 180),
    RGBColor(214, 39, 40),
    RGBColor(44, 160, 44),
    RGBColor(255, 127, 14),
    RGBColor(148, 103, 189),
    RGBColor(90, 90, 90),
];

/// A point in chart coordinates (log10 on a log axis), with its label if it has one.
type Drawn<'a> = ((f64, f64), Option<&'a String>);

/// Draws `chart` into the SVG text it returns. Values that a logarithmic axis cannot show
/// (0 and below) are left out.
pub fn svg(chart: &Chart<'_>) -> Result<String, Failure> {
    let axis = |v: f64, log: bool| {
        if log {
            (v > 0.0).then(|| v.log10())
        } else {
            Some(v)
        }
    };
    // Each series' drawable points, each with its label if it has one: a point left out
    // takes its label with it.
    let series: Vec<(&Series, Vec<Drawn<'_>>)> = chart
        .series
        .iter()
        .map(|s| {
            let points = s
                .points
                .iter()
                .enumerate()
                .filter_map(|(k, &(x, y))| {
                    let p = (axis(x, chart.log_x)?, axis(y, chart.log_y)?);
                    (p.0.is_finite() && p.1.is_finite()).then(|| (p, s.labels.get(k)))
                })
                .collect();
            (s, points)
        })
        .collect();
    let all = series.iter().flat_map(|(_, p)| p.iter().map(|&(p, _)| p));
    let (x0, x1, y0, y1) = all.fold(
        (
            f64::INFINITY,
            f64::NEG_INFINITY,
            f64::INFINITY,
            f64::NEG_INFINITY,
        ),
        |(x0, x1, y0, y1), (x, y)| (x0.min(x), x1.max(x), y0.min(y), y1.max(y)),
    );
    if !(x0.is_finite() && y0.is_finite()) {
        return Err(Failure::msg(format!("{}: nothing to plot", chart.title)));
    }
    let pad = |lo: f64, hi: f64, right: f64| {
        let span = if hi > lo { hi - lo } else { 1.0 };
        (lo - 0.03 * span, hi + right * span)
    };
    // Labels are written to the right of their points: room for them.
    let labelled = chart.series.iter().any(|s| !s.labels.is_empty());
    let ((x0, x1), (y0, y1)) = (
        pad(x0, x1, if labelled { 0.3 } else { 0.03 }),
        pad(y0, y1, 0.03),
    );
    let mut text = String::new();
    {
        let root = SVGBackend::with_string(&mut text, (760, 480)).into_drawing_area();
        let fail =
            |e: &dyn std::fmt::Display| Failure::msg(format!("{}: cannot draw: {e}", chart.title));
        root.fill(&WHITE).map_err(|e| fail(&e))?;
        let mut c = ChartBuilder::on(&root)
            .caption(chart.title, ("sans-serif", 20))
            .margin(12)
            .x_label_area_size(44)
            .y_label_area_size(70)
            .build_cartesian_2d(x0..x1, y0..y1)
            .map_err(|e| fail(&e))?;
        let tick = |log: bool| move |v: &f64| tick_label(if log { 10f64.powf(*v) } else { *v });
        let (fx, fy) = (tick(chart.log_x), tick(chart.log_y));
        c.configure_mesh()
            .x_desc(chart.x_label)
            .y_desc(chart.y_label)
            .x_label_formatter(&fx)
            .y_label_formatter(&fy)
            .light_line_style(WHITE.mix(0.0))
            .draw()
            .map_err(|e| fail(&e))?;
        for (s, points) in &series {
            let colour = COLOURS
                .get(s.colour % COLOURS.len())
                .copied()
                .unwrap_or(BLACK);
            let legend = move |(x, y): (i32, i32)| {
                PathElement::new([(x, y), (x + 16, y)], colour.stroke_width(2))
            };
            let labels = points.iter().filter_map(|&(p, label)| Some((label?, p)));
            c.draw_series(labels.map(|(label, p)| {
                Text::new(
                    label.clone(),
                    p,
                    ("sans-serif", 10).into_font().color(&colour),
                )
            }))
            .map_err(|e| fail(&e))?;
            if s.line {
                c.draw_series(LineSeries::new(
                    points.iter().map(|&(p, _)| p),
                    colour.stroke_width(2),
                ))
                .map_err(|e| fail(&e))?
                .label(s.name.as_str())
                .legend(legend);
            } else {
                c.draw_series(
                    points
                        .iter()
                        .map(|&(p, _)| Circle::new(p, 2, colour.mix(0.7).filled())),
                )
                .map_err(|e| fail(&e))?
                .label(s.name.as_str())
                .legend(legend);
            }
        }
        c.configure_series_labels()
            .position(emptiest_corner(
                series.iter().flat_map(|(_, p)| p.iter().map(|&(p, _)| p)),
                (x0, x1),
                (y0, y1),
            ))
            .background_style(WHITE.mix(0.85))
            .border_style(BLACK)
            .draw()
            .map_err(|e| fail(&e))?;
        root.present().map_err(|e| fail(&e))?;
    }
    Ok(compact_markers(&text))
}

/// Where the legend covers the fewest points: the corner (a third of the width, 40% of
/// the height) holding the fewest, the upper right on ties.
fn emptiest_corner(
    points: impl Iterator<Item = (f64, f64)> + Clone,
    (x0, x1): (f64, f64),
    (y0, y1): (f64, f64),
) -> SeriesLabelPosition {
    let corners = [
        (SeriesLabelPosition::UpperRight, true, true),
        (SeriesLabelPosition::UpperLeft, false, true),
        (SeriesLabelPosition::LowerRight, true, false),
        (SeriesLabelPosition::LowerLeft, false, false),
    ];
    let inside = |(x, y): (f64, f64), right: bool, upper: bool| {
        let (u, v) = ((x - x0) / (x1 - x0), (y - y0) / (y1 - y0));
        (if right { u > 2.0 / 3.0 } else { u < 1.0 / 3.0 })
            && (if upper { v > 0.6 } else { v < 0.4 })
    };
    let covered =
        |right: bool, upper: bool| points.clone().filter(|&p| inside(p, right, upper)).count();
    corners
        .into_iter()
        .min_by_key(|&(_, right, upper)| covered(right, upper))
        .map_or(SeriesLabelPosition::UpperRight, |(corner, _, _)| corner)
}

/// A tick's value with at most three significant digits, in scientific notation beyond
/// 1e4 and below 1e-3.
fn tick_label(v: f64) -> String {
    let magnitude = v.abs();
    if v == 0.0 {
        "0".into()
    } else if !(1e-3..1e4).contains(&magnitude) {
        let text = format!("{v:.2e}");
        // 1.00e5 -> 1e5, 3.20e4 -> 3.2e4.
        match text.split_once('e') {
            Some((mantissa, exponent)) => {
                let mantissa = mantissa.trim_end_matches('0').trim_end_matches('.');
                format!("{mantissa}e{exponent}")
            }
            None => text,
        }
    } else {
        let digits = (2 - magnitude.log10().floor() as i32).clamp(0, 6) as usize;
        let text = format!("{v:.digits$}");
        if text.contains('.') {
            text.trim_end_matches('0').trim_end_matches('.').to_string()
        } else {
            text
        }
    }
}

/// plotters writes one `<circle>` element per dot (about 90 bytes); runs of dots of one
/// style become one path of zero-length round-capped segments (about 10 bytes a dot), so
/// a chart of 3,000 dots stays small enough to commit.
fn compact_markers(svg: &str) -> String {
    let mut out = String::with_capacity(svg.len() / 4);
    // The style of the current run and its path data.
    let mut run: Option<(String, String, String)> = None;
    let flush = |out: &mut String, run: &mut Option<(String, String, String)>| {
        if let Some((fill, opacity, d)) = run.take() {
            out.push_str(&format!(
                "<path d=\"{d}\" stroke=\"{fill}\" stroke-opacity=\"{opacity}\" stroke-width=\"4\" stroke-linecap=\"round\" fill=\"none\"/>\n"
            ));
        }
    };
    for line in svg.lines() {
        let attribute = |name: &str| {
            let start = line.find(&format!(" {name}=\""))? + name.len() + 3;
            let rest = line.get(start..)?;
            rest.get(..rest.find('"')?)
        };
        let circle = line.starts_with("<circle ") && attribute("r") == Some("2");
        match (
            circle,
            attribute("cx"),
            attribute("cy"),
            attribute("fill"),
            attribute("opacity"),
        ) {
            (true, Some(x), Some(y), Some(fill), Some(opacity)) => {
                let same = run
                    .as_ref()
                    .is_some_and(|(f, o, _)| f == fill && o == opacity);
                if !same {
                    flush(&mut out, &mut run);
                    run = Some((fill.into(), opacity.into(), String::new()));
                }
                if let Some((_, _, d)) = run.as_mut() {
                    d.push_str(&format!("M{x} {y}h0"));
                }
            }
            _ => {
                flush(&mut out, &mut run);
                out.push_str(line);
                out.push('\n');
            }
        }
    }
    flush(&mut out, &mut run);
    out
}

/// Draws `chart` to `path` (atomically).
pub fn write(chart: &Chart<'_>, path: &Path) -> Result<(), Failure> {
    super::files::write_file(path, svg(chart)?.as_bytes())
}
