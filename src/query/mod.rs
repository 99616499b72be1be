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
mod quad;
mod ray;
mod span;
pub mod triangle;
mod winding;
mod work;

pub use crate::pose::{
    ParsedPose, Pose, PoseError, PoseFormat, Repairs, MAX_REPAIR, ORTHONORMAL_TOLERANCE,
};
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
    #[error("{name} must be {requirement}, got {}", shown(*value))]
    BadOption {
        /// The option.
        name: &'static str,
        /// What it must be.
        requirement: &'static str,
        /// The value given.
        value: f64,
    },
    /// One query of a batch (a ray, a point) is unusable.
    #[error("{what} {index}: {requirement}, got {}", shown(*value))]
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

/// `Ok` if option `name`'s `value` is greater than 0, else the [`QueryError::BadOption`]
/// that says so (NaN fails too).
pub(crate) fn require_positive(name: &'static str, value: f64) -> Result<(), QueryError> {
    if value.partial_cmp(&0.0) == Some(std::cmp::Ordering::Greater) {
        return Ok(());
    }
    Err(QueryError::BadOption {
        name,
        requirement: "greater than 0",
        value,
    })
}

/// `value` as an error message shows it: as Rust prints it, or in scientific notation
/// where that would be a long run of digits.
fn shown(value: f64) -> String {
    if value == 0.0 || !value.is_finite() || (1e-5..1e16).contains(&value.abs()) {
        value.to_string()
    } else {
        format!("{value:e}")
    }
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

/// The largest magnitude of a coordinate, in the frame of the model measured, that closest
/// points, winding numbers, signed distances and Hausdorff distances accept: of the query
/// points, of the measured model's own triangles, and of the other model's vertices posed
/// in that frame. They compare squared distances, which beyond it could overflow. Rays,
/// collision, distance, tolerance and span take any finite coordinates.
pub const MAX_COORDINATE: f64 = 1e150;

/// What [`QueryError::BadInput`] requires of a coordinate beyond [`MAX_COORDINATE`].
pub(crate) const WITHIN_REACH: &str = "coordinates must be within ±1e150 in the model's frame";

/// The error naming the first query point with a non-finite coordinate, or one beyond
/// [`MAX_COORDINATE`] once `to_model` maps it into the model's frame.
pub(crate) fn check_points(points: &[[f64; 3]], to_model: &Pose) -> Result<(), QueryError> {
    let bad = |index, requirement, value| QueryError::BadInput {
        what: "query point",
        index,
        requirement,
        value,
    };
    for (index, p) in points.iter().enumerate() {
        if let Some(x) = p.iter().find(|x| !x.is_finite()) {
            return Err(bad(index, "coordinates must be finite", *x));
        }
    }
    let posed = points
        .iter()
        .map(|p| to_model.apply(&(*p).into()))
        .enumerate();
    check_reach("query point", WITHIN_REACH, posed)
}

/// Whether a coordinate's magnitude `x` is at most [`MAX_COORDINATE`] (NaN is not).
pub(crate) fn within_reach(x: f64) -> bool {
    x.abs() <= MAX_COORDINATE
}

/// The error naming the first of `points` (each with its index; model frame) with a
/// coordinate beyond [`MAX_COORDINATE`] as `what` and its index.
pub(crate) fn check_reach(
    what: &'static str,
    requirement: &'static str,
    points: impl IntoIterator<Item = (usize, nalgebra::Vector3<f64>)>,
) -> Result<(), QueryError> {
    match points.into_iter().find(|(_, p)| !within_reach(p.amax())) {
        Some((index, p)) => Err(QueryError::BadInput {
            what,
            index,
            requirement,
            value: p.amax(),
        }),
        None => Ok(()),
    }
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

    /// An option must be greater than 0: zero, negatives and NaN are refused by name, and
    /// the value is shown as Rust prints it unless that is a long run of digits.
    #[test]
    fn options_are_refused_with_their_value_shown_readably() {
        assert_eq!(require_positive("rel_err", 0.5), Ok(()));
        for (value, text) in [
            (0.0, "0"),
            (-2.5, "-2.5"),
            (f64::NAN, "NaN"),
            (f64::NEG_INFINITY, "-inf"),
            (-1e-7, "-1e-7"),
            (-3e20, "-3e20"),
        ] {
            let err = require_positive("rel_err", value).expect_err("refused");
            assert_eq!(
                err.to_string(),
                format!("rel_err must be greater than 0, got {text}")
            );
        }
        for (value, text) in [
            (1e-5, "0.00001"),
            (2.5e15, "2500000000000000"),
            (f64::INFINITY, "inf"),
        ] {
            assert_eq!(shown(value), text);
        }
    }

    /// Query points must be finite and, once posed in the model's frame, within
    /// [`MAX_COORDINATE`]: the first bad one is named by its index and coordinate.
    #[test]
    fn query_points_are_checked_in_the_models_frame() {
        assert!(within_reach(MAX_COORDINATE) && within_reach(-MAX_COORDINATE));
        assert!(!within_reach(2.0 * MAX_COORDINATE) && !within_reach(f64::NAN));
        let near = [[0.0, 1.0, 2.0], [0.0, 0.0, 1e149]];
        assert_eq!(check_points(&near, &Pose::identity()), Ok(()));
        let not_finite = [[0.0; 3], [0.0, f64::NAN, 1.0]];
        let err = check_points(&not_finite, &Pose::identity()).expect_err("NaN");
        assert_eq!(
            err.to_string(),
            "query point 1: coordinates must be finite, got NaN"
        );
        let moved = Pose::new(
            nalgebra::Matrix3::identity(),
            nalgebra::Vector3::new(0.0, 0.0, 9.5e149),
        )
        .expect("a pose");
        let err = check_points(&near, &moved).expect_err("beyond reach once posed");
        assert_eq!(
            err,
            QueryError::BadInput {
                what: "query point",
                index: 1,
                requirement: WITHIN_REACH,
                value: 1e149 + 9.5e149,
            }
        );
    }
}
