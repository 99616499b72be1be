//! Casts rays at one mesh, for profilers (perf, callgrind):
//! `cargo run --release --example profile_rays -- MESH [RAYS] [RUNS]` (threads:
//! `RAYON_NUM_THREADS`). Two sets (`benches/support/rays.rs`): camera rays (coherent) and
//! random rays (incoherent). Prints the median
//! time per closest-hit ray, the hit fraction and the mean work; trees are f64 unless
//! `OBBTREE_PRECISION=f32`, in the fast layout unless `OBBTREE_LAYOUT=compact` (f32), of
//! oriented boxes unless `OBBTREE_BV=aabb` or `sphere`. `OBBTREE_T_MAX` sets the rays'
//! `t_max` (a tiny one, such as 1e-100, measures what a ray costs before its descent).
// A tool developers run by hand: stopping loudly on a broken input is what it should do.
#![allow(clippy::expect_used, clippy::indexing_slicing)]

#[path = "../benches/support/rays.rs"]
mod rays;

use obbtree::build::{build, BuildOptions};
use obbtree::mesh::TriMesh;
use obbtree::query::{cast_rays, Pose, RayOptions};
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
    // The first ray query on a file makes its ray index.
    let started = Instant::now();
    let one = [rays::random_rays(&mesh, 1, 1)[0]];
    cast_rays(&file, &Pose::identity(), &one, &RayOptions::default()).expect("answers");
    println!(
        "first query (makes the ray index): {:.1} ms",
        started.elapsed().as_secs_f64() * 1e3
    );
    let options = RayOptions {
        t_max: std::env::var("OBBTREE_T_MAX")
            .ok()
            .and_then(|s| s.parse().ok())
            .unwrap_or(f64::INFINITY),
        ..RayOptions::default()
    };
    let camera = rays::camera_rays(&mesh, count);
    let random = rays::random_rays(&mesh, count, 7);
    for (name, rays) in [("camera", &camera), ("random", &random)] {
        let mut times = Vec::new();
        let mut last = Vec::new();
        for _ in 0..runs {
            // The last answers go first: with two sets of answers alive, one of them was
            // fresh memory on every run, and its page faults were timed as the rays'.
            drop(std::mem::take(&mut last));
            let started = Instant::now();
            last = cast_rays(&file, &Pose::identity(), rays, &options).expect("answers");
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
