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

mod common;

use nalgebra::Vector3;
use obbtree::build::{build, BuildOptions};
use obbtree::bv::BvKind;
use obbtree::format::ObbtFile;
use obbtree::mesh::TriMesh;
use obbtree::query::{CollideOptions, DescentRule, DistanceOptions, PairQuery, Pose, Stats};

/// `(query, [D, I, S, K, node pairs visited])`, volume type first in the name.
#[rustfmt::skip]
const PINNED: &[(&str, [u64; 5])] = &[
    ("obb all pairs x=0.3", [2737, 3376, 158, 162, 6113]),
    ("obb all pairs x=0.6", [2199, 3094, 228, 220, 5293]),
    ("obb all pairs x=1", [1656, 2427, 200, 186, 4083]),
    ("obb all pairs x=1.7", [671, 888, 51, 58, 1559]),
    ("obb first contact x=0.6", [0, 23, 0, 1, 23]),
    ("obb first contact x=1", [21, 54, 7, 1, 75]),
    ("obb distance rel_err=0 x=2", [713, 862, 75, 0, 1575]),
    ("obb distance rel_err=0.01 x=2", [701, 830, 65, 0, 1531]),
    ("obb tolerance 0.05 x=1.83", [15, 29, 1, 0, 44]),
    ("obb span x=1", [3344, 3835, 246, 0, 7179]),
    ("aabb all pairs x=0.3", [6802, 13009, 2942, 162, 19811]),
    ("aabb all pairs x=0.6", [5126, 9741, 2088, 220, 14867]),
    ("aabb all pairs x=1", [3001, 5338, 983, 186, 8339]),
    ("aabb all pairs x=1.7", [1065, 1850, 335, 58, 2915]),
    ("aabb first contact x=0.6", [19, 90, 25, 1, 109]),
    ("aabb first contact x=1", [0, 24, 1, 1, 24]),
    ("aabb distance rel_err=0 x=2", [980, 1889, 455, 0, 2869]),
    ("aabb distance rel_err=0.01 x=2", [993, 1866, 437, 0, 2859]),
    ("aabb tolerance 0.05 x=1.83", [62, 91, 3, 0, 153]),
    ("aabb span x=1", [12373, 29808, 8718, 0, 42181]),
    ("sphere all pairs x=0.3", [11871, 26862, 7334, 162, 38733]),
    ("sphere all pairs x=0.6", [9398, 20583, 5373, 220, 29981]),
    ("sphere all pairs x=1", [5811, 11458, 2638, 186, 17269]),
    ("sphere all pairs x=1.7", [1542, 3463, 903, 58, 5005]),
    ("sphere first contact x=0.6", [143, 337, 87, 1, 480]),
    ("sphere first contact x=1", [0, 33, 6, 1, 33]),
    ("sphere distance rel_err=0 x=2", [1611, 4128, 1259, 0, 5739]),
    ("sphere distance rel_err=0.01 x=2", [1602, 4063, 1231, 0, 5665]),
    ("sphere tolerance 0.05 x=1.83", [218, 418, 55, 0, 636]),
    ("sphere span x=1", [16661, 59132, 21236, 0, 75793]),
    ("obb concentric distance rel_err=0", [22776, 26967, 2096, 0, 49743]),
    ("obb concentric distance rel_err=0.01", [22572, 26175, 1802, 0, 48747]),
    ("aabb concentric distance rel_err=0", [19848, 70951, 25552, 0, 90799]),
    ("aabb concentric distance rel_err=0.01", [19796, 70583, 25394, 0, 90379]),
    ("sphere concentric distance rel_err=0", [24347, 96548, 36101, 0, 120895]),
    ("sphere concentric distance rel_err=0.01", [24313, 96266, 35977, 0, 120579]),
    ("obb cow all pairs", [1983, 2826, 243, 179, 4809]),
    ("obb cow first contact", [0, 25, 0, 1, 25]),
    ("obb cow distance rel_err=0", [141, 324, 92, 0, 465]),
    ("obb cow distance rel_err=0.01", [136, 145, 5, 0, 281]),
    ("aabb cow all pairs", [2527, 4714, 915, 179, 7241]),
    ("aabb cow first contact", [22, 46, 0, 1, 68]),
    ("aabb cow distance rel_err=0", [219, 436, 109, 0, 655]),
    ("aabb cow distance rel_err=0.01", [181, 220, 20, 0, 401]),
    ("sphere cow all pairs", [5280, 14191, 4277, 179, 19471]),
    ("sphere cow first contact", [0, 114, 45, 1, 114]),
    ("sphere cow distance rel_err=0", [119, 360, 121, 0, 479]),
    ("sphere cow distance rel_err=0.01", [106, 161, 28, 0, 267]),
];

/// One query of the table: its name and what it runs.
struct Case {
    name: String,
    run: Box<dyn Fn(&mut PairQuery<'_>) -> Stats>,
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
                .stats
        }),
        complete: true,
    }
}

fn first_contact(name: String, pose: Pose) -> Case {
    Case {
        name,
        run: Box::new(move |pair| {
            pair.first_contact_stats(&Pose::identity(), &pose)
                .expect("first contact")
                .1
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
                .stats
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
            pair.within_tolerance(&Pose::identity(), &pose, 0.05, DescentRule::default())
                .expect("tolerance")
                .stats
        }),
        complete: false,
    });
    cases.push(Case {
        name: "span x=1".into(),
        run: Box::new(|pair| {
            let pose = common::sliding_pose(1.0, 5);
            pair.span(&Pose::identity(), &pose, DescentRule::default())
                .expect("span")
                .stats
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

/// The cow against a copy turned at random and moved by `scale` along a random direction.
fn cow_pose(seed: u64, scale: f64) -> Pose {
    let rotation = common::rng::seeded_rotation(seed);
    let direction = common::rng::seeded_rotation(seed + 100) * Vector3::x();
    Pose::new(rotation, direction * scale).expect("rotation")
}

fn cow_cases() -> Vec<Case> {
    vec![
        Case {
            name: "cow all pairs".into(),
            run: Box::new(|pair| {
                let options = CollideOptions::default();
                pair.collide(&Pose::identity(), &cow_pose(3, 0.3), &options)
                    .expect("collide")
                    .stats
            }),
            complete: true,
        },
        first_contact("cow first contact".into(), cow_pose(3, 0.3)),
        distance("cow distance rel_err=0".into(), cow_pose(4, 1.5), 0.0, true),
        distance(
            "cow distance rel_err=0.01".into(),
            cow_pose(4, 1.5),
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
