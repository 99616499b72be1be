//! Exact contact test between two closed triangles (Guigue–Devillers on exact orient3d, with
//! explicit coplanar and degenerate branches built on the same exact predicates).

use super::predicates::{
    dominant_axis, in_range, orient2d, orient3d, project, rescale, PlaneSide, P2,
};
use super::Triangle;
use nalgebra::Vector3;

type V = Vector3<f64>;

/// Do two closed triangles share at least one point?
///
/// **Contact rule: closed sets; exact on the given coordinates.** Each triangle is the closed
/// set of all convex combinations of its three corners (interior, edges and corners). The
/// answer is `true` iff the two sets share at least one point: crossing, coplanar overlap, a
/// shared corner or edge, a corner lying on the other triangle, a single touching point. A
/// zero-area triangle is the segment or point its corners span and follows the same rule.
///
/// The decision uses only the signs of orientation determinants (orient3d, and orient2d on
/// exact coordinate projections), evaluated exactly with Shewchuk's adaptive arithmetic, so it
/// is the exact answer for the f64 coordinates given (no tolerance). Pairs whose largest
/// coordinate, or largest difference of coordinates along an axis, lies outside 1e-60..1e60
/// are first scaled by a power of two (exact), so the answer stays exact unless the
/// coordinates span hundreds of orders of magnitude. A pair
/// with an infinite coordinate does not intersect (NaN corners give an unspecified answer).
/// It never panics, always terminates and needs no allocation.
///
/// Cost: an exact bounding-box rejection, then the three corners of `b` against the plane of
/// `a` (early out when all lie strictly on one side), then the corners of `a` against the plane
/// of `b`, then Guigue–Devillers' two interval checks. The side tests share each plane's cross
/// product and use Shewchuk's static error bound, falling back to exact arithmetic only when a
/// sign is too close to call.
#[inline]
pub fn triangles_intersect(a: &Triangle, b: &Triangle) -> bool {
    let Some((reach, spread)) = boxes_meet(a, b) else {
        return false;
    };
    if !(in_range(reach) && in_range(spread)) {
        // An infinite corner (a damaged, unverified file, or a pose that overflows) spans no
        // closed set: no contact. Checked here, since rescaling infinity would never end.
        if !reach.is_finite() {
            return false;
        }
        let (a, b, _) = rescale(a, b, reach, spread);
        return intersect_in_range(&a, &b);
    }
    intersect_in_range(a, b)
}

/// [`triangles_intersect`] once the boxes overlap and the coordinates are in range.
#[inline(always)]
fn intersect_in_range(a: &Triangle, b: &Triangle) -> bool {
    let pa = PlaneSide::new(a);
    // Signs of b's corners against a's plane: early out when all strictly on one side.
    let db = b.each_ref().map(|q| pa.side(a, q));
    if strictly_one_side(&db) {
        return false;
    }
    let pb = PlaneSide::new(b);
    intersect_after_a_plane(a, b, &pb, db)
}

/// [`triangles_intersect`] for callers that already have both planes and know the bounding
/// boxes overlap.
#[inline]
pub(crate) fn intersect_with_planes(
    a: &Triangle,
    b: &Triangle,
    pa: &PlaneSide,
    pb: &PlaneSide,
) -> bool {
    let db = b.each_ref().map(|q| pa.side(a, q));
    if strictly_one_side(&db) {
        return false;
    }
    intersect_after_a_plane(a, b, pb, db)
}

/// `db[j]`: exact-sign side of `b[j]` against a's plane (not all of one strict sign).
#[inline(always)]
fn intersect_after_a_plane(a: &Triangle, b: &Triangle, pb: &PlaneSide, db: [f64; 3]) -> bool {
    let da = a.each_ref().map(|p| pb.side(b, p));
    if strictly_one_side(&da) {
        return false;
    }
    let db_zero = db == [0.0; 3];
    let da_zero = da == [0.0; 3];
    if !db_zero && !da_zero {
        // Both triangles are non-degenerate (a degenerate triangle makes every side test
        // against its plane vanish) and not coplanar: the general case.
        return guigue_devillers(a, b, da, db);
    }
    special_cases(a, b, &da, &db, da_zero, db_zero)
}

/// Exact and necessary: closed sets that share a point have overlapping closed boxes.
#[inline(always)]
pub(crate) fn aabb_overlap(a: &Triangle, b: &Triangle) -> bool {
    boxes_meet(a, b).is_some()
}

/// The pair's reach and spread (`predicates::reach_and_spread`) if their closed boxes meet, from
/// the same bounds per axis.
#[inline(always)]
// why: coordinate numbers in 0..3 on fixed-size triangles; the first test of every triangle
// pair, where the index-free form was measurably slower in collision queries.
#[allow(clippy::indexing_slicing)]
fn boxes_meet(a: &Triangle, b: &Triangle) -> Option<(f64, f64)> {
    let (mut reach, mut spread) = (0.0f64, 0.0f64);
    for k in 0..3 {
        let amin = a[0][k].min(a[1][k]).min(a[2][k]);
        let amax = a[0][k].max(a[1][k]).max(a[2][k]);
        let bmin = b[0][k].min(b[1][k]).min(b[2][k]);
        let bmax = b[0][k].max(b[1][k]).max(b[2][k]);
        if amax < bmin || bmax < amin {
            return None;
        }
        let (lo, hi) = (amin.min(bmin), amax.max(bmax));
        reach = reach.max(-lo).max(hi);
        spread = spread.max(hi - lo);
    }
    Some((reach, spread))
}

#[inline(always)]
fn strictly_one_side(d: &[f64; 3]) -> bool {
    (d[0] > 0.0 && d[1] > 0.0 && d[2] > 0.0) || (d[0] < 0.0 && d[1] < 0.0 && d[2] < 0.0)
}

/// Guigue–Devillers' orientation `[a, b, c, d] = (d - c) · ((a - c) × (b - c))`, the opposite
/// of Shewchuk's orient3d. Exact sign.
#[inline(always)]
fn gd(a: &V, b: &V, c: &V, d: &V) -> f64 {
    -orient3d(a, b, c, d)
}

/// The non-coplanar, non-degenerate case. `d1[i] = gd(b0, b1, b2, a_i)`,
/// `d2[j] = gd(a0, a1, a2, b_j)` (what [`PlaneSide::side`] computes); neither is all zero nor
/// all of one strict sign.
/// Transcription of Guigue & Devillers (JGT 8(1), 2003) `tri_tri_overlap_test_3d` with closed
/// comparisons (touching counts as contact).
#[inline]
fn guigue_devillers(a: &Triangle, b: &Triangle, d1: [f64; 3], d2: [f64; 3]) -> bool {
    let (p1, q1, r1) = (&a[0], &a[1], &a[2]);
    let (p2, q2, r2) = (&b[0], &b[1], &b[2]);
    let [dp1, dq1, dr1] = d1;
    let [dp2, dq2, dr2] = d2;
    // Permute a so that its first corner is alone on its side of b's plane (swapping b's
    // orientation when that side is the negative one).
    if dp1 > 0.0 {
        if dq1 > 0.0 {
            tri_tri_3d(r1, p1, q1, p2, r2, q2, dp2, dr2, dq2, a, b)
        } else if dr1 > 0.0 {
            tri_tri_3d(q1, r1, p1, p2, r2, q2, dp2, dr2, dq2, a, b)
        } else {
            tri_tri_3d(p1, q1, r1, p2, q2, r2, dp2, dq2, dr2, a, b)
        }
    } else if dp1 < 0.0 {
        if dq1 < 0.0 {
            tri_tri_3d(r1, p1, q1, p2, q2, r2, dp2, dq2, dr2, a, b)
        } else if dr1 < 0.0 {
            tri_tri_3d(q1, r1, p1, p2, q2, r2, dp2, dq2, dr2, a, b)
        } else {
            tri_tri_3d(p1, q1, r1, p2, r2, q2, dp2, dr2, dq2, a, b)
        }
    } else if dq1 < 0.0 {
        if dr1 >= 0.0 {
            tri_tri_3d(q1, r1, p1, p2, r2, q2, dp2, dr2, dq2, a, b)
        } else {
            tri_tri_3d(p1, q1, r1, p2, q2, r2, dp2, dq2, dr2, a, b)
        }
    } else if dq1 > 0.0 {
        if dr1 > 0.0 {
            tri_tri_3d(p1, q1, r1, p2, r2, q2, dp2, dr2, dq2, a, b)
        } else {
            tri_tri_3d(q1, r1, p1, p2, q2, r2, dp2, dq2, dr2, a, b)
        }
    } else if dr1 > 0.0 {
        tri_tri_3d(r1, p1, q1, p2, q2, r2, dp2, dq2, dr2, a, b)
    } else if dr1 < 0.0 {
        tri_tri_3d(r1, p1, q1, p2, r2, q2, dp2, dr2, dq2, a, b)
    } else {
        // Unreachable (d1 is not all zero); decided exactly anyway.
        coplanar(a, b)
    }
}

/// Permutes b into canonical form, then checks the overlap of the two intervals that the
/// triangles cut on the line common to their planes.
#[allow(clippy::too_many_arguments)]
#[inline(always)]
fn tri_tri_3d(
    p1: &V,
    q1: &V,
    r1: &V,
    p2: &V,
    q2: &V,
    r2: &V,
    dp2: f64,
    dq2: f64,
    dr2: f64,
    a: &Triangle,
    b: &Triangle,
) -> bool {
    if dp2 > 0.0 {
        if dq2 > 0.0 {
            check_min_max(p1, r1, q1, r2, p2, q2)
        } else if dr2 > 0.0 {
            check_min_max(p1, r1, q1, q2, r2, p2)
        } else {
            check_min_max(p1, q1, r1, p2, q2, r2)
        }
    } else if dp2 < 0.0 {
        if dq2 < 0.0 {
            check_min_max(p1, q1, r1, r2, p2, q2)
        } else if dr2 < 0.0 {
            check_min_max(p1, q1, r1, q2, r2, p2)
        } else {
            check_min_max(p1, r1, q1, p2, q2, r2)
        }
    } else if dq2 < 0.0 {
        if dr2 >= 0.0 {
            check_min_max(p1, r1, q1, q2, r2, p2)
        } else {
            check_min_max(p1, q1, r1, p2, q2, r2)
        }
    } else if dq2 > 0.0 {
        if dr2 > 0.0 {
            check_min_max(p1, r1, q1, p2, q2, r2)
        } else {
            check_min_max(p1, q1, r1, q2, r2, p2)
        }
    } else if dr2 > 0.0 {
        check_min_max(p1, q1, r1, r2, p2, q2)
    } else if dr2 < 0.0 {
        check_min_max(p1, r1, q1, r2, p2, q2)
    } else {
        // Unreachable (d2 is not all zero); decided exactly anyway.
        coplanar(a, b)
    }
}

/// The intervals overlap iff neither lies strictly beyond the other (closed comparison).
#[inline(always)]
fn check_min_max(p1: &V, q1: &V, r1: &V, p2: &V, q2: &V, r2: &V) -> bool {
    if gd(p2, p1, q1, q2) > 0.0 {
        return false;
    }
    gd(p2, r1, p1, r2) <= 0.0
}

/// Everything that is not the general case: coplanar triangles, and degenerate (segment or
/// point) triangles. Rare, so written for clarity with exact predicates throughout.
#[cold]
#[inline(never)]
fn special_cases(
    a: &Triangle,
    b: &Triangle,
    da: &[f64; 3],
    db: &[f64; 3],
    da_zero: bool,
    db_zero: bool,
) -> bool {
    if db_zero {
        if let Some(axis) = dominant_axis(a) {
            // a is a proper triangle and b lies in its plane.
            return tri_tri_2d(&project3(a, axis), &project3(b, axis));
        }
    }
    if da_zero {
        if let Some(axis) = dominant_axis(b) {
            return tri_tri_2d(&project3(a, axis), &project3(b, axis));
        }
    }
    // Now every triangle whose orientations all vanish is degenerate.
    match (da_zero, db_zero) {
        // a degenerate (db all zero), b proper and a not in b's plane.
        (false, true) => line_crosses_triangle(a, da, b),
        (true, false) => line_crosses_triangle(b, db, a),
        // Both degenerate: segments or points.
        (true, true) => degenerate_pair(a, b),
        // Excluded by the caller: the general case, exact all the same.
        (false, false) => guigue_devillers(a, b, *da, *db),
    }
}

/// Fallback for a coplanar pair: project along a direction that is injective on the plane.
fn coplanar(a: &Triangle, b: &Triangle) -> bool {
    match dominant_axis(a).or_else(|| dominant_axis(b)) {
        Some(axis) => tri_tri_2d(&project3(a, axis), &project3(b, axis)),
        None => degenerate_pair(a, b),
    }
}

/// `s` is a degenerate triangle (its corners collinear, not all equal) that is not in the plane
/// of the proper triangle `t`; `ds[i]` is the exact-sign orientation of `s[i]` against `t`'s
/// plane, not all of one strict sign. Two corners of different side classes span the line of
/// `s`, and the segment between them contains the single point where that line meets the
/// plane; `s` touches `t` iff that point is in `t`, i.e. iff the line passes through the closed
/// triangle: the three line–edge orientations are not of both strict signs.
fn line_crosses_triangle(s: &Triangle, ds: &[f64; 3], t: &Triangle) -> bool {
    let class = |x: f64| (x > 0.0) as i8 - (x < 0.0) as i8;
    // The first pair of corners (in the order 01, 02, 12) of different classes.
    let [d0, d1, d2] = *ds;
    let [s0, s1, s2] = s;
    let pairs = [
        ((d0, s0), (d1, s1)),
        ((d0, s0), (d2, s2)),
        ((d1, s1), (d2, s2)),
    ];
    let Some(&((_, p), (_, q))) = pairs.iter().find(|((x, _), (y, _))| class(*x) != class(*y))
    else {
        return false; // all strictly on one side (excluded by the caller)
    };
    let o = [
        orient3d(p, q, &t[0], &t[1]),
        orient3d(p, q, &t[1], &t[2]),
        orient3d(p, q, &t[2], &t[0]),
    ];
    !(o.iter().any(|&x| x > 0.0) && o.iter().any(|&x| x < 0.0))
}

/// Two degenerate triangles (segments or points). They can only meet if their spans are
/// coplanar; then the three coordinate projections all intersect iff the sets do (one of them
/// is injective on the common plane or line, and any common point projects to a common point).
fn degenerate_pair(a: &Triangle, b: &Triangle) -> bool {
    if let (Some((p, q)), Some((r, s))) = (distinct_pair(a), distinct_pair(b)) {
        if orient3d(p, q, r, s) != 0.0 {
            return false; // skew lines
        }
    }
    (0..3).all(|axis| tri_tri_2d(&project3(a, axis), &project3(b, axis)))
}

/// Two distinct corners of `t`, if any.
fn distinct_pair(t: &Triangle) -> Option<(&V, &V)> {
    if t[1] != t[0] {
        Some((&t[0], &t[1]))
    } else if t[2] != t[0] {
        Some((&t[0], &t[2]))
    } else {
        None
    }
}

fn project3(t: &Triangle, axis: usize) -> [P2; 3] {
    [
        project(&t[0], axis),
        project(&t[1], axis),
        project(&t[2], axis),
    ]
}

/// Closed 2D triangles (possibly degenerate) intersect iff an edge of one meets an edge of the
/// other, or one contains a corner of the other (containment without boundary contact).
pub(crate) fn tri_tri_2d(a: &[P2; 3], b: &[P2; 3]) -> bool {
    let edges = |t: &[P2; 3]| [(t[0], t[1]), (t[1], t[2]), (t[2], t[0])];
    for (p, q) in edges(a) {
        for (r, s) in edges(b) {
            if seg_seg_2d(p, q, r, s) {
                return true;
            }
        }
    }
    point_in_tri_2d(a[0], b) || point_in_tri_2d(b[0], a)
}

#[inline]
fn same_strict(x: f64, y: f64) -> bool {
    (x > 0.0 && y > 0.0) || (x < 0.0 && y < 0.0)
}

/// Closed segments `pq` and `rs` (either may be a point) share a point. Exact.
pub(crate) fn seg_seg_2d(p: P2, q: P2, r: P2, s: P2) -> bool {
    let o1 = orient2d(p, q, r);
    let o2 = orient2d(p, q, s);
    if same_strict(o1, o2) {
        return false;
    }
    let o3 = orient2d(r, s, p);
    let o4 = orient2d(r, s, q);
    if same_strict(o3, o4) {
        return false;
    }
    if o1 == 0.0 && o2 == 0.0 && o3 == 0.0 && o4 == 0.0 {
        // All on one line (or points): the sets meet iff their bounding boxes do.
        let overlap = |p: f64, q: f64, r: f64, s: f64| p.max(q) >= r.min(s) && r.max(s) >= p.min(q);
        return overlap(p[0], q[0], r[0], s[0]) && overlap(p[1], q[1], r[1], s[1]);
    }
    true
}

/// `p` lies in the closed, proper triangle `t`; `false` for a degenerate `t` (its edges cover
/// it and are tested separately).
pub(crate) fn point_in_tri_2d(p: P2, t: &[P2; 3]) -> bool {
    if orient2d(t[0], t[1], t[2]) == 0.0 {
        return false;
    }
    let s = [
        orient2d(t[0], t[1], p),
        orient2d(t[1], t[2], p),
        orient2d(t[2], t[0], p),
    ];
    !(s.iter().any(|&x| x > 0.0) && s.iter().any(|&x| x < 0.0))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::query::triangle::predicates::pow2;

    /// The pre-filter of every triangle pair: boxes apart on any one axis, in either order,
    /// reject the pair (a filter that never rejects would leave every answer right and
    /// only cost time); closed boxes that touch do not.
    #[test]
    fn aabb_overlap_rejects_triangles_apart_on_any_axis() {
        let a: Triangle = [
            Vector3::new(0.0, 0.0, 0.0),
            Vector3::new(1.0, 0.0, 0.0),
            Vector3::new(0.0, 1.0, 1.0),
        ];
        let moved = |k: usize, by: f64| a.map(|p| p + Vector3::ith(k, by));
        for k in 0..3 {
            for by in [-1.5, 1.5] {
                assert!(!aabb_overlap(&a, &moved(k, by)), "axis {k} by {by}");
                assert!(
                    !aabb_overlap(&moved(k, by), &a),
                    "axis {k} by {by}, swapped"
                );
            }
            assert!(aabb_overlap(&a, &moved(k, 1.0)), "axis {k}: touching");
            assert!(aabb_overlap(&a, &moved(k, 0.5)), "axis {k}: overlapping");
        }
    }

    /// The coplanar fallback of the orientation dispatch decides by projection: triangles
    /// of one plane overlapping, touching at a corner, and apart.
    #[test]
    fn coplanar_pairs_are_decided_in_their_plane() {
        let tri = |p: [f64; 3], q: [f64; 3], r: [f64; 3]| -> Triangle {
            [Vector3::from(p), Vector3::from(q), Vector3::from(r)]
        };
        // The plane x + y + z = 1, so that no coordinate plane holds it.
        let a = tri([1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]);
        let inner = tri([0.5, 0.25, 0.25], [0.25, 0.5, 0.25], [0.25, 0.25, 0.5]);
        let corner = tri([1.0, 0.0, 0.0], [2.0, -1.0, 0.0], [2.0, 0.0, -1.0]);
        let apart = tri([2.0, -1.0, 0.0], [3.0, -1.0, -1.0], [2.0, 0.0, -1.0]);
        assert!(coplanar(&a, &inner) && coplanar(&inner, &a));
        assert!(coplanar(&a, &corner) && coplanar(&corner, &a));
        assert!(!coplanar(&a, &apart) && !coplanar(&apart, &a));
    }

    /// Every way of writing the same two segments: either end first, either segment first.
    fn seg_seg_2d_all_orders(p: P2, q: P2, r: P2, s: P2) -> [bool; 8] {
        [
            seg_seg_2d(p, q, r, s),
            seg_seg_2d(q, p, r, s),
            seg_seg_2d(p, q, s, r),
            seg_seg_2d(q, p, s, r),
            seg_seg_2d(r, s, p, q),
            seg_seg_2d(s, r, p, q),
            seg_seg_2d(r, s, q, p),
            seg_seg_2d(s, r, q, p),
        ]
    }

    #[test]
    fn seg_seg_2d_cases() {
        let cases = [
            ([0., 0.], [2., 2.], [0., 2.], [2., 0.], true), // crossing
            ([0., 0.], [1., 1.], [1., 1.], [2., 0.], true), // sharing an end
            ([0., 0.], [2., 0.], [1., 0.], [1., 3.], true), // an end on the other's interior
            ([0., 0.], [2., 0.], [1., 1e-300], [1., 3.], false), // that end just off it
            ([0., 0.], [1., 1.], [2., 2.], [3., 3.], false), // collinear, apart
            ([0., 0.], [2., 2.], [1., 1.], [3., 3.], true), // collinear, overlapping
            ([0., 0.], [1., 1.], [1., 1.], [3., 3.], true), // collinear, touching at an end
            ([0., 0.], [1., 0.], [2., 0.], [3., 0.], false), // horizontal, apart
            ([0., 0.], [0., 1.], [0., 2.], [0., 3.], false), // vertical, apart
            ([0., 0.], [1., 0.], [0., 1.], [1., 1.], false), // parallel
            ([1., 1.], [1., 1.], [0., 0.], [2., 2.], true), // a point on a segment
            ([1., 1.], [1., 1.], [0., 0.], [2., 2.1], false), // a point beside it
            ([1., 1.], [1., 1.], [2., 2.], [2., 2.], false), // two points apart
            ([1., 1.], [1., 1.], [1., 1.], [1., 1.], true), // two points together
        ];
        for (p, q, r, s, meet) in cases {
            assert_eq!(
                seg_seg_2d_all_orders(p, q, r, s),
                [meet; 8],
                "{p:?}-{q:?} and {r:?}-{s:?}"
            );
        }
    }

    /// A triangle's three cyclic orders, counter-clockwise and clockwise: six ways of
    /// writing one closed triangle, so every edge takes every place in the predicates.
    fn windings(t: [P2; 3]) -> [[P2; 3]; 6] {
        let [a, b, c] = t;
        [
            [a, b, c],
            [b, c, a],
            [c, a, b],
            [a, c, b],
            [c, b, a],
            [b, a, c],
        ]
    }

    #[test]
    fn point_in_tri_2d_takes_either_winding_and_the_whole_boundary() {
        let t = [[0., 0.], [4., 0.], [0., 4.]];
        let inside = [
            [1., 1.],
            [2., 2.],
            [2., 0.],
            [0., 2.],
            [0., 0.],
            [4., 0.],
            [0., 4.],
        ];
        let outside = [
            [2.5, 2.],
            [-0.5, 1.],
            [1., -0.5],
            [5., 0.],
            [-1., -1.],
            [0., 4.5],
        ];
        for w in windings(t) {
            for p in inside {
                assert!(point_in_tri_2d(p, &w), "{p:?} in {w:?}");
            }
            for p in outside {
                assert!(!point_in_tri_2d(p, &w), "{p:?} not in {w:?}");
            }
        }
        // A degenerate triangle holds nothing by itself (its edges are tested instead).
        for w in windings([[0., 0.], [1., 1.], [2., 2.]]) {
            assert!(!point_in_tri_2d([1., 1.], &w));
        }
    }

    #[test]
    fn tri_tri_2d_takes_either_winding() {
        let t = [[0., 0.], [4., 0.], [0., 4.]];
        let cases = [
            ([[1., 1.], [2., 1.], [1., 2.]], true), // inside, no edge contact
            ([[-1., -1.], [9., -1.], [-1., 9.]], true), // around it
            ([[2., 2.], [5., 5.], [2., 5.]], true), // a corner on the hypotenuse
            ([[4., 0.], [5., 0.], [5., 1.]], true), // sharing a corner
            ([[3., 3.], [5., 5.], [3., 5.]], false), // beyond the hypotenuse
            ([[1., 1.], [1., 1.], [1., 1.]], true), // a point inside
            ([[5., 5.], [5., 5.], [5., 5.]], false), // a point outside
        ];
        for (u, meet) in cases {
            for wt in windings(t) {
                for wu in windings(u) {
                    assert_eq!(tri_tri_2d(&wt, &wu), meet, "{wt:?} and {wu:?}");
                    assert_eq!(tri_tri_2d(&wu, &wt), meet, "{wu:?} and {wt:?}");
                }
            }
        }
    }

    #[test]
    fn point_in_tri_2d_cases() {
        let t = [[0., 0.], [4., 0.], [0., 4.]];
        assert!(point_in_tri_2d([1., 1.], &t));
        assert!(point_in_tri_2d([2., 2.], &t));
        assert!(point_in_tri_2d([0., 0.], &t));
        assert!(!point_in_tri_2d([2.5, 2.], &t));
    }
    /// Small integer configurations, and the same mapped exactly (per axis, a translation and
    /// a power of two, x mirrored or not) to a small pair 2^-196 from the origin along x,
    /// 2^-248 apart along x and 2^-532 along y and z: its coordinates are in the
    /// predicates' range, its differences far below it. Once only the coordinates were
    /// measured, and products of those differences underflowed: a third of the answers were
    /// wrong. The distance is zero for exactly the pairs that meet.
    #[test]
    fn a_small_pair_away_from_the_origin_meets_as_its_unit_image_does() {
        use crate::query::triangle::triangle_distance;
        let mut rng = crate::generate::Rng::new(7);
        let (x, ux, uyz) = (pow2(-196), pow2(-248), pow2(-532));
        let mut met = 0;
        for i in 0..20_000 {
            let side = if i % 2 == 0 { 1.0 } else { -1.0 };
            let mut corner = || {
                let c = [
                    rng.below(3) as f64 - 1.0,
                    rng.below(5) as f64,
                    rng.below(5) as f64,
                ];
                let small = V::new(side * (x + c[0] * ux), c[1] * uyz, c[2] * uyz);
                (V::new(side * c[0], c[1], c[2]), small)
            };
            let [(a0, a1), (a2, a3), (a4, a5), (b0, b1), (b2, b3), (b4, b5)] =
                std::array::from_fn(|_| corner());
            let unit = triangles_intersect(&[a0, a2, a4], &[b0, b2, b4]);
            let (a, b) = ([a1, a3, a5], [b1, b3, b5]);
            let at = [a0, a2, a4, b0, b2, b4];
            assert_eq!(triangles_intersect(&a, &b), unit, "{at:?}");
            assert_eq!(triangle_distance(&a, &b).distance == 0.0, unit, "{at:?}");
            met += usize::from(unit);
        }
        // Both answers occur often.
        assert!((2_000..18_000).contains(&met), "{met}");
    }
}
