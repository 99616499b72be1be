//! Whole-tree statistics: what a `.obbt` header records about its tree so that `info` reads
//! no section (`formats/obbt.md` §3).
//!
//! One set of types for everyone: the builder gathers a [`TreeShape`] leaf by leaf, the
//! writer stores a [`TreeStats`] in the header, the reader decodes it into
//! [`Info`](crate::format::Info), and `verify` recounts it from the sections and compares.

// `verify` recounts these from untrusted files: on top of the crate's no-panic lints,
// integer arithmetic must be checked or saturating and narrowing casts must be `try_from`.
#![cfg_attr(
    not(test),
    deny(clippy::arithmetic_side_effects, clippy::cast_possible_truncation)
)]

use crate::arr3;
use crate::mesh::degenerate_count;

/// How a tree's faces sit in its leaves.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct TreeShape {
    /// Number of leaf nodes.
    pub leaves: u32,
    /// Nodes on the longest root-to-leaf path (a lone root has depth 1).
    pub depth: u32,
    /// Most faces in one leaf.
    pub max_leaf_faces: u32,
}

impl TreeShape {
    /// Counts a leaf of `faces` triangles at `depth` (the root at 1).
    pub(crate) fn leaf(&mut self, depth: u32, faces: u32) {
        // Saturating only for damaged files: a tree has fewer than `u32::MAX` nodes.
        self.leaves = self.leaves.saturating_add(1);
        self.depth = self.depth.max(depth);
        self.max_leaf_faces = self.max_leaf_faces.max(faces);
    }

    /// A parent over subtrees of these shapes.
    pub(crate) fn parent(left: TreeShape, right: TreeShape) -> TreeShape {
        TreeShape {
            leaves: left.leaves.saturating_add(right.leaves),
            depth: left.depth.max(right.depth).saturating_add(1),
            max_leaf_faces: left.max_leaf_faces.max(right.max_leaf_faces),
        }
    }
}

/// Everything the header records about a tree beyond its counts: its shape, and two facts
/// about its stored vertices that tools want without reading them.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct TreeStats {
    /// Leaves, depth and the largest leaf.
    pub shape: TreeShape,
    /// Triangles of zero area as stored (exactly zero cross product of the stored corners).
    pub degenerate_triangles: u32,
    /// Componentwise minimum of all stored vertices, stored units (see
    /// [`Placement`](crate::placement::Placement)).
    pub bounds_min: [f64; 3],
    /// Componentwise maximum of all stored vertices, stored units.
    pub bounds_max: [f64; 3],
}

impl TreeStats {
    /// The statistics of a tree of `shape` over `positions` (the stored vertices, widened to
    /// f64) and `faces` (in any order; every index below `positions.len()`).
    pub(crate) fn new(shape: TreeShape, positions: &[[f64; 3]], faces: &[[u32; 3]]) -> TreeStats {
        let (bounds_min, bounds_max) = arr3::bounds(positions);
        TreeStats {
            shape,
            // At most `u32::MAX` faces fit a file, so the count never saturates.
            degenerate_triangles: u32::try_from(degenerate_count(positions, faces))
                .unwrap_or(u32::MAX),
            bounds_min,
            bounds_max,
        }
    }
}
