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
use crate::query::quad::Quad;
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

    /// Where the ray meets closed triangle `t` with a parameter in `[0, t_max]`, if it
    /// does. A ray in the triangle's plane, or a triangle whose corners are collinear as
    /// the ray sees them, is a miss. On an edge shared by two triangles on either side of
    /// it (as the ray sees them) exactly one of them is hit; at a corner, one of the
    /// triangles around it.
    #[inline]
    pub fn intersect(&self, t: &Triangle, t_max: f64) -> Option<RayTriangleHit> {
        let corners = crate::arr3::map(*t, |p| self.sheared(&p));
        let [a, b, c] = &corners;
        let functions = [
            edge_function(c, b),
            edge_function(a, c),
            edge_function(b, a),
        ];
        hit(&corners, functions, t_max)
    }

    /// Up to [`LANES`] triangles (those past it are not looked at) prepared together, one
    /// per lane: their sheared corners and float edge functions, each value the one
    /// [`RaySpace::intersect`] computes, to the bit, and which triangles those values alone
    /// show the ray misses. Most triangles a ray is tested against are missed, and this
    /// decides them with one branch for the leaf instead of one each.
    #[inline(always)]
    // why: corners count to 3 and the axes are a permutation of 0..3, made in `new`.
    #[allow(clippy::indexing_slicing)]
    pub(in crate::query) fn prepare(&self, triangles: &[Triangle]) -> Prepared {
        let [kx, ky, kz] = self.axes;
        // Lanes past the last triangle repeat the first; nothing asks for them.
        let lane = |i: usize| triangles.get(i).or(triangles.first());
        let sheared = |k: usize| {
            let d = |axis: usize| {
                let values = std::array::from_fn(|i| lane(i).map_or(0.0, |t| t[k][axis]));
                Quad::from_array(values) - Quad::splat(self.origin[axis])
            };
            let (dx, dy, dz) = (d(kx), d(ky), d(kz));
            [
                dx - Quad::splat(self.shear[0]) * dz,
                dy - Quad::splat(self.shear[1]) * dz,
                Quad::splat(self.shear[2]) * dz,
            ]
        };
        let [a, b, c] = [sheared(0), sheared(1), sheared(2)];
        let function = |p: &[Quad; 3], q: &[Quad; 3]| p[0] * q[1] - p[1] * q[0];
        let functions = [function(&c, &b), function(&a, &c), function(&b, &a)];
        // A finite non-zero value's sign is exact (see `exact_sign`): one of each sign
        // is a miss whatever the third is.
        let [u, v, w] = functions.map(Quad::finite_or_zero);
        let zero = Quad::splat(0.0);
        let missed = u.min(v).min(w).lt_mask(zero) & zero.lt_mask(u.max(v).max(w));
        Prepared {
            corners: [a, b, c].map(|corner| corner.map(Quad::to_array)),
            functions: functions.map(Quad::to_array),
            missed,
        }
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
}

/// How many triangles [`RaySpace::prepare`] takes together.
pub(in crate::query) const LANES: usize = 4;

/// Triangles prepared for one ray by [`RaySpace::prepare`].
pub(in crate::query) struct Prepared {
    /// Each corner's sheared coordinates, lane by lane.
    corners: [[[f64; LANES]; 3]; 3],
    /// The float edge functions `u`, `v`, `w`, lane by lane.
    functions: [[f64; LANES]; 3],
    /// A bit per lane, set where the float edge functions show a miss.
    missed: u32,
}

impl Prepared {
    /// [`RaySpace::intersect`] for the triangle of `lane` (`None` for a lane past
    /// [`LANES`]; a lane past the triangles given answers for the first).
    #[inline(always)]
    pub(in crate::query) fn intersect(&self, lane: usize, t_max: f64) -> Option<RayTriangleHit> {
        if lane >= LANES || self.missed >> lane & 1 == 1 {
            return None;
        }
        let at = |values: &[f64; LANES]| values.get(lane).copied();
        let corner = |k: &[[f64; LANES]; 3]| Some([at(&k[0])?, at(&k[1])?, at(&k[2])?]);
        let [a, b, c] = &self.corners;
        let [u, v, w] = &self.functions;
        hit(
            &[corner(a)?, corner(b)?, corner(c)?],
            [at(u)?, at(v)?, at(w)?],
            t_max,
        )
    }
}

/// The hit of the triangle with sheared corners `corners` and float edge functions
/// `functions` (see [`edge_function`]), if there is one up to `t_max`.
#[inline(always)]
fn hit(corners: &[[f64; 3]; 3], functions: [f64; 3], t_max: f64) -> Option<RayTriangleHit> {
    let [a, b, c] = corners;
    // Each function is twice the signed area the origin makes with an edge, so the one of
    // the edge opposite a corner is that corner's weight.
    let [u, v, w] = functions;
    let (u, v, w) = (
        exact_sign(u, c, b),
        exact_sign(v, a, c),
        exact_sign(w, b, a),
    );
    if (u < 0.0 || v < 0.0 || w < 0.0) && (u > 0.0 || v > 0.0 || w > 0.0) {
        return None;
    }
    let det = u + v + w;
    if det == 0.0 {
        return None;
    }
    // The origin lies on the line of every edge whose function is zero: the triangle keeps
    // that edge only if it owns it. With `det > 0` the triangle lies to the right of
    // a→b→c, so each edge is taken reversed to have the triangle on its left.
    let on_left = |p: &[f64; 3], q: &[f64; 3]| if det < 0.0 { owns(p, q) } else { owns(q, p) };
    if (u == 0.0 && !on_left(b, c)) || (v == 0.0 && !on_left(c, a)) || (w == 0.0 && !on_left(a, b))
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

/// `p.x q.y − p.y q.x` for sheared corners, in floating point.
#[inline(always)]
fn edge_function(p: &[f64; 3], q: &[f64; 3]) -> f64 {
    p[0] * q[1] - p[1] * q[0]
}

/// [`edge_function`]'s `value` with its sign made exact: itself when it is finite and not
/// zero, else Shewchuk's adaptive orient2d.
///
/// Rounding to nearest is monotone, so `p.x q.y > p.y q.x` gives rounded products in the
/// same order (or equal), and their rounded difference the exact sign or zero: a difference
/// of two products of inputs needs no error bound, only a zero needs the exact routine.
/// (That routine, as every floating-point predicate, is exact only where its products do
/// not underflow: corners below about 1e-150 in the sheared frame.)
#[inline(always)]
fn exact_sign(value: f64, p: &[f64; 3], q: &[f64; 3]) -> f64 {
    // Finite and not zero in one comparison: the magnitude's bits less one stay below
    // infinity's less one only for those (zero wraps round, NaN's bits lie above).
    if value.abs().to_bits().wrapping_sub(1) < f64::INFINITY.to_bits() - 1 {
        value
    } else {
        exact_cross(p, q)
    }
}

/// [`edge_function`] by the exact routine, out of the ray test's hot path. As
/// `orient2d(0, p, q)`, which works on `p − q`: corners so far out that the products
/// overflow (above about 1e154) often still give a finite value there.
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

    /// An edge function with its exact sign, as the ray test takes it.
    fn cross(p: &[f64; 3], q: &[f64; 3]) -> f64 {
        exact_sign(edge_function(p, q), p, q)
    }

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
    fn triangles_prepared_together_answer_as_each_alone() {
        let mut rng = crate::generate::Rng::new(26);
        // Corners on a small grid (edge functions of zero, ties at edges and corners,
        // collinear and repeated corners), anywhere, or far enough out that products
        // overflow.
        let corner = |rng: &mut crate::generate::Rng, kind: usize| match kind {
            0 => v(
                rng.below(5) as f64 - 2.0,
                rng.below(5) as f64 - 2.0,
                rng.below(3) as f64 - 1.0,
            ),
            1 => v(rng.signed(), rng.signed(), rng.signed()) * 3.0,
            _ => v(rng.signed(), rng.signed(), rng.signed()) * 1e158,
        };
        let (mut hits, mut ties, mut lanes) = (0, 0, 0);
        for _ in 0..20_000 {
            let kind = [0, 0, 1, 2][rng.below(4)];
            let (origin, target) = (corner(&mut rng, kind) * 4.0, corner(&mut rng, kind));
            let Some(ray) = RaySpace::new(&origin, &(target - origin)) else {
                continue;
            };
            let count = 1 + rng.below(LANES);
            let tris: Vec<Triangle> = (0..count)
                .map(|_| [(); 3].map(|()| corner(&mut rng, kind)))
                .collect();
            let t_max = [f64::INFINITY, 1.0, 0.5][rng.below(3)];
            let prepared = ray.prepare(&tris);
            for (lane, t) in tris.iter().enumerate() {
                let alone = ray.intersect(t, t_max);
                let together = prepared.intersect(lane, t_max);
                // Bit for bit, NaN-free either way.
                assert_eq!(
                    alone.map(|h| (h.t.to_bits(), h.barycentric.map(f64::to_bits))),
                    together.map(|h| (h.t.to_bits(), h.barycentric.map(f64::to_bits))),
                    "lane {lane} of {tris:?}"
                );
                // Every lane that the float functions alone show missed is decided in the
                // lanes, and no other.
                let [a, b, c] = t.map(|p| ray.sheared(&p));
                let signs = [
                    edge_function(&c, &b),
                    edge_function(&a, &c),
                    edge_function(&b, &a),
                ]
                .map(|f| if f.is_finite() { f } else { 0.0 });
                let shown = signs.iter().any(|&f| f < 0.0) && signs.iter().any(|&f| f > 0.0);
                assert_eq!(
                    prepared.missed >> lane & 1 == 1,
                    shown,
                    "lane {lane} of {tris:?}"
                );
                // And a lane marked missed is not looked at again.
                let marked = Prepared {
                    missed: 1 << lane,
                    ..prepared
                };
                assert_eq!(marked.intersect(lane, t_max), None);
                lanes += 1;
                hits += usize::from(alone.is_some());
                ties += usize::from(alone.is_some_and(|h| h.barycentric.contains(&0.0)));
            }
        }
        assert!(
            lanes > 40_000 && hits > 1_500 && ties > 200,
            "{lanes} lanes, {hits} hits, {ties} on an edge"
        );
    }

    #[test]
    fn refuses_zero_and_non_finite_directions() {
        assert!(RaySpace::new(&v(0.0, 0.0, 0.0), &v(0.0, 0.0, 0.0)).is_none());
        assert!(RaySpace::new(&v(0.0, 0.0, 0.0), &v(f64::NAN, 0.0, 1.0)).is_none());
        assert!(RaySpace::new(&v(f64::INFINITY, 0.0, 0.0), &v(0.0, 0.0, 1.0)).is_none());
    }
}
