//! The query work a tree makes, to compare build choices by how well their trees prune:
//! `cargo run --release --example tree_work -- MESH|sphere [HULL_MIN_FACES] [HULL_MAX_POINTS|all]
//! [triangles]`.
//!
//! Builds the mesh (or a 40,000-triangle lat/long sphere) with the default options, or with
//! the given `hull_min_faces`, `hull_max_points` and fit, then queries it against a turned copy at 40 fixed
//! poses: all-pairs collision and first contact with the copy moved 0.2 to 0.65 of the
//! model's diagonal, exact distance with it 1.05 to 3 diagonals away. Prints the
//! one-thread build time and the summed work (deterministic, unlike the time).
// A tool developers run by hand: stopping loudly on a broken input is what it should do.
#![allow(clippy::expect_used, clippy::indexing_slicing)]

#[path = "../tests/common/mod.rs"]
mod common;

use nalgebra::Vector3;
use obbtree::build::{build, BuildOptions};
use obbtree::fit::FitMethod;
use obbtree::mesh::TriMesh;
use obbtree::query::{CollideOptions, DistanceOptions, PairQuery, Pose};

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let Some(name) = args.get(1) else {
        eprintln!("usage: tree_work MESH|sphere [HULL_MIN_FACES] [HULL_MAX_POINTS] [triangles]");
        std::process::exit(2);
    };
    let mesh = if name == "sphere" {
        common::uv_sphere(1.0, 101, 200)
    } else {
        TriMesh::load(name.as_ref()).unwrap_or_else(|e| {
            eprintln!("{e}");
            std::process::exit(1)
        })
    };
    let defaults = BuildOptions::default();
    let options = BuildOptions {
        hull_min_faces: args
            .get(2)
            .and_then(|s| s.parse().ok())
            .unwrap_or(defaults.hull_min_faces),
        hull_max_points: args
            .get(3)
            .and_then(|s| BuildOptions::parse_hull_max_points(s))
            .unwrap_or(defaults.hull_max_points),
        fit: match args.get(4).map(String::as_str) {
            Some("triangles") => FitMethod::Triangles,
            _ => defaults.fit,
        },
        ..defaults
    };
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(1)
        .build()
        .expect("a pool");
    let started = std::time::Instant::now();
    let file = pool
        .install(|| build(&mesh, &options, None))
        .expect("builds");
    let build_ms = started.elapsed().as_secs_f64() * 1e3;
    let info = file.info();
    let diagonal = (0..3)
        .map(|k| (info.stats.bounds_max[k] - info.stats.bounds_min[k]).powi(2))
        .sum::<f64>()
        .sqrt();
    let mut pair = PairQuery::new(&file, &file).expect("one volume type");
    let here = Pose::identity();
    let mut contacts = Default::default();
    let (mut collide_tests, mut first_nodes, mut distance_nodes, mut distance_tris) = (0, 0, 0, 0);
    for k in 0..40u64 {
        let turn = common::rng::seeded_rotation(k + 1);
        let direction = common::rng::seeded_rotation(k + 101) * Vector3::x();
        let near = [0.2, 0.35, 0.5, 0.65][(k % 4) as usize];
        let near = Pose::new(turn, direction * diagonal * near).expect("a rotation");
        pair.collide_into(&here, &near, &CollideOptions::default(), &mut contacts)
            .expect("collide");
        collide_tests += contacts.work.bv_disjoint + contacts.work.bv_overlap;
        let first = CollideOptions {
            first_contact: true,
            ..CollideOptions::default()
        };
        first_nodes += pair
            .collide(&here, &near, &first)
            .expect("first")
            .work
            .nodes_visited;
        let far = [1.05, 1.2, 1.5, 3.0][(k % 4) as usize];
        let far = Pose::new(turn, direction * diagonal * far).expect("a rotation");
        let d = pair
            .distance(&here, &far, &DistanceOptions::default())
            .expect("distance");
        distance_nodes += d.work.nodes_visited;
        distance_tris += d.work.tri_separated + d.work.tri_contact;
    }
    println!(
        "{name}: build {build_ms:.1} ms (1 thread); collide box tests {collide_tests}; \
         first contact node pairs {first_nodes}; distance node pairs {distance_nodes}, \
         triangle pairs {distance_tris}"
    );
}
