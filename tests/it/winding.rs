//! Winding numbers and signed distances of one posed model (`query::winding_numbers`,
//! `query::signed_distances`): exact values on closed meshes and soups whose winding
//! numbers are known in closed form, ray parity as an independent inside test, and the
//! hierarchical approximation within its stated bound of the exact sum.
// Test code outside `#[test]` functions (helpers, property bodies): a failure is a failed test.
#![allow(clippy::expect_used, clippy::indexing_slicing)]

use crate::common;

use nalgebra::Vector3;
use obbtree::build::build;
use obbtree::generate::Rng;
use obbtree::mesh::TriMesh;
use obbtree::query::{
    all_ray_hits, closest_points, signed_distances, winding_numbers, Pose, QueryError, Ray,
    WindingAccuracy, WindingOptions,
};

const EXACT: WindingOptions = WindingOptions {
    accuracy: WindingAccuracy::Exact,
};

/// Exact, proven within `tolerance`, and Barill's rule at β = 2.
fn accuracies(tolerance: f64) -> [WindingOptions; 3] {
    [
        WindingAccuracy::Exact,
        WindingAccuracy::Bounded { tolerance },
        WindingAccuracy::Beta { beta: 2.0 },
    ]
    .map(|accuracy| WindingOptions { accuracy })
}

/// `mesh` with its triangles `keep`-filtered and repeated `copies` times, plus `extra`.
fn soup(
    mesh: &TriMesh,
    keep: impl Fn(usize) -> bool,
    copies: usize,
    extra: Option<&TriMesh>,
) -> TriMesh {
    let mut vertices = mesh.vertices().to_vec();
    let mut faces = Vec::new();
    for _ in 0..copies {
        faces.extend(
            mesh.faces()
                .iter()
                .enumerate()
                .filter(|(i, _)| keep(*i))
                .map(|(_, f)| *f),
        );
    }
    if let Some(other) = extra {
        let base = vertices.len() as u32;
        vertices.extend_from_slice(other.vertices());
        faces.extend(other.faces().iter().map(|f| f.map(|i| i + base)));
    }
    TriMesh::new(vertices, faces).expect("a soup")
}

#[test]
fn winding_numbers_of_closed_meshes_and_soups_are_known_exactly() {
    let cube = common::cube(1.0);
    // The face at x = +1 (its two triangles) left out: from the centre it covers a sixth
    // of the sphere of directions.
    let open_face: Vec<usize> = cube
        .faces()
        .iter()
        .enumerate()
        .filter(|(_, f)| f.iter().all(|&i| cube.vertices()[i as usize][0] == 1.0))
        .map(|(i, _)| i)
        .collect();
    assert_eq!(open_face.len(), 2);
    let shifted = common::cuboid([1.0, 1.0, 1.0], [1.0, 0.0, 0.0]);
    let cases = [
        (
            "cube",
            cube.clone(),
            // On the surface: the share of directions that look inside (a face's triangle
            // adds nothing, not the ±2π of either side).
            vec![
                ([0.0, 0.0, 0.0], 1.0),
                ([3.0, 0.2, 0.1], 0.0),
                ([1.0, 0.2, 0.1], 0.5),
                ([1.0, -1.0, 0.3], 0.25),
                ([-1.0, 1.0, 1.0], 0.125),
            ],
        ),
        (
            "open cube",
            soup(&cube, |i| !open_face.contains(&i), 1, None),
            vec![([0.0; 3], 5.0 / 6.0)],
        ),
        (
            "doubled cube",
            soup(&cube, |_| true, 2, None),
            vec![([0.1, 0.2, 0.3], 2.0), ([0.0, 4.0, 0.0], 0.0)],
        ),
        (
            "overlapping cubes",
            soup(&cube, |_| true, 1, Some(&shifted)),
            vec![
                ([0.5, 0.1, 0.1], 2.0),
                ([-0.5, 0.1, 0.1], 1.0),
                ([1.5, 0.1, 0.1], 1.0),
                ([2.5, 0.0, 0.0], 0.0),
            ],
        ),
    ];
    for (name, mesh, expected) in cases {
        for options in common::all_options() {
            let file = build(&mesh, &options, None).expect("builds");
            let points: Vec<[f64; 3]> = expected.iter().map(|(p, _)| *p).collect();
            for accuracy in accuracies(1e-3) {
                let w =
                    winding_numbers(&file, &Pose::identity(), &points, &accuracy).expect("answers");
                for ((p, want), got) in expected.iter().zip(&w) {
                    assert!(
                        (got.value - want).abs() <= 1e-9 + got.error_bound,
                        "{name} {options:?} {accuracy:?} at {p:?}: {} vs {want}",
                        got.value
                    );
                    // Beta's error is bounded by what it did; the others' by 1e-3 beforehand.
                    if !matches!(accuracy.accuracy, WindingAccuracy::Beta { .. }) {
                        assert!(
                            (got.value - want).abs() <= 1e-3,
                            "{name} {accuracy:?}: {got:?}"
                        );
                    }
                }
            }
        }
    }
}

/// Random points of a closed mesh's neighbourhood: inside exactly where a ray from the
/// point crosses the surface an odd number of times.
#[test]
fn inside_agrees_with_ray_parity_on_closed_meshes() {
    let meshes = [
        ("sphere", common::uv_sphere(1.0, 16, 24)),
        ("cuboid", common::cuboid([0.5, 1.0, 0.25], [0.1, -0.2, 0.0])),
    ];
    let mut rng = Rng::new(4);
    for (name, mesh) in meshes {
        let file = build(&mesh, &Default::default(), None).expect("builds");
        let pose = common::turned_pose(2, 0.5);
        let points: Vec<[f64; 3]> = (0..400)
            .map(|_| {
                pose.apply(&(Vector3::new(rng.signed(), rng.signed(), rng.signed()) * 1.3))
                    .into()
            })
            .collect();
        let rays: Vec<Ray> = points
            .iter()
            .map(|p| Ray {
                origin: *p,
                direction: [0.3, 0.5, 0.81],
            })
            .collect();
        let crossings = all_ray_hits(&file, &pose, &rays, f64::INFINITY).expect("answers");
        for accuracy in accuracies(1e-2) {
            let w = winding_numbers(&file, &pose, &points, &accuracy).expect("answers");
            for ((p, w), hits) in points.iter().zip(&w).zip(&crossings) {
                assert_eq!(
                    w.inside(),
                    hits.hits.len() % 2 == 1,
                    "{name} at {p:?}: {w:?}"
                );
                // Closed: 0 or 1 within the stated bound.
                let target = if w.inside() { 1.0 } else { 0.0 };
                assert!(
                    (w.value - target).abs() <= 1e-9 + w.error_bound,
                    "{name} at {p:?}: {w:?}"
                );
            }
        }
    }
}

/// On an open model (the cow, with holes) the approximation stays within its stated bound
/// of the exact sum, for every tree type and several tolerances, and works less.
#[test]
fn the_approximation_stays_within_its_bound_of_the_exact_sum() {
    let cow = common::cow();
    let mut rng = Rng::new(6);
    let points: Vec<[f64; 3]> = (0..300)
        .map(|k| {
            let r = if k % 3 == 0 { 3.0 } else { 0.6 };
            [rng.signed() * r, rng.signed() * r, rng.signed() * r]
        })
        .collect();
    for options in common::all_options() {
        let file = build(&cow, &options, None).expect("builds");
        let pose = common::turned_pose(1, 0.2);
        let exact = winding_numbers(&file, &pose, &points, &EXACT).expect("answers");
        assert!(exact.iter().all(|w| w.error_bound == 0.0));
        let accuracies = [1e-1, 1e-2, 1e-4]
            .map(|tolerance| WindingAccuracy::Bounded { tolerance })
            .into_iter()
            .chain([2.0, 3.0].map(|beta| WindingAccuracy::Beta { beta }));
        for accuracy in accuracies {
            let near = winding_numbers(&file, &pose, &points, &WindingOptions { accuracy })
                .expect("answers");
            let (mut ours, mut theirs, mut worst) = (0, 0, 0.0f64);
            for (a, e) in near.iter().zip(&exact) {
                if let WindingAccuracy::Bounded { tolerance } = accuracy {
                    assert!(a.error_bound <= tolerance, "{options:?}: {a:?}");
                }
                assert!(
                    (a.value - e.value).abs() <= a.error_bound + 1e-10,
                    "{options:?} {accuracy:?}: {a:?} vs {e:?}"
                );
                worst = worst.max((a.value - e.value).abs());
                ours += a.work.tri_tests() + a.work.bv_tests();
                theirs += e.work.tri_tests() + e.work.bv_tests();
            }
            let fast = match accuracy {
                WindingAccuracy::Bounded { tolerance } => tolerance >= 1e-2,
                _ => true,
            };
            if fast {
                assert!(
                    ours * 2 < theirs,
                    "{options:?} {accuracy:?}: {ours} vs {theirs}"
                );
            }
            if let WindingAccuracy::Beta { .. } = accuracy {
                // Near the cow's surface, where the expansion errs most.
                assert!(worst < 5e-2, "{options:?} {accuracy:?}: {worst}");
            }
        }
    }
}

#[test]
fn signed_distances_are_closest_distances_negative_inside() {
    let mesh = common::uv_sphere(1.0, 12, 16);
    let file = build(&mesh, &Default::default(), None).expect("builds");
    let pose = common::turned_pose(0, 0.3);
    let points: Vec<[f64; 3]> = [
        [0.0, 0.0, 0.0],
        [0.5, 0.1, 0.0],
        [2.0, 0.0, 0.0],
        [0.0, -1.5, 0.5],
    ]
    .iter()
    .map(|p| pose.apply(&Vector3::from(*p)).into())
    .collect();
    let signed = signed_distances(&file, &pose, &points, &Default::default()).expect("answers");
    let closest = closest_points(&file, &pose, &points, &Default::default()).expect("answers");
    for (k, (s, c)) in signed.iter().zip(&closest).enumerate() {
        let sign = if k < 2 { -1.0 } else { 1.0 };
        assert_eq!(*s, sign * c.distance(), "point {k}");
    }
}

#[test]
fn bad_points_and_tolerances_are_refused() {
    let file = build(&common::cube(0.5), &Default::default(), None).expect("builds");
    let pose = Pose::identity();
    let error = winding_numbers(&file, &pose, &[[0.0; 3], [f64::NAN, 0.0, 0.0]], &EXACT)
        .expect_err("refused");
    assert!(
        matches!(error, QueryError::BadInput { index: 1, .. }),
        "{error}"
    );
    let bad = [0.0, -1.0, f64::NAN]
        .map(|tolerance| (WindingAccuracy::Bounded { tolerance }, "tolerance"))
        .into_iter()
        .chain([1.0, f64::NAN].map(|beta| (WindingAccuracy::Beta { beta }, "beta")));
    for (accuracy, name) in bad {
        let error = winding_numbers(&file, &pose, &[[0.0; 3]], &WindingOptions { accuracy })
            .expect_err("refused");
        assert!(
            matches!(error, QueryError::BadOption { name: n, .. } if n == name),
            "{error}"
        );
    }
    assert!(signed_distances(&file, &pose, &[[f64::INFINITY; 3]], &EXACT).is_err());
}

/// `obbtree inside` prints what the library answers and refuses bad input with one line
/// and status 1.
#[test]
fn the_cli_answers_as_the_library() {
    use common::cli::{assert_bad_input, cow, obbtree, scratch, stderr};
    let dir = scratch("inside");
    let path = dir.join("points.txt");
    std::fs::write(&path, "# x y z\n0 0 0\n\n0.3,0.1,0\n2 2 2\n").expect("writes");
    let points = [[0.0, 0.0, 0.0], [0.3, 0.1, 0.0], [2.0, 2.0, 2.0]];
    let file = build(&common::cow(), &Default::default(), None).expect("builds");
    for (flags, accuracy) in [
        (vec![], WindingAccuracy::Beta { beta: 2.0 }),
        (vec!["--beta", "3"], WindingAccuracy::Beta { beta: 3.0 }),
        (vec!["--tolerance", "0"], WindingAccuracy::Exact),
        (
            vec!["--tolerance", "0.01"],
            WindingAccuracy::Bounded { tolerance: 0.01 },
        ),
    ] {
        let cow_path = cow();
        let mut args = vec![
            "inside",
            cow_path.as_str(),
            "--points",
            path.to_str().expect("a path"),
            "--distance",
            "--json",
        ];
        args.extend(flags);
        let o = obbtree(&args);
        assert!(o.status.success(), "{}", stderr(&o));
        let lines: Vec<serde_json::Value> = String::from_utf8_lossy(&o.stdout)
            .lines()
            .map(|l| serde_json::from_str(l).expect("JSON"))
            .collect();
        let options = WindingOptions { accuracy };
        let w = winding_numbers(&file, &Pose::identity(), &points, &options).expect("answers");
        let s = signed_distances(&file, &Pose::identity(), &points, &options).expect("answers");
        assert_eq!(lines.len(), 3);
        for ((line, w), s) in lines.iter().zip(&w).zip(&s) {
            let same = |a: &serde_json::Value, b: f64| {
                (a.as_f64().expect("a number") - b).abs()
                    <= 4.0 * f64::EPSILON * b.abs().max(1e-300)
            };
            assert!(same(&line["winding_number"], w.value), "{line}");
            assert_eq!(line["inside"], w.inside());
            assert!(same(&line["signed_distance"], *s), "{line}");
        }
    }
    let cow_path = cow();
    for (args, needle) in [
        (vec!["--point", "1,2"], "--point"),
        (vec!["--point", "0,0,nan"], "query point 0"),
        (vec!["--point", "0,0,0", "--beta", "0.5"], "--beta must be"),
        (
            vec!["--point", "0,0,0", "--tolerance", "-1"],
            "--tolerance must be at least 0 (0 is exact), got -1",
        ),
        (vec![], "--points"),
    ] {
        let mut every = vec!["inside", cow_path.as_str()];
        every.extend(args);
        assert_bad_input(&obbtree(&every), needle);
    }
}

/// Far from a model, and on a model whose moments overflow, winding numbers stay finite
/// in every mode: the expansion is evaluated on the unit direction (no power of the
/// distance is formed), a triangle's exact angle is taken again at unit scale when its
/// cubes overflow, and a cluster that cannot be placed (its area overflowed) is opened.
/// (The window where only the moments overflow is the unit test
/// `clusters_whose_moments_overflow_are_opened`.)
#[test]
fn far_points_and_huge_models_get_finite_winding_numbers() {
    let accuracies = [
        EXACT,
        WindingOptions {
            accuracy: WindingAccuracy::Bounded { tolerance: 1e-3 },
        },
        WindingOptions::default(),
    ];
    let cow = build(&common::cow(), &Default::default(), None).expect("builds");
    let far: Vec<[f64; 3]> = [1e60, 1e120, obbtree::query::MAX_COORDINATE]
        .iter()
        .map(|&x| [x, 3.0, -x])
        .collect();
    for options in &accuracies {
        let w = winding_numbers(&cow, &Pose::identity(), &far, options).expect("answers");
        for (p, w) in far.iter().zip(&w) {
            assert!(
                w.value.abs() < 1e-100 && w.error_bound.is_finite(),
                "{p:?}: {w:?}"
            );
        }
    }
    // A sphere 1e80 across: its triangles' areas (squares of squares of its size)
    // overflow, not its coordinates, so every cluster is opened.
    let huge = obbtree::build::BuildOptions {
        precision: obbtree::real::Precision::F64,
        scale: 1e80,
        ..Default::default()
    };
    let huge = build(&common::uv_sphere(1.0, 8, 12), &huge, None).expect("builds");
    let points = [[0.0; 3], [3e80, 0.0, 0.0]];
    for options in &accuracies {
        let w = winding_numbers(&huge, &Pose::identity(), &points, options).expect("answers");
        assert!((w[0].value - 1.0).abs() < 1e-9, "{:?}", w[0]);
        assert!(w[1].value.abs() < 1e-9, "{:?}", w[1]);
    }
}
