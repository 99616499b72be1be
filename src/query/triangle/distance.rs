//! Minimum and maximum distance between two closed triangles, with witness points.

use super::overlap::{aabb_overlap, intersect_with_planes};
use super::predicates::{in_range, reach_and_spread, rescale, scale_back, PlaneSide};
use super::{Triangle, TriangleDistance};
use nalgebra::Vector3;

type V = Vector3<f64>;

/// Exact minimum distance between two closed triangles, with a closest pair of points.
///
/// - **Contact:** when the triangles intersect — decided exactly by
///   [`triangles_intersect`](super::triangles_intersect), the closed-set rule — the distance
///   is exactly `0.0` and `point_a == point_b` is a common point, computed as closely as f64
///   allows (within a few ulps of both triangles). Conversely a positive distance means the
///   exact test found no contact.
/// - **Disjoint:** the distance is the minimum of the classic decomposition (PQP's TriDist):
///   the nine edge–edge segment distances and the six corner–face distances. Two certified
///   early exits answer almost every pair cheaply (corner–face when one triangle lies on one
///   side of the other's plane, edge–edge when the slab between the two closest edge points
///   separates the triangles); the full decomposition answers the rest. Segment closest points
///   use the cross-product form of the line–line solution (no `a e - b²` cancellation) with
///   Ericson's clamping; parallel and zero-length edges are handled; degenerate triangles
///   (segments, points) are covered by their edges.
/// - **Witnesses:** `point_a` lies on `a` and `point_b` on `b` up to the rounding of one
///   convex combination of corners. The distance itself is computed from local coordinate
///   differences, so it stays accurate far from the origin; `|point_b - point_a|` equals it up
///   to the rounding of the points' coordinates.
/// - **Symmetric:** `triangle_distance(b, a)` returns the same distance bit for bit, with the
///   witnesses swapped.
///
/// Never NaN and never panics for finite inputs (pairs whose largest coordinate, or largest
/// difference of coordinates along an axis, lies outside 1e-60..1e60 are solved scaled by
/// a power of two; the distance may then overflow to
/// infinity near `f64::MAX`); a pair with an infinite corner is at infinite distance. It
/// always terminates and needs no allocation.
#[inline]
pub fn triangle_distance(a: &Triangle, b: &Triangle) -> TriangleDistance {
    let (reach, spread) = reach_and_spread(a, b);
    if !(in_range(reach) && in_range(spread)) {
        // A pair with an infinite corner (a damaged, unverified file, or a pose that
        // overflows) is infinitely far apart; it has no scale.
        if !reach.is_finite() {
            return TriangleDistance {
                distance: f64::INFINITY,
                point_a: a[0],
                point_b: b[0],
            };
        }
        return distance_rescaled(a, b, reach, spread);
    }
    distance_in_range(a, b)
}

/// [`triangle_distance`] of a pair in range, or as far into it as scaling brings it.
#[inline(always)]
fn distance_in_range(a: &Triangle, b: &Triangle) -> TriangleDistance {
    // Which pair of witnesses answers first depends on the argument order; solving in a
    // canonical order makes the result exactly symmetric: d(a, b) == d(b, a) bit for bit.
    if precedes(b, a) {
        let r = distance_ordered(b, a);
        return TriangleDistance {
            distance: r.distance,
            point_a: r.point_b,
            point_b: r.point_a,
        };
    }
    distance_ordered(a, b)
}

/// Coordinates or differences so large (or small) that products of differences would
/// overflow (or underflow): solve the pair scaled by a power of two, scale back.
#[cold]
#[inline(never)]
fn distance_rescaled(a: &Triangle, b: &Triangle, reach: f64, spread: f64) -> TriangleDistance {
    let (a, b, e) = rescale(a, b, reach, spread);
    let r = distance_in_range(&a, &b);
    let back = |x: V| x.map(|c| scale_back(c, e));
    TriangleDistance {
        distance: scale_back(r.distance, e),
        point_a: back(r.point_a),
        point_b: back(r.point_b),
    }
}

/// Lexicographic order on the corner coordinates (total on finite inputs).
#[inline(always)]
// why: corner and coordinate numbers in 0..3 on fixed-size triangles; the iterator form
// was measurably slower in distance queries.
#[allow(clippy::indexing_slicing)]
fn precedes(a: &Triangle, b: &Triangle) -> bool {
    for i in 0..3 {
        for k in 0..3 {
            if a[i][k] != b[i][k] {
                return a[i][k] < b[i][k];
            }
        }
    }
    false
}

#[inline(always)]
fn distance_ordered(a: &Triangle, b: &Triangle) -> TriangleDistance {
    let fa = Prepared::new(a);
    let fb = Prepared::new(b);
    if aabb_overlap(a, b) && intersect_with_planes(a, b, &fa.plane, &fb.plane) {
        return contact(&fa, &fb);
    }
    let best = separated(&fa, &fb);
    TriangleDistance {
        distance: best.d2.sqrt(),
        point_a: best.pa,
        point_b: best.pb,
    }
}

/// Maximum distance between two closed triangles: the largest of the nine corner-to-corner
/// distances (a convex function attains its maximum over a pair of polytopes at vertices),
/// with the two corners as witnesses. Ties go to the first pair in `a`-major order.
#[inline]
pub fn triangle_max_distance(a: &Triangle, b: &Triangle) -> TriangleDistance {
    let [a0, ..] = a;
    let [b0, ..] = b;
    let mut best = (-1.0, a0, b0);
    for p in a {
        for q in b {
            let d2 = (q - p).norm_squared();
            if d2 > best.0 {
                best = (d2, p, q);
            }
        }
    }
    let (d2, p, q) = best;
    TriangleDistance {
        // `max(0)` keeps an overflowing (infinite) or NaN-free result sane.
        distance: d2.max(0.0).sqrt(),
        point_a: *p,
        point_b: *q,
    }
}

/// A triangle with the quantities every candidate needs.
struct Prepared<'t> {
    v: &'t Triangle,
    /// The plane (exact side tests) and its normal `n`.
    plane: PlaneSide,
    /// `e[i] = v[i + 1] - v[i]`.
    e: [V; 3],
    /// `|e[i]|²`.
    ee: [f64; 3],
    /// `(v1 - v0) × (v2 - v0)`.
    n: V,
    /// `|n|²`; zero for a degenerate triangle.
    nn: f64,
}

impl<'t> Prepared<'t> {
    #[inline(always)]
    fn new(v: &'t Triangle) -> Self {
        let plane = PlaneSide::new(v);
        let e = [plane.e1, v[2] - v[1], -plane.e2];
        let n = plane.n;
        Prepared {
            v,
            plane,
            e,
            ee: [
                e[0].norm_squared(),
                e[1].norm_squared(),
                e[2].norm_squared(),
            ],
            nn: n.norm_squared(),
            n,
        }
    }

    /// Corner `i`. Corner and edge numbers are always 0, 1 or 2 (loop counters, `argmin3`,
    /// and their cyclic successors), so the lookups of these three accessors never fail.
    #[inline(always)]
    // why: `i < 3` at every call (see above); the triangle code's one computed index.
    #[allow(clippy::indexing_slicing)]
    fn corner(&self, i: usize) -> &V {
        &self.v[i]
    }

    /// Edge `i`, `v[i + 1] - v[i]` (`i < 3`, see [`Prepared::corner`]).
    #[inline(always)]
    // why: `i < 3` at every call, see `corner`.
    #[allow(clippy::indexing_slicing)]
    fn edge(&self, i: usize) -> &V {
        &self.e[i]
    }

    /// `|edge(i)|²` (`i < 3`, see [`Prepared::corner`]).
    #[inline(always)]
    // why: `i < 3` at every call, see `corner`.
    #[allow(clippy::indexing_slicing)]
    fn edge_len2(&self, i: usize) -> f64 {
        self.ee[i]
    }

    /// The closest point to `p` on edge `i` (from `v[i]` to `v[i + 1]`) as its parameter
    /// `r` in `[0, 1]`, and that point minus `p` computed from local differences (accurate even
    /// far from the origin).
    #[inline(always)]
    fn edge_param(&self, i: usize, p: &V) -> (f64, V) {
        let w = p - self.corner(i);
        let e = self.edge(i);
        let t = w.dot(e);
        if t <= 0.0 {
            (0.0, -w)
        } else if t >= self.edge_len2(i) {
            (1.0, self.corner((i + 1) % 3) - p)
        } else {
            let r = t / self.edge_len2(i);
            (r, e * r - w)
        }
    }

    /// The point of edge `i` at parameter `r` (exactly a corner at `r = 0` and `r = 1`).
    #[inline(always)]
    fn edge_point(&self, i: usize, r: f64) -> V {
        if r == 0.0 {
            *self.corner(i)
        } else if r == 1.0 {
            *self.corner((i + 1) % 3)
        } else {
            self.corner(i) + self.edge(i) * r
        }
    }

    /// The closest point to `p` on edge `i`.
    #[inline(always)]
    fn on_edge(&self, i: usize, p: &V) -> V {
        self.edge_point(i, self.edge_param(i, p).0)
    }

    /// When the foot of `p` on the triangle's plane falls inside the closed triangle: its
    /// barycentric weights `(u, w)` of corners 1 and 2 (the foot is
    /// `v0 + (v1 - v0) u + (v2 - v0) w`) and the foot minus `p` from local differences.
    /// `None` otherwise or for a degenerate triangle.
    #[inline(always)]
    fn face_param(&self, p: &V) -> Option<(f64, f64, V)> {
        if self.nn <= 0.0 {
            return None;
        }
        let v = self.v;
        let w0 = p - v[0];
        let e02 = -self.e[2];
        // Barycentric weights of v1, v2 and v0, times |n|², each from its own base corner.
        let u = w0.cross(&e02).dot(&self.n);
        if u < 0.0 {
            return None;
        }
        let w = self.e[0].cross(&w0).dot(&self.n);
        if w < 0.0 {
            return None;
        }
        let z = self.e[1].cross(&(p - v[1])).dot(&self.n);
        if z < 0.0 {
            return None;
        }
        let sum = u + w + z;
        if sum <= 0.0 {
            return None;
        }
        let (u, w) = (u / sum, w / sum);
        Some((u, w, self.e[0] * u + e02 * w - w0))
    }

    #[inline(always)]
    fn face_point(&self, u: f64, w: f64) -> V {
        self.v[0] + self.e[0] * u - self.e[2] * w
    }

    /// The foot of `p` on the triangle's plane when it falls inside the closed triangle.
    #[inline(always)]
    fn face_foot(&self, p: &V) -> Option<V> {
        self.face_param(p).map(|(u, w, _)| self.face_point(u, w))
    }

    /// The closest point of the closed triangle to `p` (face or boundary).
    #[inline]
    fn closest(&self, p: &V) -> V {
        if let Some(f) = self.face_foot(p) {
            return f;
        }
        let mut best = self.on_edge(0, p);
        let mut bd = (best - p).norm_squared();
        for i in 1..3 {
            let q = self.on_edge(i, p);
            let d = (q - p).norm_squared();
            if d < bd {
                best = q;
                bd = d;
            }
        }
        best
    }
}

/// The best pair found so far.
struct Best {
    d2: f64,
    pa: V,
    pb: V,
}

impl Best {
    #[inline(always)]
    fn new(pa: V, pb: V) -> Self {
        Best {
            d2: (pb - pa).norm_squared(),
            pa,
            pb,
        }
    }

    #[inline(always)]
    fn offer(&mut self, pa: V, pb: V) {
        let d2 = (pb - pa).norm_squared();
        if d2 < self.d2 {
            *self = Best { d2, pa, pb };
        }
    }

    /// Offers a candidate whose separation `diff` (±(pb - pa), from local differences) is
    /// known; the points are only built when it wins.
    #[inline(always)]
    fn offer_with(&mut self, diff: V, points: impl FnOnce() -> (V, V)) {
        let d2 = diff.norm_squared();
        if d2 < self.d2 {
            let (pa, pb) = points();
            *self = Best { d2, pa, pb };
        }
    }
}

/// Edge `i` of `a` against edge `j` of `b`: offers the closest points of the two lines when
/// both lie within the segments. Uses the cross-product form `s = ((q - p) × d2)·n / |n|²`,
/// `n = d1 × d2`, which avoids the cancellation of the textbook `a e - b²` denominator.
#[inline(always)]
fn edge_edge_interior(fa: &Prepared, i: usize, fb: &Prepared, j: usize, best: &mut Best) {
    let d1 = fa.edge(i);
    let d2 = fb.edge(j);
    let n = d1.cross(d2);
    let nn = n.norm_squared();
    if nn <= 0.0 {
        return; // parallel: the endpoint candidates attain the minimum
    }
    let p = fa.corner(i);
    let q = fb.corner(j);
    let w = q - p;
    let s = w.cross(d2).dot(&n);
    if s < 0.0 || s > nn {
        return;
    }
    let t = w.cross(d1).dot(&n);
    if t < 0.0 || t > nn {
        return;
    }
    let (s, t) = (s / nn, t / nn);
    best.offer_with(w + d2 * t - d1 * s, || (p + d1 * s, q + d2 * t));
}

/// The distance between disjoint triangles. Two cheap certified early exits cover almost
/// every pair, the full decomposition covers the rest:
/// - edge–edge (PQP): the closest points of two edges, when the planes through them normal to
///   their separation leave the third corners on the correct sides — a separating slab whose
///   width is attained. Pairs are tried from the corners that reach furthest toward the other
///   triangle, so the first pair usually answers (about 1.6 pairs on average on random pairs);
/// - corner–face (PQP), after the first edge pair: all corners of one triangle strictly on one
///   side of the other's plane and the nearest of them projecting inside it — the plane bounds
///   the distance below and the projection attains it;
/// - otherwise (degenerate or rounding-limited cases, about 1 in 5000 random pairs) the
///   minimum over all 33 candidates.
#[inline]
fn separated(fa: &Prepared, fb: &Prepared) -> Best {
    separated_exits(fa, fb).unwrap_or_else(|| separated_full(fa, fb))
}

/// The early exits of [`separated`], in their order; `None` when none certifies its pair.
#[inline(always)]
fn separated_exits(fa: &Prepared, fb: &Prepared) -> Option<Best> {
    // Edge pairs, those next to the corners that reach furthest toward the other triangle
    // (along the line between the centroids) first: the closest features usually are there.
    let dir = (fb.v[0] + fb.v[1] + fb.v[2]) - (fa.v[0] + fa.v[1] + fa.v[2]);
    let ia = argmin3(fa.v.map(|p| -p.dot(&dir)));
    let jb = argmin3(fb.v.map(|q| q.dot(&dir)));
    // Edges k and k + 2 meet at corner k.
    let ea = [ia, (ia + 2) % 3, (ia + 1) % 3];
    let eb = [jb, (jb + 2) % 3, (jb + 1) % 3];
    for (k, (x, y)) in EDGE_PAIR_ORDER.into_iter().enumerate() {
        if k == 1 {
            // After the likeliest edge pair, the corner–face exits.
            if let Some(best) = corner_face_exit(fa, fb, false) {
                return Some(best);
            }
            if let Some(best) = corner_face_exit(fb, fa, true) {
                return Some(best);
            }
        }
        // why: `x, y < 3` (EDGE_PAIR_ORDER); `get` here was measurably slower.
        #[allow(clippy::indexing_slicing)]
        let (i, j) = (ea[x], eb[y]);
        if let Some(best) = edge_edge_exit(fa, i, fb, j) {
            return Some(best);
        }
    }
    None
}

/// The nine edge pairs, the four adjacent to both extreme corners first.
const EDGE_PAIR_ORDER: [(usize, usize); 9] = [
    (0, 0),
    (0, 1),
    (1, 0),
    (1, 1),
    (0, 2),
    (1, 2),
    (2, 0),
    (2, 1),
    (2, 2),
];

/// Phase 1: `o`'s corners against `f`'s face. `swapped`: `f` is the second triangle.
#[inline(always)]
fn corner_face_exit(f: &Prepared, o: &Prepared, swapped: bool) -> Option<Best> {
    if f.nn <= 0.0 {
        return None;
    }
    let s = o.v.map(|x| (x - f.v[0]).dot(&f.n));
    let m = if s[0] > 0.0 && s[1] > 0.0 && s[2] > 0.0 {
        argmin3(s)
    } else if s[0] < 0.0 && s[1] < 0.0 && s[2] < 0.0 {
        argmin3(s.map(|x| -x))
    } else {
        return None;
    };
    let p = o.corner(m);
    let (u, w, diff) = f.face_param(p)?;
    let foot = f.face_point(u, w);
    let (pa, pb) = if swapped { (*p, foot) } else { (foot, *p) };
    Some(Best {
        d2: diff.norm_squared(),
        pa,
        pb,
    })
}

/// `(8 ε)²`: the squared relative slack of the edge–edge certificate.
const CERT_SLACK2: f64 = (8.0 * f64::EPSILON) * (8.0 * f64::EPSILON);

#[inline(always)]
fn argmin3(s: [f64; 3]) -> usize {
    if s[0] <= s[1] {
        if s[0] <= s[2] {
            0
        } else {
            2
        }
    } else if s[1] <= s[2] {
        1
    } else {
        2
    }
}

/// Phase 2: closest points of edge `i` of `a` and edge `j` of `b` (Ericson's clamping scheme on
/// the convex quadratic, with the unconstrained solution in cross-product form), returned when
/// the third corners certify them as the global minimum.
#[inline(always)]
fn edge_edge_exit(fa: &Prepared, i: usize, fb: &Prepared, j: usize) -> Option<Best> {
    let (p, d1, dd1) = (fa.corner(i), fa.edge(i), fa.edge_len2(i));
    let (q, d2, dd2) = (fb.corner(j), fb.edge(j), fb.edge_len2(j));
    let w = q - p; // separation: w + d2 t - d1 s
    let c = d1.dot(&w);
    let f = d2.dot(&w);
    let clamp = |x: f64| if x > 0.0 { x.min(1.0) } else { 0.0 };
    let (s, t) = if dd1 <= 0.0 {
        (0.0, if dd2 > 0.0 { clamp(-f / dd2) } else { 0.0 })
    } else if dd2 <= 0.0 {
        (clamp(c / dd1), 0.0)
    } else {
        let b = d1.dot(d2);
        let n = d1.cross(d2);
        let nn = n.norm_squared();
        let s = if nn > 0.0 {
            clamp(w.cross(d2).dot(&n) / nn)
        } else {
            0.0
        };
        let tn = b * s - f;
        if tn <= 0.0 {
            (clamp(c / dd1), 0.0)
        } else if tn >= dd2 {
            (clamp((c + b) / dd1), 1.0)
        } else {
            (s, tn / dd2)
        }
    };
    let diff = w + d2 * t - d1 * s;
    // Third corners relative to the closest points: a's must not be beyond P along diff,
    // b's must not be before Q. A third corner on (or nearly on) its edge's line gives a
    // product at rounding level: allow a corner `8 ε |r|` beyond the slab (it can only make
    // the returned distance exceed the true one by that much, a few ulps of the edge length).
    // Products noisier than that (tiny separations) fall through to the full decomposition.
    let ra = -fa.edge((i + 2) % 3) - d1 * s;
    let rb = -fb.edge((j + 2) % 3) - d2 * t;
    let ka = ra.dot(&diff);
    let kb = -rb.dot(&diff);
    let dd = diff.norm_squared();
    let slack = |k: f64, r: &V| k <= 0.0 || k * k <= CERT_SLACK2 * r.norm_squared() * dd;
    if slack(ka, &ra) && slack(kb, &rb) {
        Some(Best {
            d2: diff.norm_squared(),
            pa: fa.edge_point(i, s),
            pb: fb.edge_point(j, t),
        })
    } else {
        None
    }
}

/// Phase 3: minimum over the whole decomposition (18 corner–edge, 9 edge–edge interior and
/// 6 corner–face candidates); exact distance when the triangles are disjoint.
#[inline(never)]
fn separated_full(fa: &Prepared, fb: &Prepared) -> Best {
    let (a, b) = (fa.v, fb.v);
    let mut best = Best::new(a[0], b[0]);
    // Corner–edge pairs (they include every corner–corner pair): the boundary of each
    // edge–edge parameter square.
    for p in a {
        for j in 0..3 {
            let (r, diff) = fb.edge_param(j, p);
            best.offer_with(diff, || (*p, fb.edge_point(j, r)));
        }
    }
    for q in b {
        for i in 0..3 {
            let (r, diff) = fa.edge_param(i, q);
            best.offer_with(diff, || (fa.edge_point(i, r), *q));
        }
    }
    // Interior critical points of the edge–edge pairs.
    for i in 0..3 {
        for j in 0..3 {
            edge_edge_interior(fa, i, fb, j, &mut best);
        }
    }
    // Corner–face pairs.
    for p in a {
        if let Some((u, w, diff)) = fb.face_param(p) {
            best.offer_with(diff, || (*p, fb.face_point(u, w)));
        }
    }
    for q in b {
        if let Some((u, w, diff)) = fa.face_param(q) {
            best.offer_with(diff, || (fa.face_point(u, w), *q));
        }
    }
    best
}

/// The triangles intersect: distance 0 and a common point. Every intersection contains a
/// point of an edge of one triangle on the other (the ends of the intersection segment, or a
/// corner of the inner triangle). Transversal crossings are answered by the first edge whose
/// crossing with the other triangle's plane falls inside that triangle; touching, coplanar and
/// degenerate contacts by the best of all candidates. The best pair's midpoint is returned for
/// both points.
#[cold]
fn contact(fa: &Prepared, fb: &Prepared) -> TriangleDistance {
    let mid = |best: &Best| best.pa + (best.pb - best.pa) * 0.5;
    let done = |m: V| TriangleDistance {
        distance: 0.0,
        point_a: m,
        point_b: m,
    };
    for i in 0..3 {
        if let Some(x) = edge_plane_crossing(fa, i, fb) {
            if let Some((u, w, _)) = fb.face_param(&x) {
                return done(mid(&Best::new(x, fb.face_point(u, w))));
            }
        }
        if let Some(x) = edge_plane_crossing(fb, i, fa) {
            if let Some((u, w, _)) = fa.face_param(&x) {
                return done(mid(&Best::new(fa.face_point(u, w), x)));
            }
        }
    }
    let mut best = separated_full(fa, fb);
    for i in 0..3 {
        if let Some(x) = edge_plane_crossing(fa, i, fb) {
            best.offer(x, fb.closest(&x));
        }
        if let Some(x) = edge_plane_crossing(fb, i, fa) {
            best.offer(fa.closest(&x), x);
        }
    }
    done(mid(&best))
}

/// Where edge `i` of `s` meets the plane of `t`, if it does at a single point.
#[inline]
fn edge_plane_crossing(s: &Prepared, i: usize, t: &Prepared) -> Option<V> {
    // No usable normal: a degenerate triangle, or `|n|²` underflowed (a square: never
    // negative).
    if t.nn == 0.0 {
        return None;
    }
    let p = s.corner(i);
    let sp = (p - t.corner(0)).dot(&t.n);
    let sq = (s.corner((i + 1) % 3) - t.corner(0)).dot(&t.n);
    let crosses = (sp <= 0.0 && sq >= 0.0) || (sp >= 0.0 && sq <= 0.0);
    if !crosses || sp == sq {
        return None;
    }
    // In [0, 1]: with opposite signs |sp - sq| = |sp| + |sq|, and rounding is monotone.
    let r = sp / (sp - sq);
    Some(p + s.edge(i) * r)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// splitmix64, uniform in [-1, 1).
    struct Rng(u64);
    impl Rng {
        fn next(&mut self) -> f64 {
            self.0 = self.0.wrapping_add(0x9e37_79b9_7f4a_7c15);
            let mut z = self.0;
            z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
            z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
            ((z ^ (z >> 31)) >> 11) as f64 / (1u64 << 52) as f64 - 1.0
        }
        fn tri(&mut self, c: V, r: f64) -> Triangle {
            [0; 3].map(|_| c + V::new(self.next(), self.next(), self.next()) * r)
        }
    }

    /// The certified early exits agree with the full decomposition, and between them they
    /// answer nearly every disjoint pair: every edge pair is tried, and a right pair is
    /// certified (a wrong order or certificate leaves more to the fallback).
    #[test]
    fn early_exits_agree_with_full_decomposition() {
        let mut rng = Rng(7);
        let mut exits = [0usize; 3];
        let mut disjoint = 0;
        for k in 0..20_000 {
            let spread = [0.05, 0.3, 1.0][k % 3];
            let a = rng.tri(V::zeros(), 0.1);
            let c = V::new(rng.next(), rng.next(), rng.next()) * spread;
            let b = if k % 7 == 0 {
                // Degenerate b: a segment.
                let t = rng.tri(c, 0.1);
                [t[0], t[1], t[0] * 0.25 + t[1] * 0.75]
            } else {
                rng.tri(c, 0.1)
            };
            let (fa, fb) = (Prepared::new(&a), Prepared::new(&b));
            if aabb_overlap(&a, &b) && intersect_with_planes(&a, &b, &fa.plane, &fb.plane) {
                continue;
            }
            disjoint += 1;
            let full = separated_full(&fa, &fb);
            let phased = separated(&fa, &fb);
            let (d_full, d_phased) = (full.d2.sqrt(), phased.d2.sqrt());
            assert!(
                (d_full - d_phased).abs() <= 1e-12 * d_full + 1e-15,
                "{a:?} {b:?}: full {d_full:e}, phased {d_phased:e}"
            );
            let phase = if corner_face_exit(&fa, &fb, false).is_some()
                || corner_face_exit(&fb, &fa, true).is_some()
            {
                0
            } else if (0..9).any(|ij| edge_edge_exit(&fa, ij / 3, &fb, ij % 3).is_some()) {
                1
            } else {
                2
            };
            exits[phase] += 1;
            // What `separated` answers by its exits, each exit seen above answers too.
            assert_eq!(
                separated_exits(&fa, &fb).is_some(),
                phase < 2,
                "{a:?} {b:?}"
            );
        }
        assert!(disjoint > 10_000);
        // The fallback is for rounding-limited cases only.
        assert!(exits[2] * 1000 <= disjoint, "{exits:?} of {disjoint}");
    }

    /// `Best` keeps the closer of two pairs by their separation, wherever they lie: a pair
    /// far apart on either side of the origin does not win, a closer one does.
    #[test]
    fn the_best_pair_is_the_closest_offered() {
        let (p, q) = (V::new(3.0, 0.0, 0.0), V::new(4.0, 0.0, 0.0));
        let mut best = Best::new(p, q);
        best.offer(-V::x(), V::x());
        assert_eq!((best.d2, best.pa, best.pb), (1.0, p, q));
        let (p, q) = (V::new(7.0, 1.0, 0.0), V::new(7.0, 1.5, 0.0));
        best.offer(p, q);
        assert_eq!((best.d2, best.pa, best.pb), (0.25, p, q));
    }

    /// `Prepared::closest` (what `contact`'s fallback offers) is the closed triangle's
    /// closest point: the same as the point query's, for points over the face, beside
    /// edges and corners, and on segment-like triangles.
    #[test]
    fn the_closest_point_is_the_point_querys() {
        let mut rng = Rng(11);
        for k in 0..20_000 {
            let t = if k % 5 == 0 {
                let t = rng.tri(V::zeros(), 1.0);
                [t[0], t[1], t[0] * 0.5 + t[1] * 0.5]
            } else {
                rng.tri(V::zeros(), 1.0)
            };
            let p = V::new(rng.next(), rng.next(), rng.next()) * 2.0;
            let got = Prepared::new(&t).closest(&p);
            let (want, _) = crate::query::triangle::closest_point_on_triangle(&p, &t);
            let (dg, dw) = ((got - p).norm(), (want - p).norm());
            assert!((dg - dw).abs() <= 1e-12, "{t:?} {p:?}: {got:?} {want:?}");
            assert!((got - want).norm() <= 1e-6, "{t:?} {p:?}: {got:?} {want:?}");
        }
    }

    /// `edge_plane_crossing` (what `contact` tries first) gives the point where an edge's
    /// ends change side of the other triangle's plane, an end on the plane included, and
    /// nothing for an edge beside or in the plane or for a degenerate triangle. The plane
    /// is `z = c`, where the sides are exact.
    #[test]
    fn an_edge_crosses_a_plane_where_its_ends_change_side() {
        let mut rng = Rng(13);
        let level = |rng: &mut Rng| [-0.5, 0.0, 0.25, 0.5][((rng.next() + 1.0) * 2.0) as usize];
        let (mut crossed, mut at_end) = (0, 0);
        for k in 0..20_000 {
            let c = level(&mut rng);
            let mut t = rng.tri(V::zeros(), 1.0);
            t.iter_mut().for_each(|p| p.z = c);
            if k % 10 == 0 {
                t[2] = t[0] * 0.5 + t[1] * 0.5;
            }
            let mut s = rng.tri(V::zeros(), 1.0);
            s.iter_mut().for_each(|p| {
                if rng.next() < -0.5 {
                    p.z = level(&mut rng);
                }
            });
            let (fs, ft) = (Prepared::new(&s), Prepared::new(&t));
            for i in 0..3 {
                let (p, q) = (s[i], s[(i + 1) % 3]);
                let (sp, sq) = (p.z - c, q.z - c);
                let expected = ft.nn > 0.0 && sp * sq <= 0.0 && sp != sq;
                let got = edge_plane_crossing(&fs, i, &ft);
                assert_eq!(got.is_some(), expected, "{s:?} {t:?} edge {i}: {got:?}");
                if let Some(x) = got {
                    crossed += 1;
                    at_end += usize::from(sp == 0.0 || sq == 0.0);
                    let want = p + (q - p) * (sp / (sp - sq));
                    assert!(
                        (x - want).norm() <= 1e-12,
                        "{s:?} {t:?} edge {i}: {x:?} {want:?}"
                    );
                }
            }
        }
        assert!(crossed > 10_000 && at_end > 1_000, "{crossed} {at_end}");
    }

    #[test]
    fn max_distance_ties_go_to_the_first_pair() {
        // The first corner of `a` is 1 from every corner of `b`, the others closer.
        let a = [V::zeros(), V::new(0.2, 0.2, 0.2), V::new(0.1, 0.1, 0.1)];
        let b = [V::x(), V::y(), V::z()];
        let far = triangle_max_distance(&a, &b);
        assert_eq!(far.distance, 1.0);
        assert_eq!((far.point_a, far.point_b), (a[0], b[0]));
    }
}
