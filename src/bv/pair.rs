//! Tests between two volumes of two posed models: overlap, a lower bound on their distance,
//! an upper bound on their largest distance. Everything is in f64 in the frame of box A
//! (or of model A for spheres), whatever the stored precision.

use crate::pose::Pose;
use nalgebra::{Matrix3, Vector3};

/// The guard added to every `|R_ij|` in the separating-axis test (dissertation §4.5): when
/// two box edges are nearly parallel their cross product is nearly zero and rounding alone
/// could report a separation; the guard makes the test conservative there.
pub const SAT_GUARD: f64 = 1e-6;

/// Relative error of the centre offset's projections that f64 rounding alone can cause
/// (a few roundings of products and sums of `|t|`-sized terms), with a wide margin.
pub const OFFSET_ROUNDING: f64 = 64.0 * f64::EPSILON;

/// The margins that keep an overlap test conservative under rounding: volumes that may
/// touch are never reported apart.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Guard {
    /// Added to every `|R_ij|` of the separating-axis test (§4.5): [`SAT_GUARD`] in
    /// queries, 0 only to show why it is needed. Boxes only.
    pub rotation: f64,
    /// Added to every comparison (model units of A): the rounding of mapping B's points,
    /// box centres and triangle vertices alike, into A's frame. It grows with the
    /// coordinates' magnitude, not with the volumes, so it decides for small volumes far
    /// from their model's origin. Boxes only: sphere tests bound it pair by pair.
    pub mapping: f64,
}

impl Guard {
    /// `rotation` and no mapping slack: right only for volumes whose coordinates are not
    /// many orders of magnitude larger than the volumes (unit tests near the origin).
    pub const fn rotation_only(rotation: f64) -> Guard {
        Guard {
            rotation,
            mapping: 0.0,
        }
    }

    /// The guard of a query between two models: `rotation`, and the mapping slack for
    /// points of A within the ball `a` (centre and radius, A's frame) and of B within the
    /// ball `b` (B's frame), B posed in A's frame by `b_to_a`.
    pub fn for_models(
        rotation: f64,
        a: ([f64; 3], f64),
        b: ([f64; 3], f64),
        b_to_a: &Pose,
    ) -> Guard {
        // A point's 1-norm within a ball is at most the centre's plus √3 radii.
        let magnitude = |(c, r): ([f64; 3], f64)| super::l1(&c) + 3f64.sqrt() * r;
        let translation = b_to_a.translation_vector().abs().sum();
        // Mapping rounds a few ulps of |p|₁ + |T|₁, and the difference with A's centre
        // a few of |c_A|₁; once for B's box centre, once for its vertices.
        let coordinates = magnitude(a) + magnitude(b) + translation;
        Guard {
            rotation,
            mapping: 2.0 * OFFSET_ROUNDING * coordinates,
        }
    }
}

/// Alternating projections after the first pair in [`BoxPair::closest_direction_gap`]:
/// each costs about 40 flops; more steps tighten the bound a little (a few fewer pairs
/// per extra step on the benchmark meshes) and cost more than they save.
const PROJECTION_STEPS: usize = 1;
/// How near the closest-direction gap must come to the distance of the points it was
/// taken between (at least the box distance) for the edge-edge axes to be skipped: they
/// could then raise the bound by at most 10%.
pub(crate) const CONVERGED: f64 = 0.9;

/// Two boxes in the frame of box A: A is centred at the origin with axes along x, y, z and
/// half-widths `ha`; B is centred at `t` with axes the columns of `m` and half-widths `hb`.
#[derive(Clone, Copy, Debug)]
pub struct BoxPair {
    /// B's axes in A's box frame (columns).
    pub m: Matrix3<f64>,
    /// B's centre in A's box frame.
    pub t: Vector3<f64>,
    /// A's half-widths.
    pub ha: Vector3<f64>,
    /// B's half-widths.
    pub hb: Vector3<f64>,
    /// How far the two box frames may be from orthonormal: the largest `|a_i·a_j − δ_ij|`
    /// of either frame (0 for exact frames). Expressing B's centre in A's box frame treats
    /// A's axes as orthonormal, so every projection of `t` other than on A's own axes is
    /// off by up to about `4 · frame_error · |t|`; see [`BoxPair::slack`].
    pub frame_error: f64,
}

impl BoxPair {
    /// Expresses box B (axes as rows `b_axes`, centre `cb`, in model B's frame) in box A's
    /// frame (axes as rows `a_axes`, centre `ca`, in model A's frame). `frame_error` bounds
    /// the frames' departure from orthonormality (see [`BoxPair::frame_error`]).
    #[inline]
    #[allow(clippy::too_many_arguments)]
    pub fn new(
        a_axes: &Matrix3<f64>,
        ca: &Vector3<f64>,
        ha: Vector3<f64>,
        b_axes: &Matrix3<f64>,
        cb: &Vector3<f64>,
        hb: Vector3<f64>,
        b_to_a: &Pose,
        frame_error: f64,
    ) -> BoxPair {
        let offset = b_to_a.apply(cb) - ca;
        BoxPair::from_offset(
            a_axes,
            ha,
            b_axes,
            hb,
            &offset,
            b_to_a.rotation(),
            frame_error,
        )
    }

    /// As [`BoxPair::new`], given the centre offset `offset = b_to_a(cb) − ca` (model A's
    /// frame) and the rotation of `b_to_a`.
    #[inline(always)]
    pub fn from_offset(
        a_axes: &Matrix3<f64>,
        ha: Vector3<f64>,
        b_axes: &Matrix3<f64>,
        hb: Vector3<f64>,
        offset: &Vector3<f64>,
        rotation: &Matrix3<f64>,
        frame_error: f64,
    ) -> BoxPair {
        BoxPair {
            m: a_axes * rotation * b_axes.transpose(),
            t: a_axes * offset,
            ha,
            hb,
            frame_error,
        }
    }

    /// The absolute slack added to every separating-axis comparison (model units of A):
    ///
    /// - `guard` times the sum of both boxes' half-widths: a box frame off orthonormal by
    ///   δ misplaces the box's own extent by about δ times its size (f32 frames: δ ≈ 2e-7,
    ///   within the 1e-6 guard), which the rotation guard alone covers only through the
    ///   other box's half-widths (found by fuzzing: a thin box touching another was reported
    ///   disjoint);
    /// - `(4 · frame_error + OFFSET_ROUNDING)` times `|t|₁`: the error of projecting the
    ///   centre offset through frames that are not exactly orthonormal, and of rounding.
    ///
    /// The second term once used the guard too, which for models 1e6 apart inflated every
    /// box by the size of the model and made distance queries visit nearly every leaf pair;
    /// it is now as small as the frames allow, and frames far apart are re-orthonormalised
    /// (see [`crate::bv::Obb`]) so that it stays at the rounding level.
    #[inline(always)]
    pub fn slack(&self, guard: f64) -> f64 {
        let (a, b, t) = (&self.ha, &self.hb, &self.t);
        guard * (a.x + a.y + a.z + b.x + b.y + b.z)
            + (4.0 * self.frame_error + OFFSET_ROUNDING) * (t.x.abs() + t.y.abs() + t.z.abs())
    }

    /// Whether the boxes are disjoint, by the 15 separating axes of §4.3, with the guard's
    /// rotation term added to the absolute rotation entries. Conservative: overlapping
    /// boxes are never reported disjoint.
    ///
    /// Every comparison also gets the [`BoxPair::slack`] of frames that are not exactly
    /// orthonormal (f32 axes) and of rounding, and the guard's mapping slack.
    #[inline(always)]
    // why: 3x3 matrix / 3-vector entries indexed by axis numbers in 0..3 (loop counters and
    // their cyclic successors); the hottest test of every query, kept in the book's form.
    #[allow(clippy::indexing_slicing)]
    pub fn disjoint(&self, guard: Guard) -> bool {
        let (m, t, a, b) = (&self.m, &self.t, &self.ha, &self.hb);
        let abs = m.abs().add_scalar(guard.rotation);
        let slack = self.slack(guard.rotation) + guard.mapping;
        if self.separated_on_a_faces(&abs, slack) {
            return true;
        }
        // B's face axes.
        for j in 0..3 {
            let ra = a[0] * abs[(0, j)] + a[1] * abs[(1, j)] + a[2] * abs[(2, j)];
            let tj = t[0] * m[(0, j)] + t[1] * m[(1, j)] + t[2] * m[(2, j)];
            if tj.abs() > ra + b[j] + slack {
                return true;
            }
        }
        // Edge-edge axes a_i x b_j.
        for i in 0..3 {
            let (i1, i2) = ((i + 1) % 3, (i + 2) % 3);
            for j in 0..3 {
                let (j1, j2) = ((j + 1) % 3, (j + 2) % 3);
                let ra = a[i1] * abs[(i2, j)] + a[i2] * abs[(i1, j)];
                let rb = b[j1] * abs[(i, j2)] + b[j2] * abs[(i, j1)];
                let tl = t[i2] * m[(i1, j)] - t[i1] * m[(i2, j)];
                if tl.abs() > ra + rb + slack {
                    return true;
                }
            }
        }
        false
    }

    /// Whether the boxes are disjoint by A's three face axes alone: B's box re-wrapped in
    /// the axis-aligned box of A's box frame that contains it, tested against A. This is
    /// the AABB test as the dissertation's experiments ran it (§5.2.2): cheaper than
    /// [`BoxPair::disjoint`], and it reports fewer disjoint pairs. Conservative, with the
    /// same guard and slack.
    #[inline(always)]
    pub fn rewrapped_disjoint(&self, guard: Guard) -> bool {
        let abs = self.m.abs().add_scalar(guard.rotation);
        self.separated_on_a_faces(&abs, self.slack(guard.rotation) + guard.mapping)
    }

    /// The first three separating axes: A's faces, with `abs` the guarded `|m|`.
    #[inline(always)]
    // why: as in `disjoint`, axis numbers in 0..3.
    #[allow(clippy::indexing_slicing)]
    fn separated_on_a_faces(&self, abs: &Matrix3<f64>, slack: f64) -> bool {
        let (t, a, b) = (&self.t, &self.ha, &self.hb);
        for i in 0..3 {
            let rb = b[0] * abs[(i, 0)] + b[1] * abs[(i, 1)] + b[2] * abs[(i, 2)];
            if t[i].abs() > a[i] + rb + slack {
                return true;
            }
        }
        false
    }

    /// A lower bound on the distance between the boxes: [`BoxPair::distance_lower_bound_until`]
    /// with every term.
    #[inline]
    pub fn distance_lower_bound(&self) -> f64 {
        self.distance_lower_bound_until(f64::INFINITY)
    }

    /// A lower bound on the distance between the boxes, the largest of three terms, in
    /// order of cost, stopping once one reaches `enough`:
    ///
    /// - the gaps between their projections on the 6 face axes (tight for boxes side by
    ///   side; B's three prune little between mesh pairs, but between concentric
    ///   spheres, one turned, they save pairs and time with a relative error allowed);
    /// - the gap on the direction between nearly closest points
    ///   ([`BoxPair::closest_direction_gap`]), near the box distance wherever the axis gaps
    ///   fall short of it: up to a factor √3 for boxes diagonal to each other, and without
    ///   limit for boxes far apart relative to their size;
    /// - where the second falls short of the distance of the points it was taken between
    ///   by more than a tenth, the gaps on the 9 edge-edge axes, each divided by the axis
    ///   length.
    ///
    /// Each is lowered by the frame [`BoxPair::slack`], as `disjoint` raises its radii by
    /// it. 0 if the boxes may touch.
    #[inline(always)]
    // why: as in `disjoint`, entries indexed by axis numbers in 0..3.
    #[allow(clippy::indexing_slicing)]
    pub fn distance_lower_bound_until(&self, enough: f64) -> f64 {
        let (m, t, a, b) = (&self.m, &self.t, &self.ha, &self.hb);
        let abs = m.abs();
        let slack = self.slack(SAT_GUARD);
        let mut best = 0.0f64;
        for i in 0..3 {
            let rb = b[0] * abs[(i, 0)] + b[1] * abs[(i, 1)] + b[2] * abs[(i, 2)];
            best = best.max(t[i].abs() - a[i] - rb - slack);
        }
        for j in 0..3 {
            let ra = a[0] * abs[(0, j)] + a[1] * abs[(1, j)] + a[2] * abs[(2, j)];
            let tj = t[0] * m[(0, j)] + t[1] * m[(1, j)] + t[2] * m[(2, j)];
            best = best.max(tj.abs() - ra - b[j] - slack);
        }
        if best >= enough {
            return best;
        }
        let (gap, apart) = self.closest_direction_gap();
        best = best.max(gap - slack);
        // `apart` is the distance of a pair of points of the boxes, at least the box
        // distance: a gap near it is near the distance, and the edge axes can add little.
        if best >= enough || gap >= CONVERGED * apart {
            return best;
        }
        best.max(self.edge_axis_gap(&abs, slack))
    }

    /// The largest gap between the boxes' projections on the 9 edge-edge axes `a_i × b_j`,
    /// each divided by the axis length, less `slack` (`abs` holds the `|m_ij|`); axes shorter than 1e-6 (nearly
    /// parallel edges, whose direction rounding makes meaningless) are skipped.
    #[inline]
    // why: as in `disjoint`, entries indexed by axis numbers in 0..3.
    #[allow(clippy::indexing_slicing)]
    fn edge_axis_gap(&self, abs: &Matrix3<f64>, slack: f64) -> f64 {
        let (m, t, a, b) = (&self.m, &self.t, &self.ha, &self.hb);
        let mut best = 0.0f64;
        for i in 0..3 {
            let (i1, i2) = ((i + 1) % 3, (i + 2) % 3);
            for j in 0..3 {
                // |a_i x b_j| from the two entries it is made of: `1 - m_ij^2` is the same
                // for orthonormal frames, but cancels for nearly parallel edges, where a pose
                // orthonormal only within its tolerance makes it far too short.
                let len2 = m[(i1, j)] * m[(i1, j)] + m[(i2, j)] * m[(i2, j)];
                if len2 < 1e-12 {
                    continue;
                }
                let (j1, j2) = ((j + 1) % 3, (j + 2) % 3);
                let ra = a[i1] * abs[(i2, j)] + a[i2] * abs[(i1, j)];
                let rb = b[j1] * abs[(i, j2)] + b[j2] * abs[(i, j1)];
                let tl = t[i2] * m[(i1, j)] - t[i1] * m[(i2, j)];
                let gap = tl.abs() - ra - rb - slack;
                // gap / |axis| > best, without a square root unless it is.
                if gap > 0.0 && gap * gap > best * best * len2 {
                    best = gap / len2.sqrt();
                }
            }
        }
        best
    }

    /// The gap between the boxes' projections on the direction between two points found
    /// by alternating projections (B's centre clamped into A, that point's nearest in B,
    /// and so on): the iteration converges to the closest pair, whose direction separates
    /// the boxes by exactly their distance, and any unit direction gives a lower bound, so
    /// a few steps give a bound near the true box distance where the axis gaps can be short
    /// of it by a factor up to √3 (boxes diagonal to each other, about their size apart:
    /// most of the pairs a distance query opens). 0 if the points meet, which happens
    /// only when the boxes intersect (each point lies in its box).
    ///
    /// Returns the gap and the distance between the two points (a point of each box, so
    /// at least the box distance: a gap near it is near the box distance).
    #[inline]
    pub fn closest_direction_gap(&self) -> (f64, f64) {
        let (m, t, a, b) = (&self.m, &self.t, &self.ha, &self.hb);
        let mut p = clamp_box(t, a);
        let mut q = t + m * clamp_box(&m.tr_mul(&(p - t)), b);
        for _ in 0..PROJECTION_STEPS {
            p = clamp_box(&q, a);
            q = t + m * clamp_box(&m.tr_mul(&(p - t)), b);
        }
        // Normalised through its largest component, so that points 1e300 apart (whose
        // squared distance overflows) still give a direction.
        let d = q - p;
        let scale = d.amax();
        if !(scale > 0.0 && scale.is_finite()) {
            return (0.0, 0.0);
        }
        // The gap is positively homogeneous in the direction: taken along the unscaled
        // one and divided by its length once (two divisions where a unit vector took six).
        let direction = d * (1.0 / scale);
        let length = direction.norm();
        let along_b = m.tr_mul(&direction);
        let gap = (direction.dot(t) - a.dot(&direction.abs()) - b.dot(&along_b.abs())) / length;
        (gap, scale * length)
    }

    /// The largest distance between a point of A and a point of B, exactly: the maximum of
    /// a convex function over two boxes is attained at corners, and for each corner `p` of A
    /// the farthest point of B is the corner opposite `p` along each of B's axes, at squared
    /// distance `|p - t|^2 + 2 Σ_j hb_j |(p - t)·b_j| + |hb|^2`; plus the slack of
    /// [`BoxPair::frame_error`] (none for exact frames but rounding).
    #[inline]
    pub fn max_distance(&self) -> f64 {
        let (m, t, a, b) = (&self.m, &self.t, &self.ha, &self.hb);
        let hb2 = b.norm_squared();
        let mut best = 0.0f64;
        for corner in 0..8 {
            let p = Vector3::new(
                if corner & 1 == 0 { -a.x } else { a.x },
                if corner & 2 == 0 { -a.y } else { a.y },
                if corner & 4 == 0 { -a.z } else { a.z },
            );
            let d = p - t;
            let along = m.tr_mul(&d);
            let d2 = d.norm_squared()
                + 2.0 * (b.x * along.x.abs() + b.y * along.y.abs() + b.z * along.z.abs())
                + hb2;
            best = best.max(d2);
        }
        // Raised by the frames' own slack (as `disjoint` raises its radii by the guard's):
        // frames that are not exactly orthonormal could otherwise make this "upper" bound a
        // little short.
        best.sqrt() + self.slack(self.frame_error)
    }
}

/// The point of the box `[-h, h]` nearest to `x` (`h` non-negative). Plain comparisons
/// rather than `f64::clamp`, which checks its bounds on every call (and panics on NaN
/// ones: here a NaN, from a damaged file, passes through and voids the bound).
#[inline(always)]
fn clamp_box(x: &Vector3<f64>, h: &Vector3<f64>) -> Vector3<f64> {
    let clamp = |v: f64, h: f64| {
        if v > h {
            h
        } else if v < -h {
            -h
        } else {
            v
        }
    };
    Vector3::new(clamp(x.x, h.x), clamp(x.y, h.y), clamp(x.z, h.z))
}

/// How a box pair is set up: [`Fast`](PairSetup::Fast) takes the stored frames as they are
/// and covers their error with [`BoxPair::slack`] (right for overlap tests, where only
/// boxes within about their own size of each other matter); [`Metric`](PairSetup::Metric)
/// is for distance bounds, which must stay tight for boxes any distance apart.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum PairSetup {
    Fast,
    Metric,
}

/// The pair tests and size measures shared by the two box volumes, written once: both types
/// provide `disjoint(&self, &Self, &Pose, guard) -> bool` (the separating-axis test),
/// `distance_bound(&self, &Self, &Pose, enough) -> (f64, f64)` (the distance lower bound
/// and the centres' distance),
/// `pair_with(&self, &Self, &Pose, PairSetup) -> BoxPair`,
/// `half_f64(&self) -> [f64; 3]` and `local_box(&self)` (centre, axes as rows, half-widths,
/// frame error, all f64 in the model frame).
macro_rules! box_pair_methods {
    () => {
        #[inline]
        fn overlaps(&self, other: &Self, b_to_a: &Pose, guard: $crate::bv::pair::Guard) -> bool {
            !self.disjoint(other, b_to_a, guard)
        }

        #[inline]
        fn overlaps_rewrapped(
            &self,
            other: &Self,
            b_to_a: &Pose,
            guard: $crate::bv::pair::Guard,
        ) -> bool {
            !self
                .pair_with(other, b_to_a, $crate::bv::pair::PairSetup::Fast)
                .rewrapped_disjoint(guard)
        }

        #[inline]
        fn distance_lower_bound_until(&self, other: &Self, b_to_a: &Pose, enough: f64) -> f64 {
            self.distance_bound(other, b_to_a, enough).0
        }

        /// `|t|`, B's centre in A's box frame, is the centres' distance.
        #[inline]
        fn distance_lower_bound_and_centres_until(
            &self,
            other: &Self,
            b_to_a: &Pose,
            enough: f64,
        ) -> (f64, f64) {
            self.distance_bound(other, b_to_a, enough)
        }

        #[inline]
        fn max_distance_upper_bound(&self, other: &Self, b_to_a: &Pose) -> f64 {
            self.pair_with(other, b_to_a, $crate::bv::pair::PairSetup::Metric)
                .max_distance()
        }

        fn world_aabb(&self, pose: &Pose) -> $crate::bv::Aabb<f64> {
            let (center, axes, half, frame_error) = self.local_box();
            $crate::bv::posed_box_aabb(&center, &axes, &half, frame_error, pose)
        }

        #[inline]
        fn center(&self) -> [f64; 3] {
            self.local_box().0.into()
        }

        fn enclosing_ball(&self) -> ([f64; 3], f64) {
            let (center, _, half, frame_error) = self.local_box();
            // Axes within `frame_error` of orthonormal stretch a box's half-diagonal by at
            // most 2.5 times that share; the norm, and an AABB's centre and half-widths
            // (halved sums), are off by a few ulps of their magnitudes.
            let radius = half.norm() * (1.0 + 4.0 * frame_error + 8.0 * f64::EPSILON)
                + 4.0 * f64::EPSILON * center.abs().sum();
            (center.into(), radius)
        }

        fn diameter(&self) -> f64 {
            $crate::bv::obb::box_measures(self.half_f64()).0
        }

        fn thickness(&self) -> f64 {
            let [x, y, z] = self.half_f64();
            2.0 * x.min(y).min(z)
        }

        fn volume(&self) -> f64 {
            $crate::bv::obb::box_measures(self.half_f64()).1
        }

        fn surface_area(&self) -> f64 {
            $crate::bv::obb::box_measures(self.half_f64()).2
        }
    };
}
pub(crate) use box_pair_methods;

#[cfg(test)]
mod tests {
    use super::*;
    use crate::bv::BoundingVolume;
    use crate::generate::Rng;

    /// Each half of a model pair's mapping slack bounds the error of mapping one point of
    /// B's ball into A's frame and taking its offset from a point of A's ball, measured in
    /// double-double arithmetic: under random rotations, for balls near the origin and
    /// 1e6 from it, of radius 1e-3, 1 and 1e6, and translations small and large.
    #[test]
    fn the_mapping_slack_bounds_the_rounding_of_a_mapped_offset() {
        let mut rng = Rng::new(41);
        let mut worst = [0.0f64; 8];
        for k in 0..3000 {
            let (far_a, far_b, far_t, size) = [
                (0.0, 0.0, 1.0, 1.0),
                (1e6, 0.0, 1e6, 1.0),
                (1e6, 1e6, 1.0, 1.0),
                (0.0, 1e6, 1e6, 1.0),
                (0.0, 0.0, 1e6, 1.0),
                (0.0, 0.0, 1.0, 1e6),
                (0.0, 0.0, 1e6, 1e-3),
                (0.0, 0.0, 1e-3, 1e-3),
            ][k % 8];
            let signed = |rng: &mut Rng| Vector3::new(rng.signed(), rng.signed(), rng.signed());
            let (ca, cb) = (
                signed(&mut rng) * size + Vector3::repeat(far_a),
                signed(&mut rng) * size + Vector3::repeat(far_b),
            );
            let (ra, rb) = ((1.0 + rng.unit()) * size, (1.0 + rng.unit()) * size);
            let b_to_a =
                Pose::new(rng.uniform_rotation(), signed(&mut rng) * far_t).expect("a rotation");
            let guard = Guard::for_models(SAT_GUARD, (ca.into(), ra), (cb.into(), rb), &b_to_a);
            assert_eq!(guard.rotation, SAT_GUARD);
            // Points on the balls' surfaces, where the magnitudes are largest.
            let direction = |rng: &mut Rng| signed(rng).normalize();
            let p = ca + direction(&mut rng) * ra;
            let q = cb + direction(&mut rng) * rb;
            let computed = b_to_a.apply(&q) - p;
            let (rotation, t) = (b_to_a.rotation(), b_to_a.translation_vector());
            for i in 0..3 {
                // The exact offset less the computed one, as a sum of doubles, each term
                // exact.
                let mut terms = vec![t[i], -p[i], -computed[i]];
                for j in 0..3 {
                    let (product, error) = crate::bv::two_prod(rotation[(i, j)], q[j]);
                    terms.extend([product, error]);
                }
                let (hi, lo) = crate::bv::double_double_sum(&terms);
                let error = (hi + lo).abs();
                assert!(
                    error <= guard.mapping / 2.0,
                    "case {k}: error {error:e}, {guard:?}"
                );
                worst[k % 8] = worst[k % 8].max(error / guard.mapping);
            }
        }
        // A bound of the rounding, not a multiple of the coordinates, in every kind of case
        // (catches a slack inflated by orders of magnitude, which would open far more box
        // pairs).
        assert!(
            worst.iter().all(|w| *w > 5e-4),
            "worst errors {worst:?} of the slack"
        );
    }

    /// The mapping slack widens every comparison of the box tests: boxes side by side
    /// along each axis of A, a gap `g` apart, overlap with a slack of `g` and are
    /// disjoint with one of `g / 2`.
    #[test]
    fn the_mapping_slack_widens_each_box_comparison() {
        let gap = 1e-3;
        for axis in 0..3 {
            let mut t = Vector3::zeros();
            t[axis] = 2.0 + gap;
            let pair = BoxPair {
                m: Matrix3::identity(),
                t,
                ha: Vector3::repeat(1.0),
                hb: Vector3::repeat(1.0),
                frame_error: 0.0,
            };
            let with = |mapping: f64| Guard {
                rotation: 0.0,
                mapping,
            };
            assert!(!pair.disjoint(with(gap)), "axis {axis}");
            assert!(pair.disjoint(with(gap / 2.0)), "axis {axis}");
            assert!(!pair.rewrapped_disjoint(with(gap)), "axis {axis}");
            assert!(pair.rewrapped_disjoint(with(gap / 2.0)), "axis {axis}");
            // The f32 test on the stored values, whose own rounding slack is far below g.
            let unit = |center: Vector3<f64>| crate::bv::Obb::<f32> {
                axes: [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]],
                center: center.map(|c| c as f32).into(),
                half: [1.0; 3],
            };
            let (a, b) = (unit(Vector3::zeros()), unit(t));
            let identity = Pose::identity();
            assert!(a.overlaps(&b, &identity, with(gap)), "f32, axis {axis}");
            assert!(
                !a.overlaps(&b, &identity, with(gap / 2.0)),
                "f32, axis {axis}"
            );
        }
    }

    /// Two sticks along x, B turned by 1e-8 about z (so that `m₀₀` rounds to exactly 1
    /// while `m₁₀` does not vanish) and 1000 above A: the edge axis `a₀ × b₀` has length 0
    /// in f64 but a positive gap, which divided by that length would be an infinite
    /// "lower bound". Such axes are skipped; what is left is no more than the distance.
    #[test]
    fn edge_axes_of_nearly_parallel_edges_are_skipped() {
        let angle: f64 = 1e-8;
        let (c, s) = (angle.cos(), angle.sin());
        assert_eq!(c, 1.0);
        let pair = BoxPair {
            m: Matrix3::new(c, -s, 0.0, s, c, 0.0, 0.0, 0.0, 1.0),
            t: Vector3::new(0.0, 0.0, 1000.0),
            ha: Vector3::new(1.0, 0.0, 0.0),
            hb: Vector3::new(1.0, 0.0, 0.0),
            frame_error: 0.0,
        };
        let gap = pair.edge_axis_gap(&pair.m.abs(), pair.slack(SAT_GUARD));
        assert!(gap.is_finite() && gap <= 1000.0, "{gap}");
    }
}
