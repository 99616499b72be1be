//! Closest points of one posed model (`query::closest_points`), against brute force over
//! every triangle with an independent point–triangle distance, for every tree type.
// Test code outside `#[test]` functions (helpers, property bodies): a failure is a failed test.
#![allow(clippy::expect_used, clippy::indexing_slicing)]

use crate::common;

use nalgebra::Vector3;
use obbtree::build::build;
use obbtree::format::ObbtFile;
use obbtree::generate::Rng;
use obbtree::query::triangle::Feature;
use obbtree::query::{closest_points, ClosestOptions, Pose, QueryError};

/// Distance from `p` to triangle `t`, computed another way than the library's: the
/// projection on the plane when it falls inside (edge signs), else the nearest of the
/// three segments.
pub(crate) fn point_triangle_distance(p: &Vector3<f64>, t: &[[f64; 3]; 3]) -> f64 {
    let [a, b, c] = t.map(Vector3::from);
    let segment = |s: Vector3<f64>, e: Vector3<f64>| {
        let d = e - s;
        let l2 = d.norm_squared();
        let u = if l2 > 0.0 {
            ((p - s).dot(&d) / l2).clamp(0.0, 1.0)
        } else {
            0.0
        };
        (p - (s + d * u)).norm()
    };
    let edges = segment(a, b).min(segment(b, c)).min(segment(c, a));
    let n = (b - a).cross(&(c - a));
    let n2 = n.norm_squared();
    if n2 == 0.0 {
        return edges;
    }
    let q = p - n * (n.dot(&(p - a)) / n2);
    let inside = [(a, b), (b, c), (c, a)]
        .iter()
        .all(|(s, e)| (e - s).cross(&(q - s)).dot(&n) >= 0.0);
    if inside {
        (p - q).norm().min(edges)
    } else {
        edges
    }
}

/// Query points for `file`'s stored triangles posed by `pose`: near the surface (jittered
/// corners and centroids), exactly on corners and edge midpoints, and far away.
fn query_points(triangles: &[(u32, [[f64; 3]; 3])], pose: &Pose, rng: &mut Rng) -> Vec<[f64; 3]> {
    let mut out = Vec::new();
    for k in 0..60 {
        let (_, t) = triangles[rng.below(triangles.len())];
        let [a, b, c] = t.map(Vector3::from);
        let mut jitter = |r: f64| Vector3::new(rng.signed(), rng.signed(), rng.signed()) * r;
        let local = match k % 5 {
            0 => a,
            1 => (a + b) / 2.0,
            2 => (a + b + c) / 3.0 + jitter(0.05),
            3 => a + jitter(0.2),
            _ => jitter(3.0),
        };
        out.push(pose.apply(&local).into());
    }
    out
}

#[test]
fn closest_points_match_brute_force_for_every_tree_type() {
    let cow = common::cow();
    let mut rng = Rng::new(11);
    for options in common::all_options() {
        let file = build(&cow, &options, None).expect("builds");
        let triangles = common::file_triangles(&file);
        for seed in 0..3 {
            let pose = common::turned_pose(seed, 0.7);
            let points = query_points(&triangles, &pose, &mut rng);
            let answers =
                closest_points(&file, &pose, &points, &ClosestOptions::default()).expect("answers");
            let to_model = Pose::relative(&pose, &Pose::identity());
            for (p, answer) in points.iter().zip(&answers) {
                let local = to_model.apply(&Vector3::from(*p));
                let brute = triangles
                    .iter()
                    .map(|(_, t)| point_triangle_distance(&local, t))
                    .fold(f64::INFINITY, f64::min);
                let c = answer.closest.expect("no max_distance: an answer");
                let what = format!("{options:?} seed {seed} point {p:?}");
                assert!(
                    (c.distance - brute).abs() <= 1e-12 * (1.0 + brute),
                    "{what}: {} vs {brute}",
                    c.distance
                );
                // The point is on the named triangle, at the distance reported.
                let named = triangles
                    .iter()
                    .find(|(id, _)| *id == c.triangle)
                    .expect("a triangle id");
                let on = to_model.apply(&Vector3::from(c.point));
                assert!(point_triangle_distance(&on, &named.1) <= 1e-12, "{what}");
                let reach = (Vector3::from(*p) - Vector3::from(c.point)).norm();
                assert!(
                    (reach - c.distance).abs() <= 1e-12 * (1.0 + brute),
                    "{what}"
                );
            }
        }
    }
}

#[test]
fn max_distance_cuts_answers_exactly_where_brute_force_says() {
    let cow = common::cow();
    let file = build(&cow, &Default::default(), None).expect("builds");
    let triangles = common::file_triangles(&file);
    let pose = common::turned_pose(5, 0.0);
    let points = query_points(&triangles, &pose, &mut Rng::new(3));
    let exact = closest_points(&file, &pose, &points, &ClosestOptions::default()).expect("answers");
    let limit = 0.05;
    let cut = closest_points(
        &file,
        &pose,
        &points,
        &ClosestOptions {
            max_distance: limit,
        },
    )
    .expect("answers");
    let (mut kept, mut dropped) = (0, 0);
    for (e, c) in exact.iter().zip(&cut) {
        if e.distance() < limit {
            assert_eq!(c.closest.map(|x| x.distance), e.closest.map(|x| x.distance));
            kept += 1;
        } else {
            assert!(c.closest.is_none());
            // Pruning with the limit does less work.
            assert!(c.work.bv_tests() <= e.work.bv_tests());
            dropped += 1;
        }
    }
    assert!(kept > 10 && dropped > 10, "{kept} kept, {dropped} dropped");
}

#[test]
fn features_name_where_the_point_lies() {
    let mesh = common::cube(0.5);
    let file: ObbtFile = build(&mesh, &Default::default(), None).expect("builds");
    let at = |p: [f64; 3]| {
        closest_points(&file, &Pose::identity(), &[p], &ClosestOptions::default()).expect("answers")
            [0]
        .closest
        .expect("an answer")
    };
    // Above the middle of the top face (its diagonal edge aside).
    let face = at([0.2, 0.1, 2.0]);
    assert!(
        (face.distance - 1.5).abs() < 1e-15 && face.feature == Feature::Face,
        "{face:?}"
    );
    // Beyond a corner along its diagonal: the corner, at every triangle meeting there.
    let corner = at([1.5, 1.5, 1.5]);
    assert!(matches!(corner.feature, Feature::Vertex(_)), "{corner:?}");
    assert!((corner.distance - 3f64.sqrt()).abs() < 1e-15);
    // Beside the middle of an edge of the cube.
    let edge = at([1.0, 0.0, 1.0]);
    assert!(matches!(edge.feature, Feature::Edge(_)), "{edge:?}");
    assert!((edge.distance - 0.5f64.sqrt()).abs() < 1e-15);
    // The names the CLI and the bindings print.
    let names = [face, edge, corner].map(|c| c.feature.name());
    assert_eq!(names, ["face", "edge", "vertex"]);
    // On the surface: distance 0, the point itself.
    let on = at([0.5, 0.25, -0.125]);
    assert_eq!(on.distance, 0.0);
    assert_eq!(on.point, [0.5, 0.25, -0.125]);
}

#[test]
fn bad_query_points_and_limits_are_refused() {
    let file = build(&common::cube(0.5), &Default::default(), None).expect("builds");
    let pose = Pose::identity();
    for bad in [[0.0, f64::NAN, 0.0], [f64::INFINITY, 0.0, 0.0]] {
        let points = [[0.0; 3], bad];
        let error =
            closest_points(&file, &pose, &points, &Default::default()).expect_err("refused");
        assert!(
            matches!(
                error,
                QueryError::BadInput {
                    what: "query point",
                    index: 1,
                    ..
                }
            ),
            "{error}"
        );
        assert!(error.to_string().starts_with("query point 1: "), "{error}");
    }
    for max_distance in [0.0, f64::NAN] {
        let options = ClosestOptions { max_distance };
        let error = closest_points(&file, &pose, &[[0.0; 3]], &options).expect_err("refused");
        assert!(
            matches!(
                error,
                QueryError::BadOption {
                    name: "max_distance",
                    ..
                }
            ),
            "{error}"
        );
    }
}

/// `obbtree closest` prints what the library answers, point by point, and refuses bad
/// input with one line and status 1.
#[test]
fn the_cli_answers_as_the_library() {
    use common::cli::{assert_bad_input, cow, obbtree, scratch, stderr};
    let dir = scratch("closest");
    let points = dir.join("points.txt");
    std::fs::write(&points, "# x y z\n0 0 1\n\n0.5,0,0\n0.1 0.2 0.05\n3 3 3\n").expect("writes");
    let pose = "1,0,0,0,0,-1,0,1,0,0.1,0,0";
    let o = obbtree(&[
        "closest",
        cow().as_str(),
        "--points",
        points.to_str().expect("a path"),
        "--pose",
        pose,
        "--json",
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    let lines: Vec<serde_json::Value> = String::from_utf8_lossy(&o.stdout)
        .lines()
        .map(|l| serde_json::from_str(l).expect("JSON"))
        .collect();
    let file = build(&common::cow(), &Default::default(), None).expect("builds");
    let queries = [
        [0.0, 0.0, 1.0],
        [0.5, 0.0, 0.0],
        [0.1, 0.2, 0.05],
        [3.0, 3.0, 3.0],
    ];
    let pose = Pose::from_row_major(&[1.0, 0.0, 0.0, 0.0, 0.0, -1.0, 0.0, 1.0, 0.0, 0.1, 0.0, 0.0])
        .expect("a pose");
    let answers =
        closest_points(&file, &pose, &queries, &ClosestOptions::default()).expect("answers");
    assert_eq!(lines.len(), answers.len());
    for (i, (line, answer)) in lines.iter().zip(&answers).enumerate() {
        let c = answer.closest.expect("an answer");
        assert_eq!(line["point"], i);
        assert_eq!(line["distance"].as_f64(), Some(c.distance));
        assert_eq!(line["tri"], c.triangle);
        assert_eq!(line["feature"]["kind"], c.feature.name());
    }
    let cow_path = cow();
    for (args, needle) in [
        (vec!["--point", "1,2"], "--point"),
        (vec!["--point", "0,0,nan"], "finite"),
        (
            vec!["--point", "0,0,0", "--max-distance", "-1"],
            "--max-distance must be",
        ),
        (vec![], "--points"),
    ] {
        let mut all = vec!["closest", cow_path.as_str()];
        all.extend(args);
        assert_bad_input(&obbtree(&all), needle);
    }
}

/// Coherent points (a sweep along the surface) are warm-started from the answer before
/// them: the same distances as each point asked alone, with fewer volumes and triangles
/// tested in all.
#[test]
fn a_coherent_sweep_is_warm_started_from_the_previous_answer() {
    let file = build(&common::cow(), &Default::default(), None).expect("builds");
    let pose = Pose::identity();
    let sweep: Vec<[f64; 3]> = (0..2000)
        .map(|i| {
            let a = f64::from(i) * 0.002;
            [
                0.9 * a.cos() - 0.2,
                0.25 * a.sin() + 0.1,
                0.3 * (a * 1.3).cos(),
            ]
        })
        .collect();
    let options = ClosestOptions::default();
    let warm = closest_points(&file, &pose, &sweep, &options).expect("answers");
    let (mut alone_bv, mut alone_tri) = (0, 0);
    for (p, w) in sweep.iter().zip(&warm) {
        let alone = closest_points(&file, &pose, &[*p], &options).expect("answers");
        assert_eq!(alone[0].distance(), w.distance(), "{p:?}");
        alone_bv += alone[0].work.bv_tests();
        alone_tri += alone[0].work.tri_tests();
    }
    let warm_bv: u64 = warm.iter().map(|w| w.work.bv_tests()).sum();
    let warm_tri: u64 = warm.iter().map(|w| w.work.tri_tests()).sum();
    assert!(
        warm_bv < alone_bv && warm_tri < alone_tri,
        "warm {warm_bv} volumes, {warm_tri} triangles; alone {alone_bv}, {alone_tri}"
    );
}

/// A sliver found by the differential fuzzer: Ericson's region tests cancel on it, and
/// picked the face at a point 0.056 farther than the nearest of its edges. The answer must
/// be as near as the reference's (computed another way), in both frames it was met in.
#[test]
fn a_sliver_gets_its_nearest_point() {
    use obbtree::query::triangle::closest_point_on_triangle;
    let t = [
        [5.813213737593799, 1.8982047865648, 0.4671715113867928],
        [5.915062363271039, 1.9403918686293735, 0.40824691928354306],
        [1.841117336181433, 0.2529085860464335, 2.7652306034135323],
    ];
    let p = Vector3::new(3.5, 0.875, 0.0);
    let (q, _) = closest_point_on_triangle(&p, &t.map(Vector3::from));
    let reference = point_triangle_distance(&p, &t);
    assert!((reference - 1.6051518805091713).abs() < 1e-9, "{reference}");
    assert!(((p - q).norm() - reference).abs() < 1e-12, "{q:?}");
}

/// Each Voronoi region of a triangle gives its feature: the face, edge `k` (from corner `k`
/// to corner `k + 1`) or corner `k`, with that number, and the exact closest point.
#[test]
fn each_region_of_a_triangle_names_its_feature_and_number() {
    use obbtree::query::triangle::closest_point_on_triangle;
    let t = [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]].map(Vector3::from);
    for (p, q, feature, index) in [
        ([0.25, 0.25, 1.0], [0.25, 0.25, 0.0], Feature::Face, 0),
        ([0.5, -1.0, 0.5], [0.5, 0.0, 0.0], Feature::Edge(0), 0),
        ([1.0, 1.0, 0.0], [0.5, 0.5, 0.0], Feature::Edge(1), 1),
        ([-1.0, 0.5, 0.0], [0.0, 0.5, 0.0], Feature::Edge(2), 2),
        ([-1.0, -1.0, 0.0], [0.0, 0.0, 0.0], Feature::Vertex(0), 0),
        ([2.0, -1.0, 0.0], [1.0, 0.0, 0.0], Feature::Vertex(1), 1),
        ([-1.0, 3.0, 0.0], [0.0, 1.0, 0.0], Feature::Vertex(2), 2),
    ] {
        let (got, f) = closest_point_on_triangle(&Vector3::from(p), &t);
        assert_eq!(
            (got, f, f.index()),
            (Vector3::from(q), feature, index),
            "{p:?}"
        );
    }
}

/// Triangles of no area along one axis-aligned line make boxes of no area: the index's
/// surface-area cost cannot weigh a split of them, and a group a leaf can hold stays one
/// leaf (the cost of its children is taken as the parent's), so a point tests them all.
#[test]
fn a_few_triangles_of_no_area_on_one_line_stay_one_leaf() {
    // Four segments along x (each a triangle with a repeated corner), one after another.
    let vertices: Vec<[f64; 3]> = (0..8).map(|i| [f64::from(i), 0.0, 0.0]).collect();
    let faces = vec![[0, 1, 1], [2, 3, 3], [4, 5, 5], [6, 7, 7]];
    let mesh = obbtree::mesh::TriMesh::new(vertices, faces).expect("a mesh");
    let file = common::tree_f64(&mesh);
    let answers = closest_points(
        &file,
        &Pose::identity(),
        &[[0.5, 1.0, 0.0]],
        &ClosestOptions::default(),
    )
    .expect("answers");
    let answer = &answers[0];
    let closest = answer.closest.expect("a closest point");
    assert_eq!((closest.triangle, closest.distance), (0, 1.0));
    assert_eq!(answer.work.tri_separated + answer.work.tri_contact, 4);
}

/// Closest points compare squared distances, which overflow past `MAX_COORDINATE`: a
/// query point placed beyond it (by its coordinates or by the model's pose) and a model
/// whose own triangles reach beyond it are refused by name, with the point's line when it
/// came from a file; a point at the limit is answered.
#[test]
fn coordinates_beyond_reach_are_refused_by_name_and_the_limit_is_answered() {
    use obbtree::query::MAX_COORDINATE;
    let file = build(&common::cube(0.5), &Default::default(), None).expect("builds");
    let id = Pose::identity();
    let far = MAX_COORDINATE;
    let answers =
        closest_points(&file, &id, &[[far, 0.0, 0.0]], &Default::default()).expect("answers");
    let d = answers[0].distance();
    assert!((d - (far - 0.5)).abs() <= 1e-12 * far, "{d}");
    let refused = |pose: &Pose, points: &[[f64; 3]], file: &ObbtFile| {
        closest_points(file, pose, points, &Default::default()).expect_err("refused")
    };
    let beyond = [[0.0; 3], [0.0, -1.5 * far, 0.0]];
    let moved = Pose::translation(2.0 * far, 0.0, 0.0);
    for error in [
        refused(&id, &beyond, &file),
        refused(&moved, &[[0.0; 3]], &file),
    ] {
        assert!(
            matches!(
                error,
                QueryError::BadInput {
                    what: "query point",
                    ..
                }
            ),
            "{error}"
        );
        assert!(error.to_string().contains("within ±1e150"), "{error}");
    }
    let huge = obbtree::build::BuildOptions {
        precision: obbtree::real::Precision::F64,
        scale: 10.0 * far,
        ..Default::default()
    };
    let huge = build(&common::cube(0.5), &huge, None).expect("builds");
    let error = refused(&id, &[[0.0; 3]], &huge);
    assert!(
        matches!(
            error,
            QueryError::BadInput {
                what: "model triangle",
                ..
            }
        ),
        "{error}"
    );
    assert!(error.to_string().ends_with("got 5e150"), "{error}");
    // The CLI names the line of a file's bad point (a comment and a blank line before it).
    use common::cli::{assert_bad_input, cow, obbtree, scratch};
    let dir = scratch("closest-reach");
    let points = dir.join("points.txt");
    std::fs::write(&points, "# x y z\n0 0 0\n\n0 2e150 0\n").expect("writes");
    let points = points.to_str().expect("a path");
    assert_bad_input(
        &obbtree(&["closest", cow().as_str(), "--points", points]),
        &format!("{points}: line 4: query point 1: coordinates must be within ±1e150"),
    );
}
