//! The ray index: an axis-aligned box hierarchy over a model's stored triangles, model
//! frame, split by the surface area heuristic, made once per open file at its first ray
//! query ([`ObbtFile::derived`](crate::format::ObbtFile)).
//!
//! Why a second hierarchy: the file's tree is shaped for pairs of posed models (tight
//! oriented boxes, split for volume), where a box test is paid once per node pair. A ray
//! tests one volume per node and is done in microseconds, so there the test's cost
//! dominates: an axis-aligned slab test with the ray's inverse direction is a handful of
//! operations against an oriented box's rotation and divisions, and the surface area
//! heuristic, which minimises the expected number of boxes a random ray opens, shapes the
//! tree for exactly this query.
//!
//! Boxes are stored in f32, rounded outward from the f64 corners, and the slab test widens
//! its interval by its own rounding, so the descent never prunes a box the ray meets; the
//! triangles are copied in leaf order as the exact corners the tree stores, and tested by
//! the same watertight test as before.

use super::super::engine::triangle;
use super::super::triangle::Triangle;
use super::super::{QueryError, Side};
use crate::arr3;
use crate::bv::BoundingVolume;
use crate::tree::TreeView;

/// Triangles a leaf holds at most: more are split even where the heuristic would keep them.
const MAX_LEAF: usize = 4;

/// Bins per axis of the heuristic's split search.
const BINS: usize = 12;

/// The heuristic's cost of opening a node, in triangle tests.
const NODE_COST: f64 = 1.0;

/// Children of a node at most: a descent reads them together, so wider nodes mean fewer
/// dependent memory reads per ray.
pub(super) const WIDTH: usize = 4;

/// A child slot's `count` when the node has fewer children.
const EMPTY: u32 = u32::MAX;

/// A node: the boxes of up to [`WIDTH`] children, axis by axis (f32, rounded outward), and
/// for each either another node (`count` 0, `start` its index), `count` triangles from
/// `start` in leaf order, or nothing ([`EMPTY`]). 128 bytes, two 64-byte lines.
#[derive(Clone, Copy, Debug)]
#[repr(C, align(64))]
pub(super) struct IndexNode {
    lo: [[f32; WIDTH]; 3],
    hi: [[f32; WIDTH]; 3],
    start: [u32; WIDTH],
    count: [u32; WIDTH],
}

impl IndexNode {
    const EMPTY: IndexNode = IndexNode {
        lo: [[0.0; WIDTH]; 3],
        hi: [[0.0; WIDTH]; 3],
        start: [0; WIDTH],
        count: [EMPTY; WIDTH],
    };
}

/// A child of a node the ray enters, as a descent keeps it.
#[derive(Clone, Copy, Debug)]
pub(super) struct Entered {
    /// A lower bound of where the ray enters its box.
    pub(super) entry: f64,
    /// A node index (`count` 0), or the first of its triangles.
    pub(super) start: u32,
    /// Its number of triangles, 0 for a node.
    pub(super) count: u32,
}

/// The index of one model (see the module's documentation).
#[derive(Debug)]
pub(super) struct RayIndex {
    /// Node 0 is the root; children come after their parent.
    nodes: Vec<IndexNode>,
    /// The triangles in leaf order, model frame: the stored corners, exactly.
    triangles: Vec<Triangle>,
    /// Each one's stored face index, for its input id.
    faces: Vec<u32>,
}

impl RayIndex {
    /// Node `index`, if there is one.
    #[inline(always)]
    pub(super) fn node(&self, index: u32) -> Option<&IndexNode> {
        self.nodes.get(index as usize)
    }

    /// Leaf-order triangle `i` and its stored face index.
    #[inline(always)]
    pub(super) fn triangle(&self, i: usize) -> Option<(&Triangle, u32)> {
        Some((self.triangles.get(i)?, *self.faces.get(i)?))
    }

    /// The index of `tree`'s triangles. O(n log n).
    ///
    /// # Errors
    ///
    /// [`QueryError::CorruptTree`] for a face naming a vertex out of bounds (a damaged,
    /// unverified file).
    pub(super) fn build<B: BoundingVolume>(tree: &TreeView<'_, B>) -> Result<RayIndex, QueryError> {
        let count = u32::try_from(tree.faces().len()).map_err(|_| QueryError::CorruptTree {
            which: Side::A,
            what: "more faces than 32-bit indices reach",
        })?;
        let mut prims = Vec::with_capacity(count as usize);
        for face in 0..count {
            let t = triangle(tree, face, None, Side::A)?;
            let mut bounds = Bounds::EMPTY;
            for p in &t {
                bounds.add(&[p.x, p.y, p.z]);
            }
            prims.push(Prim {
                face,
                bounds,
                centre: bounds.centre(),
            });
        }
        let binary = binary_tree(&mut prims, 0);
        let nodes = widen(&binary);
        let mut triangles = Vec::with_capacity(prims.len());
        for p in &prims {
            triangles.push(triangle(tree, p.face, None, Side::A)?);
        }
        Ok(RayIndex {
            nodes,
            triangles,
            faces: prims.iter().map(|p| p.face).collect(),
        })
    }
}

/// A node of the binary tree the index is made from.
struct Binary {
    bounds: Bounds,
    kind: BinaryKind,
}

/// A binary node's two children (binary node indices), or a leaf's prims.
enum BinaryKind {
    Children(usize, usize),
    Prims(std::ops::Range<usize>),
}

/// Groups at least this large are split on two threads: below, a thread's share of the
/// work no longer pays for handing it over.
const PARALLEL_MIN: usize = 8192;

/// The binary tree of `prims` by the surface area heuristic (prims reordered into leaf
/// order; ranges count from `offset`, where `prims` starts among all); node 0 is the root.
fn binary_tree(prims: &mut [Prim], offset: usize) -> Vec<Binary> {
    let bounds = prims.iter().fold(Bounds::EMPTY, |b, p| b.union(&p.bounds));
    if prims.len() >= PARALLEL_MIN {
        if let Some(middle) = split(prims, &bounds) {
            let (left, right) = prims.split_at_mut(middle);
            let (left, right) = rayon::join(
                || binary_tree(left, offset),
                || binary_tree(right, offset + middle),
            );
            let (l, r) = (1, 1 + left.len());
            let mut nodes = Vec::with_capacity(r + right.len());
            nodes.push(Binary {
                bounds,
                kind: BinaryKind::Children(l, r),
            });
            nodes.extend(left.into_iter().map(|n| n.shifted(l)));
            nodes.extend(right.into_iter().map(|n| n.shifted(r)));
            return nodes;
        }
    }
    let unmade = || Binary {
        bounds: Bounds::EMPTY,
        kind: BinaryKind::Prims(0..0),
    };
    let mut nodes = vec![unmade()];
    // (node, its prims) still to make; explicit, since a skewed split can be deep.
    let mut todo = vec![(0usize, 0..prims.len(), bounds)];
    while let Some((at, range, bounds)) = todo.pop() {
        let Some(these) = prims.get_mut(range.clone()) else {
            continue;
        };
        let kind = match split(these, &bounds) {
            Some(left) => {
                let (l, r) = (nodes.len(), nodes.len() + 1);
                nodes.push(unmade());
                nodes.push(unmade());
                let middle = range.start + left;
                let (left, right) = these.split_at(left);
                let of = |half: &[Prim]| half.iter().fold(Bounds::EMPTY, |b, p| b.union(&p.bounds));
                todo.push((l, range.start..middle, of(left)));
                todo.push((r, middle..range.end, of(right)));
                BinaryKind::Children(l, r)
            }
            None => BinaryKind::Prims(range.start + offset..range.end + offset),
        };
        if let Some(node) = nodes.get_mut(at) {
            *node = Binary { bounds, kind };
        }
    }
    nodes
}

impl Binary {
    /// The node with its children's indices moved by `by`.
    fn shifted(self, by: usize) -> Binary {
        let kind = match self.kind {
            BinaryKind::Children(l, r) => BinaryKind::Children(l + by, r + by),
            prims => prims,
        };
        Binary { kind, ..self }
    }
}

/// The nodes of [`WIDTH`] children made of `binary`: each takes a binary node's two
/// children, then opens the one of largest surface area that is not a leaf, until it has
/// [`WIDTH`] or only leaves.
fn widen(binary: &[Binary]) -> Vec<IndexNode> {
    let mut nodes = vec![IndexNode::EMPTY];
    let mut todo = vec![(0usize, 0usize)];
    while let Some((at, b)) = todo.pop() {
        let Some(node) = binary.get(b) else {
            continue;
        };
        let mut children = match node.kind {
            BinaryKind::Children(l, r) => vec![l, r],
            // A root that is a leaf: one child.
            BinaryKind::Prims(_) => vec![b],
        };
        while children.len() < WIDTH {
            let open = children
                .iter()
                .enumerate()
                .filter_map(|(i, &c)| {
                    let child = binary.get(c)?;
                    match child.kind {
                        BinaryKind::Children(l, r) => Some((i, l, r, child.bounds.half_area())),
                        BinaryKind::Prims(_) => None,
                    }
                })
                .max_by(|x, y| x.3.total_cmp(&y.3));
            let Some((i, l, r, _)) = open else {
                break;
            };
            children.swap_remove(i);
            children.push(l);
            children.push(r);
        }
        let mut wide = IndexNode::EMPTY;
        for (lane, &c) in children.iter().enumerate() {
            let Some(child) = binary.get(c) else {
                continue;
            };
            let (start, count) = match &child.kind {
                // (Only an empty model has an empty leaf: its slot stays empty.)
                BinaryKind::Prims(range) if range.is_empty() => continue,
                BinaryKind::Prims(range) => (range.start, range.len()),
                BinaryKind::Children(..) => {
                    nodes.push(IndexNode::EMPTY);
                    todo.push((nodes.len() - 1, c));
                    (nodes.len() - 1, 0)
                }
            };
            wide.set(lane, &child.bounds, start as u32, count as u32);
        }
        if let Some(slot) = nodes.get_mut(at) {
            *slot = wide;
        }
    }
    nodes
}

impl IndexNode {
    /// Child slot `lane`: `bounds` rounded outward, and what it holds.
    fn set(&mut self, lane: usize, bounds: &Bounds, start: u32, count: u32) {
        let (lo, hi) = bounds.outward_f32();
        let axes = self
            .lo
            .iter_mut()
            .zip(self.hi.iter_mut())
            .zip(lo.into_iter().zip(hi));
        for ((los, his), (lo, hi)) in axes {
            if let (Some(l), Some(h)) = (los.get_mut(lane), his.get_mut(lane)) {
                (*l, *h) = (lo, hi);
            }
        }
        if let (Some(s), Some(c)) = (self.start.get_mut(lane), self.count.get_mut(lane)) {
            (*s, *c) = (start, count);
        }
    }
}

/// A triangle while the index is made.
#[derive(Clone, Copy)]
struct Prim {
    bounds: Bounds,
    centre: [f64; 3],
    face: u32,
}

/// An axis-aligned box in f64.
#[derive(Clone, Copy, Debug)]
struct Bounds {
    lo: [f64; 3],
    hi: [f64; 3],
}

impl Bounds {
    const EMPTY: Bounds = Bounds {
        lo: [f64::INFINITY; 3],
        hi: [f64::NEG_INFINITY; 3],
    };

    /// The box grown to hold `p` (a NaN coordinate, of a damaged file, is skipped).
    #[inline(always)]
    fn add(&mut self, p: &[f64; 3]) {
        *self = self.union(&Bounds { lo: *p, hi: *p });
    }

    /// The smallest box holding both (NaN coordinates skipped).
    #[inline(always)]
    fn union(&self, o: &Bounds) -> Bounds {
        let mut b = *self;
        for (x, &y) in b.lo.iter_mut().zip(&o.lo) {
            if y < *x {
                *x = y;
            }
        }
        for (x, &y) in b.hi.iter_mut().zip(&o.hi) {
            if y > *x {
                *x = y;
            }
        }
        b
    }

    fn centre(&self) -> [f64; 3] {
        arr3::map(arr3::zip(self.lo, self.hi), |(lo, hi)| 0.5 * lo + 0.5 * hi)
    }

    /// Half the surface area (0 for an empty box): what the heuristic weighs children by.
    fn half_area(&self) -> f64 {
        let [x, y, z] = arr3::map(arr3::zip(self.lo, self.hi), |(lo, hi)| (hi - lo).max(0.0));
        x * y + y * z + z * x
    }

    /// The box in f32, rounded outward so that it holds the f64 one.
    fn outward_f32(&self) -> ([f32; 3], [f32; 3]) {
        let down = |x: f64| {
            let y = x as f32;
            if f64::from(y) > x {
                y.next_down()
            } else {
                y
            }
        };
        let up = |x: f64| {
            let y = x as f32;
            if f64::from(y) < x {
                y.next_up()
            } else {
                y
            }
        };
        (self.lo.map(down), self.hi.map(up))
    }
}

/// Where to split `prims` (reordered so that the left child's come first), whose boxes
/// together make `parent`: the number going left, by the binned surface area heuristic
/// over the triangles' box centres, or `None` for a leaf. A group of at most [`MAX_LEAF`]
/// whose split would cost more than testing them all stays a leaf; a larger group with no
/// split by centres (all centres equal) is halved as it lies.
fn split(prims: &mut [Prim], parent: &Bounds) -> Option<usize> {
    let n = prims.len();
    let centres = prims.iter().fold(Bounds::EMPTY, |mut b, p| {
        b.add(&p.centre);
        b
    });
    // (A small group needs no more bins than it has triangles: most groups are small.)
    let bin_count = n.clamp(2, BINS);
    let scales: [f64; 3] = std::array::from_fn(|k| {
        let extent =
            centres.hi.get(k).copied().unwrap_or(0.0) - centres.lo.get(k).copied().unwrap_or(0.0);
        if extent > 0.0 && extent.is_finite() {
            bin_count as f64 / extent
        } else {
            0.0
        }
    });
    // Per axis, the bins' counts and boxes, made in one pass over the prims.
    let mut bins = [[(0usize, Bounds::EMPTY); BINS]; 3];
    for p in prims.iter() {
        for (((axis, &c), &lo), &scale) in
            bins.iter_mut().zip(&p.centre).zip(&centres.lo).zip(&scales)
        {
            if scale == 0.0 {
                continue;
            }
            if let Some((count, bounds)) = axis.get_mut(bin(c, lo, scale, bin_count)) {
                *count += 1;
                *bounds = bounds.union(&p.bounds);
            }
        }
    }
    // (axis, bins left of the plane, cost)
    let mut best: Option<(usize, usize, f64)> = None;
    for (axis, (bins, &scale)) in bins.iter().zip(&scales).enumerate() {
        if scale == 0.0 {
            continue;
        }
        // Areas times counts left of each plane, then right of it.
        let mut left = [0.0f64; BINS];
        let (mut count, mut bounds) = (0usize, Bounds::EMPTY);
        for (slot, (c, b)) in left.iter_mut().zip(bins.iter()).take(bin_count) {
            count += c;
            bounds = bounds.union(b);
            *slot = count as f64 * bounds.half_area();
        }
        let (mut count, mut bounds) = (0usize, Bounds::EMPTY);
        for plane in (1..bin_count).rev() {
            if let Some((c, b)) = bins.get(plane) {
                count += c;
                bounds = bounds.union(b);
            }
            let cost =
                left.get(plane - 1).copied().unwrap_or(0.0) + count as f64 * bounds.half_area();
            if best.is_none_or(|(_, _, c)| cost < c) && count > 0 && count < n {
                best = Some((axis, plane, cost));
            }
        }
    }
    let area = parent.half_area();
    match best {
        Some((axis, plane, cost)) => {
            let split_cost = NODE_COST + if area > 0.0 { cost / area } else { n as f64 };
            if n <= MAX_LEAF && split_cost >= n as f64 {
                return None;
            }
            let lo = centres.lo.get(axis).copied().unwrap_or(0.0);
            let scale = scales.get(axis).copied().unwrap_or(0.0);
            Some(partition(prims, |p| {
                bin(
                    p.centre.get(axis).copied().unwrap_or(0.0),
                    lo,
                    scale,
                    bin_count,
                ) < plane
            }))
        }
        None if n <= MAX_LEAF => None,
        None => Some(n / 2),
    }
}

/// The bin of a centre coordinate `x` among `count` (clamped; NaN to the first).
#[inline]
fn bin(x: f64, lo: f64, scale: f64, count: usize) -> usize {
    (((x - lo) * scale) as usize).min(count - 1)
}

/// Moves the prims for which `left` holds first, returning how many there are.
fn partition(prims: &mut [Prim], left: impl Fn(&Prim) -> bool) -> usize {
    let mut i = 0;
    for j in 0..prims.len() {
        if prims.get(j).is_some_and(&left) {
            prims.swap(i, j);
            i += 1;
        }
    }
    i
}

/// A ray in the model frame, set up for slab tests.
pub(super) struct Slabs {
    origin: [f64; 3],
    direction: [f64; 3],
    inverse: [f64; 3],
}

/// How much a computed slab parameter may be off, relative to itself: the difference,
/// the inverse and the product each round once.
const SLAB_ROUNDING: f64 = 4.0 * f64::EPSILON;

impl Slabs {
    /// The slabs of the ray `origin + t direction` (finite, direction not zero).
    pub(super) fn new(origin: [f64; 3], direction: [f64; 3]) -> Slabs {
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
    pub(super) fn entries(&self, node: &IndexNode, reach: f64) -> [f64; WIDTH] {
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
    pub(super) fn entered(&self, node: &IndexNode, reach: f64) -> ([Entered; WIDTH], usize, usize) {
        let entries = self.entries(node, reach);
        let mut entered = [Entered {
            entry: 0.0,
            start: 0,
            count: 0,
        }; WIDTH];
        let (mut n, mut tested) = (0, 0);
        let lanes = entries.iter().zip(&node.start).zip(&node.count);
        for ((&entry, &start), &count) in lanes {
            if count == EMPTY {
                continue;
            }
            tested += 1;
            if entry < f64::INFINITY {
                if let Some(slot) = entered.get_mut(n) {
                    *slot = Entered {
                        entry,
                        start,
                        count,
                    };
                    n += 1;
                }
            }
        }
        // Insertion sort: at most four, and a library sort is not inlined here.
        for i in 1..n {
            let mut j = i;
            while j > 0 {
                let (Some(a), Some(b)) = (entered.get(j - 1), entered.get(j)) else {
                    break;
                };
                if a.entry <= b.entry {
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
        (count == 1).then_some(entered[0].entry)
    }

    #[test]
    fn outward_rounding_holds_the_box() {
        let b = Bounds {
            lo: [0.1, -0.1, 1e-40],
            hi: [0.3, -1e-45, 1.0 / 3.0],
        };
        let (lo, hi) = b.outward_f32();
        for k in 0..3 {
            assert!(f64::from(lo[k]) <= b.lo[k] && f64::from(hi[k]) >= b.hi[k]);
        }
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
