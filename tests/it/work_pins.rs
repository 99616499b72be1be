//! The exact work of fixed queries, pinned for every volume type: the BVTT statistics of
//! §2.6 (box tests disjoint D and overlapping I, triangle pairs separated S and in contact
//! K, node pairs visited) of all-pairs and first-contact collision, exact and `rel_err`
//! distance, tolerance and span queries, on sliding spheres (apart, grazing, deep,
//! concentric) and on the bundled cow against a turned copy.
//!
//! The answers are checked elsewhere; this test notices what they do not: a box test made
//! looser or tighter, a lost pruning case, a bound that stops early, a changed descent
//! order. Every count is deterministic, so a failure means the work changed. A deliberate
//! change updates the table (the failure prints the new one) and says before and after in
//! its commit message.
// Test code outside `#[test]` functions (helpers, property bodies): a failure is a failed test.
#![allow(clippy::expect_used)]

use crate::common;

use nalgebra::Vector3;
use obbtree::build::{build, BuildOptions};
use obbtree::bv::BvKind;
use obbtree::format::ObbtFile;
use obbtree::mesh::TriMesh;
use obbtree::query::{
    CollideOptions, DescentRule, DistanceOptions, PairQuery, Pose, SpanOptions, ToleranceOptions,
    Work,
};

/// `(query, [D, I, S, K, node pairs visited])`, volume type first in the name.
#[rustfmt::skip]
const PINNED: &[(&str, [u64; 5])] = &[
    ("obb all pairs x=0.3", [2767, 3404, 157, 162, 6171]),
    ("obb all pairs x=0.6", [2252, 3185, 247, 220, 5437]),
    ("obb all pairs x=1", [1760, 2459, 164, 186, 4219]),
    ("obb all pairs x=1.7", [682, 921, 62, 58, 1603]),
    ("obb first contact x=0.6", [0, 23, 0, 1, 23]),
    ("obb first contact x=1", [13, 36, 0, 1, 49]),
    ("obb distance rel_err=0 x=2", [537, 674, 69, 0, 1211]),
    ("obb distance rel_err=0.01 x=2", [530, 631, 51, 0, 1161]),
    ("obb tolerance 0.05 x=1.83", [29, 57, 1, 0, 86]),
    ("obb span x=1", [3168, 3689, 261, 0, 6857]),
    ("aabb all pairs x=0.3", [6817, 13024, 2942, 162, 19841]),
    ("aabb all pairs x=0.6", [5265, 9880, 2088, 220, 15145]),
    ("aabb all pairs x=1", [2973, 5310, 983, 186, 8283]),
    ("aabb all pairs x=1.7", [992, 1777, 335, 58, 2769]),
    ("aabb first contact x=0.6", [0, 21, 0, 1, 21]),
    ("aabb first contact x=1", [0, 22, 0, 1, 22]),
    ("aabb distance rel_err=0 x=2", [1004, 1913, 455, 0, 2917]),
    ("aabb distance rel_err=0.01 x=2", [998, 1867, 435, 0, 2865]),
    ("aabb tolerance 0.05 x=1.83", [20, 59, 2, 0, 79]),
    ("aabb span x=1", [12178, 29609, 8716, 0, 41787]),
    ("sphere all pairs x=0.3", [11952, 26677, 7201, 162, 38629]),
    ("sphere all pairs x=0.6", [9258, 19971, 5137, 220, 29229]),
    ("sphere all pairs x=1", [5457, 10766, 2469, 186, 16223]),
    ("sphere all pairs x=1.7", [1700, 3721, 953, 58, 5421]),
    ("sphere first contact x=0.6", [60, 133, 26, 1, 193]),
    ("sphere first contact x=1", [0, 21, 0, 1, 21]),
    ("sphere distance rel_err=0 x=2", [1819, 4460, 1321, 0, 6279]),
    ("sphere distance rel_err=0.01 x=2", [1792, 4377, 1293, 0, 6169]),
    ("sphere tolerance 0.05 x=1.83", [6, 43, 2, 0, 49]),
    ("sphere span x=1", [16020, 57781, 20881, 0, 73801]),
    ("obb concentric distance rel_err=0", [23299, 27018, 1860, 0, 50317]),
    ("obb concentric distance rel_err=0.01", [23030, 26071, 1521, 0, 49101]),
    ("aabb concentric distance rel_err=0", [19596, 70669, 25537, 0, 90265]),
    ("aabb concentric distance rel_err=0.01", [19553, 70296, 25372, 0, 89849]),
    ("sphere concentric distance rel_err=0", [22389, 94016, 35814, 0, 116405]),
    ("sphere concentric distance rel_err=0.01", [22343, 93688, 35673, 0, 116031]),
    ("obb cow all pairs", [1983, 2826, 243, 179, 4809]),
    ("obb cow first contact", [0, 25, 0, 1, 25]),
    ("obb cow distance rel_err=0", [161, 348, 94, 0, 509]),
    ("obb cow distance rel_err=0.01", [136, 143, 4, 0, 279]),
    ("aabb cow all pairs", [2696, 4883, 915, 179, 7579]),
    ("aabb cow first contact", [5, 41, 6, 1, 46]),
    ("aabb cow distance rel_err=0", [253, 468, 108, 0, 721]),
    ("aabb cow distance rel_err=0.01", [172, 205, 17, 0, 377]),
    ("sphere cow all pairs", [5832, 14841, 4326, 179, 20673]),
    ("sphere cow first contact", [44, 108, 21, 1, 152]),
    ("sphere cow distance rel_err=0", [200, 433, 117, 0, 633]),
    ("sphere cow distance rel_err=0.01", [187, 292, 53, 0, 479]),
];

/// One query of the table: its name and what it runs.
struct Case {
    name: String,
    run: Box<dyn Fn(&mut PairQuery<'_>) -> Work>,
    /// Whether the traversal runs to the end (every pair it opens is tested), so that
    /// `D − I + 2S + 2K = 1` holds on binary trees with one face per leaf.
    complete: bool,
}

fn collide(x: f64) -> Case {
    Case {
        name: format!("all pairs x={x}"),
        run: Box::new(move |pair| {
            let pose = common::sliding_pose(x, 5);
            let options = CollideOptions::default();
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

fn distance(name: String, pose: Pose, rel_err: f64, complete: bool) -> Case {
    Case {
        name,
        run: Box::new(move |pair| {
            let options = DistanceOptions {
                rel_err,
                ..DistanceOptions::default()
            };
            pair.distance(&Pose::identity(), &pose, &options)
                .expect("distance")
                .work
        }),
        complete,
    }
}

/// The sliding spheres of §5.3.1 at a size a test runs in a moment: radii 1 and 0.8,
/// 1,600 triangles each, B turned by a fixed rotation and moved by `x` along x.
fn sphere_cases() -> Vec<Case> {
    let mut cases: Vec<Case> = [0.3, 0.6, 1.0, 1.7].into_iter().map(collide).collect();
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
            rel_err,
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
                rel_err,
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
            0.0,
            true,
        ),
        distance(
            "cow distance rel_err=0.01".into(),
            common::turned_pose(4, 1.5),
            0.01,
            true,
        ),
    ]
}

fn tree(mesh: &TriMesh, bv: BvKind) -> ObbtFile {
    let options = BuildOptions {
        bv,
        ..BuildOptions::default()
    };
    build(mesh, &options, None).expect("builds")
}

/// Runs `cases` between trees of `a` and `b` of every volume type.
fn run(a: &TriMesh, b: &TriMesh, cases: &[Case], out: &mut Vec<(String, [u64; 5])>) {
    for bv in BvKind::ALL {
        let (ta, tb) = (tree(a, bv), tree(b, bv));
        let mut pair = PairQuery::new(&ta, &tb).expect("one volume type");
        for case in cases {
            let s = (case.run)(&mut pair);
            if case.complete {
                assert_eq!(s.identity_value(), 1, "{} {}: {s:?}", bv.name(), case.name);
            }
            out.push((
                format!("{} {}", bv.name(), case.name),
                [
                    s.bv_disjoint,
                    s.bv_overlap,
                    s.tri_separated,
                    s.tri_contact,
                    s.nodes_visited,
                ],
            ));
        }
    }
}

#[test]
fn the_work_of_fixed_queries_is_pinned_for_every_volume_type() {
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
    let pinned: Vec<(String, [u64; 5])> = PINNED
        .iter()
        .map(|(name, counts)| (name.to_string(), *counts))
        .collect();
    if actual != pinned {
        let table: String = actual
            .iter()
            .map(|(name, c)| format!("    (\"{name}\", {c:?}),\n"))
            .collect();
        let changed: Vec<&str> = actual
            .iter()
            .filter(|row| !pinned.contains(row))
            .map(|(name, _)| name.as_str())
            .collect();
        panic!("the work changed in {changed:?}; if that is intended, the new table is:\n{table}");
    }
}
