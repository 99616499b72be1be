//! Choosing axes inside a free eigenspace so that the box is tight.
//!
//! When the covariance is isotropic in a subspace (a cube, a square plate, a regular
//! prism), every orthonormal basis of it is a valid set of principal axes. The projected
//! world axes of [`super::frame`] are deterministic but give a loose box for a *rotated*
//! cube. The directions of the largest triangles at hand (hull faces, or input faces) are
//! exactly the symmetric object's own axes in such cases, so each is tried as well, and
//! the one giving the smallest box (volume, or cross-section area for a 2-D free
//! subspace) wins. The default is kept unless a candidate improves on it by a relative
//! margin, so an axis-aligned cube keeps the identity frame.
//!
//! This only runs when a tie was detected, so its extra passes over the points do not
//! matter for speed.

use super::frame::Directions;
use crate::arr3::{cross, dot, norm2, normalize, scale, sub, V3};

/// How many of the largest triangles propose directions.
const CANDIDATES: usize = 4;

/// A candidate must shrink the box by at least this fraction to replace the default.
const IMPROVEMENT: f64 = 1e-9;

/// Projections shorter than this fraction of the direction are too noisy to use.
const MIN_PROJECTION: f64 = 1e-6;

/// The few largest-area triangles seen so far (ties keep the earlier one).
#[derive(Clone, Copy, Debug, Default)]
pub(crate) struct LargestTriangles {
    tris: [[V3; 3]; CANDIDATES],
    /// Squared doubled areas, descending over the first `len` entries.
    size: [f64; CANDIDATES],
    len: usize,
}

impl LargestTriangles {
    /// Considers triangle `(p, q, r)`.
    pub(crate) fn offer(&mut self, p: V3, q: V3, r: V3) {
        let s = norm2(cross(sub(q, p), sub(r, p)));
        if !(s > 0.0 && s.is_finite()) {
            return;
        }
        // Insertion into a tiny sorted array: `s` goes before the first smaller size (sizes
        // are descending, so that is where a backward scan would stop).
        let len = self.len.min(CANDIDATES);
        let k = self
            .size
            .iter()
            .take(len)
            .position(|&x| x < s)
            .unwrap_or(len);
        if k >= CANDIDATES {
            return;
        }
        // Shift `k..end` one place up (the last entry drops off a full array).
        let end = self.len.min(CANDIDATES - 1);
        if let (Some(size), Some(tris)) = (self.size.get_mut(k..=end), self.tris.get_mut(k..=end)) {
            size.rotate_right(1);
            tris.rotate_right(1);
        }
        if let (Some(size), Some(tri)) = (self.size.get_mut(k), self.tris.get_mut(k)) {
            *size = s;
            *tri = [p, q, r];
        }
        self.len = (self.len + 1).min(CANDIDATES);
    }

    fn iter(&self) -> impl Iterator<Item = &[V3; 3]> {
        self.tris.iter().take(self.len)
    }
}

/// Columns 0 and 1 for `frame`: its determined columns, with free ones chosen to minimise
/// the box over `points` among the default and the candidates from `tris`.
pub(crate) fn refine(frame: &Directions, points: &[V3], tris: &LargestTriangles) -> (V3, V3) {
    let default = frame.default_columns();
    if !frame.is_free() {
        return default;
    }
    let mut best = default;
    let mut best_size = box_size(frame, default, points);
    let mut consider = |cols: (V3, V3)| {
        let size = box_size(frame, cols, points);
        if size < best_size * (1.0 - IMPROVEMENT) {
            best = cols;
            best_size = size;
        }
    };
    for t in tris.iter() {
        let [p, q, r] = *t;
        let Some(n) = normalize(cross(sub(q, p), sub(r, p))) else {
            continue;
        };
        let edges = [sub(q, p), sub(r, q), sub(p, r)];
        match *frame {
            Directions::Free => {
                for e in edges {
                    if let Some(a) = project(e, n) {
                        consider((n, a));
                    }
                }
            }
            Directions::FreeAfter { c0 } => {
                for d in [edges[0], edges[1], edges[2], n] {
                    if let Some(a) = project(d, c0) {
                        consider((c0, a));
                    }
                }
            }
            Directions::FreeBefore { c2 } => {
                for d in [edges[0], edges[1], edges[2], n] {
                    if let Some(a) = project(d, c2) {
                        consider((a, cross(c2, a)));
                    }
                }
            }
            Directions::Fixed { .. } => {}
        }
    }
    best
}

/// `d` projected onto the plane normal to unit `w` and normalised, unless too short.
fn project(d: V3, w: V3) -> Option<V3> {
    let r = sub(d, scale(w, dot(d, w)));
    if norm2(r) < MIN_PROJECTION * MIN_PROJECTION * norm2(d) {
        return None;
    }
    normalize(r)
}

/// The measure of the box over `points` in the free columns: the product of the extents
/// along them (determined columns are common to all candidates, so they cancel).
fn box_size(frame: &Directions, (c0, c1): (V3, V3), points: &[V3]) -> f64 {
    let c2 = cross(c0, c1);
    let axes: &[V3] = match frame {
        Directions::Free => &[c0, c1, c2],
        Directions::FreeAfter { .. } => &[c1, c2],
        Directions::FreeBefore { .. } => &[c0, c1],
        Directions::Fixed { .. } => &[],
    };
    axes.iter()
        .map(|&a| {
            let (mut lo, mut hi) = (f64::INFINITY, f64::NEG_INFINITY);
            for &p in points {
                let x = dot(a, p);
                lo = lo.min(x);
                hi = hi.max(x);
            }
            (hi - lo).max(0.0)
        })
        .product()
}
