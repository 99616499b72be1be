//! Queries between two posed trees: collision, separation distance, span.
//!
//! Models are triangle soups, that is surfaces: two models collide when their surfaces
//! share a point, and the distance is 0 exactly then. A model wholly inside another does not
//! collide with it (as in RAPID, PQP and FCL). Poses are f64 whatever the stored precision;
//! triangle ids in every result are the input mesh's ids.
//!
//! [`PairQuery`] is the one way in: made once per pair of models, it answers collision
//! ([`PairQuery::collide`]), distance ([`PairQuery::distance`]), tolerance
//! ([`PairQuery::within`]) and span ([`PairQuery::span`]), each taking the two poses and
//! its options and returning its answer with the [`Work`] it did. [`batch`] answers many
//! poses of one pair in parallel. [`details`] holds the same queries as generic functions
//! over typed tree views.
//!
//! ```
//! use obbtree::format::ObbtFile;
//! use obbtree::query::{CollideOptions, PairQuery, Pose};
//!
//! let a = ObbtFile::open(concat!(env!("CARGO_MANIFEST_DIR"), "/assets/scenes/table.obbt"))?;
//! let b = ObbtFile::open(concat!(env!("CARGO_MANIFEST_DIR"), "/assets/scenes/cow.obbt"))?;
//! let mut pair = PairQuery::new(&a, &b)?;
//! let at = Pose::translation(0.1, 0.0, 0.0);
//! let result = pair.collide(&Pose::identity(), &at, &CollideOptions::default())?;
//! println!("{} contacts, {:?}", result.pairs.len(), result.work);
//! # Ok::<(), Box<dyn std::error::Error>>(())
//! ```

mod batch;
mod closest;
mod collide;
mod descent;
pub mod details;
mod distance;
mod engine;
mod hausdorff;
mod index;
mod order;
mod pair_query;
mod ray;
mod span;
pub mod triangle;
mod winding;
mod work;

pub use crate::pose::{ParsedPose, Pose, PoseError, PoseFormat, MAX_REPAIR, ORTHONORMAL_TOLERANCE};
pub use batch::{batch, on_threads, BatchError, BatchOptions, PoseBatch};
pub use closest::{closest_points, ClosestOptions, ClosestPoint, ClosestResult};
pub use collide::{BoxTest, CollideOptions, CollideResult, Contact};
pub use descent::DescentRule;
pub use distance::{
    DistanceOptions, DistanceResult, ToleranceOptions, ToleranceResult, WarmStart, Witness,
};
pub use engine::QueryContext;
pub use hausdorff::{
    hausdorff, HausdorffDirection, HausdorffOptions, HausdorffResult, HausdorffWarmStart,
};
pub use pair_query::PairQuery;
pub use ray::{all_ray_hits, cast_rays, Ray, RayHit, RayHits, RayMode, RayOptions, RayResult};
pub use span::{SpanOptions, SpanResult};
pub use winding::{
    signed_distances, winding_numbers, WindingAccuracy, WindingOptions, WindingResult,
};
pub use work::Work;

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
    /// The two trees store different volume types, precisions or layouts.
    #[error("the trees differ in kind: A stores {a}, B stores {b}; build both with the same --bv, --precision and --layout")]
    MismatchedTrees {
        /// What A stores, e.g. `obb f32` or `obb f32 compact`.
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
    /// One query of a batch (a ray, a point) is unusable.
    #[error("{what} {index}: {requirement}, got {value}")]
    BadInput {
        /// What it is: `ray`, `query point`.
        what: &'static str,
        /// Its index in the batch.
        index: usize,
        /// What it must be.
        requirement: &'static str,
        /// The offending value.
        value: f64,
    },
    /// A file's sections could not be viewed as a tree.
    #[error(transparent)]
    Format(#[from] crate::format::FormatError),
}

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

/// The error naming the first query point with a non-finite coordinate.
pub(crate) fn check_points(points: &[[f64; 3]]) -> Result<(), QueryError> {
    for (index, p) in points.iter().enumerate() {
        if let Some(bad) = p.iter().find(|x| !x.is_finite()) {
            return Err(QueryError::BadInput {
                what: "query point",
                index,
                requirement: "coordinates must be finite",
                value: *bad,
            });
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_corrupt_tree_is_named_by_its_side() {
        for (which, name) in [(Side::A, "A"), (Side::B, "B")] {
            let err = QueryError::CorruptTree {
                which,
                what: "a node is reachable along two paths",
            };
            assert_eq!(
                err.to_string(),
                format!("tree {name} is corrupt: a node is reachable along two paths (run `obbtree verify`)")
            );
        }
    }
}
