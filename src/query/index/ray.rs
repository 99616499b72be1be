//! Rays through the surface index: which children's boxes a ray enters, nearest first.

use super::{Child, IndexNode, WIDTH};
use crate::query::quad::Quad;

/// A ray in the model frame, set up for slab tests.
pub(in crate::query) struct Slabs {
    origin: [f64; 3],
    /// Per axis, `1 / d` (see [`Slabs::new`]): exits are computed with it.
    inverse: [f64; 3],
    /// Per axis, `(1 / d) · SHRINK`, rounded: entries are computed with it, so that they
    /// come out widened by their rounding with no step of their own (see [`SHRINK`]).
    shrunk: [f64; 3],
    /// Per axis, whether the ray runs toward smaller coordinates: it then meets a box's
    /// `hi` plane first. Chosen once per ray, so a node's lanes need no comparison.
    negative: [bool; 3],
}

/// How much a computed slab parameter may be off, relative to itself: it rounds at most
/// four times (the difference, the inverse, the inverse's [`SHRINK`] for an entry, the
/// product), each by at most `ε/2`.
const SLAB_ROUNDING: f64 = 4.0 * f64::EPSILON;

/// The factor that widens a computed entry (never negative) by the rounding of both it
/// and the exit it is compared with, taken into the entry's inverse once per ray: an exact
/// entry `x` at most an exact exit `y` gives `x̃ ≤ x (1 − 4r)(1 + r) ≤ y (1 − r) ≤ ỹ`.
/// (Exits have no widening of their own: their sign is exact, and only entries at least 0
/// are compared with them.)
const SHRINK: f64 = 1.0 - 4.0 * SLAB_ROUNDING;

/// The largest exit a slab test keeps: finite, so that an infinite entry (a ray parallel
/// to a slab it lies outside) never compares below an exit.
const FARTHEST: f64 = f64::MAX;

impl Slabs {
    /// The slabs of the ray `origin + t direction` (finite, direction not zero).
    pub(in crate::query) fn new(origin: [f64; 3], direction: [f64; 3]) -> Slabs {
        // A zero direction's inverse is an infinity of its sign (see `entries`); one too
        // short to invert is NaN instead, so its axis prunes nothing.
        let inverse = direction.map(|d| match 1.0 / d {
            i if d != 0.0 && !i.is_finite() => f64::NAN,
            i => i,
        });
        Slabs {
            origin,
            inverse,
            shrunk: inverse.map(|i| i * SHRINK),
            negative: inverse.map(|i| i < 0.0),
        }
    }

    /// Where the ray enters each child box of `node` before parameter `reach` (a lower
    /// bound of the exact entry), and a bit per slot set where it does (empty slots
    /// included). The bit is set for every box the ray meets at a `t` in `[0, reach]` (of
    /// a damaged file's NaN boxes, only that it answers).
    ///
    /// An axis the ray is parallel to needs no case of its own: its inverse is infinite,
    /// so a plane on the origin's far side gives an infinite entry or a negative infinite
    /// exit (a miss) and one on its near side prunes nothing; a plane through the origin
    /// gives NaN, which `max` and `min` pass over (on the boundary counts as inside), as
    /// they pass over every value of an axis whose inverse is NaN.
    ///
    /// The three axes are combined as a tree, y with z, then with x and the bounds (0 and
    /// `reach`), not one after another: the node step is a chain of dependent operations
    /// that a descent waits on, and this takes one of them off it. A NaN of z then passes
    /// over y's value too, which only prunes less.
    // Axes count to 3, the length of every array they index.
    #[allow(clippy::indexing_slicing)]
    #[inline(always)]
    fn entries(&self, node: &IndexNode, reach: f64) -> ([f64; WIDTH], u32) {
        // The plane the ray meets first on `axis`, then the one it meets last.
        let planes = |axis: usize| {
            if self.negative[axis] {
                (&node.hi[axis], &node.lo[axis])
            } else {
                (&node.lo[axis], &node.hi[axis])
            }
        };
        let parameters = |plane: &[f32; WIDTH], axis: usize, inverse: f64| {
            (Quad::widen(plane) - Quad::splat(self.origin[axis])) * Quad::splat(inverse)
        };
        let entry = |axis: usize| parameters(planes(axis).0, axis, self.shrunk[axis]);
        let exit = |axis: usize| parameters(planes(axis).1, axis, self.inverse[axis]);
        // `a.max(b)` passes over a NaN `a` but gives a NaN `b`: y with z is NaN only where
        // z is, and the last step passes over that, its right operand holding a bound.
        let near = entry(1).max(entry(2)).max(entry(0).max(Quad::splat(0.0)));
        let far = exit(1)
            .min(exit(2))
            .min(exit(0).min(Quad::splat(reach.min(FARTHEST))));
        (near.to_array(), near.le_mask(far))
    }

    /// The children of `node` the ray enters before `reach`, farthest first and after
    /// `WIDTH − n` unused slots (so the nearest is last, and the others go on a stack as
    /// they lie); `n`, how many there are; and how many children were tested (empty slots
    /// are not).
    // Lanes count to WIDTH (two bits), the length of every array they index.
    #[allow(clippy::indexing_slicing)]
    #[inline(always)]
    pub(in crate::query) fn entered(
        &self,
        node: &IndexNode,
        reach: f64,
    ) -> ([Child; WIDTH], usize, usize) {
        let occupied = node.occupied();
        let (entries, entered) = self.entries(node, reach);
        let mask = entered & occupied;
        let child = |lane: usize| Child {
            key: entries[lane],
            start: node.start[lane],
            count: node.count[lane],
        };
        let mut children = [Child::ROOT; WIDTH];
        // One or two children entered (most nodes) are placed directly; more are sorted.
        let first = mask.trailing_zeros() as usize;
        let rest = mask & mask.wrapping_sub(1);
        if rest == 0 {
            if mask != 0 {
                children[WIDTH - 1] = child(first);
            }
        } else if rest & rest.wrapping_sub(1) == 0 {
            let (a, b) = (child(first), child(rest.trailing_zeros() as usize));
            let (near, far) = if b.key < a.key { (b, a) } else { (a, b) };
            (children[WIDTH - 2], children[WIDTH - 1]) = (far, near);
        } else {
            // Each entered child's key with its lane in the two low bits, as an integer:
            // for keys of at least 0 (an entry is) the bits order as the values do, to
            // within those two bits (any order is right; it only steers the work). Missed
            // children sort first, unused.
            let mut packed: [u64; WIDTH] = std::array::from_fn(|lane| {
                if mask >> lane & 1 == 1 {
                    entries[lane].to_bits() & !3 | lane as u64
                } else {
                    u64::MAX
                }
            });
            // A sorting network, largest first, of integer minima and maxima.
            for (i, j) in [(0, 1), (2, 3), (0, 2), (1, 3), (1, 2)] {
                let (a, b) = (packed[i], packed[j]);
                (packed[i], packed[j]) = (a.max(b), a.min(b));
            }
            children = packed.map(|bits| child((bits & 3) as usize));
        }
        (
            children,
            mask.count_ones() as usize,
            occupied.count_ones() as usize,
        )
    }
}

#[cfg(test)]
mod tests {
    use super::super::Bounds;
    use super::*;

    /// A node with one child, the box `lo`–`hi`.
    fn node(lo: [f32; 3], hi: [f32; 3]) -> IndexNode {
        let mut n = IndexNode::EMPTY;
        let b = Bounds {
            lo: lo.map(f64::from),
            hi: hi.map(f64::from),
        };
        n.set(0, &b, 0, 1);
        n
    }

    /// The unit box from `x` along the x axis.
    fn unit(x: f64) -> Bounds {
        Bounds {
            lo: [x, 0.0, 0.0],
            hi: [x + 1.0, 1.0, 1.0],
        }
    }

    /// Where a ray enters that child, if it does.
    fn entry(s: &Slabs, n: &IndexNode, reach: f64) -> Option<f64> {
        let (entered, count, tested) = s.entered(n, reach);
        assert_eq!(tested, 1);
        (count == 1).then_some(entered[WIDTH - 1].key)
    }

    #[test]
    fn a_ray_along_a_face_of_the_box_enters_it() {
        let n = node([0.0; 3], [1.0; 3]);
        // In the plane x = 0, parallel to it: on the boundary counts as inside.
        let s = Slabs::new([0.0, 0.5, -1.0], [0.0, 0.0, 1.0]);
        let t = entry(&s, &n, f64::INFINITY).expect("enters");
        assert!(t <= 1.0 && t > 1.0 - 1e-14);
        let outside = Slabs::new([-1e-300, 0.5, -1.0], [0.0, 0.0, 1.0]);
        assert_eq!(entry(&outside, &n, f64::INFINITY), None);
        // Too short a direction to invert: nothing pruned on its axis.
        let tiny = Slabs::new([-1e-300, 0.5, -1.0], [1e-310, 0.0, 1.0]);
        assert!(entry(&tiny, &n, f64::INFINITY).is_some());
    }

    #[test]
    fn entry_is_a_lower_bound_and_reach_prunes() {
        let n = node([1.0, -1.0, -1.0], [2.0, 1.0, 1.0]);
        let s = Slabs::new([0.0, 0.0, 0.0], [1.0, 0.0, 0.0]);
        let t = entry(&s, &n, f64::INFINITY).expect("enters");
        assert!(t <= 1.0 && t > 1.0 - 1e-14);
        assert!(entry(&s, &n, 0.5).is_none());
        let behind = Slabs::new([3.0, 0.0, 0.0], [1.0, 0.0, 0.0]);
        assert!(entry(&behind, &n, f64::INFINITY).is_none());
        let inside = Slabs::new([1.5, 0.0, 0.0], [-1.0, 0.2, 0.0]);
        assert_eq!(entry(&inside, &n, f64::INFINITY), Some(0.0));
    }

    #[test]
    fn children_come_farthest_first_and_empty_slots_are_not_tested() {
        let mut n = IndexNode::EMPTY;
        // Boxes at x = 4, 0 and 2 along +x, and one the ray passes beside.
        n.set(0, &unit(4.0), 10, 0);
        n.set(1, &unit(0.0), 20, 3);
        n.set(2, &unit(2.0), 30, 0);
        let s = Slabs::new([-1.0, 0.5, 0.5], [1.0, 0.0, 0.0]);
        let (entered, count, tested) = s.entered(&n, f64::INFINITY);
        assert_eq!((count, tested), (3, 3));
        let order: Vec<(u32, u32)> = entered[1..].iter().map(|e| (e.start, e.count)).collect();
        assert_eq!(order, [(10, 0), (30, 0), (20, 3)]);
        // Their keys are where the ray enters them (x = 4, 2, 0), from just below.
        for (e, t) in entered[1..].iter().zip([5.0, 3.0, 1.0]) {
            assert!(e.key <= t && e.key > t - 1e-12, "key {} for {t}", e.key);
        }
        // Up to t = 4 (x = 3) the farthest box is not entered.
        let (_, count, _) = s.entered(&n, 4.0);
        assert_eq!(count, 2);
        let beside = Slabs::new([-1.0, 2.0, 0.5], [1.0, 0.0, 0.0]);
        assert_eq!(beside.entered(&n, f64::INFINITY).1, 0);
    }

    #[test]
    fn one_or_two_children_entered_come_farthest_first_too() {
        // Two boxes entered, in either slot order, and one.
        for (first, second) in [(0.0, 2.0), (2.0, 0.0)] {
            let mut n = IndexNode::EMPTY;
            n.set(1, &unit(first), 10, 1);
            n.set(3, &unit(second), 20, 2);
            let s = Slabs::new([-1.0, 0.5, 0.5], [1.0, 0.0, 0.0]);
            let (entered, count, tested) = s.entered(&n, f64::INFINITY);
            assert_eq!((count, tested), (2, 2));
            let near = if first < second { 10 } else { 20 };
            assert_eq!(entered[WIDTH - 1].start, near);
            assert_eq!(entered[WIDTH - 2].start, 30 - near);
            assert!(entered[WIDTH - 1].key < entered[WIDTH - 2].key);
            let (entered, count, _) = s.entered(&n, 2.5);
            assert_eq!((count, entered[WIDTH - 1].start), (1, near));
        }
    }

    /// Where the ray enters and leaves the box, computed in f64 with no widening: within
    /// 4ε of the exact parameters, relative.
    fn slab_interval(o: [f64; 3], d: [f64; 3], lo: [f32; 3], hi: [f32; 3]) -> (f64, f64) {
        let (mut near, mut far) = (0.0f64, f64::INFINITY);
        for k in 0..3 {
            let (a, b) = (
                (f64::from(lo[k]) - o[k]) / d[k],
                (f64::from(hi[k]) - o[k]) / d[k],
            );
            near = near.max(a.min(b));
            far = far.min(a.max(b));
        }
        (near, far)
    }

    #[test]
    fn every_box_a_ray_surely_enters_is_kept_with_a_lower_bound() {
        let mut rng = crate::generate::Rng::new(26);
        let (mut checked, mut grazing) = (0, 0);
        for _ in 0..200_000 {
            // A box, and a ray toward a point on or just beside its faces, edges and
            // corners (each coordinate on a plane of the box or inside its slab).
            let lo: [f32; 3] = std::array::from_fn(|_| (rng.signed() * 2.0) as f32);
            let hi: [f32; 3] = std::array::from_fn(|k| lo[k] + (rng.unit() * 2.0) as f32);
            let origin: [f64; 3] = std::array::from_fn(|_| rng.signed() * 6.0);
            let target: [f64; 3] = std::array::from_fn(|k| {
                let beside = (rng.signed() * 1e-13) * f64::from(hi[k] - lo[k]);
                match rng.below(3) {
                    0 => f64::from(lo[k]) + beside,
                    1 => f64::from(hi[k]) + beside,
                    _ => f64::from(lo[k]) + rng.unit() * f64::from(hi[k] - lo[k]),
                }
            });
            let direction: [f64; 3] = std::array::from_fn(|k| target[k] - origin[k]);
            let reach = if rng.below(2) == 0 {
                f64::INFINITY
            } else {
                1.0 + rng.signed() * 1e-14
            };
            let (near, far) = slab_interval(origin, direction, lo, hi);
            // Surely entered: the interval stays open after moving its ends inward by
            // more than their rounding.
            let margin = 8.0 * f64::EPSILON * (near.abs() + far.abs());
            if near + margin < far - margin && near + margin < reach {
                checked += 1;
                let s = Slabs::new(origin, direction);
                let key = entry(&s, &node(lo, hi), reach).expect("a box surely entered is kept");
                assert!(key <= near, "entry {key} above {near}");
                if far - near < 1e-12 * far {
                    grazing += 1;
                }
            }
        }
        // Enough rays pass within a few units in the last place of an edge.
        assert!(
            checked > 50_000 && grazing > 1_000,
            "{checked} checked, {grazing} grazing"
        );
    }
}
