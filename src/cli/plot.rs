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

/// The series' colours, one per volume type in `BvKind::ALL` order, then the rest.
const COLOURS: [RGBColor; 6] = [
    RGBColor(31, 119, 180),
    RGBColor(214, 39, 40),
    RGBColor(44, 160, 44),
    RGBColor(255, 127, 14),
    RGBColor(148, 103, 189),
    RGBColor(90, 90, 90),
];

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
    let series: Vec<(&Series, Vec<(f64, f64)>)> = chart
        .series
        .iter()
        .map(|s| {
            let points = s
                .points
                .iter()
                .filter_map(|&(x, y)| Some((axis(x, chart.log_x)?, axis(y, chart.log_y)?)))
                .filter(|(x, y)| x.is_finite() && y.is_finite())
                .collect();
            (s, points)
        })
        .collect();
    let all = series.iter().flat_map(|(_, p)| p.iter().copied());
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
        return Err(Failure(format!("{}: nothing to plot", chart.title)));
    }
    let pad = |lo: f64, hi: f64| {
        let span = if hi > lo { hi - lo } else { 1.0 };
        (lo - 0.03 * span, hi + 0.03 * span)
    };
    let ((x0, x1), (y0, y1)) = (pad(x0, x1), pad(y0, y1));
    let mut text = String::new();
    {
        let root = SVGBackend::with_string(&mut text, (760, 480)).into_drawing_area();
        let fail =
            |e: &dyn std::fmt::Display| Failure(format!("{}: cannot draw: {e}", chart.title));
        root.fill(&WHITE).map_err(|e| fail(&e))?;
        let mut c = ChartBuilder::on(&root)
            .caption(chart.title, ("sans-serif", 20))
            .margin(12)
            .x_label_area_size(44)
            .y_label_area_size(70)
            .build_cartesian_2d(x0..x1, y0..y1)
            .map_err(|e| fail(&e))?;
        let tick = |log: bool| {
            move |v: &f64| {
                if log {
                    format!("1e{}", (*v * 100.0).round() / 100.0)
                } else {
                    format!("{}", (*v * 1000.0).round() / 1000.0)
                }
            }
        };
        let (fx, fy) = (tick(chart.log_x), tick(chart.log_y));
        c.configure_mesh()
            .x_desc(chart.x_label)
            .y_desc(chart.y_label)
            .x_label_formatter(&fx)
            .y_label_formatter(&fy)
            .light_line_style(WHITE.mix(0.0))
            .draw()
            .map_err(|e| fail(&e))?;
        for (k, (s, points)) in series.iter().enumerate() {
            let colour = COLOURS.get(k % COLOURS.len()).copied().unwrap_or(BLACK);
            let legend = move |(x, y): (i32, i32)| {
                PathElement::new([(x, y), (x + 16, y)], colour.stroke_width(2))
            };
            if s.line {
                c.draw_series(LineSeries::new(
                    points.iter().copied(),
                    colour.stroke_width(2),
                ))
                .map_err(|e| fail(&e))?
                .label(s.name.as_str())
                .legend(legend);
            } else {
                c.draw_series(
                    points
                        .iter()
                        .map(|&p| Circle::new(p, 2, colour.mix(0.7).filled())),
                )
                .map_err(|e| fail(&e))?
                .label(s.name.as_str())
                .legend(legend);
            }
        }
        c.configure_series_labels()
            .background_style(WHITE.mix(0.85))
            .border_style(BLACK)
            .draw()
            .map_err(|e| fail(&e))?;
        root.present().map_err(|e| fail(&e))?;
    }
    Ok(text)
}

/// Draws `chart` to `path` (atomically).
pub fn write(chart: &Chart<'_>, path: &Path) -> Result<(), Failure> {
    super::files::write_file(path, svg(chart)?.as_bytes())
}
