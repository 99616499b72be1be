//! Exact orientation predicates on f64 coordinates (Shewchuk's adaptive orient2d / orient3d).
//!
//! `orient3d` evaluates Shewchuk's static error filter inline (the same expression, in the same
//! order, as `robust::orient3d`, so the same error bound holds) and only calls the adaptive,
//! exact routine of the `robust` crate when the filter cannot certify the sign. The sign of the
//! result is exact (barring overflow or underflow of the intermediate products); its magnitude
//! is only an approximation of the determinant.

use nalgebra::Vector3;
use robust::{Coord, Coord3D};

type V = Vector3<f64>;

/// Half the f64 machine epsilon (2^-53), Shewchuk's `epsilon`.
const EPS: f64 = f64::EPSILON * 0.5;
/// Shewchuk's `o3derrboundA`.
const O3D_ERRBOUND_A: f64 = (7.0 + 56.0 * EPS) * EPS;

/// Shewchuk's orient3d: positive when `d` lies below the plane through `a`, `b`, `c` (the side
/// from which `a`, `b`, `c` appear clockwise), negative above, exactly zero iff the four points
/// are coplanar. Equals `det[a - d, b - d, c - d]` in sign.
#[inline(always)]
pub(crate) fn orient3d(a: &V, b: &V, c: &V, d: &V) -> f64 {
    let adx = a.x - d.x;
    let bdx = b.x - d.x;
    let cdx = c.x - d.x;
    let ady = a.y - d.y;
    let bdy = b.y - d.y;
    let cdy = c.y - d.y;
    let adz = a.z - d.z;
    let bdz = b.z - d.z;
    let cdz = c.z - d.z;

    let bdxcdy = bdx * cdy;
    let cdxbdy = cdx * bdy;
    let cdxady = cdx * ady;
    let adxcdy = adx * cdy;
    let adxbdy = adx * bdy;
    let bdxady = bdx * ady;

    let det = adz * (bdxcdy - cdxbdy) + bdz * (cdxady - adxcdy) + cdz * (adxbdy - bdxady);
    let permanent = (bdxcdy.abs() + cdxbdy.abs()) * adz.abs()
        + (cdxady.abs() + adxcdy.abs()) * bdz.abs()
        + (adxbdy.abs() + bdxady.abs()) * cdz.abs();
    let errbound = O3D_ERRBOUND_A * permanent;
    if det > errbound || -det > errbound {
        return det;
    }
    orient3d_adaptive(a, b, c, d)
}

#[cold]
#[inline(never)]
fn orient3d_adaptive(a: &V, b: &V, c: &V, d: &V) -> f64 {
    let p = |v: &V| Coord3D {
        x: v.x,
        y: v.y,
        z: v.z,
    };
    robust::orient3d(p(a), p(b), p(c), p(d))
}

/// A triangle's supporting plane, prepared for many exact side tests.
///
/// `side(x)` evaluates `(x - t0) · ((t1 - t0) × (t2 - t0))`, Guigue–Devillers' `[t0, t1, t2, x]`
/// and the negation of Shewchuk's `orient3d(t0, t1, t2, x)`, with the cross product shared
/// between calls. It is Shewchuk's stage-A expression for the transposed matrix (each of the
/// nine entries one rounded difference of inputs, each term an entry times a difference of two
/// products, summed left to right), so his stage-A error bound applies to it unchanged; when
/// it cannot certify the sign the adaptive exact routine decides.
#[derive(Clone, Copy, Debug)]
pub(crate) struct PlaneSide {
    /// `t1 - t0` and `t2 - t0`.
    pub e1: V,
    pub e2: V,
    /// `e1 × e2`, each component a difference of two products.
    pub n: V,
    /// Per component, the sum of the absolute values of those two products.
    nabs: V,
}

impl PlaneSide {
    #[inline(always)]
    pub fn new(t: &[V; 3]) -> Self {
        let e1 = t[1] - t[0];
        let e2 = t[2] - t[0];
        let (p1, q1) = (e1.y * e2.z, e1.z * e2.y);
        let (p2, q2) = (e1.z * e2.x, e1.x * e2.z);
        let (p3, q3) = (e1.x * e2.y, e1.y * e2.x);
        PlaneSide {
            e1,
            e2,
            n: V::new(p1 - q1, p2 - q2, p3 - q3),
            nabs: V::new(
                p1.abs() + q1.abs(),
                p2.abs() + q2.abs(),
                p3.abs() + q3.abs(),
            ),
        }
    }

    /// Exact sign of `(x - t0) · n` (approximate magnitude); `t` is the triangle this plane
    /// was made from.
    #[inline(always)]
    pub fn side(&self, t: &[V; 3], x: &V) -> f64 {
        let d = x - t[0];
        let det = d.x * self.n.x + d.y * self.n.y + d.z * self.n.z;
        let permanent = d.x.abs() * self.nabs.x + d.y.abs() * self.nabs.y + d.z.abs() * self.nabs.z;
        let errbound = O3D_ERRBOUND_A * permanent;
        if det > errbound || -det > errbound {
            return det;
        }
        -orient3d_adaptive(&t[0], &t[1], &t[2], x)
    }
}

/// Two triangles whose coordinates' largest magnitude (`reach`) and largest difference along an
/// axis (`spread`) both lie in `[RANGE_LO, RANGE_HI]` (or are zero) keep the products the
/// predicates and distance formulas form (up to fourth powers of coordinate differences, and
/// the tails of Shewchuk's expansions) clear of overflow, and of underflow for differences
/// in the range themselves; far smaller ones along other axes can still underflow (pairs
/// whose differences span hundreds of orders of magnitude). The spread counts apart
/// from the reach: coordinates in range can differ by far less, as do those of a small
/// triangle away from the origin along one axis.
const RANGE_LO: f64 = 1e-60;
const RANGE_HI: f64 = 1e60;

/// The `reach` and `spread` of two triangles (see [`RANGE_LO`]), from each axis's least and
/// greatest coordinate. An overflowing difference makes the spread infinite.
#[inline(always)]
pub(crate) fn reach_and_spread(a: &[V; 3], b: &[V; 3]) -> (f64, f64) {
    let (lo, hi) = a
        .iter()
        .chain(b)
        .fold((a[0], a[0]), |(lo, hi), p| (lo.inf(p), hi.sup(p)));
    ((-lo).max().max(hi.max()), (hi - lo).max())
}

/// Is a reach or spread inside the safe range (see [`rescale`] otherwise)?
#[inline(always)]
pub(crate) fn in_range(m: f64) -> bool {
    (RANGE_LO..=RANGE_HI).contains(&m) || m == 0.0
}

/// `2^k` for `k` in `-1022..=1023`.
pub(crate) fn pow2(k: i32) -> f64 {
    f64::from_bits(((k.clamp(-1022, 1023) + 1023) as u64) << 52)
}

/// About `floor(log2(x))` (log2 may round up to the next integer just below a power of two),
/// clamped to ±1100, past every finite double's: 0 gives -1100 and infinity 1100, so that
/// sums and negations of a few exponents never overflow.
pub(crate) fn exponent(x: f64) -> i32 {
    (x.log2().floor() as i32).clamp(-1100, 1100)
}

/// `v * 2^-e`, in two factors so that each stays representable (`e` from [`exponent`], give
/// or take a few hundred).
pub(crate) fn scale_down(v: V, e: i32) -> V {
    v * pow2(-e / 2) * pow2(-e - (-e / 2))
}

/// `x * 2^e`, which undoes [`scale_down`] on a length or coordinate, in two factors too (a
/// single `2^e` would round to zero or infinity first).
pub(crate) fn scale_back(x: f64, e: i32) -> f64 {
    x * pow2(e / 2) * pow2(e - e / 2)
}

/// Scales both triangles by a power of two `2^-e` that brings their spread to about `[1, 4)`
/// (their reach to just below `2^199` where that would take it further), and returns them
/// with `e` to scale lengths back ([`scale_back`]). Scaling by a power of two is exact (the
/// contact answer is unchanged) unless it pushes some coordinate below the normal range,
/// which only happens for pairs whose coordinates span hundreds of orders of magnitude; so
/// does a spread below about `1e-120` of the reach stay below the range.
#[cold]
pub(crate) fn rescale(a: &[V; 3], b: &[V; 3], reach: f64, spread: f64) -> ([V; 3], [V; 3], i32) {
    // The spread is at most twice the reach, unless it overflowed to infinity.
    let r = exponent(reach);
    let e = exponent(spread).min(r).max(r - 198);
    let scale = |t: &[V; 3]| t.map(|p| scale_down(p, e));
    (scale(a), scale(b), e)
}

/// A point of a coordinate plane: two of the three coordinates of a 3D point, taken exactly.
pub(crate) type P2 = [f64; 2];

/// Shewchuk's orient2d: positive when `a`, `b`, `c` turn counterclockwise, negative clockwise,
/// exactly zero iff collinear.
#[inline]
pub(crate) fn orient2d(a: P2, b: P2, c: P2) -> f64 {
    robust::orient2d(
        Coord { x: a[0], y: a[1] },
        Coord { x: b[0], y: b[1] },
        Coord { x: c[0], y: c[1] },
    )
}

/// The coordinates kept when projecting along `axis` (0 = x, 1 = y, 2 = z): the projection
/// is exact, it just drops one coordinate.
#[inline]
pub(crate) fn project(v: &V, axis: usize) -> P2 {
    match axis {
        0 => [v.y, v.z],
        1 => [v.z, v.x],
        _ => [v.x, v.y],
    }
}

/// Exact-sign components of the normal `(b - a) × (c - a)`: component `k` is the orientation of
/// the triangle projected along axis `k` (with the coordinate order of [`project`]).
#[inline]
pub(crate) fn normal_signs(a: &V, b: &V, c: &V) -> [f64; 3] {
    [0, 1, 2].map(|k| orient2d(project(a, k), project(b, k), project(c, k)))
}

/// The axis along which a non-degenerate triangle projects with the largest area, or `None`
/// when its corners are exactly collinear (or coincide). Projecting along the returned axis is
/// injective on the triangle's plane.
#[inline]
pub(crate) fn dominant_axis(t: &[V; 3]) -> Option<usize> {
    let n = normal_signs(&t[0], &t[1], &t[2]);
    let mut best = None;
    let mut best_abs = 0.0;
    for (k, v) in n.iter().enumerate() {
        if v.abs() > best_abs {
            best_abs = v.abs();
            best = Some(k);
        }
    }
    best
}

/// Whether two triangles together make a convex quadrilateral: they share an edge (two
/// corners equal exactly), lie exactly in one plane, their other corners lie strictly on
/// either side of the shared edge's line and the shared corners on either side of (or on)
/// the line through the other two, so that the two diagonals cross. Exact on the given
/// coordinates; `false` for degenerate triangles.
pub(crate) fn convex_union(t: &[V; 3], u: &[V; 3]) -> bool {
    // The corner of `t` not on the shared edge, and the edge; then `u`'s other corner.
    let shared = |p: &V| u.contains(p);
    let [p0, p1, p2] = t;
    let (c, a, b) = match (shared(p0), shared(p1), shared(p2)) {
        (false, true, true) => (p0, p1, p2),
        (true, false, true) => (p1, p2, p0),
        (true, true, false) => (p2, p0, p1),
        _ => return false,
    };
    let Some(d) = u.iter().find(|q| *q != a && *q != b) else {
        return false;
    };
    if orient3d(a, b, c, d) != 0.0 {
        return false;
    }
    let Some(axis) = dominant_axis(t) else {
        return false;
    };
    let [a, b, c, d] = [a, b, c, d].map(|v| project(v, axis));
    let opposite = |x: f64, y: f64| (x > 0.0 && y < 0.0) || (x < 0.0 && y > 0.0);
    let same_side = |x: f64, y: f64| (x > 0.0 && y > 0.0) || (x < 0.0 && y < 0.0);
    opposite(orient2d(a, b, c), orient2d(a, b, d))
        && !same_side(orient2d(c, d, a), orient2d(c, d, b))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn two_halves_of_a_convex_quad_are_convex_and_others_are_not() {
        let v = |x: f64, y: f64, z: f64| V::new(x, y, z);
        // The answer is a property of the two triangles as point sets: each case is checked
        // in either winding of either triangle, with the two swapped, and in each of the
        // three coordinate planes (so projected along each axis, either way round).
        let check = |t: [V; 3], u: [V; 3], expected: bool| {
            let turns: [fn(V) -> V; 3] =
                [|p| p, |p| V::new(p.z, p.x, p.y), |p| V::new(p.y, p.z, p.x)];
            let reverse = |s: [V; 3]| [s[0], s[2], s[1]];
            for turn in turns {
                let (t, u) = (t.map(turn), u.map(turn));
                for (t, u) in [
                    (t, u),
                    (reverse(t), u),
                    (t, reverse(u)),
                    (reverse(t), reverse(u)),
                ] {
                    assert_eq!(convex_union(&t, &u), expected, "{t:?} {u:?}");
                    assert_eq!(convex_union(&u, &t), expected, "{u:?} {t:?}");
                }
            }
        };
        let (a, b, c, d) = (v(0., 0., 0.), v(1., 0., 0.), v(1., 1., 0.), v(0., 1., 0.));
        // A square cut along either diagonal, in any corner order.
        check([a, b, c], [a, c, d], true);
        check([c, a, b], [d, c, a], true);
        check([a, b, d], [b, c, d], true);
        // A straight angle at a shared corner is still convex.
        check([a, b, c], [a, c, v(-1., 0., 0.)], true);
        // Not convex: a dart, reflex at the shared corner a.
        check([a, b, c], [a, c, v(-1., -0.5, 0.)], false);
        // Overlapping: both other corners on one side of the shared edge.
        check([a, b, c], [a, c, v(0.9, 0.2, 0.)], false);
        check([a, b, c], [a, c, v(3., 1., 0.)], false);
        // Folded by the least step off the plane, sharing a corner only, or degenerate:
        // the odd corner on the shared edge's line beyond it, or inside it (where the
        // diagonals would cross).
        check([a, b, c], [a, c, v(0., 1., 1e-300)], false);
        check([a, b, c], [a, v(-1., 0., 0.), v(-1., -1., 0.)], false);
        check([a, b, c], [a, c, v(2., 2., 0.)], false);
        check([a, b, c], [a, c, v(0.5, 0.5, 0.)], false);
        check([a, a, c], [a, c, d], false);
        // The same triangle twice overlaps itself: no other corner.
        check([a, b, c], [a, b, c], false);
    }

    #[test]
    fn filter_agrees_with_robust() {
        let pts = [
            V::new(0.0, 0.0, 0.0),
            V::new(1.0, 0.0, 0.0),
            V::new(0.0, 1.0, 0.0),
            V::new(0.1, 0.1, 1e-300),
            V::new(0.1, 0.1, 0.0),
            V::new(1e6 + 0.1, 3.0, -2.0),
        ];
        for a in &pts {
            for b in &pts {
                for c in &pts {
                    for d in &pts {
                        let p = |v: &V| Coord3D {
                            x: v.x,
                            y: v.y,
                            z: v.z,
                        };
                        let r = robust::orient3d(p(a), p(b), p(c), p(d));
                        let o = orient3d(a, b, c, d);
                        assert_eq!(r.partial_cmp(&0.0), o.partial_cmp(&0.0));
                    }
                }
            }
        }
    }

    #[test]
    fn plane_side_is_negated_orient3d() {
        let pts = [
            V::new(0.0, 0.0, 0.0),
            V::new(1.0, 0.0, 0.0),
            V::new(0.0, 1.0, 0.0),
            V::new(0.1, 0.1, 1e-300),
            V::new(0.1, 0.1, 0.0),
            V::new(1e6 + 0.1, 3.0, -2.0),
            V::new(0.3, 0.7, 0.0),
            V::new(1.0 / 3.0, 1.0 / 3.0, 1.0 / 3.0),
        ];
        for a in &pts {
            for b in &pts {
                for c in &pts {
                    let t = [*a, *b, *c];
                    let plane = PlaneSide::new(&t);
                    for d in &pts {
                        let o = -orient3d(a, b, c, d);
                        let s = plane.side(&t, d);
                        assert_eq!(s.partial_cmp(&0.0), o.partial_cmp(&0.0), "{t:?} {d:?}");
                    }
                }
            }
        }
    }

    /// Each term of the filter's error bound counts: a point straight above a corner of a
    /// nearly vertical triangle (coordinates in the hundreds) leaves only the z term (then,
    /// the axes turned, x's or y's), and that component of the normal cancels nearly to
    /// nothing, its sign decided by the products' rounding. The filter must hand every such
    /// case it cannot certify to the exact routine.
    #[test]
    fn plane_side_is_exact_where_the_normal_cancels() {
        let mut rng = crate::generate::Rng::new(11);
        let mut unit = || rng.unit();
        let mut decided_by_rounding = 0;
        let coordinate = |u: f64| 400.0 * u - 200.0;
        for _ in 0..20_000 {
            let t0 = V::new(coordinate(unit()), coordinate(unit()), coordinate(unit()));
            let along = V::new(coordinate(unit()), coordinate(unit()), coordinate(unit()));
            // t2 on the line through t0 and t1 in x and y (up to rounding), anywhere in z.
            let s = 2.0 * unit() - 0.5;
            let t = [
                t0,
                t0 + along,
                V::new(t0.x + s * along.x, t0.y + s * along.y, coordinate(unit())),
            ];
            let x = V::new(t0.x, t0.y, t0.z + coordinate(unit()));
            let exact = -orient3d_adaptive(&t[0], &t[1], &t[2], &x);
            // The coordinates turned cyclically (the same sign), so that the term left is
            // x's, then z's (not turned), then y's.
            for k in 0..3 {
                let turn = |v: &V| V::new(v[(k + 2) % 3], v[k % 3], v[(k + 1) % 3]);
                let (t, x) = (t.map(|v| turn(&v)), turn(&x));
                let side = PlaneSide::new(&t).side(&t, &x);
                assert_eq!(
                    side.partial_cmp(&0.0),
                    exact.partial_cmp(&0.0),
                    "{t:?} {x:?}"
                );
            }
            let d = x - t[0];
            let n = t[1] - t[0];
            let m = t[2] - t[0];
            if (d.z * (n.x * m.y - n.y * m.x)).partial_cmp(&0.0) != exact.partial_cmp(&0.0) {
                decided_by_rounding += 1;
            }
        }
        // The cases exist: the rounded determinant has the wrong sign in many of them.
        assert!(decided_by_rounding > 100, "{decided_by_rounding}");
    }

    /// orient3d's filter term by term: `d` straight above one of the other three points
    /// leaves only that point's term of the determinant, and the other two, nearly
    /// collinear with `d` seen from above, make its 2 × 2 minor cancel to rounding. The
    /// filter must hand every case it cannot certify to the exact routine.
    #[test]
    fn orient3d_is_exact_where_one_term_is_left_and_cancels() {
        // At a scale of 2^-10 too (exact, so the same cases): there the products are
        // below 1, and a bound that multiplied them where it should add would shrink.
        for scale in [1.0, pow2(-10)] {
            one_term_left_and_cancelling(scale);
        }
    }

    /// [`orient3d_is_exact_where_one_term_is_left_and_cancels`] at coordinates up to 200
    /// times `scale`.
    fn one_term_left_and_cancelling(scale: f64) {
        let mut rng = crate::generate::Rng::new(12);
        let mut unit = || rng.unit();
        let coordinate = |u: f64| (400.0 * u - 200.0) * scale;
        let mut decided_by_rounding = [0; 3];
        for _ in 0..20_000 {
            let base = V::new(coordinate(unit()), coordinate(unit()), coordinate(unit()));
            let along = V::new(coordinate(unit()), coordinate(unit()), coordinate(unit()));
            let s = 2.0 * unit() - 0.5;
            let (lift, height) = (coordinate(unit()), coordinate(unit()));
            // `d`, and the other two on a line through it in x and y (up to rounding).
            let d = V::new(base.x, base.y, base.z + height);
            let on_line = [
                base + along,
                V::new(base.x + s * along.x, base.y + s * along.y, base.z + lift),
            ];
            for (above, decided) in decided_by_rounding.iter_mut().enumerate() {
                // `d` straight above point `above` of `a, b, c`.
                let mut abc = [on_line[0]; 3];
                abc[above] = base;
                abc[(above + 2) % 3] = on_line[1];
                let [a, b, c] = abc;
                let exact = orient3d_adaptive(&a, &b, &c, &d);
                let filtered = orient3d(&a, &b, &c, &d);
                assert_eq!(
                    filtered.partial_cmp(&0.0),
                    exact.partial_cmp(&0.0),
                    "{abc:?} {d:?}"
                );
                let (e, f) = (abc[(above + 1) % 3] - d, abc[(above + 2) % 3] - d);
                let rounded = (abc[above].z - d.z) * (e.x * f.y - f.x * e.y);
                if rounded.partial_cmp(&0.0) != exact.partial_cmp(&0.0) {
                    *decided += 1;
                }
            }
        }
        // The cases exist for each term: rounding alone gives many of them the wrong sign.
        assert!(
            decided_by_rounding.iter().all(|&n| n > 100),
            "{decided_by_rounding:?}"
        );
    }

    #[test]
    fn orient3d_sign_convention() {
        let o = V::zeros();
        let x = V::x();
        let y = V::y();
        // d below the counterclockwise (seen from +z) plane → positive.
        assert!(orient3d(&o, &x, &y, &V::new(0.2, 0.2, -1.0)) > 0.0);
        assert!(orient3d(&o, &x, &y, &V::new(0.2, 0.2, 1.0)) < 0.0);
        assert_eq!(orient3d(&o, &x, &y, &V::new(7.0, -3.0, 0.0)), 0.0);
    }
}
