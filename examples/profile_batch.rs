//! Runs a first-contact (or all-contacts) batch of random poses of the bundled cow against
//! itself on one thread, for profilers: the workload of the Python benchmark's
//! `first contact` row (`bindings/python/bench/vs_fcl.py`), without Python.
//!
//! `cargo run --release --example profile_batch -- [first|all] [POSES] [SPREAD] [MESH]`:
//! POSES random poses (uniform rotation, translation uniform in `[-s, s]³` with `s` SPREAD
//! times the model's largest extent: 0.6 overlaps, 2 is the "wide" workspace); MESH an OBJ
//! or STL file instead of the cow. Prints the mean work per pose and the median time per
//! pose of 5 passes. Trees are f32 unless `OBBTREE_PRECISION=f64`.
// A tool developers run by hand: stopping loudly on a broken input is what it should do.
#![allow(clippy::expect_used, clippy::indexing_slicing)]

#[path = "../tests/common/mod.rs"]
mod common;

use obbtree::build::build;
use obbtree::generate::Rng;
use obbtree::mesh::TriMesh;
use obbtree::query::{CollideOptions, CollideResult, PairQuery, Pose};
use std::time::Instant;

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let kind = args.get(1).map_or("first", |s| s.as_str());
    let count: usize = args.get(2).and_then(|s| s.parse().ok()).unwrap_or(100_000);
    let spread: f64 = args.get(3).and_then(|s| s.parse().ok()).unwrap_or(0.6);
    let mesh = match args.get(4) {
        Some(path) => TriMesh::load(std::path::Path::new(path)).expect("mesh"),
        None => common::cow(),
    };
    let options = common::profiling_options();
    let tree = build(&mesh, &options, None).expect("build");
    let extent = (0..3)
        .map(|i| {
            let axis = mesh.vertices().iter().map(|v| v[i]);
            axis.clone().fold(f64::MIN, f64::max) - axis.fold(f64::MAX, f64::min)
        })
        .fold(0.0, f64::max);
    let mut rng = Rng::new(7);
    let poses: Vec<Pose> = (0..count)
        .map(|_| {
            let r = rng.uniform_rotation();
            let t = nalgebra::Vector3::from_fn(|_, _| rng.signed() * spread * extent);
            Pose::new(r, t).expect("rotation")
        })
        .collect();
    let options = CollideOptions {
        first_contact: kind == "first",
        ..CollideOptions::default()
    };
    let here = Pose::identity();
    let mut pair = PairQuery::new(&tree, &tree).expect("pair");
    let mut result = CollideResult::default();
    let (mut boxes, mut tris, mut touching) = (0u64, 0u64, 0usize);
    for pose in &poses {
        pair.collide_into(&here, pose, &options, &mut result)
            .expect("query");
        boxes += result.work.bv_tests();
        tris += result.work.tri_tests();
        touching += usize::from(result.colliding);
    }
    let n = count as f64;
    println!(
        "{kind}, {count} poses at spread {spread}: {:.1}% touching, {:.1} box tests and {:.1} triangle tests per pose",
        100.0 * touching as f64 / n,
        boxes as f64 / n,
        tris as f64 / n
    );
    let mut passes: Vec<f64> = (0..5)
        .map(|_| {
            let t0 = Instant::now();
            for pose in &poses {
                pair.collide_into(&here, std::hint::black_box(pose), &options, &mut result)
                    .expect("query");
            }
            t0.elapsed().as_secs_f64() * 1e6 / n
        })
        .collect();
    passes.sort_by(f64::total_cmp);
    println!(
        "{:.3} µs per pose (median of 5 passes), {:.1} ns per box test",
        passes[2],
        passes[2] * 1e3 * n / boxes.max(1) as f64
    );
}
