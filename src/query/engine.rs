//! The one traversal loop behind every query: an iterative tandem descent of two trees
//! (dissertation Figure 7.9, "any query"), with the query kind plugged in as a policy.
//!
//! No recursion and no allocation per test: pairs wait on an explicit stack owned by a
//! [`QueryContext`] and reused across queries. Every node access goes through the checked
//! accessors of [`TreeView`], so a corrupt, unverified tree ends in an error, not a panic,
//! and children must follow their parents, so every traversal terminates.

use super::descent::DescentRule;
use super::stats::Stats;
use super::triangle::Triangle;
use super::QueryError;
use crate::bv::pair::Transform;
use crate::bv::BoundingVolume;
use crate::tree::TreeView;
use nalgebra::Vector3;

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
    fn key(&self, a: &B, b: &B, xf: &Transform) -> f64;
    /// Whether a pair with this key still matters (checked when it is taken off the stack,
    /// since the best answer may have improved since it was pushed).
    fn keep(&self, key: f64) -> bool;
    /// Tests one triangle pair (A's triangle in A's frame, B's mapped into it).
    /// `face_a` / `face_b` are leaf-ordered face indices.
    fn triangles(
        &mut self,
        face_a: u32,
        a: &Triangle,
        face_b: u32,
        b: &Triangle,
        stats: &mut Stats,
    ) -> Flow;
}

/// A node pair waiting on the stack, with the key computed when it was pushed.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Pending {
    a: u32,
    b: u32,
    key: f64,
}

/// Reusable scratch of the traversal: keep one per thread and pass it to every query to
/// avoid allocating.
#[derive(Debug, Default)]
pub struct QueryContext {
    pub(crate) stack: Vec<Pending>,
    /// Contacting leaf-ordered face pairs of the running collision query.
    pub(crate) faces: Vec<(u32, u32)>,
}

impl QueryContext {
    /// An empty context; its buffers grow to the largest traversal seen and stay.
    pub fn new() -> QueryContext {
        QueryContext::default()
    }
}

/// Reads triangle `face` of `tree`, mapped by `xf` (identity for A).
#[inline]
fn triangle<B: BoundingVolume>(
    tree: &TreeView<'_, B>,
    face: u32,
    xf: Option<&Transform>,
    which: char,
) -> Result<Triangle, QueryError> {
    let t = tree.triangle(face).ok_or(QueryError::CorruptTree {
        which,
        what: "face or vertex index out of bounds",
    })?;
    let v = t.map(Vector3::from);
    Ok(match xf {
        Some(xf) => v.map(|p| xf.apply(&p)),
        None => v,
    })
}

/// Runs the tandem traversal of `a` and `b` (B mapped into A's frame by `xf`).
pub(crate) fn traverse<B: BoundingVolume, P: Policy<B>>(
    a: &TreeView<'_, B>,
    b: &TreeView<'_, B>,
    xf: &Transform,
    rule: DescentRule,
    policy: &mut P,
    context: &mut QueryContext,
) -> Result<Stats, QueryError> {
    let mut stats = Stats::default();
    let corrupt = |which, what| QueryError::CorruptTree { which, what };
    let (Some(root_a), Some(root_b)) = (a.node(0), b.node(0)) else {
        return Err(corrupt('A', "no root node"));
    };
    // A tree visits each node pair at most once; more means shared children (a corrupt,
    // unverified file), which could otherwise take exponential time.
    let limit = (a.nodes().len() as u64).saturating_mul(b.nodes().len() as u64);
    let stack = &mut context.stack;
    stack.clear();
    stack.push(Pending {
        a: 0,
        b: 0,
        key: policy.key(&root_a.bv, &root_b.bv, xf),
    });
    while let Some(Pending { a: ia, b: ib, key }) = stack.pop() {
        stats.nodes_visited += 1;
        if stats.nodes_visited > limit {
            return Err(corrupt('A', "a node is reachable along two paths"));
        }
        if !policy.keep(key) {
            stats.bv_disjoint += 1;
            continue;
        }
        stats.bv_overlap += 1;
        let na = a.node(ia).ok_or(corrupt('A', "node index out of bounds"))?;
        let nb = b.node(ib).ok_or(corrupt('B', "node index out of bounds"))?;
        let children_a = a.children(ia);
        let children_b = b.children(ib);
        let descend_a = match (&children_a, &children_b) {
            (None, None) => {
                let faces_a = a
                    .leaf_faces(ia)
                    .ok_or(corrupt('A', "leaf face range out of bounds"))?;
                let faces_b = b
                    .leaf_faces(ib)
                    .ok_or(corrupt('B', "leaf face range out of bounds"))?;
                for fa in faces_a {
                    let ta = triangle(a, fa, None, 'A')?;
                    for fb in faces_b.clone() {
                        let tb = triangle(b, fb, Some(xf), 'B')?;
                        if policy.triangles(fa, &ta, fb, &tb, &mut stats) == Flow::Stop {
                            return Ok(stats);
                        }
                    }
                }
                continue;
            }
            (Some(_), None) => true,
            (None, Some(_)) => false,
            (Some(_), Some(_)) => rule.descend_a(&na.bv, &nb.bv),
        };
        // Children of an internal node that `children` refused (out of bounds, or not after
        // the parent) are a corrupt tree, not a leaf.
        if children_a.is_none() && a.leaf_faces(ia).is_none() {
            return Err(corrupt('A', "child reference out of bounds or backwards"));
        }
        if children_b.is_none() && b.leaf_faces(ib).is_none() {
            return Err(corrupt('B', "child reference out of bounds or backwards"));
        }
        let start = stack.len();
        if descend_a {
            for c in children_a.into_iter().flatten() {
                let child = a.node(c).ok_or(corrupt('A', "child index out of bounds"))?;
                stack.push(Pending {
                    a: c,
                    b: ib,
                    key: policy.key(&child.bv, &nb.bv, xf),
                });
            }
        } else {
            for c in children_b.into_iter().flatten() {
                let child = b.node(c).ok_or(corrupt('B', "child index out of bounds"))?;
                stack.push(Pending {
                    a: ia,
                    b: c,
                    key: policy.key(&na.bv, &child.bv, xf),
                });
            }
        }
        if P::ORDERED {
            // Most promising last, so it is popped first.
            if let Some(tail) = stack.get_mut(start..) {
                sort_descending(tail);
            }
        }
    }
    Ok(stats)
}

/// Sorts pending pairs by decreasing key, stably. Children counts are small (2 in binary
/// trees), so an insertion sort is cheapest.
#[inline(always)]
// why: `j - 1` and `j` lie in `0..tail.len()` (`1 <= j <= i < tail.len()`).
#[allow(clippy::indexing_slicing)]
fn sort_descending(tail: &mut [Pending]) {
    for i in 1..tail.len() {
        let mut j = i;
        while j > 0 && tail[j - 1].key < tail[j].key {
            tail.swap(j - 1, j);
            j -= 1;
        }
    }
}
