//! Runs closest-point queries on one mesh, for profilers (perf, callgrind):
//! `cargo run --release --example profile_closest -- MESH [POINTS] [RUNS]` (threads:
//! `RAYON_NUM_THREADS`). Half the points lie within 1% of the bounding-box diagonal of the
//! surface, half anywhere in three times the bounding box. Prints the median time per
//! point and the mean work; trees are f64 unless `OBBTREE_PRECISION=f32`.
// A tool developers run by hand: stopping loudly on a broken input is what it should do.
#![allow(clippy::expect_used, clippy::indexing_slicing)]

use obbtree::build::{build, BuildOptions};
use obbtree::generate::Rng;
use obbtree::mesh::TriMesh;
use obbtree::query::{closest_points, ClosestOptions, Pose};
use std::time::Instant;

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let path = args
        .get(1)
        .expect("usage: profile_closest MESH [POINTS] [RUNS]");
    let count: usize = args.get(2).and_then(|s| s.parse().ok()).unwrap_or(100_000);
    let runs: usize = args.get(3).and_then(|s| s.parse().ok()).unwrap_or(5);
    let mesh = TriMesh::load(path.as_ref()).expect("a mesh");
    let precision = match std::env::var("OBBTREE_PRECISION").as_deref() {
        Ok("f32") => obbtree::real::Precision::F32,
        _ => obbtree::real::Precision::F64,
    };
    let options = BuildOptions {
        precision,
        ..BuildOptions::default()
    };
    let file = build(&mesh, &options, None).expect("builds");
    let (mut lo, mut hi) = ([f64::INFINITY; 3], [f64::NEG_INFINITY; 3]);
    for v in mesh.vertices() {
        for k in 0..3 {
            lo[k] = lo[k].min(v[k]);
            hi[k] = hi[k].max(v[k]);
        }
    }
    let diagonal =
        ((hi[0] - lo[0]).powi(2) + (hi[1] - lo[1]).powi(2) + (hi[2] - lo[2]).powi(2)).sqrt();
    let mut rng = Rng::new(7);
    let points: Vec<[f64; 3]> = (0..count)
        .map(|i| {
            if i % 2 == 0 {
                let f = mesh.faces()[rng.below(mesh.faces().len())];
                let v = f.map(|k| mesh.vertices()[k as usize]);
                let (mut a, mut b) = (rng.unit(), rng.unit());
                if a + b > 1.0 {
                    (a, b) = (1.0 - a, 1.0 - b);
                }
                std::array::from_fn(|k| {
                    v[0][k]
                        + a * (v[1][k] - v[0][k])
                        + b * (v[2][k] - v[0][k])
                        + 0.01 * diagonal * rng.signed()
                })
            } else {
                std::array::from_fn(|k| {
                    let (c, h) = ((lo[k] + hi[k]) / 2.0, (hi[k] - lo[k]) / 2.0);
                    c + 3.0 * h * rng.signed()
                })
            }
        })
        .collect();
    // `SORTED=1`: points in grid-cell order, to see what coherence is worth.
    let mut points = points;
    if std::env::var("SORTED").is_ok() {
        let cell = |p: &[f64; 3]| p.map(|x| (x * 16.0 / diagonal).floor() as i64);
        points.sort_by_key(cell);
    }
    let mut times = Vec::new();
    let mut last = Vec::new();
    for _ in 0..runs {
        // The last answers go first, so that each run's are not fresh memory (see
        // `profile_rays`).
        drop(std::mem::take(&mut last));
        let started = Instant::now();
        last = closest_points(
            &file,
            &Pose::identity(),
            &points,
            &ClosestOptions::default(),
        )
        .expect("answers");
        times.push(started.elapsed().as_secs_f64());
    }
    times.sort_by(f64::total_cmp);
    let n = count.max(1) as f64;
    let bv: u64 = last.iter().map(|r| r.work.bv_tests()).sum();
    let tri: u64 = last.iter().map(|r| r.work.tri_tests()).sum();
    println!(
        "{} points: {:.3} us per point (median of {runs}); mean {:.1} volume bounds, {:.1} triangles per point",
        count,
        times[times.len() / 2] / n * 1e6,
        bv as f64 / n,
        tri as f64 / n
    );
}
