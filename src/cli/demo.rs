//! `obbtree demo`: the main job on the bundled asset, end to end.

use super::build::build_with_progress;
use super::files::check_output;
use super::print::out;
use super::scene::SceneArgs;
use super::{human_bytes, human_seconds, Failure, WithContext};
use clap::Args;
use nalgebra::{Rotation3, Vector3};
use obbtree::build::BuildOptions;
use obbtree::bv::BvKind;
use obbtree::format::{write_atomic, ObbtFile};
use obbtree::mesh::TriMesh;
use obbtree::query::{CollideOptions, DistanceOptions, PairQuery, Pose, SpanOptions};
use obbtree::scene::{load, FrameReader, LoadedScene};
use std::io::BufReader;
use std::path::PathBuf;
use std::time::Instant;

/// The bundled asset, compiled in so the demo runs from any directory.
const COW_OBJ: &[u8] = include_bytes!("../../assets/cow.obj");

/// The shipped robot cell (`assets/scenes/`), compiled in: its scene file, frames and
/// precomputed trees, written out next to the demo's files and run from there.
const CELL: [(&str, &[u8]); 11] = [
    ("cell.toml", include_bytes!("../../assets/scenes/cell.toml")),
    (
        "cell.jsonl",
        include_bytes!("../../assets/scenes/cell.jsonl"),
    ),
    ("base.obbt", include_bytes!("../../assets/scenes/base.obbt")),
    (
        "link1.obbt",
        include_bytes!("../../assets/scenes/link1.obbt"),
    ),
    (
        "link2.obbt",
        include_bytes!("../../assets/scenes/link2.obbt"),
    ),
    (
        "link3.obbt",
        include_bytes!("../../assets/scenes/link3.obbt"),
    ),
    (
        "gripper.obbt",
        include_bytes!("../../assets/scenes/gripper.obbt"),
    ),
    (
        "table.obbt",
        include_bytes!("../../assets/scenes/table.obbt"),
    ),
    (
        "fence.obbt",
        include_bytes!("../../assets/scenes/fence.obbt"),
    ),
    ("post.obbt", include_bytes!("../../assets/scenes/post.obbt")),
    ("cow.obbt", include_bytes!("../../assets/scenes/cow.obbt")),
];

/// Run the whole pipeline on the bundled cow mesh (5,804 triangles).
///
/// Builds a tree with each bounding volume, writes the files into a directory, opens them
/// memory-mapped, verifies them, prints what it built, then runs collision, distance and
/// span queries between two posed copies, and last the shipped robot cell's scene, fast and
/// then checked against the naive run.
#[derive(Args, Debug)]
pub struct DemoArgs {
    /// Keep the built files in this directory (default: a temporary one, removed at the end).
    #[arg(long, value_name = "DIR")]
    pub out: Option<PathBuf>,
}

pub fn run(args: &DemoArgs) -> Result<(), Failure> {
    let (dir, temporary) = match &args.out {
        Some(d) => (d.clone(), false),
        None => (
            std::env::temp_dir().join(format!("obbtree-demo-{}", std::process::id())),
            true,
        ),
    };
    // Only the directory itself is made: a mistyped parent is reported, not created.
    match std::fs::create_dir(&dir) {
        Err(e) if e.kind() == std::io::ErrorKind::AlreadyExists && !dir.is_dir() => {
            return Err(Failure::msg(format!(
                "{}: exists and is not a directory",
                dir.display()
            )))
        }
        Err(e) if e.kind() != std::io::ErrorKind::AlreadyExists => {
            return Err(Failure::from(e).context(format!("{}: cannot create", dir.display())))
        }
        _ => {}
    }
    let result = run_in(&dir);
    if temporary {
        let _ = std::fs::remove_dir_all(&dir);
        result?;
        out!("inspect a file with: obbtree info <file>   (run with --out DIR to keep the files)")?;
        return Ok(());
    }
    result?;
    out!("inspect a file with: obbtree info <file>")?;
    Ok(())
}

fn run_in(dir: &std::path::Path) -> Result<(), Failure> {
    let mesh = TriMesh::from_obj_bytes(COW_OBJ, "cow.obj")?;
    out!(
        "obbtree demo: bundled mesh cow.obj, {} triangles, {} vertices ({} zero-area)",
        mesh.faces().len(),
        mesh.vertices().len(),
        mesh.degenerate_triangle_count()
    )?;
    out!("writing into {}", dir.display())?;
    for bv in BvKind::ALL {
        let options = BuildOptions {
            bv,
            ..BuildOptions::default()
        };
        let started = Instant::now();
        let built = build_with_progress(&mesh, &options, "cow.obj", true)?;
        let build_ms = started.elapsed().as_secs_f64() * 1e3;
        let path = dir.join(format!("cow-{}.obbt", bv.name()));
        check_output(&path, &[], false)?;
        built.write_atomic(&path).with_context(|| path.display())?;
        let started = Instant::now();
        let opened = ObbtFile::open(&path)?;
        let open_us = started.elapsed().as_secs_f64() * 1e6;
        let started = Instant::now();
        opened.verify().with_context(|| path.display())?;
        let verify_ms = started.elapsed().as_secs_f64() * 1e3;
        let same = opened.bytes() == built.bytes();
        let info = opened.info();
        out!(
            "  {:<6} {:>9}  {} nodes, depth {:>2}  built {:>6.1} ms, opened {:>6.1} us, verified {:>5.1} ms, file == memory: {}",
            bv.name(),
            human_bytes(info.file_bytes),
            info.nodes,
            info.stats.shape.depth,
            build_ms,
            open_us,
            verify_ms,
            if same { "yes" } else { "NO" }
        )?;
        if !same {
            return Err(Failure::msg(format!(
                "{}: the file read back differs from the tree built",
                path.display()
            )));
        }
    }
    run_queries(&dir.join("cow-obb.obbt"))?;
    run_cell(&dir.join("cell"))?;
    Ok(())
}

/// The shipped robot cell, fast and then as the naive reference.
fn run_cell(dir: &std::path::Path) -> Result<(), Failure> {
    std::fs::create_dir_all(dir).with_context(|| dir.display())?;
    for (name, bytes) in CELL {
        let path = dir.join(name);
        // A file already holding these bytes (an earlier demo) is left as it is; anything
        // else follows the rules of every output.
        if std::fs::read(&path).is_ok_and(|old| old == bytes) {
            continue;
        }
        check_output(&path, &[], false)?;
        write_atomic(&path, bytes).with_context(|| path.display())?;
    }
    out!(
        "scene: the shipped robot cell (an arm sweeping past a fence to a part on a table; obbtree scene {}):",
        dir.join("cell.toml").display()
    )?;
    let scene = dir.join("cell.toml");
    let fast = super::scene::run(&SceneArgs {
        scene: scene.clone(),
        frames: None,
        json: false,
        naive: false,
        summary_only: false,
    })?;
    // The reference, in lockstep with a second fast run, frame by frame.
    let load = |naive: bool| -> Result<LoadedScene, Failure> {
        let mut loaded = load(&scene)?;
        loaded.scene.set_naive(naive);
        Ok(loaded)
    };
    let (mut quick, mut reference) = (load(false)?, load(true)?);
    let frames_path = quick
        .frames
        .clone()
        .unwrap_or_else(|| dir.join("cell.jsonl"));
    let file = std::fs::File::open(&frames_path).with_context(|| frames_path.display())?;
    let source = frames_path.display().to_string();
    let format = (quick.pose_format, quick.orthonormalize);
    let frames = FrameReader::new(
        BufReader::new(file),
        &source,
        &quick.scene,
        format.0,
        format.1,
    );
    let mut compared = 0;
    for frame in frames {
        let frame = frame?;
        let got = quick.scene.step(&frame)?.clone();
        let want = reference.scene.step(&frame)?;
        if let Some(d) = got.disagreement(want, |a, b| quick.scene.effect(a, b)) {
            return Err(Failure::msg(format!(
                "the scheduler and the reference disagree: {d}"
            )));
        }
        compared += 1;
    }
    let naive = reference.scene.summary();
    out!(
        "the naive reference ran {} narrow queries at {:.0} frames per second; the scheduler {} ({:.0}x the frames per second), with the same answers on all {compared} frames",
        naive.narrow.total().queries,
        naive.frames_per_second(),
        fast.narrow.total().queries,
        fast.frames_per_second() / naive.frames_per_second()
    )
}

/// The queries between two copies of the cow, the second turned and slid along x, through
/// the pair object an application would keep.
fn run_queries(path: &std::path::Path) -> Result<(), Failure> {
    let cow = ObbtFile::open(path)?;
    let extent = cow.info().stats.bounds_max[0] - cow.info().stats.bounds_min[0];
    let mut pair = PairQuery::new(&cow, &cow)?;
    let a = Pose::identity();
    let first_contact = CollideOptions {
        first_contact: true,
        ..CollideOptions::default()
    };
    out!("queries between two cows (A fixed, B turned 30 degrees about z and moved along x; lengths in model units):")?;
    for shift in [0.25, 0.6, 1.5] {
        let rotation = *Rotation3::from_euler_angles(0.0, 0.0, 30f64.to_radians()).matrix();
        let b = Pose::new(rotation, Vector3::new(shift * extent, 0.0, 0.0))?;
        let timed = Instant::now();
        let all = pair.collide(&a, &b, &CollideOptions::default())?;
        let collide = human_seconds(timed.elapsed().as_secs_f64());
        let timed = Instant::now();
        let any = pair.collide(&a, &b, &first_contact)?;
        let first = human_seconds(timed.elapsed().as_secs_f64());
        let timed = Instant::now();
        let gap = pair.distance(&a, &b, &DistanceOptions::default())?;
        let distance = human_seconds(timed.elapsed().as_secs_f64());
        let timed = Instant::now();
        let far = pair.span(&a, &b, &SpanOptions::default())?;
        let span = human_seconds(timed.elapsed().as_secs_f64());
        out!(
            "  B at x = {:.3}: {} contacts ({collide}; first contact {} in {first}), distance {:.4} ({distance}), span {:.4} ({span})",
            shift * extent,
            all.pairs.len(),
            if any.colliding { "found" } else { "none" },
            gap.distance(),
            far.span(),
        )?;
    }
    Ok(())
}
