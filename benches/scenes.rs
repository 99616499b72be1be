//! Scene benchmarks (`cargo bench --bench scenes`), printed as tables:
//!
//! - (a) 200 objects from the shipped cell's trees (arm links, gripper, fixtures, the
//!   cow), 20 groups of 10, the 210 pairs of groups given `none` (147), `contact` (42),
//!   `clearance` 0.05 (17), `distance` (4: two limited to 2 units, two unlimited with
//!   `rel_err` 0.01); 50 objects move coherently, 150 are static; 1,000 frames. Frames
//!   per second of the fast path, and of `--naive` on the first frames (its answers
//!   checked identical there), in one run.
//! - (b) The broad phase alone: 10,000 boxes moving coherently, milliseconds per frame.
//! - (c) Distance over a smooth trajectory of two bunnies (`../shared/meshes/bunny.obj`;
//!   the cow when it is missing), warm-started from the previous frame's pair against
//!   cold: time and work.
// A benchmark of known-good inputs: a setup that fails is a broken benchmark, not bad input.
#![allow(clippy::unwrap_used, clippy::panic, clippy::indexing_slicing)]

#[path = "../tests/common/mod.rs"]
mod common;

use nalgebra::{Rotation3, Unit, Vector3};
use obbtree::build::{build, BuildOptions};
use obbtree::format::ObbtFile;
use obbtree::query::{DistanceOptions, PairQuery, Pose};
use obbtree::scene::broad::{Bounds, SweepAndPrune};
use obbtree::scene::{Effect, Frame, Scene, SceneBuilder};
use std::sync::Arc;
use std::time::Instant;

/// xorshift in [0, 1).
struct Random(u64);

impl Random {
    fn next(&mut self) -> f64 {
        self.0 ^= self.0 << 13;
        self.0 ^= self.0 >> 7;
        self.0 ^= self.0 << 17;
        (self.0 >> 11) as f64 / (1u64 << 53) as f64
    }
}

fn median(mut v: Vec<f64>) -> f64 {
    v.sort_by(f64::total_cmp);
    v[v.len() / 2]
}

/// The pose of mover `k` at frame `f`: a slow Lissajous drift and turn.
fn mover_pose(k: usize, f: usize, origin: Vector3<f64>) -> Pose {
    let t = f as f64 * 0.01;
    let phase = k as f64 * 0.7;
    let offset = Vector3::new(
        1.5 * (t + phase).sin(),
        1.5 * (1.3 * t + phase).cos(),
        0.3 * (0.7 * t).sin(),
    );
    let axis = Unit::new_normalize(Vector3::new(1.0, phase.sin(), phase.cos()));
    let r = Rotation3::from_axis_angle(&axis, 0.5 * t + phase);
    Pose::new(*r.matrix(), origin + offset).unwrap()
}

fn many_objects() -> (Scene, Scene, Vec<Vector3<f64>>) {
    let dir = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("assets/scenes");
    let assets: Vec<Arc<ObbtFile>> = [
        "cow", "link1", "link2", "link3", "gripper", "table", "post", "base",
    ]
    .iter()
    .map(|n| Arc::new(ObbtFile::open(dir.join(format!("{n}.obbt"))).unwrap()))
    .collect();
    let mut random = Random(0x5eed);
    let mut builder = SceneBuilder::new();
    let mut origins = Vec::new();
    for k in 0..200 {
        let origin = Vector3::new(
            random.next() * 14.0,
            random.next() * 14.0,
            random.next() * 2.0,
        );
        let r = common::rng::seeded_rotation(k as u64);
        let group = format!("g{}", k % 20);
        let asset = assets[k % assets.len()].clone();
        builder.object(
            &format!("o{k}"),
            asset,
            &[&group],
            Pose::new(r, origin).unwrap(),
        );
        origins.push(origin);
    }
    // Effects of the 210 group pairs, in the stated proportions, placed at random; the
    // distance rules alternate between a range sensor (limited to 2, exact) and an
    // unlimited distance within 1%.
    let mut effects: Vec<Effect> = (0..210)
        .map(|k| match k {
            0..147 => Effect::None,
            147..189 => Effect::Contact,
            189..206 => Effect::Clearance { clearance: 0.05 },
            k if k % 2 == 0 => Effect::Distance {
                rel_err: 0.0,
                max_distance: Some(2.0),
            },
            _ => Effect::Distance {
                rel_err: 0.01,
                max_distance: None,
            },
        })
        .collect();
    for k in (1..effects.len()).rev() {
        let swap = (random.next() * (k + 1) as f64) as usize;
        effects.swap(k, swap);
    }
    let mut effects = effects.into_iter();
    for i in 0..20 {
        for j in i..20 {
            let effect = effects.next().unwrap_or(Effect::None);
            builder.rule(&format!("g{i}"), &format!("g{j}"), effect);
        }
    }
    let fast = builder.clone().build().unwrap();
    let mut naive = builder.build().unwrap();
    naive.set_naive(true);
    (fast, naive, origins)
}

fn frame(f: usize, origins: &[Vector3<f64>]) -> Frame {
    let mut frame = Frame::new();
    // Every fourth object moves.
    for (k, origin) in origins.iter().enumerate().step_by(4) {
        frame.set(k, mover_pose(k, f, *origin));
    }
    frame
}

fn scene_benchmark() {
    let (mut fast, mut naive, origins) = many_objects();
    const FRAMES: usize = 1000;
    const NAIVE_FRAMES: usize = 10;
    let mut fast_times = Vec::new();
    let mut checked = 0;
    for f in 0..FRAMES {
        let frame = frame(f, &origins);
        let started = Instant::now();
        let report = fast.step(&frame).unwrap().clone();
        fast_times.push(started.elapsed().as_secs_f64());
        if f < NAIVE_FRAMES {
            let reference = naive.step(&frame).unwrap();
            if let Some(d) = report.disagreement(reference, |a, b| fast.effect(a, b)) {
                panic!("fast and naive disagree: {d}");
            }
            checked += 1;
        }
    }
    let s = fast.summary();
    let n = naive.summary();
    let fast_fps = s.frames_per_second();
    let naive_fps = n.frames_per_second();
    println!("\n(a) 200 objects, 20 groups, rules none 70% / contact 20% / clearance 8% / distance 2%, 50 moving:");
    println!("  pairs with an effect      {}", s.pairs_with_effect);
    println!(
        "  fast   {:>6} frames: {:>10.1} frames/s (median frame {:.3} ms); narrow {} ({} per frame), culled {}, reused {}, warm starts {}",
        s.frames,
        fast_fps,
        median(fast_times) * 1e3,
        s.narrow.total().queries,
        s.narrow.total().queries / s.frames,
        s.culled,
        s.reused,
        s.warm_starts
    );
    for (name, w) in s.narrow.by_effect() {
        println!(
            "         {name:<9} {:>6} queries, {:>9} box tests, {:>8} triangle tests, {:>8.1} ms",
            w.queries,
            w.box_tests,
            w.triangle_tests,
            w.seconds * 1e3
        );
    }
    println!(
        "  naive  {:>6} frames: {:>10.1} frames/s; narrow {} per frame",
        n.frames,
        naive_fps,
        n.narrow.total().queries / n.frames.max(1)
    );
    println!(
        "  fast / naive: {:.0}x faster, answers identical on the {checked} frames both ran",
        fast_fps / naive_fps
    );
}

/// 10,000 boxes of side 1.2 in a 100 x 100 x 20 slab (wide and flat, like a level or a
/// cell), every box moving each frame with a constant velocity of up to `speed` per axis.
fn broad_phase_run(speed: f64) -> (f64, f64, f64) {
    const BOXES: usize = 10_000;
    let mut random = Random(42);
    let side = 100.0;
    let centres: Vec<[f64; 3]> = (0..BOXES)
        .map(|_| {
            [
                random.next() * side,
                random.next() * side,
                random.next() * side * 0.2,
            ]
        })
        .collect();
    let velocities: Vec<[f64; 3]> = (0..BOXES)
        .map(|_| [random.next(), random.next(), random.next()].map(|v| (v - 0.5) * 2.0 * speed))
        .collect();
    let half = 0.6;
    let bounds = |c: &[f64; 3]| -> Bounds { [c.map(|v| v - half), c.map(|v| v + half)] };
    let started = Instant::now();
    let mut sap = SweepAndPrune::new(centres.iter().map(bounds).collect(), |_, _| true);
    let setup = started.elapsed().as_secs_f64();
    let mut times = Vec::new();
    let mut pairs = 0.0;
    let mut positions = centres;
    const FRAMES: usize = 200;
    for _ in 0..FRAMES {
        for (p, v) in positions.iter_mut().zip(&velocities) {
            for k in 0..3 {
                p[k] += v[k];
            }
        }
        let started = Instant::now();
        for (i, p) in positions.iter().enumerate() {
            sap.set_box(i as u32, bounds(p));
        }
        sap.update(|_, _| true);
        times.push(started.elapsed().as_secs_f64());
        pairs += sap.overlap_count() as f64;
    }
    (median(times), setup, pairs / FRAMES as f64)
}

fn broad_phase_benchmark() {
    println!("\n(b) broad phase alone: 10,000 boxes (side 1.2), all moving, 200 frames:");
    for speed in [0.005, 0.025] {
        let (frame, setup, pairs) = broad_phase_run(speed);
        println!(
            "  up to {speed} per axis per frame ({:.1}% of a box): {:.3} ms per frame (median; setup {:.1} ms), {pairs:.0} overlapping pairs",
            speed / 1.2 * 100.0,
            frame * 1e3,
            setup * 1e3
        );
    }
}

fn warm_start_benchmark() {
    let (mesh, name) = match common::shared_mesh("bunny.obj") {
        Some(m) => (m, "bunny"),
        None => (common::cow(), "cow"),
    };
    let file = build(&mesh, &BuildOptions::default(), None).unwrap();
    let mut pair = PairQuery::new(&file, &file).unwrap();
    let poses: Vec<Pose> = (0..300)
        .map(|k| {
            let t = k as f64 * 0.01;
            let r = Rotation3::from_euler_angles(0.3 * t, 0.5 * t, t);
            Pose::new(
                *r.matrix(),
                Vector3::new(1.15 + 0.1 * (3.0 * t).sin(), 0.2 * t.sin(), 0.1 * t),
            )
            .unwrap()
        })
        .collect();
    let identity = Pose::identity();
    let mut cold_times = Vec::new();
    let mut warm_times = Vec::new();
    let (mut cold_tests, mut warm_tests) = (0u64, 0u64);
    let mut previous = None;
    for pose in &poses {
        let started = Instant::now();
        let cold = pair
            .distance(&identity, pose, &DistanceOptions::default())
            .unwrap();
        cold_times.push(started.elapsed().as_secs_f64());
        let options = DistanceOptions {
            warm_start: previous,
            ..DistanceOptions::default()
        };
        let started = Instant::now();
        let warm = pair.distance(&identity, pose, &options).unwrap();
        warm_times.push(started.elapsed().as_secs_f64());
        assert_eq!(warm.distance(), cold.distance());
        previous = warm.warm_start;
        cold_tests += cold.work.bv_disjoint + cold.work.bv_overlap;
        warm_tests += warm.work.bv_disjoint + warm.work.bv_overlap;
    }
    let (cold, warm) = (median(cold_times), median(warm_times));
    println!(
        "\n(c) exact distance over a smooth trajectory of two {name}s ({} poses, equal answers):",
        poses.len()
    );
    println!(
        "  cold {:.1} us, warm-started {:.1} us (medians): {:.2}x; box tests {} -> {} ({:.2}x)",
        cold * 1e6,
        warm * 1e6,
        cold / warm,
        cold_tests,
        warm_tests,
        cold_tests as f64 / warm_tests as f64
    );
}

fn main() {
    // `cargo bench --bench scenes -- broad` runs only the benchmarks whose name contains
    // `broad` (names: many-objects, broad-phase, warm-start); `--bench` is cargo's.
    let filters: Vec<String> = std::env::args()
        .skip(1)
        .filter(|a| !a.starts_with("--"))
        .collect();
    let wanted =
        |name: &str| filters.is_empty() || filters.iter().any(|f| name.contains(f.as_str()));
    for (name, run) in [
        ("many-objects", scene_benchmark as fn()),
        ("broad-phase", broad_phase_benchmark),
        ("warm-start", warm_start_benchmark),
    ] {
        if wanted(name) {
            run();
        }
    }
}
