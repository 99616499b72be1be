//! Builder and file benchmarks (issue: builder and .obbt file).
//!
//! - `build/<fit>`: build throughput on ../shared/meshes/bunny.obj (75k triangles) for each
//!   fit method, OBB f32, leaf size 1 (the default tree).
//! - `open/<size>`: `ObbtFile::open` + `info()` on a 1M-triangle file and on a small one;
//!   both should take the same few microseconds (open is O(1)).
//! - File size per triangle at leaf sizes 1, 2, 4, 8 on the bunny: printed as a table (a
//!   size, not a time).
//!
//! Run: `cargo bench --bench build`. Meshes outside the repository are optional: a missing
//! one is reported and its benchmarks skipped.
// A benchmark of known-good inputs: a setup that fails is a broken benchmark, not bad input.
#![allow(clippy::expect_used)]

#[path = "../tests/common/mod.rs"]
mod common;

use criterion::{criterion_group, criterion_main, BenchmarkId, Criterion, Throughput};
use obbtree::build::{build, BuildOptions};
use obbtree::fit::FitMethod;
use obbtree::format::ObbtFile;
use std::time::Duration;

fn build_throughput(c: &mut Criterion) {
    let Some(bunny) = common::shared_mesh("bunny.obj") else {
        return;
    };
    let mut group = c.benchmark_group("build");
    group
        .sample_size(10)
        .measurement_time(Duration::from_secs(8));
    group.throughput(Throughput::Elements(bunny.faces().len() as u64));
    for fit in FitMethod::ALL {
        let options = BuildOptions {
            fit,
            ..BuildOptions::default()
        };
        group.bench_with_input(
            BenchmarkId::new("bunny", fit.name()),
            &options,
            |b, options| b.iter(|| build(&bunny, options, None).expect("bunny builds")),
        );
    }
    group.finish();

    println!("\nfile size per triangle, bunny.obj, OBB f32, hull fit:");
    println!(
        "{:>10} {:>12} {:>10} {:>10}",
        "leaf size", "bytes", "nodes", "B/tri"
    );
    for leaf_size in [1, 2, 4, 8] {
        let file = build(
            &bunny,
            &BuildOptions {
                leaf_size,
                ..BuildOptions::default()
            },
            None,
        )
        .expect("builds");
        let info = file.info();
        println!(
            "{:>10} {:>12} {:>10} {:>10.1}",
            leaf_size,
            info.file_bytes,
            info.nodes,
            info.file_bytes as f64 / f64::from(info.triangles)
        );
    }
}

fn open_time(c: &mut Criterion) {
    let dir = std::env::temp_dir().join(format!("obbtree-bench-open-{}", std::process::id()));
    std::fs::create_dir_all(&dir).expect("temp dir");
    let large = dir.join("sphere-1m.obbt");
    let small = dir.join("cube.obbt");
    // 2 * 500 * 999 + ... = 1,000,000 triangles: 2 * slices * (stacks - 1).
    let sphere = common::uv_sphere(1.0, 501, 1000);
    let options = BuildOptions {
        fit: FitMethod::Triangles,
        ..BuildOptions::default()
    };
    build(&sphere, &options, None)
        .expect("builds")
        .write_atomic(&large)
        .expect("writes");
    build(&common::cube(1.0), &options, None)
        .expect("builds")
        .write_atomic(&small)
        .expect("writes");
    let mut group = c.benchmark_group("open");
    for (name, path) in [("1M-triangles", &large), ("12-triangles", &small)] {
        let bytes = std::fs::metadata(path).expect("exists").len();
        println!("open benchmark file {name}: {bytes} bytes");
        group.bench_function(name, |b| {
            b.iter(|| {
                let file = ObbtFile::open(path).expect("opens");
                file.info().triangles
            })
        });
    }
    group.finish();
    let _ = std::fs::remove_dir_all(dir);
}

criterion_group!(benches, build_throughput, open_time);
criterion_main!(benches);
