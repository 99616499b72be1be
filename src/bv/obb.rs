//! Oriented bounding box (dissertation §3.2).

use super::pair::{box_pair_methods, BoxPair, Guard, PairSetup, SAT_GUARD};
use super::{
    all_finite, face_vertices, l1, listed_vertices, model_axes_frame, projection_slack,
    BoundingVolume, BvDefect, BvKind,
};
use crate::arr3::{self, dot};
use crate::pose::Pose;
use crate::real::{point_to_f64, Precision, Real};
use nalgebra::{Matrix3, Vector3};
use zerocopy::{FromBytes, Immutable, KnownLayout};

/// An oriented box: the points `c + Σ t_i a_i` with `|t_i| <= h_i`, in the model frame.
///
/// # Memory Layout
///
/// `#[repr(C)]`, 15 scalars: `axes` (3 unit vectors, one per row: `axes[i]` is box axis `i`
/// in model coordinates; axis 0 has the greatest spread), `center`, `half` (half-widths along
/// each axis, in model units). 60 bytes in f32, 120 in f64.
#[derive(Clone, Copy, Debug, PartialEq, FromBytes, KnownLayout, Immutable)]
#[repr(C)]
pub struct Obb<R> {
    /// Box axes as rows, orthonormal up to the stored precision.
    pub axes: [[R; 3]; 3],
    /// Box centre, model frame.
    pub center: [R; 3],
    /// Half-widths along `axes`, non-negative, model units.
    pub half: [R; 3],
}

impl<R: Real> Obb<R> {
    /// The axes as the rows of a matrix, widened.
    #[inline]
    pub fn axes_matrix(&self) -> Matrix3<f64> {
        let a = &self.axes;
        Matrix3::new(
            a[0][0].to_f64(),
            a[0][1].to_f64(),
            a[0][2].to_f64(),
            a[1][0].to_f64(),
            a[1][1].to_f64(),
            a[1][2].to_f64(),
            a[2][0].to_f64(),
            a[2][1].to_f64(),
            a[2][2].to_f64(),
        )
    }

    /// The pair in box A's frame.
    ///
    /// Stored frames are orthonormal only within the precision's axis tolerance δ (1e-6 for
    /// f32, 1e-10 for f64), and projecting the centre offset `t` through them errs by about
    /// `4δ|t|`, which [`BoxPair::slack`] covers. For an overlap test that is nothing: only
    /// boxes within about their own size of each other can overlap. For a distance bound
    /// between boxes far apart relative to their size (models 1e6 apart) it would swamp the
    /// bound, so the metric setup then (past [`FAR`]) re-orthonormalises both frames in f64
    /// and widens the half-widths to cover the move, leaving only rounding in the slack.
    #[inline(always)]
    fn pair_with(&self, other: &Self, b_to_a: &Pose, setup: PairSetup) -> BoxPair {
        let tol = axis_tolerance(R::PRECISION);
        let ca = Vector3::from(self.center_f64());
        let cb = Vector3::from(other.center_f64());
        let (ha, hb) = (
            Vector3::from(self.half_f64()),
            Vector3::from(other.half_f64()),
        );
        let offset = b_to_a.apply(&cb) - ca;
        let (axes_a, axes_b) = (self.axes_matrix(), other.axes_matrix());
        // (Overlap tests never re-orthonormalise: the frame term is only worked out for
        // distance bounds.)
        if setup == PairSetup::Metric
            && frames_far_apart(tol, offset.abs().sum(), ha.sum() + hb.sum())
        {
            return BoxPair::from_offset(
                &orthonormal_rows(&axes_a),
                widen(ha, tol),
                &orthonormal_rows(&axes_b),
                widen(hb, tol),
                &offset,
                b_to_a.rotation(),
                0.0,
            );
        }
        BoxPair::from_offset(&axes_a, ha, &axes_b, hb, &offset, b_to_a.rotation(), tol)
    }

    /// The distance lower bound ([`BoxPair::distance_lower_bound_until`]) and the centres'
    /// distance: for f32 boxes on the stored values ([`super::pair_f32`]), in f64 where
    /// the bound would re-orthonormalise the frames or the pair is beyond f32's range.
    #[inline(always)]
    fn distance_bound(&self, other: &Self, b_to_a: &Pose, enough: f64) -> (f64, f64) {
        if R::PRECISION == Precision::F32 {
            let tol = axis_tolerance(R::PRECISION);
            let far = |offset_norm1, halves| frames_far_apart(tol, offset_norm1, halves);
            if let Some(bound_and_centres) =
                super::pair_f32::distance_lower_bound_until(self, other, b_to_a, enough, far)
            {
                return bound_and_centres;
            }
        }
        let pair = self.pair_with(other, b_to_a, PairSetup::Metric);
        (pair.distance_lower_bound_until(enough), pair.t.norm())
    }

    /// The separating-axis test: on the stored values where they are f32
    /// ([`super::pair_f32`]), else in f64 ([`BoxPair::disjoint`]).
    #[inline(always)]
    fn disjoint(&self, other: &Self, b_to_a: &Pose, guard: Guard) -> bool {
        if R::PRECISION == Precision::F32 {
            super::pair_f32::disjoint(self, other, b_to_a, guard)
        } else {
            self.pair_with(other, b_to_a, PairSetup::Fast)
                .disjoint(guard)
        }
    }

    /// Centre, axes (rows), half-widths and the frame's orthonormality tolerance, in f64.
    fn local_box(&self) -> (Vector3<f64>, Matrix3<f64>, Vector3<f64>, f64) {
        (
            Vector3::from(self.center_f64()),
            self.axes_matrix(),
            Vector3::from(self.half_f64()),
            axis_tolerance(R::PRECISION),
        )
    }

    /// The axes widened to f64, one per row.
    pub fn axes_f64(&self) -> [[f64; 3]; 3] {
        self.axes.map(|a| point_to_f64(&a))
    }
    /// The centre widened to f64.
    pub fn center_f64(&self) -> [f64; 3] {
        point_to_f64(&self.center)
    }
    /// The half-widths widened to f64.
    pub fn half_f64(&self) -> [f64; 3] {
        point_to_f64(&self.half)
    }

    /// The box of `points` along `frame`'s columns (see [`BoundingVolume::enclose`]).
    fn enclose_points<'a>(
        frame: &Matrix3<f64>,
        points: impl Iterator<Item = &'a [f64; 3]>,
    ) -> Self {
        let axes_r = rounded_rows::<R>(frame);
        let scan = Scan::of::<false>(&axes_r.map(|row| point_to_f64(&row)), points);
        Self::from_extremes(axes_r, scan.lo, scan.hi, scan.l1_max)
    }

    /// [`Obb::enclose_points`] along `frame` and along the model's own axes
    /// ([`model_axes_frame`] of the points), in one pass: the coordinates' extremes are
    /// the projections on the model axes, and the largest `|p|₁` is the same for both.
    fn enclose_points_fitted_and_aligned<'a>(
        frame: &Matrix3<f64>,
        points: impl Iterator<Item = &'a [f64; 3]>,
    ) -> [(Matrix3<f64>, Self); 2] {
        let axes_r = rounded_rows::<R>(frame);
        let scan = Scan::of::<true>(&axes_r.map(|row| point_to_f64(&row)), points);
        let fitted = Self::from_extremes(axes_r, scan.lo, scan.hi, scan.l1_max);
        let model = model_axes_frame(scan.coord_lo, scan.coord_hi);
        // Each model axis is ±1 on one coordinate and 0 on the others (exact in any
        // precision), so its extremes are those of that coordinate, negated and swapped
        // for -1: the sums below have one non-zero term.
        let model_r = rounded_rows::<R>(&model);
        let m = model_r.map(|row| point_to_f64(&row));
        let (mut lo, mut hi) = ([0.0f64; 3], [0.0f64; 3]);
        for (row, (lo, hi)) in m.iter().zip(lo.iter_mut().zip(hi.iter_mut())) {
            let coords = scan.coord_lo.iter().zip(&scan.coord_hi);
            for (&x, (&coord_lo, &coord_hi)) in row.iter().zip(coords) {
                let (l, h) = if x < 0.0 {
                    (coord_hi, coord_lo)
                } else {
                    (coord_lo, coord_hi)
                };
                *lo += x * l;
                *hi += x * h;
            }
        }
        let aligned = Self::from_extremes(model_r, lo, hi, scan.l1_max);
        [(*frame, fitted), (model, aligned)]
    }

    /// The box along the (rounded) rows `axes_r` whose points project onto row `i` within
    /// `[lo[i], hi[i]]` and have `|p|₁ ≤ l1_max`: centred in the middle of those ranges
    /// (rounded to `R`), with half-widths rounded up and widened by the projections'
    /// rounding. No points (`lo` infinite): an empty box at the origin.
    // why: axis numbers in 0..3 on fixed-size arrays.
    #[allow(clippy::indexing_slicing)]
    fn from_extremes(axes_r: [[R; 3]; 3], lo: [f64; 3], hi: [f64; 3], l1_max: f64) -> Self {
        let a = axes_r.map(|row| point_to_f64(&row));
        let (lo, hi) = if lo[0].is_finite() {
            (lo, hi)
        } else {
            // No vertices (callers never do this).
            ([0.0; 3], [0.0; 3])
        };
        let mid: [f64; 3] = std::array::from_fn(|i| 0.5 * (lo[i] + hi[i]));
        let c: [f64; 3] = std::array::from_fn(|j| (0..3).map(|i| a[i][j] * mid[i]).sum());
        let center = c.map(R::from_f64_nearest);
        let c = point_to_f64(&center);
        let slack = 2.0 * projection_slack(l1_max + l1(&c));
        let half = std::array::from_fn(|i| {
            let d = dot(a[i], c);
            R::from_f64_up((hi[i] - d).max(d - lo[i]).max(0.0) + slack)
        });
        Obb {
            axes: axes_r,
            center,
            half,
        }
    }
}

/// One pass over a box's points: the extremes of their projections on three rows, of their
/// coordinates (when asked: the projections on the model's axes), and of `|p|₁`.
struct Scan {
    lo: [f64; 3],
    hi: [f64; 3],
    coord_lo: [f64; 3],
    coord_hi: [f64; 3],
    l1_max: f64,
}

impl Scan {
    // why: axis numbers in 0..3 on fixed-size arrays. The hottest loop of a build, kept as
    // written: index-free forms were measurably slower.
    #[allow(clippy::indexing_slicing)]
    #[inline(always)]
    fn of<'a, const COORDS: bool>(
        rows: &[[f64; 3]; 3],
        points: impl Iterator<Item = &'a [f64; 3]>,
    ) -> Scan {
        let mut scan = Scan {
            lo: [f64::INFINITY; 3],
            hi: [f64::NEG_INFINITY; 3],
            coord_lo: [f64::INFINITY; 3],
            coord_hi: [f64::NEG_INFINITY; 3],
            l1_max: 0.0,
        };
        for p in points {
            for i in 0..3 {
                let d = dot(rows[i], *p);
                scan.lo[i] = arr3::least(scan.lo[i], d);
                scan.hi[i] = arr3::greatest(scan.hi[i], d);
                if COORDS {
                    scan.coord_lo[i] = arr3::least(scan.coord_lo[i], p[i]);
                    scan.coord_hi[i] = arr3::greatest(scan.coord_hi[i], p[i]);
                }
            }
            scan.l1_max = arr3::greatest(scan.l1_max, l1(p));
        }
        scan
    }
}

/// The columns of `frame` rounded to `R`, one per row: a box is measured along the
/// rounded axes, so that the stored box is exactly the one whose extents were computed.
fn rounded_rows<R: Real>(frame: &Matrix3<f64>) -> [[R; 3]; 3] {
    let [c0, c1, c2]: [[f64; 3]; 3] = (*frame).into();
    [c0, c1, c2].map(|column| column.map(R::from_f64_nearest))
}

/// How many times the guard's share of the slack (`1e-6 · Σh`) the frames' share may reach
/// before a distance bound re-orthonormalises the frames: below it a bound is loosened by
/// at most 1% of the boxes' size, far less than any box overshoots its triangles, so it
/// prunes the same; above it (f32 boxes more than about 2,500 of their sizes apart: the
/// leaves of models 1e6 apart) the frames' error would grow with the offset. At 64, the
/// leaves of a bunny 4 diagonals away were re-orthonormalised at every test, a
/// measurable cost, for nothing.
const FAR: f64 = 1e4;

/// Whether a distance bound re-orthonormalises the frames (orthonormal within `tol`) of two
/// boxes whose centres are `offset_norm1` apart (1-norm) and whose half-widths sum to
/// `halves`: where the frames' share of the slack passes [`FAR`] times the guard's.
#[inline(always)]
fn frames_far_apart(tol: f64, offset_norm1: f64, halves: f64) -> bool {
    4.0 * tol * offset_norm1 > FAR * SAT_GUARD * halves
}

/// The rows of `axes` made orthonormal in f64 (Gram–Schmidt, the third row as the cross
/// product of the first two: a box is symmetric, so the sign of an axis does not matter).
/// Degenerate or non-finite rows (a damaged, unverified file) give NaN entries, which the
/// pair tests read as "may overlap" and "no bound".
fn orthonormal_rows(axes: &Matrix3<f64>) -> Matrix3<f64> {
    let (r0, r1) = (axes.row(0).transpose(), axes.row(1).transpose());
    let q0 = r0 / r0.norm();
    let v1 = r1 - q0 * q0.dot(&r1);
    let q1 = v1 / v1.norm();
    let q2 = q0.cross(&q1);
    Matrix3::from_rows(&[q0.transpose(), q1.transpose(), q2.transpose()])
}

/// Half-widths `h` of a box whose frame is orthonormal within `tol`, widened so the box
/// along the re-orthonormalised frame ([`orthonormal_rows`]) contains it: each new axis is
/// within about `3 tol` of the stored one, which moves a point `x` of the box (|x| at most
/// Σh) by at most `3 tol Σh` along it; `4 tol` covers second-order terms.
fn widen(h: Vector3<f64>, tol: f64) -> Vector3<f64> {
    h.add_scalar(4.0 * tol * h.sum())
}

/// Orthonormality tolerance of stored axes: rounding each component to f32 moves a dot
/// product by about 2e-7, so 1e-6 accepts every rounded frame and rejects real damage. It
/// must not exceed the guard of the pair tests ([`crate::bv::pair::SAT_GUARD`]), whose
/// slack keeps them conservative only for frames orthonormal within it.
pub(crate) fn axis_tolerance(precision: Precision) -> f64 {
    match precision {
        Precision::F32 => 1e-6,
        Precision::F64 => 1e-10,
    }
}

/// Half-widths of three box-like extents: diameter, volume and area of a box.
pub(crate) fn box_measures(h: [f64; 3]) -> (f64, f64, f64) {
    let diameter = 2.0 * (h[0] * h[0] + h[1] * h[1] + h[2] * h[2]).sqrt();
    let volume = 8.0 * h[0] * h[1] * h[2];
    let area = 8.0 * (h[0] * h[1] + h[1] * h[2] + h[2] * h[0]);
    (diameter, volume, area)
}

impl<R: Real> BoundingVolume for Obb<R> {
    type Real = R;
    const KIND: BvKind = BvKind::Obb;

    fn enclose(frame: &Matrix3<f64>, positions: &[[f64; 3]], faces: &[[u32; 3]]) -> Self {
        Self::enclose_points(frame, face_vertices(positions, faces))
    }

    fn enclose_vertices(frame: &Matrix3<f64>, positions: &[[f64; 3]], vertices: &[u32]) -> Self {
        Self::enclose_points(frame, listed_vertices(positions, vertices))
    }

    fn enclose_vertices_fitted_and_aligned(
        frame: &Matrix3<f64>,
        positions: &[[f64; 3]],
        vertices: &[u32],
    ) -> [(Matrix3<f64>, Self); 2] {
        Self::enclose_points_fitted_and_aligned(frame, listed_vertices(positions, vertices))
    }

    fn write_le(&self, out: &mut [u8]) {
        let [a0, a1, a2] = self.axes;
        let (c, h) = (self.center, self.half);
        // An array rather than chained iterators: the loop then unrolls into plain stores.
        let scalars = [
            a0[0], a0[1], a0[2], a1[0], a1[1], a1[2], a2[0], a2[1], a2[2], c[0], c[1], c[2], h[0],
            h[1], h[2],
        ];
        for (o, v) in out.chunks_exact_mut(size_of::<R>()).zip(scalars) {
            v.write_le(o);
        }
    }

    fn validate(&self) -> Result<(), BvDefect> {
        let flat = self
            .axes
            .iter()
            .flatten()
            .chain(&self.center)
            .chain(&self.half)
            .copied();
        if !all_finite(&flat.collect::<Vec<R>>()) {
            return Err(BvDefect::NotFinite);
        }
        if self.half.iter().any(|h| h.to_f64() < 0.0) {
            return Err(BvDefect::NegativeExtent);
        }
        let a = self.axes_f64();
        let tol = axis_tolerance(R::PRECISION);
        for (i, ai) in a.iter().enumerate() {
            for (j, aj) in a.iter().enumerate() {
                let expected = if i == j { 1.0 } else { 0.0 };
                if (dot(*ai, *aj) - expected).abs() > tol {
                    return Err(BvDefect::AxesNotOrthonormal);
                }
            }
        }
        Ok(())
    }

    fn contains(&self, p: [f64; 3], tolerance: f64) -> bool {
        let c = self.center_f64();
        let d = [p[0] - c[0], p[1] - c[1], p[2] - c[2]];
        let h = self.half_f64();
        let a = self.axes_f64();
        arr3::zip(a, h)
            .iter()
            .all(|(axis, h)| dot(*axis, d).abs() <= h + tolerance)
    }

    box_pair_methods!();
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::bv::box_corners;

    /// The boxes the builder fits hold every point and are tight, in both precisions and
    /// far from the origin: centred on the middle of the points' projections, each
    /// half-width their half-range plus rounding. The one-pass fit of a frame and the
    /// model's axes gives exactly the boxes fitted along each alone (the model's axes
    /// include a negated one when the spreads are in odd order).
    #[test]
    fn enclosed_boxes_hold_their_points_and_are_tight() {
        fn check<R: Real>(spread: [f64; 3], offset: f64, tolerance: f64) {
            let mut rng = crate::generate::Rng::new(31);
            let points: Vec<[f64; 3]> = (0..40)
                .map(|_| std::array::from_fn(|k| offset + spread[k] * rng.signed()))
                .collect();
            let frame = nalgebra::Rotation3::from_euler_angles(0.4, -0.9, 2.2).into_inner();
            let fitted = Obb::<R>::enclose_points(&frame, points.iter());
            let [(f, both_fitted), (model, aligned)] =
                Obb::<R>::enclose_points_fitted_and_aligned(&frame, points.iter());
            assert_eq!(f, frame);
            assert_eq!(both_fitted, fitted);
            assert_eq!(aligned, Obb::<R>::enclose_points(&model, points.iter()));
            let scale = offset.abs() + spread.iter().fold(0.0f64, |m, s| m.max(*s));
            for b in [fitted, aligned] {
                for p in &points {
                    assert!(b.contains(*p, 0.0), "{p:?} outside {b:?}");
                }
                let (c, h) = (b.center_f64(), b.half_f64());
                for (axis, h) in b.axes_f64().into_iter().zip(h) {
                    let (lo, hi) = points.iter().fold((f64::MAX, f64::MIN), |(lo, hi), p| {
                        let d = dot(axis, *p);
                        (lo.min(d), hi.max(d))
                    });
                    let off_middle = (dot(axis, c) - 0.5 * (lo + hi)).abs();
                    assert!(off_middle <= tolerance * scale, "{off_middle:e} {b:?}");
                    assert!(h <= 0.5 * (hi - lo) + tolerance * scale, "{h} {b:?}");
                }
            }
        }
        for offset in [0.0, -40.0, 1e5] {
            for spread in [[3.0, 1.0, 0.2], [1.0, 3.0, 0.2]] {
                check::<f64>(spread, offset, 1e-13);
                check::<f32>(spread, offset, 1e-6);
            }
        }
    }

    /// `verify` refuses a stored box with any non-finite number, a negative half-width, or
    /// axes further from orthonormal than the precision's tolerance (a tie is accepted);
    /// a flat box is well formed.
    #[test]
    fn validate_names_each_defect() {
        let good = Obb::<f64> {
            axes: [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]],
            center: [1.0, -2.0, 3.0],
            half: [1.0, 0.5, 0.0],
        };
        assert_eq!(good.validate(), Ok(()));
        for k in 0..15 {
            for bad in [f64::NAN, f64::INFINITY, f64::NEG_INFINITY] {
                let mut b = good;
                match k {
                    0..9 => b.axes[k / 3][k % 3] = bad,
                    9..12 => b.center[k - 9] = bad,
                    _ => b.half[k - 12] = bad,
                }
                assert_eq!(b.validate(), Err(BvDefect::NotFinite), "{k}");
            }
        }
        for k in 0..3 {
            let mut b = good;
            b.half[k] = -0.25;
            assert_eq!(b.validate(), Err(BvDefect::NegativeExtent), "{k}");
        }
        let tol = axis_tolerance(Precision::F64);
        for (lean, defect) in [(tol, None), (2.0 * tol, Some(BvDefect::AxesNotOrthonormal))] {
            // Row 1 leaning towards row 0: their dot product is `lean` exactly.
            let mut b = good;
            b.axes[1][0] = lean;
            assert_eq!(b.validate(), defect.map_or(Ok(()), Err), "{lean:e}");
        }
        // A row longer than a unit: its squared length is 1 + 4 tol.
        let mut b = good;
        b.axes[2][2] = 1.0 + 2.0 * tol;
        assert_eq!(b.validate(), Err(BvDefect::AxesNotOrthonormal));
    }

    /// Diameter, volume and surface area of a box of half-widths 1, 2, 3.
    #[test]
    fn box_measures_are_the_boxs() {
        let (diameter, volume, area) = box_measures([1.0, 2.0, 3.0]);
        assert!((diameter - 2.0 * 14f64.sqrt()).abs() < 1e-12);
        assert_eq!(volume, 48.0);
        assert_eq!(area, 88.0);
    }

    /// Axes made orthonormal are so to rounding, and a box along f32 axes (orthonormal only
    /// within their tolerance) lies inside the box of widened half-widths along them: every
    /// corner, for boxes of several sizes and shapes in random frames.
    #[test]
    fn widened_half_widths_hold_the_box_along_orthonormal_axes() {
        let mut rng = crate::generate::Rng::new(29);
        let tol = axis_tolerance(Precision::F32);
        for k in 0..500 {
            let rows = rounded_rows::<f32>(&rng.uniform_rotation());
            let scale = [1e-3, 1.0, 1e3][k % 3];
            let half = [0, 1, 2].map(|_| (rng.signed().abs() * scale) as f32);
            let b = Obb::<f32> {
                axes: rows,
                center: [0.0; 3],
                half,
            };
            let (axes, h) = (b.axes_matrix(), Vector3::from(b.half_f64()));
            let (q, wide) = (orthonormal_rows(&axes), widen(h, tol));
            // Orthonormal to rounding (the stored rows are only within `tol`), each row the
            // stored one's direction but for the third's sign.
            let gram = q * q.transpose();
            assert!(
                (gram - Matrix3::identity()).abs().max() < 1e-14,
                "case {k}: {gram}"
            );
            for j in 0..3 {
                let along = q.row(j).dot(&axes.row(j)).abs();
                assert!(
                    along >= 1.0 - 3.0 * tol,
                    "case {k}: row {j} turned: {along}"
                );
            }
            for (corner, p) in box_corners(&Vector3::zeros(), &axes, &h).iter().enumerate() {
                for j in 0..3 {
                    let along = q.row(j).transpose().dot(p);
                    assert!(
                        along.abs() <= wide[j],
                        "case {k}: corner {corner} {along} {wide:?}"
                    );
                }
            }
        }
    }

    /// A distance bound keeps the stored frames (and their tolerance in the slack) while the
    /// frames' share of the slack stays within [`FAR`] times the guard's, whichever box is
    /// the larger, and re-orthonormalises them beyond; an overlap test always keeps them.
    #[test]
    fn frames_are_re_orthonormalised_only_for_boxes_far_apart() {
        let axes = [[1.0f32, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]];
        let boxed = |half: f32| Obb::<f32> {
            axes,
            center: [0.0; 3],
            half: [half; 3],
        };
        let (large, small) = (boxed(1.0), boxed(0.01));
        let tol = axis_tolerance(Precision::F32);
        // Frames re-orthonormalised past |offset|₁ = FAR · SAT_GUARD · Σh / (4 tol): 7,575.
        for (a, b) in [(large, small), (small, large)] {
            for (shift, far) in [(1000.0, false), (1e5, true)] {
                let b_to_a = Pose::translation(shift, 0.0, 0.0);
                let metric = a.pair_with(&b, &b_to_a, PairSetup::Metric);
                assert_eq!(metric.frame_error, if far { 0.0 } else { tol }, "{shift}");
                let fast = a.pair_with(&b, &b_to_a, PairSetup::Fast);
                assert_eq!(fast.frame_error, tol);
            }
        }
    }
}
