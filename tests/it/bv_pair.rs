//! Pair tests of volumes under a relative pose: overlap is conservative, the distance lower
//! bound is a lower bound, the box maximum distance is exact.
// Test code outside `#[test]` functions (helpers, property bodies): a failure is a failed test.
#![allow(clippy::unwrap_used, clippy::indexing_slicing)]

use crate::common;

use common::oracle;
use nalgebra::{Matrix3, Rotation3, Vector3};
use obbtree::bv::pair::{BoxPair, Guard, OFFSET_ROUNDING, SAT_GUARD};
use obbtree::bv::{Aabb, BoundingVolume, Obb, Sphere};
use obbtree::query::triangle::Triangle;
use obbtree::query::Pose;
use proptest::prelude::*;

fn rotation(ax: f64, ay: f64, az: f64) -> Matrix3<f64> {
    *Rotation3::from_euler_angles(ax, ay, az).matrix()
}

fn obb(rot: Matrix3<f64>, c: Vector3<f64>, h: Vector3<f64>) -> Obb<f64> {
    // Axes as rows.
    let r = rot.transpose();
    Obb {
        axes: [
            [r[(0, 0)], r[(0, 1)], r[(0, 2)]],
            [r[(1, 0)], r[(1, 1)], r[(1, 2)]],
            [r[(2, 0)], r[(2, 1)], r[(2, 2)]],
        ],
        center: [c.x, c.y, c.z],
        half: [h.x, h.y, h.z],
    }
}

/// Points of an OBB in its model frame at box coordinates `s` in [-1, 1]^3.
fn point_of(b: &Obb<f64>, s: [f64; 3]) -> Vector3<f64> {
    let mut p = Vector3::from(b.center);
    for ((axis, t), h) in b.axes.iter().zip(s).zip(b.half) {
        p += Vector3::from(*axis) * (t * h);
    }
    p
}

fn corners(b: &Obb<f64>) -> Vec<Vector3<f64>> {
    (0..8)
        .map(|k| {
            point_of(
                b,
                [
                    if k & 1 == 0 { -1.0 } else { 1.0 },
                    if k & 2 == 0 { -1.0 } else { 1.0 },
                    if k & 4 == 0 { -1.0 } else { 1.0 },
                ],
            )
        })
        .collect()
}

fn grid_points(b: &Obb<f64>, n: usize) -> Vec<Vector3<f64>> {
    let t = |i: usize| -1.0 + 2.0 * i as f64 / (n - 1) as f64;
    let mut out = Vec::new();
    for i in 0..n {
        for j in 0..n {
            for k in 0..n {
                out.push(point_of(b, [t(i), t(j), t(k)]));
            }
        }
    }
    out
}

fn arb_box() -> impl Strategy<Value = Obb<f64>> {
    (
        -3.0..3.0f64,
        -3.0..3.0f64,
        -3.0..3.0f64,
        -2.0..2.0f64,
        -2.0..2.0f64,
        -2.0..2.0f64,
        0.0..1.5f64,
        0.0..1.5f64,
        0.0..1.5f64,
    )
        .prop_map(|(a, b, c, x, y, z, h0, h1, h2)| {
            obb(
                rotation(a, b, c),
                Vector3::new(x, y, z),
                Vector3::new(h0, h1, h2),
            )
        })
}

fn arb_relative_pose() -> impl Strategy<Value = Pose> {
    (
        -3.0..3.0f64,
        -3.0..3.0f64,
        -3.0..3.0f64,
        -2.0..2.0f64,
        -2.0..2.0f64,
        -2.0..2.0f64,
    )
        .prop_map(|(a, b, c, x, y, z)| Pose::new(rotation(a, b, c), Vector3::new(x, y, z)).unwrap())
}

/// `o` as a builder would store it in f32, its centre moved by `shift` along every
/// coordinate and, when `thin` is 0, 1 or 2, its half-width on that axis made 1e-7 (a
/// sliver's leaf).
fn stored_f32(o: &Obb<f64>, shift: f64, thin: usize) -> Obb<f32> {
    let mut f = Obb::<f32> {
        axes: o.axes.map(|r| r.map(|v| v as f32)),
        center: o.center.map(|v| (v + shift) as f32),
        half: o.half.map(|v| v as f32),
    };
    if let Some(h) = f.half.get_mut(thin) {
        *h = 1e-7;
    }
    f
}

/// The f32 box `f` exactly, in f64.
fn widened(f: &Obb<f32>) -> Obb<f64> {
    Obb {
        axes: f.axes.map(|r| r.map(f64::from)),
        center: f.center.map(f64::from),
        half: f.half.map(f64::from),
    }
}

/// The 12 face triangles of a box, mapped by `pose`.
fn surface(o: &Obb<f64>, pose: &Pose) -> Vec<Triangle> {
    let c: Vec<Vector3<f64>> = corners(o).iter().map(|p| pose.apply(p)).collect();
    // Corner k has bit i set when it lies on the + side of axis i (see `corners`).
    let mut out = Vec::new();
    for axis in 0..3 {
        for side in [0, 1 << axis] {
            let on: Vec<usize> = (0..8).filter(|k| k & (1 << axis) == side).collect();
            // The four corners of a face, in cyclic order: 0, 1, 3, 2 of the two free bits.
            let quad = [on[0], on[1], on[3], on[2]];
            out.push([c[quad[0]], c[quad[1]], c[quad[2]]]);
            out.push([c[quad[0]], c[quad[2]], c[quad[3]]]);
        }
    }
    out
}

/// The exact distance between the surfaces of two boxes (B mapped by `b_to_a`). For boxes
/// that do not overlap this is the box distance.
fn surface_distance(a: &Obb<f64>, b: &Obb<f64>, b_to_a: &Pose) -> f64 {
    oracle::min_distance(&surface(a, &Pose::identity()), &surface(b, b_to_a))
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 2000, ..ProptestConfig::default() })]

    #[test]
    fn box_max_distance_is_the_corner_maximum(a in arb_box(), b in arb_box(), b_to_a in arb_relative_pose()) {
        let brute = oracle::max_distance(&surface(&a, &Pose::identity()), &surface(&b, &b_to_a));
        let fast = a.max_distance_upper_bound(&b, &b_to_a);
        // An upper bound, above the corner maximum by at most the slack of f64 frames
        // (1e-10 x half-widths and offset) and rounding.
        prop_assert!(fast >= brute * (1.0 - 1e-15), "fast {fast} < brute {brute}");
        prop_assert!(fast - brute <= 2e-8 * (1.0 + brute), "fast {fast} brute {brute}");
    }

    #[test]
    fn box_lower_bound_never_exceeds_a_point_pair_distance(a in arb_box(), b in arb_box(), b_to_a in arb_relative_pose()) {
        let lb = a.distance_lower_bound(&b, &b_to_a);
        let pa = grid_points(&a, 4);
        let pb: Vec<_> = grid_points(&b, 4).iter().map(|q| b_to_a.apply(q)).collect();
        let sampled = pa.iter().flat_map(|p| pb.iter().map(move |q| (p - q).norm())).fold(f64::INFINITY, f64::min);
        prop_assert!(lb <= sampled + 1e-12, "lower bound {lb} > sampled {sampled}");
        // A positive bound means the boxes are disjoint, which the overlap test must not contradict
        // beyond its guard, and an overlap verdict of "disjoint" needs separation.
        if !a.overlaps(&b, &b_to_a, Guard::rotation_only(SAT_GUARD)) {
            prop_assert!(sampled > 0.0);
        }
    }

    /// The bound is near the box distance, not only below it: at least 2/3 of it for
    /// separated boxes (the face-axis gaps alone reach only 1/√3 of it for boxes
    /// diagonal to each other, and nothing like it for thin boxes far apart). Not a
    /// theorem: the worst of 330,000 random separated pairs of this distribution came to
    /// 0.72 (a claim of 3/4 failed on the case in the regressions file), so a bound made
    /// looser shows here.
    #[test]
    fn box_lower_bound_is_at_least_two_thirds_of_the_box_distance(a in arb_box(), b in arb_box(), b_to_a in arb_relative_pose()) {
        let lb = a.distance_lower_bound(&b, &b_to_a);
        let d = surface_distance(&a, &b, &b_to_a);
        prop_assert!(lb <= d + 1e-9, "lower bound {lb} above the surface distance {d}");
        // (Below about 1e-4 the guard's slack, 1e-6 of the boxes' size, takes its share.)
        if d > 1e-3 && !a.overlaps(&b, &b_to_a, Guard::rotation_only(0.0)) {
            prop_assert!(lb >= 2.0 / 3.0 * d, "lower bound {lb} below 2/3 of the distance {d}");
        }
    }

    /// The overlap test is tight as well as conservative: boxes further apart than a
    /// ten-thousandth of their size are reported disjoint (the guard and the slack widen
    /// each box by about a millionth of the pair's size; the margin covers edge-edge axes
    /// nearly parallel, where face axes must separate instead: 100,000 cases held at a
    /// hundred-thousandth). A test made looser, its radii scaled up or an axis skipped,
    /// shows here.
    #[test]
    fn boxes_apart_by_a_ten_thousandth_of_their_size_are_disjoint(a in arb_box(), b in arb_box(), b_to_a in arb_relative_pose()) {
        let d = surface_distance(&a, &b, &b_to_a);
        let size: f64 = a.half.iter().chain(&b.half).sum();
        // Surfaces apart are boxes apart unless one box holds the other, and then it holds
        // its corners.
        let a_to_b = b_to_a.to_isometry().inverse();
        let nested = corners(&b).iter().any(|q| a.contains(b_to_a.apply(q).into(), 0.0))
            || corners(&a).iter().any(|p| b.contains((a_to_b * nalgebra::Point3::from(*p)).coords.into(), 0.0));
        if d > 1e-4 * size && !nested {
            prop_assert!(!a.overlaps(&b, &b_to_a, Guard::rotation_only(SAT_GUARD)), "distance {d}, size {size}: reported overlapping");
            prop_assert!(!a.overlaps(&b, &b_to_a, Guard::rotation_only(0.0)), "distance {d}, size {size}: overlapping unguarded");
        }
    }

    /// The f32 box test (on the stored f32 values, `bv::pair_f32`) is at least as
    /// conservative as the f64 test of the same stored boxes, and hardly looser: along a
    /// random direction from coinciding centres, at the f64 test's last overlapping
    /// offset (bisected to the last bit) the f32 test reports overlap too, and at its own
    /// last overlapping offset the f64 test given twice the f32 test's rounding budget
    /// (the `pair_f32` module's bounds) still does. Thin boxes (a half-width of 1e-7,
    /// slivers' leaves) and boxes far from the origin included.
    #[test]
    fn f32_box_test_is_as_conservative_as_f64(
        a in arb_box(), b in arb_box(), b_to_a in arb_relative_pose(),
        thin in 0..4usize, far in prop_oneof![Just(0.0), Just(1e3)],
    ) {
        let (fa, fb) = (stored_f32(&a, far, thin), stored_f32(&b, -far, thin));
        let wide = |f: &Obb<f32>| {
            (
                Matrix3::from_fn(|i, j| f64::from(f.axes[i][j])),
                Vector3::from(f.center.map(f64::from)),
                Vector3::from(f.half.map(f64::from)),
            )
        };
        let ((axes_a, ca, ha), (axes_b, cb, hb)) = (wide(&fa), wide(&fb));
        let r = *b_to_a.rotation();
        let toward = b_to_a.translation_vector();
        prop_assume!(toward.norm() > 1e-3);
        let direction = toward.normalize();
        // B's centre on A's at s = 0, then s along `direction`.
        let pose_at = |s: f64| Pose::new(r, ca - r * cb + direction * s).unwrap();
        let f64_disjoint = |s: f64| {
            BoxPair::new(&axes_a, &ca, ha, &axes_b, &cb, hb, &pose_at(s), 1e-6).disjoint(Guard::rotation_only(SAT_GUARD))
        };
        let f32_disjoint = |s: f64| !fa.overlaps(&fb, &pose_at(s), Guard::rotation_only(SAT_GUARD));
        let (mut lo, mut hi) = (0.0f64, 10.0f64);
        prop_assume!(!f64_disjoint(lo) && f64_disjoint(hi));
        while hi - lo > f64::EPSILON * hi {
            let mid = 0.5 * (lo + hi);
            if f64_disjoint(mid) { hi = mid } else { lo = mid }
        }
        prop_assert!(!f32_disjoint(lo), "f32 test reports disjoint at the f64 test's overlapping offset {lo}");
        prop_assert!(!f32_disjoint(0.5 * lo), "f32 test reports disjoint inside the f64 test's overlap");
        // Hardly looser, measured by the test's own margins rather than by the boxes'
        // distance: near-parallel edges or flat boxes moving nearly in their planes turn a
        // slack into a gap many times its size, for both tests alike. The f32 test adds
        // 17u to the guard and 64u·(|t|₁ + Σ half-widths) to the slack; twice that, as a
        // guard of 128u more (on the half-widths and |m|) and a frame error of 32u more (on
        // |t|₁), must cover it.
        prop_assert!(f32_disjoint(10.0), "f32 test reports overlap ten units apart");
        let (mut lo, mut hi) = (lo, 10.0f64);
        while hi - lo > f64::EPSILON * hi {
            let mid = 0.5 * (lo + hi);
            if f32_disjoint(mid) { hi = mid } else { lo = mid }
        }
        let u = f64::from(f32::EPSILON) / 2.0;
        let budget = BoxPair::new(&axes_a, &ca, ha, &axes_b, &cb, hb, &pose_at(lo), 1e-6 + 32.0 * u);
        prop_assert!(
            !budget.disjoint(Guard::rotation_only(SAT_GUARD + 128.0 * u)),
            "f32 test overlaps at offset {lo}, beyond the f64 test given twice its rounding budget"
        );
    }

    /// The distance bound of f32 boxes (computed on the stored f32 values,
    /// `bv::pair_f32`) stays below the exact distance of the stored boxes, and within a
    /// hundred-thousandth (of the pair's size) of the f64 bound of the same boxes, plus
    /// what the edge axes' rounding becomes over their length. Thin boxes included.
    #[test]
    fn f32_box_lower_bound_is_a_lower_bound_near_the_f64_one(
        a in arb_box(), b in arb_box(), b_to_a in arb_relative_pose(), thin in 0..4usize,
    ) {
        let (fa, fb) = (stored_f32(&a, 0.0, thin), stored_f32(&b, 0.0, thin));
        let (wa, wb) = (widened(&fa), widened(&fb));
        let lb32 = fa.distance_lower_bound(&fb, &b_to_a);
        let d = surface_distance(&wa, &wb, &b_to_a);
        prop_assert!(lb32 <= d + 1e-12, "f32 bound {lb32} above the distance {d}");
        let ca = Vector3::from(wa.center);
        let cb = Vector3::from(wb.center);
        let matrix = |o: &Obb<f64>| Matrix3::from_fn(|i, j| o.axes[i][j]);
        let pair = BoxPair::new(
            &matrix(&wa), &ca, Vector3::from(wa.half),
            &matrix(&wb), &cb, Vector3::from(wb.half),
            &b_to_a, 1e-6,
        );
        let lb64 = pair.distance_lower_bound();
        let size: f64 = wa.half.iter().chain(&wb.half).sum::<f64>() + (b_to_a.apply(&cb) - ca).norm();
        // An edge axis's gap in f32 carries the rounding of `m` (about 64u of the size)
        // divided by the axis length; the f64 bound skips axes shorter than 1e-6.
        let shortest_edge_axis = pair.m.iter()
            .map(|x| (1.0 - x * x).max(0.0).sqrt())
            .filter(|&length| length >= 1e-6)
            .fold(1.0, f64::min);
        let u = f64::from(f32::EPSILON) / 2.0;
        let allowance = 1e-5 * size + 128.0 * u * size / shortest_edge_axis;
        prop_assert!(lb32 >= lb64 - allowance, "f32 bound {lb32} far below the f64 bound {lb64}");
    }

    /// Nearly parallel sticks under a pose whose rotation is orthonormal only within the
    /// tolerance `Pose::new` accepts (scaled by up to 1 ± 4.9e-7): the bound's edge-edge
    /// axes are then nearly zero vectors whose length must come from their own entries,
    /// not from `1 − m_ij²` (which cancelled and made the bound up to 15 times the
    /// distance).
    #[test]
    fn box_lower_bound_holds_for_nearly_parallel_sticks_under_a_pose_at_the_tolerance(
        frame in prop::array::uniform3(-3.0..3.0f64),
        widths in prop::array::uniform4(0.0..1e-3f64),
        turn in (-4.0..-1.0f64, 0.0..6.3f64),
        scale in -4.9e-7..4.9e-7f64,
        along in -2.0..2.0f64,
        across in prop::array::uniform2(-0.05..0.05f64),
    ) {
        let r = rotation(frame[0], frame[1], frame[2]);
        let (x, y, z) = (r * Vector3::x(), r * Vector3::y(), r * Vector3::z());
        let a = obb(r, Vector3::zeros(), Vector3::new(1.0, widths[0], widths[1]));
        let b = obb(r, Vector3::zeros(), Vector3::new(1.0, widths[2], widths[3]));
        let (angle, phi) = (10f64.powf(turn.0), turn.1);
        let axis = nalgebra::Unit::new_normalize(y * phi.cos() + z * phi.sin());
        let rotation = *Rotation3::from_axis_angle(&axis, angle).matrix() * (1.0 + scale);
        let pose = Pose::new(rotation, x * along + y * across[0] + z * across[1]).unwrap();
        let d = surface_distance(&a, &b, &pose);
        let lb = a.distance_lower_bound(&b, &pose);
        prop_assert!(lb <= d * (1.0 + 1e-9) + 1e-12, "f64 bound {lb} above the distance {d}");
        let (a32, b32) = (stored_f32(&a, 0.0, 3), stored_f32(&b, 0.0, 3));
        let d32 = surface_distance(&widened(&a32), &widened(&b32), &pose);
        let lb32 = a32.distance_lower_bound(&b32, &pose);
        prop_assert!(lb32 <= d32 * (1.0 + 1e-9) + 1e-12, "f32 bound {lb32} above the distance {d32}");
    }

    #[test]
    fn overlap_is_never_missed(a in arb_box(), b in arb_box(), b_to_a in arb_relative_pose()) {
        // If some point of B lies inside A, the boxes overlap and the test must say so.
        let inside = grid_points(&b, 5).iter().any(|q| a.contains(b_to_a.apply(q).into(), 1e-12));
        if inside {
            prop_assert!(a.overlaps(&b, &b_to_a, Guard::rotation_only(SAT_GUARD)));
            prop_assert!(a.overlaps(&b, &b_to_a, Guard::rotation_only(0.0)));
            prop_assert_eq!(a.distance_lower_bound(&b, &b_to_a), 0.0);
        }
    }

    #[test]
    fn the_rewrapped_test_is_looser_and_still_never_misses_an_overlap(a in arb_box(), b in arb_box(), b_to_a in arb_relative_pose()) {
        // Every pair the 15 axes pass, the re-wrapped box passes too (it tests 3 of them),
        // and overlapping boxes pass both.
        if a.overlaps(&b, &b_to_a, Guard::rotation_only(SAT_GUARD)) {
            prop_assert!(a.overlaps_rewrapped(&b, &b_to_a, Guard::rotation_only(SAT_GUARD)));
        }
        let inside = grid_points(&b, 5).iter().any(|q| a.contains(b_to_a.apply(q).into(), 1e-12));
        if inside {
            prop_assert!(a.overlaps_rewrapped(&b, &b_to_a, Guard::rotation_only(SAT_GUARD)));
        }
    }

    #[test]
    fn enclosing_balls_hold_every_corner(b in arb_box(), far in prop::array::uniform3(-1e6..1e6f64), lo in prop::array::uniform3(-2.0..2.0f64), side in prop::array::uniform3(0.0..1e-3f64)) {
        // The ball test that culls collision queries at the roots must never cut a corner
        // off: f64 boxes, the same boxes rounded to f32 (frames then off orthonormal by
        // ~1e-7) far from the origin, and tiny AABBs far out (rounded centres and halves).
        let inside = |corners: &[Vector3<f64>], (c, r): ([f64; 3], f64)| {
            corners.iter().all(|p| (p - Vector3::from(c)).norm() <= r)
        };
        prop_assert!(inside(&corners(&b), b.enclosing_ball()));
        let moved = Obb { center: [b.center[0] + far[0], b.center[1] + far[1], b.center[2] + far[2]], ..b };
        let narrow = Obb::<f32> {
            axes: moved.axes.map(|row| row.map(|v| v as f32)),
            center: moved.center.map(|v| v as f32),
            half: moved.half.map(|v| v as f32),
        };
        let widened = Obb {
            axes: narrow.axes.map(|row| row.map(f64::from)),
            center: narrow.center.map(f64::from),
            half: narrow.half.map(f64::from),
        };
        prop_assert!(inside(&corners(&widened), narrow.enclosing_ball()));
        let min = [far[0] + lo[0], far[1] + lo[1], far[2] + lo[2]];
        let max = [min[0] + side[0], min[1] + side[1], min[2] + side[2]];
        let aabb = Aabb { min, max };
        let box_corners: Vec<Vector3<f64>> = (0..8)
            .map(|k| Vector3::new(
                if k & 1 == 0 { min[0] } else { max[0] },
                if k & 2 == 0 { min[1] } else { max[1] },
                if k & 4 == 0 { min[2] } else { max[2] },
            ))
            .collect();
        prop_assert!(inside(&box_corners, aabb.enclosing_ball()));
    }

    #[test]
    fn spheres_and_aabbs_agree_with_points(c1 in prop::array::uniform3(-2.0..2.0f64), c2 in prop::array::uniform3(-2.0..2.0f64), r1 in 0.0..1.5f64, r2 in 0.0..1.5f64, b_to_a in arb_relative_pose()) {
        let s1 = Sphere { center: c1, radius: r1 };
        let s2 = Sphere { center: c2, radius: r2 };
        let d = (Vector3::from(c1) - b_to_a.apply(&Vector3::from(c2))).norm();
        prop_assert_eq!(s1.overlaps(&s2, &b_to_a, Guard::rotation_only(0.0)), d <= r1 + r2);
        prop_assert!((s1.distance_lower_bound(&s2, &b_to_a) - (d - r1 - r2).max(0.0)).abs() < 1e-12);
        prop_assert!((s1.max_distance_upper_bound(&s2, &b_to_a) - (d + r1 + r2)).abs() < 1e-12);
        let lo1 = [c1[0] - r1, c1[1] - r1, c1[2] - r1];
        let hi1 = [c1[0] + r1, c1[1] + r1, c1[2] + r1];
        let lo2 = [c2[0] - r2, c2[1] - r2, c2[2] - r2];
        let hi2 = [c2[0] + r2, c2[1] + r2, c2[2] + r2];
        let a1 = Aabb { min: lo1, max: hi1 };
        let a2 = Aabb { min: lo2, max: hi2 };
        let o1 = obb(Matrix3::identity(), Vector3::from(c1), Vector3::repeat(r1));
        let o2 = obb(Matrix3::identity(), Vector3::from(c2), Vector3::repeat(r2));
        prop_assert_eq!(a1.overlaps(&a2, &b_to_a, Guard::rotation_only(SAT_GUARD)), o1.overlaps(&o2, &b_to_a, Guard::rotation_only(SAT_GUARD)));
        prop_assert!((a1.max_distance_upper_bound(&a2, &b_to_a) - o1.max_distance_upper_bound(&o2, &b_to_a)).abs() < 2e-8);
    }
}

/// The f32 distance bound at the ends of f32's range, where its rounding bounds fail and
/// the f64 bound answers: boxes about 3e38 across, overlapping where the offset between
/// their centres (3.5e38) rounds to infinity in f32, have a bound of 0; sticks about
/// 1e-44 long, their numbers subnormal in f32, get a bound below their distance.
#[test]
fn f32_distance_bounds_beyond_f32_s_range_stay_below_the_distance() {
    let unit = [[1.0f32, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]];
    let huge = Obb::<f32> {
        axes: unit,
        center: [0.0; 3],
        half: [3e38, 1.0, 1.0],
    };
    let there = Pose::translation(3.5e38, 0.0, 0.0);
    assert_eq!(huge.distance_lower_bound(&huge, &there), 0.0);
    // Two sticks along x, each of half-length eight times the least f32, three quarters
    // of that least f32 apart along z: a distance below anything f32 holds.
    let least = f64::from(f32::from_bits(1));
    let stick = Obb::<f32> {
        axes: unit,
        center: [0.0; 3],
        half: [f32::from_bits(8), 0.0, 0.0],
    };
    let distance = 0.75 * least;
    let bound = stick.distance_lower_bound(&stick, &Pose::translation(0.0, 0.0, distance));
    assert!(
        bound <= distance,
        "bound {bound} above the distance {distance}"
    );
}

#[test]
fn separated_axis_aligned_boxes_have_the_exact_gap_as_lower_bound() {
    let a = obb(
        Matrix3::identity(),
        Vector3::zeros(),
        Vector3::new(1.0, 1.0, 1.0),
    );
    let b = obb(
        Matrix3::identity(),
        Vector3::zeros(),
        Vector3::new(0.5, 0.5, 0.5),
    );
    let b_to_a = Pose::translation(3.0, 0.0, 0.0);
    assert!(!a.overlaps(&b, &b_to_a, Guard::rotation_only(SAT_GUARD)));
    // The exact gap, less the guard's slack of 1e-6 x the half-widths (4.5e-6) and the f64
    // frames' 4e-10 x the offset.
    let lb = a.distance_lower_bound(&b, &b_to_a);
    assert!((1.5 - 5e-6..=1.5).contains(&lb), "{lb}");
    // Farthest corners: (-1, ±1, ±1) and (3.5, ∓0.5, ∓0.5).
    let expected = (4.5f64 * 4.5 + 1.5 * 1.5 + 1.5 * 1.5).sqrt();
    let ub = a.max_distance_upper_bound(&b, &b_to_a);
    assert!(
        (expected..expected + 2e-9).contains(&ub),
        "{ub} vs {expected}"
    );
    let pair = BoxPair::new(
        &Matrix3::identity(),
        &Vector3::zeros(),
        Vector3::repeat(1.0),
        &Matrix3::identity(),
        &Vector3::zeros(),
        Vector3::repeat(0.5),
        &b_to_a,
        0.0,
    );
    assert!(pair.disjoint(Guard::rotation_only(0.0)));
}

/// Boxes far apart along a diagonal: the separating-axis gaps alone reach only about 1/√3
/// of the distance (which made distance queries between far-apart models visit nearly
/// every leaf pair); the centre-to-box bound brings the lower bound within the boxes'
/// circumradius of the distance.
#[test]
fn far_apart_boxes_along_a_diagonal_have_a_tight_lower_bound() {
    let unit = Vector3::repeat(0.01);
    let a = obb(Matrix3::identity(), Vector3::zeros(), unit);
    let b = obb(rotation(0.3, -0.2, 0.5), Vector3::zeros(), unit);
    for far in [1.0, 10.0, 1e3, 1e300] {
        let b_to_a = Pose::translation(far, far, far);
        let centres = 3f64.sqrt() * far;
        let lb = a.distance_lower_bound(&b, &b_to_a);
        // Each box lies within 0.01·√3 of its centre.
        let slack = 2.0 * 0.01 * 3f64.sqrt();
        // Up to the rounding of the centres' distance itself.
        assert!(
            lb <= centres * (1.0 + 1e-15),
            "{far}: {lb} exceeds the centre distance {centres}"
        );
        // Less rounding: the frames are re-orthonormalised for boxes this far apart, so
        // nothing proportional to the offset but rounding remains.
        assert!(
            lb >= centres - slack - 1e-12 * far,
            "{far}: {lb} is not within {slack} of {centres}"
        );
    }
}

/// f32 frames are orthonormal only to about 1e-7; projecting an offset of 1e6 through them
/// errs by about 0.1. A slack proportional to the offset once covered that and made every
/// box of two models 1e6 apart "possibly as close as the nearest" (distance queries then
/// measured nearly every triangle pair). Far apart, the bound must stay within the boxes'
/// size of the true distance, for f32 and f64 frames alike.
#[test]
fn f32_boxes_far_apart_keep_a_tight_lower_bound() {
    let half = Vector3::new(0.3, 0.2, 0.1);
    let to_f32 = |b: Obb<f64>| Obb::<f32> {
        axes: b.axes.map(|r| r.map(|x| x as f32)),
        center: b.center.map(|x| x as f32),
        half: b.half.map(|x| (x as f32) * (1.0 + 1e-6)),
    };
    let a64 = obb(rotation(0.7, -0.4, 1.1), Vector3::zeros(), half);
    let b64 = obb(rotation(-0.2, 0.9, 0.3), Vector3::zeros(), half);
    let (a32, b32) = (to_f32(a64), to_f32(b64));
    for far in [1e3, 1e6, 1e9, 1e12] {
        for direction in [Vector3::x(), Vector3::new(1.0, 1.0, 1.0).normalize()] {
            let b_to_a = Pose::new(rotation(0.1, 0.2, 0.3), direction * far).unwrap();
            // Each box lies within its circumradius of its centre (which is at the origin).
            let reach = 2.0 * half.norm() * (1.0 + 1e-5);
            for lb in [
                a64.distance_lower_bound(&b64, &b_to_a),
                a32.distance_lower_bound(&b32, &b_to_a),
            ] {
                assert!(lb <= far, "{far}: {lb} exceeds the centre distance");
                assert!(
                    lb >= far - reach - 1e-12 * far,
                    "{far} along {direction:?}: {lb} is not within {reach} of {far}"
                );
            }
        }
    }
}

/// Thin boxes (single triangles: the leaves of two distant models) far apart: the bound
/// reaches the gap along the line through the centres (the closest direction is nearly
/// that line), where the centre bounds fall short
/// by a box's circumradius and the face-axis gaps by the cosine of their angle to the line.
/// Those weaker bounds made a distance between two bunnies 1e3 apart measure 16,752
/// triangle pairs where an AABB tree measured 45.
#[test]
fn thin_boxes_far_apart_are_bounded_along_the_centre_line() {
    let half = Vector3::new(0.3, 0.2, 0.0);
    for (k, far) in [10.0, 1e3, 1e6].into_iter().enumerate() {
        let a = obb(rotation(0.7, -0.4, 1.1 + k as f64), Vector3::zeros(), half);
        let b = obb(rotation(-0.2, 0.9, 0.3), Vector3::zeros(), half);
        let direction = Vector3::new(1.0, -2.0, 0.5).normalize();
        let b_to_a = Pose::new(Matrix3::identity(), direction * far).unwrap();
        // Support radii of the two flat boxes along the line.
        let support = |o: &Obb<f64>| {
            o.axes
                .iter()
                .zip(o.half)
                .map(|(axis, h)| h * Vector3::from(*axis).dot(&direction).abs())
                .sum::<f64>()
        };
        let gap = far - support(&a) - support(&b);
        let lb = a.distance_lower_bound(&b, &b_to_a);
        // The true distance exceeds the gap by at most how far the boxes bulge across the
        // line: (circumradius sum)^2 / far; no lower bound may exceed it.
        let bulge = (2.0 * half.norm()).powi(2) / far;
        assert!(lb <= gap + bulge, "{far}: {lb} above the distance");
        // Short of it by at most the frames' slack, which a distance bound lets grow to
        // 1% of the boxes' half-width sum (0.01 here) before it re-orthonormalises them.
        assert!(
            lb >= gap - 0.01,
            "{far}: {lb} short of the centre-line gap {gap}"
        );
    }
}

/// A pair given in A's box frame: B's axes `m` (columns), centre `t`, half-widths.
fn box_pair(m: Matrix3<f64>, t: [f64; 3], ha: [f64; 3], hb: [f64; 3], frame_error: f64) -> BoxPair {
    BoxPair {
        m,
        t: Vector3::from(t),
        ha: Vector3::from(ha),
        hb: Vector3::from(hb),
        frame_error,
    }
}

/// Two zero-size boxes at one point (two triangles collapsed onto the same vertex at the
/// origin, where rounding adds no slack): every projection and every radius is 0, and only
/// the strict comparisons of the separating-axis test keep the pair touching.
#[test]
fn zero_size_boxes_at_one_point_touch() {
    for m in [Matrix3::identity(), rotation(0.3, -1.1, 2.0)] {
        let pair = box_pair(m, [0.0; 3], [0.0; 3], [0.0; 3], 0.0);
        assert!(!pair.disjoint(Guard::rotation_only(0.0)), "{m}");
        assert!(!pair.disjoint(Guard::rotation_only(SAT_GUARD)), "{m}");
        assert_eq!(pair.distance_lower_bound(), 0.0);
        assert_eq!(pair.max_distance(), 0.0);
        // The alternating projections meet: no direction, and no gap along it.
        assert_eq!(pair.closest_direction_gap(), (0.0, 0.0));
    }
}

/// Equal boxes at zero offset, turned or not: overlapping, no distance, and the largest
/// distance is the diagonal.
#[test]
fn boxes_at_zero_offset_overlap() {
    let h = [1.0, 2.0, 3.0];
    for m in [Matrix3::identity(), rotation(0.3, -1.1, 2.0)] {
        let pair = box_pair(m, [0.0; 3], h, h, 0.0);
        assert!(!pair.disjoint(Guard::rotation_only(0.0)));
        assert_eq!(pair.distance_lower_bound(), 0.0);
        assert_eq!(pair.closest_direction_gap(), (0.0, 0.0));
    }
    let diagonal = 2.0 * 14f64.sqrt();
    let same = box_pair(Matrix3::identity(), [0.0; 3], h, h, 0.0);
    assert!((same.max_distance() - diagonal).abs() < 1e-12);
}

/// Unit cubes side by side with a gap of 1 along x: the lower bound (the box pair's own,
/// as the volumes' is) is the gap less the slack, exactly.
#[test]
fn cubes_side_by_side_have_their_gap_as_lower_bound() {
    let pair = box_pair(
        Matrix3::identity(),
        [3.0, 0.0, 0.0],
        [1.0; 3],
        [1.0; 3],
        0.0,
    );
    let expected = 1.0 - pair.slack(SAT_GUARD);
    assert!((pair.distance_lower_bound() - expected).abs() < 1e-12);
    assert!((pair.distance_lower_bound_until(0.5) - expected).abs() < 1e-12);
    assert!(pair.disjoint(Guard::rotation_only(SAT_GUARD)));
}

/// Where cubes of half-width `h` side by side along x (offset `y` across, frames `frame_error`
/// from orthonormal) stop touching, by the documented slack: the face axis x has radii
/// `2h + 3 guard h` (the guard on B's three rotation entries), and the slack adds
/// `guard · 6h + (4 frame_error + OFFSET_ROUNDING) (x + y)`; no other axis is as short.
fn cube_separation(h: f64, y: f64, frame_error: f64) -> f64 {
    let k = 4.0 * frame_error + OFFSET_ROUNDING;
    (2.0 * h + 3.0 * SAT_GUARD * h + 6.0 * SAT_GUARD * h + k * y) / (1.0 - k)
}

/// Boxes a billionth inside the slack touch and a billionth outside are apart: every term
/// of [`BoxPair::slack`] is pinned (at these sizes dropping or shrinking any one moves the
/// edge by far more), f64 frames and f32 frames alike.
#[test]
fn separation_is_reported_at_the_edge_of_the_slack() {
    let (h, y) = (1e-3, 0.5e-3);
    for frame_error in [0.0, 1e-10, 1e-6] {
        let edge = cube_separation(h, y, frame_error);
        for (scale, apart) in [(1.0 - 1e-9, false), (1.0 + 1e-9, true)] {
            let pair = box_pair(
                Matrix3::identity(),
                [edge * scale, y, 0.0],
                [h; 3],
                [h; 3],
                frame_error,
            );
            assert_eq!(
                pair.disjoint(Guard::rotation_only(SAT_GUARD)),
                apart,
                "frame error {frame_error}, offset {scale} of the edge"
            );
        }
    }
    // Stored f32 boxes are tested in f32 (`bv::pair_f32`): the f32 frame tolerance, 1e-6,
    // whatever their axes, 17u more guard and 64u (|t|₁ + Σ half-widths) more slack, with u
    // f32's unit roundoff. Its rounding of the guard and slack up to f32 moves the edge by
    // up to a few 1e-7 of itself, so the edge is pinned to 1e-6 here (dropping the f32
    // slack would move it by 1.6e-5, the f32 guard by 1.5e-6).
    let hf = 1e-3f32;
    let cube = Obb::<f32> {
        axes: [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]],
        center: [0.0; 3],
        half: [hf; 3],
    };
    let (h, u) = (f64::from(hf), f64::from(f32::EPSILON) / 2.0);
    let k = 4.0 * 1e-6 + OFFSET_ROUNDING + 64.0 * u;
    let guard = SAT_GUARD + 17.0 * u;
    let edge =
        (2.0 * h + 3.0 * guard * h + 6.0 * SAT_GUARD * h + 64.0 * u * 6.0 * h + k * y) / (1.0 - k);
    for (scale, apart) in [(1.0 - 1e-6, false), (1.0 + 1e-6, true)] {
        let pose = Pose::translation(edge * scale, y, 0.0);
        assert_eq!(
            !cube.overlaps(&cube, &pose, Guard::rotation_only(SAT_GUARD)),
            apart,
            "f32, {scale} of the edge"
        );
    }
}
