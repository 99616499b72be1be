//! Closest-hit rays, obbtree against parry3d 0.31, one thread each, the same meshes and rays
//! (`support/rays.rs`: camera rays, coherent, and random rays, incoherent). Answers are
//! checked against each other: a ray hit by one and not the other, or at a `t` differing by
//! more than 1e-4 relative (parry3d computes in f32), is counted; rays that graze an edge
//! can legitimately differ, so the count is printed, not failed on.
//!
//! `cargo bench --bench rays [-- RAYS]` (default 100,000 rays per set). Prints a table of
//! median microseconds per ray (of 5 runs) and the geometric mean of obbtree's time over
//! parry3d's. The bundled cow always runs; `../shared/meshes` when present.
// A benchmark run by hand: stopping loudly on a broken input is what it should do.
#![allow(clippy::expect_used, clippy::indexing_slicing)]

#[path = "../tests/common/mod.rs"]
mod common;
#[path = "support/parry.rs"]
#[allow(dead_code)]
mod parry_support;
#[path = "support/rays.rs"]
mod rays;

use obbtree::build::{build, BuildOptions};
use obbtree::experiment::median_time;
use obbtree::mesh::TriMesh;
use obbtree::query::{cast_rays, Pose, Ray, RayOptions};
use obbtree::real::Precision;
use parry3d::math::Vector as PVector;
use parry3d::query::RayCast;

/// Seconds per ray of one closest-hit cast of `rays` by obbtree (`f32` or `f64` tree),
/// and the `t` of each (infinite on a miss).
fn obbtree_rays(mesh: &TriMesh, precision: Precision, rays: &[Ray]) -> (f64, Vec<f64>) {
    let options = BuildOptions {
        precision,
        ..BuildOptions::default()
    };
    let file = build(mesh, &options, None).expect("builds");
    let (answers, seconds) = median_time(5, || {
        cast_rays(&file, &Pose::identity(), rays, &RayOptions::default())
    })
    .expect("answers");
    let ts = answers
        .iter()
        .map(|r| r.hit.map_or(f64::INFINITY, |h| h.t))
        .collect();
    (seconds / rays.len() as f64, ts)
}

/// The same for parry3d's `TriMesh::cast_local_ray` (its BVH built before the clock).
fn parry_rays(mesh: &TriMesh, rays: &[Ray]) -> (f64, Vec<f64>) {
    let shape = parry_support::parry_mesh(mesh);
    let theirs: Vec<parry3d::query::Ray> = rays
        .iter()
        .map(|r| {
            let [o, d] = [r.origin, r.direction].map(|v| v.map(|x| x as f32));
            parry3d::query::Ray::new(
                PVector::new(o[0], o[1], o[2]),
                PVector::new(d[0], d[1], d[2]),
            )
        })
        .collect();
    let (ts, seconds) = median_time(5, || {
        Ok::<_, ()>(
            theirs
                .iter()
                .map(|r| {
                    shape
                        .cast_local_ray(r, f32::MAX, false)
                        .map_or(f64::INFINITY, f64::from)
                })
                .collect::<Vec<f64>>(),
        )
    })
    .expect("answers");
    (seconds / rays.len() as f64, ts)
}

fn main() {
    let count: usize = std::env::args()
        .skip(1)
        .find_map(|a| a.parse().ok())
        .unwrap_or(100_000);
    let mut meshes = vec![("cow".to_string(), common::cow())];
    for name in [
        "bunny.obj",
        "fandisk.stl",
        "pig.stl",
        "cad/boeing.obj",
        "cad/ALSTOM_TEST4.obj",
        "cad/anchor.obj",
    ] {
        if let Some(mesh) = common::shared_mesh(name) {
            meshes.push((name.to_string(), mesh));
        }
    }
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(1)
        .build()
        .expect("a pool");
    println!(
        "| mesh | triangles | rays | obbtree f64 µs | obbtree f32 µs | parry3d µs | f64 / parry3d | f32 / parry3d | disagree |"
    );
    println!("|---|---:|---|---:|---:|---:|---:|---:|---:|");
    let (mut log64, mut log32, mut n) = (0.0, 0.0, 0);
    for (name, mesh) in &meshes {
        for (kind, set) in [
            ("camera", rays::camera_rays(mesh, count)),
            ("random", rays::random_rays(mesh, count, 7)),
        ] {
            let (t64, ours) = pool.install(|| obbtree_rays(mesh, Precision::F64, &set));
            let (t32, _) = pool.install(|| obbtree_rays(mesh, Precision::F32, &set));
            let (tp, theirs) = parry_rays(mesh, &set);
            let disagree = ours
                .iter()
                .zip(&theirs)
                .filter(|(a, b)| {
                    a.is_finite() != b.is_finite()
                        || (a.is_finite() && (*a - *b).abs() > 1e-4 * a.abs().max(1.0))
                })
                .count();
            println!(
                "| {name} | {} | {kind} | {:.3} | {:.3} | {:.3} | {:.2} | {:.2} | {disagree} |",
                mesh.faces().len(),
                t64 * 1e6,
                t32 * 1e6,
                tp * 1e6,
                t64 / tp,
                t32 / tp
            );
            log64 += (t64 / tp).ln();
            log32 += (t32 / tp).ln();
            n += 1;
        }
    }
    let n = f64::from(n);
    println!(
        "\ngeometric mean of obbtree's time over parry3d's: f64 trees {:.2}, f32 trees {:.2}",
        (log64 / n).exp(),
        (log32 / n).exp()
    );
}
