//! The box pair tests of two f32 boxes on the stored f32 values: the separating-axis
//! test and the face-axis and direction terms of the distance lower bound, four lanes per
//! operation where the f64 tests of [`super::pair::BoxPair`] take one or two, and no
//! widening of the 30 stored numbers. Exactly as conservative as the f64 tests: every
//! rounding of the f32 arithmetic is bounded and added to the guard and the slack, so a
//! pair the f64 overlap test keeps is kept here too, and the bound stays below the boxes'
//! distance.
//!
//! Only B's axes in A's box frame (`m`) are computed in f32. The centre offset `t` is
//! computed in f64, as the f64 tests do, and then rounded: in f32 its error would be
//! relative to the models' coordinates rather than to `t`, and inflate small boxes far
//! from the origin.
//!
//! Error bounds (u = 2⁻²⁴, rows of unit length within the f32 axis tolerance):
//!
//! - each entry of `m` is off by at most 16u: the pose's rotation rounded to f32 (u per
//!   entry), then two 3-term dot products of unit-length rows (3u each, the second
//!   carrying the first's error through a row of 1-norm at most √3);
//! - `t` rounded to f32 is off by u per component;
//! - a projection of `t` on an axis (a 3-term or 2-term combination of `t` and `m`) is
//!   off by at most 40u·|t|₁, and a radius (sums of half-widths times guarded `|m|`) is
//!   under-estimated by at most 8u of itself, the comparisons' sums by 2u;
//! - the gap along a direction `d` (`(d·t − Σ ha|d_i| − Σ hb|(mᵀd)_j|) / |d|`, a lower
//!   bound for any `d` when computed exactly) is off by at most 33u·(|t|₁ + Σ
//!   half-widths), and by 8u of itself for the division and the square root.
//!
//! So `|m|` gets 17u more guard than the f64 test's, every comparison and face-axis gap
//! `64u·(|t|₁ + Σ half-widths)` more slack, and the direction's gap that slack and 8u of
//! itself.

use super::pair::{Guard, CONVERGED, OFFSET_ROUNDING, SAT_GUARD};
use super::Obb;
use crate::pose::Pose;
use crate::real::Real;
use nalgebra::Vector3;

/// f32's unit roundoff, 2⁻²⁴.
const U: f64 = f32::EPSILON as f64 / 2.0;

/// Three f32 lanes and a fourth, in one SSE register on x86-64 (SSE2 is part of that
/// target's baseline, so no run-time detection is needed) and as an array elsewhere. The
/// fourth lane is 0 but in the rows of `rows_and_half`, and no result reads it. (The array
/// version is checked by the same tests with its cfg swapped by hand.)
#[derive(Clone, Copy, Debug)]
struct F4(lanes::V);

// SAFETY (every `unsafe` block of this module): the intrinsics are SSE and SSE2
// instructions, which the cfg below guarantees are enabled for the whole build (they are in
// the x86-64 baseline), so every CPU this code runs on has them; only `load` and `store`
// touch memory, the 16 bytes of the array each is given.
#[cfg(all(target_arch = "x86_64", target_feature = "sse2"))]
mod lanes {
    use std::arch::x86_64::*;

    pub type V = __m128;

    #[inline(always)]
    pub fn new(x: f32, y: f32, z: f32) -> V {
        unsafe { _mm_set_ps(0.0, z, y, x) }
    }
    #[inline(always)]
    pub fn splat(v: f32) -> V {
        unsafe { _mm_set_ps(0.0, v, v, v) }
    }
    /// The four values, in order.
    #[inline(always)]
    pub fn load(v: &[f32; 4]) -> V {
        // (A read of the 16 bytes the reference covers.)
        unsafe { _mm_loadu_ps(v.as_ptr()) }
    }
    /// Lane by lane, the larger (`b` where either is NaN).
    #[inline(always)]
    pub fn max(a: V, b: V) -> V {
        unsafe { _mm_max_ps(a, b) }
    }
    /// Lane by lane, `a` clamped to `[-h, h]` (`h` non-negative; a NaN `a` gives `-h`).
    #[inline(always)]
    pub fn clamp(a: V, h: V) -> V {
        unsafe { _mm_max_ps(_mm_min_ps(a, h), _mm_xor_ps(h, _mm_set1_ps(-0.0))) }
    }
    /// The four lanes, in order.
    #[inline(always)]
    pub fn store(v: V) -> [f32; 4] {
        let mut out = [0.0f32; 4];
        // (A write of the 16 bytes of `out`.)
        unsafe { _mm_storeu_ps(out.as_mut_ptr(), v) };
        out
    }
    #[inline(always)]
    pub fn add(a: V, b: V) -> V {
        unsafe { _mm_add_ps(a, b) }
    }
    #[inline(always)]
    pub fn sub(a: V, b: V) -> V {
        unsafe { _mm_sub_ps(a, b) }
    }
    #[inline(always)]
    pub fn mul(a: V, b: V) -> V {
        unsafe { _mm_mul_ps(a, b) }
    }
    #[inline(always)]
    pub fn div(a: V, b: V) -> V {
        unsafe { _mm_div_ps(a, b) }
    }
    #[inline(always)]
    pub fn sqrt(a: V) -> V {
        unsafe { _mm_sqrt_ps(a) }
    }
    #[inline(always)]
    pub fn abs(a: V) -> V {
        unsafe { _mm_andnot_ps(_mm_set1_ps(-0.0), a) }
    }
    /// Lane `k` of `a` in lanes 0 to 2 (and in lane 3, which callers multiply by 0).
    #[inline(always)]
    pub fn broadcast<const K: i32>(a: V) -> V {
        unsafe { _mm_shuffle_ps::<K>(a, a) }
    }
    pub const LANE_0: i32 = 0b00_00_00_00;
    pub const LANE_1: i32 = 0b01_01_01_01;
    pub const LANE_2: i32 = 0b10_10_10_10;
    /// `(y, z, x, w)`.
    #[inline(always)]
    pub fn rot1(a: V) -> V {
        unsafe { _mm_shuffle_ps::<0b11_00_10_01>(a, a) }
    }
    /// `(z, x, y, w)`.
    #[inline(always)]
    pub fn rot2(a: V) -> V {
        unsafe { _mm_shuffle_ps::<0b11_01_00_10>(a, a) }
    }
    /// Whether a lane of 0 to 2 of `a` exceeds `b`'s (false with NaN).
    #[inline(always)]
    pub fn any_gt(a: V, b: V) -> bool {
        unsafe { _mm_movemask_ps(_mm_cmpgt_ps(a, b)) & 0b111 != 0 }
    }
    /// The columns of the rows `r` (lane 3 of each row 0).
    #[inline(always)]
    pub fn transpose(r: [V; 3]) -> [V; 3] {
        let [r0, r1, r2] = r;
        let zero = unsafe { _mm_setzero_ps() };
        let (t0, t1) = unsafe { (_mm_unpacklo_ps(r0, r1), _mm_unpacklo_ps(r2, zero)) };
        let (t2, t3) = unsafe { (_mm_unpackhi_ps(r0, r1), _mm_unpackhi_ps(r2, zero)) };
        unsafe {
            [
                _mm_movelh_ps(t0, t1),
                _mm_movehl_ps(t1, t0),
                _mm_movelh_ps(t2, t3),
            ]
        }
    }
}

#[cfg(not(all(target_arch = "x86_64", target_feature = "sse2")))]
mod lanes {
    pub type V = [f32; 4];

    #[inline(always)]
    fn zip(a: V, b: V, f: impl Fn(f32, f32) -> f32) -> V {
        let ([a0, a1, a2, a3], [b0, b1, b2, b3]) = (a, b);
        [f(a0, b0), f(a1, b1), f(a2, b2), f(a3, b3)]
    }
    #[inline(always)]
    pub fn new(x: f32, y: f32, z: f32) -> V {
        [x, y, z, 0.0]
    }
    #[inline(always)]
    pub fn splat(v: f32) -> V {
        [v, v, v, 0.0]
    }
    #[inline(always)]
    pub fn load(v: &[f32; 4]) -> V {
        *v
    }
    #[inline(always)]
    pub fn store(v: V) -> [f32; 4] {
        v
    }
    #[inline(always)]
    pub fn max(a: V, b: V) -> V {
        zip(a, b, f32::max)
    }
    #[inline(always)]
    pub fn clamp(a: V, h: V) -> V {
        zip(a, h, |x, h| x.min(h).max(-h))
    }
    #[inline(always)]
    pub fn add(a: V, b: V) -> V {
        zip(a, b, |x, y| x + y)
    }
    #[inline(always)]
    pub fn sub(a: V, b: V) -> V {
        zip(a, b, |x, y| x - y)
    }
    #[inline(always)]
    pub fn mul(a: V, b: V) -> V {
        zip(a, b, |x, y| x * y)
    }
    #[inline(always)]
    pub fn div(a: V, b: V) -> V {
        zip(a, b, |x, y| x / y)
    }
    #[inline(always)]
    pub fn sqrt(a: V) -> V {
        let [x, y, z, w] = a;
        [x.sqrt(), y.sqrt(), z.sqrt(), w.sqrt()]
    }
    #[inline(always)]
    pub fn abs(a: V) -> V {
        let [x, y, z, w] = a;
        [x.abs(), y.abs(), z.abs(), w.abs()]
    }
    #[inline(always)]
    pub fn broadcast<const K: i32>(a: V) -> V {
        let [x, y, z, _] = a;
        splat(match K {
            LANE_0 => x,
            LANE_1 => y,
            _ => z,
        })
    }
    pub const LANE_0: i32 = 0;
    pub const LANE_1: i32 = 1;
    pub const LANE_2: i32 = 2;
    #[inline(always)]
    pub fn rot1(a: V) -> V {
        let [x, y, z, w] = a;
        [y, z, x, w]
    }
    #[inline(always)]
    pub fn rot2(a: V) -> V {
        let [x, y, z, w] = a;
        [z, x, y, w]
    }
    #[inline(always)]
    pub fn any_gt(a: V, b: V) -> bool {
        let ([a0, a1, a2, _], [b0, b1, b2, _]) = (a, b);
        (a0 > b0) | (a1 > b1) | (a2 > b2)
    }
    #[inline(always)]
    pub fn transpose(r: [V; 3]) -> [V; 3] {
        let [[a, b, c, _], [d, e, f, _], [g, h, i, _]] = r;
        [new(a, d, g), new(b, e, h), new(c, f, i)]
    }
}

impl F4 {
    #[inline(always)]
    fn new(x: f32, y: f32, z: f32) -> F4 {
        F4(lanes::new(x, y, z))
    }
    #[inline(always)]
    fn splat(v: f32) -> F4 {
        F4(lanes::splat(v))
    }
    #[inline(always)]
    fn add(self, o: F4) -> F4 {
        F4(lanes::add(self.0, o.0))
    }
    #[inline(always)]
    fn sub(self, o: F4) -> F4 {
        F4(lanes::sub(self.0, o.0))
    }
    #[inline(always)]
    fn mul(self, o: F4) -> F4 {
        F4(lanes::mul(self.0, o.0))
    }
    /// `self + a * b`.
    #[inline(always)]
    fn mul_add(self, a: F4, b: F4) -> F4 {
        self.add(a.mul(b))
    }
    #[inline(always)]
    fn div(self, o: F4) -> F4 {
        F4(lanes::div(self.0, o.0))
    }
    #[inline(always)]
    fn sqrt(self) -> F4 {
        F4(lanes::sqrt(self.0))
    }
    #[inline(always)]
    fn abs(self) -> F4 {
        F4(lanes::abs(self.0))
    }
    #[inline(always)]
    fn lane0(self) -> F4 {
        F4(lanes::broadcast::<{ lanes::LANE_0 }>(self.0))
    }
    #[inline(always)]
    fn lane1(self) -> F4 {
        F4(lanes::broadcast::<{ lanes::LANE_1 }>(self.0))
    }
    #[inline(always)]
    fn lane2(self) -> F4 {
        F4(lanes::broadcast::<{ lanes::LANE_2 }>(self.0))
    }
    /// The lanes moved one place down, cyclically over the three: `(y, z, x)`.
    #[inline(always)]
    fn rot1(self) -> F4 {
        F4(lanes::rot1(self.0))
    }
    /// The lanes moved two places down: `(z, x, y)`.
    #[inline(always)]
    fn rot2(self) -> F4 {
        F4(lanes::rot2(self.0))
    }
    /// Whether any of the three lanes exceeds `other`'s (false with NaN: not separated).
    #[inline(always)]
    fn any_gt(self, other: F4) -> bool {
        lanes::any_gt(self.0, other.0)
    }
    /// The lanes as numbers.
    #[inline(always)]
    fn lanes(self) -> [f32; 4] {
        lanes::store(self.0)
    }
    /// Lane by lane, the larger (where a lane is NaN, either value: the callers take a
    /// largest lane, which ignores NaN).
    #[inline(always)]
    fn max(self, o: F4) -> F4 {
        F4(lanes::max(self.0, o.0))
    }
    /// The largest of the three lanes, NaN ignored (as `f64::max` does).
    #[inline(always)]
    fn max_lane(self) -> f32 {
        let [x, y, z, _] = self.lanes();
        x.max(y).max(z)
    }
    /// The point of the box `[-h, h]` nearest to the lanes (`h` non-negative). A NaN lane
    /// (a damaged file) gives some point of the box: any direction between the points
    /// gives a valid bound.
    #[inline(always)]
    fn clamp(self, h: F4) -> F4 {
        F4(lanes::clamp(self.0, h.0))
    }
    /// The dot product of the three lanes.
    #[inline(always)]
    fn dot(self, o: F4) -> f32 {
        let [x, y, z, _] = self.mul(o).lanes();
        x + y + z
    }
}

/// A non-negative `x` rounded to an f32 at least as large: the nearest f32 (at most u
/// below `x`) raised by 4 ulps, which leaves room for the product's own rounding.
/// (`Real::from_f64_up`, exact to the ulp, costs a select per call on this hot path.)
#[inline(always)]
fn up(x: f64) -> f32 {
    (x as f32) * (1.0 + 4.0 * f32::EPSILON)
}

/// Rows of a 3×3 matrix as lanes, transposed: the columns.
#[inline(always)]
fn transpose(rows: [F4; 3]) -> [F4; 3] {
    let [r0, r1, r2] = rows;
    lanes::transpose([r0.0, r1.0, r2.0]).map(F4)
}

/// `Σ_k s_k rows_k`: the row vector `s` times the matrix of `rows`.
#[inline(always)]
fn combine(s: F4, rows: &[F4; 3]) -> F4 {
    let [r0, r1, r2] = *rows;
    r0.mul(s.lane0())
        .mul_add(r1, s.lane1())
        .mul_add(r2, s.lane2())
}

/// One edge-axis family of the separating-axis test, the three axes `a_i × b_j` of one `i`
/// at once: the projection of the centre offset, `|t_i2 m_i1j − t_i1 m_i2j|`, and the sum
/// of the boxes' radii, `ha_i1 |m_i2j| + ha_i2 |m_i1j| + hb_j1 |m_ij2| + hb_j2 |m_ij1|`, both
/// scaled by the axis length, where `(i1, i2)` follow `i` cyclically. The arguments are the
/// family's `i` (rows `i1` and `i2` of `m`, rows `i`, `i1`, `i2` of the guarded `|m|`, and
/// the scalars splatted) and B's half-widths.
#[inline(always)]
fn edge_terms(family: &EdgeFamily, hb: F4) -> (F4, F4) {
    let (m_i1, m_i2) = family.m;
    let (abs_i, abs_i1, abs_i2) = family.abs;
    let (t_i1, t_i2) = family.t;
    let (ha_i1, ha_i2) = family.ha;
    let tl = m_i1.mul(t_i2).sub(m_i2.mul(t_i1)).abs();
    let ra = abs_i2.mul(ha_i1).mul_add(abs_i1, ha_i2);
    let rb = hb.rot1().mul(abs_i.rot2()).mul_add(hb.rot2(), abs_i.rot1());
    (tl, ra.add(rb))
}

/// What [`edge_terms`] reads of one family `i` of edge axes (see there).
struct EdgeFamily {
    m: (F4, F4),
    abs: (F4, F4, F4),
    t: (F4, F4),
    ha: (F4, F4),
}

/// The three edge-axis families of two boxes (`m`, `t`, `ha` as in [`F32Pair`], `abs_m`
/// the guarded `|m|`), in the order `i` = 0, 1, 2.
#[inline(always)]
fn edge_families(m: [F4; 3], abs_m: [F4; 3], t: F4, ha: F4) -> [EdgeFamily; 3] {
    let (tx, ty, tz) = (t.lane0(), t.lane1(), t.lane2());
    let (hx, hy, hz) = (ha.lane0(), ha.lane1(), ha.lane2());
    let [m0, m1, m2] = m;
    let [abs0, abs1, abs2] = abs_m;
    [
        EdgeFamily {
            m: (m1, m2),
            abs: (abs0, abs1, abs2),
            t: (ty, tz),
            ha: (hy, hz),
        },
        EdgeFamily {
            m: (m2, m0),
            abs: (abs1, abs2, abs0),
            t: (tz, tx),
            ha: (hz, hx),
        },
        EdgeFamily {
            m: (m0, m1),
            abs: (abs2, abs0, abs1),
            t: (tx, ty),
            ha: (hx, hy),
        },
    ]
}

/// A box's axes as three rows and its half-widths, each loaded as four values: the three
/// of the row and, in the fourth lane, the next stored number (which everything that
/// reads the rows ignores: they are only broadcast lane by lane or transposed), and the
/// half-widths with a 0 in the fourth lane.
#[inline(always)]
fn rows_and_half<R: Real>(o: &Obb<R>) -> ([F4; 3], F4) {
    let [[a0, a1, a2], [a3, a4, a5], [a6, a7, a8]] = o.axes;
    let [c0, _, _] = o.center;
    let [h0, h1, h2] = o.half;
    let f = |x: R| x.to_f32();
    let rows = [
        [f(a0), f(a1), f(a2), f(a3)],
        [f(a3), f(a4), f(a5), f(a6)],
        [f(a6), f(a7), f(a8), f(c0)],
    ];
    let half = [f(h0), f(h1), f(h2), 0.0];
    (rows.map(|r| F4(lanes::load(&r))), F4(lanes::load(&half)))
}

/// Two f32 boxes in box A's frame, as [`super::pair::BoxPair`] holds two boxes in f64:
/// B's axes `m` in f32 (each entry within 16u), the centre offset `t` in f64 and rounded,
/// and the half-widths.
struct F32Pair {
    m: [F4; 3],
    t: F4,
    t64: [f64; 3],
    ha: F4,
    hb: F4,
    /// `Σ ha`, `Σ hb` and `|t|₁`, in f64.
    sum_a: f64,
    sum_b: f64,
    t_norm1: f64,
}

impl F32Pair {
    /// B (posed in A's model frame by `b_to_a`) in A's box frame. `R` is `f32` (see
    /// [`Real::to_f32`], exact there).
    #[inline(always)]
    fn new<R: Real>(a: &Obb<R>, b: &Obb<R>, b_to_a: &Pose) -> F32Pair {
        F32Pair::with_offset(a, b, b_to_a, &centre_offset(a, b, b_to_a))
    }

    /// As [`F32Pair::new`], given [`centre_offset`].
    #[inline(always)]
    fn with_offset<R: Real>(
        a: &Obb<R>,
        b: &Obb<R>,
        b_to_a: &Pose,
        offset: &Vector3<f64>,
    ) -> F32Pair {
        let (rows_a, ha) = rows_and_half(a);
        let (rows_b, hb) = rows_and_half(b);
        // The centre offset in A's box frame (exact f32 axes, widened).
        let [a0, a1, a2] = a.axes_f64();
        let project = |[x, y, z]: [f64; 3]| x * offset.x + y * offset.y + z * offset.z;
        let t64 = [project(a0), project(a1), project(a2)];
        let [t0, t1, t2] = t64;
        // m = A R Bᵀ, row by row: W = R Bᵀ (rows of R against B's columns), then m = A W.
        let [p0, p1, p2]: [[f64; 3]; 3] = b_to_a.rotation().transpose().into();
        let pose_row = |[x, y, z]: [f64; 3]| F4::new(x as f32, y as f32, z as f32);
        let columns_b = transpose(rows_b);
        let w = [
            combine(pose_row(p0), &columns_b),
            combine(pose_row(p1), &columns_b),
            combine(pose_row(p2), &columns_b),
        ];
        let [r0, r1, r2] = rows_a;
        F32Pair {
            m: [combine(r0, &w), combine(r1, &w), combine(r2, &w)],
            t: F4::new(t0 as f32, t1 as f32, t2 as f32),
            t64,
            ha,
            hb,
            sum_a: half_sum(a),
            sum_b: half_sum(b),
            t_norm1: t0.abs() + t1.abs() + t2.abs(),
        }
    }

    /// The f64 test's slack ([`super::pair::BoxPair::slack`]) with f32 frames, plus the
    /// f32 rounding bound of the module documentation.
    #[inline(always)]
    fn slack(&self, guard: f64) -> f64 {
        let frame_error = super::obb::axis_tolerance(crate::real::Precision::F32);
        guard * (self.sum_a + self.sum_b)
            + (4.0 * frame_error + OFFSET_ROUNDING) * self.t_norm1
            + 64.0 * U * (self.t_norm1 + self.sum_a + self.sum_b)
    }

    /// Whether the boxes are certainly disjoint, by the 15 separating axes, with `guard` as
    /// in [`super::pair::BoxPair::disjoint`]: `true` only where that test also reports
    /// them disjoint, up to the rounding bounds of the module documentation (which hold
    /// where the pair is [`within_f32_range`]: docs/LIMITATIONS.md says where not).
    #[inline(always)]
    fn disjoint(&self, guard: Guard) -> bool {
        let (m, t, ha, hb) = (self.m, self.t, self.ha, self.hb);
        let slack = F4::splat(up(self.slack(guard.rotation) + guard.mapping));
        let g = F4::splat(up(guard.rotation + 17.0 * U));
        let abs_m = [m[0].abs().add(g), m[1].abs().add(g), m[2].abs().add(g)];
        // A's face axes, all three at once: |t_i| > ha_i + Σ_j hb_j |m_ij|.
        let rb = combine(hb, &transpose(abs_m));
        if t.abs().any_gt(ha.add(rb).add(slack)) {
            return true;
        }
        // B's face axes: |Σ_i t_i m_ij| > Σ_i ha_i |m_ij| + hb_j.
        let tb = combine(t, &m).abs();
        let ra = combine(ha, &abs_m);
        if tb.any_gt(ra.add(hb).add(slack)) {
            return true;
        }
        // Edge axes a_i × b_j, the three j of one i at once: the offset's projection
        // beyond the radii and the slack.
        let separates = |family: &EdgeFamily| {
            let (projection, radii) = edge_terms(family, hb);
            projection.any_gt(radii.add(slack))
        };
        let [i0, i1, i2] = edge_families(m, abs_m, t, ha);
        separates(&i0) || separates(&i1) || separates(&i2)
    }

    /// [`super::pair::BoxPair::distance_lower_bound_until`] in f32: the face-axis gaps;
    /// unless they reach `enough`, the gap along the direction of the alternating
    /// projections' points; and where that falls short of the points' distance (as the f64
    /// bound decides), the edge-edge axes' gaps. Each less the f64 slack and the f32
    /// rounding bound (for the gaps divided by a length, also 8u of themselves: the
    /// division and square root), so a lower bound on the box distance.
    #[inline(always)]
    fn distance_lower_bound_until(&self, enough: f64) -> f64 {
        let (m, t, ha, hb) = (self.m, self.t, self.ha, self.hb);
        let slack = self.slack(SAT_GUARD);
        // The entries' error, as the overlap test's guard covers it (no §4.5 guard here,
        // as in f64).
        let g = F4::splat(up(17.0 * U));
        let abs_m = [m[0].abs().add(g), m[1].abs().add(g), m[2].abs().add(g)];
        let face_a = t.abs().sub(ha).sub(combine(hb, &transpose(abs_m)));
        let face_b = combine(t, &m).abs().sub(combine(ha, &abs_m)).sub(hb);
        let best = f64::from(face_a.max(face_b).max_lane()) - slack;
        let best = best.max(0.0);
        if best >= enough {
            return best;
        }
        // Alternating projections: B's centre clamped into A, the point of B nearest it,
        // that clamped into A (PROJECTION_STEPS = 1 of the f64 bound).
        let columns_m = transpose(m);
        let p = t.clamp(ha);
        let q = t.add(combine(combine(p.sub(t), &m).clamp(hb), &columns_m));
        let p = q.clamp(ha);
        let q = t.add(combine(combine(p.sub(t), &m).clamp(hb), &columns_m));
        let d = q.sub(p);
        let length2 = d.dot(d);
        // (Points that meet, or NaN from a damaged file: no direction, and, as in f64,
        // nothing more to try.)
        if !(length2 > 0.0 && length2.is_finite()) {
            return best;
        }
        let length = length2.sqrt();
        let numerator = d.dot(t) - ha.dot(d.abs()) - hb.dot(combine(d, &m).abs());
        let gap = f64::from(numerator / length);
        // |m̂ᵀd| is off by 16u|d|₁ per entry, the dot products by 3u of their terms: the
        // module's 64u bound per unit of direction, and the division and root's 8u.
        let gap = gap - slack - 8.0 * U * gap.abs();
        let best = best.max(gap);
        if edges_could_add(gap, slack, f64::from(length), best, enough) {
            best.max(self.edge_axis_gap(abs_m, slack))
        } else {
            best
        }
    }

    /// The largest gap on the 9 edge-edge axes `a_i × b_j`
    /// ([`super::pair::BoxPair::edge_axis_gap`]), less `slack`, or 0: each axis's
    /// projected gap (off by at most the module's `64u·(|t|₁ + Σ half-widths)`, in
    /// `slack`) divided by an upper bound on the axis length. That length, `|(m_i1j,
    /// m_i2j)|` (B's axis `j`, column `j` of `m`, across A's axis `i`: the exact length of
    /// that cross product in A's frame), is off by at most 23u through `m`'s entries and
    /// about 3u through its own rounding, both inside the 32u added. No axis needs
    /// skipping: a gap is positive only on an axis longer than the slack's share of the
    /// offset (about 8e-6), far above that error.
    ///
    /// So an edge gap loses about `64u·(|t|₁ + Σ half-widths)` over the axis length
    /// against the f64 bound's: tight across edges that cross at large angles, looser
    /// for nearly parallel ones, where the face axes bound the boxes about as well.
    // Not inlined: few pairs get here, and inlined into the traversal it changed the code
    // generated for the collision queries too (more instructions there).
    #[inline(never)]
    fn edge_axis_gap(&self, abs_m: [F4; 3], slack: f64) -> f64 {
        let length_error = F4::splat(up(32.0 * U));
        let slack = F4::splat(up(slack));
        let gaps = edge_families(self.m, abs_m, self.t, self.ha)
            .iter()
            .map(|family| {
                let (projection, radii) = edge_terms(family, self.hb);
                let (m_i1, m_i2) = family.m;
                let length = m_i1.mul(m_i1).add(m_i2.mul(m_i2)).sqrt().add(length_error);
                projection.sub(radii).sub(slack).div(length)
            })
            .fold(F4::splat(0.0), F4::max);
        // The division's rounding and the slack's subtraction: within 8u of the gap.
        // (Lane 3 is 0 / 0, which the largest lane does not read.)
        let gap = f64::from(gaps.max_lane());
        (gap - 8.0 * U * gap.abs()).max(0.0)
    }
}

/// B's centre less A's, in A's model frame, in f64 (as the f64 tests compute it).
#[inline(always)]
fn centre_offset<R: Real>(a: &Obb<R>, b: &Obb<R>, b_to_a: &Pose) -> Vector3<f64> {
    b_to_a.apply(&Vector3::from(b.center_f64())) - Vector3::from(a.center_f64())
}

/// Whether the f64 bound would go on to the edge-edge axes after the direction's `gap`
/// (lowered by `slack`) between points `length` apart, as [`super::pair::BoxPair`]'s rule
/// decides on the unlowered gap (short of `CONVERGED` of the points' distance), and the
/// bound `best` so far is still short of `enough`. Either way the bound stays a lower
/// bound: this only decides whether the edge axes are worth their cost.
#[inline(always)]
fn edges_could_add(gap: f64, slack: f64, length: f64, best: f64, enough: f64) -> bool {
    gap + slack < CONVERGED * length && best < enough
}

/// A box's half-widths summed, in f64.
#[inline(always)]
fn half_sum<R: Real>(o: &Obb<R>) -> f64 {
    o.half_f64().iter().sum()
}

/// Whether the module's rounding bounds hold for a pair whose centre offset (1-norm) and
/// half-widths sum to `scale`: f32's relative rounding needs the few-term sums of the
/// tests below its largest number, and the slack, proportional to `scale`, far above the
/// absolute error of products that underflow. Outside (models about 1e36 across or posed
/// as far out, and below 1e-30; or a NaN) the distance bound hands the pair to f64; the
/// overlap test does not check, since a check there costs every collision query
/// measurably (docs/LIMITATIONS.md).
#[inline(always)]
fn within_f32_range(scale: f64) -> bool {
    (1e-30..=1e36).contains(&scale)
}

/// Whether two f32 boxes are certainly disjoint (B posed in A's model frame by `b_to_a`),
/// by the 15 separating axes, with `guard` as in [`super::pair::BoxPair::disjoint`]:
/// `true` only where that test also reports them disjoint, up to the rounding bounds of
/// the module documentation. `R` is `f32` (see [`Real::to_f32`], exact there).
#[inline(always)]
pub(crate) fn disjoint<R: Real>(a: &Obb<R>, b: &Obb<R>, b_to_a: &Pose, guard: Guard) -> bool {
    F32Pair::new(a, b, b_to_a).disjoint(guard)
}

/// A lower bound on the distance between two f32 boxes (B posed in A's model frame by
/// `b_to_a`) and the distance of their centres: the terms of the f64 bound in f32, with
/// their rounding taken off, stopping once the bound reaches `enough`. `None` where the
/// f64 bound would re-orthonormalise the frames (boxes far apart relative to their size,
/// `far(|offset|₁, Σ half-widths)`) and outside [`within_f32_range`]: the caller then
/// computes it.
#[inline(always)]
pub(crate) fn distance_lower_bound_until<R: Real>(
    a: &Obb<R>,
    b: &Obb<R>,
    b_to_a: &Pose,
    enough: f64,
    far: impl Fn(f64, f64) -> bool,
) -> Option<(f64, f64)> {
    // Checked before anything is computed in f32: past it the caller computes in f64.
    let offset = centre_offset(a, b, b_to_a);
    let (offset_norm1, halves) = (offset.abs().sum(), half_sum(a) + half_sum(b));
    if far(offset_norm1, halves) || !within_f32_range(offset_norm1 + halves) {
        return None;
    }
    let pair = F32Pair::with_offset(a, b, b_to_a, &offset);
    let [t0, t1, t2] = pair.t64;
    let centres = (t0 * t0 + t1 * t1 + t2 * t2).sqrt();
    Some((pair.distance_lower_bound_until(enough), centres))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The edge axes are computed where the unlowered gap is short of `CONVERGED` of the
    /// points' distance (as in f64, exclusive at equality) and the bound short of `enough`
    /// (exclusive too: a bound that reached it prunes already).
    #[test]
    fn edge_axes_only_where_the_unlowered_gap_is_short_and_the_bound_is_not_enough() {
        // CONVERGED · 10 is 9 exactly; 8.5 + 0.5 too.
        assert_eq!(CONVERGED * 10.0, 9.0);
        // Short: the unlowered gap 8.9 < 9.
        assert!(edges_could_add(8.4, 0.5, 10.0, 8.4, 100.0));
        // At the threshold, and above it though the lowered gap alone is below.
        assert!(!edges_could_add(8.5, 0.5, 10.0, 8.5, 100.0));
        assert!(!edges_could_add(8.6, 0.5, 10.0, 8.6, 100.0));
        // Short, but the bound reached `enough` (exactly, or past it).
        assert!(!edges_could_add(8.4, 0.5, 10.0, 8.4, 8.4));
        assert!(!edges_could_add(8.4, 0.5, 10.0, 8.4, 8.0));
        assert!(edges_could_add(8.4, 0.5, 10.0, 8.4, 8.5));
    }

    /// `|m|` with the rounding guard the distance bound adds.
    fn guarded_abs(pair: &F32Pair) -> [F4; 3] {
        let g = F4::splat(up(17.0 * U));
        pair.m.map(|row| row.abs().add(g))
    }

    /// A stick: a box of f32 frame `axes` (rows) and half-widths (1, 0, 0) at `center`.
    fn stick(axes: [[f64; 3]; 3], center: [f64; 3]) -> Obb<f32> {
        Obb {
            axes: axes.map(|row| row.map(|v| v as f32)),
            center: center.map(|v| v as f32),
            half: [1.0, 0.0, 0.0],
        }
    }

    /// Two sticks on skew lines `h` apart, crossing at 10°, B's centre off the closest
    /// points along its line, both frames turned about the sticks: no face axis is the
    /// common perpendicular and one alternating projection falls short, so the edge axis
    /// `a₀ × b₀` carries the bound, which comes within the slacks of `h` and stays below
    /// it.
    #[test]
    fn the_edge_axes_bound_crossing_sticks_by_their_distance() {
        let h = 0.25;
        let (s10, c10) = 10f64.to_radians().sin_cos();
        let (s30, c30) = 30f64.to_radians().sin_cos();
        let a = stick(
            [[1.0, 0.0, 0.0], [0.0, c30, s30], [0.0, -s30, c30]],
            [0.0; 3],
        );
        // B along v = (cos 10°, sin 10°, 0); its other axes z and v × z, turned 30° about v.
        let (v, w1, w2) = ([c10, s10, 0.0], [0.0, 0.0, 1.0], [s10, -c10, 0.0]);
        let turn =
            |p: f64, q: f64| crate::arr3::map(crate::arr3::zip(w1, w2), |(x, y)| p * x + q * y);
        let b = stick(
            [v, turn(c30, s30), turn(-s30, c30)],
            [0.4 * c10, 0.4 * s10, h],
        );
        let here = Pose::identity();
        let pair = F32Pair::new(&a, &b, &here);
        // The edge gaps, and the bound they carry: below h by the slacks divided by the
        // axis length, sin 10°.
        let edges = pair.edge_axis_gap(guarded_abs(&pair), pair.slack(SAT_GUARD));
        assert!(edges <= h && edges > h - 2e-4, "{edges}");
        let bound = pair.distance_lower_bound_until(f64::INFINITY);
        assert_eq!(bound, edges);
        // The terms before the edge axes are short of it.
        let f64_pair = super::super::pair::BoxPair::new(
            &a.axes_matrix(),
            &Vector3::from(a.center_f64()),
            Vector3::from(a.half_f64()),
            &b.axes_matrix(),
            &Vector3::from(b.center_f64()),
            Vector3::from(b.half_f64()),
            &here,
            super::super::obb::axis_tolerance(crate::real::Precision::F32),
        );
        let (direction_gap, apart) = f64_pair.closest_direction_gap();
        assert!(direction_gap < CONVERGED * apart && direction_gap < 0.9 * h);
        let (m, t) = (f64_pair.m, f64_pair.t);
        let faces = (0..3).map(|i| {
            let along_a = t[i].abs() - (m.row(i).abs() * f64_pair.hb)[0] - f64_pair.ha[i];
            let along_b = (m.column(i).dot(&t)).abs() - f64_pair.ha.dot(&m.column(i).abs());
            along_a.max(along_b - f64_pair.hb[i])
        });
        assert!(faces.fold(0.0, f64::max) < 0.9 * h);
    }

    /// Two sticks along x, B turned by 1e-8 about z and 1000 above A: the edge axis
    /// `a₀ × b₀` is of length about 1e-8, within the rounding of `m`. The edge gaps stay
    /// finite and below the distance, and the bound, from the other axes, within 0.01 of
    /// it.
    #[test]
    fn nearly_parallel_edges_keep_the_bound_below_the_distance() {
        let (s, c) = 1e-8f64.sin_cos();
        let a = stick(
            [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]],
            [0.0; 3],
        );
        let b = stick(
            [[c, s, 0.0], [-s, c, 0.0], [0.0, 0.0, 1.0]],
            [0.0, 0.0, 1000.0],
        );
        let pair = F32Pair::new(&a, &b, &Pose::identity());
        let edges = pair.edge_axis_gap(guarded_abs(&pair), pair.slack(SAT_GUARD));
        assert!(edges.is_finite() && edges <= 1000.0, "{edges}");
        let bound = pair.distance_lower_bound_until(f64::INFINITY);
        assert!(bound <= 1000.0 && bound > 999.99, "{bound}");
    }
}
