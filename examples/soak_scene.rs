//! Soak run of a large scene: many objects over many frames, resident memory sampled as it
//! goes, and sampled frames answered again by a fresh scene (no history, no warm starts)
//! that must agree with the long-running one.
//!
//! ```sh
//! cargo run --release --example soak_scene -- [OBJECTS [FRAMES [CHECKS]]]
//! ```
//!
//! Defaults: 10,000 objects (the shipped cell's trees, on a 100 × 100 grid in a slab, ten
//! groups with rules of every effect), 100,000 frames in which every tenth object drifts
//! and turns among its neighbours, 20 checked frames. Prints one JSON line per memory
//! sample (`frame`, `rss_mib`, `frames_per_second` since the last sample) and a summary
//! line: resident memory at the end of warm-up (the first tenth of the frames) and its
//! largest value after, the checks and how many agreed. Exits with status 1 if a checked
//! frame disagrees.
// An example: a failed setup is a failed run, reported by the panic.
#![allow(clippy::unwrap_used, clippy::expect_used, clippy::indexing_slicing)]

use nalgebra::{Rotation3, Unit, Vector3};
use obbtree::format::ObbtFile;
use obbtree::query::Pose;
use obbtree::scene::{Effect, Frame, FrameReport, Scene, SceneBuilder};
use std::sync::Arc;
use std::time::Instant;

/// Grid spacing (world units): the cell's trees are about a unit across, so a drifting
/// object meets its neighbours now and then.
const SPACING: f64 = 2.0;
/// One object in this many moves.
const MOVER_EVERY: usize = 10;

/// Resident memory of this process (MiB), from `/proc/self/statm`.
fn rss_mib() -> f64 {
    let statm = std::fs::read_to_string("/proc/self/statm").unwrap_or_default();
    let pages: f64 = statm
        .split_whitespace()
        .nth(1)
        .and_then(|p| p.parse().ok())
        .unwrap_or(f64::NAN);
    pages * 4096.0 / (1024.0 * 1024.0)
}

/// Where object `k` starts: a 100-wide grid, heights and turns from its index.
fn start_pose(k: usize) -> Pose {
    let (i, j) = ((k % 100) as f64, (k / 100) as f64);
    let z = (k as f64 * 0.37).sin();
    let axis = Unit::new_normalize(Vector3::new((k as f64).cos(), (k as f64).sin(), 1.0));
    let r = Rotation3::from_axis_angle(&axis, k as f64 * 0.9);
    Pose::new(*r.matrix(), Vector3::new(i * SPACING, j * SPACING, z)).unwrap()
}

/// Mover `k` at frame `f`: a slow drift of up to 1.2 around its start and a turn.
fn mover_pose(k: usize, f: usize) -> Pose {
    let start = start_pose(k);
    let t = f as f64 * 0.02;
    let phase = k as f64 * 0.7;
    let drift = Vector3::new(
        1.2 * (t + phase).sin(),
        1.2 * (1.3 * t + phase).cos(),
        0.3 * (0.7 * t).sin(),
    );
    let axis = Unit::new_normalize(Vector3::new(1.0, phase.sin(), phase.cos()));
    let turn = Rotation3::from_axis_angle(&axis, 0.5 * t);
    Pose::new(
        turn.matrix() * start.rotation(),
        start.translation_vector() + drift,
    )
    .unwrap()
}

fn frame(f: usize, objects: usize) -> Frame {
    let mut frame = Frame::new();
    for k in (0..objects).step_by(MOVER_EVERY) {
        frame.set(k, mover_pose(k, f));
    }
    frame
}

fn builder(objects: usize) -> SceneBuilder {
    let dir = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("assets/scenes");
    let assets: Vec<Arc<ObbtFile>> = ["cow", "link1", "link2", "link3", "gripper", "post"]
        .iter()
        .map(|n| Arc::new(ObbtFile::open(dir.join(format!("{n}.obbt"))).unwrap()))
        .collect();
    let mut builder = SceneBuilder::new();
    for k in 0..objects {
        let group = format!("g{}", k % 10);
        let asset = assets[k % assets.len()].clone();
        builder.object(&format!("o{k}"), asset, &[&group], start_pose(k));
    }
    // Movers are the objects of group g0; each other group gets one effect against them.
    let effects = [
        Effect::Contacts,
        Effect::Contact,
        Effect::Clearance { clearance: 0.05 },
        Effect::Distance {
            rel_err: 0.0,
            max_distance: Some(0.5),
        },
        Effect::Distance {
            rel_err: 0.01,
            max_distance: Some(1.0),
        },
        Effect::Contact,
        Effect::Clearance { clearance: 0.2 },
        Effect::None,
        Effect::Contact,
    ];
    builder.rule("g0", "g0", Effect::Contact);
    for (g, effect) in effects.into_iter().enumerate() {
        builder.rule("g0", &format!("g{}", g + 1), effect);
    }
    builder
}

/// The long run's report of a frame against a fresh scene's, events aside (a fresh scene
/// has no previous frame to differ from).
fn check(report: &FrameReport, fresh: &mut Scene, f: usize, objects: usize) -> Option<String> {
    let mut all = frame(f, objects);
    // A fresh scene starts at the start poses, which the static objects keep.
    for k in (0..objects).filter(|k| k % MOVER_EVERY != 0) {
        all.set(k, start_pose(k));
    }
    let mut want = fresh.step(&all).expect("the fresh scene steps").clone();
    let mut got = report.clone();
    got.events.clear();
    want.events.clear();
    want.frame = got.frame;
    got.disagreement(&want, |a, b| fresh.effect(a, b))
}

fn main() {
    let args: Vec<usize> = std::env::args()
        .skip(1)
        .map(|a| a.parse().expect("OBJECTS FRAMES CHECKS are counts"))
        .collect();
    let objects = args.first().copied().unwrap_or(10_000);
    let frames = args.get(1).copied().unwrap_or(100_000);
    let checks = args.get(2).copied().unwrap_or(20).max(1);
    let sample_every = (frames / 200).max(1);
    let warm_up = frames / 10;
    let check_every = (frames / checks).max(1);

    let builder = builder(objects);
    let mut scene = builder.clone().build().unwrap();
    let (mut rss_warm, mut rss_max_after) = (f64::NAN, 0.0f64);
    let (mut checked, mut agreed) = (0, 0);
    let mut window = Instant::now();
    let started = Instant::now();
    for f in 0..frames {
        let report = scene.step(&frame(f, objects)).unwrap();
        if f % check_every == check_every / 2 {
            let mut fresh = builder.clone().build().unwrap();
            checked += 1;
            match check(report, &mut fresh, f, objects) {
                None => agreed += 1,
                Some(d) => eprintln!("soak_scene: frame {f} disagrees with a fresh scene: {d}"),
            }
        }
        if (f + 1) % sample_every == 0 {
            let rss = rss_mib();
            if f + 1 == warm_up.max(sample_every) {
                rss_warm = rss;
            } else if f + 1 > warm_up {
                rss_max_after = rss_max_after.max(rss);
            }
            let fps = sample_every as f64 / window.elapsed().as_secs_f64();
            window = Instant::now();
            println!(
                "{}",
                serde_json::json!({"frame": f + 1, "rss_mib": rss, "frames_per_second": fps})
            );
        }
    }
    let summary = scene.summary();
    println!(
        "{}",
        serde_json::json!({
            "objects": objects,
            "frames": frames,
            "seconds": started.elapsed().as_secs_f64(),
            "narrow_queries": summary.narrow.total().queries,
            "pairs_with_effect": summary.pairs_with_effect,
            "rss_mib_after_warm_up": rss_warm,
            "rss_mib_max_after_warm_up": rss_max_after,
            "checked_frames": checked,
            "agreed": agreed,
        })
    );
    if agreed != checked {
        std::process::exit(1);
    }
}
