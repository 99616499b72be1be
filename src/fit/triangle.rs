//! Fast path: the frame of a single triangle.
//!
//! Leaves of a tree hold one triangle, so half of all fits are of this kind, and the
//! general pipeline (per-thread buffers, hull, sorting) costs several times more than the
//! answer needs. For one triangle all three methods agree: the area covariance of a
//! triangle is `(1/12) Σ p'p'ᵀ` and its vertex covariance `(1/3) Σ p'p'ᵀ` (centred
//! vertices `p'`), the same matrix up to scale, and its hull is itself. The dimension rules
//! are those of `dimension::classify`, applied to three points directly.

use nalgebra::Matrix3;

use super::dimension::{DIMENSION_TOLERANCE, POINT_TOLERANCE};
use super::eigen::axes2;
use super::frame::{finish, Directions};
use super::symmetry::{refine, LargestTriangles};
use crate::arr3;
use crate::arr3::{cross, dot, norm2, normalize, sub, V3};

/// The principal-axes frame of triangle `(p, q, r)`, by the same rules as the general fit.
pub(crate) fn triangle_frame(p: V3, q: V3, r: V3) -> Matrix3<f64> {
    let mut lo = p;
    let mut hi = p;
    let mut magnitude = 0.0_f64;
    for x in [p, q, r] {
        lo = arr3::min(lo, x);
        hi = arr3::max(hi, x);
        magnitude = x.iter().fold(magnitude, |m, c| m.max(c.abs()));
    }
    let d2 = norm2(sub(hi, lo));
    let point = POINT_TOLERANCE * magnitude;
    if !d2.is_finite() || d2 == 0.0 || d2 <= point * point {
        return Matrix3::identity();
    }
    // The longest edge plays the part of the farthest pair.
    let (e_pq, e_qr, e_rp) = (sub(q, p), sub(r, q), sub(p, r));
    let (l_pq, l_qr, l_rp) = (norm2(e_pq), norm2(e_qr), norm2(e_rp));
    let (a, e, c) = if l_pq >= l_qr && l_pq >= l_rp {
        (p, e_pq, r)
    } else if l_qr >= l_rp {
        (q, e_qr, p)
    } else {
        (r, e_rp, q)
    };
    let Some(u) = normalize(e) else {
        return Matrix3::identity();
    };
    let n = cross(u, sub(c, a));
    let tol = DIMENSION_TOLERANCE * DIMENSION_TOLERANCE * d2;
    let normal = if norm2(n) > tol { normalize(n) } else { None };
    let Some(normal) = normal else {
        let (c0, c1) = Directions::FreeAfter { c0: u }.default_columns();
        return finish(c0, c1);
    };
    let v = cross(normal, u);
    // In-plane coordinates of the centred vertices; Σ p'p'ᵀ in the basis (u, v).
    let m = [
        (p[0] + q[0] + r[0]) / 3.0,
        (p[1] + q[1] + r[1]) / 3.0,
        (p[2] + q[2] + r[2]) / 3.0,
    ];
    let (mut sxx, mut sxy, mut syy) = (0.0, 0.0, 0.0);
    for x in [p, q, r] {
        let d = sub(x, m);
        let (xu, xv) = (dot(d, u), dot(d, v));
        sxx += xu * xu;
        sxy += xu * xv;
        syy += xv * xv;
    }
    let Some(frame) = axes2(sxx, sxy, syy, u, v, normal) else {
        return Matrix3::identity();
    };
    let (c0, c1) = if frame.is_free() {
        // An equilateral triangle: let its edges propose the in-plane axes.
        let mut tris = LargestTriangles::default();
        tris.offer(p, q, r);
        refine(&frame, &[p, q, r], &tris)
    } else {
        frame.default_columns()
    };
    finish(c0, c1)
}
