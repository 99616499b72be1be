//! The surface index: an axis-aligned box hierarchy over one model's stored triangles,
//! model frame, split by the surface area heuristic, for the queries of one model against
//! rays ([`ray`]) and points ([`point`]). Made once per open file at its first such query
//! ([`ObbtFile::derived`](crate::format::ObbtFile)) and kept with it.
//!
//! Why a second hierarchy: the file's tree is shaped for pairs of posed models (tight
//! oriented boxes, split for volume), where a box test is paid once per node pair. A ray
//! or a point tests one volume per node and is done in microseconds, so there the test's
//! cost decides: an axis-aligned box against a ray's inverse direction or a point is a
//! handful of operations against an oriented box's change of frame, four children side by
//! side are read at once, and the surface area heuristic, which minimises the expected
//! number of boxes a random ray opens, shapes the tree for exactly these queries.
//!
//! Boxes are stored in f32, rounded outward from the f64 corners, and each query widens
//! its bounds by their own rounding, so no box is pruned that holds an answer; the
//! triangles are copied in leaf order as the exact corners the tree stores, and tested by
//! the same exact triangle tests as before.

pub(in crate::query) mod point;
pub(in crate::query) mod ray;

use super::engine::triangle;
use super::triangle::Triangle;
use super::{source_id, within_reach, QueryError, Side, WITHIN_REACH};
use crate::arr3;
use crate::bv::BoundingVolume;
use crate::real::Real;
use crate::tree::TreeView;

/// Triangles a leaf holds at most: more are split even where the heuristic would keep them.
const MAX_LEAF: usize = 4;

/// Bins per axis of the heuristic's split search.
const BINS: usize = 12;

/// The heuristic's cost of opening a node, in triangle tests.
const NODE_COST: f64 = 1.0;

/// Children of a node at most: a descent reads them together, so wider nodes mean fewer
/// dependent memory reads per ray.
pub(in crate::query) const WIDTH: usize = 4;

/// A child slot's `count` when the node has fewer children.
const EMPTY: u32 = u32::MAX;

/// A node: the boxes of up to [`WIDTH`] children, axis by axis (f32, rounded outward), and
/// for each either another node (`count` 0, `start` its index), `count` triangles from
/// `start` in leaf order, or nothing ([`EMPTY`]). 128 bytes, two 64-byte lines.
#[derive(Clone, Copy, Debug)]
#[repr(C, align(64))]
pub(in crate::query) struct IndexNode {
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

/// A child of a node that a query keeps: its key (where a ray enters its box, or the square
/// of a lower bound of a point's distance to it), and either a node (`count` 0, `start` its
/// index) or `count` triangles from `start` in leaf order.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(in crate::query) struct Child {
    pub(in crate::query) key: f64,
    pub(in crate::query) start: u32,
    pub(in crate::query) count: u32,
}

impl Child {
    /// The root, as a child to take first.
    pub(in crate::query) const ROOT: Child = Child {
        key: 0.0,
        start: 0,
        count: 0,
    };
}

impl IndexNode {
    /// A bit per slot, set where the slot is occupied.
    #[inline(always)]
    fn occupied(&self) -> u32 {
        let [a, b, c, d] = self.count.map(|c| u32::from(c != EMPTY));
        a | b << 1 | c << 2 | d << 3
    }

    /// The children whose key (one per slot) `keep` accepts, in slot order; how many they
    /// are; and how many children were keyed (empty slots are not).
    #[inline(always)]
    fn kept(
        &self,
        keys: [f64; WIDTH],
        keep: impl Fn(f64) -> bool,
    ) -> ([Child; WIDTH], usize, usize) {
        let mut kept = [Child::ROOT; WIDTH];
        let (mut n, mut keyed) = (0, 0);
        for ((&key, &start), &count) in keys.iter().zip(&self.start).zip(&self.count) {
            if count == EMPTY {
                continue;
            }
            keyed += 1;
            if keep(key) {
                if let Some(slot) = kept.get_mut(n) {
                    *slot = Child { key, start, count };
                    n += 1;
                }
            }
        }
        (kept, n, keyed)
    }
}

/// What an occupied child slot of a node holds.
#[derive(Clone, Debug, PartialEq)]
pub(in crate::query) enum Slot {
    /// Another node, by its index (after its parent's).
    Node(u32),
    /// These triangles, in leaf order.
    Triangles(std::ops::Range<usize>),
}

impl IndexNode {
    /// What child slot `lane` holds, if it is occupied.
    #[inline(always)]
    pub(in crate::query) fn slot(&self, lane: usize) -> Option<Slot> {
        let (&start, &count) = self.start.get(lane).zip(self.count.get(lane))?;
        match count {
            EMPTY => None,
            0 => Some(Slot::Node(start)),
            n => Some(Slot::Triangles(start as usize..start as usize + n as usize)),
        }
    }

    /// The occupied child slots, in lane order: each one's lane and what it holds.
    pub(in crate::query) fn slots(&self) -> impl Iterator<Item = (usize, Slot)> + '_ {
        (0..WIDTH).filter_map(|lane| Some((lane, self.slot(lane)?)))
    }
}

/// The index of one model (see the module's documentation).
#[derive(Debug)]
pub(in crate::query) struct SurfaceIndex {
    /// Node 0 is the root; children come after their parent.
    nodes: Vec<IndexNode>,
    /// The triangles in leaf order, model frame: the stored corners, exactly.
    triangles: Vec<Triangle>,
    /// Each one's stored face index, for its input id.
    faces: Vec<u32>,
    /// The first stored face with a coordinate beyond [`super::MAX_COORDINATE`], and that
    /// coordinate's magnitude.
    beyond_reach: Option<(u32, f64)>,
}

impl SurfaceIndex {
    /// How many nodes there are; node 0 is the root.
    pub(in crate::query) fn node_count(&self) -> usize {
        self.nodes.len()
    }

    /// Node `index`, if there is one.
    #[inline(always)]
    pub(in crate::query) fn node(&self, index: u32) -> Option<&IndexNode> {
        self.nodes.get(index as usize)
    }

    /// The leaf-order triangles of `range`, if they exist.
    #[inline(always)]
    pub(in crate::query) fn triangles(&self, range: std::ops::Range<usize>) -> Option<&[Triangle]> {
        self.triangles.get(range)
    }

    /// Leaf-order triangle `i` and its stored face index.
    #[inline(always)]
    pub(in crate::query) fn triangle(&self, i: usize) -> Option<(&Triangle, u32)> {
        Some((self.triangles.get(i)?, *self.faces.get(i)?))
    }

    /// The error naming the first triangle (by its input id) with a coordinate beyond
    /// [`super::MAX_COORDINATE`], for the queries that measure squared distances to the
    /// model.
    /// `what` names such a triangle ("model triangle"); the tree is model `which`'s.
    pub(in crate::query) fn check_reach<B: BoundingVolume>(
        &self,
        tree: &TreeView<'_, B>,
        which: Side,
        what: &'static str,
    ) -> Result<(), QueryError> {
        match self.beyond_reach {
            Some((face, value)) => Err(QueryError::BadInput {
                what,
                index: source_id(tree, face, which)? as usize,
                requirement: WITHIN_REACH,
                value,
            }),
            None => Ok(()),
        }
    }

    /// The index of `tree`'s triangles. O(n log n).
    ///
    /// # Errors
    ///
    /// [`QueryError::CorruptTree`] for a face naming a vertex out of bounds (a damaged,
    /// unverified file).
    pub(in crate::query) fn build<B: BoundingVolume>(
        tree: &TreeView<'_, B>,
    ) -> Result<SurfaceIndex, QueryError> {
        let count = u32::try_from(tree.faces().len()).map_err(|_| QueryError::CorruptTree {
            which: Side::A,
            what: "more faces than 32-bit indices reach",
        })?;
        // Each stored triangle read once, in face order, then put in leaf order.
        let stored = (0..count)
            .map(|face| triangle(tree, face, None, Side::A))
            .collect::<Result<Vec<Triangle>, QueryError>>()?;
        let mut prims: Vec<Prim> = (0..count)
            .zip(&stored)
            .map(|(face, t)| {
                let mut bounds = Bounds::EMPTY;
                for p in t {
                    bounds.add(&[p.x, p.y, p.z]);
                }
                Prim {
                    face,
                    bounds,
                    centre: bounds.centre(),
                }
            })
            .collect();
        let binary = binary_tree(&mut prims, 0);
        let nodes = widen(&binary);
        // (Every prim's face is one of `stored`'s.)
        let triangles = prims
            .iter()
            .filter_map(|p| stored.get(p.face as usize).copied())
            .collect();
        let beyond_reach = (0..count).zip(&stored).find_map(|(face, t)| {
            let largest = t.iter().map(|p| p.amax()).fold(0.0, f64::max);
            (!within_reach(largest)).then_some((face, largest))
        });
        Ok(SurfaceIndex {
            nodes,
            triangles,
            faces: prims.iter().map(|p| p.face).collect(),
            beyond_reach,
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

    /// The smallest box holding both (NaN coordinates skipped). Plain comparisons rather
    /// than `arr3::min`/`max`: this is the build's inner loop, and `f64::min`'s NaN
    /// handling made the build about a fifth slower.
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
        (
            arr3::map(self.lo, f32::from_f64_down),
            arr3::map(self.hi, f32::from_f64_up),
        )
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
    // 0 (the axis skipped) where the centres do not spread, or a damaged file's extent is
    // not finite: where the bins' scale is not a finite number.
    let scales: [f64; 3] = std::array::from_fn(|k| {
        let extent =
            centres.hi.get(k).copied().unwrap_or(0.0) - centres.lo.get(k).copied().unwrap_or(0.0);
        let scale = bin_count as f64 / extent;
        if scale.is_finite() {
            scale
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

#[cfg(test)]
mod tests {
    use super::*;

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
}
