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
    clippy::expect_used,
    clippy::indexing_slicing,
    clippy::unwrap_in_result
)]

use crate::common;

use common::oracle;
use nalgebra::{Rotation3, Vector3};
use obbtree::build::build;
use obbtree::bv::BoundingVolume;
use obbtree::format::ObbtFile;
use obbtree::mesh::TriMesh;
use obbtree::query::details::{self, QueryContext};
use obbtree::query::triangle::{triangle_distance, Triangle};
use obbtree::query::{
    CollideOptions, DescentRule, DistanceOptions, PairQuery, Pose, SpanOptions, ToleranceOptions,
};
use obbtree::tree::TreeView;
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

/// The queries over typed views ([`details`]) against brute force, for every descent
/// rule: what [`check_all`] runs on each build's views.
struct CheckViews<'a> {
    what: String,
    pose_a: &'a Pose,
    pose_b: &'a Pose,
    ta: &'a [Triangle],
    tb: &'a [Triangle],
    brute: &'a oracle::Answers,
    binary: bool,
    context: &'a mut QueryContext,
}

impl common::ViewsVisitor for CheckViews<'_> {
    type Output = Result<(), TestCaseError>;

    fn visit<B: BoundingVolume>(self, va: &TreeView<'_, B>, vb: &TreeView<'_, B>) -> Self::Output {
        let CheckViews {
            what: options,
            pose_a,
            pose_b,
            ta,
            tb,
            brute,
            binary,
            context,
        } = self;
        for rule in DescentRule::ALL {
            let what = format!("{options} {rule:?}");
            let all = details::collide(
                va,
                pose_a,
                vb,
                pose_b,
                &CollideOptions {
                    rule,
                    ..CollideOptions::default()
                },
                context,
            )
            .unwrap();
            prop_assert_eq!(&all.pairs, &brute.pairs, "{}", what);
            if binary {
                prop_assert_eq!(all.work.identity_value(), 1, "{} {:?}", what, all.work);
            }
            let first = CollideOptions {
                rule,
                first_contact: true,
                ..CollideOptions::default()
            };
            let one = details::collide(va, pose_a, vb, pose_b, &first, context).unwrap();
            prop_assert_eq!(one.colliding, !brute.pairs.is_empty(), "{}", what);
            prop_assert!(one.pairs.iter().all(|p| brute.pairs.contains(p)));

            let r = details::distance(
                va,
                pose_a,
                vb,
                pose_b,
                &DistanceOptions {
                    rule,
                    ..DistanceOptions::default()
                },
                context,
            )
            .unwrap();
            let d = r.closest.expect("no maximum distance");
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
                prop_assert_eq!(r.work.identity_value(), 1, "{} {:?}", what, r.work);
            }

            let s = details::span(va, pose_a, vb, pose_b, &SpanOptions { rule }, context).unwrap();
            prop_assert!(
                (s.span() - brute.max_distance).abs() <= 1e-9 * (1.0 + brute.max_distance),
                "{} span {} vs {}",
                what,
                s.span(),
                brute.max_distance
            );
            let far = s.farthest;
            prop_assert!(
                ((far.point_a - far.point_b).norm() - s.span()).abs() <= 1e-9 * (1.0 + s.span())
            );
            if binary {
                prop_assert_eq!(s.work.identity_value(), 1, "{} {:?}", what, s.work);
            }
        }
        // Tolerance: agrees with the exact distance away from the threshold.
        for t in [brute.min_distance * 0.5, brute.min_distance * 1.5 + 1e-9] {
            let tolerance = ToleranceOptions {
                tolerance: t,
                rule: DescentRule::default(),
            };
            let r = details::within(va, pose_a, vb, pose_b, &tolerance, context).unwrap();
            prop_assert_eq!(r.closer(), brute.min_distance < t);
            if let Some(w) = r.witness {
                prop_assert!(w.distance < t);
            }
        }
        // Approximate distance keeps its documented guarantee.
        for (rel, abs) in [(0.1, 0.0), (0.0, 0.05), (0.5, 0.01)] {
            let o = DistanceOptions {
                rel_err: rel,
                abs_err: abs,
                ..DistanceOptions::default()
            };
            let d = details::distance(va, pose_a, vb, pose_b, &o, context)
                .unwrap()
                .distance();
            let exact = brute.min_distance;
            prop_assert!(d >= exact - 1e-9 * (1.0 + exact));
            prop_assert!(d <= (exact * (1.0 + rel)).max(exact + abs) + 1e-9 * (1.0 + exact));
        }
        Ok(())
    }
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
        common::with_views(
            &fa,
            &fb,
            CheckViews {
                what: format!("{options:?}"),
                pose_a,
                pose_b,
                ta: &ta,
                tb: &tb,
                brute: &brute,
                binary,
                context: &mut context,
            },
        )?;
        // The pair object answers as the typed functions do; a maximum distance gives no
        // pair exactly when the distance reaches it; a warm start from any pair changes
        // nothing but work.
        let mut pair = PairQuery::new(&fa, &fb).unwrap();
        let all = pair
            .collide(pose_a, pose_b, &CollideOptions::default())
            .unwrap();
        prop_assert_eq!(&all.pairs, &brute.pairs);
        let first_contact = CollideOptions {
            first_contact: true,
            ..CollideOptions::default()
        };
        let first = pair
            .collide(pose_a, pose_b, &first_contact)
            .unwrap()
            .pairs
            .first()
            .copied();
        prop_assert_eq!(first.is_some(), !brute.pairs.is_empty());
        prop_assert!(first.is_none_or(|p| brute.pairs.contains(&p)));
        let exact = DistanceOptions::default();
        let scale = 1.0 + brute.min_distance;
        let moved = Pose::new(
            *pose_b.rotation(),
            pose_b.translation_vector() + Vector3::new(0.3, -0.2, 0.1),
        )
        .unwrap();
        let elsewhere = pair
            .distance(pose_a, &moved, &exact)
            .unwrap()
            .warm_start
            .expect("no maximum distance");
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
                let below = DistanceOptions {
                    max_distance: limit,
                    ..*options
                };
                let r = pair.distance(pose_a, pose_b, &below).unwrap().closest;
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
        let cold_start = cold.warm_start.expect("no maximum distance");
        for start in [cold_start, elsewhere] {
            let warm = DistanceOptions {
                warm_start: Some(start),
                ..DistanceOptions::default()
            };
            let d = pair.distance(pose_a, pose_b, &warm).unwrap();
            prop_assert!((d.distance() - brute.min_distance).abs() <= 1e-9 * scale);
            prop_assert!(d.work.tri_separated + d.work.tri_contact >= 1);
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
    let shown = format!("{pair:?}");
    assert!(
        shown.starts_with("PairQuery") && shown.contains("Obb"),
        "{shown}"
    );
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
    // And it answers as the typed function does.
    struct Collide<'a>(&'a Pose);
    impl common::ViewsVisitor for Collide<'_> {
        type Output = obbtree::query::CollideResult;
        fn visit<B: BoundingVolume>(
            self,
            a: &TreeView<'_, B>,
            b: &TreeView<'_, B>,
        ) -> Self::Output {
            let mut context = QueryContext::new();
            let (here, options) = (Pose::identity(), CollideOptions::default());
            details::collide(a, &here, b, self.0, &options, &mut context).unwrap()
        }
    }
    let expected = common::with_views(&obb, &obb, Collide(&further));
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
        assert_eq!(warm.distance(), cold.distance(), "step {step}");
        previous = warm.warm_start;
        cold_work += cold.work.nodes_visited;
        warm_work += warm.work.nodes_visited;
    }
    assert!(warm_work < cold_work, "warm {warm_work} cold {cold_work}");
    // A warm start that touches ends the query at once, and counts as the one test made.
    let here = Pose::identity();
    let touching = pair
        .distance(&here, &here, &DistanceOptions::default())
        .unwrap();
    let again = DistanceOptions {
        warm_start: touching.warm_start,
        ..DistanceOptions::default()
    };
    let warm = pair.distance(&here, &here, &again).unwrap();
    assert_eq!(warm.distance(), 0.0);
    let one_contact = obbtree::query::Work {
        tri_contact: 1,
        ..Default::default()
    };
    assert_eq!(warm.work, one_contact);
}

/// A mesh of one triangle per three consecutive `vertices`, none sharing a corner.
fn separate_triangles(vertices: Vec<[f64; 3]>) -> TriMesh {
    let faces = (0..vertices.len() as u32 / 3)
        .map(|i| [3 * i, 3 * i + 1, 3 * i + 2])
        .collect();
    TriMesh::new(vertices, faces).expect("triangles")
}

/// "Closer than t?" is strict, and a pair at exactly `t` does not end the search: one leaf
/// of B holds, first, a triangle exactly `t` above A's and, second, one at `t / 2`.
#[test]
fn a_pair_at_exactly_the_tolerance_does_not_end_the_search() {
    let triangle = |z: f64| [[0.0, 0.0, z], [1.0, 0.0, z], [0.0, 1.0, z]];
    let mesh = |zs: &[f64]| separate_triangles(zs.iter().flat_map(|&z| triangle(z)).collect());
    let options = obbtree::build::BuildOptions {
        leaf_size: 2,
        ..Default::default()
    };
    let a = build(&mesh(&[0.0]), &options, None).expect("builds");
    let b = build(&mesh(&[0.5, 0.25]), &options, None).expect("builds");
    let mut pair = PairQuery::new(&a, &b).expect("a pair");
    let here = Pose::identity();
    let within = |pair: &mut PairQuery<'_>, tolerance: f64| {
        let options = ToleranceOptions {
            tolerance,
            rule: DescentRule::default(),
        };
        pair.within(&here, &here, &options).expect("answers")
    };
    let found = within(&mut pair, 0.5);
    let witness = found
        .witness
        .expect("the lower triangle is closer than 0.5");
    assert_eq!((witness.tri_b, witness.distance), (1, 0.25));
    assert!(
        !within(&mut pair, 0.25).closer(),
        "0.25 is not closer than 0.25"
    );
}

/// A maximum distance excludes pairs at exactly that distance, and a pair found there does
/// not let the error allowance prune pairs below it: B's first triangle lies exactly
/// `max_distance` above A's (measured first, as the warm start), its second `1/32` less,
/// within the 5% allowed, and that one is the answer.
#[test]
fn a_pair_at_exactly_the_maximum_distance_is_not_an_answer() {
    let options = obbtree::build::BuildOptions::default();
    let a = build(
        &separate_triangles(vec![[0.0, 0.0, 0.0], [8.0, 0.0, 0.0], [0.0, 8.0, 0.0]]),
        &options,
        None,
    )
    .expect("builds");
    let low = 0.96875;
    let b = build(
        &separate_triangles(vec![
            [0.0, 0.0, 1.0],
            [0.5, 0.0, 1.0],
            [0.0, 0.5, 1.0],
            [3.0, 0.0, low],
            [4.0, 0.0, low],
            [3.0, 1.0, low],
        ]),
        &options,
        None,
    )
    .expect("builds");
    let mut pair = PairQuery::new(&a, &b).expect("a pair");
    let here = Pose::identity();
    // Moved 7 along x, only B's first triangle is over A's: the warm start is that pair.
    let moved = Pose::translation(7.0, 0.0, 0.0);
    let first = pair
        .distance(&here, &moved, &DistanceOptions::default())
        .expect("answers");
    assert_eq!(first.closest.map(|w| (w.tri_b, w.distance)), Some((0, 1.0)));
    let options = DistanceOptions {
        rel_err: 0.05,
        max_distance: 1.0,
        warm_start: first.warm_start,
        ..Default::default()
    };
    let got = pair.distance(&here, &here, &options).expect("answers");
    assert_eq!(got.closest.map(|w| (w.tri_b, w.distance)), Some((1, low)));
    // Without the lower triangle in range, nothing is: 1.0 is not below 1.0.
    let options = DistanceOptions {
        max_distance: low,
        ..options
    };
    let got = pair.distance(&here, &here, &options).expect("answers");
    assert_eq!(got.closest, None);
}

/// The allowances and the maximum prune as documented: a `max_distance` of 0 or less is
/// refused (nothing is below 0); models exactly the maximum apart are beyond it (a pair
/// at the maximum is not below it); with an absolute error as large as the models, the
/// first triangle pair measured is within it of every other, and nothing more is
/// measured.
#[test]
fn the_maximum_and_the_absolute_error_end_the_search_where_they_say() {
    let cow = common::cow();
    let file = build(&cow, &obbtree::build::BuildOptions::default(), None).unwrap();
    let mut pair = PairQuery::new(&file, &file).unwrap();
    let here = Pose::identity();
    for refused in [0.0, -1.0, f64::NAN] {
        let options = DistanceOptions {
            max_distance: refused,
            ..DistanceOptions::default()
        };
        let error = pair.distance(&here, &here, &options).unwrap_err();
        assert!(
            error
                .to_string()
                .contains("max_distance must be greater than 0"),
            "{error}"
        );
    }
    // Models further apart than the maximum: their root pair is the only one tested.
    let apart = Pose::translation(1.5, 0.0, 0.0);
    let near = DistanceOptions {
        max_distance: 0.01,
        ..DistanceOptions::default()
    };
    let beyond = pair.distance(&here, &apart, &near).unwrap();
    assert_eq!(beyond.closest, None);
    assert_eq!(beyond.work.nodes_visited, 1, "{:?}", beyond.work);
    let exact = pair
        .distance(&here, &apart, &DistanceOptions::default())
        .unwrap();
    // A maximum of exactly the distance: the closest pair is at it, not below it.
    let at = |max_distance| DistanceOptions {
        max_distance,
        ..DistanceOptions::default()
    };
    let at_the_distance = pair.distance(&here, &apart, &at(exact.distance())).unwrap();
    assert_eq!(at_the_distance.closest, None);
    let above = at(exact.distance().next_up());
    assert_eq!(
        pair.distance(&here, &apart, &above).unwrap().distance(),
        exact.distance()
    );
    let loose = DistanceOptions {
        abs_err: 10.0,
        ..DistanceOptions::default()
    };
    let first = pair.distance(&here, &apart, &loose).unwrap();
    assert_eq!(
        first.work.tri_separated + first.work.tri_contact,
        1,
        "{:?}",
        first.work
    );
    assert!(first.distance() <= exact.distance() + 10.0);
    assert!(exact.work.tri_separated > 1, "{:?}", exact.work);
    // An allowance of exactly that first distance prunes everything after it too (every
    // bound is at least 0); below 1, a product in its place would not.
    let d1 = first.distance();
    assert!(d1 < 1.0, "{d1}");
    let just = DistanceOptions {
        abs_err: d1,
        ..DistanceOptions::default()
    };
    let again = pair.distance(&here, &apart, &just).unwrap();
    assert_eq!((again.distance(), again.work), (d1, first.work));
}

/// A span of 0 is an answer: two models that are one and the same point (a triangle whose
/// corners coincide) are nowhere apart.
#[test]
fn two_models_at_one_point_span_zero() {
    let point = TriMesh::new(vec![[0.25, 0.5, 1.0]; 3], vec![[0, 1, 2]]).expect("a triangle");
    let file = build(&point, &obbtree::build::BuildOptions::default(), None).expect("builds");
    let mut pair = PairQuery::new(&file, &file).expect("a pair");
    let here = Pose::identity();
    let span = pair
        .span(&here, &here, &SpanOptions::default())
        .expect("answers");
    assert_eq!(span.span(), 0.0);
}
