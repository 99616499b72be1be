//! The charts drawn of each experiment, declared as data: every chapter 5 experiment lists
//! its charts ([`SLIDING`], [`PROXIMITY`], [`TRANSVERSE`]) as specs of a title, axes and
//! what the series show, and each accuracy query its chart ([`TRADE_CHARTS`]).

use crate::cli::plot::{Chart, Series};
use obbtree::bv::BvKind;
use obbtree::experiment::accuracy::{Trade, Workload};
use obbtree::experiment::{self, of_kind, of_variant, Outcome, Point, Variant};

/// One chart of a chapter 5 experiment.
pub struct ChartSpec {
    /// Its file's name after the experiment's: `{experiment}-{file}.svg`.
    pub file: &'static str,
    /// The chart's title, with the dissertation's figure it redraws.
    pub title: &'static str,
    /// The x axis's label; `None` for the experiment's parameter ([`Outcome::x_name`]).
    pub x_label: Option<&'static str>,
    /// The y axis's label.
    pub y_label: &'static str,
    /// Whether the x axis is logarithmic.
    pub log_x: bool,
    /// Whether the y axis is logarithmic.
    pub log_y: bool,
    /// What its series show.
    pub plotted: Plotted,
}

/// What a chart's series show of an outcome.
pub enum Plotted {
    /// One series per volume type of `measure` at each point, then the lines fitted to
    /// the measure the library names `fits` ([`experiment::Fit::measure`]), if any.
    PerKind {
        /// The value drawn of each point.
        measure: Measure,
        /// The fitted lines drawn with it.
        fits: Option<&'static str>,
    },
    /// OBB contacts, and the length of the spheres' intersection curve scaled to them:
    /// contacts follow the curve (sliding spheres, Fig. 5.4).
    ContactsAlongCurve,
    /// Each listed setup's volume tests over OBB's, in the palette colour given with it.
    OverObb(&'static [(BvKind, Variant, usize)]),
    /// Mean thickness per level for each volume type, and the dissertation's reference
    /// for OBBs (proximity, Fig. 5.17).
    Thickness,
}

/// A value of each point, drawn per volume type.
#[derive(Clone, Copy)]
pub enum Measure {
    /// Mean contacting triangle pairs.
    Contacts,
    /// Mean volume tests.
    BvTests,
    /// Volume tests per contact (none without contacts).
    ContactCost,
}

impl Measure {
    /// The measure of `p`; `None` where it has no value.
    fn of(self, p: &Point) -> Option<f64> {
        match self {
            Measure::Contacts => Some(p.contacts),
            Measure::BvTests => Some(p.bv_tests()),
            Measure::ContactCost => (p.contacts > 0.0).then(|| p.bv_tests() / p.contacts),
        }
    }
}

/// The sliding spheres' charts (§5.3.1).
pub const SLIDING: [ChartSpec; 4] = [
    ChartSpec {
        file: "contacts",
        title: "Contacts as the small sphere moves (Fig. 5.4)",
        x_label: None,
        y_label: "contacting triangle pairs",
        log_x: false,
        log_y: false,
        plotted: Plotted::ContactsAlongCurve,
    },
    ChartSpec {
        file: "bv-tests",
        title: "Volume tests (Fig. 5.5)",
        x_label: None,
        y_label: "volume tests",
        log_x: false,
        log_y: true,
        plotted: Plotted::PerKind {
            measure: Measure::BvTests,
            fits: None,
        },
    },
    ChartSpec {
        file: "ratios",
        title: "Volume tests over OBB's (Fig. 5.7)",
        x_label: None,
        y_label: "ratio",
        log_x: false,
        log_y: true,
        plotted: Plotted::OverObb(&[
            (BvKind::Aabb, Variant::Standard, 1),
            (BvKind::Sphere, Variant::Standard, 2),
            (BvKind::Aabb, Variant::Rewrapped, 3),
            (BvKind::Sphere, Variant::MinimalSpheres, 4),
        ]),
    },
    ChartSpec {
        file: "contact-cost",
        title: "Contact cost: volume tests per contact (Fig. 5.8)",
        x_label: None,
        y_label: "volume tests per contact",
        log_x: false,
        log_y: true,
        plotted: Plotted::PerKind {
            measure: Measure::ContactCost,
            fits: None,
        },
    },
];

/// The parallel close proximity charts (§5.3.2).
pub const PROXIMITY: [ChartSpec; 2] = [
    slope_chart(
        "bv-tests",
        "Parallel close proximity (Fig. 5.11)",
        "volume tests (mean)",
        Measure::BvTests,
        "bv_tests",
    ),
    ChartSpec {
        file: "thickness",
        title: "Mean thickness per level, inner sphere (Fig. 5.17)",
        x_label: Some("level"),
        y_label: "mean thickness",
        log_x: false,
        log_y: true,
        plotted: Plotted::Thickness,
    },
];

/// The transverse contact charts (§5.3.3.1).
pub const TRANSVERSE: [ChartSpec; 2] = [
    slope_chart(
        "contacts",
        "Contacts against tessellation (Fig. 5.21)",
        "contacts (mean)",
        Measure::Contacts,
        "contacts",
    ),
    slope_chart(
        "bv-tests",
        "Volume tests against tessellation (Fig. 5.22)",
        "volume tests (mean)",
        Measure::BvTests,
        "bv_tests",
    ),
];

/// A chart whose slope the dissertation reads off: `measure` per volume type against the
/// experiment's parameter with the lines fitted to it (named `fits` by the library), on
/// log-log axes, where those lines are straight.
const fn slope_chart(
    file: &'static str,
    title: &'static str,
    y_label: &'static str,
    measure: Measure,
    fits: &'static str,
) -> ChartSpec {
    ChartSpec {
        file,
        title,
        x_label: None,
        y_label,
        log_x: true,
        log_y: true,
        plotted: Plotted::PerKind {
            measure,
            fits: Some(fits),
        },
    }
}

impl ChartSpec {
    /// The chart of `outcome` this spec describes.
    pub fn chart(&self, outcome: &Outcome) -> Chart<'static> {
        let series = match self.plotted {
            Plotted::PerKind { measure, fits } => {
                let mut series = per_kind(outcome, measure);
                if let Some(fits) = fits {
                    series.extend(fitted(outcome, fits));
                }
                series
            }
            Plotted::ContactsAlongCurve => contacts_along_curve(outcome),
            Plotted::OverObb(setups) => setups
                .iter()
                .map(|&(bv, variant, colour)| over_obb(outcome, bv, variant, colour))
                .collect(),
            Plotted::Thickness => thickness(outcome),
        };
        Chart {
            title: self.title,
            x_label: self.x_label.unwrap_or(outcome.x_name),
            y_label: self.y_label,
            log_x: self.log_x,
            log_y: self.log_y,
            series,
        }
    }
}

/// The palette index of a volume type's series (its place in `BvKind::ALL`).
fn colour_of(bv: BvKind) -> usize {
    BvKind::ALL.iter().position(|&k| k == bv).unwrap_or(0)
}

/// A series with nothing but its points: no labels.
fn series(name: String, points: Vec<(f64, f64)>, line: bool, colour: usize) -> Series {
    Series {
        name,
        points,
        line,
        colour,
        labels: Vec::new(),
    }
}

/// One series per volume type of `measure` against x.
fn per_kind(outcome: &Outcome, measure: Measure) -> Vec<Series> {
    BvKind::ALL
        .into_iter()
        .map(|bv| {
            let points = of_kind(&outcome.points, bv)
                .iter()
                .filter_map(|p| Some((p.x, measure.of(p)?)))
                .collect();
            series(bv.name().to_uppercase(), points, false, colour_of(bv))
        })
        .collect()
}

/// The lines fitted to `measure`, as two-point series over their ranges.
fn fitted(outcome: &Outcome, measure: &str) -> Vec<Series> {
    outcome
        .fits
        .iter()
        .filter(|f| f.measure == measure)
        .map(|f| {
            let at = |x: f64| (x, 10f64.powf(f.line.intercept + f.line.slope * x.log10()));
            let name = format!(
                "{} fit, slope {:.2}",
                f.bv.name().to_uppercase(),
                f.line.slope
            );
            series(name, vec![at(f.from), at(f.to)], true, colour_of(f.bv))
        })
        .collect()
}

/// OBB contacts, and the intersection curve's length times the contacts per unit length
/// (when there are contacts to measure that by).
fn contacts_along_curve(outcome: &Outcome) -> Vec<Series> {
    let obb = of_kind(&outcome.points, BvKind::Obb);
    let contacts = obb.iter().map(|p| (p.x, p.contacts)).collect();
    let mut all = vec![series("contacts".into(), contacts, false, 0)];
    if let Some(k) = experiment::sliding::contacts_per_length(&outcome.points) {
        let curve = obb
            .iter()
            .map(|p| (p.x, k * experiment::sliding::intersection_length(p.x)))
            .collect();
        let name = format!("{k:.0} x length of the intersection curve");
        all.push(series(name, curve, true, 3));
    }
    all
}

/// The volume tests of `bv` built and tested as `variant`, over OBB's at each x where
/// OBBs test any.
fn over_obb(outcome: &Outcome, bv: BvKind, variant: Variant, colour: usize) -> Series {
    let obb = of_kind(&outcome.points, BvKind::Obb);
    let setup = of_variant(&outcome.points, bv, variant);
    let name = setup.first().map_or(String::new(), Point::label);
    let ratios = setup
        .iter()
        .zip(&obb)
        .filter(|(_, o)| o.bv_tests() > 0.0)
        .map(|(s, o)| (s.x, s.bv_tests() / o.bv_tests()))
        .collect();
    series(format!("{name} / obb"), ratios, false, colour)
}

/// Mean thickness per level for each volume type, and the dissertation's reference for
/// OBBs: a quarter every two levels, from level 2 to the last full level.
fn thickness(outcome: &Outcome) -> Vec<Series> {
    let mut all: Vec<Series> = outcome
        .levels
        .iter()
        .map(|(bv, levels)| {
            // Levels of flat single-triangle leaves (thickness at rounding level) left out.
            let points = levels
                .iter()
                .enumerate()
                .map(|(l, s)| (l as f64, s.thickness.0))
                .filter(|&(_, t)| {
                    levels
                        .first()
                        .is_some_and(|root| t > 1e-6 * root.thickness.0)
                })
                .collect();
            series(bv.name().to_uppercase(), points, false, colour_of(*bv))
        })
        .collect();
    let obb = outcome.levels.iter().find(|(bv, _)| *bv == BvKind::Obb);
    if let Some((_, levels)) = obb {
        let (Some(top), Some(last)) = (
            levels.get(2),
            experiment::proximity::last_full_level(levels),
        ) else {
            return all;
        };
        let at = |l: f64| (l, top.thickness.0 * 4f64.powf(-(l - 2.0) / 2.0));
        let reference = vec![at(2.0), at(last as f64)];
        all.push(series(
            "a quarter every two levels".into(),
            reference,
            true,
            5,
        ));
    }
    all
}

/// The chart of one accuracy query: time against the error incurred.
pub struct TradeChart {
    /// The query, as [`Trade::query`] names it; the file is `accuracy-{query}.svg`.
    pub query: &'static str,
    /// The chart's title.
    pub title: &'static str,
    /// The x axis's label: what the error measures.
    pub x_label: &'static str,
}

/// The accuracy experiment's charts, one per query.
pub const TRADE_CHARTS: [TradeChart; 3] = [
    TradeChart {
        query: "distance",
        title: "Distance: time against the error incurred (exact at 1e-16)",
        x_label: "largest relative error over the poses",
    },
    TradeChart {
        query: "collision",
        title: "Collision: time against the contacts missed or added (exact at 1e-16)",
        x_label: "largest share of contacting pairs differing",
    },
    TradeChart {
        query: "hausdorff",
        title: "Hausdorff distance: time against the error incurred (exact at 1e-16)",
        x_label: "largest relative error over the poses",
    },
];

/// Errors below this are drawn at it: exact answers (0) have no place on a log axis.
const ERROR_FLOOR: f64 = 1e-16;

impl TradeChart {
    /// Time against the error incurred, one colour per scene, and each scene's Pareto
    /// front as a line with each of its choices labelled (the rest are in the table).
    pub fn chart(&self, trades: &[Trade], scenes: &[Workload]) -> Chart<'static> {
        let mut all = Vec::new();
        for (colour, scene) in scenes.iter().enumerate() {
            let mine: Vec<&Trade> = trades
                .iter()
                .filter(|t| t.scene == scene.name && t.query == self.query)
                .collect();
            let at = |t: &Trade| (t.error_max.max(ERROR_FLOOR), t.seconds * 1e3);
            let points = mine.iter().map(|t| at(t)).collect();
            all.push(series(scene.name.clone(), points, false, colour));
            let mut front: Vec<&&Trade> = mine.iter().filter(|t| t.pareto).collect();
            front.sort_by(|p, q| p.error_max.total_cmp(&q.error_max));
            all.push(Series {
                name: format!("{}: Pareto front", scene.name),
                points: front.iter().map(|t| at(t)).collect(),
                line: true,
                colour,
                labels: front.iter().map(|t| t.choice.replace("--", "")).collect(),
            });
        }
        Chart {
            title: self.title,
            x_label: self.x_label,
            y_label: "time for the poses (ms)",
            log_x: true,
            log_y: true,
            series: all,
        }
    }
}

/// What size costs in time: for each scene and query, the time of every tree choice asked
/// for the exact answer against its trees' bytes per triangle, each point labelled with its
/// choice (what differs between them is the tree).
pub fn size_chart(trades: &[Trade], scenes: &[Workload]) -> Chart<'static> {
    let mut all = Vec::new();
    for (colour, (scene, query)) in scenes
        .iter()
        .flat_map(|scene| TRADE_CHARTS.iter().map(move |c| (scene, c.query)))
        .enumerate()
    {
        let exact: Vec<&Trade> = trades
            .iter()
            .filter(|t| t.scene == scene.name && t.query == query && t.exact)
            .collect();
        all.push(Series {
            name: format!("{} {query}", scene.name),
            points: exact
                .iter()
                .map(|t| (t.bytes_per_triangle, t.seconds * 1e3))
                .collect(),
            line: false,
            colour,
            labels: exact
                .iter()
                .map(|t| t.choice.replace("--", "").replace(", exact", ""))
                .collect(),
        });
    }
    Chart {
        title: "Size: time against the trees' bytes per triangle (exact answers)",
        x_label: "bytes per triangle (both trees)",
        y_label: "time for the poses (ms)",
        log_x: false,
        log_y: true,
        series: all,
    }
}
