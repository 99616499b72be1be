//! Queries between two posed trees: collision, separation distance, span.
//!
//! Models are triangle soups, that is surfaces: two models collide when their surfaces
//! share a point, and the distance is 0 exactly then. A model wholly inside another does not
//! collide with it (as in RAPID, PQP and FCL). Poses are f64 whatever the stored precision;
//! triangle ids in every result are the input mesh's ids.
//!
//! ```no_run
//! use obbtree::format::ObbtFile;
//! use obbtree::query::{collide_files, CollideOptions, Pose, QueryContext};
//!
//! let a = ObbtFile::open("bunny.obbt")?;
//! let b = ObbtFile::open("cow.obbt")?;
//! let mut context = QueryContext::new();
//! let result = collide_files(&a, &Pose::identity(), &b, &Pose::translation(0.1, 0.0, 0.0), &CollideOptions::default(), &mut context)?;
//! println!("{} contacts, {:?}", result.pairs.len(), result.stats);
//! # Ok::<(), Box<dyn std::error::Error>>(())
//! ```

mod collide;
mod descent;
mod distance;
mod engine;
mod pair_query;
mod span;
mod stats;
pub mod triangle;

pub use crate::pose::{ParsedPose, Pose, PoseError, PoseFormat, MAX_REPAIR, ORTHONORMAL_TOLERANCE};
pub use collide::{collide, collide_files, collide_into, BoxTest, CollideOptions, CollideResult};
pub use descent::DescentRule;
pub use distance::{
    distance, distance_below, distance_files, within_tolerance, within_tolerance_files,
    DistanceOptions, DistanceResult, ToleranceResult, Witness,
};
pub use engine::QueryContext;
pub use pair_query::PairQuery;
pub use span::{span, span_files, SpanResult};
pub use stats::Stats;

use crate::bv::{Aabb, BvKind, Obb, Sphere};
use crate::format::ObbtFile;
use crate::real::Precision;
use crate::tree::TreeView;

/// One of the two models of a pair query: A, in whose frame results are given, or B.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Side {
    /// The first model.
    A,
    /// The second model.
    B,
}

impl std::fmt::Display for Side {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(match self {
            Side::A => "A",
            Side::B => "B",
        })
    }
}

/// Why a query could not answer.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum QueryError {
    /// The two trees store different volume types or precisions.
    #[error("the trees differ in kind: A stores {a}, B stores {b}; build both with the same --bv and --precision")]
    MismatchedTrees {
        /// What A stores, e.g. `obb f32`.
        a: String,
        /// What B stores.
        b: String,
    },
    /// A tree's contents are inconsistent (an unverified, corrupt file).
    #[error("tree {which} is corrupt: {what} (run `obbtree verify`)")]
    CorruptTree {
        /// The model whose tree it is.
        which: Side,
        /// What was found.
        what: &'static str,
    },
    /// An option value is out of range.
    #[error("{name} must be {requirement}, got {value}")]
    BadOption {
        /// The option.
        name: &'static str,
        /// What it must be.
        requirement: &'static str,
        /// The value given.
        value: f64,
    },
    /// A view of a tree could not be made.
    #[error("{0}")]
    Format(String),
}

/// Typed views of two files of the same volume type and precision: the one place a pair
/// of files is dispatched on its header tags ([`ViewPair::of`]), and the one match that
/// runs generic code on it ([`on_views!`]). A [`PairQuery`] makes it once, since typing a
/// file's sections costs about 20 ns, a sixth of a query culled at the roots.
#[derive(Clone, Copy)]
pub(crate) enum ViewPair<'f> {
    // (Variants named for the volume type and precision both views have.)
    ObbF32(TreeView<'f, Obb<f32>>, TreeView<'f, Obb<f32>>),
    ObbF64(TreeView<'f, Obb<f64>>, TreeView<'f, Obb<f64>>),
    AabbF32(TreeView<'f, Aabb<f32>>, TreeView<'f, Aabb<f32>>),
    AabbF64(TreeView<'f, Aabb<f64>>, TreeView<'f, Aabb<f64>>),
    SphereF32(TreeView<'f, Sphere<f32>>, TreeView<'f, Sphere<f32>>),
    SphereF64(TreeView<'f, Sphere<f64>>, TreeView<'f, Sphere<f64>>),
}

impl<'f> ViewPair<'f> {
    /// The views of `a` and `b`; an error if they store different volume types or
    /// precisions, or a section cannot be viewed.
    pub(crate) fn of(a: &'f ObbtFile, b: &'f ObbtFile) -> Result<ViewPair<'f>, QueryError> {
        if (a.bv_kind(), a.precision()) != (b.bv_kind(), b.precision()) {
            return Err(QueryError::MismatchedTrees {
                a: format!("{} {}", a.bv_kind().name(), a.precision().name()),
                b: format!("{} {}", b.bv_kind().name(), b.precision().name()),
            });
        }
        let fmt = |e: crate::format::FormatError| QueryError::Format(e.to_string());
        Ok(match (a.bv_kind(), a.precision()) {
            (BvKind::Obb, Precision::F32) => {
                ViewPair::ObbF32(a.view().map_err(fmt)?, b.view().map_err(fmt)?)
            }
            (BvKind::Obb, Precision::F64) => {
                ViewPair::ObbF64(a.view().map_err(fmt)?, b.view().map_err(fmt)?)
            }
            (BvKind::Aabb, Precision::F32) => {
                ViewPair::AabbF32(a.view().map_err(fmt)?, b.view().map_err(fmt)?)
            }
            (BvKind::Aabb, Precision::F64) => {
                ViewPair::AabbF64(a.view().map_err(fmt)?, b.view().map_err(fmt)?)
            }
            (BvKind::Sphere, Precision::F32) => {
                ViewPair::SphereF32(a.view().map_err(fmt)?, b.view().map_err(fmt)?)
            }
            (BvKind::Sphere, Precision::F64) => {
                ViewPair::SphereF64(a.view().map_err(fmt)?, b.view().map_err(fmt)?)
            }
        })
    }
}

impl std::fmt::Debug for ViewPair<'_> {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        on_views!(self, |va, vb| f
            .debug_struct("ViewPair")
            .field("a_nodes", &va.nodes().len())
            .field("b_nodes", &vb.nodes().len())
            .finish())
    }
}

/// Runs `$body` with `$va`, `$vb` bound to the typed views of a [`ViewPair`].
macro_rules! on_views {
    ($pair:expr, |$va:ident, $vb:ident| $body:expr) => {{
        use $crate::query::ViewPair;
        match $pair {
            ViewPair::ObbF32($va, $vb) => $body,
            ViewPair::ObbF64($va, $vb) => $body,
            ViewPair::AabbF32($va, $vb) => $body,
            ViewPair::AabbF64($va, $vb) => $body,
            ViewPair::SphereF32($va, $vb) => $body,
            ViewPair::SphereF64($va, $vb) => $body,
        }
    }};
}
pub(crate) use on_views;

/// Runs `$body` with `$va`, `$vb` bound to typed views of two files of the same volume type
/// and precision ([`ViewPair::of`], then [`on_views!`]).
macro_rules! with_views {
    ($a:expr, $b:expr, |$va:ident, $vb:ident| $body:expr) => {{
        $crate::query::on_views!($crate::query::ViewPair::of($a, $b)?, |$va, $vb| $body)
    }};
}
pub(crate) use with_views;

/// The input-mesh id of leaf-ordered face `face`.
pub(crate) fn source_id<B: crate::bv::BoundingVolume>(
    tree: &crate::tree::TreeView<'_, B>,
    face: u32,
    which: Side,
) -> Result<u32, QueryError> {
    tree.source_id(face).ok_or(QueryError::CorruptTree {
        which,
        what: "face index out of bounds",
    })
}
