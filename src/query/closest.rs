//! The closest point of one posed model to query points: a best-first descent of one tree,
//! pruned by each volume's lower bound on its distance to the point.

use super::engine::{corrupt, triangle};
use super::triangle::{closest_point_on_triangle, Feature};
use super::{check_points, source_id, QueryError, Side, Work};
use crate::bv::BoundingVolume;
use crate::format::{ObbtFile, TreeVisitor};
use crate::pose::Pose;
use crate::tree::{NodeDefect, NodeKind, TreeView};
use nalgebra::Vector3;
use rayon::prelude::*;
use std::cmp::Ordering;
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
/// - [`QueryError::BadInput`] for a query point with a non-finite coordinate,
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
    // (NaN fails too.)
    if options.max_distance.partial_cmp(&0.0) != Some(Ordering::Greater) {
        return Err(QueryError::BadOption {
            name: "max_distance",
            requirement: "greater than 0",
            value: options.max_distance,
        });
    }
    check_points(points)?;
    /// The typed descent, run for every point.
    struct Visit<'q> {
        pose: &'q Pose,
        points: &'q [[f64; 3]],
        options: &'q ClosestOptions,
    }
    impl TreeVisitor for Visit<'_> {
        type Output = Result<Vec<ClosestResult>, QueryError>;
        fn visit<B: BoundingVolume>(self, tree: TreeView<'_, B>) -> Self::Output {
            // World to model: the world frame posed in the model's.
            let to_model = Pose::relative(self.pose, &Pose::identity());
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
                            let found =
                                descend(&tree, &local, self.options.max_distance, seed, heap)?;
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
        pose,
        points,
        options,
    })?
}

/// A node waiting, by its lower bound (smallest first in a max-heap).
#[derive(Clone, Copy, Debug, PartialEq)]
pub(super) struct Waiting {
    bound: f64,
    node: u32,
}

impl Eq for Waiting {}

impl PartialOrd for Waiting {
    fn partial_cmp(&self, other: &Self) -> Option<Ordering> {
        Some(self.cmp(other))
    }
}

impl Ord for Waiting {
    fn cmp(&self, other: &Self) -> Ordering {
        other.bound.total_cmp(&self.bound)
    }
}

/// Points per run of [`closest_points`]: each point's descent starts from the answer of
/// the point before it in its run. Long enough that the seeding pays, short enough for
/// every thread to get runs of a large batch.
pub(super) const WARM_RUN: usize = 256;

/// The best triangle of a descent: its face in the tree, its input id, the closest point
/// (model frame) and its feature.
pub(super) struct Best {
    pub(super) face: u32,
    pub(super) id: u32,
    pub(super) point: Vector3<f64>,
    pub(super) feature: Feature,
}

/// What one descent found: the best triangle, its distance, and the work.
pub(super) struct Found {
    pub(super) best: Option<Best>,
    pub(super) distance: f64,
    pub(super) work: Work,
}

impl Found {
    /// Tests `face` against `p`, keeping it when nearer than the best so far.
    fn offer<B: BoundingVolume>(
        &mut self,
        tree: &TreeView<'_, B>,
        p: &Vector3<f64>,
        face: u32,
    ) -> Result<(), QueryError> {
        let t = triangle(tree, face, None, Side::A)?;
        let (q, feature) = closest_point_on_triangle(p, &t);
        let d = (p - q).norm();
        if d == 0.0 {
            self.work.tri_contact += 1;
        } else {
            self.work.tri_separated += 1;
        }
        if d < self.distance {
            self.distance = d;
            self.best = Some(Best {
                face,
                id: source_id(tree, face, Side::A)?,
                point: q,
                feature,
            });
        }
        Ok(())
    }
}

/// Dives and a heap, as the pair distance traversal does: each expansion continues with
/// its nearest child down to a leaf (a first answer to prune with, one step per level), the
/// other children wait on a heap, and the next dive starts from the nearest node waiting;
/// the descent ends when that node's bound reaches the best distance found (every other
/// waiting is at least as far). (Best first alone expanded the many boxes that all bound
/// a point near the surface at 0 level by level before reaching any leaf; depth first
/// alone opened half again as many boxes on the bunny.) A `seed` face, tested first,
/// prunes from the start: for coherent points, the previous point's answer.
pub(super) fn descend<B: BoundingVolume>(
    tree: &TreeView<'_, B>,
    p: &Vector3<f64>,
    max_distance: f64,
    seed: Option<u32>,
    heap: &mut BinaryHeap<Waiting>,
) -> Result<Found, QueryError> {
    let mut found = Found {
        best: None,
        distance: max_distance,
        work: Work::default(),
    };
    if let Some(face) = seed {
        found.offer(tree, p, face)?;
    }
    let point = [p.x, p.y, p.z];
    let root = tree
        .node(0)
        .ok_or_else(|| corrupt(Side::A, NodeDefect::Missing))?;
    heap.clear();
    let mut dive = Some(Waiting {
        bound: root.bv.point_distance_lower_bound(point),
        node: 0,
    });
    while let Some(Waiting { bound, node }) = dive.take().or_else(|| heap.pop()) {
        found.work.nodes_visited += 1;
        if bound >= found.distance {
            // Taken from the heap: it and every node still waiting are pruned.
            found.work.bv_disjoint += 1 + heap.len() as u64;
            break;
        }
        found.work.bv_overlap += 1;
        match tree.node_kind(node).map_err(|d| corrupt(Side::A, d))? {
            NodeKind::Faces(faces) => {
                // (The seed was tested first.)
                for face in faces.filter(|&face| Some(face) != seed) {
                    found.offer(tree, p, face)?;
                }
            }
            // Children come after their parent (checked by `node_kind`): the descent
            // ends on any file.
            NodeKind::Children(range) => {
                for child in range {
                    let n = tree
                        .node(child)
                        .ok_or_else(|| corrupt(Side::A, NodeDefect::Missing))?;
                    let bound = n.bv.point_distance_lower_bound(point);
                    if bound >= found.distance {
                        found.work.nodes_visited += 1;
                        found.work.bv_disjoint += 1;
                        continue;
                    }
                    let waiting = Waiting { bound, node: child };
                    // The nearest child continues the dive; the others wait.
                    match dive {
                        Some(d) if d.bound <= bound => heap.push(waiting),
                        Some(d) => {
                            heap.push(d);
                            dive = Some(waiting);
                        }
                        None => dive = Some(waiting),
                    }
                }
            }
        }
    }
    Ok(found)
}
