//! Rays against one posed model (`query::cast_rays`, `query::all_ray_hits`): the traversal
//! against brute force over every triangle, the triangle test against an independent one
//! (Möller–Trumbore) away from edges, and watertightness on closed meshes with rays aimed
//! exactly at corners and edges.
// Test code outside `#[test]` functions (helpers, property bodies): a failure is a failed test.
#![allow(clippy::expect_used, clippy::indexing_slicing)]

use crate::common;

use nalgebra::Vector3;
use obbtree::build::build;
use obbtree::format::ObbtFile;
use obbtree::generate::Rng;
use obbtree::query::triangle::RaySpace;
use obbtree::query::{all_ray_hits, cast_rays, Pose, QueryError, Ray, RayHit, RayMode, RayOptions};

type Tri = [[f64; 3]; 3];

/// Rays at `triangles` (model frame) posed by `pose`: aimed at corners, edge midpoints and
/// jittered centroids from outside, grazing along edges, from inside the model, and
/// random ones that mostly miss.
fn rays_at(triangles: &[(u32, Tri)], pose: &Pose, rng: &mut Rng) -> Vec<Ray> {
    let mut out = Vec::new();
    for k in 0..80 {
        let (_, t) = triangles[rng.below(triangles.len())];
        let [a, b, c] = t.map(Vector3::from);
        let mut random = |r: f64| Vector3::new(rng.signed(), rng.signed(), rng.signed()) * r;
        let from = random(4.0);
        let (origin, target) = match k % 6 {
            0 => (from, a),
            1 => (from, (a + b) / 2.0),
            2 => (from, (a + b + c) / 3.0 + random(0.02)),
            // Along an edge: grazing the surface.
            3 => (a - (b - a) * 2.0, b),
            // From the model's middle outwards.
            4 => (random(0.05), (a + b + c) / 3.0),
            _ => (from, random(4.0)),
        };
        let direction = target - origin;
        if direction.norm() == 0.0 {
            continue;
        }
        out.push(Ray {
            origin: pose.apply(&origin).into(),
            direction: (pose.rotation() * direction).into(),
        });
    }
    out
}

/// Every hit of `ray` on `triangles`, one triangle at a time, in the model frame the
/// library maps the ray into; sorted by `t`, then id.
fn brute_hits(triangles: &[(u32, Tri)], pose: &Pose, ray: &Ray, t_max: f64) -> Vec<(f64, u32)> {
    let to_model = Pose::relative(pose, &Pose::identity());
    let origin = to_model.apply(&Vector3::from(ray.origin));
    let direction = to_model.rotation() * Vector3::from(ray.direction);
    let space = RaySpace::new(&origin, &direction).expect("a valid ray");
    let mut hits: Vec<(f64, u32)> = triangles
        .iter()
        .filter_map(|(id, t)| Some((space.intersect(&t.map(Vector3::from), t_max)?.t, *id)))
        .collect();
    hits.sort_by(|a, b| a.0.total_cmp(&b.0).then(a.1.cmp(&b.1)));
    hits
}

/// A hit's geometry agrees with itself: the barycentric point is the ray's point at `t`,
/// and the normal is the named triangle's, posed.
fn assert_consistent(hit: &RayHit, ray: &Ray, triangles: &[(u32, Tri)], pose: &Pose, what: &str) {
    let (_, t) = triangles
        .iter()
        .find(|(id, _)| *id == hit.triangle)
        .expect("a triangle id");
    let [a, b, c] = t.map(|p| pose.apply(&Vector3::from(p)));
    let w = hit.barycentric;
    assert!(w.iter().all(|x| *x >= 0.0), "{what}: weights {w:?}");
    assert!((w.iter().sum::<f64>() - 1.0).abs() < 1e-12, "{what}");
    let on = a * w[0] + b * w[1] + c * w[2];
    let at = Vector3::from(ray.at(hit.t));
    let scale = 1.0 + at.norm() + Vector3::from(ray.origin).norm();
    assert!((on - at).norm() <= 1e-9 * scale, "{what}: {on:?} vs {at:?}");
    let n = (b - a).cross(&(c - a));
    if n.norm() > 1e-12 {
        assert!(
            (n.normalize() - Vector3::from(hit.normal)).norm() < 1e-9,
            "{what}"
        );
    }
}

#[test]
fn closest_any_and_all_hits_match_brute_force_for_every_tree_type() {
    let cow = common::cow();
    let mut rng = Rng::new(21);
    for options in common::all_options() {
        let file = build(&cow, &options, None).expect("builds");
        let triangles = common::file_triangles(&file);
        for seed in 0..2 {
            let pose = common::turned_pose(seed, 0.7);
            let rays = rays_at(&triangles, &pose, &mut rng);
            let closest = cast_rays(&file, &pose, &rays, &RayOptions::default()).expect("answers");
            let all = all_ray_hits(&file, &pose, &rays, f64::INFINITY).expect("answers");
            let t_max = 1.5;
            let any = cast_rays(
                &file,
                &pose,
                &rays,
                &RayOptions {
                    mode: RayMode::Any,
                    t_max,
                },
            )
            .expect("answers");
            for (k, ray) in rays.iter().enumerate() {
                let what = format!("{options:?} seed {seed} ray {k} {ray:?}");
                let brute = brute_hits(&triangles, &pose, ray, f64::INFINITY);
                // Ties: the smallest input id among equal `t`.
                let first = closest[k].hit.map(|h| (h.t, h.triangle));
                assert_eq!(first, brute.first().copied(), "{what}");
                let every: Vec<(f64, u32)> =
                    all[k].hits.iter().map(|h| (h.t, h.triangle)).collect();
                assert_eq!(every, brute, "{what}");
                for hit in closest[k].hit.iter().chain(&all[k].hits) {
                    assert_consistent(hit, ray, &triangles, &pose, &what);
                }
                let within = brute_hits(&triangles, &pose, ray, t_max);
                match any[k].hit {
                    Some(h) => assert!(within.contains(&(h.t, h.triangle)), "{what}"),
                    None => assert!(within.is_empty(), "{what}"),
                }
            }
        }
    }
}

/// Ties go to the smallest input id, wherever the tied triangles lie in the index: two
/// groups of four copies of a triangle (a leaf's worth each) in one plane, overlapping
/// where the rays meet it, the smaller ids in either group; rays from either side, from
/// afar (the copies of a group tie) and from a point of the plane (all eight tie at
/// `t = 0`, where a box entered exactly at the horizon must still be opened).
#[test]
fn tied_triangles_go_to_the_smallest_id() {
    let small = [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]];
    let large = [[-1.0, -1.0, 0.0], [9.0, -1.0, 0.0], [0.2, 5.0, 0.0]];
    for first in [small, large] {
        let second = if first == small { large } else { small };
        let corners: Vec<[f64; 3]> = [first; 4]
            .into_iter()
            .chain([second; 4])
            .flatten()
            .collect();
        let faces = (0..8u32).map(|k| [3 * k, 3 * k + 1, 3 * k + 2]).collect();
        let mesh = obbtree::mesh::TriMesh::new(corners, faces).expect("a mesh");
        for options in common::all_options() {
            let file = build(&mesh, &options, None).expect("builds");
            let mut rays = Vec::new();
            for (x, y) in [(0.2, 0.3), (0.5, 0.25), (0.1, 0.1), (0.3, 0.6)] {
                for (z, dz) in [(2.0, -1.0), (-3.0, 1.0), (0.0, 1.0), (0.0, -1.0)] {
                    rays.push(Ray {
                        origin: [x, y, z],
                        direction: [0.01, -0.01, dz],
                    });
                }
            }
            let pose = Pose::identity();
            let closest = cast_rays(&file, &pose, &rays, &RayOptions::default()).expect("answers");
            let all = all_ray_hits(&file, &pose, &rays, f64::INFINITY).expect("answers");
            for (k, ray) in rays.iter().enumerate() {
                let what = format!("{options:?} ray {ray:?}");
                let hits: Vec<(f64, u32)> = all[k].hits.iter().map(|h| (h.t, h.triangle)).collect();
                assert_eq!(hits.len(), 8, "{what}");
                // Copies of one triangle tie exactly; the two shapes' `t` may differ by a
                // rounding, except from a point of the plane, where every `t` is 0.
                let hit = closest[k].hit.map(|h| (h.t, h.triangle));
                assert_eq!(hit, hits.first().copied(), "{what}");
                if ray.origin[2] == 0.0 {
                    assert_eq!(hit, Some((0.0, 0)), "{what}");
                }
            }
        }
    }
}

/// A model large enough that its index is built on two threads (past `PARALLEL_MIN`
/// triangles, which the cow is not) answers as brute force: closest and all hits.
#[test]
fn a_model_whose_index_is_built_in_parallel_answers_as_brute_force() {
    let sphere = common::uv_sphere(1.0, 70, 80);
    let file = build(&sphere, &Default::default(), None).expect("builds");
    let triangles = common::file_triangles(&file);
    assert!(triangles.len() > 10_000, "{} triangles", triangles.len());
    let pose = common::turned_pose(2, 0.4);
    let rays = rays_at(&triangles, &pose, &mut Rng::new(5));
    let closest = cast_rays(&file, &pose, &rays, &RayOptions::default()).expect("answers");
    let all = all_ray_hits(&file, &pose, &rays, f64::INFINITY).expect("answers");
    for (k, ray) in rays.iter().enumerate() {
        let brute = brute_hits(&triangles, &pose, ray, f64::INFINITY);
        let first = closest[k].hit.map(|h| (h.t, h.triangle));
        assert_eq!(first, brute.first().copied(), "ray {k} {ray:?}");
        let every: Vec<(f64, u32)> = all[k].hits.iter().map(|h| (h.t, h.triangle)).collect();
        assert_eq!(every, brute, "ray {k} {ray:?}");
    }
}

/// Möller–Trumbore's test, for rays clearly inside or outside a triangle: the weights of
/// corners 1 and 2 and the ray parameter.
fn moller_trumbore(o: &Vector3<f64>, d: &Vector3<f64>, t: &Tri) -> Option<(f64, f64, f64)> {
    let [a, b, c] = t.map(Vector3::from);
    let (e1, e2) = (b - a, c - a);
    let p = d.cross(&e2);
    let det = e1.dot(&p);
    if det.abs() < 1e-12 {
        return None;
    }
    let s = o - a;
    let u = s.dot(&p) / det;
    let q = s.cross(&e1);
    let v = d.dot(&q) / det;
    Some((u, v, e2.dot(&q) / det))
}

#[test]
fn the_triangle_test_agrees_with_moller_trumbore_away_from_edges() {
    let mut rng = Rng::new(5);
    let mut checked = 0;
    for _ in 0..20_000 {
        let mut point = || Vector3::new(rng.signed(), rng.signed(), rng.signed());
        let t: Tri = [point().into(), point().into(), point().into()];
        let (o, d) = (point() * 3.0, point());
        let Some(space) = RaySpace::new(&o, &d) else {
            continue;
        };
        let Some((u, v, t_mt)) = moller_trumbore(&o, &d, &t) else {
            continue;
        };
        let margin = 1e-7;
        let inside = u > margin && v > margin && u + v < 1.0 - margin && t_mt > margin;
        let outside = u < -margin || v < -margin || u + v > 1.0 + margin || t_mt < -margin;
        let hit = space.intersect(&t.map(Vector3::from), f64::INFINITY);
        if inside {
            let hit = hit.expect("Möller–Trumbore hits");
            assert!(
                (hit.t - t_mt).abs() <= 1e-9 * (1.0 + t_mt),
                "{} vs {t_mt}",
                hit.t
            );
            assert!((hit.barycentric[1] - u).abs() < 1e-9 && (hit.barycentric[2] - v).abs() < 1e-9);
            checked += 1;
        } else if outside {
            assert!(hit.is_none(), "Möller–Trumbore misses: {t:?} {o:?} {d:?}");
            checked += 1;
        }
    }
    assert!(checked > 15_000, "{checked}");
}

/// Every corner and edge midpoint of `triangles`, exactly (the stored coordinates, so f32
/// trees are aimed at exactly too).
fn corners_and_midpoints(triangles: &[(u32, Tri)]) -> Vec<Vector3<f64>> {
    let mut out = Vec::new();
    for (_, t) in triangles {
        for k in 0..3 {
            let (a, b) = (Vector3::from(t[k]), Vector3::from(t[(k + 1) % 3]));
            out.extend([a, (a + b) / 2.0]);
        }
    }
    out
}

/// Whether `p` is strictly inside the convex polyhedron of outward-facing `triangles`.
fn inside_convex(triangles: &[(u32, Tri)], p: &Vector3<f64>) -> bool {
    triangles.iter().all(|(_, t)| {
        let [a, b, c] = t.map(Vector3::from);
        (p - a).dot(&(b - a).cross(&(c - a))) < -1e-12
    })
}

/// Closed convex meshes: a ray from outside aimed exactly at a corner or an edge crosses
/// the surface an even number of times (none when it only touches the surface there),
/// from inside an odd number of times, and a ray that enters the interior through the
/// corner or edge hits it there. A ray slipping between two triangles, or hitting an edge
/// twice, breaks one of these.
#[test]
fn rays_through_corners_and_edges_of_closed_meshes_are_watertight() {
    let meshes = [
        ("cube", common::cube(0.5)),
        ("sphere", common::uv_sphere(1.0, 12, 16)),
        (
            "cuboid",
            common::cuboid([0.5, 1.0, 0.25], [0.125, -0.5, 0.0]),
        ),
    ];
    let mut rng = Rng::new(8);
    for (name, mesh) in meshes {
        for options in common::all_options() {
            let file = build(&mesh, &options, None).expect("builds");
            let triangles = common::file_triangles(&file);
            let pose = Pose::identity();
            let mut rays = Vec::new();
            for target in corners_and_midpoints(&triangles) {
                // From outside: along the axes and diagonals (exact directions) and
                // random ones; from the centre.
                let mut origins = vec![
                    target + Vector3::new(4.0, 0.0, 0.0),
                    target + Vector3::new(0.0, 0.0, -4.0),
                    target + Vector3::new(3.0, 3.0, 3.0),
                    target + Vector3::new(rng.signed(), rng.signed(), rng.signed()) * 5.0,
                ];
                origins.retain(|o| o.norm() > 2.5);
                for origin in origins {
                    let enters = inside_convex(&triangles, &(target + (target - origin) * 1e-4));
                    rays.push((
                        false,
                        enters,
                        Ray {
                            origin: origin.into(),
                            direction: (target - origin).into(),
                        },
                    ));
                }
                let centre = Vector3::new(0.01, -0.02, 0.015)
                    + mesh
                        .vertices()
                        .iter()
                        .map(|p| Vector3::from(*p))
                        .sum::<Vector3<f64>>()
                        / mesh.vertices().len() as f64;
                rays.push((
                    true,
                    true,
                    Ray {
                        origin: centre.into(),
                        direction: (target - centre).into(),
                    },
                ));
            }
            let only: Vec<Ray> = rays.iter().map(|(_, _, r)| *r).collect();
            let all = all_ray_hits(&file, &pose, &only, f64::INFINITY).expect("answers");
            let closest = cast_rays(&file, &pose, &only, &RayOptions::default()).expect("answers");
            let mut entering = 0;
            for (((inside, enters, ray), hits), first) in rays.iter().zip(&all).zip(&closest) {
                let what = format!("{name} {options:?} {ray:?}: {:?}", hits.hits);
                assert_eq!(hits.hits.len() % 2 == 1, *inside, "{what}");
                assert_eq!(first.hit.is_some(), !hits.hits.is_empty(), "{what}");
                if *enters && !*inside {
                    // Hit at the aimed point (t = 1) or before it.
                    let t = first.hit.map(|h| h.t).expect(&what);
                    assert!(t <= 1.0 + 1e-12, "{what}");
                    entering += 1;
                }
            }
            assert!(entering > 20, "{name}: {entering} rays enter");
        }
    }
}

#[test]
fn bad_rays_and_limits_are_refused_naming_the_ray() {
    let file = build(&common::cube(0.5), &Default::default(), None).expect("builds");
    let pose = Pose::identity();
    let good = Ray {
        origin: [0.0, 0.0, 3.0],
        direction: [0.0, 0.0, -1.0],
    };
    let cases = [
        (
            Ray {
                origin: [f64::NAN, 0.0, 0.0],
                ..good
            },
            "origin",
        ),
        (
            Ray {
                direction: [0.0; 3],
                ..good
            },
            "zero",
        ),
        (
            Ray {
                direction: [0.0, f64::INFINITY, 1.0],
                ..good
            },
            "direction coordinates",
        ),
    ];
    for (bad, needle) in cases {
        let error = cast_rays(&file, &pose, &[good, good, bad], &RayOptions::default())
            .expect_err("refused");
        assert!(
            matches!(
                error,
                QueryError::BadInput {
                    what: "ray",
                    index: 2,
                    ..
                }
            ),
            "{error}"
        );
        assert!(
            error.to_string().starts_with("ray 2: ") && error.to_string().contains(needle),
            "{error}"
        );
        assert!(all_ray_hits(&file, &pose, &[bad], 1.0).is_err());
    }
    for t_max in [0.0, -1.0, f64::NAN] {
        let options = RayOptions {
            t_max,
            ..Default::default()
        };
        let error = cast_rays(&file, &pose, &[good], &options).expect_err("refused");
        assert!(
            matches!(error, QueryError::BadOption { name: "t_max", .. }),
            "{error}"
        );
    }
}

/// Coordinates near the top of f64's range neither panic nor produce NaN: a hit is finite or
/// there is none.
#[test]
fn huge_coordinates_answer_without_nan() {
    let file: ObbtFile = build(&common::cube(0.5), &Default::default(), None).expect("builds");
    let rays = [
        Ray {
            origin: [1e300, 0.1, 0.2],
            direction: [-1.0, 0.0, 0.0],
        },
        Ray {
            origin: [0.1, 0.2, 3.0],
            direction: [1e-300, 0.0, -1e-300],
        },
        Ray {
            origin: [0.1, 0.2, 3.0],
            direction: [0.0, 1e299, -1e300],
        },
        Ray {
            origin: [-1e308, 1e308, 1e308],
            direction: [1e308, -1e308, -1e308],
        },
    ];
    for pose in [Pose::identity(), common::turned_pose(3, 1e200)] {
        for result in cast_rays(&file, &pose, &rays, &RayOptions::default()).expect("answers") {
            if let Some(hit) = result.hit {
                assert!(
                    hit.t.is_finite() && hit.normal.iter().all(|x| x.is_finite()),
                    "{hit:?}"
                );
            }
        }
    }
    // A direction 1e300 long meets the cube 1e-300 along it.
    let long = cast_rays(
        &file,
        &Pose::identity(),
        &rays[2..3],
        &RayOptions::default(),
    )
    .expect("answers");
    assert!(long[0].hit.is_some_and(|h| h.t > 0.0 && h.t < 1e-299));
}

/// A hit's `t` and normal are right however small or large the triangle (f64 trees, a
/// cube from 1e-150 to 1e150 across): `t` summed as products of three coordinates would
/// underflow below about 1e-100 and overflow above about 1e100 (then `t = inf` passed
/// for a hit of the far face), and the normal's sum of squares would underflow below
/// about 1e-81 and overflow above about 1e77.
#[test]
fn tiny_and_huge_triangles_have_their_t_and_unit_normals() {
    for exponent in (-150..=150).step_by(10) {
        let size = 10f64.powi(exponent);
        let file = common::tree_f64(&common::cube(size));
        let ray = Ray {
            origin: [0.1 * size, 0.2 * size, 3.0 * size],
            direction: [0.0, 0.0, -1.0],
        };
        let answer =
            cast_rays(&file, &Pose::identity(), &[ray], &RayOptions::default()).expect("answers");
        let hit = answer[0].hit.expect("the cube's top is hit");
        assert!(
            (hit.t - 2.0 * size).abs() <= 1e-12 * size,
            "{size}: {hit:?}"
        );
        assert_eq!(hit.normal, [0.0, 0.0, 1.0], "{size}: {hit:?}");
    }
}

/// `obbtree ray` prints what the library answers, ray by ray and mode by mode, and
/// refuses bad input with one line and status 1.
#[test]
fn the_cli_answers_as_the_library() {
    use common::cli::{assert_bad_input, cow, obbtree, scratch, stderr};
    let dir = scratch("rays");
    let path = dir.join("rays.txt");
    std::fs::write(
        &path,
        "# ox oy oz dx dy dz\n-10 0.01 0.02 1 0 0\n\n0,5,0,0,-1,0\n0 5 0 0 1 0\n",
    )
    .expect("writes");
    let pose = "1,0,0,0,0,-1,0,1,0,0.1,0,0";
    let rays = [
        Ray {
            origin: [-10.0, 0.01, 0.02],
            direction: [1.0, 0.0, 0.0],
        },
        Ray {
            origin: [0.0, 5.0, 0.0],
            direction: [0.0, -1.0, 0.0],
        },
        Ray {
            origin: [0.0, 5.0, 0.0],
            direction: [0.0, 1.0, 0.0],
        },
    ];
    let file = build(&common::cow(), &Default::default(), None).expect("builds");
    let pose_value =
        Pose::from_row_major(&[1.0, 0.0, 0.0, 0.0, 0.0, -1.0, 0.0, 1.0, 0.0, 0.1, 0.0, 0.0])
            .expect("a pose");
    // serde_json's parser may be an ulp off the printed shortest decimal.
    let same = |a: f64, b: f64| (a - b).abs() <= 4.0 * f64::EPSILON * b.abs();
    let run = |mode: &str| -> Vec<serde_json::Value> {
        let o = obbtree(&[
            "ray",
            cow().as_str(),
            "--rays",
            path.to_str().expect("a path"),
            "--pose",
            pose,
            "--mode",
            mode,
            "--json",
        ]);
        assert!(o.status.success(), "{}", stderr(&o));
        String::from_utf8_lossy(&o.stdout)
            .lines()
            .map(|l| serde_json::from_str(l).expect("JSON"))
            .collect()
    };
    let closest = cast_rays(&file, &pose_value, &rays, &RayOptions::default()).expect("answers");
    let lines = run("closest");
    assert_eq!(lines.len(), 3);
    for (i, (line, answer)) in lines.iter().zip(&closest).enumerate() {
        assert_eq!(line["ray"], i);
        assert_eq!(line["hit"], answer.hit.is_some());
        if let Some(h) = answer.hit {
            assert!(same(line["t"].as_f64().expect("t"), h.t), "{line}");
            assert_eq!(line["tri"], h.triangle);
        }
    }
    assert!(closest[0].hit.is_some() && closest[2].hit.is_none());
    let all = all_ray_hits(&file, &pose_value, &rays, f64::INFINITY).expect("answers");
    for (line, answer) in run("all").iter().zip(&all) {
        let ts: Vec<f64> = line["hits"]
            .as_array()
            .expect("hits")
            .iter()
            .map(|h| h["t"].as_f64().expect("t"))
            .collect();
        assert_eq!(ts.len(), answer.hits.len());
        assert!(
            ts.iter().zip(&answer.hits).all(|(t, h)| same(*t, h.t)),
            "{line}"
        );
    }
    assert!(all[0].hits.len() >= 2);
    assert_eq!(run("any")[2]["hit"], false);
    let cow_path = cow();
    for (args, needle) in [
        (vec!["--ray", "1,2,3"], "--ray"),
        (
            vec!["--ray", "0,0,0,0,0,0"],
            "ray 0: direction must not be zero",
        ),
        (vec!["--ray", "0,0,nan,1,0,0"], "finite"),
        (
            vec!["--ray", "0,0,0,1,0,0", "--t-max", "0"],
            "--t-max must be",
        ),
        (vec![], "--rays"),
    ] {
        let mut every = vec!["ray", cow_path.as_str()];
        every.extend(args);
        assert_bad_input(&obbtree(&every), needle);
    }
    // A bad row of a file is named by its line, after the comment and the blank line.
    let bad = dir.join("bad-rays.txt");
    std::fs::write(&bad, "# ox oy oz dx dy dz\n0 0 0 1 0 0\n\n0 0 0 0 0 0\n").expect("writes");
    let bad = bad.to_str().expect("a path");
    assert_bad_input(
        &obbtree(&["ray", cow_path.as_str(), "--rays", bad]),
        &format!("{bad}: line 4: ray 1: direction must not be zero"),
    );
}

/// `--threads` on the one-model commands picks how many threads answer, never what they
/// answer: one thread and two print the same lines.
#[test]
fn the_one_model_commands_answer_alike_on_any_thread_count() {
    use common::cli::{cow, obbtree, scratch, stderr};
    let dir = scratch("one-model-threads");
    let points = dir.join("points.txt");
    let rays = dir.join("rays.txt");
    let (mut p, mut r) = (String::new(), String::new());
    for i in 0..60 {
        let a = f64::from(i) * 0.31;
        p += &format!(
            "{} {} {}\n",
            0.9 * a.cos(),
            0.5 * a.sin(),
            0.3 * (2.0 * a).sin()
        );
        r += &format!(
            "{} {} 0.1 {} {} 0.02\n",
            3.0 * a.cos(),
            3.0 * a.sin(),
            -a.cos(),
            -a.sin()
        );
    }
    std::fs::write(&points, p).expect("writes");
    std::fs::write(&rays, r).expect("writes");
    let (points, rays) = (points.to_str().expect("path"), rays.to_str().expect("path"));
    let cow = cow();
    let commands: [&[&str]; 3] = [
        &["ray", &cow, "--rays", rays, "--mode", "all", "--json"],
        &["closest", &cow, "--points", points, "--csv"],
        &["inside", &cow, "--points", points, "--distance", "--csv"],
    ];
    for command in commands {
        let printed: Vec<String> = ["1", "2"]
            .iter()
            .map(|threads| {
                let o = obbtree(&[command, &["--threads", threads]].concat());
                assert!(o.status.success(), "{command:?}: {}", stderr(&o));
                String::from_utf8_lossy(&o.stdout).into_owned()
            })
            .collect();
        assert_eq!(
            printed[0].lines().count(),
            if command[0] == "ray" { 60 } else { 61 }
        );
        assert_eq!(printed[0], printed[1], "{command:?}");
    }
}

/// Triangles whose boxes share one centre (nested copies of a triangle) give the index's
/// builder no plane to split by; more of them than a leaf holds are halved as they lie,
/// so a ray past the small ones tests the large ones only.
#[test]
fn nested_triangles_with_one_centre_are_split_so_rays_skip_the_small_ones() {
    // Sixteen copies of a triangle whose box is centred on the origin, scaled 1 to 16.
    let copies = 16u32;
    let mut vertices = Vec::new();
    let mut faces = Vec::new();
    for k in 1..=copies {
        let s = f64::from(k);
        let first = vertices.len() as u32;
        vertices.extend([[-s, -s, 0.0], [s, -s, 0.0], [0.0, s, 0.0]]);
        faces.push([first, first + 1, first + 2]);
    }
    let mesh = obbtree::mesh::TriMesh::new(vertices, faces).expect("a mesh");
    let file = common::tree_f64(&mesh);
    // Down through the point of each copy's base: inside copies k and up, outside the
    // smaller ones (their boxes do not reach it).
    let down = |y: f64| Ray {
        origin: [0.0, y, 1.0],
        direction: [0.0, 0.0, -1.0],
    };
    let rays: Vec<Ray> = (1..=copies).map(|k| down(-(f64::from(k) - 0.5))).collect();
    let options = RayOptions {
        mode: RayMode::Closest,
        t_max: f64::INFINITY,
    };
    let answers = cast_rays(&file, &Pose::identity(), &rays, &options).expect("answers");
    for (k, answer) in (1..=copies).zip(&answers) {
        // Every copy hit lies at t = 1; the tie goes to the smallest id: copy k's.
        let hit = answer.hit.expect("a hit");
        assert_eq!((hit.t, hit.triangle), (1.0, k - 1), "ray {k}");
        let tested = answer.work.tri_separated + answer.work.tri_contact;
        // One leaf of all sixteen would test every copy; halving leaves the ray past the
        // smaller half's box at most the larger half and a leaf of the smaller.
        if k > copies / 2 {
            assert!(tested <= u64::from(copies / 2), "ray {k} tested {tested}");
        }
    }
}
