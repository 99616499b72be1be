//! The separating-axis test of two f32 boxes, on the stored f32 values: four lanes per
//! operation where the f64 test of [`super::pair::BoxPair::disjoint`] takes one or two,
//! and no widening of the 30 stored numbers. Exactly as conservative as the f64 test:
//! every rounding of the f32 arithmetic is bounded below and added to the guard and the
//! slack, so a pair the f64 test keeps is kept here too.
//!
//! Only B's axes in A's box frame (`m`) are computed in f32. The centre offset `t` is
//! computed in f64, as the f64 test does, and then rounded: in f32 its error would be
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
//!   under-estimated by at most 8u of itself, the comparisons' sums by 2u.
//!
//! So `|m|` gets 17u more guard than the f64 test's, and every comparison
//! `64u·(|t|₁ + Σ half-widths)` more slack.

use super::pair::OFFSET_ROUNDING;
use super::Obb;
use crate::pose::Pose;
use crate::real::Real;
use nalgebra::Vector3;

/// f32's unit roundoff, 2⁻²⁴.
const U: f64 = f32::EPSILON as f64 / 2.0;

/// Three f32 lanes and a fourth that stays 0, in one SSE register on x86-64 (SSE2 is part
/// of that target's baseline, so no run-time detection is needed) and as an array
/// elsewhere.
#[derive(Clone, Copy, Debug)]
struct F4(lanes::V);

// SAFETY (every `unsafe` block of this module): the intrinsics are SSE and SSE2
// instructions, which the cfg below guarantees are enabled for the whole build (they are in
// the x86-64 baseline), so every CPU this code runs on has them; only `load` reads memory,
// the 16 bytes of the array it is given.
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

/// One edge-axis family of the separating-axis test, the three `a_i × b_j` of one `i` at
/// once: `|t_i2 m_i1j − t_i1 m_i2j| > ha_i1 |m_i2j| + ha_i2 |m_i1j| + hb_j1 |m_ij2| +
/// hb_j2 |m_ij1| + slack` for some `j`, where `(i1, i2)` follow `i` cyclically. The
/// arguments are rows `i1` and `i2` of `m`, rows `i`, `i1`, `i2` of the guarded `|m|`, and
/// the scalars splatted.
#[inline(always)]
#[allow(clippy::too_many_arguments)]
fn edge_separates(
    (m_i1, m_i2): (F4, F4),
    (abs_i, abs_i1, abs_i2): (F4, F4, F4),
    (t_i1, t_i2): (F4, F4),
    (ha_i1, ha_i2): (F4, F4),
    hb: F4,
    slack: F4,
) -> bool {
    let tl = m_i1.mul(t_i2).sub(m_i2.mul(t_i1)).abs();
    let ra = abs_i2.mul(ha_i1).mul_add(abs_i1, ha_i2);
    let rb = hb.rot1().mul(abs_i.rot2()).mul_add(hb.rot2(), abs_i.rot1());
    tl.any_gt(ra.add(rb).add(slack))
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

/// Whether two f32 boxes are certainly disjoint (B posed in A's model frame by `b_to_a`),
/// by the 15 separating axes, with `guard` as in [`super::pair::BoxPair::disjoint`]:
/// `true` only where that test also reports them disjoint, up to the rounding bounds of
/// the module documentation. `R` is `f32` (see [`Real::to_f32`], exact there).
#[inline(always)]
pub(crate) fn disjoint<R: Real>(a: &Obb<R>, b: &Obb<R>, b_to_a: &Pose, guard: f64) -> bool {
    let (rows_a, ha) = rows_and_half(a);
    let (rows_b, hb) = rows_and_half(b);

    // The centre offset in f64, then in A's box frame (exact f32 axes, widened).
    let ca = Vector3::from(a.center_f64());
    let cb = Vector3::from(b.center_f64());
    let offset = b_to_a.apply(&cb) - ca;
    let [a0, a1, a2] = a.axes_f64();
    let project = |[x, y, z]: [f64; 3]| x * offset.x + y * offset.y + z * offset.z;
    let (t0, t1, t2) = (project(a0), project(a1), project(a2));
    let t = F4::new(t0 as f32, t1 as f32, t2 as f32);

    // m = A R Bᵀ, row by row: W = R Bᵀ (rows of R against B's columns), then m = A W.
    let [p0, p1, p2]: [[f64; 3]; 3] = b_to_a.rotation().transpose().into();
    let pose_row = |[x, y, z]: [f64; 3]| F4::new(x as f32, y as f32, z as f32);
    let columns_b = transpose(rows_b);
    let w = [
        combine(pose_row(p0), &columns_b),
        combine(pose_row(p1), &columns_b),
        combine(pose_row(p2), &columns_b),
    ];
    let m = [
        combine(rows_a[0], &w),
        combine(rows_a[1], &w),
        combine(rows_a[2], &w),
    ];

    // The f64 test's guard and slack, plus the f32 rounding bounds (module docs).
    let (sum_a, sum_b) = (
        a.half_f64().iter().sum::<f64>(),
        b.half_f64().iter().sum::<f64>(),
    );
    let t_norm1 = t0.abs() + t1.abs() + t2.abs();
    let frame_error = super::obb::axis_tolerance(R::PRECISION);
    let slack = guard * (sum_a + sum_b)
        + (4.0 * frame_error + OFFSET_ROUNDING) * t_norm1
        + 64.0 * U * (t_norm1 + sum_a + sum_b);
    let slack = F4::splat(up(slack));
    let g = F4::splat(up(guard + 17.0 * U));
    let abs_m = [m[0].abs().add(g), m[1].abs().add(g), m[2].abs().add(g)];
    let abs_t = t.abs();

    // A's face axes, all three at once: |t_i| > ha_i + Σ_j hb_j |m_ij|.
    let rb = combine(hb, &transpose(abs_m));
    if abs_t.any_gt(ha.add(rb).add(slack)) {
        return true;
    }
    // B's face axes: |Σ_i t_i m_ij| > Σ_i ha_i |m_ij| + hb_j.
    let tb = combine(t, &m).abs();
    let ra = combine(ha, &abs_m);
    if tb.any_gt(ra.add(hb).add(slack)) {
        return true;
    }
    // Edge axes a_i × b_j, the three j of one i at once:
    // |t_i2 m_i1j − t_i1 m_i2j| > ha_i1 |m_i2j| + ha_i2 |m_i1j| + hb_j1 |m_ij2| + hb_j2 |m_ij1|.
    let (tx, ty, tz) = (t.lane0(), t.lane1(), t.lane2());
    let (hx, hy, hz) = (ha.lane0(), ha.lane1(), ha.lane2());
    let [m0, m1, m2] = m;
    let [abs0, abs1, abs2] = abs_m;
    edge_separates((m1, m2), (abs0, abs1, abs2), (ty, tz), (hy, hz), hb, slack)
        || edge_separates((m2, m0), (abs1, abs2, abs0), (tz, tx), (hz, hx), hb, slack)
        || edge_separates((m0, m1), (abs2, abs0, abs1), (tx, ty), (hx, hy), hb, slack)
}
