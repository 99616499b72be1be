//! Bounding sphere.

use super::pair::Guard;
use super::{
    all_finite, face_vertices, l1, listed_vertices, projection_slack, Aabb, BoundingVolume,
    BvDefect, BvKind,
};
use crate::arr3;
use crate::arr3::dot;
use crate::pose::Pose;
use crate::real::{point_to_f64, Real};
use nalgebra::{Matrix3, Vector3};
use zerocopy::{FromBytes, Immutable, KnownLayout};

/// The ball `|p - center| <= radius` in the model frame.
///
/// # Memory Layout
///
/// `#[repr(C)]`, 4 scalars: `center` then `radius`. 16 bytes in f32, 32 in f64.
#[derive(Clone, Copy, Debug, PartialEq, FromBytes, KnownLayout, Immutable)]
#[repr(C)]
pub struct Sphere<R> {
    /// Centre, model frame.
    pub center: [R; 3],
    /// Radius, non-negative, model units.
    pub radius: R,
}

impl<R: Real> Sphere<R> {
    /// The distance between the centres once `other` is mapped into this sphere's model
    /// frame, the sum of the radii, and a bound on the rounding error of either and of
    /// their difference (model units of this sphere).
    #[inline]
    fn centres_radii_slack(&self, other: &Self, b_to_a: &Pose) -> (f64, f64, f64) {
        let (ca, cb) = (point_to_f64(&self.center), point_to_f64(&other.center));
        let offset = b_to_a.apply(&Vector3::from(cb)) - Vector3::from(ca);
        let (d, r) = (offset.norm(), self.radius.to_f64() + other.radius.to_f64());
        // Mapping B's centre and subtracting A's each round a few ulps of the coordinates'
        // magnitudes (their sum, which far from the origin dwarfs d and r, is at least d);
        // the norm and the sums a few ulps of d and r.
        let magnitudes = l1(&ca) + l1(&cb) + b_to_a.translation_vector().abs().sum();
        let slack = 4.0 * projection_slack(magnitudes + r);
        (d, r, slack)
    }

    /// The sphere of `points` for `frame` (see [`BoundingVolume::enclose`]).
    fn enclose_points<'a>(
        frame: &Matrix3<f64>,
        points: impl Iterator<Item = &'a [f64; 3]> + Clone,
    ) -> Self {
        let axes: [[f64; 3]; 3] = std::array::from_fn(|i| std::array::from_fn(|j| frame[(j, i)]));
        let mut lo = [f64::INFINITY; 3];
        let mut hi = [f64::NEG_INFINITY; 3];
        for p in points.clone() {
            let d = [dot(axes[0], *p), dot(axes[1], *p), dot(axes[2], *p)];
            lo = arr3::min(lo, d);
            hi = arr3::max(hi, d);
        }
        if !lo[0].is_finite() {
            lo = [0.0; 3];
            hi = [0.0; 3];
        }
        // c_j = Σ_i axes_i_j · ½ (lo_i + hi_i), summed over i in order.
        let lo_hi = arr3::zip(lo, hi);
        let c: [f64; 3] = arr3::map(arr3::transpose(axes), |column| {
            column
                .iter()
                .zip(&lo_hi)
                .map(|(x, (lo, hi))| x * 0.5 * (lo + hi))
                .sum()
        });
        Self::around(c, points)
    }

    /// The sphere of `points` about `center` (rounded to the stored precision), its radius
    /// the largest distance rounded outward.
    fn around<'a>(center: [f64; 3], points: impl Iterator<Item = &'a [f64; 3]>) -> Self {
        let center = center.map(R::from_f64_nearest);
        let c = point_to_f64(&center);
        let mut r2 = 0.0f64;
        let mut l1_max = 0.0f64;
        for p in points {
            let d = [p[0] - c[0], p[1] - c[1], p[2] - c[2]];
            r2 = r2.max(dot(d, d));
            l1_max = l1_max.max(l1(p));
        }
        let slack = 2.0 * projection_slack(l1_max + l1(&c));
        Sphere {
            center,
            radius: R::from_f64_up(r2.sqrt() + slack),
        }
    }
}

impl<R: Real> BoundingVolume for Sphere<R> {
    type Real = R;
    const KIND: BvKind = BvKind::Sphere;

    /// Centred on the middle of the vertices' extents along the fitted axes (the centre of
    /// the OBB of the same frame), which for elongated sets is far tighter than the
    /// centroid; the radius is the largest distance from that centre.
    fn enclose(frame: &Matrix3<f64>, positions: &[[f64; 3]], faces: &[[u32; 3]]) -> Self {
        Self::enclose_points(frame, face_vertices(positions, faces))
    }

    fn enclose_vertices(frame: &Matrix3<f64>, positions: &[[f64; 3]], vertices: &[u32]) -> Self {
        Self::enclose_points(frame, listed_vertices(positions, vertices))
    }

    /// Centred on the smallest ball's centre (Welzl's algorithm); the radius measured from
    /// it.
    fn enclose_vertices_minimal_ball(positions: &[[f64; 3]], vertices: &[u32]) -> Option<Self> {
        let points = listed_vertices(positions, vertices);
        let center = super::ball::minimal_ball_center(points.clone());
        Some(Self::around(center, points))
    }

    fn write_le(&self, out: &mut [u8]) {
        let c = self.center;
        // An array rather than chained iterators: the loop then unrolls into plain stores.
        let scalars = [c[0], c[1], c[2], self.radius];
        for (o, v) in out.chunks_exact_mut(size_of::<R>()).zip(scalars) {
            v.write_le(o);
        }
    }

    fn validate(&self) -> Result<(), BvDefect> {
        if !all_finite(&self.center) || !self.radius.to_f64().is_finite() {
            return Err(BvDefect::NotFinite);
        }
        if self.radius.to_f64() < 0.0 {
            return Err(BvDefect::NegativeExtent);
        }
        Ok(())
    }

    fn contains(&self, p: [f64; 3], tolerance: f64) -> bool {
        let c = point_to_f64(&self.center);
        let d = [p[0] - c[0], p[1] - c[1], p[2] - c[2]];
        dot(d, d).sqrt() <= self.radius.to_f64() + tolerance
    }

    #[inline]
    fn overlaps(&self, other: &Self, b_to_a: &Pose, _guard: Guard) -> bool {
        // A sphere test must never reject a pair that touches, whatever the rounding.
        let (d, r, slack) = self.centres_radii_slack(other, b_to_a);
        d - r <= slack
    }

    #[inline]
    fn distance_lower_bound_until(&self, other: &Self, b_to_a: &Pose, enough: f64) -> f64 {
        self.distance_lower_bound_and_centres_until(other, b_to_a, enough)
            .0
    }

    #[inline]
    fn distance_lower_bound_and_centres_until(
        &self,
        other: &Self,
        b_to_a: &Pose,
        _enough: f64,
    ) -> (f64, f64) {
        let (centres, r, slack) = self.centres_radii_slack(other, b_to_a);
        ((centres - r - slack).max(0.0), centres)
    }

    #[inline]
    fn max_distance_upper_bound(&self, other: &Self, b_to_a: &Pose) -> f64 {
        let (centres, r, slack) = self.centres_radii_slack(other, b_to_a);
        centres + r + slack
    }

    fn world_aabb(&self, pose: &Pose) -> Aabb<f64> {
        let c = pose.apply(&Vector3::from(point_to_f64(&self.center)));
        let r = self.radius.to_f64();
        let r =
            r + 16.0 * f64::EPSILON * (c.abs().max() + r + pose.translation_vector().abs().max());
        Aabb {
            min: c.add_scalar(-r).into(),
            max: c.add_scalar(r).into(),
        }
    }

    #[inline]
    fn center(&self) -> [f64; 3] {
        point_to_f64(&self.center)
    }

    fn enclosing_ball(&self) -> ([f64; 3], f64) {
        (point_to_f64(&self.center), self.radius.to_f64())
    }

    fn diameter(&self) -> f64 {
        2.0 * self.radius.to_f64()
    }
    fn thickness(&self) -> f64 {
        self.diameter()
    }
    fn volume(&self) -> f64 {
        4.0 / 3.0 * std::f64::consts::PI * self.radius.to_f64().powi(3)
    }
    fn surface_area(&self) -> f64 {
        4.0 * std::f64::consts::PI * self.radius.to_f64().powi(2)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::generate::Rng;

    /// `verify` refuses a stored sphere with any non-finite number, whichever it is, and a
    /// negative radius; a point sphere is well formed.
    #[test]
    fn validate_names_each_defect() {
        let sphere = |center: [f64; 3], radius: f64| Sphere { center, radius };
        assert_eq!(sphere([1.0, -2.0, 3.0], 0.5).validate(), Ok(()));
        assert_eq!(sphere([1.0, -2.0, 3.0], 0.0).validate(), Ok(()));
        for bad in [f64::NAN, f64::INFINITY, f64::NEG_INFINITY] {
            assert_eq!(
                sphere([1.0, bad, 3.0], 0.5).validate(),
                Err(BvDefect::NotFinite)
            );
            assert_eq!(
                sphere([1.0, -2.0, 3.0], bad).validate(),
                Err(BvDefect::NotFinite)
            );
        }
        assert_eq!(
            sphere([1.0, -2.0, 3.0], -0.5).validate(),
            Err(BvDefect::NegativeExtent)
        );
    }

    /// A point is inside up to the tolerance: on the sphere, and just beyond it with a
    /// tolerance that reaches it or not.
    #[test]
    fn contains_is_the_ball_widened_by_the_tolerance() {
        let s = Sphere::<f64> {
            center: [1.0, -2.0, 3.0],
            radius: 0.5,
        };
        assert!(s.contains([1.0, -2.0, 3.0], 0.0));
        for k in 0..3 {
            for outward in [-1.0, 1.0] {
                let mut p = s.center;
                p[k] += outward * 0.5;
                assert!(s.contains(p, 0.0), "{p:?}");
                p[k] += outward * 0.125;
                assert!(!s.contains(p, 0.0), "{p:?}");
                assert!(!s.contains(p, 0.0625), "{p:?}");
                assert!(s.contains(p, 0.125), "{p:?}");
            }
        }
    }

    /// The sphere about the smallest ball's centre holds every point and is no larger than
    /// the sphere about the fitted box's centre; its radius is half the widest pair's distance.
    #[test]
    fn the_minimal_ball_sphere_holds_the_points_and_is_the_smaller() {
        let positions = [
            [0.0, 0.0, 0.0],
            [4.0, 0.0, 0.0],
            [2.0, 0.5, 0.0],
            [1.0, 0.1, 0.2],
        ];
        let vertices = [0, 1, 2, 3];
        let ball = Sphere::<f64>::enclose_vertices_minimal_ball(&positions, &vertices)
            .expect("spheres are fitted to the smallest ball");
        let fitted = Sphere::<f64>::enclose_vertices(&Matrix3::identity(), &positions, &vertices);
        assert!(positions.iter().all(|&p| ball.contains(p, 0.0)));
        assert!(ball.radius <= fitted.radius, "{ball:?} {fitted:?}");
        assert!((ball.radius - 2.0).abs() < 1e-9, "{ball:?}");
    }

    /// The radius holds every point exactly, not only as rounded arithmetic measures it:
    /// segments of integer corners far from the origin, across the direction (1, 1, 1), so
    /// that their corners have the centre's own L1 norm and the square root alone would
    /// round half of the radii below the truth.
    #[test]
    fn around_holds_every_point_exactly() {
        let mut rng = Rng::new(17);
        for _ in 0..200 {
            let offset = |rng: &mut Rng| (rng.signed() * 1000.0).round();
            let base = 2f64.powi(30);
            let c = [0, 1, 2].map(|_| base + offset(&mut rng));
            let (a, b) = (offset(&mut rng), offset(&mut rng));
            let u = [a, b, -(a + b)];
            let points = [1.0, -1.0].map(|side| arr3::zip(c, u).map(|(c, u)| c + side * u));
            let s = Sphere::<f64>::enclose_points(&Matrix3::identity(), points.iter());
            for p in points {
                // Integer differences below 2^12: their squares' sum is exact.
                let d = arr3::sub(p, s.center);
                let d2 = dot(d, d);
                // r² = h + l exactly; r² ≥ d2 iff (h − d2) + l ≥ 0, with h − d2 exact.
                let h = s.radius * s.radius;
                let l = s.radius.mul_add(s.radius, -h);
                assert!(h - d2 >= -l, "{p:?} outside {s:?}");
            }
        }
    }

    /// Rounding never makes the sphere test reject a pair that touches, nor the distance
    /// bounds miss it: sphere pairs posed to touch, under random rotations, small and large,
    /// near the origin and far from it. Where the posed centres lie is measured in
    /// double-double arithmetic: the pairs it puts within the sum of the radii must
    /// overlap at a lower bound of 0, and for the others the upper bound must reach twice
    /// that sum.
    #[test]
    fn spheres_posed_to_touch_overlap() {
        use crate::bv::{double_double_sum as sum, two_prod, two_sum};
        let mut rng = Rng::new(23);
        let (mut touching, mut apart) = (0, 0);
        for k in 0..6000 {
            // Radii of `size`, centres within `size` of points `far` from the origin (where
            // their coordinates' rounding dwarfs the radii).
            let (size, far) = [
                (1e-3, 0.0),
                (1.0, 0.0),
                (1e3, 0.0),
                (1e-3, 1e6),
                (1.0, 1e6),
                (1e3, 1e6),
                (1e-6, 1e-3),
            ][k % 7];
            let vector = |rng: &mut Rng, far: f64| {
                Vector3::new(rng.signed(), rng.signed(), rng.signed()) * size + Vector3::repeat(far)
            };
            // Radii whose sum rounds.
            let (ra, rb) = (size, size * (1.0 + rng.signed() / 3.0));
            let rotation = rng.uniform_rotation();
            let u = Vector3::new(rng.signed(), rng.signed(), rng.signed()).normalize();
            // B's centre placed at the sum of the radii from A's, to rounding: by the
            // translation, with both centres far or only B's; or by B's centre, both far,
            // under a translation of the radii's size.
            let (ca, cb, t) = match k / 7 % 3 {
                mode @ (0 | 1) => {
                    let ca = vector(&mut rng, [far, 0.0][mode]);
                    let cb = vector(&mut rng, far);
                    (ca, cb, ca + u * (ra + rb) - rotation * cb)
                }
                _ => {
                    let (ca, t) = (vector(&mut rng, far), vector(&mut rng, 0.0));
                    (ca, rotation.transpose() * (ca + u * (ra + rb) - t), t)
                }
            };
            let a = Sphere::<f64> {
                center: ca.into(),
                radius: ra,
            };
            let b = Sphere::<f64> {
                center: cb.into(),
                radius: rb,
            };
            let b_to_a = Pose::new(rotation, t).expect("a rotation");
            // The posed centres' offset, each coordinate as a double-double, and its
            // squared length against the radii's sum squared, both exact to far below an ulp.
            let mut excess = Vec::new();
            for i in 0..3 {
                let mut terms = vec![t[i], -ca[i]];
                for j in 0..3 {
                    let (p, e) = two_prod(rotation[(i, j)], cb[j]);
                    terms.extend([p, e]);
                }
                let (hi, lo) = sum(&terms);
                let (p, e) = two_prod(hi, hi);
                excess.extend([p, e, 2.0 * hi * lo]);
            }
            let (r, r_low) = two_sum(ra, rb);
            let (r2, r2_low) = two_prod(r, r);
            excess.extend([-r2, -r2_low, -2.0 * r * r_low]);
            let (excess, _) = sum(&excess);
            let case = format!("case {k}: {a:?} and {b:?} under {b_to_a:?}");
            if excess < -1e-25 * size * size {
                touching += 1;
                assert!(a.overlaps(&b, &b_to_a, Guard::rotation_only(0.0)), "{case}");
                assert_eq!(a.distance_lower_bound(&b, &b_to_a), 0.0, "{case}");
            } else if excess > 1e-25 * size * size {
                apart += 1;
                let upper = a.max_distance_upper_bound(&b, &b_to_a);
                assert!(sum(&[upper, -2.0 * r, -2.0 * r_low]).0 >= 0.0, "{case}");
            }
        }
        assert!(touching > 1000 && apart > 1000, "{touching} {apart}");
        // With nothing to round but the radii: concentric spheres about the origin reach
        // the radii's sum, and two points there touch.
        for _ in 0..1000 {
            let (ra, rb) = (3.0 * rng.signed().abs(), rng.signed().abs() / 7.0);
            let [a, b] = [ra, rb].map(|radius| Sphere::<f64> {
                center: [0.0; 3],
                radius,
            });
            let b_to_a = Pose::new(rng.uniform_rotation(), Vector3::zeros()).expect("a rotation");
            let (r, r_low) = two_sum(ra, rb);
            let upper = a.max_distance_upper_bound(&b, &b_to_a);
            assert!(sum(&[upper, -r, -r_low]).0 >= 0.0, "{a:?} {b:?}");
        }
        let point = Sphere::<f64> {
            center: [0.0; 3],
            radius: 0.0,
        };
        assert!(point.overlaps(&point, &Pose::identity(), Guard::rotation_only(0.0)));
    }

    /// The measures a descent rule and the statistics read, by their formulas.
    #[test]
    fn measures_are_the_spheres() {
        // (A radius of 2 would be its own double's sum.)
        let s = Sphere::<f64> {
            center: [1.0, 2.0, 3.0],
            radius: 3.0,
        };
        let pi = std::f64::consts::PI;
        assert_eq!(s.diameter(), 6.0);
        assert_eq!(s.thickness(), 6.0);
        assert!((s.volume() - 36.0 * pi).abs() < 1e-12);
        assert!((s.surface_area() - 36.0 * pi).abs() < 1e-12);
    }

    /// The trait's defaults as spheres take them: the re-wrapped test is the plain one (a
    /// sphere re-wrapped in a sphere is itself), and the distance bound without a
    /// threshold is the gap between the posed spheres.
    #[test]
    fn the_rewrapped_test_and_the_plain_bound_are_the_spheres_own() {
        let unit = Sphere::<f64> {
            center: [0.0, 0.0, 0.0],
            radius: 1.0,
        };
        let other = Sphere::<f64> {
            center: [1.0, 0.0, 0.0],
            radius: 0.5,
        };
        for (shift, gap) in [(0.0, 0.0), (4.0, 3.5), (-7.0, 4.5)] {
            let b_to_a = Pose::translation(shift, 0.0, 0.0);
            let plain = unit.overlaps(&other, &b_to_a, Guard::rotation_only(0.0));
            assert_eq!(plain, gap == 0.0, "shift {shift}");
            assert_eq!(
                unit.overlaps_rewrapped(&other, &b_to_a, Guard::rotation_only(0.0)),
                plain
            );
            let bound = unit.distance_lower_bound(&other, &b_to_a);
            assert!((bound - gap).abs() < 1e-12, "shift {shift}: {bound}");
        }
    }

    /// The world box holds the points at the radius along each axis from the posed centre,
    /// near the origin and far from it, and is no wider than rounding needs.
    #[test]
    fn world_aabb_holds_the_posed_sphere() {
        let mut rng = Rng::new(11);
        for k in 0..2000 {
            let pose = crate::bv::turned_far_pose(&mut rng, k);
            // Centres near the origin, or placed so that the posed centre is near it.
            let local = Vector3::new(rng.signed(), rng.signed(), rng.signed()) * 1e6;
            let center = if k % 2 == 0 {
                local
            } else {
                pose.rotation().transpose() * (local - pose.translation_vector())
            };
            let s = Sphere::<f64> {
                center: center.into(),
                radius: [1.0, 1e6][k / 2 % 2],
            };
            let world = s.world_aabb(&pose);
            let c = pose.apply(&center);
            let rounding = 64.0
                * f64::EPSILON
                * (c.abs().max() + s.radius + pose.translation_vector().abs().max());
            for j in 0..3 {
                let widening = [world.max[j] - c[j], c[j] - world.min[j]].map(|w| w - s.radius);
                assert!(
                    widening.iter().all(|w| w.abs() <= rounding),
                    "case {k}: {world:?} about {c:?}"
                );
            }
            for i in 0..3 {
                let mut along = Vector3::zeros();
                along[i] = s.radius;
                // The points on the sphere along the axis, by mapping them from the model.
                let back = pose.rotation().transpose() * along;
                for p in [
                    pose.apply(&(center + back)),
                    pose.apply(&(center - back)),
                    c,
                ] {
                    assert!(
                        (0..3).all(|j| world.min[j] <= p[j] && p[j] <= world.max[j]),
                        "case {k}: {p:?} outside {world:?}"
                    );
                }
            }
        }
    }
}
