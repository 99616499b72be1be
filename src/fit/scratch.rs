//! Per-thread reusable buffers, and gathering the distinct vertices of a face set.
//!
//! A tree build calls the fit once per node, mostly on tiny face sets; allocating fresh
//! buffers each time would dominate. Each thread keeps one [`Scratch`] (see
//! `principal_axes`), sized by the largest input it has seen.

use super::dimension::Extremes;
use super::hull::HullScratch;
use crate::arr3;
use crate::arr3::V3;

/// Buffers reused across fits on one thread.
#[derive(Debug, Default)]
pub(crate) struct Scratch {
    /// `stamp[i] == generation` marks vertex `i` as already gathered in this call: an
    /// O(1) "seen" set that needs no clearing between calls.
    stamp: Vec<u32>,
    generation: u32,
    /// The distinct vertices of the current face set, centred at their bounding-box centre.
    pub(crate) pts: Vec<V3>,
    /// The indices of the distinct vertices, in order of first reference (before welding,
    /// which may merge and reorder `pts`).
    pub(crate) ids: Vec<u32>,
    /// Largest absolute coordinate before centring (sets the "single point" floor).
    pub(crate) magnitude: f64,
    /// The bounding box of `pts` (after centring) and the points on it.
    pub(crate) extremes: Extremes,
    /// Convex-hull buffers.
    pub(crate) hull: HullScratch,
}

impl Scratch {
    /// Fills [`Scratch::pts`] with the vertices referenced by `faces`, each index once, in
    /// order of first reference (and [`Scratch::ids`] with their indices); with `weld`,
    /// vertices at bitwise-equal positions are merged too (and the order becomes
    /// lexicographic). Indices out of range are ignored.
    pub(crate) fn gather(&mut self, positions: &[[f64; 3]], faces: &[[u32; 3]], weld: bool) {
        self.pts.clear();
        self.ids.clear();
        if self.stamp.len() < positions.len() {
            self.stamp.resize(positions.len(), 0);
        }
        self.generation = self.generation.wrapping_add(1);
        if self.generation == 0 {
            // Stamps from 2³² calls ago could collide: start over.
            self.stamp.fill(0);
            self.generation = 1;
        }
        let generation = self.generation;
        for f in faces {
            for &v in f {
                let i = v as usize;
                if let (Some(st), Some(&p)) = (self.stamp.get_mut(i), positions.get(i)) {
                    if *st != generation {
                        *st = generation;
                        self.pts.push(p);
                        self.ids.push(v);
                    }
                }
            }
        }
        if weld {
            // `+ 0.0` turns -0.0 into +0.0 so the total order treats them as one point.
            for p in &mut self.pts {
                *p = [p[0] + 0.0, p[1] + 0.0, p[2] + 0.0];
            }
            self.pts.sort_unstable_by(|a, b| {
                a[0].total_cmp(&b[0])
                    .then(a[1].total_cmp(&b[1]))
                    .then(a[2].total_cmp(&b[2]))
            });
            self.pts.dedup();
        }
        self.center();
    }

    /// Centres the points at their bounding-box centre; records the magnitude and the
    /// extremes of the centred points.
    fn center(&mut self) {
        let Some(&first) = self.pts.first() else {
            self.magnitude = 0.0;
            return;
        };
        let (mut lo, mut hi) = (first, first);
        for p in &self.pts {
            lo = arr3::map(arr3::zip(lo, *p), |(l, x)| arr3::least(l, x));
            hi = arr3::map(arr3::zip(hi, *p), |(h, x)| arr3::greatest(h, x));
        }
        let sides = arr3::zip(lo, hi);
        let c = arr3::map(sides, |(lo, hi)| 0.5 * (lo + hi));
        let magnitude = sides
            .iter()
            .fold(0.0_f64, |m, (lo, hi)| m.max(lo.abs()).max(hi.abs()));
        self.magnitude = magnitude;
        let centred = |p: V3| [p[0] - c[0], p[1] - c[1], p[2] - c[2]];
        let mut extremes = Extremes::new(centred(first));
        for (i, p) in self.pts.iter_mut().enumerate() {
            *p = centred(*p);
            extremes.add(i, *p);
        }
        self.extremes = extremes;
    }
}
