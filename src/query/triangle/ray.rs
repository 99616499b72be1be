//! Where a ray meets a triangle: watertight, with exact edge signs.
//!
//! Woop, Benthin and Wald's test ("Watertight Ray/Triangle Intersection", JCGT 2013): every
//! corner is moved into the ray's frame, sheared so the ray is the +z axis, and the ray
//! meets the triangle where the three 2D edge functions at the origin agree in sign. A
//! corner's sheared coordinates depend only on the corner and the ray, so two triangles
//! sharing an edge see it identically; the edge functions' signs are then taken exactly
//! (the float value unless it is zero or not finite, then Shewchuk's orient2d), so no ray
//! slips between them. A ray exactly on an edge or a corner belongs to one triangle only,
//! by a tie rule that is a symbolic perturbation of the ray (see [`owns`]).

use super::predicates::orient2d;
use super::Triangle;
use nalgebra::Vector3;

/// A ray prepared for triangle tests: its origin and the shear that maps its direction to
/// +z. Made once per ray, used for every triangle.
#[derive(Clone, Copy, Debug)]
pub struct RaySpace {
    origin: Vector3<f64>,
    /// The coordinates that become the sheared x, y and z.
    axes: [usize; 3],
    /// `d[kx] / d[kz]`, `d[ky] / d[kz]` and `1 / d[kz]`.
    shear: [f64; 3],
}

/// Where a ray meets a triangle.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RayTriangleHit {
    /// The ray parameter: the point is `origin + t · direction`.
    pub t: f64,
    /// The point's weights on the triangle's three corners (non-negative, summing to 1).
    pub barycentric: [f64; 3],
}

impl RaySpace {
    /// The ray from `origin` along `direction`, or `None` when the direction is zero or
    /// either is not finite.
    pub fn new(origin: &Vector3<f64>, direction: &Vector3<f64>) -> Option<RaySpace> {
        let finite = |v: &Vector3<f64>| v.x.is_finite() && v.y.is_finite() && v.z.is_finite();
        if !(finite(origin) && finite(direction)) {
            return None;
        }
        let kz = direction.iamax();
        if direction[kz] == 0.0 {
            return None;
        }
        let (mut kx, mut ky) = ((kz + 1) % 3, (kz + 2) % 3);
        // Keeps the sheared frame right-handed, so a triangle's 2D winding is its facing.
        if direction[kz] < 0.0 {
            std::mem::swap(&mut kx, &mut ky);
        }
        let dz = direction[kz];
        Some(RaySpace {
            origin: *origin,
            axes: [kx, ky, kz],
            shear: [direction[kx] / dz, direction[ky] / dz, 1.0 / dz],
        })
    }

    /// A corner in the ray's sheared frame: the ray is the +z axis, and `z` is the ray
    /// parameter of the corner's projection onto it.
    #[inline(always)]
    // why: the axes are a permutation of 0..3, made in `new`.
    #[allow(clippy::indexing_slicing)]
    fn sheared(&self, p: &Vector3<f64>) -> [f64; 3] {
        let [kx, ky, kz] = self.axes;
        let d = p - self.origin;
        [
            d[kx] - self.shear[0] * d[kz],
            d[ky] - self.shear[1] * d[kz],
            self.shear[2] * d[kz],
        ]
    }

    /// Where the ray meets closed triangle `t` with a parameter in `[0, t_max]`, if it
    /// does. A ray in the triangle's plane, or a triangle whose corners are collinear as
    /// the ray sees them, is a miss. On an edge shared by two triangles on either side of
    /// it (as the ray sees them) exactly one of them is hit; at a corner, one of the
    /// triangles around it.
    #[inline]
    pub fn intersect(&self, t: &Triangle, t_max: f64) -> Option<RayTriangleHit> {
        let [a, b, c] = crate::arr3::map(*t, |p| self.sheared(&p));
        // Each function is twice the signed area the origin makes with an edge, so the one
        // of the edge opposite a corner is that corner's weight.
        let u = cross(&c, &b);
        let v = cross(&a, &c);
        let w = cross(&b, &a);
        if (u < 0.0 || v < 0.0 || w < 0.0) && (u > 0.0 || v > 0.0 || w > 0.0) {
            return None;
        }
        let det = u + v + w;
        if det == 0.0 {
            return None;
        }
        // The origin lies on the line of every edge whose function is zero: the triangle
        // keeps that edge only if it owns it. With `det > 0` the triangle lies to the right
        // of a→b→c, so each edge is taken reversed to have the triangle on its left.
        let on_left = |p: &[f64; 3], q: &[f64; 3]| if det < 0.0 { owns(p, q) } else { owns(q, p) };
        if (u == 0.0 && !on_left(&b, &c))
            || (v == 0.0 && !on_left(&c, &a))
            || (w == 0.0 && !on_left(&a, &b))
        {
            return None;
        }
        // The corners' ray parameters weighted by the barycentric coordinates (in [0, 1]):
        // weighting by `u`, `v`, `w` first would square the coordinates' magnitude, and
        // underflow for triangles below about 1e-100 across or overflow above about 1e100.
        let barycentric = [u / det, v / det, w / det];
        let t_hit = barycentric[0] * a[2] + barycentric[1] * b[2] + barycentric[2] * c[2];
        // (Also refuses NaN, from coordinates so large that products overflow.)
        if !(t_hit >= 0.0 && t_hit <= t_max) {
            return None;
        }
        Some(RayTriangleHit {
            t: t_hit,
            barycentric,
        })
    }
}

/// `p.x q.y − p.y q.x` for sheared corners, with its sign exact: the float value when it
/// is finite and not zero, else Shewchuk's adaptive orient2d.
///
/// Rounding to nearest is monotone, so `p.x q.y > p.y q.x` gives rounded products in the
/// same order (or equal), and their rounded difference the exact sign or zero: a difference
/// of two products of inputs needs no error bound, only a zero needs the exact routine.
/// (That routine, as every floating-point predicate, is exact only where its products do
/// not underflow: corners below about 1e-150 in the sheared frame.)
#[inline(always)]
fn cross(p: &[f64; 3], q: &[f64; 3]) -> f64 {
    let value = p[0] * q[1] - p[1] * q[0];
    // Finite and not zero in one comparison: the magnitude's bits less one stay below
    // infinity's less one only for those (zero wraps round, NaN's bits lie above).
    if value.abs().to_bits().wrapping_sub(1) < f64::INFINITY.to_bits() - 1 {
        value
    } else {
        exact_cross(p, q)
    }
}

/// [`cross`] by the exact routine, out of the ray test's hot path. As `orient2d(0, p, q)`,
/// which works on `p − q`: corners so far out that the products overflow (above about
/// 1e154) often still give a finite value there.
#[cold]
#[inline(never)]
fn exact_cross(p: &[f64; 3], q: &[f64; 3]) -> f64 {
    orient2d([0.0, 0.0], [p[0], p[1]], [q[0], q[1]])
}

/// Whether the directed edge `p → q` (with its triangle on its left) owns the points of
/// it: those whose direction is upward, or horizontal and leftward. Of an edge's two
/// directions exactly one does, so of two triangles on either side of an edge exactly one
/// keeps it. This is the side a point nudged by `(−η, −η²)`, for a vanishing η, falls on,
/// so at a corner too exactly one of the triangles around it (seen from the ray) keeps the
/// point. A zero-length edge owns nothing.
#[inline(always)]
fn owns(p: &[f64; 3], q: &[f64; 3]) -> bool {
    // The signs of these differences are exact.
    let (dx, dy) = (q[0] - p[0], q[1] - p[1]);
    dy > 0.0 || (dy == 0.0 && dx < 0.0)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn v(x: f64, y: f64, z: f64) -> Vector3<f64> {
        Vector3::new(x, y, z)
    }

    #[test]
    fn hits_the_middle_with_its_weights() {
        let ray = RaySpace::new(&v(0.25, 0.25, 5.0), &v(0.0, 0.0, -2.0)).unwrap();
        let tri = [v(0.0, 0.0, 1.0), v(1.0, 0.0, 1.0), v(0.0, 1.0, 1.0)];
        let hit = ray.intersect(&tri, f64::INFINITY).unwrap();
        assert_eq!(hit.t, 2.0);
        assert_eq!(hit.barycentric, [0.5, 0.25, 0.25]);
        assert!(ray.intersect(&tri, 1.5).is_none());
        let behind = RaySpace::new(&v(0.25, 0.25, 5.0), &v(0.0, 0.0, 1.0)).unwrap();
        assert!(behind.intersect(&tri, f64::INFINITY).is_none());
    }

    #[test]
    fn a_shared_edge_and_corner_are_hit_once() {
        // A square of two triangles and a fan of four around the centre.
        let sq = [
            v(0.0, 0.0, 0.0),
            v(1.0, 0.0, 0.0),
            v(1.0, 1.0, 0.0),
            v(0.0, 1.0, 0.0),
        ];
        let square = [[sq[0], sq[1], sq[2]], [sq[0], sq[2], sq[3]]];
        let m = v(0.5, 0.5, 0.0);
        let fan: Vec<Triangle> = (0..4).map(|k| [m, sq[k], sq[(k + 1) % 4]]).collect();
        for dir in [v(0.0, 0.0, -1.0), v(0.0, 0.0, 1.0), v(0.3, -0.2, -1.0)] {
            let hits = |tris: &[Triangle], at: Vector3<f64>| {
                let ray = RaySpace::new(&(at - dir * 3.0), &dir).unwrap();
                tris.iter()
                    .filter(|t| ray.intersect(t, f64::INFINITY).is_some())
                    .count()
            };
            // Inside the diagonal: once; at its ends, on the square's border, at most once
            // (the perturbed ray may pass outside).
            for s in [0.25, 0.5] {
                assert_eq!(hits(&square, v(s, s, 0.0)), 1, "diagonal at {s}, {dir:?}");
            }
            for s in [0.0, 1.0] {
                assert!(hits(&square, v(s, s, 0.0)) <= 1, "corner {s}, {dir:?}");
            }
            assert_eq!(hits(&fan, m), 1, "centre of the fan, {dir:?}");
        }
    }

    #[test]
    fn edge_signs_are_exact_where_the_float_product_rounds_to_zero() {
        // (1 + 2⁻⁵²)(1 − 2⁻⁵²) − 1 = −2⁻¹⁰⁴, which rounds to 0 in f64.
        let (x, y) = (1.0 + f64::EPSILON, 1.0 - f64::EPSILON);
        assert_eq!(x * y - 1.0, 0.0);
        assert!(cross(&[x, 1.0, 0.0], &[1.0, y, 0.0]) < 0.0);
        assert!(cross(&[1.0, y, 0.0], &[x, 1.0, 0.0]) > 0.0);
    }

    #[test]
    fn a_tie_goes_to_the_triangle_the_nudged_ray_meets() {
        // Which triangle keeps a shared edge is the side the ray's point falls on when it
        // is nudged by (−η, −η²) in the sheared frame. Along +z that frame is the world's
        // x and y; along −z they are swapped (to stay right-handed), so the nudge is −η in
        // y there.
        let hit = |tris: &[Triangle], at: Vector3<f64>, dir: Vector3<f64>| {
            let ray = RaySpace::new(&(at - dir * 3.0), &dir).unwrap();
            let hits: Vec<usize> = (0..tris.len())
                .filter(|&i| ray.intersect(&tris[i], f64::INFINITY).is_some())
                .collect();
            assert_eq!(hits.len(), 1, "{at:?} along {dir:?}: {hits:?}");
            hits[0]
        };
        let (up, down) = (v(0.0, 0.0, 1.0), v(0.0, 0.0, -1.0));
        // The unit square's diagonal: below it x > y, above it y > x.
        let (o, x, xy, y) = (
            v(0.0, 0.0, 0.0),
            v(1.0, 0.0, 0.0),
            v(1.0, 1.0, 0.0),
            v(0.0, 1.0, 0.0),
        );
        let square = [[o, x, xy], [o, xy, y]];
        assert_eq!(hit(&square, v(0.5, 0.5, 0.0), up), 1, "x − η: above");
        assert_eq!(hit(&square, v(0.5, 0.5, 0.0), down), 0, "y − η: below");
        // A horizontal edge along +z: the −η² in y takes the triangle below it.
        let (l, r) = (v(0.0, 0.5, 0.0), v(1.0, 0.5, 0.0));
        let split = [[o, r, l], [l, r, v(0.5, 1.0, 0.0)]];
        assert_eq!(hit(&split, v(0.5, 0.5, 0.0), up), 0, "y − η²: below");
        // Along −z the same edge is vertical in the sheared frame, whose −η is world y's:
        // the lower one again.
        assert_eq!(hit(&split, v(0.5, 0.5, 0.0), down), 0);
    }

    #[test]
    fn a_float_edge_function_is_zero_or_of_the_exact_sign() {
        // Nearly parallel p and q: p × q is a difference of two close products, each
        // rounded. The float value is then often zero, never of the wrong sign, and the
        // exact routine decides the zeros.
        let mut rng = crate::generate::Rng::new(31);
        let mut zeros = 0;
        for _ in 0..100_000 {
            let p = [rng.signed(), rng.signed(), 0.0];
            let s = rng.signed() * 4.0;
            let q = [
                p[0] * s + rng.signed() * 1e-16,
                p[1] * s + rng.signed() * 1e-16,
                0.0,
            ];
            let exact = orient2d([0.0, 0.0], [p[0], p[1]], [q[0], q[1]]);
            let float = p[0] * q[1] - p[1] * q[0];
            if float == 0.0 {
                zeros += 1;
            } else {
                assert_eq!(float.signum(), exact.signum(), "{p:?} {q:?}");
            }
            assert_eq!(
                cross(&p, &q).partial_cmp(&0.0),
                exact.partial_cmp(&0.0),
                "{p:?} {q:?}"
            );
        }
        assert!(zeros > 10_000, "only {zeros} zeros");
    }

    #[test]
    fn corners_whose_products_overflow_are_still_hit() {
        // Corners near 1e158 in the ray's frame: the edge function of b and c overflows
        // as a difference of products (infinity minus infinity), not as the exact routine
        // forms it; the ray passes well inside (the other two functions are about 1e145).
        let tri = [
            v(-1.0, -1.0 + 1e-13, 0.0),
            v(1e158, 1e158, 0.0),
            v(1e158 + 1e145, 1e158 - 1e145, 0.0),
        ];
        let ray = RaySpace::new(&v(0.0, 0.0, -1.0), &v(0.0, 0.0, 1.0)).unwrap();
        let float = |t: &Triangle| {
            let [_, b, c] = t.map(|p| ray.sheared(&p));
            c[0] * b[1] - c[1] * b[0]
        };
        assert!(float(&tri).is_nan());
        assert_eq!(ray.intersect(&tri, f64::INFINITY).expect("a hit").t, 1.0);
        // One product just above the largest double, the other just below: the float
        // value is infinite, with the right sign, and the exact one about 3.6e305.
        let x = f64::MAX.sqrt();
        let tri = [tri[0], v(x, x, 0.0), v(x * 1.001, x * 0.999, 0.0)];
        assert_eq!(float(&tri), f64::INFINITY);
        assert_eq!(ray.intersect(&tri, f64::INFINITY).expect("a hit").t, 1.0);
    }

    #[test]
    fn refuses_zero_and_non_finite_directions() {
        assert!(RaySpace::new(&v(0.0, 0.0, 0.0), &v(0.0, 0.0, 0.0)).is_none());
        assert!(RaySpace::new(&v(0.0, 0.0, 0.0), &v(f64::NAN, 0.0, 1.0)).is_none());
        assert!(RaySpace::new(&v(f64::INFINITY, 0.0, 0.0), &v(0.0, 0.0, 1.0)).is_none());
    }
}
