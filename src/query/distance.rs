//! Separation distance: exact, approximate within error bounds, up to a maximum distance,
//! and "closer than a tolerance?".

use super::engine::{traverse, Flow, Policy, QueryContext};
use super::triangle::{triangle_distance, Triangle};
use super::{source_id, DescentRule, Pose, QueryError, Side, Work};
use crate::bv::BoundingVolume;
use crate::tree::TreeView;
use nalgebra::Vector3;

/// How to run a distance query.
///
/// With both errors 0 the distance is exact (up to the relative resolution of f64 bounds
/// on far-apart models). Otherwise a pair of volumes is skipped once its lower bound `lb`
/// satisfies `lb * (1 + rel_err) >= best` or `lb + abs_err >= best`, so the returned
/// distance `d` and the true distance `d*` satisfy
/// `d* <= d <= max(d* * (1 + rel_err), d* + abs_err)`; the points always realise `d`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct DistanceOptions {
    /// Relative error allowed, >= 0.
    pub rel_err: f64,
    /// Absolute error allowed (world units), >= 0.
    pub abs_err: f64,
    /// The distance beyond which the answer is not wanted (world units, > 0; infinite by
    /// default). Volume pairs at least this far apart are never opened, so a distance
    /// wanted only up to a range costs what its range needs; models at least this far
    /// apart give [`DistanceResult::closest`] `None`, which is exact.
    pub max_distance: f64,
    /// Which tree to descend when both can be.
    pub rule: DescentRule,
    /// The triangle pair of an earlier answer for the same two trees
    /// ([`DistanceResult::warm_start`]). Its distance at the new poses is measured first and
    /// bounds the search from the start: over a smooth trajectory the closest pair moves
    /// little, so most of the tree is pruned at once (the coherence PQP and SWIFT++ use).
    /// It changes the work, never the guarantee; a pair out of range is ignored, and the
    /// measurement counts as one more triangle test in the work.
    pub warm_start: Option<WarmStart>,
}

impl Default for DistanceOptions {
    fn default() -> Self {
        DistanceOptions {
            rel_err: 0.0,
            abs_err: 0.0,
            max_distance: f64::INFINITY,
            rule: DescentRule::default(),
            warm_start: None,
        }
    }
}

/// The triangle pair behind a distance answer, as leaf-ordered faces of its two trees: a
/// hint for the next query of the same trees ([`DistanceOptions::warm_start`]).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct WarmStart {
    face_a: u32,
    face_b: u32,
}

/// A triangle of A and a triangle of B with the distance between them and the points that
/// realise it: the closest pair of a distance query, a pair closer than the tolerance of a
/// tolerance query, the farthest pair of a span query.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Witness {
    /// The distance between the two points, world units.
    pub distance: f64,
    /// The point on A, world frame.
    pub point_a: Vector3<f64>,
    /// The point on B, world frame.
    pub point_b: Vector3<f64>,
    /// Input-mesh id of the triangle of A holding `point_a`.
    pub tri_a: u32,
    /// Input-mesh id of the triangle of B holding `point_b`.
    pub tri_b: u32,
}

/// The answer of a distance query.
#[derive(Clone, Debug, PartialEq)]
pub struct DistanceResult {
    /// The closest pair (distance 0 if the surfaces touch); `None` when the models are at
    /// least [`DistanceOptions::max_distance`] apart.
    pub closest: Option<Witness>,
    /// The closest pair as a warm start for the next query of these trees (`None` with
    /// `closest`).
    pub warm_start: Option<WarmStart>,
    /// Work done.
    pub work: Work,
}

impl DistanceResult {
    /// The distance between the surfaces, world units: infinite when the models are at
    /// least [`DistanceOptions::max_distance`] apart.
    pub fn distance(&self) -> f64 {
        self.closest.map_or(f64::INFINITY, |w| w.distance)
    }
}

/// How to run a tolerance query: whether the models come closer than `tolerance`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ToleranceOptions {
    /// The distance that counts as too close (world units, >= 0): the answer is yes when
    /// the surfaces come closer than it (distance < tolerance).
    pub tolerance: f64,
    /// Which tree to descend when both can be.
    pub rule: DescentRule,
}

impl ToleranceOptions {
    /// A tolerance query for `tolerance` with the default descent rule.
    pub fn new(tolerance: f64) -> ToleranceOptions {
        ToleranceOptions {
            tolerance,
            rule: DescentRule::default(),
        }
    }
}

/// The answer of a tolerance query.
#[derive(Clone, Debug, PartialEq)]
pub struct ToleranceResult {
    /// A triangle pair closer than the tolerance (not necessarily the closest), or `None`
    /// when the surfaces stay at least the tolerance apart.
    pub witness: Option<Witness>,
    /// Work done.
    pub work: Work,
}

impl ToleranceResult {
    /// Whether the surfaces come closer than the tolerance.
    pub fn closer(&self) -> bool {
        self.witness.is_some()
    }
}

/// The relative difference below which distances of far-apart models cannot be told apart:
/// box bounds carry a rounding slack of 64 ε per component of the centre offset (up to
/// 192 ε of it), so a pair whose bound is within this of the best cannot be shown closer.
/// Pruning it keeps every answer within this factor of the minimum, far below the
/// triangle distance's own rounding for any offset near the models, and stops models
/// 1e300 apart (where every triangle pair is at the same f64 distance) from measuring
/// every pair.
const RESOLUTION: f64 = 256.0 * f64::EPSILON;

/// The best pair found so far, in A's frame.
#[derive(Clone, Copy)]
struct Best {
    distance: f64,
    point_a: Vector3<f64>,
    point_b: Vector3<f64>,
    /// The leaf-ordered faces of the pair; `None` until a pair is measured.
    faces: Option<(u32, u32)>,
}

struct Distance {
    rel_err: f64,
    abs_err: f64,
    /// Pairs at or beyond this distance are of no interest (infinite: none is excluded).
    max_distance: f64,
    /// Stop as soon as a pair is closer than this (tolerance queries); `-1` otherwise.
    stop_below: f64,
    best: Best,
    /// A key at or above which [`Policy::keep`] certainly prunes (the maximum distance
    /// while nothing else can): the bound of a pair need not be tightened past it. It is
    /// [`Distance::threshold`] of `best`, kept with it: every bound asks for it, and the
    /// best changes only a few times a query.
    prune_at: f64,
}

impl Distance {
    /// Measures one triangle pair and keeps it if it is the best so far.
    fn measure(&mut self, fa: u32, a: &Triangle, fb: u32, b: &Triangle, work: &mut Work) -> Flow {
        let d = triangle_distance(a, b);
        if d.distance == 0.0 {
            work.tri_contact += 1;
        } else {
            work.tri_separated += 1;
        }
        let first = self.best.faces.is_none() && !d.distance.is_nan();
        if d.distance < self.best.distance || first {
            self.best = Best {
                distance: d.distance,
                point_a: d.point_a,
                point_b: d.point_b,
                faces: Some((fa, fb)),
            };
            self.prune_at = self.threshold();
            // Nothing can be closer than 0.
            if d.distance == 0.0 || d.distance < self.stop_below {
                return Flow::Stop;
            }
        }
        Flow::Continue
    }
}

impl Distance {
    /// Whether a pair below the maximum distance has been measured: from then on the best
    /// answer prunes; before, only the maximum does (or the error allowance could hide the pairs
    /// below it, after a warm start beyond it).
    #[inline]
    fn found(&self) -> bool {
        self.best.faces.is_some() && self.best.distance < self.max_distance
    }

    /// Whether a volume pair with lower bound `key` may hold a pair closer than the best
    /// answer by more than the allowances `rel_err` and `abs_err`.
    #[inline]
    fn may_improve(&self, key: f64, rel_err: f64, abs_err: f64) -> bool {
        // Until a first pair is measured without a maximum nothing is pruned: a pose far
        // enough out overflows every bound to infinity, and the answer is then an infinite
        // distance, not none.
        if self.best.faces.is_none() && self.max_distance == f64::INFINITY {
            return true;
        }
        // (NaN keys and bests compare false: a damaged file's pair is pruned.)
        let within_max = key < self.max_distance;
        if !within_max || !self.found() {
            return within_max;
        }
        let best = self.best.distance;
        key * (1.0 + rel_err) < best && key + abs_err < best && key < best * (1.0 - RESOLUTION)
    }

    /// [`Distance::prune_at`] computed from the best answer.
    fn threshold(&self) -> f64 {
        if !self.found() {
            return self.max_distance;
        }
        let best = self.best.distance;
        // Each condition of `keep` fails from its own threshold on; the smallest of them
        // is where the first fails. Rounding in these divisions could only make the
        // threshold a little high (a little more work), never prune a kept pair: `keep`
        // still decides on the key itself.
        (best / (1.0 + self.rel_err))
            .min(best - self.abs_err)
            .min(best * (1.0 - RESOLUTION))
            .min(self.max_distance)
    }
}

impl<B: BoundingVolume> Policy<B> for Distance {
    const ORDERED: bool = true;

    #[inline]
    fn key(&self, a: &B, b: &B, b_to_a: &Pose) -> f64 {
        a.distance_lower_bound_until(b, b_to_a, self.prune_at)
    }

    /// The rank is the mean of the bound and the centres' distance: a bound favours the
    /// larger of two children, which reaches further, not the one nearer the other model.
    /// Dives chosen so land nearer the closest pair, whose answer prunes more of what waits
    /// (measured in docs/results: fewer node pairs, far fewer on touching models).
    #[inline]
    fn key_and_rank(&self, a: &B, b: &B, b_to_a: &Pose) -> (f64, f64) {
        let (bound, centres) = a.distance_lower_bound_and_centres_until(b, b_to_a, self.prune_at);
        (bound, 0.5 * (bound + centres))
    }

    #[inline]
    fn keep(&self, key: f64) -> bool {
        self.may_improve(key, self.rel_err, self.abs_err)
    }

    #[inline]
    fn triangles(&mut self, fa: u32, a: &Triangle, fb: u32, b: &Triangle, work: &mut Work) -> Flow {
        self.measure(fa, a, fb, b, work)
    }
}

fn check(name: &'static str, value: f64) -> Result<(), QueryError> {
    if value.is_finite() && value >= 0.0 {
        Ok(())
    } else {
        Err(QueryError::BadOption {
            name,
            requirement: "a finite number >= 0",
            value,
        })
    }
}

/// Triangle `face` of `tree` mapped into A's frame by `to_a` (the identity for A's own
/// triangles), if the tree holds it.
fn mapped_triangle<B: BoundingVolume>(
    tree: &TreeView<'_, B>,
    face: u32,
    to_a: &Pose,
) -> Option<Triangle> {
    tree.triangle(face)
        .map(|t| t.map(|p| to_a.apply(&Vector3::from(p))))
}

/// Runs the distance traversal: the warm start first, then the tree pairs. The best pair
/// found below `policy.max_distance` (any, without a maximum), in world terms.
#[allow(clippy::too_many_arguments)]
fn run<B: BoundingVolume>(
    a: &TreeView<'_, B>,
    pose_a: &Pose,
    b: &TreeView<'_, B>,
    pose_b: &Pose,
    mut policy: Distance,
    rule: DescentRule,
    warm_start: Option<WarmStart>,
    context: &mut QueryContext,
) -> Result<DistanceResult, QueryError> {
    let b_to_a = Pose::relative(pose_a, pose_b);
    let mut warm = Work::default();
    let mut flow = Flow::Continue;
    if let Some(w) = warm_start {
        let pair = (
            mapped_triangle(a, w.face_a, &Pose::identity()),
            mapped_triangle(b, w.face_b, &b_to_a),
        );
        if let (Some(ta), Some(tb)) = pair {
            flow = policy.measure(w.face_a, &ta, w.face_b, &tb, &mut warm);
        }
    }
    let mut work = match flow {
        Flow::Continue => traverse(a, b, &b_to_a, rule, &mut policy, context)?,
        Flow::Stop => Work::default(),
    };
    work.tri_separated += warm.tri_separated;
    work.tri_contact += warm.tri_contact;
    let best = policy.best;
    let found = best
        .faces
        .filter(|_| best.distance < policy.max_distance || policy.max_distance == f64::INFINITY);
    let Some((face_a, face_b)) = found else {
        return Ok(DistanceResult {
            closest: None,
            warm_start: None,
            work,
        });
    };
    Ok(DistanceResult {
        closest: Some(Witness {
            distance: best.distance,
            point_a: pose_a.apply(&best.point_a),
            point_b: pose_a.apply(&best.point_b),
            tri_a: source_id(a, face_a, Side::A)?,
            tri_b: source_id(b, face_b, Side::B)?,
        }),
        warm_start: Some(WarmStart { face_a, face_b }),
        work,
    })
}

/// The policy of a distance query with these error allowances and maximum distance.
fn policy(rel_err: f64, abs_err: f64, max_distance: f64) -> Result<Distance, QueryError> {
    check("rel_err", rel_err)?;
    check("abs_err", abs_err)?;
    Ok(Distance {
        rel_err,
        abs_err,
        max_distance,
        stop_below: -1.0,
        best: Best {
            distance: f64::INFINITY,
            point_a: Vector3::zeros(),
            point_b: Vector3::zeros(),
            faces: None,
        },
        // Nothing found: the maximum alone prunes.
        prune_at: max_distance,
    })
}

/// The distance between two posed trees, exact or within the errors of `options`, up to
/// `options.max_distance`: what [`super::PairQuery::distance`] runs once it has typed the
/// trees.
///
/// # Errors
///
/// [`QueryError::BadOption`] for a negative or non-finite error allowance or a
/// `max_distance` that is not greater than 0 (nothing is below 0);
/// [`QueryError::CorruptTree`] when a tree's nodes are inconsistent.
pub fn distance<B: BoundingVolume>(
    a: &TreeView<'_, B>,
    pose_a: &Pose,
    b: &TreeView<'_, B>,
    pose_b: &Pose,
    options: &DistanceOptions,
    context: &mut QueryContext,
) -> Result<DistanceResult, QueryError> {
    let max_distance = options.max_distance;
    // Nothing is closer than 0, so a maximum of 0 could only answer "beyond".
    super::require_positive("max_distance", max_distance)?;
    let policy = policy(options.rel_err, options.abs_err, max_distance)?;
    let warm = options.warm_start;
    let result = run(a, pose_a, b, pose_b, policy, options.rule, warm, context)?;
    // Every tree has a face, so without a maximum some triangle pair was measured unless
    // the tree is corrupt.
    if result.closest.is_none() && max_distance == f64::INFINITY {
        return Err(QueryError::CorruptTree {
            which: Side::A,
            what: "no triangle pair reached",
        });
    }
    Ok(result)
}

/// Whether two posed trees come closer than `options.tolerance`, stopping as soon as it
/// knows: what [`super::PairQuery::within`] runs once it has typed the trees.
///
/// # Errors
///
/// [`QueryError::BadOption`] for a negative or non-finite tolerance;
/// [`QueryError::CorruptTree`] when a tree's nodes are inconsistent.
pub fn within<B: BoundingVolume>(
    a: &TreeView<'_, B>,
    pose_a: &Pose,
    b: &TreeView<'_, B>,
    pose_b: &Pose,
    options: &ToleranceOptions,
    context: &mut QueryContext,
) -> Result<ToleranceResult, QueryError> {
    let tolerance = options.tolerance;
    check("tolerance", tolerance)?;
    // Pairs that cannot come closer than the tolerance are pruned from the start.
    let mut policy = policy(0.0, 0.0, tolerance)?;
    policy.stop_below = tolerance;
    let found = run(a, pose_a, b, pose_b, policy, options.rule, None, context)?;
    Ok(ToleranceResult {
        witness: found.closest,
        work: found.work,
    })
}
