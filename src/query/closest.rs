//! The closest point of one posed model to query points: a descent of the model's surface
//! index ([`super::index`]), pruned by each box's distance to the point.

use super::index::SurfaceIndex;
use super::triangle::Feature;
use super::{check_points, QueryError, Side, Work};
use crate::bv::BoundingVolume;
use crate::format::{ObbtFile, TreeVisitor};
use crate::pose::Pose;
use crate::tree::TreeView;
use nalgebra::Vector3;
use rayon::prelude::*;
use std::collections::BinaryHeap;

/// How a closest-point query is asked.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ClosestOptions {
    /// Only points of the model nearer than this count (world units, `> 0`, may be
    /// infinite): a point farther from the whole model gets no answer, sooner.
    pub max_distance: f64,
}

impl Default for ClosestOptions {
    fn default() -> Self {
        ClosestOptions {
            max_distance: f64::INFINITY,
        }
    }
}

/// The closest point of a model to a query point.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ClosestPoint {
    /// Distance from the query point (world units).
    pub distance: f64,
    /// The closest point of the model's surface, world frame.
    pub point: [f64; 3],
    /// Its triangle, as an input-mesh triangle id.
    pub triangle: u32,
    /// Where on that triangle it lies (corners and edges in the input's vertex order).
    pub feature: Feature,
}

/// The answer for one query point.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ClosestResult {
    /// The closest point; `None` when the model is at least
    /// [`ClosestOptions::max_distance`] away.
    pub closest: Option<ClosestPoint>,
    /// Work done: D and I count volumes pruned and kept, S and K triangles tested (K those
    /// the point lies on).
    pub work: Work,
}

impl ClosestResult {
    /// The distance, infinite without an answer.
    pub fn distance(&self) -> f64 {
        self.closest.map_or(f64::INFINITY, |c| c.distance)
    }
}

/// The closest point of `model`, posed by `pose` (model frame to world), to each of
/// `points` (world frame), computed in parallel.
///
/// Each point's search starts from the triangle found for the point before it (within
/// fixed runs of points, so that the answers do not depend on the thread count): give
/// coherent points (a scan line, a sweep, a sorted cloud) in order and they cost less.
/// Where two triangles are equally near, which one is named may depend on that order; the
/// distance does not.
///
/// # Errors
///
/// - [`QueryError::BadInput`] for a query point with a non-finite coordinate, or one
///   beyond [`MAX_COORDINATE`](super::MAX_COORDINATE) in the model's frame ("query
///   point"), or a model triangle beyond it ("model triangle");
///   [`QueryError::BadOption`] for a `max_distance` that is not greater than 0.
/// - [`QueryError::CorruptTree`] or [`QueryError::Format`] for a damaged, unverified file.
///
/// # Examples
///
/// ```
/// use obbtree::format::ObbtFile;
/// use obbtree::query::{closest_points, ClosestOptions, Pose};
///
/// let table = ObbtFile::open(concat!(env!("CARGO_MANIFEST_DIR"), "/assets/scenes/table.obbt"))?;
/// let above = [[0.0, 0.0, 5.0], [0.1, 0.2, 3.0]];
/// let answers = closest_points(&table, &Pose::identity(), &above, &ClosestOptions::default())?;
/// for (p, answer) in above.iter().zip(&answers) {
///     let c = answer.closest.expect("no max_distance: always an answer");
///     println!("{p:?}: triangle {} at {:.3} ({})", c.triangle, c.distance, c.feature.name());
/// }
/// # Ok::<(), Box<dyn std::error::Error>>(())
/// ```
pub fn closest_points(
    model: &ObbtFile,
    pose: &Pose,
    points: &[[f64; 3]],
    options: &ClosestOptions,
) -> Result<Vec<ClosestResult>, QueryError> {
    super::require_positive("max_distance", options.max_distance)?;
    check_points(points, &Pose::relative(pose, &Pose::identity()))?;
    /// The typed descent, run for every point.
    struct Visit<'q> {
        model: &'q ObbtFile,
        pose: &'q Pose,
        points: &'q [[f64; 3]],
        options: &'q ClosestOptions,
    }
    impl TreeVisitor for Visit<'_> {
        type Output = Result<Vec<ClosestResult>, QueryError>;
        fn visit<B: BoundingVolume>(self, tree: TreeView<'_, B>) -> Self::Output {
            // World to model: the world frame posed in the model's.
            let to_model = Pose::relative(self.pose, &Pose::identity());
            let index = self.model.derived(|| SurfaceIndex::build(&tree))?;
            index.check_reach(&tree, Side::A, "model triangle")?;
            // Runs of points in input order, each point's descent seeded with the triangle
            // its predecessor in the run found: fixed runs keep the answers independent of
            // the thread count. One heap per worker, reused point after point.
            let runs: Vec<Vec<ClosestResult>> = self
                .points
                .par_chunks(WARM_RUN)
                .map_init(BinaryHeap::new, |heap, run| {
                    let mut seed = None;
                    run.iter()
                        .map(|p| {
                            let local = to_model.apply(&Vector3::from(*p));
                            let found = index.nearest(
                                &tree,
                                &local,
                                self.options.max_distance,
                                seed,
                                heap,
                            )?;
                            seed = found.best.as_ref().map(|best| best.face);
                            Ok(ClosestResult {
                                closest: found.best.map(|best| ClosestPoint {
                                    distance: found.distance,
                                    point: self.pose.apply(&best.point).into(),
                                    triangle: best.id,
                                    feature: best.feature,
                                }),
                                work: found.work,
                            })
                        })
                        .collect()
                })
                .collect::<Result<_, QueryError>>()?;
            Ok(runs.into_iter().flatten().collect())
        }
    }
    model.visit(Visit {
        model,
        pose,
        points,
        options,
    })?
}

/// Points per run of [`closest_points`]: each point's descent starts from the answer of
/// the point before it in its run. Long enough that the seeding pays, short enough for
/// every thread to get runs of a large batch.
pub(super) const WARM_RUN: usize = 256;
