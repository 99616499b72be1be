//! `obbtree experiment`: the dissertation's chapter 5 experiments and the accuracy
//! experiment, run end to end. Here: the arguments and the order of the work; the CSV
//! files are written by [`csv`], the charts declared as data in [`charts`], the printed
//! tables in [`table`].

mod charts;
mod csv;
mod table;

use super::build::load_mesh;
use super::plot;
use super::print::out;
use super::progress::with_progress;
use super::{human_seconds, with_threads, Failure};
use charts::ChartSpec;
use clap::{Args, ValueEnum};
use obbtree::experiment::{self, accuracy, ExperimentError, Outcome, Progress, Size};
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

/// A chapter 5 experiment: the library's run, and the charts drawn of what it measured.
struct Chapter5 {
    /// Runs it at a size from a seed, counting its queries in the progress.
    run: fn(Size, u64, Option<&Progress>) -> Result<Outcome, ExperimentError>,
    /// Its charts, in the order they are written.
    charts: &'static [ChartSpec],
}

/// Runs the experiment `args` names and writes its files, then prints its table and what
/// it wrote. Nothing is written unless the experiment ran to the end.
pub fn run(args: &ExperimentArgs) -> Result<(), Failure> {
    let size = if args.quick { Size::Quick } else { Size::Full };
    if !args.mesh.is_empty() && !matches!(args.experiment, ExperimentArg::Accuracy) {
        return Err(Failure::msg(
            "--mesh applies to the accuracy experiment only",
        ));
    }
    if args.out.exists() && !args.out.is_dir() {
        return Err(Failure::msg(format!(
            "{}: is not a directory",
            args.out.display()
        )));
    }
    let started = Instant::now();
    let chapter_5 = match args.experiment {
        ExperimentArg::Sliding => Chapter5 {
            run: experiment::sliding::run,
            charts: &charts::SLIDING,
        },
        ExperimentArg::Proximity => Chapter5 {
            run: experiment::proximity::run,
            charts: &charts::PROXIMITY,
        },
        ExperimentArg::Transverse => Chapter5 {
            run: experiment::transverse::run,
            charts: &charts::TRANSVERSE,
        },
        ExperimentArg::Accuracy => return run_accuracy(args, size, started),
    };
    run_chapter_5(args, size, started, &chapter_5)
}

/// A chapter 5 experiment, with a progress bar on a terminal: its points (and fitted
/// lines) as CSV, its charts and its table against the dissertation.
fn run_chapter_5(
    args: &ExperimentArgs,
    size: Size,
    started: Instant,
    chapter_5: &Chapter5,
) -> Result<(), Failure> {
    let progress = Progress::default();
    let experiment = || (chapter_5.run)(size, args.seed, Some(&progress));
    let label = format!(
        "{:?}{}",
        args.experiment,
        if args.quick { " (quick)" } else { "" }
    );
    let show = std::io::stderr().is_terminal();
    let (done, total) = (&progress.done, &progress.total);
    let work = || with_threads(args.threads, experiment);
    let outcome = with_progress(&label, "queries", show, done, total, work)
        .ok_or_else(|| Failure::msg(format!("{label}: the experiment crashed")))???;
    let seconds = started.elapsed().as_secs_f64();
    create_out(&args.out)?;
    let mut written = vec![csv::write_points(&outcome, &args.out)?];
    if !outcome.fits.is_empty() {
        written.push(csv::write_fits(&outcome, &args.out)?);
    }
    for spec in chapter_5.charts {
        let path = args.out.join(format!("{}-{}.svg", outcome.name, spec.file));
        plot::write(&spec.chart(&outcome), &path)?;
        written.push(path);
    }
    table::print_comparisons(&outcome, args.quick)?;
    let queries: u64 = outcome.points.iter().map(|p| u64::from(p.queries)).sum();
    let summary = format!("ran in {} ({queries} queries)", human_seconds(seconds));
    print_written(&summary, &written)
}

/// The accuracy experiment: its trades as CSV, a chart per query and a table per scene
/// and query.
fn run_accuracy(args: &ExperimentArgs, size: Size, started: Instant) -> Result<(), Failure> {
    let mut scenes = vec![accuracy::spheres(size, args.seed)?];
    for path in &args.mesh {
        let mesh = load_mesh(path)?;
        let name = path
            .file_stem()
            .map_or("mesh".into(), |s| s.to_string_lossy().into_owned());
        // Scenes are told apart by name in the table, the CSV and the plots.
        if scenes.iter().any(|s| s.name == name) {
            return Err(Failure::msg(format!(
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
    for spec in &charts::TRADE_CHARTS {
        let path = args.out.join(format!("accuracy-{}.svg", spec.query));
        plot::write(&spec.chart(&trades, &scenes), &path)?;
        written.push(path);
    }
    let path = args.out.join("accuracy-size.svg");
    plot::write(&charts::size_chart(&trades, &scenes), &path)?;
    written.push(path);
    table::print_trades(&trades, &scenes)?;
    print_written(&format!("ran in {}", human_seconds(seconds)), &written)
}

/// Creates the output directory once the experiment has run, so that a failed run leaves
/// nothing behind.
fn create_out(dir: &Path) -> Result<(), Failure> {
    std::fs::create_dir_all(dir)
        .map_err(|e| Failure::msg(format!("{}: cannot create: {e}", dir.display())))
}

/// Prints the run's `summary` after a blank line, then each file it wrote.
fn print_written(summary: &str, written: &[PathBuf]) -> Result<(), Failure> {
    out!("")?;
    out!("{summary}")?;
    for path in written {
        out!("wrote {}", path.display())?;
    }
    Ok(())
}
