//! Tests of the fitting module (dissertation chapter 3): principal-axes frames for the
//! three covariance methods, their degenerate cases, and the convex hull.
// Test code outside `#[test]` functions (helpers, property bodies): a failure is a failed test.
#![allow(clippy::panic, clippy::indexing_slicing)]

use nalgebra::{Matrix3, Rotation3, SymmetricEigen, Vector3};
use obbtree::fit::hull::{convex_hull, ConvexHull, HULL_TOLERANCE};
use obbtree::fit::{principal_axes, FitMethod};
use proptest::prelude::*;

use crate::common;

use common::rng::Rng;

type P = [f64; 3];

// ---------------------------------------------------------------- helpers

fn col(m: &Matrix3<f64>, i: usize) -> Vector3<f64> {
    m.column(i).into_owned()
}

fn v(p: P) -> Vector3<f64> {
    Vector3::new(p[0], p[1], p[2])
}

/// Orthonormal to 1e-12 with determinant +1.
fn assert_frame(m: &Matrix3<f64>) {
    let e = (m.transpose() * m - Matrix3::identity()).abs().max();
    assert!(e < 1e-12, "not orthonormal (error {e:e}):\n{m}");
    let d = m.determinant();
    assert!((d - 1.0).abs() < 1e-12, "determinant {d} != 1:\n{m}");
}

/// `a` and `b` are parallel or antiparallel unit vectors, to `tol`.
fn assert_parallel(a: Vector3<f64>, b: Vector3<f64>, tol: f64) {
    let c = a.normalize().dot(&b.normalize()).abs();
    assert!(1.0 - c < tol, "{a:?} not parallel to {b:?} (|cos| = {c})");
}

/// Every column of `m` is parallel to some column of `r` (a match up to sign and
/// permutation).
fn assert_same_axes(m: &Matrix3<f64>, r: &Matrix3<f64>, tol: f64) {
    for i in 0..3 {
        let best = (0..3)
            .map(|j| col(m, i).dot(&col(r, j)).abs())
            .fold(0.0, f64::max);
        assert!(
            1.0 - best < tol,
            "column {i} of\n{m}matches no axis of\n{r}"
        );
    }
}

/// Closed, outward-oriented triangulated box: 8 corners, 12 triangles. `half` are the half
/// extents along the box axes, which are the columns of `rot`.
fn box_mesh(center: P, half: P, rot: &Matrix3<f64>) -> (Vec<P>, Vec<[u32; 3]>) {
    let mut pos = Vec::new();
    for i in 0..8 {
        let s = |b: usize| if i >> b & 1 == 1 { 1.0 } else { -1.0 };
        let local = Vector3::new(s(0) * half[0], s(1) * half[1], s(2) * half[2]);
        let p = rot * local + v(center);
        pos.push([p.x, p.y, p.z]);
    }
    // Corner index bits: x = 1, y = 2, z = 4.
    let faces = vec![
        [0, 2, 3],
        [0, 3, 1], // z-
        [4, 5, 7],
        [4, 7, 6], // z+
        [0, 1, 5],
        [0, 5, 4], // y-
        [2, 6, 7],
        [2, 7, 3], // y+
        [0, 4, 6],
        [0, 6, 2], // x-
        [1, 3, 7],
        [1, 7, 5], // x+
    ];
    (pos, faces)
}

fn rotation() -> Matrix3<f64> {
    *Rotation3::from_euler_angles(0.3, -0.7, 1.1).matrix()
}

/// A `nx` × `ny` grid of unit squares (two triangles each) in the plane spanned by `u`,
/// `w` through `origin`.
fn planar_grid(nx: u32, ny: u32, origin: P, u: P, w: P) -> (Vec<P>, Vec<[u32; 3]>) {
    let mut pos = Vec::new();
    for j in 0..=ny {
        for i in 0..=nx {
            let p = v(origin) + v(u) * i as f64 + v(w) * j as f64;
            pos.push([p.x, p.y, p.z]);
        }
    }
    let id = |i: u32, j: u32| j * (nx + 1) + i;
    let mut faces = Vec::new();
    for j in 0..ny {
        for i in 0..nx {
            faces.push([id(i, j), id(i + 1, j), id(i + 1, j + 1)]);
            faces.push([id(i, j), id(i + 1, j + 1), id(i, j + 1)]);
        }
    }
    (pos, faces)
}

/// Points on a sphere, spread by the golden-angle spiral.
fn sphere_points(n: usize, radius: f64, center: P) -> Vec<P> {
    let golden = std::f64::consts::PI * (3.0 - 5.0_f64.sqrt());
    (0..n)
        .map(|i| {
            let z = 1.0 - 2.0 * (i as f64 + 0.5) / n as f64;
            let r = (1.0 - z * z).sqrt();
            let t = golden * i as f64;
            [
                center[0] + radius * r * t.cos(),
                center[1] + radius * r * t.sin(),
                center[2] + radius * z,
            ]
        })
        .collect()
}

/// Faces that reference every point (as degenerate-free as the order allows); for the
/// point-set tests of the vertex and hull methods, whose results depend only on the
/// referenced vertices.
fn cover(n: usize) -> Vec<[u32; 3]> {
    let n = n as u32;
    (0..n).map(|i| [i, (i + 1) % n, (i + 2) % n]).collect()
}

fn diameter(points: &[P]) -> f64 {
    let mut lo = [f64::MAX; 3];
    let mut hi = [f64::MIN; 3];
    for p in points {
        for k in 0..3 {
            lo[k] = lo[k].min(p[k]);
            hi[k] = hi[k].max(p[k]);
        }
    }
    (v(hi) - v(lo)).norm()
}

/// Checks the hull invariants: closed 2-manifold (every directed edge has its reverse),
/// vertices are input points, and every point is inside or within tolerance of every face
/// plane (so the faces are outward and the hull convex).
fn assert_hull_contains(points: &[P], triangles: &[[u32; 3]]) {
    // The hull promises containment to within a few times its tolerance.
    let tol = 100.0 * HULL_TOLERANCE * diameter(points) + 1e-12;
    let mut edges = std::collections::HashSet::new();
    for t in triangles {
        for k in 0..3 {
            assert!((t[k] as usize) < points.len());
            assert!(edges.insert((t[k], t[(k + 1) % 3])), "edge used twice");
        }
    }
    for &(a, b) in &edges {
        assert!(edges.contains(&(b, a)), "hull surface is not closed");
    }
    for t in triangles {
        let (a, b, c) = (
            v(points[t[0] as usize]),
            v(points[t[1] as usize]),
            v(points[t[2] as usize]),
        );
        let n = (b - a).cross(&(c - a));
        let n = n / n.norm();
        for p in points {
            let h = n.dot(&(v(*p) - a));
            assert!(
                h <= tol,
                "point {p:?} is {h:e} outside a hull face (tolerance {tol:e})"
            );
        }
    }
}

/// The hull-surface covariance frame computed independently: the public hull, the
/// closed-form moments of §3.4 written out again, and nalgebra's iterative solver.
fn reference_hull_axes(points: &[P]) -> (Vector3<f64>, Vector3<f64>) {
    let Ok(ConvexHull::Polyhedron { triangles }) = convex_hull(points) else {
        panic!("expected a polyhedron");
    };
    let (mut area, mut mean, mut second) = (0.0, Vector3::zeros(), Matrix3::zeros());
    for t in &triangles {
        let (p, q, r) = (
            v(points[t[0] as usize]),
            v(points[t[1] as usize]),
            v(points[t[2] as usize]),
        );
        let a = 0.5 * (q - p).cross(&(r - p)).norm();
        let m = (p + q + r) / 3.0;
        area += a;
        mean += a * m;
        second += a / 12.0
            * (9.0 * m * m.transpose() + p * p.transpose() + q * q.transpose() + r * r.transpose());
    }
    let mean = mean / area;
    let c = second / area - mean * mean.transpose();
    let e = SymmetricEigen::new(c);
    let mut idx = [0, 1, 2];
    idx.sort_by(|&i, &j| e.eigenvalues[j].total_cmp(&e.eigenvalues[i]));
    (
        e.eigenvectors.column(idx[0]).into_owned(),
        e.eigenvectors.column(idx[2]).into_owned(),
    )
}

// ---------------------------------------------------------------- FitMethod

#[test]
fn method_names_and_tags_round_trip() {
    assert_eq!(FitMethod::default(), FitMethod::Hull);
    assert_eq!(
        FitMethod::ALL,
        [FitMethod::Hull, FitMethod::Triangles, FitMethod::Vertices]
    );
    let names: Vec<_> = FitMethod::ALL.iter().map(|m| m.name()).collect();
    assert_eq!(names, ["hull", "triangles", "vertices"]);
    let tags: Vec<_> = FitMethod::ALL.iter().map(|m| m.tag()).collect();
    assert_eq!(tags, [1, 2, 3]);
    for m in FitMethod::ALL {
        assert_eq!(FitMethod::from_name(m.name()), Some(m));
        assert_eq!(FitMethod::from_tag(m.tag()), Some(m));
    }
    assert_eq!(FitMethod::from_name("Hull"), None);
    assert_eq!(FitMethod::from_name(""), None);
    assert_eq!(FitMethod::from_tag(0), None);
    assert_eq!(FitMethod::from_tag(4), None);
}

// ---------------------------------------------------------------- single triangle

#[test]
fn one_triangle_has_its_normal_as_column_2() {
    let pos = vec![[1.0, 2.0, 3.0], [4.0, 2.5, 2.0], [1.5, 5.0, 4.5]];
    let faces = [[0, 1, 2]];
    let n = (v(pos[1]) - v(pos[0])).cross(&(v(pos[2]) - v(pos[0])));
    for m in FitMethod::ALL {
        let r = principal_axes(m, &pos, &faces);
        assert_frame(&r);
        assert_parallel(col(&r, 2), n, 1e-14);
        // Columns 0 and 1 span the triangle's plane.
        assert!(col(&r, 0).dot(&n.normalize()).abs() < 1e-14);
    }
}

#[test]
fn one_triangle_matches_the_general_covariance() {
    // A long thin triangle: the fast path must agree with the eigenvectors of its
    // vertex covariance (which, for one triangle, is proportional to its area covariance).
    let pos = vec![[0.0, 0.0, 0.0], [10.0, 1.0, 0.5], [3.0, 2.0, -1.0]];
    let m = (v(pos[0]) + v(pos[1]) + v(pos[2])) / 3.0;
    let c: Matrix3<f64> = pos
        .iter()
        .map(|&p| (v(p) - m) * (v(p) - m).transpose())
        .sum();
    let e = SymmetricEigen::new(c);
    let imax = e.eigenvalues.imax();
    for method in FitMethod::ALL {
        let r = principal_axes(method, &pos, &[[0, 1, 2]]);
        assert_parallel(col(&r, 0), e.eigenvectors.column(imax).into_owned(), 1e-12);
    }
}

// ---------------------------------------------------------------- degenerate sets

#[test]
fn collinear_points_put_column_0_along_the_line() {
    let d = v([1.0, -2.0, 0.5]);
    let pos: Vec<P> = (0..7)
        .map(|i| {
            let p = v([3.0, 1.0, -2.0]) + d * (i as f64 * 0.37);
            [p.x, p.y, p.z]
        })
        .collect();
    let faces = [[0, 1, 2], [2, 3, 6], [1, 4, 5]];
    for m in FitMethod::ALL {
        let r = principal_axes(m, &pos, &faces);
        assert_frame(&r);
        assert_parallel(col(&r, 0), d, 1e-14);
    }
    // A single degenerate triangle too.
    for m in FitMethod::ALL {
        let r = principal_axes(m, &pos, &[[0, 3, 6]]);
        assert_frame(&r);
        assert_parallel(col(&r, 0), d, 1e-14);
    }
}

#[test]
fn coincident_points_give_the_identity() {
    let pos = vec![[1.5, -2.0, 7.0]; 5];
    for m in FitMethod::ALL {
        assert_eq!(principal_axes(m, &pos, &[[0, 1, 2]]), Matrix3::identity());
        assert_eq!(
            principal_axes(m, &pos, &[[0, 1, 2], [2, 3, 4]]),
            Matrix3::identity()
        );
        assert_eq!(principal_axes(m, &pos, &[[3, 3, 3]]), Matrix3::identity());
    }
}

#[test]
fn coplanar_grid_has_the_plane_normal_as_column_2() {
    // A 6 × 2 grid in a tilted plane: long along u.
    let u = [0.8, 0.6, 0.0];
    let w = [-0.36, 0.48, 0.8];
    let (pos, faces) = planar_grid(6, 2, [1.0, -3.0, 2.0], u, w);
    let n = v(u).cross(&v(w));
    for m in FitMethod::ALL {
        let r = principal_axes(m, &pos, &faces);
        assert_frame(&r);
        assert_parallel(col(&r, 2), n, 1e-14);
        assert_parallel(col(&r, 0), v(u), 1e-12);
    }
}

#[test]
fn coplanar_hull_uses_the_convex_polygon() {
    // An L-shaped region (3×3 grid without its top-right 2×2 block) in a tilted plane.
    // The hull method must see only its convex polygon: it agrees with the triangle
    // method applied to that polygon, and differs from the triangle method on the L.
    let rot = rotation();
    let to3 = |x: f64, y: f64| {
        let p = rot * Vector3::new(x, y, 0.0) + Vector3::new(5.0, -1.0, 2.0);
        [p.x, p.y, p.z]
    };
    let mut pos = Vec::new();
    let mut faces = Vec::new();
    for j in 0..3u32 {
        for i in 0..3u32 {
            if i >= 1 && j >= 1 {
                continue;
            }
            // Make the L uneven so its principal axes are well defined.
            let (x, y) = (i as f64 * 2.0, j as f64);
            let b = pos.len() as u32;
            pos.extend([
                to3(x, y),
                to3(x + 2.0, y),
                to3(x + 2.0, y + 1.0),
                to3(x, y + 1.0),
            ]);
            faces.extend([[b, b + 1, b + 2], [b, b + 2, b + 3]]);
        }
    }
    // Convex hull of the L: (0,0) (6,0) (6,1) (2,3) (0,3).
    let poly = [
        to3(0.0, 0.0),
        to3(6.0, 0.0),
        to3(6.0, 1.0),
        to3(2.0, 3.0),
        to3(0.0, 3.0),
    ];
    let poly_faces = [[0, 1, 2], [0, 2, 3], [0, 3, 4]];
    let hull = principal_axes(FitMethod::Hull, &pos, &faces);
    let reference = principal_axes(FitMethod::Triangles, &poly, &poly_faces);
    let tris = principal_axes(FitMethod::Triangles, &pos, &faces);
    assert_frame(&hull);
    assert_parallel(col(&hull, 2), col(&rot, 2), 1e-14);
    assert_parallel(col(&hull, 0), col(&reference, 0), 1e-12);
    assert!(
        col(&hull, 0).dot(&col(&tris, 0)).abs() < 0.999,
        "hull should differ from triangles"
    );
}

// ---------------------------------------------------------------- boxes

#[test]
fn axis_aligned_cube_gets_the_identity() {
    let (pos, faces) = box_mesh([0.5, -2.0, 3.0], [1.0, 1.0, 1.0], &Matrix3::identity());
    for m in FitMethod::ALL {
        let r = principal_axes(m, &pos, &faces);
        assert!((r - Matrix3::identity()).abs().max() < 1e-12, "{m:?}:\n{r}");
    }
}

#[test]
fn rotated_box_gets_the_rotated_axes_in_order() {
    let rot = rotation();
    let (pos, faces) = box_mesh([1.0, 2.0, 3.0], [3.0, 2.0, 1.0], &rot);
    for m in FitMethod::ALL {
        let r = principal_axes(m, &pos, &faces);
        assert_frame(&r);
        for i in 0..3 {
            assert_parallel(col(&r, i), col(&rot, i), 1e-12);
        }
    }
}

#[test]
fn rotated_cube_gets_the_rotated_axes() {
    // A cube's covariance is isotropic, so the covariance alone cannot orient it; the
    // tie-breaking must still find the cube's own axes (a tight box).
    let rot = rotation();
    let (pos, faces) = box_mesh([-1.0, 0.5, 2.0], [1.5, 1.5, 1.5], &rot);
    for m in FitMethod::ALL {
        let r = principal_axes(m, &pos, &faces);
        assert_frame(&r);
        assert_same_axes(&r, &rot, 1e-12);
    }
}

#[test]
fn rotated_square_prism_gets_its_cross_section_axes() {
    // Two equal eigenvalues (square cross-section): the free pair must align with the
    // square's sides.
    let rot = rotation();
    let (pos, faces) = box_mesh([0.0, 0.0, 0.0], [4.0, 1.0, 1.0], &rot);
    for m in FitMethod::ALL {
        let r = principal_axes(m, &pos, &faces);
        assert_frame(&r);
        assert_parallel(col(&r, 0), col(&rot, 0), 1e-12);
        assert_same_axes(&r, &rot, 1e-12);
    }
}

#[test]
fn elongated_box_has_column_0_along_the_long_axis() {
    let d = v([1.0, 1.0, 0.2]).normalize();
    let rot = *Rotation3::rotation_between(&Vector3::x(), &d)
        .unwrap()
        .matrix();
    let (pos, faces) = box_mesh([0.0, 10.0, -4.0], [20.0, 0.5, 0.3], &rot);
    for m in FitMethod::ALL {
        let r = principal_axes(m, &pos, &faces);
        assert_frame(&r);
        assert_parallel(col(&r, 0), d, 1e-12);
    }
}

#[test]
fn far_from_origin_box_is_still_exact() {
    // Covariance sums are taken relative to the data, not the origin.
    let rot = rotation();
    let (pos, faces) = box_mesh([1e6, -2e6, 3e5], [3.0, 2.0, 1.0], &rot);
    for m in FitMethod::ALL {
        let r = principal_axes(m, &pos, &faces);
        assert_frame(&r);
        for i in 0..3 {
            assert_parallel(col(&r, i), col(&rot, i), 1e-9);
        }
    }
}

// ---------------------------------------------------------------- duplicates

#[test]
fn duplicated_vertices_and_triangles_change_nothing_for_hull_and_vertices() {
    let mut rng = Rng::new(7);
    let pos: Vec<P> = (0..40)
        .map(|_| [rng.signed() * 3.0, rng.signed(), rng.signed() * 0.5])
        .collect();
    let faces: Vec<[u32; 3]> = (0..30)
        .map(|_| {
            let mut i = || rng.below(40) as u32;
            [i(), i(), i()]
        })
        .collect();
    // Every face twice.
    let doubled: Vec<[u32; 3]> = faces.iter().chain(&faces).copied().collect();
    // Every position twice; faces alternate between the copies (an unwelded soup).
    let pos2: Vec<P> = pos.iter().chain(&pos).copied().collect();
    let split: Vec<[u32; 3]> = faces
        .iter()
        .enumerate()
        .map(|(k, f)| {
            f.map(|i| {
                if (k + i as usize).is_multiple_of(2) {
                    i
                } else {
                    i + 40
                }
            })
        })
        .collect();
    for m in [FitMethod::Hull, FitMethod::Vertices] {
        let r = principal_axes(m, &pos, &faces);
        for (p, f) in [(&pos, &doubled), (&pos2, &split)] {
            let r2 = principal_axes(m, p, f);
            assert!((r - r2).abs().max() < 1e-12, "{m:?}:\n{r}\n{r2}");
        }
    }
    // Repeated triangles do not change the triangle method's area distribution either.
    let r = principal_axes(FitMethod::Triangles, &pos, &faces);
    let r2 = principal_axes(FitMethod::Triangles, &pos, &doubled);
    assert!((r - r2).abs().max() < 1e-12);
}

// ---------------------------------------------------------------- contract

#[test]
fn results_are_deterministic_bitwise() {
    let mut rng = Rng::new(11);
    let pos: Vec<P> = (0..500)
        .map(|_| [rng.signed(), rng.signed() * 2.0, rng.signed()])
        .collect();
    let faces = cover(pos.len());
    let (cube, cube_faces) = box_mesh([0.0; 3], [1.0; 3], &rotation());
    for m in FitMethod::ALL {
        let a = principal_axes(m, &pos, &faces);
        // Interleave other work so per-thread buffers hold different state.
        let _ = principal_axes(m, &cube, &cube_faces);
        let b = principal_axes(m, &pos, &faces);
        let c = std::thread::scope(|s| s.spawn(|| principal_axes(m, &pos, &faces)).join().unwrap());
        for (x, y) in a.iter().zip(b.iter()).chain(a.iter().zip(c.iter())) {
            assert_eq!(x.to_bits(), y.to_bits());
        }
    }
}

#[test]
fn odd_input_never_panics() {
    let pos = vec![
        [0.0, 0.0, 0.0],
        [1.0, 0.0, 0.0],
        [0.0, 1.0, 0.0],
        [f64::NAN, 0.0, 1.0],
    ];
    for m in FitMethod::ALL {
        assert_eq!(principal_axes(m, &pos, &[]), Matrix3::identity());
        // Out-of-range indices are ignored.
        assert_frame(&principal_axes(m, &pos, &[[0, 1, 99]]));
        assert_frame(&principal_axes(m, &pos, &[[0, 1, 2], [7, 8, 9]]));
        // Non-finite coordinates (outside the contract) still give a frame.
        assert_frame(&principal_axes(m, &pos, &[[0, 1, 3]]));
        assert_frame(&principal_axes(m, &pos, &[[0, 1, 2], [1, 2, 3]]));
        assert_frame(&principal_axes(m, &[], &[[0, 1, 2], [1, 2, 3]]));
    }
}

#[test]
fn hull_frame_matches_an_independent_computation() {
    let mut rng = Rng::new(3);
    // An anisotropic cloud so the axes are well separated.
    let pos: Vec<P> = (0..300)
        .map(|_| {
            let p = rotation()
                * Vector3::new(3.0 * rng.signed(), 1.5 * rng.signed(), 0.5 * rng.signed());
            [p.x, p.y, p.z]
        })
        .collect();
    let r = principal_axes(FitMethod::Hull, &pos, &cover(pos.len()));
    let (e0, e2) = reference_hull_axes(&pos);
    assert_parallel(col(&r, 0), e0, 1e-10);
    assert_parallel(col(&r, 2), e2, 1e-10);
}

#[test]
fn every_method_gives_a_frame_on_random_clouds() {
    let mut rng = Rng::new(99);
    for n in [3usize, 4, 5, 8, 17, 64, 1000] {
        let pos: Vec<P> = (0..n)
            .map(|_| [rng.signed(), rng.signed(), rng.signed()])
            .collect();
        for m in FitMethod::ALL {
            assert_frame(&principal_axes(m, &pos, &cover(n)));
        }
    }
}

// ---------------------------------------------------------------- convex hull

#[test]
fn hull_of_cube_corners_and_interior_points() {
    let mut rng = Rng::new(5);
    let (mut pos, _) = box_mesh([0.5, 0.5, 0.5], [0.5, 0.5, 0.5], &Matrix3::identity());
    pos.extend((0..200).map(|_| {
        [
            0.05 + 0.9 * rng.unit(),
            0.05 + 0.9 * rng.unit(),
            0.05 + 0.9 * rng.unit(),
        ]
    }));
    let hull = convex_hull(&pos).unwrap();
    let ConvexHull::Polyhedron { triangles } = &hull else {
        panic!("expected a polyhedron, got {hull:?}");
    };
    assert_eq!(triangles.len(), 12);
    assert!(triangles.iter().flatten().all(|&i| i < 8));
    assert!((hull.area(&pos) - 6.0).abs() < 1e-12);
    assert_hull_contains(&pos, triangles);
}

#[test]
fn hull_of_points_on_a_sphere_uses_every_point() {
    let pos = sphere_points(2000, 2.5, [1.0, -1.0, 3.0]);
    let ConvexHull::Polyhedron { triangles } = convex_hull(&pos).unwrap() else {
        panic!("expected a polyhedron");
    };
    let mut used = vec![false; pos.len()];
    for &i in triangles.iter().flatten() {
        used[i as usize] = true;
    }
    assert!(
        used.iter().all(|&u| u),
        "a point on the sphere is not a hull vertex"
    );
    // Euler: a triangulated sphere with V vertices has 2V − 4 faces.
    assert_eq!(triangles.len(), 2 * pos.len() - 4);
    assert_hull_contains(&pos, &triangles);
}

#[test]
fn hull_of_random_points_contains_them() {
    let mut rng = Rng::new(42);
    for (n, scale) in [(10usize, 1.0), (100, 1e-3), (1000, 1.0), (5000, 1e4)] {
        let pos: Vec<P> = (0..n)
            .map(|_| {
                [
                    scale * rng.signed(),
                    scale * rng.signed(),
                    scale * rng.signed(),
                ]
            })
            .collect();
        let ConvexHull::Polyhedron { triangles } = convex_hull(&pos).unwrap() else {
            panic!("expected a polyhedron");
        };
        assert_hull_contains(&pos, &triangles);
    }
}

#[test]
fn hull_of_grids_terminates_and_is_right() {
    // A 3-D lattice: lots of exactly coplanar and collinear points on the boundary.
    let mut pos = Vec::new();
    for i in 0..8 {
        for j in 0..8 {
            for k in 0..8 {
                pos.push([i as f64, j as f64 * 0.5, k as f64 * 0.25]);
            }
        }
    }
    let hull = convex_hull(&pos).unwrap();
    let ConvexHull::Polyhedron { triangles } = &hull else {
        panic!("expected a polyhedron");
    };
    assert_hull_contains(&pos, triangles);
    let area = 2.0 * (7.0 * 3.5 + 7.0 * 1.75 + 3.5 * 1.75);
    assert!((hull.area(&pos) - area).abs() < 1e-9);

    // A planar lattice: a polygon with the plane normal.
    let (grid, _) = planar_grid(10, 7, [0.0, 0.0, 1.0], [1.0, 0.0, 1.0], [0.0, 1.0, 0.0]);
    let hull = convex_hull(&grid).unwrap();
    let ConvexHull::Polygon { vertices, normal } = &hull else {
        panic!("expected a polygon, got {hull:?}");
    };
    assert_eq!(vertices.len(), 4, "collinear boundary points are dropped");
    assert_parallel(v(*normal), v([-1.0, 0.0, 1.0]), 1e-14);
    assert!((hull.area(&grid) - 70.0 * 2.0_f64.sqrt()).abs() < 1e-9);

    // Latitude-longitude points on a sphere (cospherical, many on common circles, poles
    // repeated).
    let mut ll = Vec::new();
    for a in 0..=20 {
        for b in 0..40 {
            let (t, p) = (
                a as f64 * std::f64::consts::PI / 20.0,
                b as f64 * std::f64::consts::PI / 20.0,
            );
            ll.push([t.sin() * p.cos(), t.sin() * p.sin(), t.cos()]);
        }
    }
    let ConvexHull::Polyhedron { triangles } = convex_hull(&ll).unwrap() else {
        panic!("expected a polyhedron");
    };
    assert_hull_contains(&ll, &triangles);
}

#[test]
fn hull_of_noisy_nearly_coplanar_points_succeeds() {
    // Points sampled on the faces of a rotated box (scanned-CAD-like: large, nearly flat
    // patches), with noise around the hull tolerance and exact duplicates.
    let rot = rotation();
    for (seed, noise) in [
        (1u64, 0.0),
        (2, 1e-12),
        (3, 1e-9),
        (4, 1e-8),
        (5, 1e-7),
        (6, 1e-5),
    ] {
        let mut rng = Rng::new(seed);
        let mut pos = Vec::new();
        for _ in 0..3000 {
            let axis = rng.below(3);
            let mut q = [rng.signed() * 2.0, rng.signed(), rng.signed() * 0.5];
            q[axis] = if rng.unit() < 0.5 { -1.0 } else { 1.0 } * [2.0, 1.0, 0.5][axis];
            let p = rot * (v(q) + Vector3::new(rng.signed(), rng.signed(), rng.signed()) * noise);
            pos.push([p.x + 10.0, p.y - 5.0, p.z]);
        }
        let copy = pos.clone();
        pos.extend(copy.iter().step_by(3));
        let hull = convex_hull(&pos);
        let Ok(ConvexHull::Polyhedron { triangles }) = &hull else {
            panic!("noise {noise:e}: {hull:?}");
        };
        assert_hull_contains(&pos, triangles);
    }
}

#[test]
fn hull_classifies_low_dimensional_sets() {
    assert_eq!(convex_hull(&[]), Err(obbtree::fit::hull::HullError::Empty));
    assert!(matches!(
        convex_hull(&[[1.0, 2.0, 3.0]; 4]),
        Ok(ConvexHull::Point { .. })
    ));
    let line: Vec<P> = (0..5).map(|i| [i as f64, 2.0 * i as f64, 1.0]).collect();
    let Ok(ConvexHull::Segment { ends }) = convex_hull(&line) else {
        panic!("expected a segment");
    };
    let mut ends = ends;
    ends.sort();
    assert_eq!(ends, [0, 4]);
    // A triangle, and a nearly flat set (within the tolerance): polygons.
    assert!(matches!(
        convex_hull(
            &line[..2]
                .iter()
                .chain(&[[0.0, 0.0, 5.0]])
                .copied()
                .collect::<Vec<_>>()
        ),
        Ok(ConvexHull::Polygon { .. })
    ));
    let flat = [
        [0.0, 0.0, 0.0],
        [1.0, 0.0, 0.0],
        [0.0, 1.0, 0.0],
        [1.0, 1.0, 1e-12],
    ];
    assert!(matches!(convex_hull(&flat), Ok(ConvexHull::Polygon { .. })));
}

#[test]
fn real_mesh_if_available() {
    // The shared meshes are not part of the crate; skip quietly when absent.
    let Ok(text) = std::fs::read_to_string("/work/shared/meshes/cow.obj") else {
        return;
    };
    let mut pos = Vec::new();
    let mut faces = Vec::new();
    for line in text.lines() {
        let mut it = line.split_whitespace();
        match it.next() {
            Some("v") => {
                let c: Vec<f64> = it.take(3).filter_map(|x| x.parse().ok()).collect();
                pos.push([c[0], c[1], c[2]]);
            }
            Some("f") => {
                let c: Vec<u32> = it
                    .filter_map(|x| x.split('/').next()?.parse::<u32>().ok())
                    .map(|i| i - 1)
                    .collect();
                for k in 1..c.len() - 1 {
                    faces.push([c[0], c[k], c[k + 1]]);
                }
            }
            _ => {}
        }
    }
    for m in FitMethod::ALL {
        assert_frame(&principal_axes(m, &pos, &faces));
    }
    let ConvexHull::Polyhedron { triangles } = convex_hull(&pos).unwrap() else {
        panic!("expected a polyhedron");
    };
    assert_hull_contains(&pos, &triangles);
}

// ---------------------------------------------------------------- properties

/// Random clouds: general, with duplicated points, exactly coplanar (in a random plane),
/// and nearly coplanar.
fn cloud() -> impl Strategy<Value = Vec<P>> {
    let point = prop::array::uniform3(-100.0f64..100.0);
    (
        prop::collection::vec(point, 1..60),
        0u8..4,
        prop::array::uniform3(-1.0f64..1.0),
    )
        .prop_map(|(mut pts, kind, dir)| {
            match kind {
                1 => {
                    let copy = pts.clone();
                    pts.extend(copy.iter().step_by(2));
                }
                2 | 3 => {
                    // Project onto the plane through the origin with normal `dir`.
                    let n = v(dir);
                    if n.norm() > 1e-3 {
                        let n = n.normalize();
                        let thickness = if kind == 3 { 1e-9 } else { 0.0 };
                        for (i, p) in pts.iter_mut().enumerate() {
                            let q = v(*p) - n * n.dot(&v(*p)) + n * (thickness * (i % 3) as f64);
                            *p = [q.x, q.y, q.z];
                        }
                    }
                }
                _ => {}
            }
            pts
        })
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(256))]

    #[test]
    fn prop_frames_are_orthonormal_and_right_handed(pts in cloud(), seed in any::<u64>()) {
        let n = pts.len();
        let mut rng = Rng::new(seed);
        let faces: Vec<[u32; 3]> = (0..1 + n / 2)
            .map(|_| [rng.below(n) as u32, rng.below(n) as u32, rng.below(n) as u32])
            .collect();
        for m in FitMethod::ALL {
            let r = principal_axes(m, &pts, &faces);
            assert_frame(&r);
            let again = principal_axes(m, &pts, &faces);
            prop_assert!(r.iter().zip(again.iter()).all(|(a, b)| a.to_bits() == b.to_bits()));
        }
    }

    #[test]
    fn prop_hull_of_noisy_box_surfaces(seed in any::<u64>(), noise in 0.0f64..1e-6, n in 4usize..400) {
        let mut rng = Rng::new(seed);
        let pos: Vec<P> = (0..n)
            .map(|_| {
                let axis = rng.below(3);
                let mut q = [rng.signed(), rng.signed(), rng.signed()];
                q[axis] = if rng.unit() < 0.5 { -1.0 } else { 1.0 };
                [q[0] + noise * rng.signed(), q[1] + noise * rng.signed(), q[2] + noise * rng.signed()]
            })
            .collect();
        // Noise around the tolerance is the hardest case for floating point: the hull may
        // (rarely) report failure, but never return a wrong surface.
        if let Ok(ConvexHull::Polyhedron { triangles }) = convex_hull(&pos) {
            assert_hull_contains(&pos, &triangles);
        }
        // The fit never fails: it falls back to the triangle covariance.
        for m in FitMethod::ALL {
            assert_frame(&principal_axes(m, &pos, &cover(n)));
        }
    }

    #[test]
    fn prop_hull_contains_every_point(pts in cloud()) {
        match convex_hull(&pts) {
            Ok(ConvexHull::Polyhedron { triangles }) => assert_hull_contains(&pts, &triangles),
            Ok(ConvexHull::Polygon { vertices, normal }) => {
                prop_assert!(vertices.len() >= 3);
                // All points lie in the polygon's plane and inside its edges.
                let d = diameter(&pts);
                let tol = 10.0 * HULL_TOLERANCE * d + 1e-12;
                let n = v(normal);
                let o = v(pts[vertices[0] as usize]);
                for k in 0..vertices.len() {
                    let a = v(pts[vertices[k] as usize]);
                    let b = v(pts[vertices[(k + 1) % vertices.len()] as usize]);
                    let out = (b - a).cross(&n).normalize();
                    for p in &pts {
                        prop_assert!(n.dot(&(v(*p) - o)).abs() <= tol * 10.0 + 1e-9 * d);
                        prop_assert!(out.dot(&(v(*p) - a)) <= tol);
                    }
                }
            }
            Ok(_) => {}
            Err(e) => prop_assert!(false, "hull failed: {e}"),
        }
    }
}
