//! Where two touching triangles meet: the segment along which two crossing triangles cut
//! each other, or the polygon two coplanar triangles share.
//!
//! Which side of a plane each corner lies on is decided exactly (orient3d), so a corner on
//! the other triangle's plane is a corner of the answer and never an interpolated point
//! near it; the crossing points themselves are computed in floating point, and
//! [`TriangleIntersection::residual`] says how far from either triangle they landed.

use super::predicates::{dominant_axis, orient2d, orient3d, project};
use super::{closest_point_on_triangle, triangle_distance, triangles_intersect, Triangle};
use nalgebra::Vector3;

/// The shape two touching triangles share.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum IntersectionKind {
    /// The triangles cross (or touch at a point, or along an edge, out of one plane): a
    /// segment, whose two ends coincide when they touch at a point.
    Segment,
    /// The triangles lie in one plane: the convex polygon they share (three to six
    /// corners; two or one when they touch along an edge or at a corner).
    Polygon,
}

/// The intersection of two touching triangles, in their common frame.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct TriangleIntersection {
    /// A segment or a coplanar polygon.
    pub kind: IntersectionKind,
    corners: [Vector3<f64>; 6],
    count: u8,
    /// The largest distance from a point of the answer to either triangle, as computed:
    /// 0 for exact corners, a few ulps of the coordinates for crossing points, more where
    /// the planes are nearly parallel (the crossing line is then ill-conditioned).
    pub residual: f64,
}

impl TriangleIntersection {
    /// The segment's two ends, or the polygon's corners in order around it.
    pub fn points(&self) -> &[Vector3<f64>] {
        self.corners
            .get(..usize::from(self.count))
            .unwrap_or(&self.corners)
    }

    /// The segment's length; 0 for a polygon.
    pub fn length(&self) -> f64 {
        match (self.kind, self.points()) {
            (IntersectionKind::Segment, [p, q]) => (q - p).norm(),
            _ => 0.0,
        }
    }

    /// The polygon's area; 0 for a segment.
    pub fn area(&self) -> f64 {
        let points = self.points();
        match (self.kind, points.split_first()) {
            (IntersectionKind::Polygon, Some((first, rest))) => {
                let twice: Vector3<f64> = rest
                    .iter()
                    .zip(rest.iter().skip(1))
                    .map(|(p, q)| (p - first).cross(&(q - first)))
                    .sum();
                twice.norm() / 2.0
            }
            _ => 0.0,
        }
    }

    /// The same intersection placed by `pose` (from the triangles' frame into another).
    pub fn posed(&self, pose: &crate::pose::Pose) -> TriangleIntersection {
        TriangleIntersection {
            corners: self.corners.map(|p| pose.apply(&p)),
            ..*self
        }
    }

    fn new(kind: IntersectionKind, points: &[Vector3<f64>], a: &Triangle, b: &Triangle) -> Self {
        let mut corners = [Vector3::zeros(); 6];
        for (slot, p) in corners.iter_mut().zip(points) {
            *slot = *p;
        }
        let residual = points
            .iter()
            .map(|p| {
                let on_a = (p - closest_point_on_triangle(p, a).0).norm();
                let on_b = (p - closest_point_on_triangle(p, b).0).norm();
                on_a.max(on_b)
            })
            .fold(0.0, f64::max);
        TriangleIntersection {
            kind,
            corners,
            count: points.len().min(6) as u8,
            residual,
        }
    }
}

/// Where `a` and `b` meet, for triangles that touch ([`super::triangles_intersect`]); `None`
/// when they do not after all (the caller asked about a pair that does not touch). A
/// zero-area triangle meets the other at the one point of contact its closest pair gives.
pub fn triangle_intersection(a: &Triangle, b: &Triangle) -> Option<TriangleIntersection> {
    if !triangles_intersect(a, b) {
        return None;
    }
    // The point a closest pair finds (at distance 0): the answer where no shape is found.
    let single = || {
        let p = triangle_distance(a, b).point_a;
        TriangleIntersection::new(IntersectionKind::Segment, &[p, p], a, b)
    };
    let (Some(_), Some(axis)) = (dominant_axis(b), dominant_axis(a)) else {
        return Some(single());
    };
    let side_a = a.map(|p| orient3d(&b[0], &b[1], &b[2], &p));
    if side_a.iter().all(|&s| s == 0.0) {
        return Some(coplanar(a, b, axis).unwrap_or_else(single));
    }
    let side_b = b.map(|p| orient3d(&a[0], &a[1], &a[2], &p));
    let (Some(sa), Some(sb)) = (section(a, &side_a), section(b, &side_b)) else {
        return Some(single());
    };
    // A section of one point (a corner on the other's plane, the rest to one side, or two
    // crossings rounded together) holds all the triangles share: that point, taken as it
    // is, whatever the other section rounds to.
    if let Some([p, _]) = [sa, sb].into_iter().find(|[p, q]| p == q) {
        return Some(TriangleIntersection::new(
            IntersectionKind::Segment,
            &[p, p],
            a,
            b,
        ));
    }
    // Both sections lie on the line where the planes meet: keep their overlap.
    let normal = |t: &Triangle| (t[1] - t[0]).cross(&(t[2] - t[0]));
    let line = normal(a).cross(&normal(b));
    let along = |p: &Vector3<f64>| line.dot(p);
    let order = |[p, q]: [Vector3<f64>; 2]| {
        if along(&p) <= along(&q) {
            [p, q]
        } else {
            [q, p]
        }
    };
    let ([a0, a1], [b0, b1]) = (order(sa), order(sb));
    let lo = if along(&a0) >= along(&b0) { a0 } else { b0 };
    let hi = if along(&a1) <= along(&b1) { a1 } else { b1 };
    // Rounding may cross the ends of sections that touch at one point.
    let ends = if along(&lo) <= along(&hi) {
        [lo, hi]
    } else {
        let mid = (lo + hi) / 2.0;
        [mid, mid]
    };
    Some(TriangleIntersection::new(
        IntersectionKind::Segment,
        &ends,
        a,
        b,
    ))
}

/// The part of triangle `t` on the other's plane, given each corner's exact side of it:
/// its corners on the plane and the points where its edges cross it (one or two points,
/// the second equal to the first when there is one).
fn section(t: &Triangle, side: &[f64; 3]) -> Option<[Vector3<f64>; 2]> {
    let mut points = [Vector3::zeros(); 3];
    let mut count = 0;
    let mut push = |p: Vector3<f64>| {
        if let Some(slot) = points.get_mut(count) {
            *slot = p;
            count += 1;
        }
    };
    // Each corner with the next one: the edges.
    let next = [(t[1], side[1]), (t[2], side[2]), (t[0], side[0])];
    for ((ti, si), (tj, sj)) in t.iter().zip(side).zip(next) {
        if *si == 0.0 {
            push(*ti);
        }
        if (*si < 0.0 && sj > 0.0) || (*si > 0.0 && sj < 0.0) {
            // The crossing divides the edge as the corners' (exact-signed) heights do.
            let u = (si / (si - sj)).clamp(0.0, 1.0);
            push(ti + (tj - ti) * u);
        }
    }
    match (count, points) {
        (1, [p, ..]) => Some([p, p]),
        (2, [p, q, _]) => Some([p, q]),
        // (Three only for a triangle in the plane: the coplanar case, handled apart.)
        _ => None,
    }
}

/// The polygon coplanar triangles share: `a` clipped by the three edges of `b`, in the
/// projection along `axis` (injective on their plane).
fn coplanar(a: &Triangle, b: &Triangle, axis: usize) -> Option<TriangleIntersection> {
    let flat = |p: &Vector3<f64>| project(p, axis);
    let turn = orient2d(flat(&b[0]), flat(&b[1]), flat(&b[2]));
    let mut polygon: Vec<Vector3<f64>> = a.to_vec();
    for (p0, p1) in b.iter().zip(b.iter().cycle().skip(1)) {
        let (e0, e1) = (flat(p0), flat(p1));
        // Inside is the side of b's edge where its third corner lies (edges included).
        let inside = |p: &Vector3<f64>| orient2d(e0, e1, flat(p)) * turn.signum();
        let mut clipped = Vec::with_capacity(polygon.len() + 1);
        for (p, q) in polygon.iter().zip(polygon.iter().cycle().skip(1)) {
            let (sp, sq) = (inside(p), inside(q));
            if sp >= 0.0 {
                clipped.push(*p);
            }
            if (sp > 0.0 && sq < 0.0) || (sp < 0.0 && sq > 0.0) {
                clipped.push(p + (q - p) * (sp / (sp - sq)));
            }
        }
        polygon = clipped;
        if polygon.is_empty() {
            return None;
        }
    }
    // Corners met twice (a corner of one on an edge of the other) count once.
    polygon.dedup();
    if polygon.len() > 1 && polygon.first() == polygon.last() {
        polygon.pop();
    }
    (polygon.len() <= 6)
        .then(|| TriangleIntersection::new(IntersectionKind::Polygon, &polygon, a, b))
}
