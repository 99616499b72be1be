//! `obbtree experiment`: the dissertation's chapter 5 experiments, run end to end, with
//! their CSV files, plots and a table of measured against reported figures.

mod csv;
mod table;

use super::build::load_mesh;
use super::plot::{self, Chart, Series};
use super::print::out;
use super::progress::with_progress;
use super::{human_seconds, with_threads, Failure};
use clap::{Args, ValueEnum};
use obbtree::bv::BvKind;
use obbtree::experiment::{
    self, accuracy, of_kind, of_variant, Outcome, Point, Progress, Size, Variant,
};
use std::io::IsTerminal;
use std::path::{Path, PathBuf};
use std::time::Instant;

/// Run an experiment of the dissertation's chapter 5 for OBB, AABB and sphere trees, and
/// write its CSV, its plots (SVG) and a table of measured against reported figures.
///
/// sliding: a sphere of radius 0.8 slides through a unit sphere (§5.3.1), both turned at
/// random at each of 1,001 steps; all contacts found at each step (8 s on 2 cores).
///
/// proximity: a unit sphere inside a sphere of radius 1 + gap (§5.3.2), gaps from 100 to
/// 1e-7; the slope of volume tests against the gap on log-log axes (6 minutes).
///
/// transverse: two unit spheres meeting at right angles (§5.3.3.1), 80 to 600,000
/// triangles; how contacts and volume tests grow with the tessellation (40 s).
///
/// accuracy: what each choice that trades accuracy for time costs, and the Pareto front
/// of time against the error incurred (seconds).
///
/// Queries run in parallel over --threads (default: one per core); the counts do not
/// depend on it, the times do (take them with --threads 1).
///
/// Example: obbtree experiment sliding --quick --out results
#[derive(Args, Debug)]
pub struct ExperimentArgs {
    /// Which experiment.
    #[arg(value_enum)]
    pub experiment: ExperimentArg,
    /// A reduced size that runs in seconds (smaller spheres, fewer steps and queries).
    #[arg(long)]
    pub quick: bool,
    /// Directory for the CSV and SVG files (created if needed; files of the same names
    /// are replaced).
    #[arg(long, value_name = "DIR", default_value = "experiments")]
    pub out: PathBuf,
    /// Seed of the random orientations.
    #[arg(long, default_value_t = 1)]
    pub seed: u64,
    /// accuracy: also measure this mesh (.obj, .stl) against a turned copy of itself
    /// (repeatable).
    #[arg(long, value_name = "FILE")]
    pub mesh: Vec<PathBuf>,
    /// Threads that run the queries [default: one per core; accuracy times one query at
    /// a time whatever this says].
    #[arg(long, value_name = "N", value_parser = clap::value_parser!(u32).range(1..1025))]
    pub threads: Option<u32>,
}

/// The experiments.
#[derive(ValueEnum, Clone, Copy, Debug)]
pub enum ExperimentArg {
    /// Sliding spheres (§5.3.1).
    Sliding,
    /// Parallel close proximity (§5.3.2).
    Proximity,
    /// Transverse contact against tessellation (§5.3.3.1).
    Transverse,
    /// What accuracy costs in time: distance error allowed, tolerance queries, f32 or
    /// f64, fit and leaf size, each timed (one query at a time) and held to an exact f64
    /// answer, on the sliding spheres and each --mesh against a turned copy.
    Accuracy,
}

pub fn run(args: &ExperimentArgs) -> Result<(), Failure> {
    let size = if args.quick { Size::Quick } else { Size::Full };
    if !args.mesh.is_empty() && !matches!(args.experiment, ExperimentArg::Accuracy) {
        return Err(Failure(
            "--mesh applies to the accuracy experiment only".into(),
        ));
    }
    if args.out.exists() && !args.out.is_dir() {
        return Err(Failure(format!(
            "{}: is not a directory",
            args.out.display()
        )));
    }
    let started = Instant::now();
    let chapter_5 = match args.experiment {
        ExperimentArg::Sliding => experiment::sliding::run,
        ExperimentArg::Proximity => experiment::proximity::run,
        ExperimentArg::Transverse => experiment::transverse::run,
        ExperimentArg::Accuracy => return run_accuracy(args, size, started),
    };
    let progress = Progress::default();
    let experiment = || chapter_5(size, args.seed, Some(&progress));
    let label = format!(
        "{:?}{}",
        args.experiment,
        if args.quick { " (quick)" } else { "" }
    );
    let show = std::io::stderr().is_terminal();
    let (done, total) = (&progress.done, &progress.total);
    let work = || with_threads(args.threads, experiment);
    let outcome = with_progress(&label, "queries", show, done, total, work)
        .ok_or_else(|| Failure(format!("{label}: the experiment crashed")))???;
    let seconds = started.elapsed().as_secs_f64();
    create_out(&args.out)?;
    let mut written = vec![csv::write_points(&outcome, &args.out)?];
    if !outcome.fits.is_empty() {
        written.push(csv::write_fits(&outcome, &args.out)?);
    }
    for (name, chart) in charts(&outcome) {
        let path = args.out.join(format!("{}-{name}.svg", outcome.name));
        plot::write(&chart, &path)?;
        written.push(path);
    }
    table::print_comparisons(&outcome, args.quick)?;
    out!("")?;
    out!(
        "ran in {} ({} queries)",
        human_seconds(seconds),
        queries(&outcome)
    )?;
    for path in written {
        out!("wrote {}", path.display())?;
    }
    Ok(())
}

/// The accuracy experiment: its trades as CSV, two charts and a table.
fn run_accuracy(args: &ExperimentArgs, size: Size, started: Instant) -> Result<(), Failure> {
    let mut scenes = vec![accuracy::spheres(size, args.seed)?];
    for path in &args.mesh {
        let mesh = load_mesh(path)?;
        let name = path
            .file_stem()
            .map_or("mesh".into(), |s| s.to_string_lossy().into_owned());
        // Scenes are told apart by name in the table, the CSV and the plots.
        if scenes.iter().any(|s| s.name == name) {
            return Err(Failure(format!(
                "{}: a scene named {name:?} is already measured (--mesh files need distinct names)",
                path.display()
            )));
        }
        scenes.push(accuracy::turned_copy(&name, &mesh, args.seed));
    }
    eprintln!(
        "running Accuracy{} ...",
        if args.quick { " (quick)" } else { "" }
    );
    let repeat = if args.quick { 3 } else { 15 };
    let trades = accuracy::run(&scenes, repeat)?;
    let seconds = started.elapsed().as_secs_f64();
    create_out(&args.out)?;
    let mut written = vec![csv::write_trades(&trades, &args.out)?];
    for query in ["distance", "collision"] {
        let path = args.out.join(format!("accuracy-{query}.svg"));
        plot::write(&accuracy_chart(&trades, &scenes, query), &path)?;
        written.push(path);
    }
    table::print_trades(&trades, &scenes)?;
    out!("")?;
    out!("ran in {}", human_seconds(seconds))?;
    for path in written {
        out!("wrote {}", path.display())?;
    }
    Ok(())
}

/// Errors below this are drawn at it: exact answers (0) have no place on a log axis.
const ERROR_FLOOR: f64 = 1e-16;

/// Time against the error incurred, one colour per scene, each choice labelled, and each
/// scene's Pareto front as a line.
fn accuracy_chart(
    trades: &[accuracy::Trade],
    scenes: &[accuracy::Scene],
    query: &str,
) -> Chart<'static> {
    let mut series = Vec::new();
    for (colour, scene) in scenes.iter().enumerate() {
        let mine: Vec<&accuracy::Trade> = trades
            .iter()
            .filter(|t| t.scene == scene.name && t.query == query)
            .collect();
        let at = |t: &accuracy::Trade| (t.error_max.max(ERROR_FLOOR), t.seconds * 1e3);
        series.push(Series {
            name: scene.name.clone(),
            points: mine.iter().map(|t| at(t)).collect(),
            line: false,
            colour,
            labels: Vec::new(),
        });
        // The choices worth making, labelled: the rest are in the table.
        let mut front: Vec<&&accuracy::Trade> = mine.iter().filter(|t| t.pareto).collect();
        front.sort_by(|p, q| p.error_max.total_cmp(&q.error_max));
        series.push(Series {
            name: format!("{}: Pareto front", scene.name),
            points: front.iter().map(|t| at(t)).collect(),
            line: true,
            colour,
            labels: front.iter().map(|t| t.choice.replace("--", "")).collect(),
        });
    }
    let (title, x_label) = if query == "distance" {
        (
            "Distance: time against the error incurred (exact at 1e-16)",
            "largest relative error over the poses",
        )
    } else {
        (
            "Collision: time against the contacts missed or added (exact at 1e-16)",
            "largest share of contacting pairs differing",
        )
    };
    Chart {
        title,
        x_label,
        y_label: "time for the poses (ms)",
        log_x: true,
        log_y: true,
        series,
    }
}

/// Creates the output directory once the experiment has run, so that a failed run leaves
/// nothing behind.
fn create_out(dir: &Path) -> Result<(), Failure> {
    std::fs::create_dir_all(dir)
        .map_err(|e| Failure(format!("{}: cannot create: {e}", dir.display())))
}

fn queries(outcome: &Outcome) -> u64 {
    outcome.points.iter().map(|p| u64::from(p.queries)).sum()
}

/// The palette index of a volume type's series (its place in `BvKind::ALL`).
fn colour_of(bv: BvKind) -> usize {
    BvKind::ALL.iter().position(|&k| k == bv).unwrap_or(0)
}

/// One series per volume type of `value` against x.
fn per_kind(outcome: &Outcome, value: impl Fn(&Point) -> Option<f64>) -> Vec<Series> {
    BvKind::ALL
        .into_iter()
        .map(|bv| Series {
            name: bv.name().to_uppercase(),
            colour: colour_of(bv),
            points: of_kind(&outcome.points, bv)
                .iter()
                .filter_map(|p| Some((p.x, value(p)?)))
                .collect(),
            line: false,
            labels: Vec::new(),
        })
        .collect()
}

/// The fitted lines of `measure`, as two-point series over their ranges.
fn fitted(outcome: &Outcome, measure: &str) -> Vec<Series> {
    outcome
        .fits
        .iter()
        .filter(|f| f.measure == measure)
        .map(|f| {
            let at = |x: f64| (x, 10f64.powf(f.line.intercept + f.line.slope * x.log10()));
            Series {
                name: format!(
                    "{} fit, slope {:.2}",
                    f.bv.name().to_uppercase(),
                    f.line.slope
                ),
                points: vec![at(f.from), at(f.to)],
                line: true,
                colour: colour_of(f.bv),
                labels: Vec::new(),
            }
        })
        .collect()
}

/// Mean thickness per level for each volume type, and the dissertation's reference for
/// OBBs: a quarter every two levels, from level 2 to the last full level.
fn thickness(outcome: &Outcome) -> Vec<Series> {
    let mut series: Vec<Series> = outcome
        .levels
        .iter()
        .map(|(bv, levels)| Series {
            name: bv.name().to_uppercase(),
            // Levels of flat single-triangle leaves (thickness at rounding level) left out.
            points: levels
                .iter()
                .enumerate()
                .map(|(l, s)| (l as f64, s.thickness.0))
                .filter(|&(_, t)| {
                    levels
                        .first()
                        .is_some_and(|root| t > 1e-6 * root.thickness.0)
                })
                .collect(),
            line: false,
            colour: colour_of(*bv),
            labels: Vec::new(),
        })
        .collect();
    let obb = outcome.levels.iter().find(|(bv, _)| *bv == BvKind::Obb);
    if let Some((_, levels)) = obb {
        let (Some(top), Some(last)) = (
            levels.get(2),
            experiment::proximity::last_full_level(levels),
        ) else {
            return series;
        };
        let at = |l: f64| (l, top.thickness.0 * 4f64.powf(-(l - 2.0) / 2.0));
        series.push(Series {
            name: "a quarter every two levels".into(),
            points: vec![at(2.0), at(last as f64)],
            line: true,
            colour: 5,
            labels: Vec::new(),
        });
    }
    series
}

fn charts(outcome: &Outcome) -> Vec<(&'static str, Chart<'static>)> {
    let chart = |title, x_label, y_label, log_x, log_y, series| Chart {
        title,
        x_label,
        y_label,
        log_x,
        log_y,
        series,
    };
    match outcome.name {
        "sliding" => {
            let obb = of_kind(&outcome.points, BvKind::Obb);
            let mut contacts = vec![Series {
                name: "contacts".into(),
                points: obb.iter().map(|p| (p.x, p.contacts)).collect(),
                line: false,
                colour: 0,
                labels: Vec::new(),
            }];
            // The intersection curve's length times the contacts per unit length.
            if let Some(k) = experiment::sliding::contacts_per_length(&outcome.points) {
                contacts.push(Series {
                    name: format!("{k:.0} x length of the intersection curve"),
                    points: obb
                        .iter()
                        .map(|p| (p.x, k * experiment::sliding::intersection_length(p.x)))
                        .collect(),
                    line: true,
                    colour: 3,
                    labels: Vec::new(),
                });
            }
            let ratio = |bv, variant, colour| {
                let series = of_variant(&outcome.points, bv, variant);
                let name = series.first().map_or(String::new(), Point::label);
                Series {
                    colour,
                    name: format!("{} / obb", name),
                    points: series
                        .iter()
                        .zip(&obb)
                        .filter(|(_, o)| o.bv_tests() > 0.0)
                        .map(|(s, o)| (s.x, s.bv_tests() / o.bv_tests()))
                        .collect(),
                    line: false,
                    labels: Vec::new(),
                }
            };
            vec![
                (
                    "contacts",
                    chart(
                        "Contacts as the small sphere moves (Fig. 5.4)",
                        outcome.x_name,
                        "contacting triangle pairs",
                        false,
                        false,
                        contacts,
                    ),
                ),
                (
                    "bv-tests",
                    chart(
                        "Volume tests (Fig. 5.5)",
                        outcome.x_name,
                        "volume tests",
                        false,
                        true,
                        per_kind(outcome, |p| Some(p.bv_tests())),
                    ),
                ),
                (
                    "ratios",
                    chart(
                        "Volume tests over OBB's (Fig. 5.7)",
                        outcome.x_name,
                        "ratio",
                        false,
                        true,
                        vec![
                            ratio(BvKind::Aabb, Variant::Standard, 1),
                            ratio(BvKind::Sphere, Variant::Standard, 2),
                            ratio(BvKind::Aabb, Variant::Rewrapped, 3),
                            ratio(BvKind::Sphere, Variant::MinimalSpheres, 4),
                        ],
                    ),
                ),
                (
                    "contact-cost",
                    chart(
                        "Contact cost: volume tests per contact (Fig. 5.8)",
                        outcome.x_name,
                        "volume tests per contact",
                        false,
                        true,
                        per_kind(outcome, |p| {
                            (p.contacts > 0.0).then(|| p.bv_tests() / p.contacts)
                        }),
                    ),
                ),
            ]
        }
        "proximity" => {
            let mut series = per_kind(outcome, |p| Some(p.bv_tests()));
            series.extend(fitted(outcome, "bv_tests"));
            vec![
                (
                    "bv-tests",
                    chart(
                        "Parallel close proximity (Fig. 5.11)",
                        outcome.x_name,
                        "volume tests (mean)",
                        true,
                        true,
                        series,
                    ),
                ),
                (
                    "thickness",
                    chart(
                        "Mean thickness per level, inner sphere (Fig. 5.17)",
                        "level",
                        "mean thickness",
                        false,
                        true,
                        thickness(outcome),
                    ),
                ),
            ]
        }
        _ => {
            let mut contacts = per_kind(outcome, |p| Some(p.contacts));
            contacts.extend(fitted(outcome, "contacts"));
            let mut tests = per_kind(outcome, |p| Some(p.bv_tests()));
            tests.extend(fitted(outcome, "bv_tests"));
            vec![
                (
                    "contacts",
                    chart(
                        "Contacts against tessellation (Fig. 5.21)",
                        outcome.x_name,
                        "contacts (mean)",
                        true,
                        true,
                        contacts,
                    ),
                ),
                (
                    "bv-tests",
                    chart(
                        "Volume tests against tessellation (Fig. 5.22)",
                        outcome.x_name,
                        "volume tests (mean)",
                        true,
                        true,
                        tests,
                    ),
                ),
            ]
        }
    }
}
