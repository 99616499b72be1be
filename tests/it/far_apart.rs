//! Models far apart cost what models near each other cost.
//!
//! Two copies of the bundled cow (about 1 unit across), B translated by 1e3 … 1e9. The box
//! tests once carried a slack proportional to the centre offset (a millionth of it), which
//! at 1e6 is as large as the cow: every lower bound collapsed and an exact distance measured
//! 25 million of the 33.7 million triangle pairs (5 s) where 1e3 measured 491. The work is
//! deterministic, so the test asserts triangle-test counts, not times.
// Test code outside `#[test]` functions (helpers, property bodies): a failure is a failed test.
#![allow(clippy::unwrap_used)]

use crate::common;

use common::oracle;
use nalgebra::Vector3;
use obbtree::build::{build, BuildOptions};
use obbtree::bv::BvKind;
use obbtree::query::triangle::Triangle;
use obbtree::query::{
    CollideOptions, DescentRule, DistanceOptions, DistanceResult, PairQuery, Pose, ToleranceOptions,
};
use obbtree::real::Precision;

const OFFSETS: [f64; 5] = [1e3, 1e5, 1e6, 1e7, 1e9];

fn triangle_tests(s: &obbtree::query::Work) -> u64 {
    s.tri_separated + s.tri_contact
}

/// B turned a little (so no box axis lines up with the offset) and moved `offset` along
/// `direction`.
fn pose_b(offset: f64, direction: Vector3<f64>) -> Pose {
    Pose::new(
        common::rng::seeded_rotation(3),
        direction.normalize() * offset,
    )
    .unwrap()
}

struct Work {
    exact: u64,
    approximate: u64,
    tolerance_no: u64,
    tolerance_yes: u64,
}

/// The work of the distance and tolerance queries of a model against itself (`pair`).
fn work(pair: &mut PairQuery<'_>, pose: &Pose, distance: f64) -> Work {
    let a = Pose::identity();
    let exact = pair
        .distance(&a, pose, &DistanceOptions::default())
        .unwrap()
        .work;
    let rel = DistanceOptions {
        rel_err: 0.01,
        ..DistanceOptions::default()
    };
    let approximate = pair.distance(&a, pose, &rel).unwrap().work;
    let rule = DescentRule::default();
    let tolerance = |t| ToleranceOptions { tolerance: t, rule };
    // Just short of the distance: the answer is "no", every candidate must be ruled out.
    let no = pair
        .within(&a, pose, &tolerance(distance * 0.999_999))
        .unwrap();
    assert!(!no.closer());
    // Just past it: "yes", found by descending towards the closest pair.
    let yes = pair
        .within(&a, pose, &tolerance(distance * 1.000_001))
        .unwrap();
    assert!(yes.closer());
    Work {
        exact: triangle_tests(&exact),
        approximate: triangle_tests(&approximate),
        tolerance_no: triangle_tests(&no.work),
        tolerance_yes: triangle_tests(&yes.work),
    }
}

#[test]
fn distance_work_does_not_grow_with_the_offset() {
    let cow = common::cow();
    for bv in [BvKind::Obb, BvKind::Aabb] {
        for precision in Precision::ALL {
            let options = BuildOptions {
                bv,
                precision,
                ..BuildOptions::default()
            };
            let file = build(&cow, &options, None).unwrap();
            let mut pair = PairQuery::new(&file, &file).unwrap();
            for direction in [Vector3::x(), Vector3::new(1.0, -1.0, 1.0)] {
                let mut baseline: Option<Work> = None;
                for offset in OFFSETS {
                    let pose = pose_b(offset, direction);
                    let a = Pose::identity();
                    let exact = DistanceOptions::default();
                    let d = pair.distance(&a, &pose, &exact).unwrap().distance();
                    // The cow is about 1 unit across: the gap is the offset less about that.
                    assert!(d > offset - 2.0 && d < offset, "{offset}: distance {d}");
                    let w = work(&mut pair, &pose, d);
                    let label = format!("{bv:?} {precision:?} along {direction:?} at {offset:e}");
                    let base = baseline.get_or_insert(Work { ..w });
                    for (what, now, then) in [
                        ("exact", w.exact, base.exact),
                        ("rel_err 0.01", w.approximate, base.approximate),
                        ("tolerance (no)", w.tolerance_no, base.tolerance_no),
                        ("tolerance (yes)", w.tolerance_yes, base.tolerance_yes),
                    ] {
                        assert!(
                            now <= 2 * then.max(1),
                            "{label}: {what} made {now} triangle tests, {then} at 1e3"
                        );
                    }
                    // Far apart, collision is decided at the roots.
                    let hit = pair.collide(&a, &pose, &CollideOptions::default()).unwrap();
                    assert!(!hit.colliding);
                    assert_eq!(hit.work.nodes_visited, 1, "{label}");
                }
            }
        }
    }
}

/// The exact distance between the model at the identity and a copy moved `offset` along
/// x (`pair` is the model against itself), and that copy's pose.
fn along_x(pair: &mut PairQuery<'_>, offset: f64) -> (Pose, DistanceResult) {
    let pose = Pose::translation(offset, 0.0, 0.0);
    let exact = DistanceOptions::default();
    let r = pair.distance(&Pose::identity(), &pose, &exact).unwrap();
    (pose, r)
}

/// Far apart, the exact distance is still exact. Along x, only triangles of A reaching
/// within 0.05 of its largest x and of B within 0.05 of its smallest can hold the closest
/// pair (every other pair is farther apart in x alone than the answer), so a brute force
/// over those two slabs is the reference.
#[test]
fn far_distances_stay_exact() {
    let cow = common::cow();
    for precision in Precision::ALL {
        let options = BuildOptions {
            precision,
            ..BuildOptions::default()
        };
        let file = build(&cow, &options, None).unwrap();
        let mut pair = PairQuery::new(&file, &file).unwrap();
        let triangles: Vec<Triangle> = common::file_triangles(&file)
            .iter()
            .map(|(_, t)| t.map(Vector3::from))
            .collect();
        let max_x = triangles
            .iter()
            .flatten()
            .map(|p| p.x)
            .fold(f64::MIN, f64::max);
        let min_x = triangles
            .iter()
            .flatten()
            .map(|p| p.x)
            .fold(f64::MAX, f64::min);
        let right: Vec<Triangle> = triangles
            .iter()
            .filter(|t| t.iter().any(|p| p.x > max_x - 0.05))
            .copied()
            .collect();
        let left: Vec<Triangle> = triangles
            .iter()
            .filter(|t| t.iter().any(|p| p.x < min_x + 0.05))
            .copied()
            .collect();
        for offset in OFFSETS {
            let (pose, r) = along_x(&mut pair, offset);
            let left_of_b = oracle::in_frame_of_a(&Pose::identity(), &pose, &left);
            let brute = oracle::min_distance(&right, &left_of_b);
            assert!(
                brute < offset - (max_x - min_x) + 1e-3,
                "the slabs hold the answer"
            );
            assert!(
                (r.distance() - brute).abs() <= 8.0 * f64::EPSILON * offset,
                "{precision:?} at {offset:e}: {} vs brute force {brute}",
                r.distance()
            );
        }
    }
}

/// Past about 1e13 model sizes away, f64 cannot tell the models' triangles apart: every
/// pair is at the same rounded distance, and bounds within rounding of it once opened
/// every pair (33.7 million, 20 s at 1e300). Candidates within the bounds' resolution of
/// the best (a relative 6e-14) are no longer opened.
#[test]
fn models_beyond_f64_resolution_do_not_open_every_pair() {
    let cow = common::cow();
    let file = build(&cow, &BuildOptions::default(), None).unwrap();
    let mut pair = PairQuery::new(&file, &file).unwrap();
    for offset in [1e13, 1e16, 1e100, 1e300] {
        let (_, r) = along_x(&mut pair, offset);
        assert!(triangle_tests(&r.work) <= 1000, "{offset:e}: {:?}", r.work);
        // The cow is about 1 unit wide: the distance is the offset less that.
        assert!(
            (r.distance() - (offset - 1.0)).abs() <= 1.0 + 1e-13 * offset,
            "{offset:e}: {}",
            r.distance()
        );
    }
}
