//! The crate's one toolkit for plain `[T; 3]` arrays: componentwise helpers and 3-vector
//! arithmetic on `[f64; 3]`, written with constant indices so that loops over the three
//! axes need no computed index (and so no bounds check or `indexing_slicing` allow). Each
//! is the plain per-component expression; results are bit-identical to the loops they
//! replace.
//!
//! The builder (fitting, enclosing) works on these plain arrays rather than nalgebra
//! types: its inner loops (hull distance tests, moment sums, extents) then compile to
//! straight scalar code, and the arrays match the mesh's `positions` layout. The query
//! side, whose transforms compose matrices, uses nalgebra.

/// `[(a0, b0), (a1, b1), (a2, b2)]`.
#[inline(always)]
pub(crate) fn zip<A, B>([a0, a1, a2]: [A; 3], [b0, b1, b2]: [B; 3]) -> [(A, B); 3] {
    [(a0, b0), (a1, b1), (a2, b2)]
}

/// `[f(a0), f(a1), f(a2)]`: like `<[T; 3]>::map`, but three plain calls that always inline
/// (the std `map` goes through `try_map`, which the optimiser does not always flatten).
#[inline(always)]
pub(crate) fn map<T, U>([a0, a1, a2]: [T; 3], mut f: impl FnMut(T) -> U) -> [U; 3] {
    [f(a0), f(a1), f(a2)]
}

/// Componentwise `f64::min`.
#[inline(always)]
pub(crate) fn min(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [a[0].min(b[0]), a[1].min(b[1]), a[2].min(b[2])]
}

/// Componentwise `f64::max`.
#[inline(always)]
pub(crate) fn max(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [a[0].max(b[0]), a[1].max(b[1]), a[2].max(b[2])]
}

/// The lesser of two finite numbers: one compare-and-select, where `f64::min`, which also
/// orders NaN, takes several instructions. (With a NaN it answers `a`.)
#[inline(always)]
pub(crate) fn least(a: f64, b: f64) -> f64 {
    if b < a {
        b
    } else {
        a
    }
}

/// The greater of two finite numbers, as [`least`] (with a NaN, `a`).
#[inline(always)]
pub(crate) fn greatest(a: f64, b: f64) -> f64 {
    if b > a {
        b
    } else {
        a
    }
}

/// Componentwise extremes `(min, max)` of `points` (zeros for none).
pub(crate) fn bounds<'a>(points: impl IntoIterator<Item = &'a [f64; 3]>) -> ([f64; 3], [f64; 3]) {
    let mut lo = [f64::INFINITY; 3];
    let mut hi = [f64::NEG_INFINITY; 3];
    let mut any = false;
    for p in points {
        lo = min(lo, *p);
        hi = max(hi, *p);
        any = true;
    }
    if any {
        (lo, hi)
    } else {
        ([0.0; 3], [0.0; 3])
    }
}

/// Rows become columns.
#[inline(always)]
pub(crate) fn transpose<T>(m: [[T; 3]; 3]) -> [[T; 3]; 3] {
    let [[a, b, c], [d, e, f], [g, h, i]] = m;
    [[a, d, g], [b, e, h], [c, f, i]]
}

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
