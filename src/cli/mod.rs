//! Command-line interface. Every command is a few calls into the library plus printing;
//! errors become one line on stderr and exit status 1 (usage errors: 2, from clap).

mod build;
mod demo;
mod experiment;
mod files;
mod generate;
mod info;
mod plot;
mod poses;
mod print;
mod progress;
mod query;
mod scene;
mod verify;

use clap::{Parser, Subcommand};
use std::process::ExitCode;

/// Collision queries on triangle meshes with oriented bounding box trees.
///
/// Build a tree once, offline (`obbtree build`), then open the `.obbt` file instantly
/// (memory-mapped, nothing parsed or rebuilt) wherever queries run.
#[derive(Parser, Debug)]
#[command(
    name = "obbtree",
    version,
    about,
    long_about,
    arg_required_else_help = true
)]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Subcommand, Debug)]
enum Command {
    Build(build::BuildArgs),
    Info(info::InfoArgs),
    Verify(verify::VerifyArgs),
    Collide(query::CollideArgs),
    Distance(query::DistanceArgs),
    Span(query::SpanArgs),
    Scene(scene::SceneArgs),
    Demo(demo::DemoArgs),
    Experiment(experiment::ExperimentArgs),
    Mesh(generate::MeshArgs),
    Poses(generate::PosesArgs),
}

/// A failure to report: one line, exit status 1.
#[derive(Debug)]
pub struct Failure(pub String);

impl<E: std::fmt::Display> From<E> for Failure {
    fn from(e: E) -> Self {
        Failure(e.to_string())
    }
}

/// Parses the arguments, runs the command, and maps the outcome to an exit status.
pub fn main() -> ExitCode {
    let cli = Cli::parse();
    files::handle_interrupts();
    let outcome = match cli.command {
        Command::Build(args) => build::run(&args),
        Command::Info(args) => info::run(&args),
        Command::Verify(args) => verify::run(&args),
        Command::Collide(args) => query::collide(&args),
        Command::Distance(args) => query::distance(&args),
        Command::Span(args) => query::span(&args),
        Command::Scene(args) => scene::run(&args).map(|_| ()),
        Command::Demo(args) => demo::run(&args),
        Command::Experiment(args) => experiment::run(&args),
        Command::Mesh(args) => generate::mesh(&args),
        Command::Poses(args) => generate::poses(&args),
    };
    match outcome {
        Ok(()) => ExitCode::SUCCESS,
        Err(Failure(message)) => {
            eprintln!("obbtree: error: {message}");
            ExitCode::from(1)
        }
    }
}

/// Runs `work` on rayon's global pool, or on a pool of `threads` threads when given
/// (`--threads N`).
pub fn with_threads<T: Send>(
    threads: Option<u32>,
    work: impl FnOnce() -> T + Send,
) -> Result<T, Failure> {
    match threads {
        None => Ok(work()),
        Some(n) => Ok(rayon::ThreadPoolBuilder::new()
            .num_threads(n as usize)
            .build()
            .map_err(|e| Failure(format!("--threads {n}: {e}")))?
            .install(work)),
    }
}

/// Bytes as a short human-readable size.
pub fn human_bytes(n: u64) -> String {
    let mut value = n as f64;
    let mut unit = "B";
    for larger in ["KiB", "MiB", "GiB"] {
        if value < 1024.0 {
            break;
        }
        value /= 1024.0;
        unit = larger;
    }
    if unit == "B" {
        format!("{n} B")
    } else {
        format!("{value:.1} {unit}")
    }
}

/// A number for people: the shortest decimals that read back exactly, in scientific
/// notation when they would be very long (1e300 prints as `1e300`, not 301 digits).
pub fn number(x: f64) -> String {
    let magnitude = x.abs();
    if x == 0.0 || !x.is_finite() || (1e-5..1e15).contains(&magnitude) {
        format!("{x}")
    } else {
        format!("{x:e}")
    }
}

/// A duration for people, in the unit that keeps it readable (`0.4 µs`, `12.5 ms`).
pub fn human_seconds(seconds: f64) -> String {
    if seconds < 1e-3 {
        format!("{:.1} µs", seconds * 1e6)
    } else if seconds < 1.0 {
        format!("{:.2} ms", seconds * 1e3)
    } else {
        format!("{seconds:.2} s")
    }
}
