//! Points through the surface index: the nearest triangle to a point.

use super::{Child, IndexNode, SurfaceIndex, WIDTH};
use crate::bv::BoundingVolume;
use crate::query::engine::{corrupt, triangle};
use crate::query::triangle::{closest_point_on_triangle, Feature, Triangle};
use crate::query::{source_id, QueryError, Side, Work};
use crate::tree::{NodeDefect, TreeView};
use nalgebra::Vector3;
use std::collections::BinaryHeap;

/// Children wait in a closest-point descent by key, the square of a lower bound of their
/// distance to the point: smallest first in a max-heap.
impl Eq for Child {}

impl PartialOrd for Child {
    fn partial_cmp(&self, other: &Self) -> Option<std::cmp::Ordering> {
        Some(self.cmp(other))
    }
}

impl Ord for Child {
    fn cmp(&self, other: &Self) -> std::cmp::Ordering {
        other.key.total_cmp(&self.key)
    }
}

/// How far, relative, a computed square of a box's distance may be from the exact one:
/// the differences, squares and sums each round once.
const DISTANCE_ROUNDING: f64 = 8.0 * f64::EPSILON;

/// The best triangle of a descent: its face in the tree, its input id, the closest point
/// (model frame) and its feature.
pub(in crate::query) struct Best {
    pub(in crate::query) face: u32,
    pub(in crate::query) id: u32,
    pub(in crate::query) point: Vector3<f64>,
    pub(in crate::query) feature: Feature,
}

/// What one descent found: the best triangle, its distance, and the work.
pub(in crate::query) struct Found {
    pub(in crate::query) best: Option<Best>,
    pub(in crate::query) distance: f64,
    pub(in crate::query) work: Work,
}

impl Found {
    /// Tests triangle `t` (face `face` of `tree`) against `p`, keeping it when nearer
    /// than the best so far.
    fn offer<B: BoundingVolume>(
        &mut self,
        tree: &TreeView<'_, B>,
        p: &Vector3<f64>,
        t: &Triangle,
        face: u32,
    ) -> Result<(), QueryError> {
        let (q, feature) = closest_point_on_triangle(p, t);
        let d = (p - q).norm();
        if d == 0.0 {
            self.work.tri_contact += 1;
        } else {
            self.work.tri_separated += 1;
        }
        if d < self.distance {
            self.distance = d;
            self.best = Some(Best {
                face,
                id: source_id(tree, face, Side::A)?,
                point: q,
                feature,
            });
        }
        Ok(())
    }
}

/// The children of `node` nearer to `p` than `distance`, with the squares of lower
/// bounds of their boxes' distances.
#[inline(always)]
fn near_children(node: &IndexNode, p: &[f64; 3], distance: f64) -> ([Child; WIDTH], usize, usize) {
    let mut d2 = [0.0f64; WIDTH];
    let axes = node.lo.iter().zip(&node.hi).zip(p);
    for ((lo, hi), &x) in axes {
        for ((d2, &lo), &hi) in d2.iter_mut().zip(lo).zip(hi) {
            let below = f64::from(lo) - x;
            let above = x - f64::from(hi);
            let gap = if below > 0.0 {
                below
            } else if above > 0.0 {
                above
            } else {
                0.0
            };
            *d2 += gap * gap;
        }
    }
    // Pruned only when surely at least as far as the best: both sides rounded apart. (A
    // NaN bound, of a damaged file, is kept.)
    let best2 = widened_square(distance);
    let bounds = d2.map(|d2| d2 * (1.0 - DISTANCE_ROUNDING));
    node.kept(bounds, |bound2| bound2 < best2 || bound2.is_nan())
}

impl SurfaceIndex {
    /// The triangle of `tree` (whose index this is) nearest to `p` (model frame) and
    /// closer than `max_distance`: each expansion continues with its nearest child down to
    /// a leaf (a first answer to prune with, one step per level), the other children wait
    /// on a heap, and the next dive starts from the nearest waiting; the descent ends when
    /// that one's bound reaches the best distance found, since every other waiting is at
    /// least as far. (Best first alone expands the many boxes that all bound a point near
    /// the surface at 0 level by level before reaching any leaf; depth first alone opens
    /// half again as many.) The `seed` face, tested first, prunes from the start: for
    /// coherent points, the previous point's answer.
    pub(in crate::query) fn nearest<B: BoundingVolume>(
        &self,
        tree: &TreeView<'_, B>,
        p: &Vector3<f64>,
        max_distance: f64,
        seed: Option<u32>,
        heap: &mut BinaryHeap<Child>,
    ) -> Result<Found, QueryError> {
        let missing = || corrupt(Side::A, NodeDefect::Missing);
        let mut found = Found {
            best: None,
            distance: max_distance,
            work: Work::default(),
        };
        if let Some(face) = seed {
            found.offer(tree, p, &triangle(tree, face, None, Side::A)?, face)?;
        }
        let point = [p.x, p.y, p.z];
        heap.clear();
        found.work.nodes_visited += 1;
        let mut dive = Some(Child::ROOT);
        while let Some(taken) = dive.take().or_else(|| heap.pop()) {
            if taken.key >= widened_square(found.distance) {
                // Taken from the heap: it and every one still waiting are pruned.
                found.work.bv_disjoint += 1 + heap.len() as u64;
                break;
            }
            found.work.bv_overlap += 1;
            if taken.count > 0 {
                let start = taken.start as usize;
                for i in start..start + taken.count as usize {
                    let (t, face) = self.triangle(i).ok_or_else(missing)?;
                    // (The seed was tested first.)
                    if Some(face) != seed {
                        found.offer(tree, p, t, face)?;
                    }
                }
                continue;
            }
            let node = self.node(taken.start).ok_or_else(missing)?;
            let (near, n, tested) = near_children(node, &point, found.distance);
            found.work.nodes_visited += tested as u64;
            found.work.bv_disjoint += (tested - n) as u64;
            // The nearest child continues the dive; the others wait.
            for &child in near.iter().take(n) {
                match dive {
                    Some(d) if d.key <= child.key => heap.push(child),
                    Some(d) => {
                        heap.push(d);
                        dive = Some(child);
                    }
                    None => dive = Some(child),
                }
            }
        }
        Ok(found)
    }
}

/// `d²` rounded up past its rounding: a box whose computed bound reaches it is surely at
/// least as far as `d`.
#[inline(always)]
fn widened_square(d: f64) -> f64 {
    d * d * (1.0 + DISTANCE_ROUNDING)
}
