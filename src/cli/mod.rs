//! Command-line interface. Every command is a few calls into the library plus printing;
//! errors become one line on stderr and exit status 1 (usage errors: 2, from clap).

mod build;
mod closest;
mod demo;
mod experiment;
mod files;
mod generate;
mod info;
mod input;
mod inside;
mod plot;
mod poses;
mod print;
mod progress;
mod query;
mod ray;
mod rows;
mod scene;
mod verify;

use clap::{Parser, Subcommand};
use obbtree::query::QueryError;
use obbtree::scene::SceneError;
use std::error::Error;
use std::fmt::{self, Display};
use std::num::NonZeroUsize;
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
    Hausdorff(query::HausdorffArgs),
    Closest(closest::ClosestArgs),
    Ray(ray::RayArgs),
    Inside(inside::InsideArgs),
    Scene(scene::SceneArgs),
    Demo(demo::DemoArgs),
    Experiment(experiment::ExperimentArgs),
    Mesh(generate::MeshArgs),
    Poses(generate::PosesArgs),
}

/// A failure to report: the typed error that stopped the command, with its `source()`
/// chain, printed on one line as `obbtree: error: outer: cause: cause` (exit status 1).
///
/// Every error converts into it with `?`, keeping its type (so nothing a library error
/// carries is flattened into a string before it is printed). It is deliberately not an
/// `Error` itself: that is what lets the blanket `From` below coexist with `From<T> for T`.
#[derive(Debug)]
pub struct Failure {
    error: Box<dyn Error + Send + Sync + 'static>,
}

impl Failure {
    /// A failure that is only a message, with no typed cause.
    pub fn msg(message: impl Into<String>) -> Failure {
        Failure {
            error: message.into().into(),
        }
    }

    /// This failure with `context` in front: it prints as `context: failure`, and the
    /// typed error stays the cause.
    pub fn context(self, context: impl Display) -> Failure {
        Failure {
            error: Box::new(Context {
                context: context.to_string(),
                source: self.error,
            }),
        }
    }
}

impl<E: Error + Send + Sync + 'static> From<E> for Failure {
    fn from(error: E) -> Self {
        Failure {
            error: Box::new(error),
        }
    }
}

/// The whole chain, joined with `: `. Each error in it shows only its own part and leaves
/// its cause to `source()`, so no text appears twice; a [`SceneError`] is the exception
/// its doc states (its message is complete, located in the scene file, with the cause's
/// text), so the chain stops there.
///
/// A query's option is named by its flag (`--rel-err`), not its field (`rel_err`): each
/// option of the library's queries is a flag of the same name here.
impl Display for Failure {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let mut error: &(dyn Error + 'static) = &*self.error;
        match error.downcast_ref::<QueryError>() {
            Some(e @ QueryError::BadOption { name, .. }) => {
                let text = e.to_string();
                let rest = text.strip_prefix(name).unwrap_or(&text);
                write!(f, "--{}{rest}", name.replace('_', "-"))?;
            }
            _ => write!(f, "{error}")?,
        }
        while let (None, Some(cause)) = (error.downcast_ref::<SceneError>(), error.source()) {
            write!(f, ": {cause}")?;
            error = cause;
        }
        Ok(())
    }
}

/// What [`Failure::context`] puts in front of an error.
#[derive(Debug, thiserror::Error)]
#[error("{context}")]
struct Context {
    context: String,
    source: Box<dyn Error + Send + Sync + 'static>,
}

/// [`Failure::context`] for a `Result`, the context computed only when it failed.
pub trait WithContext<T> {
    /// The error, made a [`Failure`], with `context()` in front.
    fn with_context<C: Display>(self, context: impl FnOnce() -> C) -> Result<T, Failure>;
}

impl<T, E: Into<Failure>> WithContext<T> for Result<T, E> {
    fn with_context<C: Display>(self, context: impl FnOnce() -> C) -> Result<T, Failure> {
        self.map_err(|error| error.into().context(context()))
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
        Command::Hausdorff(args) => query::hausdorff(&args),
        Command::Closest(args) => closest::run(&args),
        Command::Ray(args) => ray::run(&args),
        Command::Inside(args) => inside::run(&args),
        Command::Scene(args) => scene::run(&args).map(|_| ()),
        Command::Demo(args) => demo::run(&args),
        Command::Experiment(args) => experiment::run(&args),
        Command::Mesh(args) => generate::mesh(&args),
        Command::Poses(args) => generate::poses(&args),
    };
    match outcome {
        Ok(()) => ExitCode::SUCCESS,
        Err(failure) => {
            // One line whatever the error quotes: a path or a name may hold a newline.
            let mut text = String::new();
            for c in failure.to_string().chars() {
                match c.is_control() {
                    true => text.extend(c.escape_default()),
                    false => text.push(c),
                }
            }
            eprintln!("obbtree: error: {text}");
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
    let threads = threads.and_then(|n| NonZeroUsize::new(usize::try_from(n).ok()?));
    Ok(obbtree::query::on_threads(threads, work)?)
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

#[cfg(test)]
mod tests {
    use super::*;
    use obbtree::experiment::ExperimentError;
    use obbtree::format::{ObbtFile, VerifyError};
    use obbtree::mesh::TriMesh;
    use std::path::Path;

    #[test]
    fn the_chain_joins_context_error_and_causes() {
        let levels = ExperimentError::Levels(VerifyError {
            region: "padding".into(),
            problem: "byte 7 is not 0".into(),
        });
        let failure = Failure::from(levels).context("proximity");
        assert_eq!(
            failure.to_string(),
            "proximity: measuring a tree's levels: padding: byte 7 is not 0"
        );
        let failure: Result<(), _> = Err(Failure::msg("inner")).with_context(|| "outer");
        assert_eq!(
            failure.map_err(|f| f.to_string()),
            Err("outer: inner".into())
        );
    }

    /// Errors whose message already ends with their cause's text must not return the cause
    /// from `source()` too, or the chain would show it twice.
    #[test]
    fn causes_in_the_message_are_printed_once() {
        let missing = Path::new("no-such-dir/missing.obbt");
        let os_error = std::fs::read(missing).unwrap_err().to_string();
        let Err(open) = ObbtFile::open(missing) else {
            panic!("opened {missing:?}")
        };
        let Err(load) = TriMesh::load(missing) else {
            panic!("loaded {missing:?}")
        };
        let cases = [
            (open.to_string(), Failure::from(open)),
            (load.to_string(), Failure::from(load)),
        ];
        for (message, failure) in cases {
            assert!(message.ends_with(&os_error), "{message}");
            assert_eq!(failure.to_string(), message);
        }
    }
}
