//! Runs one query kind many times on the sliding spheres, for profilers (perf, callgrind).
//!
//! `cargo run --release --example profile_query -- KIND X RUNS [DIR]` with KIND one of
//! `all`, `first`, `distance`, `rel` (rel_err 0.01), `culled`, `concentric` (exact
//! distance, spheres of radii 1 and 1.05); X the sliding position
//! (0.2 … 2.2), or with DIR (a case kept by `OBBTREE_PEERS_KEEP=1 cargo bench --bench
//! peers`: `a.obj`, `b.obj`, `poses.txt`) the index of a pose line. Prints the work of one
//! query and the median time per query. Trees are f32 unless `OBBTREE_PRECISION=f64`.
// A tool developers run by hand: stopping loudly on a broken input is what it should do.
#![allow(clippy::expect_used, clippy::indexing_slicing)]

#[path = "../tests/common/mod.rs"]
mod common;

use obbtree::build::build;
use obbtree::mesh::TriMesh;
use obbtree::query::{CollideOptions, DistanceOptions, PairQuery, Pose};
use std::time::Instant;

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let kind = args.get(1).map_or("all", |s| s.as_str());
    let x: f64 = args.get(2).and_then(|s| s.parse().ok()).unwrap_or(1.0);
    let runs: usize = args.get(3).and_then(|s| s.parse().ok()).unwrap_or(1000);
    let options = common::profiling_options();
    let case = args.get(4).map(std::path::PathBuf::from);
    let (mesh_a, mesh_b) = match &case {
        Some(dir) => (
            TriMesh::load(&dir.join("a.obj")).expect("a.obj"),
            TriMesh::load(&dir.join("b.obj")).expect("b.obj"),
        ),
        None => (
            common::uv_sphere(1.0, 101, 200),
            common::uv_sphere(0.8, 101, 200),
        ),
    };
    let a = build(&mesh_a, &options, None).expect("build");
    let b = build(&mesh_b, &options, None).expect("build");
    let mut pair = PairQuery::new(&a, &b).expect("pair");
    let (here, there) = match (&case, kind) {
        (Some(dir), _) => {
            let text = std::fs::read_to_string(dir.join("poses.txt")).expect("poses.txt");
            let line = text.lines().nth(x as usize).expect("a pose line");
            let v: Vec<f64> = line
                .split_whitespace()
                .map(|w| w.parse().expect("number"))
                .collect();
            let pose = |v: &[f64]| Pose::from_row_major(v).expect("pose");
            (pose(&v[..12]), pose(&v[12..]))
        }
        (None, "culled") => (Pose::identity(), Pose::translation(10.0, 0.0, 0.0)),
        (None, "concentric") => (Pose::identity(), Pose::identity()),
        (None, _) => (Pose::identity(), common::sliding_pose(x, 5)),
    };
    let (mut buffer, mut first_buffer) = (Default::default(), Default::default());
    let all = CollideOptions::default();
    let first = CollideOptions {
        first_contact: true,
        ..CollideOptions::default()
    };
    let exact = DistanceOptions::default();
    let rel = DistanceOptions {
        rel_err: 0.01,
        ..DistanceOptions::default()
    };
    // The poses go through `black_box` so that nothing is hoisted out of the timing loop.
    let mut once = |pair: &mut PairQuery<'_>| {
        let (here, there) = std::hint::black_box((&here, &there));
        match kind {
            "first" | "culled" => {
                pair.collide_into(here, there, &first, &mut first_buffer)
                    .expect("q");
                first_buffer.work
            }
            "distance" | "concentric" => pair.distance(here, there, &exact).expect("q").work,
            "rel" => pair.distance(here, there, &rel).expect("q").work,
            _ => {
                pair.collide_into(here, there, &all, &mut buffer)
                    .expect("q");
                buffer.work
            }
        }
    };
    if kind == "views" {
        // The cost of typing a file's sections, which PairQuery::new pays once per pair.
        let t0 = Instant::now();
        for _ in 0..runs {
            let f = std::hint::black_box(&a);
            std::hint::black_box(f.view::<obbtree::bv::Obb<f32>>().expect("view"));
        }
        println!(
            "view: {:.1} ns",
            t0.elapsed().as_secs_f64() * 1e9 / runs as f64
        );
        return;
    }
    println!("{kind} at x = {x}: {:?}", once(&mut pair));
    // The median of 11 batches: the machine is shared, and a batch may be interrupted.
    let mut batches: Vec<f64> = (0..11)
        .map(|_| {
            let t0 = Instant::now();
            for _ in 0..runs.div_ceil(11) {
                std::hint::black_box(once(&mut pair));
            }
            t0.elapsed().as_secs_f64() * 1e6 / runs.div_ceil(11) as f64
        })
        .collect();
    batches.sort_by(f64::total_cmp);
    println!("{:.3} µs per query (median of 11 batches)", batches[5]);
}
