//! Queries against brute force over all triangle pairs, for every volume type, descent
//! rule, leaf size and precision, on random small meshes (degenerate and coplanar ones
//! included) under random poses.
//!
//! The brute force reads the same stored triangles and maps B into A's frame with the same
//! relative transform, so the answers must agree exactly for collision and to 1e-9 for
//! distance; `f32_world_frame_disagreement` measures how often deciding contact in the world
//! frame instead would differ.
// Test code outside `#[test]` functions (helpers, property bodies): a failure is a failed test.
#![allow(
    clippy::unwrap_used,
    clippy::indexing_slicing,
    clippy::unwrap_in_result
)]

mod common;

use common::oracle;
use nalgebra::{Rotation3, Vector3};
use obbtree::build::build;
use obbtree::format::ObbtFile;
use obbtree::mesh::TriMesh;
use obbtree::query::triangle::{triangle_distance, Triangle};
use obbtree::query::{
    collide_files, distance_files, span_files, within_tolerance_files, CollideOptions, DescentRule,
    DistanceOptions, PairQuery, Pose, QueryContext,
};
use proptest::prelude::*;

/// The stored triangles of a file, by input-mesh id, in its model frame.
fn stored(file: &ObbtFile) -> Vec<Triangle> {
    let faces = common::file_triangles(file);
    let mut out = vec![[Vector3::zeros(); 3]; faces.len()];
    for (id, t) in faces {
        out[id as usize] = t.map(Vector3::from);
    }
    out
}

fn mesh_strategy() -> impl Strategy<Value = TriMesh> {
    let coordinate = prop_oneof![
        3 => -1.0..1.0f64,
        // Snapped to a coarse grid: exact coplanarity, shared edges and exact touching.
        2 => (-4i32..=4).prop_map(|k| f64::from(k) * 0.25),
    ];
    let vertex = prop::array::uniform3(coordinate);
    (
        prop::collection::vec(vertex, 3..40),
        prop::collection::vec(prop::array::uniform3(0usize..1000), 1..60),
    )
        .prop_map(|(vertices, faces)| {
            let n = vertices.len();
            let faces = faces
                .into_iter()
                .map(|f| f.map(|i| (i % n) as u32))
                .collect();
            TriMesh::new(vertices, faces).unwrap()
        })
}

fn pose_strategy() -> impl Strategy<Value = Pose> {
    (
        prop::array::uniform3(-3.2..3.2f64),
        prop::array::uniform3(-1.0..1.0f64),
    )
        .prop_map(|(e, t)| {
            let r = *Rotation3::from_euler_angles(e[0], e[1], e[2]).matrix();
            Pose::new(r, Vector3::from(t)).unwrap()
        })
}

fn point_on_triangle(p: &Vector3<f64>, t: &Triangle, tolerance: f64) -> bool {
    // Distance from p to the triangle, via the primitive with a degenerate triangle.
    triangle_distance(&[*p, *p, *p], t).distance <= tolerance
}

fn check_all(
    mesh_a: &TriMesh,
    mesh_b: &TriMesh,
    pose_a: &Pose,
    pose_b: &Pose,
) -> Result<(), TestCaseError> {
    let mut context = QueryContext::new();
    for options in common::all_options() {
        let fa = build(mesh_a, &options, None).unwrap();
        let fb = build(mesh_b, &options, None).unwrap();
        let (ta, tb) = (stored(&fa), stored(&fb));
        let brute = oracle::Answers::of(&ta, &oracle::in_frame_of_a(pose_a, pose_b, &tb));
        let binary = fa.info().leaf_size == 1 && fb.info().leaf_size == 1;
        for rule in DescentRule::ALL {
            let what = format!("{options:?} {rule:?}");
            let all = collide_files(
                &fa,
                pose_a,
                &fb,
                pose_b,
                &CollideOptions {
                    rule,
                    ..CollideOptions::default()
                },
                &mut context,
            )
            .unwrap();
            prop_assert_eq!(&all.pairs, &brute.pairs, "{}", what);
            if binary {
                prop_assert_eq!(all.stats.identity_value(), 1, "{} {:?}", what, all.stats);
            }
            let first = CollideOptions {
                rule,
                first_contact: true,
                ..CollideOptions::default()
            };
            let one = collide_files(&fa, pose_a, &fb, pose_b, &first, &mut context).unwrap();
            prop_assert_eq!(one.colliding, !brute.pairs.is_empty(), "{}", what);
            prop_assert!(one.pairs.iter().all(|p| brute.pairs.contains(p)));

            let d = distance_files(
                &fa,
                pose_a,
                &fb,
                pose_b,
                &DistanceOptions {
                    rule,
                    ..DistanceOptions::default()
                },
                &mut context,
            )
            .unwrap();
            let scale = 1.0 + brute.min_distance;
            prop_assert!(
                (d.distance - brute.min_distance).abs() <= 1e-9 * scale,
                "{} {} vs {}",
                what,
                d.distance,
                brute.min_distance
            );
            prop_assert_eq!(d.distance == 0.0, !brute.pairs.is_empty(), "{}", what);
            // The points lie on the reported triangles (world frame) and realise the distance.
            let world = |t: &Triangle, pose: &Pose| t.map(|p| pose.apply(&p));
            prop_assert!(point_on_triangle(
                &d.point_a,
                &world(&ta[d.tri_a as usize], pose_a),
                1e-9 * scale
            ));
            prop_assert!(point_on_triangle(
                &d.point_b,
                &world(&tb[d.tri_b as usize], pose_b),
                1e-9 * scale
            ));
            prop_assert!(((d.point_a - d.point_b).norm() - d.distance).abs() <= 1e-9 * scale);
            if binary && d.distance > 0.0 {
                prop_assert_eq!(d.stats.identity_value(), 1, "{} {:?}", what, d.stats);
            }

            let s = span_files(&fa, pose_a, &fb, pose_b, rule, &mut context).unwrap();
            prop_assert!(
                (s.span - brute.max_distance).abs() <= 1e-9 * (1.0 + brute.max_distance),
                "{} span {} vs {}",
                what,
                s.span,
                brute.max_distance
            );
            prop_assert!(((s.point_a - s.point_b).norm() - s.span).abs() <= 1e-9 * (1.0 + s.span));
            if binary {
                prop_assert_eq!(s.stats.identity_value(), 1, "{} {:?}", what, s.stats);
            }
        }
        // Tolerance: agrees with the exact distance away from the threshold.
        for t in [brute.min_distance * 0.5, brute.min_distance * 1.5 + 1e-9] {
            let r = within_tolerance_files(
                &fa,
                pose_a,
                &fb,
                pose_b,
                t,
                DescentRule::default(),
                &mut context,
            )
            .unwrap();
            prop_assert_eq!(r.closer, brute.min_distance < t);
            if let Some(w) = r.witness {
                prop_assert!(w.distance < t);
            }
        }
        // The pair object answers as the free functions do; a limit gives `None` exactly
        // when the distance reaches it; a warm start from any pair changes nothing but work.
        let mut pair = PairQuery::new(&fa, &fb).unwrap();
        let all = pair
            .collide(pose_a, pose_b, &CollideOptions::default())
            .unwrap();
        prop_assert_eq!(&all.pairs, &brute.pairs);
        let first = pair.first_contact(pose_a, pose_b).unwrap();
        prop_assert_eq!(first.is_some(), !brute.pairs.is_empty());
        prop_assert!(first.is_none_or(|p| brute.pairs.contains(&p)));
        let exact = DistanceOptions::default();
        let scale = 1.0 + brute.min_distance;
        let moved = Pose::new(
            *pose_b.rotation(),
            pose_b.translation_vector() + Vector3::new(0.3, -0.2, 0.1),
        )
        .unwrap();
        let elsewhere = pair.distance(pose_a, &moved, &exact).unwrap().witness;
        // Limits, also with an error allowance and a warm start from another pose (whose
        // pair may lie beyond the limit: the allowance must not then hide closer pairs).
        let approximate = DistanceOptions {
            rel_err: 0.3,
            warm_start: Some(elsewhere),
            ..DistanceOptions::default()
        };
        let limits = [0.5, 1.05, 1.5].map(|f| brute.min_distance * f + 1e-9);
        for limit in limits {
            for (options, rel) in [(&exact, 0.0), (&approximate, 0.3)] {
                let (r, _) = pair.distance_below(pose_a, pose_b, options, limit).unwrap();
                match r {
                    Some(r) => {
                        prop_assert!(brute.min_distance < limit);
                        prop_assert!(r.distance >= brute.min_distance - 1e-9 * scale);
                        prop_assert!(r.distance <= brute.min_distance * (1.0 + rel) + 1e-9 * scale);
                    }
                    None => prop_assert!(brute.min_distance >= limit - 1e-9 * scale),
                }
            }
        }
        let cold = pair.distance(pose_a, pose_b, &exact).unwrap();
        for start in [cold.witness, elsewhere] {
            let warm = DistanceOptions {
                warm_start: Some(start),
                ..DistanceOptions::default()
            };
            let d = pair.distance(pose_a, pose_b, &warm).unwrap();
            prop_assert!((d.distance - brute.min_distance).abs() <= 1e-9 * scale);
            prop_assert!(d.stats.tri_separated + d.stats.tri_contact >= 1);
        }
        // Approximate distance keeps its documented guarantee.
        for (rel, abs) in [(0.1, 0.0), (0.0, 0.05), (0.5, 0.01)] {
            let o = DistanceOptions {
                rel_err: rel,
                abs_err: abs,
                ..DistanceOptions::default()
            };
            let d = distance_files(&fa, pose_a, &fb, pose_b, &o, &mut context).unwrap();
            let exact = brute.min_distance;
            prop_assert!(d.distance >= exact - 1e-9 * (1.0 + exact));
            prop_assert!(
                d.distance <= (exact * (1.0 + rel)).max(exact + abs) + 1e-9 * (1.0 + exact)
            );
        }
    }
    Ok(())
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 48, ..ProptestConfig::default() })]

    #[test]
    fn queries_match_brute_force(a in mesh_strategy(), b in mesh_strategy(), pa in pose_strategy(), pb in pose_strategy()) {
        check_all(&a, &b, &pa, &pb)?;
    }
}

#[test]
fn queries_match_brute_force_on_overlapping_spheres() {
    let a = common::uv_sphere(1.0, 8, 12);
    let b = common::uv_sphere(0.8, 7, 10);
    for (x, angle) in [(0.0, 0.3), (0.3, 1.1), (1.0, 2.0), (1.79, 0.7), (2.5, 0.1)] {
        let rotation = *Rotation3::from_euler_angles(angle, 0.5 * angle, -angle).matrix();
        let pb = Pose::new(rotation, Vector3::new(x, 0.0, 0.0)).unwrap();
        check_all(&a, &b, &Pose::identity(), &pb).unwrap();
    }
}

#[test]
fn identical_coplanar_grids_touch_everywhere_they_overlap() {
    let g = common::grid(3);
    check_all(&g, &g, &Pose::identity(), &Pose::identity()).unwrap();
    check_all(&g, &g, &Pose::identity(), &Pose::translation(1.0, 0.5, 0.0)).unwrap();
    check_all(
        &g,
        &g,
        &Pose::identity(),
        &Pose::translation(0.0, 0.0, 1e-9),
    )
    .unwrap();
}

#[test]
fn queries_match_brute_force_at_small_and_large_scales() {
    for scale in [1e-3, 1e3] {
        let a = common::uv_sphere(scale, 7, 10);
        let b = common::uv_sphere(0.8 * scale, 6, 9);
        for (x, angle) in [(0.5, 0.4), (1.2, 1.3)] {
            let rotation = *Rotation3::from_euler_angles(angle, -angle, 0.3).matrix();
            let pb = Pose::new(rotation, Vector3::new(x * scale, 0.1 * scale, 0.0)).unwrap();
            check_all(&a, &b, &Pose::identity(), &pb).unwrap();
        }
    }
}

#[test]
fn a_pair_query_refuses_trees_of_different_kinds_and_reuses_its_buffers() {
    let cow = common::cow();
    let obb = build(&cow, &obbtree::build::BuildOptions::default(), None).unwrap();
    let aabb = build(
        &cow,
        &obbtree::build::BuildOptions {
            bv: obbtree::bv::BvKind::Aabb,
            ..Default::default()
        },
        None,
    )
    .unwrap();
    assert!(PairQuery::new(&obb, &aabb).is_err());
    let mut pair = PairQuery::new(&obb, &obb).unwrap();
    let shifted = Pose::translation(0.2, 0.0, 0.0);
    let mut result = pair
        .collide(&Pose::identity(), &shifted, &CollideOptions::default())
        .unwrap();
    assert!(result.pairs.len() > 100, "{}", result.pairs.len());
    let buffer = result.pairs.as_ptr();
    // Fewer contacts further out: the same buffer holds them.
    let further = Pose::translation(0.5, 0.0, 0.0);
    pair.collide_into(
        &Pose::identity(),
        &further,
        &CollideOptions::default(),
        &mut result,
    )
    .unwrap();
    assert_eq!(result.pairs.as_ptr(), buffer);
    let mut context = QueryContext::new();
    let expected = collide_files(
        &obb,
        &Pose::identity(),
        &obb,
        &further,
        &CollideOptions::default(),
        &mut context,
    )
    .unwrap();
    assert_eq!(result, expected);
}

/// Over a smooth trajectory the previous answer's pair bounds the next query from the
/// start: the same distances, fewer triangle and box tests.
#[test]
fn warm_started_distances_equal_cold_ones_with_less_work() {
    let cow = common::cow();
    let file = build(&cow, &obbtree::build::BuildOptions::default(), None).unwrap();
    let mut pair = PairQuery::new(&file, &file).unwrap();
    let (mut cold_work, mut warm_work) = (0, 0);
    let mut previous = None;
    for step in 0..50 {
        let t = f64::from(step) * 0.02;
        let rotation = *Rotation3::from_euler_angles(0.0, 0.3 * t, t).matrix();
        let pose = Pose::new(rotation, Vector3::new(1.3 + 0.2 * t.sin(), 0.1 * t, 0.0)).unwrap();
        let cold = pair
            .distance(&Pose::identity(), &pose, &DistanceOptions::default())
            .unwrap();
        let warm = pair
            .distance(
                &Pose::identity(),
                &pose,
                &DistanceOptions {
                    warm_start: previous,
                    ..DistanceOptions::default()
                },
            )
            .unwrap();
        assert_eq!(warm.distance, cold.distance, "step {step}");
        previous = Some(warm.witness);
        cold_work += cold.stats.nodes_visited;
        warm_work += warm.stats.nodes_visited;
    }
    assert!(warm_work < cold_work, "warm {warm_work} cold {cold_work}");
}
