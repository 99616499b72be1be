//! The dissertation's benchmark scenes at a coarse tessellation, against brute force: the
//! sliding spheres of §5.3.1 (collision) and the concentric spheres (distance).

use crate::common;

use common::oracle;
use nalgebra::Vector3;
use obbtree::build::{build, BuildOptions};
use obbtree::query::triangle::{triangle_distance, Triangle};
use obbtree::query::{CollideOptions, DistanceOptions, PairQuery, Pose};

fn triangles(mesh: &obbtree::mesh::TriMesh, pose: &Pose) -> Vec<Triangle> {
    oracle::posed(mesh.vertices(), mesh.faces(), pose)
}

use common::tree_f64 as tree;

#[test]
fn sliding_spheres_match_brute_force() {
    let big = common::uv_sphere(1.0, 21, 40); // 1,600 triangles
    let small = common::uv_sphere(0.8, 21, 40);
    let (ta, tb) = (tree(&big), tree(&small));
    let a = triangles(&big, &Pose::identity());
    let mut pair = PairQuery::new(&ta, &tb).unwrap();
    for (step, x) in [0.0, 0.2, 0.6, 1.0, 1.4, 1.8, 2.0].into_iter().enumerate() {
        let pose = common::sliding_pose(x, step as u64);
        // Brute force in A's frame (= world, A is at the identity) with B's triangles posed.
        let b = triangles(&small, &pose);
        let expected = oracle::contact_pairs(&a, &b);
        let r = pair
            .collide(&Pose::identity(), &pose, &CollideOptions::default())
            .unwrap();
        assert_eq!(r.pairs, expected, "x = {x}");
        assert_eq!(r.work.identity_value(), 1);
        // The surfaces cross well inside 0.2 < x < 1.8 (both ends are tangent in the smooth
        // scene, so tessellation decides there); nested at 0, apart at 2.
        if [0.6, 1.0, 1.4].contains(&x) {
            assert!(r.colliding, "x = {x}");
        }
        if [0.0, 2.0].contains(&x) {
            assert!(!r.colliding, "x = {x}");
        }
    }
}

#[test]
fn concentric_spheres_distance_matches_brute_force() {
    let inner = common::uv_sphere(1.0, 16, 30);
    let outer = common::uv_sphere(1.05, 16, 30);
    let (ta, tb) = (tree(&inner), tree(&outer));
    let a = triangles(&inner, &Pose::identity());
    let mut pair = PairQuery::new(&ta, &tb).unwrap();
    for seed in 0..3u64 {
        let pose = Pose::new(common::rng::seeded_rotation(seed), Vector3::zeros()).unwrap();
        let b = triangles(&outer, &pose);
        let brute = oracle::min_distance(&a, &b);
        let r = pair
            .distance(&Pose::identity(), &pose, &DistanceOptions::default())
            .unwrap();
        assert!(
            (r.distance() - brute).abs() <= 1e-12,
            "{} vs {brute}",
            r.distance()
        );
        assert!(r.distance() > 0.0 && r.distance() < 0.05);
        assert_eq!(r.work.identity_value(), 1);
    }
}

/// How often an f32 file's contacts differ from an f64 brute force over the input mesh in
/// the world frame, and that every difference is a pair within a few f32 ulps of touching.
/// Run with `--nocapture` to see the counts (quoted in docs/BENCHMARKS.md).
#[test]
fn f32_contacts_differ_from_f64_brute_force_only_at_touching_pairs() {
    let big = common::uv_sphere(1.0, 21, 40);
    let small = common::uv_sphere(0.8, 21, 40);
    let options = BuildOptions::default(); // f32
    let (ta, tb) = (
        build(&big, &options, None).unwrap(),
        build(&small, &options, None).unwrap(),
    );
    let a = triangles(&big, &Pose::identity());
    let mut pair = PairQuery::new(&ta, &tb).unwrap();
    let (mut total, mut differing, mut worst) = (0usize, 0usize, 0.0f64);
    for step in 0..40u64 {
        let x = 0.05 * step as f64;
        let pose = common::sliding_pose(x, 100 + step);
        let b = triangles(&small, &pose);
        let expected: std::collections::BTreeSet<(u32, u32)> =
            oracle::contact_pairs(&a, &b).into_iter().collect();
        let found: std::collections::BTreeSet<(u32, u32)> = pair
            .collide(&Pose::identity(), &pose, &CollideOptions::default())
            .unwrap()
            .pairs
            .into_iter()
            .collect();
        total += expected.len();
        for &(i, j) in expected.symmetric_difference(&found) {
            differing += 1;
            let d = triangle_distance(&a[i as usize], &b[j as usize]).distance;
            worst = worst.max(d);
            // f32 rounding moves a unit-scale vertex by at most 6e-8.
            assert!(
                d <= 2e-7,
                "x = {x}: pair ({i}, {j}) differs but is {d} apart"
            );
        }
    }
    println!("f32 vs f64 world-frame brute force: {differing} of {total} contacting pairs differ; largest gap among them {worst:e}");
    assert!(total > 2_000);
}
