//! Leaf primitives: ns per call of `triangles_intersect`, `triangle_distance` and
//! `triangle_max_distance` on random triangle pairs.
//!
//! Workloads (1024 pairs each, cycled so the branch predictor cannot learn one answer):
//! - `unit`: both triangles with corners uniform in the unit cube (about half intersect);
//! - `near`: small triangles (edge ~0.1) around nearby centres, as in the leaves of a
//!   collision query whose boxes overlap (a minority intersect);
//! - `apart`: the same triangles with centres 0.5 to 1 apart (none intersect; the bounding-box
//!   or plane tests reject most of them).
//!
//! Run: `cargo bench --bench triangle`.
// A benchmark of known-good inputs: a setup that fails is a broken benchmark, not bad input.
#![allow(clippy::indexing_slicing)]

use criterion::{black_box, criterion_group, criterion_main, Criterion};
use nalgebra::Vector3;
use obbtree::query::triangle::{
    triangle_distance, triangle_max_distance, triangles_intersect, Triangle,
};
use std::time::Duration;

/// A small deterministic generator (splitmix64), uniform in [0, 1).
struct Rng(u64);

impl Rng {
    fn next(&mut self) -> f64 {
        self.0 = self.0.wrapping_add(0x9e37_79b9_7f4a_7c15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
        ((z ^ (z >> 31)) >> 11) as f64 / (1u64 << 53) as f64
    }

    fn point(&mut self, r: f64) -> Vector3<f64> {
        Vector3::new(self.next(), self.next(), self.next()).map(|x| (x - 0.5) * 2.0 * r)
    }

    fn triangle_around(&mut self, c: Vector3<f64>, r: f64) -> Triangle {
        [c + self.point(r), c + self.point(r), c + self.point(r)]
    }
}

fn workload(name: &str, rng: &mut Rng) -> Vec<(Triangle, Triangle)> {
    (0..1024)
        .map(|_| match name {
            "unit" => (
                rng.triangle_around(Vector3::zeros(), 0.5),
                rng.triangle_around(Vector3::zeros(), 0.5),
            ),
            "near" => {
                let c = rng.point(0.05);
                (
                    rng.triangle_around(Vector3::zeros(), 0.05),
                    rng.triangle_around(c, 0.05),
                )
            }
            _ => {
                let dir = rng.point(1.0).normalize();
                let c = dir * (0.5 + 0.5 * rng.next());
                (
                    rng.triangle_around(Vector3::zeros(), 0.05),
                    rng.triangle_around(c, 0.05),
                )
            }
        })
        .collect()
}

fn primitives(c: &mut Criterion) {
    let mut rng = Rng(0x0bb7);
    for name in ["unit", "near", "apart"] {
        let pairs = workload(name, &mut rng);
        let hits = pairs
            .iter()
            .filter(|(a, b)| triangles_intersect(a, b))
            .count();
        eprintln!("workload {name}: {hits}/1024 pairs intersect");
        let mut group = c.benchmark_group(format!("triangle/{name}"));
        group
            .sample_size(30)
            .warm_up_time(Duration::from_millis(500))
            .measurement_time(Duration::from_secs(2));
        group.bench_function("intersect", |b| {
            let mut i = 0;
            b.iter(|| {
                i = (i + 1) & 1023;
                let (p, q) = &pairs[i];
                triangles_intersect(black_box(p), black_box(q))
            })
        });
        group.bench_function("distance", |b| {
            let mut i = 0;
            b.iter(|| {
                i = (i + 1) & 1023;
                let (p, q) = &pairs[i];
                triangle_distance(black_box(p), black_box(q))
            })
        });
        group.bench_function("max_distance", |b| {
            let mut i = 0;
            b.iter(|| {
                i = (i + 1) & 1023;
                let (p, q) = &pairs[i];
                triangle_max_distance(black_box(p), black_box(q))
            })
        });
        group.finish();
    }
}

criterion_group!(benches, primitives);
criterion_main!(benches);
