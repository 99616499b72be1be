//! Componentwise helpers for `[T; 3]`, written with constant indices so that loops over the
//! three axes need no computed index (and so no bounds check or `indexing_slicing` allow).
//! Each is the plain per-component expression; results are bit-identical to the loops
//! they replace.

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

/// Componentwise extremes `(min, max)` of `points` (zeros for none).
pub(crate) fn bounds(points: &[[f64; 3]]) -> ([f64; 3], [f64; 3]) {
    if points.is_empty() {
        return ([0.0; 3], [0.0; 3]);
    }
    let mut lo = [f64::INFINITY; 3];
    let mut hi = [f64::NEG_INFINITY; 3];
    for p in points {
        lo = min(lo, *p);
        hi = max(hi, *p);
    }
    (lo, hi)
}

/// Rows become columns.
#[inline(always)]
pub(crate) fn transpose<T>(m: [[T; 3]; 3]) -> [[T; 3]; 3] {
    let [[a, b, c], [d, e, f], [g, h, i]] = m;
    [[a, d, g], [b, e, h], [c, f, i]]
}
