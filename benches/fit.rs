//! Benchmarks of `obbtree::fit`: one-triangle fits (the leaves of a tree), whole-mesh fits
//! (the root), and a simulated top-down build pass that fits every node, serially and on
//! two threads. Uses the shared bunny mesh when present (`OBBTREE_BENCH_MESH` overrides
//! the path); the mesh benchmarks are skipped without it.
// A benchmark of known-good inputs: a setup that fails is a broken benchmark, not bad input.
#![allow(clippy::expect_used, clippy::indexing_slicing)]

use std::time::Duration;

use criterion::{black_box, criterion_group, criterion_main, BenchmarkId, Criterion};
use obbtree::fit::{principal_axes, FitMethod};

type P = [f64; 3];

/// Vertices and fan-triangulated faces of an OBJ file (`v` and `f` lines only).
fn load_obj(path: &str) -> Option<(Vec<P>, Vec<[u32; 3]>)> {
    let text = std::fs::read_to_string(path).ok()?;
    let mut pos = Vec::new();
    let mut faces = Vec::new();
    for line in text.lines() {
        let mut it = line.split_whitespace();
        match it.next() {
            Some("v") => {
                let c: Vec<f64> = it.take(3).filter_map(|x| x.parse().ok()).collect();
                pos.push([*c.first()?, *c.get(1)?, *c.get(2)?]);
            }
            Some("f") => {
                let c: Vec<u32> = it
                    .filter_map(|x| x.split('/').next()?.parse::<u32>().ok())
                    .map(|i| i - 1)
                    .collect();
                for k in 1..c.len().saturating_sub(1) {
                    faces.push([c[0], c[k], c[k + 1]]);
                }
            }
            _ => {}
        }
    }
    Some((pos, faces))
}

/// A top-down pass as a builder makes it: fit the node, split its faces at the mean
/// centroid along column 0 (halves by count if that fails), recurse to single triangles.
/// Returns the number of nodes fitted.
fn top_down(m: FitMethod, pos: &[P], faces: &mut [[u32; 3]], parallel: bool) -> usize {
    let r = principal_axes(m, pos, faces);
    if faces.len() <= 1 {
        return 1;
    }
    let axis = [r[(0, 0)], r[(1, 0)], r[(2, 0)]];
    let key = |f: &[u32; 3]| -> f64 {
        f.iter()
            .map(|&i| {
                let p = pos[i as usize];
                p[0] * axis[0] + p[1] * axis[1] + p[2] * axis[2]
            })
            .sum()
    };
    let mean = faces.iter().map(key).sum::<f64>() / faces.len() as f64;
    let mut i = 0;
    for j in 0..faces.len() {
        if key(&faces[j]) < mean {
            faces.swap(i, j);
            i += 1;
        }
    }
    if i == 0 || i == faces.len() {
        i = faces.len() / 2;
    }
    let (a, b) = faces.split_at_mut(i);
    if parallel && a.len() + b.len() > 256 {
        let (x, y) = rayon::join(|| top_down(m, pos, a, true), || top_down(m, pos, b, true));
        1 + x + y
    } else {
        1 + top_down(m, pos, a, false) + top_down(m, pos, b, false)
    }
}

fn bench(c: &mut Criterion) {
    let tri = [[0.0, 0.0, 0.0], [1.0, 0.2, 0.1], [0.3, 1.0, 0.5]];
    let mut g = c.benchmark_group("one_triangle");
    for m in FitMethod::ALL {
        g.bench_function(m.name(), |b| {
            b.iter(|| principal_axes(m, black_box(&tri), black_box(&[[0, 1, 2]])))
        });
    }
    g.finish();

    let path = std::env::var("OBBTREE_BENCH_MESH")
        .unwrap_or_else(|_| "/work/shared/meshes/bunny.obj".to_string());
    let Some((pos, faces)) = load_obj(&path) else {
        eprintln!("fit benches: {path} not found, skipping mesh benchmarks");
        return;
    };

    let mut g = c.benchmark_group("mesh_root");
    g.sample_size(20);
    for m in FitMethod::ALL {
        g.bench_function(m.name(), |b| {
            b.iter(|| principal_axes(m, black_box(&pos), black_box(&faces)))
        });
    }
    g.finish();

    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(2)
        .build()
        .expect("thread pool");
    let mut g = c.benchmark_group("mesh_top_down");
    g.sample_size(10).measurement_time(Duration::from_secs(8));
    let mut work = faces.clone();
    for m in FitMethod::ALL {
        for (label, parallel) in [("serial", false), ("2_threads", true)] {
            g.bench_function(BenchmarkId::new(m.name(), label), |b| {
                b.iter(|| {
                    work.copy_from_slice(&faces);
                    pool.install(|| top_down(m, &pos, &mut work, parallel))
                })
            });
        }
    }
    g.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
