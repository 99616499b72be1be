//! The dissertation's benchmark scenes at a coarse tessellation, against brute force: the
//! sliding spheres of §5.3.1 (collision) and the concentric spheres (distance).

mod common;

use nalgebra::Vector3;
use obbtree::build::{build, BuildOptions};
use obbtree::format::ObbtFile;
use obbtree::query::triangle::{triangle_distance, triangles_intersect, Triangle};
use obbtree::query::{
    collide_files, distance_files, CollideOptions, DistanceOptions, Pose, QueryContext,
};
use obbtree::real::Precision;

fn triangles(mesh: &obbtree::mesh::TriMesh, pose: &Pose) -> Vec<Triangle> {
    mesh.faces()
        .iter()
        .map(|f| f.map(|v| pose.apply(&Vector3::from(mesh.vertices()[v as usize]))))
        .collect()
}

fn tree(mesh: &obbtree::mesh::TriMesh) -> ObbtFile {
    build(
        mesh,
        &BuildOptions {
            precision: Precision::F64,
            ..BuildOptions::default()
        },
        None,
    )
    .unwrap()
}

#[test]
fn sliding_spheres_match_brute_force() {
    let big = common::uv_sphere(1.0, 21, 40); // 1,600 triangles
    let small = common::uv_sphere(0.8, 21, 40);
    let (ta, tb) = (tree(&big), tree(&small));
    let a = triangles(&big, &Pose::identity());
    let mut context = QueryContext::new();
    for (step, x) in [0.0, 0.2, 0.6, 1.0, 1.4, 1.8, 2.0].into_iter().enumerate() {
        let pose = common::sliding_pose(x, step as u64);
        // Brute force in A's frame (= world, A is at the identity) with B's triangles posed.
        let b = triangles(&small, &pose);
        let mut expected = Vec::new();
        for (i, s) in a.iter().enumerate() {
            for (j, t) in b.iter().enumerate() {
                if triangles_intersect(s, t) {
                    expected.push((i as u32, j as u32));
                }
            }
        }
        let r = collide_files(
            &ta,
            &Pose::identity(),
            &tb,
            &pose,
            &CollideOptions::default(),
            &mut context,
        )
        .unwrap();
        assert_eq!(r.pairs, expected, "x = {x}");
        assert_eq!(r.stats.identity_value(), 1);
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
    let mut context = QueryContext::new();
    for seed in 0..3u64 {
        let pose = Pose::new(common::seeded_rotation(seed), Vector3::zeros()).unwrap();
        let b = triangles(&outer, &pose);
        let brute = a
            .iter()
            .flat_map(|s| b.iter().map(move |t| triangle_distance(s, t).distance))
            .fold(f64::INFINITY, f64::min);
        let r = distance_files(
            &ta,
            &Pose::identity(),
            &tb,
            &pose,
            &DistanceOptions::default(),
            &mut context,
        )
        .unwrap();
        assert!(
            (r.distance - brute).abs() <= 1e-12,
            "{} vs {brute}",
            r.distance
        );
        assert!(r.distance > 0.0 && r.distance < 0.05);
        assert_eq!(r.stats.identity_value(), 1);
    }
}
