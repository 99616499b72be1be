//! Turning principal directions into the final right-handed orthonormal frame.
//!
//! A [`Directions`] records which columns the covariance determined and which are free (a
//! repeated eigenvalue, or the directions across a line). Free columns default to the world
//! axes projected into the free subspace (Gram–Schmidt), so an axis-aligned cube gets the
//! identity; [`super::symmetry`] may then pick better ones. [`finish`] fixes signs and
//! handedness and re-orthonormalises.

use nalgebra::Matrix3;

use crate::arr3::{axis, cross, dot, norm2, normalize, scale, sub, V3};

/// Principal directions, sorted by decreasing spread, with possibly free columns.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) enum Directions {
    /// Columns 0 and 1 are determined (column 2 is their cross product).
    Fixed { c0: V3, c1: V3 },
    /// Column 0 is determined; columns 1 and 2 are free in the plane normal to it.
    FreeAfter { c0: V3 },
    /// Column 2 is determined; columns 0 and 1 are free in the plane normal to it.
    FreeBefore { c2: V3 },
    /// All columns are free (isotropic spread).
    Free,
}

impl Directions {
    /// True when some column is not determined by the covariance.
    pub(crate) fn is_free(&self) -> bool {
        !matches!(self, Directions::Fixed { .. })
    }

    /// Columns 0 and 1 with free columns set to projected world axes.
    pub(crate) fn default_columns(&self) -> (V3, V3) {
        match *self {
            Directions::Fixed { c0, c1 } => (c0, c1),
            Directions::FreeAfter { c0 } => (c0, in_plane_axis(c0)),
            Directions::FreeBefore { c2 } => {
                let c0 = in_plane_axis(c2);
                (c0, cross(c2, c0))
            }
            Directions::Free => (axis(0), axis(1)),
        }
    }
}

/// The first world axis (x, then y, then z) that is not too close to `w`, projected onto
/// the plane normal to `w` and normalised.
///
/// "Not too close" means at least a third of its squared length survives the projection;
/// two of the three axes always qualify (the squared components of a unit vector sum to
/// one), so the choice is well conditioned and, for `w` near a world axis, stable.
pub(crate) fn in_plane_axis(w: V3) -> V3 {
    for i in 0..3 {
        let wi = w.get(i).copied().unwrap_or(0.0);
        if 1.0 - wi * wi >= 1.0 / 3.0 {
            if let Some(a) = normalize(sub(axis(i), scale(w, wi))) {
                return a;
            }
        }
    }
    // Unreachable for a unit `w`; any non-finite input ends up here.
    axis(0)
}

/// Makes the sign of `c` deterministic: its largest-magnitude component (the first, on
/// exact ties) is positive.
fn fix_sign(c: V3) -> V3 {
    // Signs and magnitudes of fitted axes are a coin toss: selects, not branches.
    let mut largest = c[0];
    for x in [c[1], c[2]] {
        largest = std::hint::select_unpredictable(x.abs() > largest.abs(), x, largest);
    }
    scale(c, std::hint::select_unpredictable(largest < 0.0, -1.0, 1.0))
}

/// `v` scaled to unit length. Inputs here are almost always unit already (to a few ulps),
/// and then one Newton step for `1/√s` (error `≈ 3/8 (s − 1)²`, below 1e-16 for
/// `|s − 1| < 1e-8`) replaces the square root and division, which dominate the latency
/// of a one-triangle fit.
#[inline]
fn unitize(v: V3) -> Option<V3> {
    let s = norm2(v);
    if (s - 1.0).abs() < 1e-8 {
        Some(scale(v, 1.5 - 0.5 * s))
    } else {
        normalize(v)
    }
}

/// The final frame from its first two columns: orthonormalised (column 1 made orthogonal
/// to column 0), sign-normalised, and completed with column 2 = column 0 × column 1 so the
/// determinant is +1. Falls back to the identity if the input is degenerate or not finite.
pub(crate) fn finish(c0: V3, c1: V3) -> Matrix3<f64> {
    let built = (|| {
        let c0 = fix_sign(unitize(c0)?);
        let c1 = fix_sign(unitize(sub(c1, scale(c0, dot(c0, c1))))?);
        let c2 = unitize(cross(c0, c1))?;
        Some(Matrix3::new(
            c0[0], c1[0], c2[0], c0[1], c1[1], c2[1], c0[2], c1[2], c2[2],
        ))
    })();
    match built {
        Some(m) if m.iter().all(|v| v.is_finite()) => m,
        _ => Matrix3::identity(),
    }
}
