//! From drafts to the final arrays: choose the encoding from the tree's shape.

use super::topdown::DraftTree;
use super::BuiltTree;
use crate::bv::BoundingVolume;
use crate::placement::Placement;
use crate::stats::TreeStats;
use crate::tree::Encoding;

/// The finished arrays of a built tree, with its header statistics.
pub(crate) fn finish<B: BoundingVolume>(
    draft: DraftTree<B>,
    vertices: Vec<[B::Real; 3]>,
    stats: TreeStats,
    placement: Placement,
) -> BuiltTree<B> {
    let shape = stats.shape;
    let node_count = draft.node_count();
    // Every internal node has two children, so single-face leaves make a binary tree.
    // (An empty mesh is one leaf of no faces, which only the variable encoding holds.)
    let encoding = if shape.max_leaf_faces == 1 {
        Encoding::Binary
    } else {
        Encoding::Variable
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
