//! Triangle–triangle primitives evaluated at the leaves of collision, distance and span
//! queries: an exact contact test, the minimum distance with witness points, and the maximum
//! distance.
//!
//! All three take triangles as three f64 corners in one common frame (the caller transforms
//! one of them first). They never allocate, never panic and never return NaN for finite
//! inputs, including degenerate triangles (collinear or coincident corners), parallel and
//! coplanar pairs, and pairs sharing corners or edges.
//!
//! - [`triangles_intersect`]: **closed sets; exact on the given coordinates**. Two triangles
//!   are in contact iff their closed point sets (interior, edges and corners) share at least
//!   one point; a zero-area triangle is the segment or point it spans. Decided with exact
//!   orientation predicates (Guigue–Devillers on Shewchuk's adaptive orient3d, orient2d for
//!   coplanar and degenerate configurations).
//! - [`triangle_distance`]: minimum distance and a closest pair, `0` exactly when
//!   [`triangles_intersect`] says they touch.
//! - [`triangle_max_distance`]: maximum distance, attained at a corner pair.
//! - [`closest_point_on_triangle`]: the closest point of one triangle to a point, with the
//!   [`Feature`] (face, edge, corner) it lies on.
//! - [`triangle_intersection`]: where two touching triangles meet: the segment of a
//!   crossing pair, the shared polygon of a coplanar one.
//! - [`RaySpace::intersect`]: where a ray meets a triangle, watertight: a ray on an edge
//!   shared by two triangles meets exactly one of them.

mod distance;
mod intersection;
mod overlap;
mod point;
mod predicates;
pub(in crate::query) mod ray;

pub use distance::{triangle_distance, triangle_max_distance};
pub use intersection::{triangle_intersection, IntersectionKind, TriangleIntersection};
pub use overlap::triangles_intersect;
pub use point::{closest_point_on_triangle, Feature};
pub use ray::{RaySpace, RayTriangleHit};

pub(crate) use predicates::convex_union;

use nalgebra::Vector3;

/// A triangle as its three corners. Any corners are accepted, including collinear or
/// coincident ones (a segment or a point).
pub type Triangle = [Vector3<f64>; 3];

/// A distance between two triangles and a pair of points realising it: `point_a` on the first
/// triangle, `point_b` on the second, `distance == |point_a - point_b|` (up to rounding).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct TriangleDistance {
    /// The distance, never negative, never NaN.
    pub distance: f64,
    /// The witness point on the first triangle.
    pub point_a: Vector3<f64>,
    /// The witness point on the second triangle.
    pub point_b: Vector3<f64>,
}
