//! Accuracy versus time: what each accuracy choice costs, and which answers it changes.
//!
//! Scenes:
//! - `spheres`: the sliding spheres of §5.3.1 (40,000 triangles each, radii 1 and 0.8);
//!   collision at x = 1.0 (deep crossing), distance at x = 2.0 (gap about 0.2);
//! - `bunny`: ../shared/meshes/bunny.obj (75k triangles) against a rotated copy: collision
//!   with the copy shifted by a quarter of its width, distance with the copy shifted by 1.1
//!   times its diagonal.
//!
//! Configurations, each changing one choice of the baseline (OBB, f64 file, hull fit,
//! separating-axis guard 1e-6, exact distance):
//! `f32` file, `guard-off` (guard 0), `rel-0.01` and `rel-0.1` (distance `rel_err`), and
//! `fit-triangles`, `fit-vertices`.
//!
//! Printed once per scene: contacts, pairs gained and lost, and distance against the
//! baseline. Timed: `accuracy/<scene>/build/<config>`, `.../collide/<config>`,
//! `.../distance/<config>`. Then a table of the distance reported for gaps from 1e-1 to
//! 1e-9 between two unit cubes, by obbtree (f32 and f64 files) and by parry3d 0.31.
//!
//! Run: `cargo bench --bench accuracy`; the bunny part needs ../shared/meshes and is
//! skipped with a message without it.
// A benchmark of known-good inputs: a setup that fails is a broken benchmark, not bad input.
#![allow(clippy::expect_used, clippy::indexing_slicing)]

#[path = "../tests/common/mod.rs"]
mod common;
#[path = "support/parry.rs"]
mod parry_support;

use criterion::{criterion_group, criterion_main, BenchmarkId, Criterion};
use nalgebra::{Matrix3, Vector3};
use obbtree::build::{build, BuildOptions, DEFAULT_HULL_MAX_POINTS, DEFAULT_HULL_MIN_FACES};
use obbtree::bv::pair::SAT_GUARD;
use obbtree::fit::FitMethod;
use obbtree::format::ObbtFile;
use obbtree::mesh::TriMesh;
use obbtree::query::{CollideOptions, DistanceOptions, PairQuery, Pose};
use obbtree::real::Precision;
use parry3d::math::Pose as PPose;
use parry_support::{parry_mesh, parry_pose};
use std::collections::BTreeSet;
use std::time::Duration;

/// One accuracy choice away from the baseline.
#[derive(Clone, Copy)]
struct Config {
    name: &'static str,
    precision: Precision,
    fit: FitMethod,
    /// `BuildOptions::hull_min_faces`.
    hull_min_faces: u32,
    /// `BuildOptions::hull_max_points`.
    hull_max_points: u32,
    /// `BuildOptions::model_axes`.
    model_axes: bool,
    /// `BuildOptions::split_by_volume`.
    split_by_volume: bool,
    guard: f64,
    rel_err: f64,
}

const BASELINE: Config = Config {
    name: "baseline",
    precision: Precision::F64,
    fit: FitMethod::Hull,
    hull_min_faces: DEFAULT_HULL_MIN_FACES,
    hull_max_points: DEFAULT_HULL_MAX_POINTS,
    model_axes: true,
    split_by_volume: true,
    guard: SAT_GUARD,
    rel_err: 0.0,
};

const CONFIGS: [Config; 8] = [
    BASELINE,
    Config {
        name: "f32",
        precision: Precision::F32,
        ..BASELINE
    },
    Config {
        name: "guard-off",
        guard: 0.0,
        ..BASELINE
    },
    Config {
        name: "rel-0.01",
        rel_err: 0.01,
        ..BASELINE
    },
    Config {
        name: "rel-0.1",
        rel_err: 0.1,
        ..BASELINE
    },
    Config {
        // The dissertation's §3.4 as written: every node, every vertex, fitted frames only,
        // split along the greatest spread.
        name: "fit-hull-everywhere",
        hull_min_faces: 1,
        hull_max_points: u32::MAX,
        model_axes: false,
        split_by_volume: false,
        ..BASELINE
    },
    Config {
        name: "fit-triangles",
        fit: FitMethod::Triangles,
        ..BASELINE
    },
    Config {
        name: "fit-vertices",
        fit: FitMethod::Vertices,
        ..BASELINE
    },
];

impl Config {
    fn build_options(&self) -> BuildOptions {
        BuildOptions {
            precision: self.precision,
            fit: self.fit,
            hull_min_faces: self.hull_min_faces,
            hull_max_points: self.hull_max_points,
            model_axes: self.model_axes,
            split_by_volume: self.split_by_volume,
            ..BuildOptions::default()
        }
    }

    /// Whether this configuration changes the file (and so has its own build timing).
    fn changes_the_file(&self) -> bool {
        self.precision != BASELINE.precision
            || self.fit != BASELINE.fit
            || self.hull_min_faces != BASELINE.hull_min_faces
            || self.hull_max_points != BASELINE.hull_max_points
            || self.model_axes != BASELINE.model_axes
            || self.split_by_volume != BASELINE.split_by_volume
            || self.name == "baseline"
    }
}

/// Two models and the poses of B for the collision and the distance query (A at identity).
struct Scene {
    name: &'static str,
    a: TriMesh,
    b: TriMesh,
    collide_pose: Pose,
    distance_pose: Pose,
}

fn spheres() -> Scene {
    Scene {
        name: "spheres",
        a: common::uv_sphere(1.0, 101, 200),
        b: common::uv_sphere(0.8, 101, 200),
        collide_pose: common::sliding_pose(1.0, 2),
        distance_pose: common::sliding_pose(2.0, 4),
    }
}

fn bunny() -> Option<Scene> {
    let bunny = common::shared_mesh("bunny.obj")?;
    let (lo, hi) = bunny
        .vertices()
        .iter()
        .fold(([f64::MAX; 3], [f64::MIN; 3]), |(lo, hi), p| {
            (
                std::array::from_fn(|k| lo[k].min(p[k])),
                std::array::from_fn(|k| hi[k].max(p[k])),
            )
        });
    let center = Vector3::from(std::array::from_fn(|k| (lo[k] + hi[k]) / 2.0));
    let size = Vector3::from(std::array::from_fn(|k| hi[k] - lo[k]));
    let r = common::rng::seeded_rotation(11);
    // Rotate the copy about the bunny's centre, then shift it along x.
    let around_center = |shift: f64| -> Pose {
        Pose::new(r, center - r * center + Vector3::new(shift, 0.0, 0.0)).expect("rotation")
    };
    Some(Scene {
        name: "bunny",
        a: bunny.clone(),
        b: bunny,
        collide_pose: around_center(0.25 * size.x),
        distance_pose: around_center(1.1 * size.norm()),
    })
}

/// The built files of a scene for one configuration.
fn files(scene: &Scene, config: &Config) -> (ObbtFile, ObbtFile) {
    let options = config.build_options();
    (
        build(&scene.a, &options, None).expect("builds"),
        build(&scene.b, &options, None).expect("builds"),
    )
}

fn collide_options(config: &Config) -> CollideOptions {
    CollideOptions {
        guard: config.guard,
        ..CollideOptions::default()
    }
}

fn distance_options(config: &Config) -> DistanceOptions {
    DistanceOptions {
        rel_err: config.rel_err,
        ..DistanceOptions::default()
    }
}

fn accuracy(c: &mut Criterion) {
    let scenes: Vec<Scene> = [Some(spheres()), bunny()].into_iter().flatten().collect();
    for scene in &scenes {
        let built: Vec<(Config, ObbtFile, ObbtFile)> = CONFIGS
            .iter()
            .map(|config| {
                let (a, b) = files(scene, config);
                (*config, a, b)
            })
            .collect();

        // Answers against the baseline.
        let id = Pose::identity();
        let mut baseline: Option<(BTreeSet<(u32, u32)>, f64)> = None;
        println!(
            "\n{}: {} and {} triangles",
            scene.name,
            scene.a.faces().len(),
            scene.b.faces().len()
        );
        println!(
            "{:>14} {:>9} {:>7} {:>7} {:>16} {:>12} {:>9}",
            "config", "contacts", "gained", "lost", "distance", "vs baseline", "D+I"
        );
        for (config, a, b) in &built {
            let mut pair = PairQuery::new(a, b).expect("one volume type");
            let hit = pair
                .collide(&id, &scene.collide_pose, &collide_options(config))
                .expect("query");
            let d = pair
                .distance(&id, &scene.distance_pose, &distance_options(config))
                .expect("query")
                .distance();
            let pairs: BTreeSet<(u32, u32)> = hit.pairs.iter().copied().collect();
            let (base_pairs, base_d) = baseline.get_or_insert_with(|| (pairs.clone(), d));
            println!(
                "{:>14} {:>9} {:>7} {:>7} {:>16.10e} {:>12.2e} {:>9}",
                config.name,
                pairs.len(),
                pairs.difference(base_pairs).count(),
                base_pairs.difference(&pairs).count(),
                d,
                (d - *base_d) / *base_d,
                hit.work.bv_disjoint + hit.work.bv_overlap,
            );
        }

        let mut group = c.benchmark_group(format!("accuracy/{}", scene.name));
        group
            .sample_size(10)
            .measurement_time(Duration::from_secs(4));
        for config in CONFIGS.iter().filter(|c| c.changes_the_file()) {
            let options = config.build_options();
            group.bench_with_input(
                BenchmarkId::new("build", config.name),
                &options,
                |bench, options| bench.iter(|| build(&scene.a, options, None).expect("builds")),
            );
        }
        for (config, a, b) in &built {
            let mut pair = PairQuery::new(a, b).expect("one volume type");
            if config.rel_err == 0.0 {
                let options = collide_options(config);
                group.bench_with_input(
                    BenchmarkId::new("collide", config.name),
                    &options,
                    |bench, options| {
                        bench.iter(|| {
                            pair.collide(&id, &scene.collide_pose, options)
                                .expect("query")
                                .pairs
                                .len()
                        })
                    },
                );
            }
            if config.guard == SAT_GUARD {
                let options = distance_options(config);
                group.bench_with_input(
                    BenchmarkId::new("distance", config.name),
                    &options,
                    |bench, options| {
                        bench.iter(|| {
                            pair.distance(&id, &scene.distance_pose, options)
                                .expect("query")
                                .distance()
                        })
                    },
                );
            }
        }
        group.finish();
    }
}

/// Distances reported for known gaps between two unit cubes (half-width 1, face to face),
/// by obbtree from f64 and f32 files and by parry3d (f32 throughout). Not timed.
fn near_contact_table(_: &mut Criterion) {
    let cube = common::cube(1.0);
    let f64_file = build(
        &cube,
        &BuildOptions {
            precision: Precision::F64,
            ..BuildOptions::default()
        },
        None,
    )
    .expect("builds");
    let f32_file = build(&cube, &BuildOptions::default(), None).expect("builds");
    let parry_cube = parry_mesh(&cube);
    let mut pair_f64 = PairQuery::new(&f64_file, &f64_file).expect("one volume type");
    let mut pair_f32 = PairQuery::new(&f32_file, &f32_file).expect("one volume type");
    println!("\nnear contact, two unit cubes face to face, a slight rotation on B:");
    println!(
        "{:>8} {:>14} {:>14} {:>14}",
        "gap", "obbtree f64", "obbtree f32", "parry3d"
    );
    // A small rotation keeps the closest features generic (not exactly parallel faces).
    let rotation: Matrix3<f64> = *nalgebra::Rotation3::from_euler_angles(0.01, 0.02, 0.03).matrix();
    for k in 1..=9 {
        let gap = 10f64.powi(-k);
        // Rotating B about its centre makes its nearest corner reach out further; shift by
        // that reach so that the gap is exact in exact arithmetic.
        let reach = common::cube(1.0)
            .vertices()
            .iter()
            .map(|p| -(rotation * Vector3::from(*p)).x)
            .fold(f64::MIN, f64::max);
        let pose = Pose::new(rotation, Vector3::new(1.0 + reach + gap, 0.0, 0.0)).expect("pose");
        let ours = |pair: &mut PairQuery<'_>| {
            pair.distance(&Pose::identity(), &pose, &DistanceOptions::default())
                .expect("query")
                .distance()
        };
        let theirs = parry3d::query::distance(
            &PPose::IDENTITY,
            &parry_cube,
            &parry_pose(&pose),
            &parry_cube,
        )
        .expect("supported")
        .distance;
        println!(
            "{gap:>8.0e} {:>14.6e} {:>14.6e} {:>14.6e}",
            ours(&mut pair_f64),
            ours(&mut pair_f32),
            theirs
        );
    }
}

criterion_group!(benches, near_contact_table, accuracy);
criterion_main!(benches);
