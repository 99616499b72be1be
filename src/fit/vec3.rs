//! Minimal 3-vector arithmetic on `[f64; 3]`.
//!
//! The fitting code works on plain arrays rather than nalgebra types: the inner loops
//! (hull distance tests, moment sums) then compile to straight scalar code with no
//! abstraction in the way, and the arrays match the caller's `positions` layout.

/// A point or direction in model units.
pub(crate) type V3 = [f64; 3];

#[inline(always)]
pub(crate) fn sub(a: V3, b: V3) -> V3 {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}

#[inline(always)]
pub(crate) fn scale(a: V3, s: f64) -> V3 {
    [a[0] * s, a[1] * s, a[2] * s]
}

#[inline(always)]
pub(crate) fn dot(a: V3, b: V3) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

#[inline(always)]
pub(crate) fn cross(a: V3, b: V3) -> V3 {
    [
        a[1] * b[2] - a[2] * b[1],
        a[2] * b[0] - a[0] * b[2],
        a[0] * b[1] - a[1] * b[0],
    ]
}

#[inline(always)]
pub(crate) fn norm2(a: V3) -> f64 {
    dot(a, a)
}

/// `a` scaled to unit length, or `None` when its length is zero or not finite
/// (so callers decide explicitly what a degenerate direction means).
#[inline]
pub(crate) fn normalize(a: V3) -> Option<V3> {
    let len = norm2(a).sqrt();
    if len > 0.0 && len.is_finite() {
        Some(scale(a, 1.0 / len))
    } else {
        None
    }
}

/// World axis `i` (0 = x, 1 = y, 2 = z).
#[inline]
pub(crate) fn axis(i: usize) -> V3 {
    let mut e = [0.0; 3];
    if let Some(c) = e.get_mut(i) {
        *c = 1.0;
    }
    e
}
