//! The leaf primitives of the queries: exact contact of closed triangles, minimum distance
//! with witnesses, maximum distance.
//!
//! Hand-built configurations with known answers (each also run with its corners permuted, the
//! two triangles swapped, scaled and offset), then seeded property tests against independent
//! references: an exact integer oracle for contact on grid coordinates, a brute-force
//! distance by convex one-dimensional searches, plus sampling and separating-plane
//! certificates that do not depend on any formula.
// Test code outside `#[test]` functions (helpers, property bodies): a failure is a failed test.
#![allow(clippy::indexing_slicing)]

use nalgebra::Vector3;
use obbtree::query::triangle::{
    triangle_distance, triangle_max_distance, triangles_intersect, Triangle, TriangleDistance,
};
use proptest::prelude::*;
use proptest::test_runner::RngSeed;

type V = Vector3<f64>;

fn v(x: f64, y: f64, z: f64) -> V {
    V::new(x, y, z)
}

fn t(p: [f64; 3], q: [f64; 3], r: [f64; 3]) -> Triangle {
    [V::from(p), V::from(q), V::from(r)]
}

// ---------------------------------------------------------------------------------------------
// Independent references.
// ---------------------------------------------------------------------------------------------

/// Exact contact oracle on integer coordinates, in i128, by a different method: two closed
/// triangles meet iff an edge of one meets the other (closed) triangle.
mod exact {
    pub type P = [i128; 3];

    fn sub(a: P, b: P) -> P {
        [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
    }
    fn cross(a: P, b: P) -> P {
        [
            a[1] * b[2] - a[2] * b[1],
            a[2] * b[0] - a[0] * b[2],
            a[0] * b[1] - a[1] * b[0],
        ]
    }
    fn dot(a: P, b: P) -> i128 {
        a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
    }
    fn scale(a: P, k: i128) -> P {
        [a[0] * k, a[1] * k, a[2] * k]
    }
    const ZERO: P = [0, 0, 0];

    fn point_on_seg(p: P, r: P, s: P) -> bool {
        if r == s {
            return p == r;
        }
        let (w, d) = (sub(p, r), sub(s, r));
        cross(w, d) == ZERO && dot(w, d) >= 0 && dot(w, d) <= dot(d, d)
    }

    pub fn seg_seg(p: P, q: P, r: P, s: P) -> bool {
        if p == q {
            return point_on_seg(p, r, s);
        }
        if r == s {
            return point_on_seg(r, p, q);
        }
        let (u, v, w) = (sub(q, p), sub(s, r), sub(r, p));
        let c = cross(u, v);
        if c == ZERO {
            if cross(u, w) != ZERO {
                return false; // distinct parallel lines
            }
            let (b0, b1) = (dot(w, u), dot(sub(s, p), u));
            return b0.max(b1) >= 0 && b0.min(b1) <= dot(u, u);
        }
        if dot(w, c) != 0 {
            return false; // skew
        }
        let cc = dot(c, c);
        let tp = dot(cross(w, v), c);
        let tr = dot(cross(w, u), c);
        (0..=cc).contains(&tp) && (0..=cc).contains(&tr)
    }

    fn in_tri_coplanar(p: P, t: &[P; 3], n: P) -> bool {
        (0..3).all(|i| dot(cross(sub(t[(i + 1) % 3], t[i]), sub(p, t[i])), n) >= 0)
    }

    pub fn seg_tri(p: P, q: P, t: &[P; 3]) -> bool {
        let n = cross(sub(t[1], t[0]), sub(t[2], t[0]));
        let edges = |p, q| (0..3).any(|i| seg_seg(p, q, t[i], t[(i + 1) % 3]));
        if n == ZERO {
            return edges(p, q);
        }
        let sp = dot(n, sub(p, t[0]));
        let sq = dot(n, sub(q, t[0]));
        if (sp > 0 && sq > 0) || (sp < 0 && sq < 0) {
            return false;
        }
        if sp == 0 && sq == 0 {
            return in_tri_coplanar(p, t, n) || in_tri_coplanar(q, t, n) || edges(p, q);
        }
        // The crossing point is x / den with x = q sp - p sq, den = sp - sq != 0.
        let den = sp - sq;
        let x = sub(scale(q, sp), scale(p, sq));
        (0..3).all(|i| {
            let e = sub(t[(i + 1) % 3], t[i]);
            let rel = sub(x, scale(t[i], den));
            dot(cross(e, rel), n) * den.signum() >= 0
        })
    }

    pub fn intersect(a: &[P; 3], b: &[P; 3]) -> bool {
        (0..3).any(|i| seg_tri(a[i], a[(i + 1) % 3], b))
            || (0..3).any(|j| seg_tri(b[j], b[(j + 1) % 3], a))
    }
}

/// Brute-force distances by convex one-dimensional searches, sharing no formula with the
/// crate: the distance from a point to a segment (clamped projection) is minimised over one
/// parameter by ternary search, which converges on any convex function. Robust for slivers and
/// (nearly) parallel segments, where closed-form routines lose digits.
mod brute {
    use super::V;

    pub fn point_segment(p: V, a: V, b: V) -> f64 {
        let d = b - a;
        let dd = d.dot(&d);
        let t = if dd > 0.0 {
            ((p - a).dot(&d) / dd).clamp(0.0, 1.0)
        } else {
            0.0
        };
        (p - (a + d * t)).norm()
    }

    /// Minimum of a convex function on [0, 1].
    fn minimise(f: impl Fn(f64) -> f64) -> f64 {
        let (mut lo, mut hi) = (0.0f64, 1.0f64);
        for _ in 0..100 {
            let m1 = lo + (hi - lo) / 3.0;
            let m2 = hi - (hi - lo) / 3.0;
            if f(m1) <= f(m2) {
                hi = m2;
            } else {
                lo = m1;
            }
        }
        f(0.5 * (lo + hi)).min(f(0.0)).min(f(1.0))
    }

    pub fn segment_segment(p1: V, q1: V, p2: V, q2: V) -> f64 {
        minimise(|s| point_segment(p1 + (q1 - p1) * s, p2, q2))
    }

    /// The triangle is the union over u of the segments from v0 + u(v1 - v0) to
    /// v2 + u(v1 - v2); the distance to each is convex in u (a partial minimum of a convex
    /// function of the affine parameters).
    pub fn point_triangle(p: V, t: &[V; 3]) -> f64 {
        minimise(|u| point_segment(p, t[0] + (t[1] - t[0]) * u, t[2] + (t[1] - t[2]) * u))
    }

    /// Distance between disjoint triangles: 9 segment pairs and 6 corner–triangle pairs.
    pub fn separated_distance(a: &[V; 3], b: &[V; 3]) -> f64 {
        let mut d = f64::INFINITY;
        for i in 0..3 {
            for j in 0..3 {
                d = d.min(segment_segment(a[i], a[(i + 1) % 3], b[j], b[(j + 1) % 3]));
            }
            d = d.min(point_triangle(a[i], b));
            d = d.min(point_triangle(b[i], a));
        }
        d
    }
}

/// Floating-point contact where it is clear-cut, written independently of the crate.
mod float {
    use super::V;

    /// Does the segment pq cross the proper triangle t, with every sign deciding it at least
    /// `margin` (relative) away from zero? `None` when some sign is too close to call.
    pub fn clear_segment_crossing(p: V, q: V, t: &[V; 3], margin: f64) -> Option<bool> {
        let n = (t[1] - t[0]).cross(&(t[2] - t[0]));
        let scale = n.norm() * ((p - t[0]).norm() + (q - t[0]).norm() + 1e-300);
        let sp = n.dot(&(p - t[0]));
        let sq = n.dot(&(q - t[0]));
        if sp.abs() < margin * scale || sq.abs() < margin * scale {
            return None;
        }
        if (sp > 0.0) == (sq > 0.0) {
            return Some(false);
        }
        let x = p + (q - p) * (sp / (sp - sq));
        let mut inside = true;
        for i in 0..3 {
            let e = t[(i + 1) % 3] - t[i];
            let s = e.cross(&(x - t[i])).dot(&n);
            let sc = e.norm() * (x - t[i]).norm() * n.norm();
            if s.abs() < margin * sc {
                return None;
            }
            inside &= s > 0.0;
        }
        Some(inside)
    }

    /// Contact decided in floating point where every deciding sign is clear; `None` if not.
    pub fn clear_intersect(a: &[V; 3], b: &[V; 3], margin: f64) -> Option<bool> {
        let mut any = false;
        for (s, o) in [(a, b), (b, a)] {
            for i in 0..3 {
                any |= clear_segment_crossing(s[i], s[(i + 1) % 3], o, margin)?;
            }
        }
        Some(any)
    }
}

// ---------------------------------------------------------------------------------------------
// Invariants checked on every pair.
// ---------------------------------------------------------------------------------------------

/// The largest coordinate magnitude of the pair (at least 1e-300): the scale that bounds
/// rounding errors of points and differences.
fn coord_scale(a: &Triangle, b: &Triangle) -> f64 {
    a.iter()
        .chain(b.iter())
        .map(|p| p.amax())
        .fold(1e-300, f64::max)
}

/// Checks every invariant of the three functions on `(a, b)` and returns the distance result.
fn check_pair(a: &Triangle, b: &Triangle, ctx: &str) -> TriangleDistance {
    let scale = coord_scale(a, b);
    let hit = triangles_intersect(a, b);
    assert_eq!(hit, triangles_intersect(b, a), "{ctx}: intersect symmetric");
    let r = triangle_distance(a, b);
    assert!(
        r.distance.is_finite() && r.distance >= 0.0,
        "{ctx}: distance {r:?}"
    );
    assert!(
        r.point_a
            .iter()
            .chain(r.point_b.iter())
            .all(|x| x.is_finite()),
        "{ctx}: points {r:?}"
    );
    // 0 exactly when the exact test says contact.
    if hit {
        assert_eq!(r.distance, 0.0, "{ctx}: intersecting but distance {r:?}");
        assert_eq!(r.point_a, r.point_b, "{ctx}: contact points differ");
    }
    // Witnesses lie on their triangles and realise the distance.
    let on_tol = 1e-12 * scale;
    let da = brute::point_triangle(r.point_a, a);
    let db = brute::point_triangle(r.point_b, b);
    assert!(da <= on_tol, "{ctx}: point_a off a by {da:e} ({r:?})");
    assert!(db <= on_tol, "{ctx}: point_b off b by {db:e} ({r:?})");
    let realised = (r.point_b - r.point_a).norm();
    assert!(
        (realised - r.distance).abs() <= 1e-14 * scale + 1e-12 * r.distance,
        "{ctx}: |pb - pa| = {realised:e} but distance {:e}",
        r.distance
    );
    // Symmetry, exact: the same distance and the same witnesses, swapped.
    let s = triangle_distance(b, a);
    assert_eq!(s.distance, r.distance, "{ctx}: d(a,b) != d(b,a)");
    assert_eq!(
        (s.point_a, s.point_b),
        (r.point_b, r.point_a),
        "{ctx}: witnesses"
    );
    // Separating plane through the closest points: a certificate of minimality.
    if r.distance > 1e-6 * scale {
        let n = (r.point_b - r.point_a) / realised;
        let a_max = a
            .iter()
            .map(|p| n.dot(&(p - r.point_a)))
            .fold(f64::MIN, f64::max);
        let b_min = b
            .iter()
            .map(|q| n.dot(&(q - r.point_a)))
            .fold(f64::MAX, f64::min);
        let lower_bound = b_min - a_max; // ≤ the true distance
                                         // The plane's normal comes from rounded points: its direction is off by about
                                         // ε·scale/distance, which the extent of the pair turns into a height error.
        let extent = a
            .iter()
            .chain(b.iter())
            .map(|p| (p - r.point_a).norm())
            .fold(0.0, f64::max);
        let tol = 1e-9 * r.distance + 1e-14 * scale * (1.0 + extent / r.distance);
        assert!(
            r.distance - lower_bound <= tol,
            "{ctx}: plane certificate fails: distance {:e}, certified lower bound {lower_bound:e}",
            r.distance
        );
    }
    // Maximum distance: the vertex-pair maximum, witnesses are corners.
    let m = triangle_max_distance(a, b);
    let vmax = a
        .iter()
        .flat_map(|p| b.iter().map(move |q| (q - p).norm()))
        .fold(0.0, f64::max);
    assert_eq!(m.distance, vmax, "{ctx}: max distance");
    assert!(a.contains(&m.point_a) && b.contains(&m.point_b), "{ctx}");
    assert_eq!((m.point_b - m.point_a).norm(), m.distance, "{ctx}");
    assert_eq!(triangle_max_distance(b, a).distance, m.distance, "{ctx}");
    r
}

/// Reference distance: 0 when `reference_hit`, else the brute-force decomposition.
fn check_against_reference(a: &Triangle, b: &Triangle, reference_hit: bool, ctx: &str) {
    let r = check_pair(a, b, ctx);
    let scale = coord_scale(a, b);
    let expected = if reference_hit {
        0.0
    } else {
        brute::separated_distance(a, b)
    };
    let tol = 1e-9 * expected + 1e-13 * scale;
    assert!(
        (r.distance - expected).abs() <= tol,
        "{ctx}: distance {:e}, reference {expected:e} (diff {:e})",
        r.distance,
        r.distance - expected
    );
}

/// Barycentric sample points of a triangle: corners, edge points and interior points.
fn samples(t: &Triangle) -> Vec<V> {
    let n = 6;
    let mut out = Vec::new();
    for i in 0..=n {
        for j in 0..=n - i {
            let (u, w) = (i as f64 / n as f64, j as f64 / n as f64);
            out.push(t[0] + (t[1] - t[0]) * u + (t[2] - t[0]) * w);
        }
    }
    out
}

/// The minimum is below, the maximum above, every sampled pair distance.
fn check_sampled(a: &Triangle, b: &Triangle, ctx: &str) {
    let scale = coord_scale(a, b);
    let lo = triangle_distance(a, b).distance;
    let hi = triangle_max_distance(a, b).distance;
    let tol = 1e-13 * scale;
    for p in samples(a) {
        for q in samples(b) {
            let d = (q - p).norm();
            assert!(lo <= d + tol, "{ctx}: min {lo:e} > sampled {d:e}");
            assert!(hi >= d - tol, "{ctx}: max {hi:e} < sampled {d:e}");
        }
    }
}

// ---------------------------------------------------------------------------------------------
// Hand-built cases.
// ---------------------------------------------------------------------------------------------

/// All orderings of a triangle's corners (rotations and reflections).
fn orderings(t: &Triangle) -> [Triangle; 6] {
    let [p, q, r] = *t;
    [
        [p, q, r],
        [q, r, p],
        [r, p, q],
        [p, r, q],
        [r, q, p],
        [q, p, r],
    ]
}

fn map(t: &Triangle, f: impl Fn(V) -> V) -> Triangle {
    [f(t[0]), f(t[1]), f(t[2])]
}

/// The similarity transforms `(scale, offset)` every hand-built case is checked under.
const TRANSFORMS: [(f64, f64); 6] = [
    (1.0, 0.0),
    (1e3, 0.0),
    (1.0 / 1024.0, 0.0),
    (1e-3, 0.0),
    (1.0, 1e6),
    (1e3, 1e6),
];

/// The rounding error of `a + b` (Knuth's TwoSum), zero iff the sum is exact.
fn two_sum_err(a: f64, b: f64) -> f64 {
    let s = a + b;
    let bb = s - a;
    (a - (s - bb)) + (b - bb)
}

/// Is `p * scale + offset` computed without rounding for every coordinate of `t`? Then the
/// transformed pair is an exact similarity image and touching stays touching.
fn transform_is_exact(t: &Triangle, scale: f64, offset: f64) -> bool {
    t.iter().flat_map(|p| p.iter()).all(|&x| {
        let q = x * scale;
        x.mul_add(scale, -q) == 0.0 && two_sum_err(q, offset) == 0.0
    })
}

/// Checks a hand-built case with a known answer, in every corner ordering, both argument
/// orders and under [`TRANSFORMS`]. `distance` is the expected distance at scale 1.
fn expect(name: &str, a: Triangle, b: Triangle, hit: bool, distance: f64) {
    assert_eq!(hit, distance == 0.0, "{name}: inconsistent expectation");
    for (scale, offset) in TRANSFORMS {
        let exact = transform_is_exact(&a, scale, offset) && transform_is_exact(&b, scale, offset);
        let f = |p: V| p * scale + V::repeat(offset);
        let (ta, tb) = (map(&a, f), map(&b, f));
        for (i, oa) in orderings(&ta).iter().enumerate() {
            for (j, ob) in orderings(&tb).iter().enumerate() {
                let ctx = format!("{name} [scale {scale:e} offset {offset:e} orders {i},{j}]");
                let r = check_pair(oa, ob, &ctx);
                let coord = coord_scale(oa, ob);
                let want = distance * scale;
                if exact || !(0.0..1e-6).contains(&distance) {
                    assert_eq!(triangles_intersect(oa, ob), hit, "{ctx}: intersect");
                }
                let tol = 1e-12 * want + 1e-14 * coord;
                assert!(
                    (r.distance - want).abs() <= tol,
                    "{ctx}: distance {:e}, expected {want:e}",
                    r.distance
                );
            }
        }
        check_sampled(&ta, &tb, name);
    }
}

fn unit() -> Triangle {
    t([0., 0., 0.], [1., 0., 0.], [0., 1., 0.])
}

#[test]
fn crossing_triangles() {
    // b stands vertically through a's interior.
    let b = t([0.25, 0.25, -1.], [0.25, 0.25, 1.], [0.25, -1., 0.]);
    expect("crossing", unit(), b, true, 0.0);
    // Two triangles linked like chain links (each pierces the other).
    let a = t([0., 0., 0.], [2., 0., 0.], [1., 2., 0.]);
    let b = t([1., 1., -1.], [1., 1., 1.], [1., -1., 0.5]);
    expect("linked", a, b, true, 0.0);
}

#[test]
fn parallel_disjoint_at_half() {
    let b = map(&unit(), |p| p + v(0.1, 0.1, 0.5));
    expect("parallel gap 0.5", unit(), b, false, 0.5);
    // Mirrored and overlapping in projection.
    let b = t([1., 1., 0.5], [-0.5, 0.5, 0.5], [0.5, -0.5, 0.5]);
    expect("parallel gap 0.5 rotated", unit(), b, false, 0.5);
}

#[test]
fn coplanar_cases() {
    let a = unit();
    // Overlapping (crossing edges).
    expect(
        "coplanar overlap",
        a,
        t([0.25, 0.25, 0.], [2., 0.25, 0.], [0.25, 2., 0.]),
        true,
        0.0,
    );
    // One contains the other (no boundary contact).
    expect(
        "coplanar containment",
        a,
        t([0.125, 0.125, 0.], [0.5, 0.125, 0.], [0.125, 0.5, 0.]),
        true,
        0.0,
    );
    // Disjoint, gap in the plane along x.
    expect(
        "coplanar gap",
        a,
        t([1.5, 0., 0.], [3., 0., 0.], [1.5, 1., 0.]),
        false,
        0.5,
    );
    // Disjoint, gap across the hypotenuse: b's corner (1, 1) is 1/√2 from x + y = 1.
    let d = 0.5f64.sqrt();
    expect(
        "coplanar diagonal gap",
        a,
        t([1., 1., 0.], [2., 1., 0.], [1., 2., 0.]),
        false,
        d,
    );
    // Touching at a single corner.
    expect(
        "coplanar corner-corner",
        a,
        t([1., 0., 0.], [2., 0., 0.], [2., 1., 0.]),
        true,
        0.0,
    );
    // A corner of b on the hypotenuse of a.
    expect(
        "coplanar corner-edge",
        a,
        t([0.5, 0.5, 0.], [1., 1., 0.], [2., 0.5, 0.]),
        true,
        0.0,
    );
    // Sharing an edge (adjacent mesh triangles).
    expect(
        "coplanar shared edge",
        a,
        t([1., 0., 0.], [0., 1., 0.], [1., 1., 0.]),
        true,
        0.0,
    );
    // Partially overlapping collinear edges.
    expect(
        "coplanar collinear edges",
        a,
        t([0.5, 0., 0.], [2., 0., 0.], [1., -1., 0.]),
        true,
        0.0,
    );
    // Collinear edges with a gap.
    expect(
        "coplanar collinear gap",
        a,
        t([1.25, 0., 0.], [2., 0., 0.], [1.5, -1., 0.]),
        false,
        0.25,
    );
}

#[test]
fn shared_corner_and_edge() {
    let a = unit();
    // A fan around the origin, out of plane.
    expect(
        "shared corner",
        a,
        t([0., 0., 0.], [-1., 0., 1.], [0., -1., 1.]),
        true,
        0.0,
    );
    // Hinged along the x axis.
    expect(
        "hinged edge",
        a,
        t([0., 0., 0.], [1., 0., 0.], [0.5, -1., 1.]),
        true,
        0.0,
    );
    expect(
        "folded edge",
        a,
        t([1., 0., 0.], [0., 0., 0.], [0.5, 0.5, 1.]),
        true,
        0.0,
    );
}

#[test]
fn piercing_and_touching() {
    let a = unit();
    // An edge of b pierces a's interior (b is otherwise far).
    expect(
        "edge pierces face",
        a,
        t([0.25, 0.25, -1.], [0.25, 0.25, 1.], [3., 3., 0.5]),
        true,
        0.0,
    );
    // An edge of b crosses an edge of a at one point (b in the plane x = 0.5, below y = 0).
    expect(
        "edge crosses edge",
        a,
        t([0.5, -1., 1.], [0.5, 1., -1.], [0.5, -3., 0.]),
        true,
        0.0,
    );
    // Same, b slanted: it meets a only at (0.5, 0, 0).
    expect(
        "edge crosses edge slanted",
        a,
        t([0.5, -1., 1.], [0.5, 1., -1.], [1., -2., 0.5]),
        true,
        0.0,
    );
    // A corner of b exactly on a's interior, the rest above.
    expect(
        "corner on face",
        a,
        t([0.25, 0.25, 0.], [1., 1., 1.], [0., 1., 2.]),
        true,
        0.0,
    );
    // A corner of b exactly on an edge of a.
    expect(
        "corner on edge",
        a,
        t([0.5, 0., 0.], [1., -1., 1.], [0., -1., 2.]),
        true,
        0.0,
    );
    // An edge of b lying on a's face (b standing on it).
    expect(
        "edge on face",
        a,
        t([0.125, 0.25, 0.], [0.5, 0.25, 0.], [0.25, 0.25, 1.]),
        true,
        0.0,
    );
    // An edge of b in a's plane, on the line of an edge of a: overlapping, touching at a
    // corner, apart; and in the plane beside a corner.
    expect(
        "in-plane edge overlaps edge",
        a,
        t([0.5, 0., 0.], [2., 0., 0.], [1., 1., 1.]),
        true,
        0.0,
    );
    expect(
        "in-plane edge at corner",
        a,
        t([1., 0., 0.], [3., 0., 0.], [2., 1., 1.]),
        true,
        0.0,
    );
    expect(
        "in-plane edge apart",
        a,
        t([2., 0., 0.], [3., 0., 0.], [2.5, 1., 1.]),
        false,
        1.0,
    );
    expect(
        "in-plane edge beside",
        a,
        t([1., 0.5, 0.], [2., 0.5, 0.], [1.5, 1., -1.]),
        false,
        0.5f64.sqrt() * 0.5,
    );
    // Found by the grid property test against a mutant: b's edge in a's plane, on the line
    // through a corner of a, apart from it (closest: two skew edges, 1/√14 apart).
    let g = t([0., -1., 1.], [-1., -1., 0.], [2., -1., -1.]);
    let d = 1.0 / 14f64.sqrt();
    expect(
        "in-plane edge toward corner",
        g,
        t([0., -1., -1.], [0., 0., 0.], [1., -1., -1.]),
        false,
        d,
    );
}

#[test]
fn degenerate_triangles() {
    let a = unit();
    // A segment (repeated corner) crossing a.
    expect(
        "segment crosses",
        a,
        t([0.25, 0.25, -1.], [0.25, 0.25, 1.], [0.25, 0.25, 1.]),
        true,
        0.0,
    );
    // A segment as three collinear corners (middle corner outside the order).
    expect(
        "collinear crosses",
        a,
        t([0.25, 0.25, 1.], [0.25, 0.25, -1.], [0.25, 0.25, 0.5]),
        true,
        0.0,
    );
    // A segment ending exactly on a's face.
    expect(
        "segment ends on face",
        a,
        t([0.25, 0.25, 0.], [0.25, 0.25, 1.], [0.25, 0.25, 0.5]),
        true,
        0.0,
    );
    // A segment above a.
    expect(
        "segment above",
        a,
        t([0.25, 0.25, 0.75], [0.25, 0.25, 1.], [0.25, 0.25, 3.]),
        false,
        0.75,
    );
    // A segment lying in a's plane crossing its edge, and one outside it.
    expect(
        "segment in plane",
        a,
        t([0.5, -1., 0.], [0.5, 1., 0.], [0.5, 1., 0.]),
        true,
        0.0,
    );
    expect(
        "segment in plane apart",
        a,
        t([2., -1., 0.], [2., 1., 0.], [2., 0., 0.]),
        false,
        1.0,
    );
    // A point on a's interior, on its edge, at a corner, and above.
    let pt = |x, y, z| t([x, y, z], [x, y, z], [x, y, z]);
    expect("point on face", a, pt(0.25, 0.25, 0.), true, 0.0);
    expect("point on edge", a, pt(0.5, 0.5, 0.), true, 0.0);
    expect("point at corner", a, pt(0., 1., 0.), true, 0.0);
    expect("point above", a, pt(0.25, 0.25, 0.5), false, 0.5);
    expect("point beside", a, pt(-0.5, 0.5, 0.), false, 0.5);
    // Both degenerate: crossing segments, skew segments, touching points.
    let seg = |p: [f64; 3], q: [f64; 3]| t(p, q, q);
    expect(
        "segments cross",
        seg([0., 0., 0.], [1., 1., 0.]),
        seg([0., 1., 0.], [1., 0., 0.]),
        true,
        0.0,
    );
    expect(
        "segments skew",
        seg([0., 0., 0.], [1., 1., 0.]),
        seg([0., 1., 0.5], [1., 0., 0.5]),
        false,
        0.5,
    );
    expect(
        "segments collinear touch",
        seg([0., 0., 0.], [1., 1., 1.]),
        seg([1., 1., 1.], [2., 2., 2.]),
        true,
        0.0,
    );
    let d = 3f64.sqrt();
    expect(
        "segments collinear gap",
        seg([0., 0., 0.], [1., 1., 1.]),
        seg([2., 2., 2.], [3., 3., 3.]),
        false,
        d,
    );
    expect(
        "segments parallel",
        seg([0., 0., 0.], [2., 0., 0.]),
        seg([1., 0.75, 0.], [3., 0.75, 0.]),
        false,
        0.75,
    );
    expect(
        "points equal",
        pt(0.5, 0.25, 1.),
        pt(0.5, 0.25, 1.),
        true,
        0.0,
    );
    expect(
        "points apart",
        pt(0.5, 0.25, 1.),
        pt(0.5, 0.25, 1.5),
        false,
        0.5,
    );
    expect(
        "point on segment",
        pt(0.5, 0.5, 0.5),
        seg([0., 0., 0.], [1., 1., 1.]),
        true,
        0.0,
    );
}

#[test]
fn nearly_touching() {
    let a = unit();
    for k in 1..=12 {
        let g = 10f64.powi(-k);
        let name = format!("gap 1e-{k}");
        // A corner of b just above a's interior.
        expect(
            &format!("{name} corner-face"),
            a,
            t([0.25, 0.25, g], [1., 1., 1.], [0., 1., 2.]),
            false,
            g,
        );
        // Skew edges passing at distance g (closest points interior to both edges).
        expect(
            &format!("{name} edge-edge"),
            a,
            t([0.5, -g, -1.], [0.5, -g, 1.], [0.5, -1., 0.]),
            false,
            g,
        );
        // An edge of b parallel to a's face, at height g above it.
        expect(
            &format!("{name} edge-face"),
            a,
            t([0.5, -1., g], [0.5, 1., g], [0.5, 0., 2.]),
            false,
            g,
        );
        // Parallel faces.
        expect(
            &format!("{name} face-face"),
            a,
            map(&a, |p| p + v(0.25, 0.25, g)),
            false,
            g,
        );
        // Coplanar, gap in the plane.
        expect(
            &format!("{name} coplanar"),
            a,
            t([1. + g, 0., 0.], [2., 0., 0.], [2., 1., 0.]),
            false,
            g,
        );
        // A corner just beside an edge (out of plane).
        expect(
            &format!("{name} corner-edge"),
            a,
            t([0.5, -g, 0.], [0.5, -1., 1.], [0.5, -1., -1.]),
            false,
            g,
        );
    }
}

/// Offsetting a tiny gap to 1e6 rounds it: the expectation follows the represented numbers.
#[test]
fn nearly_touching_far_from_origin() {
    for k in 1..=12 {
        let g = 10f64.powi(-k);
        let o = 1e6;
        let a = map(&unit(), |p| p + V::repeat(o));
        let b = t(
            [o + 0.25, o + 0.25, o + g],
            [o + 1., o + 1., o + 1.],
            [o, o + 1., o + 2.],
        );
        let gap = (o + g) - o; // exact: what the coordinates actually say
        let r = check_pair(&a, &b, &format!("offset gap 1e-{k}"));
        assert_eq!(triangles_intersect(&a, &b), gap == 0.0);
        assert!((r.distance - gap).abs() <= 1e-12 * gap + 1e-14 * o);
        assert!(
            (r.distance - gap).abs() <= 1e-9 * g + 1e-16 * o,
            "k={k}: {r:?}"
        );
    }
}

#[test]
fn exact_on_non_dyadic_coordinates() {
    // Shared corners and edges are contact whatever the coordinates.
    let a = t([0.1, 0.2, 0.3], [1.7, -0.3, 0.9], [0.4, 1.1, -0.6]);
    let b = t([0.1, 0.2, 0.3], [-1.3, 0.7, 0.2], [0.3, -0.9, -1.1]);
    assert!(triangles_intersect(&a, &b));
    let b = t([1.7, -0.3, 0.9], [0.4, 1.1, -0.6], [2.3, 1.9, 0.7]);
    assert!(triangles_intersect(&a, &b));
    assert_eq!(triangle_distance(&a, &b).distance, 0.0);
}

/// Scaling by a power of two is exact, so contact and the (scaled) distance must not change,
/// from subnormal-adjacent to overflow-adjacent magnitudes, on either side of the origin.
#[test]
fn power_of_two_scales_change_nothing() {
    let pairs = [
        (unit(), t([0.25, 0.25, 0.], [1., 1., 1.], [0., 1., 2.])),
        (unit(), t([0.25, 0.25, 1e-9], [1., 1., 1.], [0., 1., 2.])),
        (unit(), t([0.5, -1., 1.], [0.5, 1., -1.], [0.5, -3., 0.])),
        (
            unit(),
            t([0.5, -1e-9, -1.], [0.5, -1e-9, 1.], [0.5, -1., 0.]),
        ),
        (unit(), map(&unit(), |p| p + v(0.25, 0.25, 0.5))),
        (unit(), t([1., 1., 0.], [2., 1., 0.], [1., 2., 0.])),
        (
            t([0., 0., 0.], [1., 1., 1.], [1., 1., 1.]),
            t([0., 1., 0.5], [1., 0., 0.5], [1., 0., 0.5]),
        ),
    ];
    for (a, b) in pairs {
        let hit = triangles_intersect(&a, &b);
        let d = triangle_distance(&a, &b).distance;
        let scales = [-1000, -600, -200, -64, 64, 200, 600, 1000].map(|k| 2f64.powi(k));
        for s in scales.into_iter().flat_map(|s| [s, -s]) {
            let (sa, sb) = (map(&a, |p| p * s), map(&b, |p| p * s));
            assert_eq!(triangles_intersect(&sa, &sb), hit, "{s:e}");
            let r = triangle_distance(&sa, &sb);
            assert!(
                (r.distance - d * s.abs()).abs() <= 1e-12 * d * s.abs(),
                "{s:e}: {r:?} vs {d:e}"
            );
            let on = |p: V, t: &Triangle| brute::point_triangle(p / s, &map(t, |q| q / s));
            assert!(
                on(r.point_a, &sa) <= 1e-12 && on(r.point_b, &sb) <= 1e-12,
                "{s:e}"
            );
        }
    }
}

/// Near the ends of the f64 range nothing panics and nothing is NaN.
#[test]
fn extreme_magnitudes_never_nan() {
    let shapes = [
        unit(),
        t([0., 0., 0.], [1., 1., 1.], [2., 2., 2.]),
        t([0.5, 0.5, 0.5], [0.5, 0.5, 0.5], [0.5, 0.5, 0.5]),
        t([-1., 0.25, 3.], [2., -1., 0.5], [0.125, 4., -2.]),
    ];
    for scale in [
        1e-300,
        1e-160,
        1e-80,
        1e80,
        1e150,
        1e200,
        1e300,
        f64::MAX / 8.0,
    ] {
        for sa in &shapes {
            for sb in &shapes {
                for shift in [0.0, 0.5, -2.0] {
                    let a = map(sa, |p| p * scale);
                    let b = map(sb, |p| (p + V::repeat(shift)) * scale);
                    assert!(a
                        .iter()
                        .chain(b.iter())
                        .all(|p| p.iter().all(|x| x.is_finite())));
                    let _ = triangles_intersect(&a, &b);
                    for r in [triangle_distance(&a, &b), triangle_max_distance(&a, &b)] {
                        assert!(
                            !r.distance.is_nan() && r.distance >= 0.0,
                            "{scale:e}: {r:?}"
                        );
                        assert!(
                            !r.point_a.iter().chain(r.point_b.iter()).any(|x| x.is_nan()),
                            "{scale:e}: {r:?}"
                        );
                    }
                }
            }
        }
    }
}

/// Pairs with no spread (every corner one point) scaled as far as their reach allows: the
/// witnesses come back where the point is (a single factor of 2^e once rounded them to 0).
#[test]
fn a_pair_of_one_point_far_below_unit_size_keeps_its_witnesses() {
    for x in [1e-270, 1e-300, 5e-324] {
        let a = [v(x, 0.0, 0.0); 3];
        let r = triangle_distance(&a, &a);
        assert_eq!(
            (r.distance, r.point_a, r.point_b),
            (0.0, a[0], a[0]),
            "{x:e}"
        );
        assert!(triangles_intersect(&a, &a), "{x:e}");
    }
}

/// Regression: a corner at infinity (an unverified, damaged file, or a pose that overflows
/// huge coordinates) used to make both primitives rescale by 2^-inf and call themselves for
/// ever (a stack overflow). Infinite pairs do not touch and are infinitely far apart; NaN
/// corners give some answer, but always return.
#[test]
fn non_finite_corners_terminate() {
    let inf = f64::INFINITY;
    for bad in [inf, -inf, f64::NAN] {
        for corner in 0..3 {
            for axis in 0..3 {
                let mut a = unit();
                a[corner][axis] = bad;
                let b = unit();
                for (x, y) in [(&a, &b), (&b, &a)] {
                    let hit = triangles_intersect(x, y);
                    let d = triangle_distance(x, y);
                    let _ = triangle_max_distance(x, y);
                    if bad.is_infinite() {
                        assert!(!hit, "{bad} at corner {corner} axis {axis}");
                        assert_eq!(d.distance, inf, "{bad} at corner {corner} axis {axis}");
                    }
                }
            }
        }
    }
}

#[test]
fn max_distance_known() {
    let a = unit();
    let b = map(&a, |p| p + v(0., 0., 2.));
    let m = triangle_max_distance(&a, &b);
    assert_eq!(m.distance, 6f64.sqrt()); // (1,0,0) to (0,1,2)
    assert_eq!((m.point_b - m.point_a).norm(), m.distance);
    let m = triangle_max_distance(&a, &a);
    assert_eq!(m.distance, 2f64.sqrt());
}

// ---------------------------------------------------------------------------------------------
// Property tests (fixed seed, no persistence files).
// ---------------------------------------------------------------------------------------------

fn config(cases: u32) -> ProptestConfig {
    ProptestConfig {
        cases,
        rng_seed: RngSeed::Fixed(0x0bb7_7ee5),
        failure_persistence: None,
        ..ProptestConfig::default()
    }
}

type ITri = [[i64; 3]; 3];

fn grid_point(r: i64) -> impl Strategy<Value = [i64; 3]> {
    prop::array::uniform3(-r..=r)
}

/// Integer triangles, a third of them degenerate (repeated or collinear corners).
fn grid_triangle(r: i64) -> impl Strategy<Value = ITri> {
    prop_oneof![
        4 => prop::array::uniform3(grid_point(r)),
        1 => (grid_point(r), grid_point(r), -1i64..=2).prop_map(|(p, q, k)| {
            [p, q, [0, 1, 2].map(|c| p[c] + (q[c] - p[c]) * k)]
        }),
        1 => grid_point(r).prop_map(|p| [p, p, p]),
    ]
}

/// Exact maps of the grid: a positive power-of-two scale and an integer offset.
const GRID_MAPS: [(f64, f64); 4] = [
    (1.0, 0.0),
    (1.0 / 1024.0, 0.0),
    (1024.0, 0.0),
    (1.0 / 8.0, 1e6),
];

fn to_f64(t: &ITri, (s, o): (f64, f64)) -> Triangle {
    t.map(|p| V::new(p[0] as f64, p[1] as f64, p[2] as f64) * s + V::repeat(o))
}

fn to_i128(t: &ITri) -> [exact::P; 3] {
    t.map(|p| p.map(|c| c as i128))
}

fn float_point(r: f64) -> impl Strategy<Value = V> {
    prop::array::uniform3(-r..r).prop_map(V::from)
}

fn float_triangle(r: f64) -> impl Strategy<Value = Triangle> {
    prop::array::uniform3(float_point(r))
}

fn check_grid(a: &ITri, b: &ITri) {
    let want = exact::intersect(&to_i128(a), &to_i128(b));
    for m in GRID_MAPS {
        let (fa, fb) = (to_f64(a, m), to_f64(b, m));
        let ctx = format!("grid {a:?} {b:?} map {m:?}");
        assert_eq!(
            triangles_intersect(&fa, &fb),
            want,
            "{ctx}: contact vs exact oracle"
        );
        check_against_reference(&fa, &fb, want, &ctx);
    }
}

proptest! {
    #![proptest_config(config(4000))]

    /// Tiny and small grids: many exact touchings, coplanar pairs and degenerate triangles.
    #[test]
    fn grid_tiny_matches_exact_oracle(a in grid_triangle(1), b in grid_triangle(1)) {
        check_grid(&a, &b);
    }

    #[test]
    fn grid_small_matches_exact_oracle(a in grid_triangle(2), b in grid_triangle(2)) {
        check_grid(&a, &b);
    }

    #[test]
    fn grid_large_matches_exact_oracle(a in grid_triangle(40), b in grid_triangle(40)) {
        check_grid(&a, &b);
    }

    /// Coplanar grid pairs: both triangles in the plane z = 0 or in a slanted plane.
    #[test]
    fn grid_coplanar_matches_exact_oracle(
        a in prop::array::uniform3(prop::array::uniform2(-3i64..=3)),
        b in prop::array::uniform3(prop::array::uniform2(-3i64..=3)),
        slant in prop::array::uniform2(-2i64..=2),
    ) {
        let lift = |t: [[i64; 2]; 3]| t.map(|[x, y]| [x, y, slant[0] * x + slant[1] * y]);
        check_grid(&lift(a), &lift(b));
    }
}

proptest! {
    #![proptest_config(config(3000))]

    /// Random float pairs: contact agrees with a floating-point crossing test wherever that
    /// test is clear; distance agrees with the brute-force decomposition.
    #[test]
    fn random_pairs_match_reference(a in float_triangle(1.0), b in float_triangle(1.0),
                                    scale in prop::sample::select(vec![1.0, 1e-3, 1e3]),
                                    offset in prop::sample::select(vec![0.0, 1e6])) {
        let f = |p: V| p * scale + V::repeat(offset);
        let (a, b) = (map(&a, f), map(&b, f));
        let clear = float::clear_intersect(&a, &b, 1e-9);
        let hit = triangles_intersect(&a, &b);
        if let Some(c) = clear {
            prop_assert_eq!(hit, c);
        }
        check_against_reference(&a, &b, hit, "random");
        check_sampled(&a, &b, "random");
    }

    /// Pairs built to cross: a common point interior to both, planes transversal.
    #[test]
    fn constructed_crossings_intersect(a in float_triangle(1.0),
                                       bary in prop::array::uniform2(0.1f64..0.4),
                                       u in float_point(1.0), w in float_point(1.0)) {
        let n = (a[1] - a[0]).cross(&(a[2] - a[0]));
        prop_assume!(n.norm() > 1e-2 && u.cross(&w).norm() > 1e-2);
        prop_assume!(u.cross(&w).normalize().cross(&n.normalize()).norm() > 0.1);
        let x = a[0] + (a[1] - a[0]) * bary[0] + (a[2] - a[0]) * bary[1];
        let b = [x + u, x + w, x - (u + w)];
        prop_assert!(triangles_intersect(&a, &b));
        let r = check_pair(&a, &b, "constructed crossing");
        prop_assert_eq!(r.distance, 0.0);
    }

    /// Pairs built apart: a separating plane with a known gap bounds the distance below.
    #[test]
    fn constructed_separations(a in float_triangle(1.0), b in float_triangle(1.0),
                               dir in float_point(1.0), gap in 1e-9f64..1.0) {
        prop_assume!(dir.norm() > 1e-3);
        let n = dir.normalize();
        let a_max = a.iter().map(|p| n.dot(p)).fold(f64::MIN, f64::max);
        let b_min = b.iter().map(|p| n.dot(p)).fold(f64::MAX, f64::min);
        let b = map(&b, |p| p + n * (a_max - b_min + gap));
        let r = check_pair(&a, &b, "constructed separation");
        prop_assert!(!triangles_intersect(&a, &b));
        prop_assert!(r.distance >= gap * (1.0 - 1e-9) - 1e-14, "{} < {}", r.distance, gap);
        check_against_reference(&a, &b, false, "constructed separation");
    }

    /// Shared corners and shared edges are contact on any coordinates.
    #[test]
    fn shared_features_touch(a in float_triangle(1e3), p in float_point(1e3), q in float_point(1e3),
                             i in 0usize..3, j in 0usize..3) {
        let corner = {
            let mut b = [p, q, a[i] * 0.5 + p * 0.5];
            b[j] = a[i];
            b
        };
        prop_assert!(triangles_intersect(&a, &corner));
        prop_assert_eq!(triangle_distance(&a, &corner).distance, 0.0);
        check_pair(&a, &corner, "shared corner");
        let edge = [a[i], a[(i + 1) % 3], p];
        prop_assert!(triangles_intersect(&a, &edge));
        check_pair(&a, &edge, "shared edge");
    }

    /// Nearly degenerate (sliver) and nearly parallel configurations.
    #[test]
    fn slivers_and_near_parallel(a in float_triangle(1.0), b in float_triangle(1.0),
                                 eps_a in prop::sample::select(vec![0.0, 1e-14, 1e-9, 1e-5]),
                                 eps_b in prop::sample::select(vec![0.0, 1e-14, 1e-9, 1e-5])) {
        // Pull a's third corner onto (almost) the line of its first two; make b a sliver
        // along a direction parallel to a's first edge (nearly parallel edge pairs).
        let a = [a[0], a[1], a[0] + (a[1] - a[0]) * 0.3 + (a[2] - a[0]) * eps_a];
        let d = a[1] - a[0];
        let b = [b[0], b[0] + d * 0.8, b[0] + d * 0.3 + (b[2] - b[0]) * eps_b];
        let hit = triangles_intersect(&a, &b);
        check_against_reference(&a, &b, hit, "sliver");
        check_sampled(&a, &b, "sliver");
    }
}
