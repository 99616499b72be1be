//! Casts rays at one mesh, for profilers (perf, callgrind):
//! `cargo run --release --example profile_rays -- MESH [RAYS] [RUNS]` (threads:
//! `RAYON_NUM_THREADS`). Two sets: camera rays (a square image seen from outside the
//! bounding sphere, coherent) and random rays (from random points of a sphere twice the
//! bounding sphere to random points of the bounding box, incoherent). Prints the median
//! time per closest-hit ray, the hit fraction and the mean work; trees are f64 unless
//! `OBBTREE_PRECISION=f32`, in the fast layout unless `OBBTREE_LAYOUT=compact` (f32), of
//! oriented boxes unless `OBBTREE_BV=aabb` or `sphere`.
// A tool developers run by hand: stopping loudly on a broken input is what it should do.
#![allow(clippy::expect_used, clippy::indexing_slicing)]

use obbtree::build::{build, BuildOptions};
use obbtree::generate::Rng;
use obbtree::mesh::TriMesh;
use obbtree::query::{cast_rays, Pose, Ray, RayOptions};
use std::time::Instant;

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let path = args.get(1).expect("usage: profile_rays MESH [RAYS] [RUNS]");
    let count: usize = args.get(2).and_then(|s| s.parse().ok()).unwrap_or(100_000);
    let runs: usize = args.get(3).and_then(|s| s.parse().ok()).unwrap_or(5);
    let mesh = TriMesh::load(path.as_ref()).expect("a mesh");
    let precision = match std::env::var("OBBTREE_PRECISION").as_deref() {
        Ok("f32") => obbtree::real::Precision::F32,
        _ => obbtree::real::Precision::F64,
    };
    let layout = match std::env::var("OBBTREE_LAYOUT").as_deref() {
        Ok("compact") => obbtree::bv::Layout::Compact,
        _ => obbtree::bv::Layout::Fast,
    };
    let bv = match std::env::var("OBBTREE_BV").as_deref() {
        Ok("aabb") => obbtree::bv::BvKind::Aabb,
        Ok("sphere") => obbtree::bv::BvKind::Sphere,
        _ => obbtree::bv::BvKind::Obb,
    };
    let options = BuildOptions {
        bv,
        precision,
        layout,
        leaf_size: layout.default_leaf_size(),
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
    let centre: [f64; 3] = std::array::from_fn(|k| (lo[k] + hi[k]) / 2.0);
    let radius = (0..3).map(|k| (hi[k] - lo[k]).powi(2)).sum::<f64>().sqrt() / 2.0;
    let mut rng = Rng::new(7);
    let side = (count as f64).sqrt().ceil() as usize;
    let camera: Vec<Ray> = (0..side * side)
        .map(|i| {
            let (u, v) = (
                (i % side) as f64 / side as f64,
                (i / side) as f64 / side as f64,
            );
            let origin = [centre[0], centre[1], centre[2] + 3.0 * radius];
            let target = [
                centre[0] + (2.0 * u - 1.0) * radius,
                centre[1] + (2.0 * v - 1.0) * radius,
                centre[2],
            ];
            Ray {
                origin,
                direction: std::array::from_fn(|k| target[k] - origin[k]),
            }
        })
        .collect();
    let random: Vec<Ray> = (0..count)
        .map(|_| {
            let d = loop {
                let d = [rng.signed(), rng.signed(), rng.signed()];
                let n = (d[0] * d[0] + d[1] * d[1] + d[2] * d[2]).sqrt();
                if n > 0.1 && n <= 1.0 {
                    break d.map(|x| x / n);
                }
            };
            let origin: [f64; 3] = std::array::from_fn(|k| centre[k] + 2.0 * radius * d[k]);
            let target: [f64; 3] = std::array::from_fn(|k| lo[k] + (hi[k] - lo[k]) * rng.unit());
            Ray {
                origin,
                direction: std::array::from_fn(|k| target[k] - origin[k]),
            }
        })
        .collect();
    for (name, rays) in [("camera", &camera), ("random", &random)] {
        let mut times = Vec::new();
        let mut last = Vec::new();
        for _ in 0..runs {
            let started = Instant::now();
            last =
                cast_rays(&file, &Pose::identity(), rays, &RayOptions::default()).expect("answers");
            times.push(started.elapsed().as_secs_f64());
        }
        times.sort_by(f64::total_cmp);
        let n = rays.len().max(1) as f64;
        let hits = last.iter().filter(|r| r.hit.is_some()).count();
        let bv: u64 = last.iter().map(|r| r.work.bv_tests()).sum();
        let tri: u64 = last.iter().map(|r| r.work.tri_tests()).sum();
        println!(
            "{name}: {} rays, {:.3} us per ray (median of {runs}), {:.0}% hit; mean {:.1} volume tests, {:.1} triangles per ray",
            rays.len(),
            times[times.len() / 2] / n * 1e6,
            100.0 * hits as f64 / n,
            bv as f64 / n,
            tri as f64 / n
        );
    }
}
