//! Rays through the surface index: which children's boxes a ray enters, nearest first.

use super::{Child, IndexNode, WIDTH};

/// A ray in the model frame, set up for slab tests.
pub(in crate::query) struct Slabs {
    origin: [f64; 3],
    direction: [f64; 3],
    inverse: [f64; 3],
}

/// How much a computed slab parameter may be off, relative to itself: the difference,
/// the inverse and the product each round once.
const SLAB_ROUNDING: f64 = 4.0 * f64::EPSILON;

impl Slabs {
    /// The slabs of the ray `origin + t direction` (finite, direction not zero).
    pub(in crate::query) fn new(origin: [f64; 3], direction: [f64; 3]) -> Slabs {
        Slabs {
            origin,
            direction,
            inverse: direction.map(|d| 1.0 / d),
        }
    }

    /// Where the ray enters each child box of `node` before parameter `reach`: a lower
    /// bound of the exact entry, or +∞ where it does not. Never +∞ for a box the ray meets
    /// at a `t` in `[0, reach]` (of a damaged file's NaN boxes, only that it answers).
    #[inline(always)]
    fn entries(&self, node: &IndexNode, reach: f64) -> [f64; WIDTH] {
        let mut near = [0.0f64; WIDTH];
        let mut far = [reach; WIDTH];
        let axes = node.lo.iter().zip(&node.hi);
        let rays = self.origin.iter().zip(&self.inverse).zip(&self.direction);
        for ((lo, hi), ((&o, &inverse), &direction)) in axes.zip(rays) {
            let lanes = near.iter_mut().zip(far.iter_mut()).zip(lo.iter().zip(hi));
            if inverse.is_finite() {
                for ((near, far), (&lo, &hi)) in lanes {
                    let t0 = (f64::from(lo) - o) * inverse;
                    let t1 = (f64::from(hi) - o) * inverse;
                    let (a, b) = if t0 <= t1 { (t0, t1) } else { (t1, t0) };
                    // (Plain comparisons: NaN, of a damaged file, compares false.)
                    if a > *near {
                        *near = a;
                    }
                    if b < *far {
                        *far = b;
                    }
                }
            } else if direction == 0.0 {
                // Parallel to the slab: outside it, the ray misses. (A direction so short
                // that its inverse overflows prunes nothing on its axis.)
                for ((_, far), (&lo, &hi)) in lanes {
                    if o < f64::from(lo) || o > f64::from(hi) {
                        *far = f64::NEG_INFINITY;
                    }
                }
            }
        }
        // Widened by their rounding once: `x ∓ |x| r` is increasing in `x`, so this is
        // the largest (smallest) of the widened bounds of the three slabs.
        std::array::from_fn(|lane| {
            let (near, far) = (near.get(lane).copied(), far.get(lane).copied());
            let (Some(near), Some(far)) = (near, far) else {
                return f64::INFINITY;
            };
            let (near, far) = (
                near - near.abs() * SLAB_ROUNDING,
                far + far.abs() * SLAB_ROUNDING,
            );
            if near <= far {
                near
            } else {
                f64::INFINITY
            }
        })
    }

    /// The children of `node` the ray enters before `reach`, nearest first, and how many
    /// there are; the other slots are unused.
    #[inline(always)]
    pub(in crate::query) fn entered(
        &self,
        node: &IndexNode,
        reach: f64,
    ) -> ([Child; WIDTH], usize, usize) {
        let (mut entered, n, tested) = node.kept(self.entries(node, reach), |e| e < f64::INFINITY);
        // Insertion sort: at most four, and a library sort is not inlined here.
        for i in 1..n {
            let mut j = i;
            while j > 0 {
                let (Some(a), Some(b)) = (entered.get(j - 1), entered.get(j)) else {
                    break;
                };
                if a.key <= b.key {
                    break;
                }
                entered.swap(j - 1, j);
                j -= 1;
            }
        }
        (entered, n, tested)
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

    /// Where a ray enters that child, if it does.
    fn entry(s: &Slabs, n: &IndexNode, reach: f64) -> Option<f64> {
        let (entered, count, tested) = s.entered(n, reach);
        assert_eq!(tested, 1);
        (count == 1).then_some(entered[0].key)
    }

    #[test]
    fn a_ray_along_a_face_of_the_box_enters_it() {
        let n = node([0.0; 3], [1.0; 3]);
        // In the plane x = 0, parallel to it: on the boundary counts as inside.
        let s = Slabs::new([0.0, 0.5, -1.0], [0.0, 0.0, 1.0]);
        let t = entry(&s, &n, f64::INFINITY).expect("enters");
        assert!(t <= 1.0 && t > 1.0 - 1e-15);
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
        assert!(t <= 1.0 && t > 1.0 - 1e-15);
        assert!(entry(&s, &n, 0.5).is_none());
        let behind = Slabs::new([3.0, 0.0, 0.0], [1.0, 0.0, 0.0]);
        assert!(entry(&behind, &n, f64::INFINITY).is_none());
        let inside = Slabs::new([1.5, 0.0, 0.0], [-1.0, 0.2, 0.0]);
        assert_eq!(entry(&inside, &n, f64::INFINITY), Some(0.0));
    }

    #[test]
    fn children_come_nearest_first_and_empty_slots_are_not_tested() {
        let mut n = IndexNode::EMPTY;
        let unit = |x: f64| Bounds {
            lo: [x, 0.0, 0.0],
            hi: [x + 1.0, 1.0, 1.0],
        };
        // Boxes at x = 4, 0 and 2 along +x, and one the ray passes beside.
        n.set(0, &unit(4.0), 10, 0);
        n.set(1, &unit(0.0), 20, 3);
        n.set(2, &unit(2.0), 30, 0);
        let s = Slabs::new([-1.0, 0.5, 0.5], [1.0, 0.0, 0.0]);
        let (entered, count, tested) = s.entered(&n, f64::INFINITY);
        assert_eq!((count, tested), (3, 3));
        let order: Vec<(u32, u32)> = entered[..3].iter().map(|e| (e.start, e.count)).collect();
        assert_eq!(order, [(20, 3), (30, 0), (10, 0)]);
        // Up to t = 4 (x = 3) the farthest box is not entered.
        let (_, count, _) = s.entered(&n, 4.0);
        assert_eq!(count, 2);
        let beside = Slabs::new([-1.0, 2.0, 0.5], [1.0, 0.0, 0.0]);
        assert_eq!(beside.entered(&n, f64::INFINITY).1, 0);
    }
}
