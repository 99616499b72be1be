//! Axis-aligned bounding box in the model frame.

use super::pair::{box_pair_methods, BoxPair, Guard, PairSetup};
use super::{all_finite, face_vertices, listed_vertices, BoundingVolume, BvDefect, BvKind};
use crate::arr3;
use crate::pose::Pose;
use crate::real::{point_to_f64, Real};
use nalgebra::{Matrix3, Vector3};
use zerocopy::{FromBytes, Immutable, KnownLayout};

/// The box `min <= p <= max` (componentwise) in the model frame.
///
/// # Memory Layout
///
/// `#[repr(C)]`, 6 scalars: `min` then `max`. 24 bytes in f32, 48 in f64.
#[derive(Clone, Copy, Debug, PartialEq, FromBytes, KnownLayout, Immutable)]
#[repr(C)]
pub struct Aabb<R> {
    /// Smallest coordinates, model units.
    pub min: [R; 3],
    /// Largest coordinates, model units; `max >= min` componentwise.
    pub max: [R; 3],
}

impl<R: Real> Aabb<R> {
    /// Centre and half-widths, widened. Under a relative rotation the other model's box is
    /// no longer axis-aligned, so pair tests treat both as oriented boxes with model axes.
    #[inline]
    fn center_half(&self) -> (Vector3<f64>, Vector3<f64>) {
        let lo = Vector3::from(point_to_f64(&self.min));
        let hi = Vector3::from(point_to_f64(&self.max));
        ((lo + hi) * 0.5, (hi - lo) * 0.5)
    }

    /// Centre, axes (the model's), half-widths and frame error (none: model axes are
    /// exactly orthonormal, so a pair's slack is rounding only), in f64.
    fn local_box(&self) -> (Vector3<f64>, Matrix3<f64>, Vector3<f64>, f64) {
        let (c, h) = self.center_half();
        (c, Matrix3::identity(), h, 0.0)
    }

    /// The distance lower bound ([`BoxPair::distance_lower_bound_until`]) and the centres'
    /// distance.
    #[inline(always)]
    fn distance_bound(&self, other: &Self, b_to_a: &Pose, enough: f64) -> (f64, f64) {
        let pair = self.pair_with(other, b_to_a, PairSetup::Metric);
        (pair.distance_lower_bound_until(enough), pair.t.norm())
    }

    /// The separating-axis test (see [`BoxPair::disjoint`]).
    #[inline(always)]
    fn disjoint(&self, other: &Self, b_to_a: &Pose, guard: Guard) -> bool {
        self.pair_with(other, b_to_a, PairSetup::Fast)
            .disjoint(guard)
    }

    #[inline]
    fn pair_with(&self, other: &Self, b_to_a: &Pose, _setup: PairSetup) -> BoxPair {
        let (ca, ha) = self.center_half();
        let (cb, hb) = other.center_half();
        let identity = Matrix3::identity();
        BoxPair::new(&identity, &ca, ha, &identity, &cb, hb, b_to_a, 0.0)
    }

    fn half_f64(&self) -> [f64; 3] {
        arr3::map(arr3::zip(self.max, self.min), |(hi, lo)| {
            0.5 * (hi.to_f64() - lo.to_f64())
        })
    }

    /// The box of `points` (see [`BoundingVolume::enclose`]).
    fn enclose_points<'a>(points: impl Iterator<Item = &'a [f64; 3]>) -> Self {
        let mut lo = [f64::INFINITY; 3];
        let mut hi = [f64::NEG_INFINITY; 3];
        for p in points {
            lo = arr3::min(lo, *p);
            hi = arr3::max(hi, *p);
        }
        if !lo[0].is_finite() {
            lo = [0.0; 3];
            hi = [0.0; 3];
        }
        // Directed rounding keeps the box conservative in f32; comparisons are exact.
        Aabb {
            min: lo.map(R::from_f64_down),
            max: hi.map(R::from_f64_up),
        }
    }
}

impl<R: Real> BoundingVolume for Aabb<R> {
    type Real = R;
    const KIND: BvKind = BvKind::Aabb;

    fn enclose(_frame: &Matrix3<f64>, positions: &[[f64; 3]], faces: &[[u32; 3]]) -> Self {
        Self::enclose_points(face_vertices(positions, faces))
    }

    fn enclose_vertices(_frame: &Matrix3<f64>, positions: &[[f64; 3]], vertices: &[u32]) -> Self {
        Self::enclose_points(listed_vertices(positions, vertices))
    }

    fn write_le(&self, out: &mut [u8]) {
        let (lo, hi) = (self.min, self.max);
        // An array rather than chained iterators: the loop then unrolls into plain stores.
        let scalars = [lo[0], lo[1], lo[2], hi[0], hi[1], hi[2]];
        for (o, v) in out.chunks_exact_mut(size_of::<R>()).zip(scalars) {
            v.write_le(o);
        }
    }

    fn validate(&self) -> Result<(), BvDefect> {
        if !all_finite(&self.min) || !all_finite(&self.max) {
            return Err(BvDefect::NotFinite);
        }
        if arr3::zip(self.max, self.min)
            .iter()
            .any(|(hi, lo)| hi.to_f64() < lo.to_f64())
        {
            return Err(BvDefect::NegativeExtent);
        }
        Ok(())
    }

    fn contains(&self, p: [f64; 3], tolerance: f64) -> bool {
        let (lo, hi) = (point_to_f64(&self.min), point_to_f64(&self.max));
        arr3::zip(p, arr3::zip(lo, hi))
            .iter()
            .all(|&(x, (lo, hi))| x >= lo - tolerance && x <= hi + tolerance)
    }

    box_pair_methods!();
}

#[cfg(test)]
mod tests {
    use super::*;

    /// `verify` refuses a stored box with any non-finite number, in either corner, and one
    /// whose largest coordinate is below its smallest on any axis; a flat box is well formed.
    #[test]
    fn validate_names_each_defect() {
        let aabb = |min: [f64; 3], max: [f64; 3]| Aabb { min, max };
        let (lo, hi) = ([-1.0, 0.0, 2.0], [1.0, 0.5, 3.0]);
        assert_eq!(aabb(lo, hi).validate(), Ok(()));
        assert_eq!(aabb(lo, [1.0, 0.0, 3.0]).validate(), Ok(()));
        for k in 0..3 {
            for bad in [f64::NAN, f64::INFINITY, f64::NEG_INFINITY] {
                let (mut min, mut max) = (lo, hi);
                min[k] = bad;
                max[k] = bad;
                assert_eq!(aabb(min, hi).validate(), Err(BvDefect::NotFinite));
                assert_eq!(aabb(lo, max).validate(), Err(BvDefect::NotFinite));
            }
            let mut max = hi;
            max[k] = lo[k] - 0.25;
            assert_eq!(aabb(lo, max).validate(), Err(BvDefect::NegativeExtent));
        }
    }

    /// A point is inside up to the tolerance on each axis: on each face, and just beyond
    /// it with a tolerance that reaches it or not.
    #[test]
    fn contains_is_the_box_widened_by_the_tolerance() {
        let b = Aabb::<f64> {
            min: [-1.0, 0.0, 2.0],
            max: [1.0, 0.5, 3.0],
        };
        let inside = [0.0, 0.25, 2.5];
        assert!(b.contains(inside, 0.0));
        for k in 0..3 {
            for (end, outward) in [(b.min[k], -1.0), (b.max[k], 1.0)] {
                let mut p = inside;
                p[k] = end;
                assert!(b.contains(p, 0.0), "{p:?}");
                p[k] = end + outward * 0.125;
                assert!(!b.contains(p, 0.0), "{p:?}");
                assert!(!b.contains(p, 0.0625), "{p:?}");
                assert!(b.contains(p, 0.125), "{p:?}");
            }
        }
    }
}
