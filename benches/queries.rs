//! Query benchmarks on the dissertation's scenes, with parry3d in the same run.
//!
//! - `sliding/<x>`: all contacts between two 40,000-triangle lat/long spheres (radii 1 and
//!   0.8, §5.3.1), the small one at x with a seeded random rotation; `first/<x>`: first
//!   contact. Contacts and D, I, S, K are printed once per x.
//! - `concentric`: exact distance between spheres of radii 1 and 1.05 (gap 0.05).
//! - `far/<offset>`: exact distance and `rel_err` 0.01 between two bundled cows (about 1 unit
//!   across), B turned and moved 1e3 … 1e9 along a diagonal, OBB f32 (the default) and AABB
//!   f32: the work must not grow with the offset. Triangle tests are printed per offset.
//! - `parry/*`: parry3d 0.31 on the same meshes and poses: boolean intersection
//!   (`query::intersection_test`), all pairs (`Bvh::leaf_pairs` with a posed AABB check,
//!   then parry's exact triangle test), and distance (`query::distance`).
//!
//! Run: `cargo bench --bench queries`.
// A benchmark of known-good inputs: a setup that fails is a broken benchmark, not bad input.
#![allow(clippy::expect_used)]

#[path = "../tests/common/mod.rs"]
mod common;
#[path = "support/parry.rs"]
mod parry_support;

use criterion::{criterion_group, criterion_main, BenchmarkId, Criterion};
use obbtree::query::{CollideOptions, DistanceOptions, PairQuery, Pose};
use parry3d::bounding_volume::BoundingVolume as _;
use parry3d::math::Pose as PPose;
use std::hint::black_box;

const XS: [f64; 5] = [0.2, 0.6, 1.0, 1.4, 1.8];

use common::tree_f64 as tree;
use parry_support::{parry_mesh, parry_pose};

/// All intersecting triangle pairs with parry: its BVH pair traversal plus its exact test.
fn parry_all_pairs(
    a: &parry3d::shape::TriMesh,
    b: &parry3d::shape::TriMesh,
    pos12: &PPose,
) -> usize {
    let check = |n1: &parry3d::partitioning::BvhNode, n2: &parry3d::partitioning::BvhNode| {
        n1.aabb().intersects(&n2.aabb().transform_by(pos12))
    };
    let mut count = 0;
    for (i, j) in a.bvh().leaf_pairs(b.bvh(), check) {
        let (ta, tb) = (a.triangle(i), b.triangle(j));
        if parry3d::query::intersection_test(&PPose::IDENTITY, &ta, pos12, &tb)
            .is_ok_and(|r| r.intersecting)
        {
            count += 1;
        }
    }
    count
}

fn sliding_spheres(c: &mut Criterion) {
    let big = common::uv_sphere(1.0, 101, 200); // 40,000 triangles
    let small = common::uv_sphere(0.8, 101, 200);
    let (ta, tb) = (tree(&big), tree(&small));
    let (pa, pb) = (parry_mesh(&big), parry_mesh(&small));
    let mut pair = PairQuery::new(&ta, &tb).expect("one volume type");
    let mut group = c.benchmark_group("sliding");
    println!("\nsliding spheres, 40,000 triangles each, OBB f64:");
    println!(
        "{:>5} {:>9} {:>9} {:>9} {:>9} {:>9} {:>12}",
        "x", "contacts", "D", "I", "S", "K", "parry pairs"
    );
    for (step, x) in XS.into_iter().enumerate() {
        let pose = common::sliding_pose(x, step as u64);
        let all = CollideOptions::default();
        let first = CollideOptions {
            first_contact: true,
            ..CollideOptions::default()
        };
        let r = pair.collide(&Pose::identity(), &pose, &all).expect("query");
        let pos12 = parry_pose(&pose);
        let s = r.work;
        println!(
            "{x:>5.1} {:>9} {:>9} {:>9} {:>9} {:>9} {:>12}",
            r.pairs.len(),
            s.bv_disjoint,
            s.bv_overlap,
            s.tri_separated,
            s.tri_contact,
            parry_all_pairs(&pa, &pb, &pos12)
        );
        group.bench_with_input(BenchmarkId::new("all", x), &pose, |bench, pose| {
            bench.iter(|| {
                pair.collide(&Pose::identity(), pose, &all)
                    .expect("query")
                    .pairs
                    .len()
            })
        });
        group.bench_with_input(BenchmarkId::new("first", x), &pose, |bench, pose| {
            bench.iter(|| {
                pair.collide(&Pose::identity(), pose, &first)
                    .expect("query")
                    .colliding
            })
        });
        group.bench_with_input(BenchmarkId::new("parry-all", x), &pos12, |bench, pos12| {
            bench.iter(|| parry_all_pairs(&pa, &pb, pos12))
        });
        group.bench_with_input(
            BenchmarkId::new("parry-boolean", x),
            &pos12,
            |bench, pos12| {
                bench.iter(|| {
                    parry3d::query::intersection_test(&PPose::IDENTITY, &pa, pos12, &pb)
                        .expect("supported")
                        .intersecting
                })
            },
        );
    }
    group.finish();
}

fn concentric_spheres(c: &mut Criterion) {
    let inner = common::uv_sphere(1.0, 101, 200);
    let outer = common::uv_sphere(1.05, 101, 200);
    let (ta, tb) = (tree(&inner), tree(&outer));
    let (pa, pb) = (parry_mesh(&inner), parry_mesh(&outer));
    let pose =
        Pose::new(common::rng::seeded_rotation(7), nalgebra::Vector3::zeros()).expect("rotation");
    let mut pair = PairQuery::new(&ta, &tb).expect("one volume type");
    let exact = DistanceOptions::default();
    let r = pair
        .distance(&Pose::identity(), &pose, &exact)
        .expect("query");
    let pos12 = parry_pose(&pose);
    let parry_d = black_box(parry3d::query::distance(&PPose::IDENTITY, &pa, &pos12, &pb));
    println!("\nconcentric spheres (1 and 1.05), 40,000 triangles each: distance {} ({:?}); parry: {parry_d:?}", r.distance(), r.work);
    let mut group = c.benchmark_group("concentric");
    group.sample_size(10);
    for rel in [0.0, 0.01, 0.1] {
        let options = DistanceOptions {
            rel_err: rel,
            ..DistanceOptions::default()
        };
        group.bench_with_input(
            BenchmarkId::new("distance-rel-err", rel),
            &options,
            |bench, options| {
                bench.iter(|| {
                    pair.distance(&Pose::identity(), &pose, options)
                        .expect("query")
                        .distance()
                })
            },
        );
    }
    group.bench_function("parry-distance", |bench| {
        bench.iter(|| parry3d::query::distance(&PPose::IDENTITY, &pa, &pos12, &pb))
    });
    group.finish();
}

fn far_apart(c: &mut Criterion) {
    let cow = common::cow();
    let mut group = c.benchmark_group("far");
    println!("\ntwo cows far apart, triangle tests of exact distance / rel_err 0.01:");
    for bv in [obbtree::bv::BvKind::Obb, obbtree::bv::BvKind::Aabb] {
        let options = obbtree::build::BuildOptions {
            bv,
            ..Default::default()
        };
        let file = obbtree::build::build(&cow, &options, None).expect("builds");
        let mut pair = PairQuery::new(&file, &file).expect("one volume type");
        for offset in [1e3, 1e5, 1e6, 1e9] {
            let direction = nalgebra::Vector3::new(1.0, -1.0, 1.0).normalize();
            let pose =
                Pose::new(common::rng::seeded_rotation(3), direction * offset).expect("pose");
            let a = Pose::identity();
            let exact = DistanceOptions::default();
            let rel = DistanceOptions {
                rel_err: 0.01,
                ..DistanceOptions::default()
            };
            let mut tests = |o: &DistanceOptions| {
                let s = pair.distance(&a, &pose, o).expect("query").work;
                s.tri_separated + s.tri_contact
            };
            let (exact_tests, rel_tests) = (tests(&exact), tests(&rel));
            println!("  {} {offset:e}: {exact_tests} / {rel_tests}", bv.name());
            for (name, o) in [("exact", &exact), ("rel-err-0.01", &rel)] {
                let id = BenchmarkId::new(format!("{}-{name}", bv.name()), offset);
                group.bench_with_input(id, o, |bench, o| {
                    bench.iter(|| pair.distance(&a, &pose, o).expect("query").distance())
                });
            }
        }
    }
    group.finish();
}

criterion_group!(benches, sliding_spheres, concentric_spheres, far_apart);
criterion_main!(benches);
