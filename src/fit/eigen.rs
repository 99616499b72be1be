//! Symmetric eigen-decompositions sorted by decreasing eigenvalue, with ties detected.
//!
//! A covariance determines its principal axes only up to rotations inside an eigenspace
//! of a repeated eigenvalue. Rather than trusting whatever vectors the solver returns
//! there (they depend on rounding), ties within [`TIE_TOLERANCE`] are reported as free
//! subspaces, and [`super::frame`] chooses the axes in them deterministically.

use nalgebra::{Matrix3, SymmetricEigen};

use super::covariance::Sym3;
use super::frame::{in_plane_axis, Directions};
use crate::arr3::{cross, norm2, normalize, V3};
#[cfg(test)]
use crate::arr3::{scale, sub};

/// Eigenvalues closer than this fraction of the largest one count as equal.
pub(crate) const TIE_TOLERANCE: f64 = 1e-9;

/// The principal axes of a 3×3 covariance, as a possibly partly free [`Directions`].
///
/// Returns `None` when the input is not finite or no solver succeeds.
pub(crate) fn axes3(c: &Sym3) -> Option<Directions> {
    if !c.is_finite() {
        return None;
    }
    // Scaling to unit size makes the tolerances below absolute; eigenvectors are unchanged.
    let s = c.max_abs();
    if s <= 0.0 {
        return Some(Directions::Free);
    }
    let a = Sym3(c.0.map(|v| v / s));
    let (values, vectors) = closed_form(&a).or_else(|| iterative(&a))?;
    let [l0, l1, l2] = values;
    let [e0, e1, e2] = vectors;
    let tol = TIE_TOLERANCE * l0.abs();
    Some(if l0 - l2 <= tol {
        Directions::Free
    } else if l0 - l1 <= tol {
        Directions::FreeBefore { c2: e2 }
    } else if l1 - l2 <= tol {
        Directions::FreeAfter { c0: e0 }
    } else {
        Directions::Fixed { c0: e0, c1: e1 }
    })
}

/// Eigenpairs sorted by decreasing eigenvalue.
type Eigenpairs = ([f64; 3], [V3; 3]);

/// Closed-form eigen-decomposition of a symmetric 3×3 matrix scaled to entries ≤ 1.
///
/// Several times faster than the iterative solver, which matters because every
/// internal node of a tree build needs one. Stability comes from the order of work:
/// 1. the eigenvalue farthest from the other two, by the trigonometric formula for the
///    roots of the characteristic cubic (the sign of the cubic's invariant tells which end
///    of the spectrum is isolated);
/// 2. its eigenvector as the longest cross product of two rows of `A − λI` (well
///    conditioned, since that eigenvalue's gap is at least half the spread);
/// 3. the remaining pair from the exact 2×2 restriction of `A` to the orthogonal plane, so
///    a close pair is resolved as accurately as its own conditioning allows.
///
/// Returns `None` (the caller falls back to the iterative solver) when step 2 is not
/// clearly well conditioned.
fn closed_form(a: &Sym3) -> Option<Eigenpairs> {
    let [xx, yy, zz, xy, xz, yz] = a.0;
    let q = (xx + yy + zz) * (1.0 / 3.0);
    let (bx, by, bz) = (xx - q, yy - q, zz - q);
    let off = xy * xy + xz * xz + yz * yz;
    let p2 = (bx * bx + by * by + bz * bz + 2.0 * off) * (1.0 / 6.0);
    if p2 <= f64::EPSILON * f64::EPSILON {
        // Isotropic to rounding: any basis is an eigenbasis.
        return Some(([q; 3], [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]]));
    }
    let p = p2.sqrt();
    let det = bx * (by * bz - yz * yz) - xy * (xy * bz - yz * xz) + xz * (xy * yz - by * xz);
    let r = (det / (2.0 * p2 * p)).clamp(-1.0, 1.0);
    let phi = r.acos() * (1.0 / 3.0);
    // r ≥ 0: the largest eigenvalue is the isolated one; otherwise the smallest.
    let top = r >= 0.0;
    let lambda = if top {
        q + 2.0 * p * phi.cos()
    } else {
        q + 2.0 * p * (phi + 2.0 * std::f64::consts::FRAC_PI_3).cos()
    };
    let r0 = [xx - lambda, xy, xz];
    let r1 = [xy, yy - lambda, yz];
    let r2 = [xz, yz, zz - lambda];
    let mut best = cross(r0, r1);
    let mut best_n = norm2(best);
    for c in [cross(r0, r2), cross(r1, r2)] {
        let n = norm2(c);
        if n > best_n {
            (best, best_n) = (c, n);
        }
    }
    // Mathematically |cross| is the product of the two gaps, ≥ p²/4 here.
    // (NaN fails the comparison, and falls back too.)
    if best_n.is_nan() || best_n <= 1e-6 * p2 * p2 {
        return None;
    }
    let e = normalize(best)?;
    let u = in_plane_axis(e);
    let v = cross(e, u);
    let (m0, m1, [x, y]) = sym2(a.form(u, u), a.form(u, v), a.form(v, v));
    let w0 = normalize([
        x * u[0] + y * v[0],
        x * u[1] + y * v[1],
        x * u[2] + y * v[2],
    ])?;
    let w1 = cross(e, w0);
    let (mut values, mut vectors) = if top {
        ([lambda, m0, m1], [e, w0, w1])
    } else {
        ([m0, m1, lambda], [w0, w1, e])
    };
    // Rounding could in principle misorder values that are within a few ulps.
    // Bubble sort of three: compare-swap positions (0, 1), (1, 2), (0, 1).
    if values[0] < values[1] {
        values.swap(0, 1);
        vectors.swap(0, 1);
    }
    if values[1] < values[2] {
        values.swap(1, 2);
        vectors.swap(1, 2);
    }
    if values[0] < values[1] {
        values.swap(0, 1);
        vectors.swap(0, 1);
    }
    values
        .iter()
        .all(|v| v.is_finite())
        .then_some((values, vectors))
}

/// nalgebra's iterative solver, the fallback of [`closed_form`].
fn iterative(a: &Sym3) -> Option<Eigenpairs> {
    let [xx, yy, zz, xy, xz, yz] = a.0;
    let m = Matrix3::new(xx, xy, xz, xy, yy, yz, xz, yz, zz);
    let eig = SymmetricEigen::try_new(m, f64::EPSILON, 100)?;
    let mut order = [0usize, 1, 2];
    let val = |i: usize| eig.eigenvalues.get(i).copied().unwrap_or(0.0);
    // Sort by decreasing eigenvalue; index order breaks exact ties deterministically.
    order.sort_by(|&i, &j| val(j).total_cmp(&val(i)).then(i.cmp(&j)));
    let columns: [V3; 3] = eig.eigenvectors.into();
    let col = |i: usize| -> V3 { columns.get(i).copied().unwrap_or([0.0; 3]) };
    Some((order.map(val), order.map(col)))
}

/// Eigen-decomposition of `[[a, b], [b, c]]`: eigenvalues `l0 ≥ l1` and an (unnormalised)
/// eigenvector of `l0`, or `(1, 0)` when the two are exactly equal.
fn sym2(a: f64, b: f64, c: f64) -> (f64, f64, [f64; 2]) {
    let mean = 0.5 * (a + c);
    // Plain square root rather than `hypot`: the entries are far from overflow, and
    // `hypot` is a slow library call on the per-node hot path.
    let h = 0.5 * (a - c);
    let r = (h * h + b * b).sqrt();
    let (l0, l1) = (mean + r, mean - r);
    if r == 0.0 {
        return (l0, l1, [1.0, 0.0]);
    }
    // Of the two (equivalent in exact arithmetic) eigenvector formulas, use the one whose
    // leading entry is the larger difference, which is at least r.
    let dir = if a >= c { [l0 - c, b] } else { [b, l0 - a] };
    (l0, l1, dir)
}

/// The principal axes of a covariance restricted to a plane.
///
/// `(a, b, c)` is the 2×2 covariance `[[a, b], [b, c]]` in the orthonormal in-plane basis
/// `(u, v)`; `normal = u × v`. The normal is the axis of least (zero) spread, column 2.
pub(crate) fn axes2(a: f64, b: f64, c: f64, u: V3, v: V3, normal: V3) -> Option<Directions> {
    if !(a.is_finite() && b.is_finite() && c.is_finite()) {
        return None;
    }
    let (l0, l1, [x, y]) = sym2(a, b, c);
    if l0 - l1 <= TIE_TOLERANCE * l0.abs() {
        return Some(Directions::FreeBefore { c2: normal });
    }
    let c0 = normalize([
        x * u[0] + y * v[0],
        x * u[1] + y * v[1],
        x * u[2] + y * v[2],
    ])?;
    Some(Directions::Fixed {
        c0,
        c1: cross(normal, c0),
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::arr3::dot;

    /// SplitMix64, for reproducible random matrices.
    fn rng(state: &mut u64) -> f64 {
        *state = state.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = *state;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        ((z ^ (z >> 31)) >> 11) as f64 / (1u64 << 53) as f64 * 2.0 - 1.0
    }

    /// `R diag(l) Rᵀ` for a random rotation `R`, normalised to max entry 1 like `axes3`.
    fn with_spectrum(l: [f64; 3], state: &mut u64) -> (Sym3, [V3; 3]) {
        let a = normalize([rng(state), rng(state), rng(state)]).unwrap();
        let b = normalize(cross(a, in_plane_axis(a))).unwrap();
        let b = normalize(cross(a, cross(b, a))).unwrap();
        let c = cross(a, b);
        let r = [a, b, c];
        let mut m = [[0.0; 3]; 3];
        for i in 0..3 {
            for j in 0..3 {
                m[i][j] = (0..3).map(|k| l[k] * r[k][i] * r[k][j]).sum();
            }
        }
        let s = Sym3([m[0][0], m[1][1], m[2][2], m[0][1], m[0][2], m[1][2]]);
        let scale = s.max_abs();
        (Sym3(s.0.map(|x| x / scale)), r)
    }

    #[test]
    fn closed_form_matches_the_iterative_solver() {
        let mut state = 1;
        let spectra = [
            [3.0, 2.0, 1.0],
            [1.0, 1e-3, 1e-9],
            [5.0, 5.0 - 1e-6, 0.1],
            [2.0, 1.0, 1.0 - 1e-6],
            [1.0, 0.0, -1.0],
            [1e-8, 0.0, 0.0],
        ];
        for l in spectra {
            for _ in 0..200 {
                let (a, r) = with_spectrum(l, &mut state);
                let (values, vectors) = closed_form(&a).unwrap();
                let (ref_values, _) = iterative(&a).unwrap();
                for k in 0..3 {
                    assert!(
                        (values[k] - ref_values[k]).abs() < 1e-14,
                        "{l:?}: {values:?} vs {ref_values:?}"
                    );
                    // Residual |A v − λ v| is at rounding level.
                    let av = [
                        a.form(vectors[k], [1.0, 0.0, 0.0]),
                        a.form(vectors[k], [0.0, 1.0, 0.0]),
                        a.form(vectors[k], [0.0, 0.0, 1.0]),
                    ];
                    let res = sub(av, scale(vectors[k], values[k]));
                    assert!(norm2(res).sqrt() < 1e-14, "{l:?}: residual {res:?}");
                }
                // Orthonormal basis.
                for i in 0..3 {
                    for j in 0..3 {
                        let d = dot(vectors[i], vectors[j]);
                        assert!((d - if i == j { 1.0 } else { 0.0 }).abs() < 1e-14);
                    }
                }
                // Well-separated eigenvalues: the vectors are the generating axes.
                let gap = (l[0] - l[1]).abs().min((l[1] - l[2]).abs()) / l[0].abs();
                if gap > 1e-3 {
                    for k in 0..3 {
                        assert!(1.0 - dot(vectors[k], r[k]).abs() < 1e-12);
                    }
                }
            }
        }
    }

    #[test]
    fn ties_are_reported_as_free_subspaces() {
        let mut state = 9;
        let (a, r) = with_spectrum([2.0, 2.0, 1.0], &mut state);
        match axes3(&a) {
            Some(Directions::FreeBefore { c2 }) => assert!(1.0 - dot(c2, r[2]).abs() < 1e-12),
            other => panic!("{other:?}"),
        }
        let (a, r) = with_spectrum([3.0, 1.0, 1.0], &mut state);
        match axes3(&a) {
            Some(Directions::FreeAfter { c0 }) => assert!(1.0 - dot(c0, r[0]).abs() < 1e-12),
            other => panic!("{other:?}"),
        }
        let (a, _) = with_spectrum([1.0, 1.0, 1.0], &mut state);
        assert_eq!(axes3(&a), Some(Directions::Free));
        assert!(matches!(
            axes3(&with_spectrum([3.0, 2.0, 1.0], &mut state).0),
            Some(Directions::Fixed { .. })
        ));
        assert_eq!(axes3(&Sym3([f64::NAN, 0.0, 0.0, 0.0, 0.0, 0.0])), None);
    }
}
