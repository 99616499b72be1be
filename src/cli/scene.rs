//! `obbtree scene`: many models moving over frames, each pair answering only what its
//! rules ask for.

use super::print::{self, out};
use super::{human_seconds, Failure, WithContext};
use clap::Args;
use indicatif::{ProgressBar, ProgressDrawTarget, ProgressStyle};
use obbtree::scene::{load, Answer, EventKind, FrameReader, LoadedScene, Scene, Summary};
use std::io::{BufRead, BufReader, IsTerminal};
use std::path::PathBuf;
use std::time::{Duration, Instant};

/// Run a scene: objects moving over frames, every pair getting the effect its rules ask for, and no more work than that needs
///
/// The scene file (TOML) lists objects and rules; a pair of distinct objects gets the
/// effect of the last rule that matches it (either order), none without one:
///
///   frames = "cell.jsonl"          # optional: the frames to run
///
///   [[object]]
///   name = "link2"                 # unique; letters, digits, _ . -
///   asset = "link2.obbt"           # .obbt file or mesh, relative to the scene file
///   groups = ["robot"]             # optional
///   pose = [1,0,0, 0,1,0, 0,0,1, 0,0,0.4]   # optional start pose: R row-major, then T
///
///   [[rule]]
///   a = "robot"                    # object name, group name, or "*"
///   b = "fixtures"
///   effect = "clearance"           # none | contact | contacts | clearance | distance | span
///   clearance = 0.05               # required for clearance
///   # rel_err = 0.01               # optional for distance
///   # max_distance = 0.5           # optional for distance: beyond it, not listed
///
/// Frames are JSON Lines, one frame per line: {"poses": {"link2": [12 numbers], ...}}.
/// An object not named keeps its pose. Per frame the scheduler moves the world boxes of
/// the objects that moved, culls pairs with a sweep-and-prune broad phase, reuses answers
/// of pairs that did not move, and runs the cheapest query per remaining pair (first
/// contact, all contacts, tolerance, bounded and warm-started distance, span) in parallel.
///
/// Example: obbtree scene assets/scenes/cell.toml --json
#[derive(Args, Debug)]
#[command(verbatim_doc_comment)]
pub struct SceneArgs {
    /// The scene file (TOML).
    pub scene: PathBuf,
    /// Frames as JSON Lines, or - for standard input [default: the scene's `frames`, else
    /// one frame at the start poses].
    #[arg(long, value_name = "FILE|-")]
    pub frames: Option<String>,
    /// One JSON object per frame ({"frame", "pairs", "events"}), then {"summary": ...}.
    #[arg(long)]
    pub json: bool,
    /// The reference: every pair with an effect, its full exact query, every frame; no
    /// broad phase, no reuse, no warm start. Its answers define what the fast path prints.
    #[arg(long)]
    pub naive: bool,
    /// Print only the summary.
    #[arg(long)]
    pub summary_only: bool,
}

/// Runs the scene of `args`, prints what it asks for, and returns the summary.
pub fn run(args: &SceneArgs) -> Result<Summary, Failure> {
    let LoadedScene {
        mut scene,
        frames,
        pose_format,
        orthonormalize,
        repairs,
    } = load(&args.scene)?;
    super::poses::report(&repairs, &args.scene.display().to_string());
    scene.set_naive(args.naive);
    let input: Option<FramesInput> = match (args.frames.as_deref(), frames) {
        (Some("-"), _) => Some((Box::new(std::io::stdin().lock()), "-".into(), None)),
        (Some(path), _) => Some(open_frames(PathBuf::from(path))?),
        (None, Some(path)) => Some(open_frames(path)?),
        (None, None) => None,
    };
    let Some((reader, source, size)) = input else {
        // No frames: one frame at the start poses.
        show(&mut scene, args, &obbtree::scene::Frame::new())?;
        return finish(&scene, args);
    };
    let mut frames = FrameReader::new(reader, &source, &scene, pose_format, orthonormalize);
    let started = Instant::now();
    let mut bar: Option<ProgressBar> = None;
    while let Some(frame) = frames.next_frame() {
        show(&mut scene, args, &frame?)?;
        if print::closed() {
            break;
        }
        progress(&mut bar, size, frames.bytes_read(), started);
    }
    if let Some(bar) = bar {
        bar.finish_and_clear();
    }
    super::poses::report(frames.repairs(), &source);
    finish(&scene, args)
}

/// A frames input: the reader, its name in errors, and its size when it is a file.
type FramesInput = (Box<dyn BufRead>, String, Option<u64>);

fn open_frames(path: PathBuf) -> Result<FramesInput, Failure> {
    let name = path.display().to_string();
    let file = std::fs::File::open(&path).with_context(|| &name)?;
    let size = file.metadata().ok().map(|m| m.len());
    Ok((Box::new(BufReader::new(file)), name, size))
}

/// A progress bar on a terminal, by bytes of the frames file, once a run takes a second.
fn progress(bar: &mut Option<ProgressBar>, size: Option<u64>, done: u64, started: Instant) {
    let Some(total) = size else { return };
    if bar.is_none()
        && started.elapsed() > Duration::from_secs(1)
        && std::io::stderr().is_terminal()
    {
        let b = ProgressBar::with_draw_target(Some(total), ProgressDrawTarget::stderr());
        b.set_style(
            ProgressStyle::with_template("frames [{bar:40}] {percent}%, {eta} left")
                .unwrap_or_else(|_| ProgressStyle::default_bar())
                .progress_chars("=> "),
        );
        *bar = Some(b);
    }
    if let Some(b) = bar {
        b.set_position(done);
    }
}

/// Steps one frame and prints it: a JSON line, or its events as text.
fn show(scene: &mut Scene, args: &SceneArgs, frame: &obbtree::scene::Frame) -> Result<(), Failure> {
    let report = scene.step(frame)?.clone();
    if args.summary_only {
        return Ok(());
    }
    if args.json {
        return out!("{}", report.to_json(scene.names()));
    }
    let name = |i: usize| scene.names().get(i).map(String::as_str).unwrap_or("?");
    for e in &report.events {
        let what = match e.kind {
            EventKind::ContactStarted => "contact started",
            EventKind::ContactEnded => "contact ended",
            EventKind::ClearanceViolated => "clearance violated",
            EventKind::ClearanceRestored => "clearance restored",
        };
        let detail = report
            .pairs
            .iter()
            .find(|p| (p.a, p.b) == (e.a, e.b))
            .map(|p| match &p.answer {
                Answer::Contacts(pairs) => format!(" ({} triangle pairs)", pairs.len()),
                Answer::Closer { distance, .. } => format!(" (at {distance:.4})"),
                _ => String::new(),
            })
            .unwrap_or_default();
        out!(
            "frame {:>6}  {} / {}: {what}{detail}",
            report.frame,
            name(e.a),
            name(e.b)
        )?;
    }
    Ok(())
}

fn finish(scene: &Scene, args: &SceneArgs) -> Result<Summary, Failure> {
    let s = *scene.summary();
    let mode = if args.naive { "naive" } else { "fast" };
    if args.json {
        out!("{}", s.to_json(mode))?;
    } else {
        print_summary(&s, mode)?;
    }
    Ok(s)
}

/// The summary as a table: what was skipped, then the narrow work by effect.
pub fn print_summary(s: &Summary, mode: &str) -> Result<(), Failure> {
    let pair_frames = s.pairs_with_effect * s.frames;
    out!("summary ({mode})")?;
    out!("  frames               {}", s.frames)?;
    out!("  objects              {}", s.objects)?;
    out!(
        "  pairs with an effect {} ({pair_frames} pair-frames)",
        s.pairs_with_effect
    )?;
    out!("  culled (broad phase) {}", s.culled)?;
    out!("  reused answers       {}", s.reused)?;
    out!("  early exits          {}", s.early_exits)?;
    out!("  warm starts          {}", s.warm_starts)?;
    out!(
        "  time                 {} ({:.0} frames per second)",
        human_seconds(s.seconds),
        s.frames_per_second()
    )?;
    out!(
        "  {:<10} {:>10} {:>12} {:>14} {:>12}",
        "narrow",
        "queries",
        "box tests",
        "triangle tests",
        "time"
    )?;
    let total = s.narrow.total();
    for (name, w) in s.narrow.by_effect().into_iter().chain([("total", &total)]) {
        out!(
            "  {name:<10} {:>10} {:>12} {:>14} {:>12}",
            w.queries,
            w.box_tests,
            w.triangle_tests,
            human_seconds(w.seconds)
        )?;
    }
    Ok(())
}
