//! Weighted first and second moments, and the covariance matrices built from them.
//!
//! Two kinds of distribution are accumulated:
//! * the uniform area distribution over triangles (dissertation §3.4, closed form): a
//!   triangle `(p, q, r)` of area `A` and centroid `m` contributes weight `A`, first moment
//!   `A m` and second moment `A/12 (9 m mᵀ + p pᵀ + q qᵀ + r rᵀ)`;
//! * unit point masses (the vertex covariance, §3.3).
//!
//! Callers pass coordinates relative to a reference point close to the data (the
//! covariance is translation invariant); that keeps the final `E[x xᵀ] − m mᵀ`
//! subtraction free of catastrophic cancellation for data far from the origin.

use crate::arr3::{cross, norm2, scale, sub, V3};

/// A symmetric 3×3 matrix stored as `[xx, yy, zz, xy, xz, yz]`.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub(crate) struct Sym3(pub [f64; 6]);

impl Sym3 {
    /// Row `i` of the matrix.
    #[inline]
    pub(crate) fn row(&self, i: usize) -> V3 {
        let [xx, yy, zz, xy, xz, yz] = self.0;
        match i {
            0 => [xx, xy, xz],
            1 => [xy, yy, yz],
            _ => [xz, yz, zz],
        }
    }

    /// The bilinear form `aᵀ C b`.
    #[inline]
    pub(crate) fn form(&self, a: V3, b: V3) -> f64 {
        let cb = [
            crate::arr3::dot(self.row(0), b),
            crate::arr3::dot(self.row(1), b),
            crate::arr3::dot(self.row(2), b),
        ];
        crate::arr3::dot(a, cb)
    }

    /// True when every entry is finite.
    #[inline]
    pub(crate) fn is_finite(&self) -> bool {
        self.0.iter().all(|v| v.is_finite())
    }

    /// The largest absolute entry (a cheap norm for relative tolerances).
    #[inline]
    pub(crate) fn max_abs(&self) -> f64 {
        self.0.iter().fold(0.0_f64, |m, v| m.max(v.abs()))
    }
}

/// What a [`Moments`] has accumulated, which fixes the scale of its raw sums.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
enum Kind {
    /// Nothing yet.
    #[default]
    Empty,
    /// Triangles: weight is twice the area, first moment three times, second moment
    /// twelve times the true sums (see [`Moments::add_triangle`]).
    Area,
    /// Unit point masses: the sums are exact.
    Points,
}

/// One triangle's area moments about its own centroid: the part of a face's contribution
/// to [`Moments`] that does not depend on the reference origin. A build computes it once
/// per face and sums it at every level of the tree (the parallel-axis theorem moves it to
/// each node's origin), where recomputing it from the corners took a sixth of a build.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub(crate) struct FaceMoment {
    /// Twice the area.
    weight: f64,
    /// The mean of the three corners.
    centroid: V3,
    /// `weight · Σ (v − centroid)(v − centroid)ᵀ` over the corners, laid out as [`Sym3`].
    central: [f64; 6],
}

impl FaceMoment {
    /// The moments of triangle `(p, q, r)`.
    #[inline]
    pub(crate) fn new(p: V3, q: V3, r: V3) -> FaceMoment {
        let weight = norm2(cross(sub(q, p), sub(r, p))).sqrt();
        let centroid = scale(
            [p[0] + q[0] + r[0], p[1] + q[1] + r[1], p[2] + q[2] + r[2]],
            1.0 / 3.0,
        );
        let [a, b, c] = [sub(p, centroid), sub(q, centroid), sub(r, centroid)];
        let e = |j: usize, k: usize| weight * (a[j] * a[k] + b[j] * b[k] + c[j] * c[k]);
        FaceMoment {
            weight,
            centroid,
            central: [e(0, 0), e(1, 1), e(2, 2), e(0, 1), e(0, 2), e(1, 2)],
        }
    }

    /// The moments of `face`, or `None` if an index is out of range.
    #[inline]
    pub(crate) fn of(positions: &[[f64; 3]], face: &[u32; 3]) -> Option<FaceMoment> {
        let [a, b, c] = face.map(|v| positions.get(v as usize));
        Some(FaceMoment::new(*a?, *b?, *c?))
    }

    /// The mean of the corners.
    #[inline]
    pub(crate) fn centroid(&self) -> V3 {
        self.centroid
    }
}

/// Running sums of weight, first moment and second moment about the reference origin.
/// One accumulator holds either triangles or points, not both.
#[derive(Clone, Copy, Debug, Default)]
pub(crate) struct Moments {
    kind: Kind,
    /// Scaled total weight (see [`Kind`]).
    weight: f64,
    first: V3,
    /// Second moment `Σ w x xᵀ`, same layout as [`Sym3`].
    second: [f64; 6],
}

impl Moments {
    /// Adds the uniform area distribution of triangle `(p, q, r)`.
    ///
    /// With `s = p + q + r = 3m`, the second-moment term `9 m mᵀ` is `s sᵀ`, and the
    /// factors ½ (area from the cross product), ⅓ and 1/12 are applied once in
    /// [`Moments::covariance`]: the per-triangle work is one square root, no division.
    #[inline]
    pub(crate) fn add_triangle(&mut self, p: V3, q: V3, r: V3) {
        let n = cross(
            [q[0] - p[0], q[1] - p[1], q[2] - p[2]],
            [r[0] - p[0], r[1] - p[1], r[2] - p[2]],
        );
        let w = norm2(n).sqrt(); // twice the area
        let s = [p[0] + q[0] + r[0], p[1] + q[1] + r[1], p[2] + q[2] + r[2]];
        // Coordinate j of s, p, q, r; `e(j, k)` is Σ over the four of their j·k products.
        let x = [s[0], p[0], q[0], r[0]];
        let y = [s[1], p[1], q[1], r[1]];
        let z = [s[2], p[2], q[2], r[2]];
        let e = |j: [f64; 4], k: [f64; 4]| j[0] * k[0] + j[1] * k[1] + j[2] * k[2] + j[3] * k[3];
        self.weight += w;
        self.first[0] += w * s[0];
        self.first[1] += w * s[1];
        self.first[2] += w * s[2];
        self.second[0] += w * e(x, x);
        self.second[1] += w * e(y, y);
        self.second[2] += w * e(z, z);
        self.second[3] += w * e(x, y);
        self.second[4] += w * e(x, z);
        self.second[5] += w * e(y, z);
        self.kind = Kind::Area;
    }

    /// Adds the uniform area distribution of a face from its [`FaceMoment`], in
    /// coordinates relative to `origin`: with `d` its centroid less the origin, the
    /// corners' `Σ v vᵀ` is the central sum plus `3 d dᵀ`, and the triangle's second-moment
    /// term (see [`Moments::add_triangle`]) `9 d dᵀ + Σ v vᵀ` is the central sum plus
    /// `12 d dᵀ`.
    #[inline]
    pub(crate) fn add_face(&mut self, f: &FaceMoment, origin: V3) {
        let d = sub(f.centroid, origin);
        let wd = scale(d, f.weight);
        let c = &f.central;
        self.weight += f.weight;
        self.first[0] += 3.0 * wd[0];
        self.first[1] += 3.0 * wd[1];
        self.first[2] += 3.0 * wd[2];
        self.second[0] += c[0] + 12.0 * wd[0] * d[0];
        self.second[1] += c[1] + 12.0 * wd[1] * d[1];
        self.second[2] += c[2] + 12.0 * wd[2] * d[2];
        self.second[3] += c[3] + 12.0 * wd[0] * d[1];
        self.second[4] += c[4] + 12.0 * wd[0] * d[2];
        self.second[5] += c[5] + 12.0 * wd[1] * d[2];
        self.kind = Kind::Area;
    }

    /// Adds a unit point mass at `p`.
    #[inline]
    pub(crate) fn add_point(&mut self, p: V3) {
        self.weight += 1.0;
        self.kind = Kind::Points;
        self.first[0] += p[0];
        self.first[1] += p[1];
        self.first[2] += p[2];
        self.second[0] += p[0] * p[0];
        self.second[1] += p[1] * p[1];
        self.second[2] += p[2] * p[2];
        self.second[3] += p[0] * p[1];
        self.second[4] += p[0] * p[2];
        self.second[5] += p[1] * p[2];
    }

    /// Total weight accumulated, up to a positive factor (zero when there is none).
    #[inline]
    pub(crate) fn weight(&self) -> f64 {
        self.weight
    }

    /// The covariance `Σ w x xᵀ / Σ w − m mᵀ`, or `None` when the weight is not positive
    /// or the result is not finite (callers then fall back to another method).
    pub(crate) fn covariance(&self) -> Option<Sym3> {
        let w = self.weight;
        if w.is_nan() || w <= 0.0 || w.is_infinite() {
            return None;
        }
        let (first_scale, second_scale) = match self.kind {
            Kind::Area => (1.0 / (3.0 * w), 1.0 / (12.0 * w)),
            Kind::Points => (1.0 / w, 1.0 / w),
            Kind::Empty => return None,
        };
        let m = self.first.map(|v| v * first_scale);
        let s = self.second.map(|v| v * second_scale);
        let c = Sym3([
            s[0] - m[0] * m[0],
            s[1] - m[1] * m[1],
            s[2] - m[2] * m[2],
            s[3] - m[0] * m[1],
            s[4] - m[0] * m[2],
            s[5] - m[1] * m[2],
        ]);
        c.is_finite().then_some(c)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A face's moments moved to an origin by the parallel-axis theorem give the same
    /// covariance as the triangle summed from its corners relative to that origin: for
    /// triangles of every shape (slivers included) and size, near and far from the origin.
    #[test]
    fn face_moments_moved_to_an_origin_match_the_triangles_summed_there() {
        let mut state = 0x9e37_79b9_7f4a_7c15_u64;
        let mut next = move || {
            state ^= state << 13;
            state ^= state >> 7;
            state ^= state << 17;
            (state >> 11) as f64 / (1u64 << 53) as f64 * 2.0 - 1.0
        };
        for case in 0..2000 {
            let scale = [1e-3, 1.0, 1e3][case % 3];
            let far = [0.0, 1.0, 1e4][case / 3 % 3];
            let mut corner = || [0, 1, 2].map(|_| far + scale * next());
            let mut faces = [[[0.0; 3]; 3]; 4];
            for f in &mut faces {
                *f = [corner(), corner(), corner()];
            }
            if case % 7 == 0 {
                // A sliver: the third corner on the first edge, nearly.
                let [p, q, _] = faces[0];
                faces[0][2] = [0, 1, 2].map(|k| 0.5 * (p[k] + q[k]) + 1e-9 * scale);
            }
            let origin = faces[0][0];
            let (mut corners, mut moved) = (Moments::default(), Moments::default());
            for [p, q, r] in faces {
                corners.add_triangle(sub(p, origin), sub(q, origin), sub(r, origin));
                moved.add_face(&FaceMoment::new(p, q, r), origin);
            }
            let (a, b) = (corners.covariance().unwrap(), moved.covariance().unwrap());
            let size = a.max_abs();
            // Relative to the squared coordinates' size: the rounding of either sum.
            let tolerance = 1e-12 * (size + (far * far + scale * scale) * 1e-4);
            for (x, y) in a.0.iter().zip(b.0) {
                assert!(
                    (x - y).abs() <= tolerance,
                    "case {case}: {a:?} against {b:?}"
                );
            }
        }
    }
}
