//! Whole-tree statistics: what a `.obbt` header records about its tree so that `info` reads
//! no section (`formats/obbt.md` §3).
//!
//! One set of types for everyone: the builder gathers a [`TreeShape`] leaf by leaf, the
//! writer stores a [`TreeStats`] in the header, the reader decodes it into
//! [`Info`](crate::format::Info), and `verify` recounts it from the sections and compares.
//! [`level_stats`] measures a tree's volumes level by level (`obbtree info --levels`).

// `verify` recounts these from untrusted files: on top of the crate's no-panic lints,
// integer arithmetic must be checked or saturating and narrowing casts must be `try_from`.
#![cfg_attr(
    not(test),
    deny(clippy::arithmetic_side_effects, clippy::cast_possible_truncation)
)]

use crate::arr3;
use crate::bv::BoundingVolume;
use crate::mesh::degenerate_count;
use crate::tree::{NodeDefect, NodeKind, TreeView};

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

/// The volumes of one level of a tree (the root is level 0): how many, and how thick, large
/// and wide they are. Thickness is the smallest width
/// ([`BoundingVolume::thickness`]); the dissertation's Fig. 5.17 shows OBB thickness
/// shrinking about 4× every two levels on smooth surfaces.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct LevelStats {
    /// Nodes on the level.
    pub nodes: u64,
    /// Mean and largest thickness, model units.
    pub thickness: (f64, f64),
    /// Mean and largest enclosed volume, cubic model units.
    pub volume: (f64, f64),
    /// Mean and largest diameter, model units.
    pub diameter: (f64, f64),
}

impl LevelStats {
    fn add(&mut self, bv: &impl BoundingVolume) {
        self.nodes = self.nodes.saturating_add(1);
        for (sum_max, x) in [
            (&mut self.thickness, bv.thickness()),
            (&mut self.volume, bv.volume()),
            (&mut self.diameter, bv.diameter()),
        ] {
            sum_max.0 += x;
            sum_max.1 = sum_max.1.max(x);
        }
    }

    /// Turns the sums gathered by `add` into means.
    fn finish(mut self) -> LevelStats {
        let n = self.nodes.max(1) as f64;
        for (sum, _) in [&mut self.thickness, &mut self.volume, &mut self.diameter] {
            *sum /= n;
        }
        self
    }
}

/// Every level of `tree` from the root down, measured ([`LevelStats`]). Walks each node
/// once; a damaged, unverified tree gives the defect of the first bad node met, or
/// [`NodeDefect::BadChildren`] if some node is reachable twice.
///
/// # Errors
///
/// On a damaged tree only (a verified one has none): [`NodeDefect::Missing`],
/// [`NodeDefect::BadChildren`] or [`NodeDefect::BadFaces`] for the first bad node met
/// ([`TreeView::node_kind`]), and [`NodeDefect::BadChildren`] for a node reachable twice.
pub fn level_stats<B: BoundingVolume>(
    tree: &TreeView<'_, B>,
) -> Result<Vec<LevelStats>, NodeDefect> {
    let mut levels = Vec::new();
    let mut level = vec![0u32];
    let mut next = Vec::new();
    let mut visited = 0usize;
    while !level.is_empty() {
        let mut stats = LevelStats::default();
        for &index in &level {
            visited = visited.saturating_add(1);
            // Children lie after their parents, so a well-formed tree visits each node
            // once; more visits mean shared children, which could grow without bound.
            if visited > tree.nodes().len() {
                return Err(NodeDefect::BadChildren);
            }
            let node = tree.node(index).ok_or(NodeDefect::Missing)?;
            stats.add(&node.bv);
            if let NodeKind::Children(children) = tree.node_kind(index)? {
                next.extend(children);
            }
        }
        levels.push(stats.finish());
        std::mem::swap(&mut level, &mut next);
        next.clear();
    }
    Ok(levels)
}
