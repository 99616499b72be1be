//! The one traversal loop behind every query: an iterative tandem descent of two trees
//! (dissertation Figure 7.9, "any query"), with the query kind plugged in as a policy.
//!
//! No recursion and no allocation per test: pairs wait on an explicit stack (collision) or
//! a bounded heap and stack (distance, span: best first) owned by a [`QueryContext`] and
//! reused across queries. Every node access goes through the checked
//! accessors of [`TreeView`], so a corrupt, unverified tree ends in an error, not a panic,
//! and children must follow their parents, so every traversal terminates.

use super::descent::DescentRule;
use super::triangle::Triangle;
use super::work::Work;
use super::{QueryError, Side};
use crate::bv::{BoundingVolume, Node};
use crate::pose::Pose;
use crate::tree::{NodeDefect, NodeKind, TreeView};
use nalgebra::Vector3;
use std::collections::BinaryHeap;
use std::ops::Range;

/// What a policy says after a triangle pair: go on, or stop the whole traversal.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum Flow {
    Continue,
    Stop,
}

/// The query-specific part of a traversal.
pub(crate) trait Policy<B: BoundingVolume> {
    /// Whether children pairs should be visited in order of their keys (smallest first).
    const ORDERED: bool;
    /// The key of a volume pair: collision uses 0 (may overlap) or infinity (disjoint);
    /// distance a lower bound; span the negated upper bound. Smaller is more promising.
    fn key(&self, a: &B, b: &B, b_to_a: &Pose) -> f64;
    /// Whether a pair with this key still matters (checked when it is taken off the stack
    /// or heap, since the best answer may have improved since it was pushed). Monotone: a
    /// larger key is never kept where a smaller one is not, which lets an ordered
    /// traversal stop at the first pruned smallest key; and a key once refused stays
    /// refused (the best answer only improves).
    fn keep(&self, key: f64) -> bool;
    /// Whether an unordered traversal takes the two children of a step nearer first (by
    /// the distance between their volumes' centres and the other node's), rather than in
    /// stored order: worth its cost when the query stops at its first find.
    #[inline]
    fn nearest_first(&self) -> bool {
        false
    }
    /// The key of a volume pair and the rank a dive of an ordered traversal chooses
    /// between children by (smaller first): the key itself by default.
    #[inline]
    fn key_and_rank(&self, a: &B, b: &B, b_to_a: &Pose) -> (f64, f64) {
        let key = self.key(a, b, b_to_a);
        (key, key)
    }
    /// Tests one triangle pair (A's triangle in A's frame, B's mapped into it).
    /// `face_a` / `face_b` are leaf-ordered face indices.
    fn triangles(
        &mut self,
        face_a: u32,
        a: &Triangle,
        face_b: u32,
        b: &Triangle,
        work: &mut Work,
    ) -> Flow;
}

/// A node pair waiting, with the key computed when it was pushed (ordered policies).
///
/// Packed into one integer whose order is the heap's: the key's bits mapped so that
/// unsigned order is [`f64::total_cmp`]'s, then A's node, then B's. Sifting the heap then
/// compares one `u128` per step instead of a float total order and two tie-breaks (the
/// heap's sifting was a tenth of an exact distance query's time).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) struct Pending(u128);

impl Pending {
    #[inline(always)]
    fn new(a: u32, b: u32, key: f64) -> Pending {
        Pending((u128::from(key_rank(key)) << 64) | (u128::from(a) << 32) | u128::from(b))
    }

    #[inline(always)]
    fn a(self) -> u32 {
        (self.0 >> 32) as u32
    }

    #[inline(always)]
    fn b(self) -> u32 {
        self.0 as u32
    }

    #[inline(always)]
    fn key(self) -> f64 {
        rank_key((self.0 >> 64) as u64)
    }
}

/// `key`'s bits, mapped so that their unsigned order is [`f64::total_cmp`]'s order of keys
/// (negatives have their bits flipped, non-negatives their sign bit set).
#[inline(always)]
fn key_rank(key: f64) -> u64 {
    let bits = key.to_bits();
    if bits >> 63 == 1 {
        !bits
    } else {
        bits | (1 << 63)
    }
}

/// Inverse of [`key_rank`].
#[inline(always)]
fn rank_key(rank: u64) -> f64 {
    f64::from_bits(if rank >> 63 == 1 {
        rank & !(1 << 63)
    } else {
        !rank
    })
}

/// Pending pairs of an ordered traversal, smallest key on top: reversed (`BinaryHeap` is
/// a max-heap) on the key, then on the node indices, so that the order of a traversal
/// never depends on the heap's layout.
impl PartialOrd for Pending {
    fn partial_cmp(&self, other: &Self) -> Option<std::cmp::Ordering> {
        Some(self.cmp(other))
    }
}

impl Ord for Pending {
    #[inline(always)]
    fn cmp(&self, other: &Self) -> std::cmp::Ordering {
        other.0.cmp(&self.0)
    }
}

/// Reusable scratch of the traversal: keep one per thread and pass it to every query to
/// avoid allocating.
#[derive(Debug)]
pub struct QueryContext {
    /// Pairs waiting in a collision traversal (depth first), or beyond the heap in an
    /// ordered one.
    pub(crate) stack: Vec<Pending>,
    /// Pairs waiting in an ordered traversal (best first; see [`Frontier`]).
    pub(crate) heap: BinaryHeap<Pending>,
    /// Contacting leaf-ordered face pairs of the running collision query.
    pub(crate) faces: Vec<(u32, u32)>,
    /// How many pairs `heap` holds before new ones go on `stack`: [`FRONTIER_HEAP`]
    /// (tests lower it, so that small traversals use the stack too).
    heap_limit: usize,
}

impl Default for QueryContext {
    fn default() -> Self {
        QueryContext {
            stack: Vec::new(),
            heap: BinaryHeap::new(),
            faces: Vec::new(),
            heap_limit: FRONTIER_HEAP,
        }
    }
}

/// The pairs waiting in a traversal: a stack (depth first) for unordered policies, a
/// [`Frontier`] for ordered ones.
trait Waiting {
    fn put(&mut self, pending: Pending);
    /// The next pair, and whether it has the smallest key of all that waited.
    fn take(&mut self) -> Option<(Pending, bool)>;
    fn len(&self) -> usize;
}

impl Waiting for Vec<Pending> {
    #[inline(always)]
    fn put(&mut self, pending: Pending) {
        self.push(pending);
    }
    #[inline(always)]
    fn take(&mut self) -> Option<(Pending, bool)> {
        self.pop().map(|p| (p, false))
    }
    fn len(&self) -> usize {
        Vec::len(self)
    }
}

/// How many pairs the heap of an ordered traversal holds before new ones go on a stack:
/// 64 KiB, within a core's L2 cache. Between concentric spheres (the worst case of
/// distance bounds: 2.4 million pairs) an unbounded heap grew past the caches and its
/// sifting took half the query's time (2.3 times the depth-first order's time).
const FRONTIER_HEAP: usize = 4096;

/// The pairs waiting in an ordered traversal: a heap of at most [`FRONTIER_HEAP`] pairs,
/// smallest key first, and a stack for the pairs that arrive while it is full, taken
/// first (depth first below the best-first top of the search).
struct Frontier<'c> {
    heap: &'c mut BinaryHeap<Pending>,
    overflow: &'c mut Vec<Pending>,
    /// The heap's capacity ([`QueryContext`]'s `heap_limit`).
    limit: usize,
}

impl Waiting for Frontier<'_> {
    #[inline(always)]
    fn put(&mut self, pending: Pending) {
        if self.heap.len() < self.limit {
            self.heap.push(pending);
        } else {
            self.overflow.push(pending);
        }
    }
    #[inline(always)]
    fn take(&mut self) -> Option<(Pending, bool)> {
        match self.overflow.pop() {
            Some(p) => Some((p, false)),
            // With the stack empty, the heap's smallest is the smallest of all.
            None => self.heap.pop().map(|p| (p, true)),
        }
    }
    fn len(&self) -> usize {
        self.heap.len() + self.overflow.len()
    }
}

impl QueryContext {
    /// An empty context; its buffers grow to the largest traversal seen and stay.
    pub fn new() -> QueryContext {
        QueryContext::default()
    }

    /// An empty context whose ordered traversals keep at most `limit` pairs on the heap.
    #[cfg(test)]
    pub(crate) fn with_heap_limit(limit: usize) -> QueryContext {
        QueryContext {
            heap_limit: limit,
            ..QueryContext::default()
        }
    }
}

/// Reads triangle `face` of `tree`, mapped into A's frame by `b_to_a` (`None` for A's own).
#[inline]
pub(super) fn triangle<B: BoundingVolume>(
    tree: &TreeView<'_, B>,
    face: u32,
    b_to_a: Option<&Pose>,
    which: Side,
) -> Result<Triangle, QueryError> {
    let t = tree.triangle(face).ok_or(QueryError::CorruptTree {
        which,
        what: "face or vertex index out of bounds",
    })?;
    let v = t.map(Vector3::from);
    Ok(match b_to_a {
        Some(b_to_a) => v.map(|p| b_to_a.apply(&p)),
        None => v,
    })
}

/// Runs the tandem traversal of `a` and `b` (B mapped into A's frame by `b_to_a`).
///
/// Unordered policies (collision) go depth first and test a pair when it is taken, as
/// RAPID's recursion does: a first-contact query that stops never tests the pairs still
/// waiting. Ordered policies (distance, span) key a pair when it is pushed and dive: each
/// expansion continues with its most promising child (smallest rank, see
/// [`Policy::key_and_rank`]) down to a triangle pair (a first
/// answer to prune with, one step per level), the other children wait on a heap, and the
/// next dive starts from the smallest key waiting, wherever in the trees it is (up to the
/// [`Frontier`]'s heap size). The traversal ends as soon as that smallest key is pruned,
/// since every other key waiting is at least as large. (A depth-first order instead
/// resumes from the last sibling pushed: when its first answer was barely within
/// `rel_err`, it proved thousands of nearly-as-close pairs too far before trying the
/// closer ones.)
pub(crate) fn traverse<B: BoundingVolume, P: Policy<B>>(
    a: &TreeView<'_, B>,
    b: &TreeView<'_, B>,
    b_to_a: &Pose,
    rule: DescentRule,
    policy: &mut P,
    context: &mut QueryContext,
) -> Result<Work, QueryError> {
    if P::ORDERED {
        let mut frontier = Frontier {
            heap: &mut context.heap,
            overflow: &mut context.stack,
            limit: context.heap_limit,
        };
        frontier.heap.clear();
        frontier.overflow.clear();
        let (Some(ra), Some(rb)) = (a.node(0), b.node(0)) else {
            return Err(corrupt(Side::A, NodeDefect::Missing));
        };
        let key = ordered_key(policy.key(&ra.bv, &rb.bv, b_to_a));
        frontier.put(Pending::new(0, 0, key));
        descend(a, b, b_to_a, rule, policy, &mut frontier)
    } else {
        let stack = &mut context.stack;
        stack.clear();
        stack.push(Pending::new(0, 0, 0.0));
        descend(a, b, b_to_a, rule, policy, stack)
    }
}

pub(super) fn corrupt(which: Side, defect: NodeDefect) -> QueryError {
    QueryError::CorruptTree {
        which,
        what: defect.describe(),
    }
}

/// A key as the heap orders it: NaN (a damaged, unverified file) as +∞, so that it is
/// taken last and `keep` decides on it as on any large key, never first.
#[inline(always)]
fn ordered_key(key: f64) -> f64 {
    if key.is_nan() {
        f64::INFINITY
    } else {
        key
    }
}

/// The traversal loop over `waiting` (see [`traverse`]).
fn descend<B: BoundingVolume, P: Policy<B>, W: Waiting>(
    a: &TreeView<'_, B>,
    b: &TreeView<'_, B>,
    b_to_a: &Pose,
    rule: DescentRule,
    policy: &mut P,
    waiting: &mut W,
) -> Result<Work, QueryError> {
    let mut work = Work::default();
    // A tree visits each node pair at most once; more means shared children (a corrupt,
    // unverified file), which could otherwise take exponential time.
    let limit = (a.nodes().len() as u64).saturating_mul(b.nodes().len() as u64);
    // The child a dive continues with, taken before anything waiting.
    let mut dive: Option<Pending> = None;
    loop {
        let taken = match dive.take() {
            Some(pair) => Some((pair, false)),
            None => waiting.take(),
        };
        let Some((pending, smallest)) = taken else {
            break;
        };
        let (ia, ib, key) = (pending.a(), pending.b(), pending.key());
        work.nodes_visited += 1;
        if work.nodes_visited > limit {
            return Err(QueryError::CorruptTree {
                which: Side::A,
                what: "a node is reachable along two paths",
            });
        }
        let na = a
            .node(ia)
            .ok_or_else(|| corrupt(Side::A, NodeDefect::Missing))?;
        let nb = b
            .node(ib)
            .ok_or_else(|| corrupt(Side::B, NodeDefect::Missing))?;
        let key = if P::ORDERED {
            key
        } else {
            policy.key(&na.bv, &nb.bv, b_to_a)
        };
        if !policy.keep(key) {
            work.bv_disjoint += 1;
            if P::ORDERED && smallest {
                // The smallest key waiting is pruned, so is every other: they were all
                // tested when pushed, and count as pruned pairs taken off.
                let rest = waiting.len() as u64;
                work.bv_disjoint += rest;
                work.nodes_visited += rest;
                break;
            }
            continue;
        }
        work.bv_overlap += 1;
        let kind_a = a.node_kind(ia).map_err(|d| corrupt(Side::A, d))?;
        let kind_b = b.node_kind(ib).map_err(|d| corrupt(Side::B, d))?;
        // The tree a step descends, and its node's children.
        let (side, children) = match (kind_a, kind_b) {
            (NodeKind::Faces(faces_a), NodeKind::Faces(faces_b)) => {
                for fa in faces_a {
                    let ta = triangle(a, fa, None, Side::A)?;
                    for fb in faces_b.clone() {
                        let tb = triangle(b, fb, Some(b_to_a), Side::B)?;
                        if policy.triangles(fa, &ta, fb, &tb, &mut work) == Flow::Stop {
                            return Ok(work);
                        }
                    }
                }
                continue;
            }
            (NodeKind::Children(children), NodeKind::Faces(_)) => (Side::A, children),
            (NodeKind::Faces(_), NodeKind::Children(children)) => (Side::B, children),
            (NodeKind::Children(children_a), NodeKind::Children(children_b)) => {
                if rule.descend_a(&na.bv, &nb.bv) {
                    (Side::A, children_a)
                } else {
                    (Side::B, children_b)
                }
            }
        };
        let step = match side {
            Side::A => Step {
                tree: a,
                side,
                children,
                other_bv: &nb.bv,
                other: ib,
            },
            Side::B => Step {
                tree: b,
                side,
                children,
                other_bv: &na.bv,
                other: ia,
            },
        };
        dive = push_children(&step, b_to_a, policy, waiting, &mut work)?;
    }
    Ok(work)
}

/// One step of a traversal: `side`'s node is descended into its `children` (nodes of
/// `tree`), each paired with the other tree's node `other` (volume `other_bv`).
struct Step<'s, 't, B: BoundingVolume> {
    tree: &'s TreeView<'t, B>,
    side: Side,
    children: Range<u32>,
    other_bv: &'s B,
    other: u32,
}

impl<B: BoundingVolume> Step<'_, '_, B> {
    /// The pair of child `c` and the other node, with `key`.
    #[inline(always)]
    fn pair(&self, c: u32, key: f64) -> Pending {
        match self.side {
            Side::A => Pending::new(c, self.other, key),
            Side::B => Pending::new(self.other, c, key),
        }
    }

    /// Child `c`'s node record.
    #[inline(always)]
    fn child(&self, c: u32) -> Result<&Node<B>, QueryError> {
        self.tree
            .node(c)
            .ok_or_else(|| corrupt(self.side, NodeDefect::Missing))
    }

    /// The centre of the other node's volume, in A's frame (where B's are mapped).
    #[inline(always)]
    fn other_centre(&self, b_to_a: &Pose) -> Vector3<f64> {
        centre_in_a(self.other_bv, self.side == Side::A, b_to_a)
    }

    /// The centre of child `c`'s volume, in A's frame.
    #[inline(always)]
    fn child_centre(&self, c: u32, b_to_a: &Pose) -> Result<Vector3<f64>, QueryError> {
        Ok(centre_in_a(
            &self.child(c)?.bv,
            self.side == Side::B,
            b_to_a,
        ))
    }
}

/// The centre of `bv` in A's frame: mapped by `b_to_a` if it is one of B's volumes.
#[inline(always)]
fn centre_in_a<B: BoundingVolume>(bv: &B, of_b: bool, b_to_a: &Pose) -> Vector3<f64> {
    let c = Vector3::from(bv.center());
    if of_b {
        b_to_a.apply(&c)
    } else {
        c
    }
}

/// Puts the pairs of a step's two children (a binary tree's) on the stack nearer last, so
/// that the nearer is taken first: the distance between the volumes' centres, a cheap
/// guess at where contact is.
#[inline(always)]
fn push_nearest_last<B: BoundingVolume>(
    step: &Step<'_, '_, B>,
    b_to_a: &Pose,
    waiting: &mut impl Waiting,
) -> Result<(), QueryError> {
    let pair = |c: u32| step.pair(c, 0.0);
    let (first, second) = (step.children.start, step.children.start.wrapping_add(1));
    let other_centre = step.other_centre(b_to_a);
    let distance = |c: u32| -> Result<f64, QueryError> {
        Ok((step.child_centre(c, b_to_a)? - other_centre).norm_squared())
    };
    // (A NaN distance, from a damaged file, compares false: the first child first.)
    if distance(second)? < distance(first)? {
        waiting.put(pair(first));
        waiting.put(pair(second));
    } else {
        waiting.put(pair(second));
        waiting.put(pair(first));
    }
    Ok(())
}

/// Puts the pairs of a step's children with the other tree's node waiting, keyed now if
/// the policy is ordered; returns the child pair a dive continues with.
///
/// An ordered traversal continues with one child at once, the rest wait: a greedy dive
/// that reaches a triangle pair, and a first answer to prune with, in one step per level.
/// It takes the child of smaller rank ([`Policy::key_and_rank`]). A pair whose key is
/// refused is counted as a pruned pair and dropped rather than put waiting: the best
/// answer only improves, so it would be refused when taken too, and a heap push and pop
/// cost more than its key (bunny–fandisk, exact distance: a fifth of the pairs, with
/// `rel_err` 0.01 half).
#[inline(always)]
fn push_children<B: BoundingVolume, P: Policy<B>>(
    step: &Step<'_, '_, B>,
    b_to_a: &Pose,
    policy: &P,
    waiting: &mut impl Waiting,
    work: &mut Work,
) -> Result<Option<Pending>, QueryError> {
    // (Wider nodes, of the variable encoding, keep the order below.)
    if !P::ORDERED && policy.nearest_first() && step.children.len() == 2 {
        push_nearest_last(step, b_to_a, waiting)?;
        return Ok(None);
    }
    if !P::ORDERED {
        for c in step.children.clone() {
            waiting.put(step.pair(c, 0.0));
        }
        return Ok(None);
    }
    // The pair a dive continues with, and its rank.
    let mut dive: Option<(Pending, f64)> = None;
    for c in step.children.clone() {
        let child = step.child(c)?;
        let (key, rank) = match step.side {
            Side::A => policy.key_and_rank(&child.bv, step.other_bv, b_to_a),
            Side::B => policy.key_and_rank(step.other_bv, &child.bv, b_to_a),
        };
        let (key, rank) = (ordered_key(key), ordered_key(rank));
        if !policy.keep(key) {
            work.nodes_visited += 1;
            work.bv_disjoint += 1;
            continue;
        }
        let pair = step.pair(c, key);
        dive = match dive {
            Some((d, d_rank)) if d_rank <= rank => {
                waiting.put(pair);
                Some((d, d_rank))
            }
            Some((d, _)) => {
                waiting.put(d);
                Some((pair, rank))
            }
            None => Some((pair, rank)),
        };
    }
    Ok(dive.map(|(pair, _)| pair))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::build::{build, BuildOptions};
    use crate::generate::Rng;
    use crate::mesh::TriMesh;
    use crate::query::{DistanceOptions, PairQuery, SpanOptions};

    /// A heap of one or a few pairs sends nearly every pair of an ordered traversal to the
    /// overflow stack, taken first: the traversal must still end only where the smallest
    /// key of all is pruned, with the answers of the full heap.
    #[test]
    fn ordered_answers_do_not_depend_on_the_heap_size() {
        let path = concat!(env!("CARGO_MANIFEST_DIR"), "/assets/cow.obj");
        let cow = build(
            &TriMesh::load(path.as_ref()).unwrap(),
            &BuildOptions::default(),
            None,
        )
        .unwrap();
        let mut full = PairQuery::new(&cow, &cow).unwrap();
        let mut rng = Rng::new(11);
        let here = Pose::identity();
        for limit in [1, 2, 16] {
            let mut small =
                PairQuery::with_context(&cow, &cow, QueryContext::with_heap_limit(limit)).unwrap();
            for _ in 0..12 {
                // Apart by up to about the cow's size, some poses touching.
                let t = nalgebra::Vector3::from_fn(|_, _| 1.2 * rng.signed());
                let pose = Pose::new(rng.uniform_rotation(), t).unwrap();
                let exact = full
                    .distance(&here, &pose, &DistanceOptions::default())
                    .unwrap()
                    .distance();
                let mut got = |rel_err| {
                    let options = DistanceOptions {
                        rel_err,
                        ..Default::default()
                    };
                    small.distance(&here, &pose, &options).unwrap().distance()
                };
                assert_eq!(got(0.0), exact, "heap of {limit}");
                let within = got(0.05);
                assert!(
                    within >= exact && within <= exact * 1.05,
                    "heap of {limit}: {within} against {exact}"
                );
                let span = |q: &mut PairQuery<'_>| {
                    q.span(&here, &pose, &SpanOptions::default())
                        .unwrap()
                        .span()
                };
                assert_eq!(span(&mut small), span(&mut full), "heap of {limit}");
            }
        }
    }
}
