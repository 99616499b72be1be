//! Convex hulls of point sets, classified by intrinsic dimension.
//!
//! [`convex_hull`] is the public entry point; the fit uses the same machinery through
//! `HullScratch` on its reusable buffers. Full-dimensional sets go to the 3-D quickhull,
//! sets within [`HULL_TOLERANCE`] of a plane to the 2-D monotone chain in that plane, and
//! lower-dimensional sets are reported as a point or a segment.

use std::fmt;

use super::dimension::{classify, Shape, DIMENSION_TOLERANCE};
use super::polygon::convex_polygon;
use super::quickhull::QuickHull;
use crate::arr3;
use crate::arr3::{cross, dot, norm2, sub, V3};

/// Relative plane tolerance of the hull, as a fraction of the point set's diameter
/// (bounding-box diagonal).
///
/// Points within a few `HULL_TOLERANCE × diameter` of the hull may be left out of it, and
/// a set within it of a plane is treated as planar. The value is large enough that the
/// plane of even a sliver face (height above this tolerance) is computed to well within
/// it, which is what keeps the construction consistent in floating point, and small
/// enough that the effect on a covariance is negligible.
pub const HULL_TOLERANCE: f64 = 1e-8;

/// The convex hull of a point set. Indices refer to the input slice.
#[derive(Clone, Debug, PartialEq)]
pub enum ConvexHull {
    /// All points coincide (within rounding); `index` is one of them.
    Point {
        /// Index of a representative point.
        index: u32,
    },
    /// All points are collinear; the hull is the segment between the two extreme ones.
    Segment {
        /// Indices of the segment's endpoints.
        ends: [u32; 2],
    },
    /// All points lie within the tolerance of a plane; the hull is a convex polygon.
    Polygon {
        /// Polygon vertices, counter-clockwise seen from the tip of `normal`.
        vertices: Vec<u32>,
        /// Unit normal of the plane.
        normal: [f64; 3],
    },
    /// A full-dimensional set; the hull is a closed triangulated surface.
    Polyhedron {
        /// Triangles, counter-clockwise seen from outside (right-hand normals point out).
        triangles: Vec<[u32; 3]>,
    },
}

impl ConvexHull {
    /// Surface area of the hull in squared model units: the area of the closed surface for
    /// a polyhedron, the (one-sided) area of a polygon, zero otherwise. `points` must be
    /// the slice the hull was computed from; indices out of range contribute nothing.
    pub fn area(&self, points: &[[f64; 3]]) -> f64 {
        let tri = |a: u32, b: u32, c: u32| -> f64 {
            match (
                points.get(a as usize),
                points.get(b as usize),
                points.get(c as usize),
            ) {
                (Some(&p), Some(&q), Some(&r)) => 0.5 * norm2(cross(sub(q, p), sub(r, p))).sqrt(),
                _ => 0.0,
            }
        };
        match self {
            ConvexHull::Point { .. } | ConvexHull::Segment { .. } => 0.0,
            ConvexHull::Polygon { vertices, .. } => match vertices.split_first() {
                Some((&first, rest)) => rest
                    .windows(2)
                    .map(|w| match *w {
                        [a, b] => tri(first, a, b),
                        _ => 0.0,
                    })
                    .sum(),
                None => 0.0,
            },
            ConvexHull::Polyhedron { triangles } => {
                triangles.iter().map(|t| tri(t[0], t[1], t[2])).sum()
            }
        }
    }
}

/// Why [`convex_hull`] gave no hull.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum HullError {
    /// No points were given.
    Empty,
    /// More points than `u32` indices can address.
    TooManyPoints,
    /// Floating-point trouble broke the construction (rare; near-degenerate input).
    Numerical,
}

impl fmt::Display for HullError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(match self {
            HullError::Empty => "convex hull of an empty point set",
            HullError::TooManyPoints => "too many points for u32 indices",
            HullError::Numerical => "convex hull failed on near-degenerate input",
        })
    }
}

impl std::error::Error for HullError {}

/// Computes the convex hull of `points` (finite coordinates, any order, duplicates
/// allowed).
///
/// The result is exact up to a small multiple of [`HULL_TOLERANCE`]: every point lies
/// inside every face plane or within a few `HULL_TOLERANCE × diameter` of it (typically
/// under one, more only on nearly degenerate input), and hull vertices are input points. A polyhedron is a closed, consistently oriented, convex
/// triangulated surface. Never panics, and runs in `O(n log n)` expected time.
///
/// Floating point can defeat the construction on nearly degenerate input (points within
/// about the tolerance of a common plane, in ways that fold the surface); that is
/// detected and reported as [`HullError::Numerical`], never returned as a wrong hull. It
/// is rare: no node of the shared test meshes but one in fandisk's tree hits it, and only
/// a small fraction of adversarial random sets do.
///
/// # Errors
///
/// - [`HullError::Empty`] for no points.
/// - [`HullError::TooManyPoints`] for more points than `u32` indices address.
/// - [`HullError::Numerical`] when rounding defeats the construction on nearly
///   degenerate input (detected, never a wrong hull).
///
/// # Examples
///
/// ```
/// use obbtree::fit::hull::{convex_hull, ConvexHull, HullError};
///
/// // A tetrahedron and a point inside it: the hull is the tetrahedron.
/// let points = [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0], [0.1, 0.1, 0.1]];
/// let hull = convex_hull(&points)?;
/// assert!(matches!(&hull, ConvexHull::Polyhedron { triangles } if triangles.len() == 4));
/// assert_eq!(convex_hull(&[]), Err(HullError::Empty));
/// # Ok::<(), HullError>(())
/// ```
pub fn convex_hull(points: &[[f64; 3]]) -> Result<ConvexHull, HullError> {
    let Some(&first) = points.first() else {
        return Err(HullError::Empty);
    };
    if points.len() >= u32::MAX as usize {
        return Err(HullError::TooManyPoints);
    }
    // Centre at the bounding-box centre so plane offsets carry little rounding.
    let mut lo = first;
    let mut hi = first;
    for p in points {
        lo = arr3::min(lo, *p);
        hi = arr3::max(hi, *p);
    }
    let c = [
        0.5 * (lo[0] + hi[0]),
        0.5 * (lo[1] + hi[1]),
        0.5 * (lo[2] + hi[2]),
    ];
    let magnitude = lo.iter().chain(&hi).fold(0.0_f64, |m, v| m.max(v.abs()));
    let centred: Vec<V3> = points.iter().map(|&p| sub(p, c)).collect();
    let shape = classify(&centred, magnitude);
    let s = shape.simplex;
    match shape.dim {
        0 => return Ok(ConvexHull::Point { index: s[0] as u32 }),
        1 => {
            return Ok(ConvexHull::Segment {
                ends: [s[0] as u32, s[1] as u32],
            })
        }
        _ => {}
    }
    let mut scratch = HullScratch::default();
    if is_flat(&shape) {
        scratch.polygon(&centred, &shape);
        if scratch.poly.len() < 3 {
            return Err(HullError::Numerical);
        }
        Ok(ConvexHull::Polygon {
            vertices: scratch.poly,
            normal: shape.normal,
        })
    } else {
        scratch
            .polyhedron(&centred, &shape)
            .map_err(|_| HullError::Numerical)?;
        Ok(ConvexHull::Polyhedron {
            triangles: scratch.tris,
        })
    }
}

/// True when the hull of a set of this shape is computed as a planar polygon.
pub(crate) fn is_flat(shape: &Shape) -> bool {
    shape.dim < 3 || shape.thickness <= HULL_TOLERANCE * shape.diameter
}

/// An orthonormal basis `(u, v, n)` of the shape's plane with `u × v = n`.
pub(crate) fn plane_basis(shape: &Shape) -> (V3, V3, V3) {
    let u = shape.direction;
    let n = shape.normal;
    (u, cross(n, u), n)
}

/// Reusable hull buffers.
#[derive(Debug, Default)]
pub(crate) struct HullScratch {
    quick: QuickHull,
    /// Hull triangles of the last [`HullScratch::polyhedron`] call.
    pub(crate) tris: Vec<[u32; 3]>,
    /// 2-D coordinates of the points in the plane basis, from [`HullScratch::polygon`].
    pub(crate) plane: Vec<[f64; 2]>,
    order: Vec<u32>,
    /// Polygon of the last [`HullScratch::polygon`] call, counter-clockwise about the
    /// shape's normal.
    pub(crate) poly: Vec<u32>,
}

impl HullScratch {
    /// Projects `points` onto the plane of `shape` (into [`HullScratch::plane`]) and
    /// computes their convex polygon into [`HullScratch::poly`].
    pub(crate) fn polygon(&mut self, points: &[V3], shape: &Shape) {
        let (u, v, _) = plane_basis(shape);
        let origin = points.get(shape.simplex[0]).copied().unwrap_or([0.0; 3]);
        self.plane.clear();
        self.plane.extend(points.iter().map(|&p| {
            let d = sub(p, origin);
            [dot(d, u), dot(d, v)]
        }));
        // Only rounding-level collinearity is merged here: unlike the 3-D hull, the
        // chain's decisions accumulate along nearly straight boundaries, so a thick
        // tolerance could cut off more than itself.
        let eps = DIMENSION_TOLERANCE * shape.diameter;
        convex_polygon(&self.plane, eps, &mut self.order, &mut self.poly);
    }

    /// Computes the 3-D hull of `points` (centred) into [`HullScratch::tris`].
    pub(crate) fn polyhedron(
        &mut self,
        points: &[V3],
        shape: &Shape,
    ) -> Result<(), super::quickhull::QuickHullError> {
        let eps = HULL_TOLERANCE * shape.diameter;
        self.quick.run(points, shape.simplex, eps, &mut self.tris)
    }
}
