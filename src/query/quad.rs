//! Four f64 lanes, one per child slot of an index node or triangle of a leaf: two SSE2
//! registers on x86-64 (SSE2 is part of that target's baseline, so no run-time detection is
//! needed), an array elsewhere. The compiler does not vectorise such lanes by itself: it
//! mixes scalar and packed steps and shuffles between them. Each operation rounds as the
//! scalar one does, so a lane's value is the scalar computation's to the bit.
//!
//! Comparisons follow the SSE instructions' NaN rule, which the slab test relies on:
//! [`Quad::max`] and [`Quad::min`] return their second operand where either is NaN.

/// Four f64 lanes.
#[derive(Clone, Copy, Debug)]
pub(in crate::query) struct Quad(lanes::V);

impl Quad {
    /// All four lanes `v`.
    #[inline(always)]
    pub(in crate::query) fn splat(v: f64) -> Quad {
        Quad(lanes::splat(v))
    }
    /// The four values, in lane order.
    #[inline(always)]
    pub(in crate::query) fn from_array(v: [f64; 4]) -> Quad {
        Quad(lanes::load(v))
    }
    /// Four f32 values, widened exactly.
    #[inline(always)]
    pub(in crate::query) fn widen(v: &[f32; 4]) -> Quad {
        Quad(lanes::widen(v))
    }
    /// The lanes, in order.
    #[inline(always)]
    pub(in crate::query) fn to_array(self) -> [f64; 4] {
        lanes::store(self.0)
    }
    /// Lane by lane, the larger: `b` where `a > b` is false, NaN in either included.
    #[inline(always)]
    pub(in crate::query) fn max(self, b: Quad) -> Quad {
        Quad(lanes::max(self.0, b.0))
    }
    /// Lane by lane, the smaller: `b` where `a < b` is false, NaN in either included.
    #[inline(always)]
    pub(in crate::query) fn min(self, b: Quad) -> Quad {
        Quad(lanes::min(self.0, b.0))
    }
    /// Bit `k` set where lane `k` of `self` is at most `b`'s (unset with NaN).
    #[inline(always)]
    pub(in crate::query) fn le_mask(self, b: Quad) -> u32 {
        lanes::le_mask(self.0, b.0)
    }
    /// Bit `k` set where lane `k` of `self` is less than `b`'s (unset with NaN).
    #[inline(always)]
    pub(in crate::query) fn lt_mask(self, b: Quad) -> u32 {
        lanes::lt_mask(self.0, b.0)
    }
    /// Lane by lane, the value where it is finite and 0 where it is infinite or NaN.
    #[inline(always)]
    pub(in crate::query) fn finite_or_zero(self) -> Quad {
        Quad(lanes::finite_or_zero(self.0))
    }
}

impl std::ops::Sub for Quad {
    type Output = Quad;
    #[inline(always)]
    fn sub(self, b: Quad) -> Quad {
        Quad(lanes::sub(self.0, b.0))
    }
}

impl std::ops::Mul for Quad {
    type Output = Quad;
    #[inline(always)]
    fn mul(self, b: Quad) -> Quad {
        Quad(lanes::mul(self.0, b.0))
    }
}

// SAFETY (every `unsafe` block of this module): the intrinsics are SSE and SSE2
// instructions, which the cfg below guarantees are enabled for the whole build (they are in
// the x86-64 baseline), so every CPU this code runs on has them; only `widen` and `store`
// touch memory, the 16 and 32 bytes of the arrays they are given.
#[cfg(all(target_arch = "x86_64", target_feature = "sse2"))]
mod lanes {
    use std::arch::x86_64::*;

    /// Lanes 0 and 1, then 2 and 3.
    pub type V = (__m128d, __m128d);

    #[inline(always)]
    fn both(a: V, b: V, f: impl Fn(__m128d, __m128d) -> __m128d) -> V {
        (f(a.0, b.0), f(a.1, b.1))
    }
    #[inline(always)]
    pub fn splat(v: f64) -> V {
        let x = unsafe { _mm_set1_pd(v) };
        (x, x)
    }
    #[inline(always)]
    pub fn load(v: [f64; 4]) -> V {
        let [a, b, c, d] = v;
        unsafe { (_mm_set_pd(b, a), _mm_set_pd(d, c)) }
    }
    #[inline(always)]
    pub fn widen(v: &[f32; 4]) -> V {
        // (A read of the 16 bytes the reference covers.)
        let x = unsafe { _mm_loadu_ps(v.as_ptr()) };
        unsafe { (_mm_cvtps_pd(x), _mm_cvtps_pd(_mm_movehl_ps(x, x))) }
    }
    #[inline(always)]
    pub fn store(v: V) -> [f64; 4] {
        let mut out = [0.0f64; 4];
        // (Writes of the two 16-byte halves of `out`.)
        unsafe {
            _mm_storeu_pd(out.as_mut_ptr(), v.0);
            _mm_storeu_pd(out.as_mut_ptr().add(2), v.1);
        }
        out
    }
    #[inline(always)]
    pub fn max(a: V, b: V) -> V {
        both(a, b, |a, b| unsafe { _mm_max_pd(a, b) })
    }
    #[inline(always)]
    pub fn min(a: V, b: V) -> V {
        both(a, b, |a, b| unsafe { _mm_min_pd(a, b) })
    }
    /// Bit `k` set where lane `k` of a comparison's result is all ones.
    #[inline(always)]
    fn mask((lo, hi): V) -> u32 {
        let bits = unsafe { _mm_movemask_pd(lo) | (_mm_movemask_pd(hi) << 2) };
        bits as u32
    }
    #[inline(always)]
    pub fn le_mask(a: V, b: V) -> u32 {
        mask(both(a, b, |a, b| unsafe { _mm_cmple_pd(a, b) }))
    }
    #[inline(always)]
    pub fn lt_mask(a: V, b: V) -> u32 {
        mask(both(a, b, |a, b| unsafe { _mm_cmplt_pd(a, b) }))
    }
    #[inline(always)]
    pub fn finite_or_zero(v: V) -> V {
        // |x| < ∞ is false for infinities and NaN: those lanes' bits are cleared.
        let keep = |x: __m128d| unsafe {
            let magnitude = _mm_andnot_pd(_mm_set1_pd(-0.0), x);
            _mm_and_pd(x, _mm_cmplt_pd(magnitude, _mm_set1_pd(f64::INFINITY)))
        };
        (keep(v.0), keep(v.1))
    }
    #[inline(always)]
    pub fn sub(a: V, b: V) -> V {
        both(a, b, |a, b| unsafe { _mm_sub_pd(a, b) })
    }
    #[inline(always)]
    pub fn mul(a: V, b: V) -> V {
        both(a, b, |a, b| unsafe { _mm_mul_pd(a, b) })
    }
}

#[cfg(not(all(target_arch = "x86_64", target_feature = "sse2")))]
mod lanes {
    pub type V = [f64; 4];

    #[inline(always)]
    fn zip(a: V, b: V, f: impl Fn(f64, f64) -> f64) -> V {
        let ([a0, a1, a2, a3], [b0, b1, b2, b3]) = (a, b);
        [f(a0, b0), f(a1, b1), f(a2, b2), f(a3, b3)]
    }
    #[inline(always)]
    pub fn splat(v: f64) -> V {
        [v; 4]
    }
    #[inline(always)]
    pub fn load(v: [f64; 4]) -> V {
        v
    }
    #[inline(always)]
    pub fn widen(v: &[f32; 4]) -> V {
        v.map(f64::from)
    }
    #[inline(always)]
    pub fn store(v: V) -> [f64; 4] {
        v
    }
    #[inline(always)]
    pub fn max(a: V, b: V) -> V {
        zip(a, b, |a, b| if a > b { a } else { b })
    }
    #[inline(always)]
    pub fn min(a: V, b: V) -> V {
        zip(a, b, |a, b| if a < b { a } else { b })
    }
    /// Bit `k` set where `f` holds for lane `k` of `a` and `b`.
    #[inline(always)]
    fn mask(a: V, b: V, f: impl Fn(f64, f64) -> bool) -> u32 {
        let ([a0, a1, a2, a3], [b0, b1, b2, b3]) = (a, b);
        u32::from(f(a0, b0))
            | u32::from(f(a1, b1)) << 1
            | u32::from(f(a2, b2)) << 2
            | u32::from(f(a3, b3)) << 3
    }
    #[inline(always)]
    pub fn le_mask(a: V, b: V) -> u32 {
        mask(a, b, |a, b| a <= b)
    }
    #[inline(always)]
    pub fn lt_mask(a: V, b: V) -> u32 {
        mask(a, b, |a, b| a < b)
    }
    #[inline(always)]
    pub fn finite_or_zero(v: V) -> V {
        v.map(|x| if x.is_finite() { x } else { 0.0 })
    }
    #[inline(always)]
    pub fn sub(a: V, b: V) -> V {
        zip(a, b, |a, b| a - b)
    }
    #[inline(always)]
    pub fn mul(a: V, b: V) -> V {
        zip(a, b, |a, b| a * b)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn lanes_keep_their_order_and_the_nan_rule() {
        let a = Quad::widen(&[1.0, -2.0, f32::NAN, 4.0]);
        let b = Quad::widen(&[0.5, 3.0, 7.0, f32::NAN]);
        let max = a.max(b).to_array();
        assert_eq!((max[0], max[1], max[2]), (1.0, 3.0, 7.0));
        assert!(max[3].is_nan());
        let min = a.min(b).to_array();
        assert_eq!((min[0], min[1], min[2]), (0.5, -2.0, 7.0));
        assert!(min[3].is_nan());
        assert_eq!(a.le_mask(b), 0b0010);
        assert_eq!(b.le_mask(a), 0b0001);
        let c = Quad::from_array([1.0, 3.0, 2.0, f64::NAN]);
        let d = Quad::from_array([1.0, 2.0, 3.0, 0.0]);
        assert_eq!(
            (c.lt_mask(d), d.lt_mask(c), c.le_mask(d)),
            (0b0100, 0b0010, 0b0101)
        );
        let odd = Quad::from_array([f64::INFINITY, -0.5, f64::NAN, f64::NEG_INFINITY]);
        assert_eq!(odd.finite_or_zero().to_array(), [0.0, -0.5, 0.0, 0.0]);
        let sum = (a - Quad::splat(1.0)) * Quad::splat(2.0);
        assert_eq!(sum.to_array()[0], 0.0);
        assert_eq!(sum.to_array()[3], 6.0);
    }
}
