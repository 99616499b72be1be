//! The exact work of fixed queries, pinned for every volume type and for the compact
//! layout's quantised boxes: the BVTT statistics of §2.6 (box tests disjoint D and
//! overlapping I, triangle pairs separated S and in contact K, node pairs visited) of
//! all-pairs and first-contact collision, exact and `rel_err` distance, tolerance and span
//! queries, on sliding spheres (apart, grazing, deep, concentric) and on the bundled cow
//! against a turned copy.
//!
//! The one-model queries (rays, closest points and winding numbers, which descend the
//! surface index rather than the tree) have a table of their own, in the counts each
//! result type documents.
//!
//! The answers are checked elsewhere; this test notices what they do not: a box test made
//! looser or tighter, a lost pruning case, a bound that stops early, a changed descent
//! order. Every count is deterministic, so a failure means the work changed. A deliberate
//! change updates the table (the failure prints the new one) and says before and after in
//! its commit message.
// Test code outside `#[test]` functions (helpers, property bodies): a failure is a failed test.
#![allow(clippy::expect_used)]

use crate::common;

// The ray benchmark's own ray sets (support code that indexes its 3-arrays by axis).
#[allow(clippy::indexing_slicing)]
#[path = "../../benches/support/rays.rs"]
mod rays;

use nalgebra::Vector3;
use obbtree::build::{build, BuildOptions};
use obbtree::bv::{BvKind, Layout};
use obbtree::generate::Rng;
use obbtree::mesh::TriMesh;
use obbtree::query::{
    all_ray_hits, cast_rays, closest_points, winding_numbers, BoxTest, ClosestOptions,
    CollideOptions, DescentRule, DistanceOptions, PairQuery, Pose, Ray, RayMode, RayOptions,
    SpanOptions, ToleranceOptions, WindingAccuracy, WindingOptions, Work,
};

/// `(query, [D, I, S, K, node pairs visited])`, the kind of tree ([`tree_options`]) first
/// in the name.
#[rustfmt::skip]
const PINNED: &[(&str, [u64; 5])] = &[
    ("obb all pairs x=0.3", [2750, 3385, 156, 162, 6135]),
    ("obb all pairs x=0.6", [2245, 3156, 236, 220, 5401]),
    ("obb all pairs x=1", [1671, 2366, 162, 186, 4037]),
    ("obb all pairs x=1.7", [679, 928, 67, 58, 1607]),
    ("obb all pairs x=0.6 --rule volume", [2248, 3155, 234, 220, 5403]),
    ("obb all pairs x=0.6 --rule area", [2240, 3153, 237, 220, 5393]),
    ("obb all pairs x=0.6 --rule a", [5177, 6216, 300, 220, 11393]),
    ("obb all pairs x=0.6 --rule b", [11876, 12787, 236, 220, 24663]),
    ("obb first contact x=0.6", [0, 23, 0, 1, 23]),
    ("obb first contact x=1", [14, 37, 0, 1, 51]),
    ("obb distance rel_err=0 x=2", [531, 674, 72, 0, 1205]),
    ("obb distance rel_err=0.01 x=2", [534, 639, 53, 0, 1173]),
    ("obb tolerance 0.05 x=1.83", [29, 56, 1, 0, 85]),
    ("obb all pairs x=0.6 --box-test rewrapped", [3968, 5953, 773, 220, 9921]),
    ("obb distance max_distance=0.05 x=3", [1, 0, 0, 0, 1]),
    ("obb span x=1", [3218, 3739, 261, 0, 6957]),
    ("aabb all pairs x=0.3", [6885, 13092, 2942, 162, 19977]),
    ("aabb all pairs x=0.6", [5305, 9920, 2088, 220, 15225]),
    ("aabb all pairs x=1", [2976, 5313, 983, 186, 8289]),
    ("aabb all pairs x=1.7", [994, 1779, 335, 58, 2773]),
    ("aabb all pairs x=0.6 --rule volume", [5301, 9916, 2088, 220, 15217]),
    ("aabb all pairs x=0.6 --rule area", [5295, 9910, 2088, 220, 15205]),
    ("aabb all pairs x=0.6 --rule a", [10584, 15199, 2088, 220, 25783]),
    ("aabb all pairs x=0.6 --rule b", [22289, 26904, 2088, 220, 49193]),
    ("aabb first contact x=0.6", [0, 21, 0, 1, 21]),
    ("aabb first contact x=1", [0, 22, 0, 1, 22]),
    ("aabb distance rel_err=0 x=2", [1026, 1935, 455, 0, 2961]),
    ("aabb distance rel_err=0.01 x=2", [1020, 1889, 435, 0, 2909]),
    ("aabb tolerance 0.05 x=1.83", [20, 59, 2, 0, 79]),
    ("aabb all pairs x=0.6 --box-test rewrapped", [7367, 13334, 2764, 220, 20701]),
    ("aabb distance max_distance=0.05 x=3", [1, 0, 0, 0, 1]),
    ("aabb span x=1", [12213, 29644, 8716, 0, 41857]),
    ("sphere all pairs x=0.3", [10209, 24436, 6952, 162, 34645]),
    ("sphere all pairs x=0.6", [7867, 18320, 5007, 220, 26187]),
    ("sphere all pairs x=1", [4824, 9991, 2398, 186, 14815]),
    ("sphere all pairs x=1.7", [1357, 3214, 871, 58, 4571]),
    ("sphere all pairs x=0.6 --rule volume", [7867, 18320, 5007, 220, 26187]),
    ("sphere all pairs x=0.6 --rule area", [7867, 18320, 5007, 220, 26187]),
    ("sphere all pairs x=0.6 --rule a", [11478, 21677, 4880, 220, 33155]),
    ("sphere all pairs x=0.6 --rule b", [25559, 34196, 4099, 220, 59755]),
    ("sphere first contact x=0.6", [171, 566, 188, 1, 737]),
    ("sphere first contact x=1", [3, 45, 10, 1, 48]),
    ("sphere distance rel_err=0 x=2", [1408, 3869, 1231, 0, 5277]),
    ("sphere distance rel_err=0.01 x=2", [1395, 3796, 1201, 0, 5191]),
    ("sphere tolerance 0.05 x=1.83", [245, 500, 60, 0, 745]),
    ("sphere all pairs x=0.6 --box-test rewrapped", [7867, 18320, 5007, 220, 26187]),
    ("sphere distance max_distance=0.05 x=3", [1, 0, 0, 0, 1]),
    ("sphere span x=1", [13647, 54322, 20338, 0, 67969]),
    ("compact all pairs x=0.3", [2768, 3405, 157, 162, 6173]),
    ("compact all pairs x=0.6", [2267, 3184, 239, 220, 5451]),
    ("compact all pairs x=1", [1687, 2394, 168, 186, 4081]),
    ("compact all pairs x=1.7", [683, 934, 68, 58, 1617]),
    ("compact all pairs x=0.6 --rule volume", [2269, 3180, 236, 220, 5449]),
    ("compact all pairs x=0.6 --rule area", [2257, 3176, 240, 220, 5433]),
    ("compact all pairs x=0.6 --rule a", [5225, 6266, 301, 220, 11491]),
    ("compact all pairs x=0.6 --rule b", [11978, 12897, 240, 220, 24875]),
    ("compact first contact x=0.6", [0, 23, 0, 1, 23]),
    ("compact first contact x=1", [14, 37, 0, 1, 51]),
    ("compact distance rel_err=0 x=2", [653, 800, 74, 0, 1453]),
    ("compact distance rel_err=0.01 x=2", [645, 758, 57, 0, 1403]),
    ("compact tolerance 0.05 x=1.83", [29, 56, 1, 0, 85]),
    ("compact all pairs x=0.6 --box-test rewrapped", [4007, 6020, 787, 220, 10027]),
    ("compact distance max_distance=0.05 x=3", [1, 0, 0, 0, 1]),
    ("compact span x=1", [3252, 3783, 266, 0, 7035]),
    ("obb concentric distance rel_err=0", [22860, 26697, 1919, 0, 49557]),
    ("obb concentric distance rel_err=0.01", [22624, 25731, 1554, 0, 48355]),
    ("aabb concentric distance rel_err=0", [19542, 70615, 25537, 0, 90157]),
    ("aabb concentric distance rel_err=0.01", [19484, 70229, 25373, 0, 89713]),
    ("sphere concentric distance rel_err=0", [19452, 89593, 35071, 0, 109045]),
    ("sphere concentric distance rel_err=0.01", [19432, 89229, 34899, 0, 108661]),
    ("compact concentric distance rel_err=0", [23027, 26966, 1970, 0, 49993]),
    ("compact concentric distance rel_err=0.01", [22805, 25962, 1579, 0, 48767]),
    ("obb cow all pairs", [1764, 2605, 242, 179, 4369]),
    ("obb cow first contact", [4, 27, 0, 1, 31]),
    ("obb cow distance rel_err=0", [156, 343, 94, 0, 499]),
    ("obb cow distance rel_err=0.01", [148, 155, 4, 0, 303]),
    ("aabb cow all pairs", [2402, 4589, 915, 179, 6991]),
    ("aabb cow first contact", [0, 25, 0, 1, 25]),
    ("aabb cow distance rel_err=0", [195, 410, 108, 0, 605]),
    ("aabb cow distance rel_err=0.01", [142, 175, 17, 0, 317]),
    ("sphere cow all pairs", [4751, 13572, 4232, 179, 18323]),
    ("sphere cow first contact", [1, 53, 14, 1, 54]),
    ("sphere cow distance rel_err=0", [165, 416, 126, 0, 581]),
    ("sphere cow distance rel_err=0.01", [154, 211, 29, 0, 365]),
    ("compact cow all pairs", [1770, 2617, 245, 179, 4387]),
    ("compact cow first contact", [4, 27, 0, 1, 31]),
    ("compact cow distance rel_err=0", [159, 346, 94, 0, 505]),
    ("compact cow distance rel_err=0.01", [158, 165, 4, 0, 323]),
];

/// One query of the table: its name and what it runs.
struct Case {
    name: String,
    run: Box<dyn Fn(&mut PairQuery<'_>) -> Work>,
    /// Whether the traversal runs to the end (every pair it opens is tested), so that
    /// `D − I + 2S + 2K = 1` holds on binary trees with one face per leaf.
    complete: bool,
}

/// All contacts at `x` under `rule`, named with the rule as the CLI names it unless it is
/// the default.
fn collide(x: f64, rule: DescentRule) -> Case {
    let name = if rule == DescentRule::default() {
        format!("all pairs x={x}")
    } else {
        format!("all pairs x={x} --rule {}", rule.name())
    };
    Case {
        name,
        run: Box::new(move |pair| {
            let pose = common::sliding_pose(x, 5);
            let options = CollideOptions {
                rule,
                ..CollideOptions::default()
            };
            pair.collide(&Pose::identity(), &pose, &options)
                .expect("collide")
                .work
        }),
        complete: true,
    }
}

fn first_contact(name: String, pose: Pose) -> Case {
    Case {
        name,
        run: Box::new(move |pair| {
            let options = CollideOptions {
                first_contact: true,
                ..CollideOptions::default()
            };
            pair.collide(&Pose::identity(), &pose, &options)
                .expect("first contact")
                .work
        }),
        complete: false,
    }
}

fn distance(name: String, pose: Pose, options: DistanceOptions, complete: bool) -> Case {
    Case {
        name,
        run: Box::new(move |pair| {
            pair.distance(&Pose::identity(), &pose, &options)
                .expect("distance")
                .work
        }),
        complete,
    }
}

/// Exact distance (`rel_err` 0) or within `rel_err`, the other options at their defaults.
fn relative(rel_err: f64) -> DistanceOptions {
    DistanceOptions {
        rel_err,
        ..DistanceOptions::default()
    }
}

/// The sliding spheres of §5.3.1 at a size a test runs in a moment: radii 1 and 0.8,
/// 1,600 triangles each, B turned by a fixed rotation and moved by `x` along x.
fn sphere_cases() -> Vec<Case> {
    let mut cases: Vec<Case> = [0.3, 0.6, 1.0, 1.7]
        .into_iter()
        .map(|x| collide(x, DescentRule::default()))
        .collect();
    // The other descent rules (§7.3.2).
    cases.extend(DescentRule::ALL[1..].iter().map(|&rule| collide(0.6, rule)));
    for x in [0.6, 1.0] {
        cases.push(first_contact(
            format!("first contact x={x}"),
            common::sliding_pose(x, 5),
        ));
    }
    for rel_err in [0.0, 0.01] {
        cases.push(distance(
            format!("distance rel_err={rel_err} x=2"),
            common::sliding_pose(2.0, 5),
            relative(rel_err),
            true,
        ));
    }
    cases.push(Case {
        name: "tolerance 0.05 x=1.83".into(),
        run: Box::new(|pair| {
            let pose = common::sliding_pose(1.83, 5);
            let options = ToleranceOptions {
                tolerance: 0.05,
                rule: DescentRule::default(),
            };
            pair.within(&Pose::identity(), &pose, &options)
                .expect("tolerance")
                .work
        }),
        complete: false,
    });
    cases.push(Case {
        name: "all pairs x=0.6 --box-test rewrapped".into(),
        run: Box::new(|pair| {
            let options = CollideOptions {
                box_test: BoxTest::Rewrapped,
                ..CollideOptions::default()
            };
            pair.collide(&Pose::identity(), &common::sliding_pose(0.6, 5), &options)
                .expect("collide")
                .work
        }),
        complete: true,
    });
    // Apart by more than the limit: the root pair's bound alone answers.
    let limited = DistanceOptions {
        max_distance: 0.05,
        ..DistanceOptions::default()
    };
    cases.push(distance(
        "distance max_distance=0.05 x=3".into(),
        common::sliding_pose(3.0, 5),
        limited,
        false,
    ));
    cases.push(Case {
        name: "span x=1".into(),
        run: Box::new(|pair| {
            let pose = common::sliding_pose(1.0, 5);
            let options = SpanOptions {
                rule: DescentRule::default(),
            };
            pair.span(&Pose::identity(), &pose, &options)
                .expect("span")
                .work
        }),
        complete: false,
    });
    cases
}

/// A sphere of radius 1 around one of radius 0.95, B turned: parallel close proximity
/// (§5.3.2), the hardest case for distance.
fn concentric_cases() -> Vec<Case> {
    let turned = Pose::new(common::rng::seeded_rotation(7), Vector3::zeros()).expect("rotation");
    [0.0, 0.01]
        .into_iter()
        .map(|rel_err| {
            distance(
                format!("concentric distance rel_err={rel_err}"),
                turned,
                relative(rel_err),
                true,
            )
        })
        .collect()
}

fn cow_cases() -> Vec<Case> {
    vec![
        Case {
            name: "cow all pairs".into(),
            run: Box::new(|pair| {
                let options = CollideOptions::default();
                pair.collide(&Pose::identity(), &common::turned_pose(3, 0.3), &options)
                    .expect("collide")
                    .work
            }),
            complete: true,
        },
        first_contact("cow first contact".into(), common::turned_pose(3, 0.3)),
        distance(
            "cow distance rel_err=0".into(),
            common::turned_pose(4, 1.5),
            relative(0.0),
            true,
        ),
        distance(
            "cow distance rel_err=0.01".into(),
            common::turned_pose(4, 1.5),
            relative(0.01),
            true,
        ),
    ]
}

/// The trees of the table, by the name its rows start with: each volume type at the default
/// options, and the quantised boxes of the compact layout (one face per leaf, so that the
/// identity of complete traversals holds for it too).
fn tree_options() -> Vec<(&'static str, BuildOptions)> {
    let mut out: Vec<_> = BvKind::ALL
        .into_iter()
        .map(|bv| {
            let options = BuildOptions {
                bv,
                ..BuildOptions::default()
            };
            (bv.name(), options)
        })
        .collect();
    let compact = BuildOptions {
        layout: Layout::Compact,
        ..BuildOptions::default()
    };
    out.push(("compact", compact));
    out
}

/// Runs `cases` between trees of `a` and `b` of every kind of [`tree_options`].
fn run(a: &TriMesh, b: &TriMesh, cases: &[Case], out: &mut Vec<(String, [u64; 5])>) {
    for (kind, options) in tree_options() {
        let ta = build(a, &options, None).expect("builds");
        let tb = build(b, &options, None).expect("builds");
        let mut pair = PairQuery::new(&ta, &tb).expect("one kind of tree");
        for case in cases {
            let s = (case.run)(&mut pair);
            if case.complete {
                assert_eq!(s.identity_value(), 1, "{kind} {}: {s:?}", case.name);
            }
            out.push((format!("{kind} {}", case.name), counts(&s)));
        }
    }
}

#[test]
fn the_work_of_fixed_queries_is_pinned_for_every_kind_of_tree() {
    let mut actual = Vec::new();
    let (big, small) = (
        common::uv_sphere(1.0, 21, 40),
        common::uv_sphere(0.8, 21, 40),
    );
    run(&big, &small, &sphere_cases(), &mut actual);
    run(
        &big,
        &common::uv_sphere(0.95, 21, 40),
        &concentric_cases(),
        &mut actual,
    );
    let cow = common::cow();
    run(&cow, &cow, &cow_cases(), &mut actual);
    assert_pinned(&actual, PINNED);
}

/// Fails unless `actual` is `pinned`, naming the rows that changed and printing the new
/// table.
fn assert_pinned(actual: &[(String, [u64; 5])], pinned: &[(&str, [u64; 5])]) {
    let pinned: Vec<(String, [u64; 5])> = pinned
        .iter()
        .map(|(name, counts)| (name.to_string(), *counts))
        .collect();
    assert!(actual == pinned, "{}", changes(actual, &pinned));
}

/// Which rows of `actual` differ from `pinned`, and the new table.
fn changes(actual: &[(String, [u64; 5])], pinned: &[(String, [u64; 5])]) -> String {
    let table: String = actual
        .iter()
        .map(|(name, c)| format!("    (\"{name}\", {c:?}),\n"))
        .collect();
    let changed: Vec<&str> = actual
        .iter()
        .filter(|row| !pinned.contains(row))
        .map(|(name, _)| name.as_str())
        .collect();
    format!("the work changed in {changed:?}; if that is intended, the new table is:\n{table}")
}

/// `(query, [D, I, S, K, nodes visited])`, summed over the rays or points of each query.
#[rustfmt::skip]
const ONE_MODEL_PINNED: &[(&str, [u64; 5])] = &[
    ("rays closest", [11094, 4536, 1069, 312, 15630]),
    ("rays any", [9503, 4179, 727, 307, 14616]),
    ("rays closest t_max=0.5", [3285, 837, 6, 3, 4122]),
    ("rays all hits", [17725, 8416, 2742, 674, 26141]),
    ("closest points", [23209, 15077, 10334, 0, 38286]),
    ("closest points max_distance=0.05", [15985, 9368, 5961, 0, 25353]),
    ("closest points at corners", [20199, 8209, 1720, 1658, 28408]),
    ("winding exact", [0, 1235652, 4724456, 0, 3749284]),
    ("winding beta=2", [60909, 23162, 11885, 0, 89921]),
    ("winding tolerance=0.001", [427439, 425924, 1013515, 0, 1374822]),
];

/// The ray benchmark's two sets at the bundled cow (400 camera rays and 400 random ones),
/// posed.
fn cow_rays(cow: &TriMesh, pose: &Pose) -> Vec<Ray> {
    let mut model = rays::camera_rays(cow, 400);
    model.extend(rays::random_rays(cow, 400, 11));
    model
        .into_iter()
        .map(|ray| Ray {
            origin: pose.apply(&Vector3::from(ray.origin)).into(),
            direction: (pose.rotation() * Vector3::from(ray.direction)).into(),
        })
        .collect()
}

/// A query's work as the table's five counts.
fn counts(w: &Work) -> [u64; 5] {
    [
        w.bv_disjoint,
        w.bv_overlap,
        w.tri_separated,
        w.tri_contact,
        w.nodes_visited,
    ]
}

/// The five counts summed over a query's answers.
fn total<'a>(works: impl Iterator<Item = &'a Work>) -> [u64; 5] {
    works.fold([0; 5], |mut sum, w| {
        for (s, c) in sum.iter_mut().zip(counts(w)) {
            *s += c;
        }
        sum
    })
}

#[test]
fn the_work_of_one_model_queries_is_pinned() {
    let mesh = common::cow();
    let cow = build(&mesh, &BuildOptions::default(), None).expect("builds");
    let pose = common::turned_pose(5, 0.7);
    let rays = cow_rays(&mesh, &pose);
    let mut actual = Vec::new();
    let hits = cast_rays(&cow, &pose, &rays, &RayOptions::default()).expect("rays");
    actual.push((
        "rays closest".to_string(),
        total(hits.iter().map(|a| &a.work)),
    ));
    for (name, mode, t_max) in [
        ("rays any", RayMode::Any, f64::INFINITY),
        ("rays closest t_max=0.5", RayMode::Closest, 0.5),
    ] {
        let options = RayOptions { mode, t_max };
        let answers = cast_rays(&cow, &pose, &rays, &options).expect("rays");
        actual.push((name.to_string(), total(answers.iter().map(|a| &a.work))));
    }
    let all = all_ray_hits(&cow, &pose, &rays, f64::INFINITY).expect("all hits");
    actual.push((
        "rays all hits".to_string(),
        total(all.iter().map(|a| &a.work)),
    ));
    // Points near the surface (the rays' first hits, moved off it to either side), and far.
    let mut points: Vec<[f64; 3]> = [0.98, 1.02]
        .iter()
        .flat_map(|along| {
            hits.iter().zip(&rays).filter_map(move |(a, ray)| {
                let t = a.hit?.t * along;
                Some(std::array::from_fn(|k| {
                    ray.origin[k] + ray.direction[k] * t
                }))
            })
        })
        .collect();
    let mut rng = Rng::new(12);
    points.extend((0..200).map(|_| [rng.signed() * 3.0, rng.signed() * 3.0, rng.signed() * 3.0]));
    for (name, max_distance) in [
        ("closest points", f64::INFINITY),
        ("closest points max_distance=0.05", 0.05),
    ] {
        let options = ClosestOptions { max_distance };
        let answers = closest_points(&cow, &pose, &points, &options).expect("closest");
        actual.push((name.to_string(), total(answers.iter().map(|a| &a.work))));
    }
    // Points on the surface: a corner of every fifth triangle as stored, unposed, so that
    // their distances are 0.
    let corners: Vec<[f64; 3]> = common::file_triangles(&cow)
        .iter()
        .step_by(5)
        .map(|(_, [a, _, _])| *a)
        .collect();
    let answers = closest_points(
        &cow,
        &Pose::identity(),
        &corners,
        &ClosestOptions::default(),
    )
    .expect("closest");
    actual.push((
        "closest points at corners".to_string(),
        total(answers.iter().map(|a| &a.work)),
    ));
    for (name, accuracy) in [
        ("winding exact", WindingAccuracy::Exact),
        ("winding beta=2", WindingAccuracy::default()),
        (
            "winding tolerance=0.001",
            WindingAccuracy::Bounded { tolerance: 1e-3 },
        ),
    ] {
        let options = WindingOptions { accuracy };
        let answers = winding_numbers(&cow, &pose, &points, &options).expect("winding");
        actual.push((name.to_string(), total(answers.iter().map(|a| &a.work))));
    }
    assert_pinned(&actual, ONE_MODEL_PINNED);
}
