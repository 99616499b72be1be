//! From drafts to the final arrays: choose the encoding from the tree's shape, pack every
//! reference, and gather the statistics that `info` reads from the header.

use super::topdown::DraftTree;
use super::BuiltTree;
use crate::arr3;
use crate::bv::BoundingVolume;
use crate::mesh::triangle_is_degenerate;
use crate::placement::Placement;
use crate::tree::{Encoding, NodeRef};

/// Whole-tree statistics, computed once at build time and stored in the file header so that
/// `info` never reads the sections.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct TreeStats {
    /// Number of leaf nodes.
    pub leaves: u32,
    /// Nodes on the longest root-to-leaf path (a lone root has depth 1).
    pub depth: u32,
    /// Most faces in one leaf.
    pub max_leaf_faces: u32,
    /// Triangles of zero area as stored (exactly zero cross product of the stored corners).
    pub degenerate_triangles: u32,
    /// Componentwise minimum of all stored vertices, stored units (see [`Placement`]).
    pub bounds_min: [f64; 3],
    /// Componentwise maximum of all stored vertices, stored units.
    pub bounds_max: [f64; 3],
}

impl TreeStats {
    /// Statistics of a node array whose children always follow their parent; also says
    /// whether the tree is binary with single-face leaves. Returns `None` if a reference
    /// points outside the arrays or backwards.
    pub(crate) fn of_nodes(
        refs: impl Iterator<Item = NodeRef>,
        node_count: usize,
    ) -> Option<(TreeStats, bool)> {
        let mut depth = vec![0u32; node_count];
        let mut stats = TreeStats::default();
        let mut binary = true;
        for (i, r) in refs.enumerate() {
            let d = if i == 0 { 1 } else { *depth.get(i)? };
            if d == 0 {
                return None; // never referenced by a parent: not a tree
            }
            stats.depth = stats.depth.max(d);
            match r {
                NodeRef::Internal { first, count } => {
                    binary &= count == 2;
                    let range = r.range();
                    if first as usize <= i || range.end > node_count as u64 {
                        return None;
                    }
                    for child in range {
                        let slot = depth.get_mut(child as usize)?;
                        if *slot != 0 {
                            return None; // two parents
                        }
                        *slot = d + 1;
                    }
                    let _ = first;
                }
                NodeRef::Leaf { count, .. } => {
                    binary &= count == 1;
                    stats.leaves += 1;
                    stats.max_leaf_faces = stats.max_leaf_faces.max(count);
                }
            }
        }
        Some((stats, binary))
    }
}

/// The finished arrays and header statistics of a built tree. `degenerate_triangles` and
/// the vertex `bounds` do not depend on the tree, so the caller finds them while the tree
/// is being built.
pub(crate) fn finish<B: BoundingVolume>(
    draft: DraftTree<B>,
    vertices: Vec<[B::Real; 3]>,
    degenerate_triangles: u32,
    (bounds_min, bounds_max): ([f64; 3], [f64; 3]),
    placement: Placement,
) -> BuiltTree<B> {
    let shape = draft.shape;
    let node_count = draft.node_count();
    // Every internal node has two children, so single-face leaves make a binary tree.
    // (An empty mesh is one leaf of no faces, which only the variable encoding holds.)
    let encoding = if shape.max_leaf_faces == 1 {
        Encoding::Binary
    } else {
        Encoding::Variable
    };
    let stats = TreeStats {
        leaves: shape.leaves,
        depth: shape.depth,
        max_leaf_faces: shape.max_leaf_faces,
        degenerate_triangles,
        bounds_min,
        bounds_max,
    };
    BuiltTree {
        vertices,
        faces: draft.faces,
        source_ids: draft.source_ids,
        node_count,
        nodes: draft.pieces,
        encoding,
        stats,
        placement,
    }
}

/// Number of triangles of zero area (exactly zero cross product of their corners).
pub(crate) fn degenerate_count(positions: &[[f64; 3]], faces: &[[u32; 3]]) -> u32 {
    faces
        .iter()
        .filter(|f| {
            let [p, q, r] = arr3::map(**f, |v| {
                positions.get(v as usize).copied().unwrap_or_default()
            });
            triangle_is_degenerate(p, q, r)
        })
        .count() as u32
}

/// Componentwise extremes of `points` (zeros for none).
pub(crate) fn bounds(points: &[[f64; 3]]) -> ([f64; 3], [f64; 3]) {
    let mut lo = [f64::INFINITY; 3];
    let mut hi = [f64::NEG_INFINITY; 3];
    for p in points {
        lo = arr3::min(lo, *p);
        hi = arr3::max(hi, *p);
    }
    if points.is_empty() {
        return ([0.0; 3], [0.0; 3]);
    }
    (lo, hi)
}
