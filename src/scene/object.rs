//! A scene's object: a named, grouped, posed use of a shared tree, and its world box for
//! the broad phase.

use super::broad::Bounds;
use crate::bv::BoundingVolume;
use crate::format::{ObbtFile, TreeVisitor};
use crate::query::Pose;
use crate::tree::TreeView;
use std::sync::Arc;

/// One object of a scene: a name, the tree it uses (shared with other objects of the same
/// asset), its groups and its current pose.
#[derive(Clone, Debug)]
pub struct SceneObject {
    /// Unique name, `[A-Za-z0-9_.-]+`.
    pub name: String,
    /// Groups it belongs to (same characters).
    pub groups: Vec<String>,
    /// Its tree.
    pub asset: Arc<ObbtFile>,
    /// Where it is now.
    pub pose: Pose,
}

/// The world box of a tree's root volume under a pose.
pub(super) struct RootBounds<'p>(&'p Pose);

impl TreeVisitor for RootBounds<'_> {
    type Output = Option<Bounds>;
    fn visit<B: BoundingVolume>(self, tree: TreeView<'_, B>) -> Option<Bounds> {
        let root = tree.node(0)?;
        let b = root.bv.world_aabb(self.0);
        Some([b.min, b.max])
    }
}

/// An object's world box, inflated by `margin` on every side; an empty box far away for an
/// object whose tree has no root (a damaged file: it can then meet nothing).
pub(super) fn inflated_bounds(object: Option<&SceneObject>, margin: Option<f64>) -> Bounds {
    let far = [[f64::INFINITY; 3], [f64::INFINITY; 3]];
    let Some(object) = object else { return far };
    let Ok(Some(b)) = object.asset.visit(RootBounds(&object.pose)) else {
        return far;
    };
    let m = margin.unwrap_or(0.0);
    [b[0].map(|v| v - m), b[1].map(|v| v + m)]
}
