//! Runs winding-number queries on one mesh, for profilers (perf, callgrind):
//! `cargo run --release --example profile_winding -- MESH [POINTS] [RUNS] [BETA]` (threads:
//! `RAYON_NUM_THREADS`). Points are uniform in the mesh's bounding box, as in
//! `bindings/python/bench/vs_winding.py`. Prints the median time per point and the mean
//! work: clusters summed by moments, clusters opened, triangles summed exactly.
// A tool developers run by hand: stopping loudly on a broken input is what it should do.
#![allow(clippy::expect_used, clippy::indexing_slicing)]

use obbtree::build::{build, BuildOptions};
use obbtree::generate::Rng;
use obbtree::mesh::TriMesh;
use obbtree::query::{winding_numbers, Pose, WindingAccuracy, WindingOptions};
use std::time::Instant;

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let path = args
        .get(1)
        .expect("usage: profile_winding MESH [POINTS] [RUNS] [BETA]");
    let count: usize = args.get(2).and_then(|s| s.parse().ok()).unwrap_or(100_000);
    let runs: usize = args.get(3).and_then(|s| s.parse().ok()).unwrap_or(5);
    let beta: f64 = args.get(4).and_then(|s| s.parse().ok()).unwrap_or(2.0);
    let mesh = TriMesh::load(path.as_ref()).expect("a mesh");
    let file = build(&mesh, &BuildOptions::default(), None).expect("builds");
    let (mut lo, mut hi) = ([f64::INFINITY; 3], [f64::NEG_INFINITY; 3]);
    for v in mesh.vertices() {
        for k in 0..3 {
            lo[k] = lo[k].min(v[k]);
            hi[k] = hi[k].max(v[k]);
        }
    }
    let mut rng = Rng::new(7);
    // (In the caller's order: `winding_numbers` orders them in space itself.)
    let points: Vec<[f64; 3]> = (0..count)
        .map(|_| std::array::from_fn(|k| lo[k] + (hi[k] - lo[k]) * rng.unit()))
        .collect();
    let options = WindingOptions {
        accuracy: WindingAccuracy::Beta { beta },
    };
    let mut times = Vec::new();
    let mut last = Vec::new();
    for _ in 0..runs {
        // The last answers go first, so that each run's are not fresh memory (see
        // `profile_rays`).
        drop(std::mem::take(&mut last));
        let started = Instant::now();
        last = winding_numbers(&file, &Pose::identity(), &points, &options).expect("answers");
        times.push(started.elapsed().as_secs_f64());
    }
    times.sort_by(f64::total_cmp);
    let n = count.max(1) as f64;
    let mean = |f: &dyn Fn(&obbtree::query::Work) -> u64| {
        last.iter().map(|r| f(&r.work)).sum::<u64>() as f64 / n
    };
    println!(
        "{count} points: {:.3} us per point (median of {runs}); mean {:.1} clusters by moments, {:.1} opened, {:.1} triangles per point",
        times[times.len() / 2] / n * 1e6,
        mean(&|w| w.bv_disjoint),
        mean(&|w| w.bv_overlap),
        mean(&|w| w.tri_tests()),
    );
}
