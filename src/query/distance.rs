//! Separation distance: exact, approximate within error bounds, below a limit, and
//! "closer than t?".

use super::engine::{traverse, Flow, Policy, QueryContext};
use super::triangle::{triangle_distance, Triangle};
use super::{source_id, with_views, DescentRule, Pose, QueryError, Side, Stats};
use crate::bv::BoundingVolume;
use crate::format::ObbtFile;
use crate::tree::TreeView;
use nalgebra::Vector3;

/// How to run a distance query.
///
/// With both errors 0 the distance is exact (up to a relative 6e-14, the resolution of f64
/// bounds on far-apart models). Otherwise a pair of volumes is skipped once
/// its lower bound `lb` satisfies `lb * (1 + rel_err) >= best` or `lb + abs_err >= best`, so
/// the returned distance `d` and the true distance `d*` satisfy
/// `d* <= d <= max(d* * (1 + rel_err), d* + abs_err)`; the points always realise `d`.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct DistanceOptions {
    /// Relative error allowed, >= 0.
    pub rel_err: f64,
    /// Absolute error allowed (model units of A), >= 0.
    pub abs_err: f64,
    /// Which tree to descend when both can be.
    pub rule: DescentRule,
    /// The triangle pair of an earlier answer for the same two trees
    /// ([`DistanceResult::witness`]). Its distance at the new poses is measured first and
    /// bounds the search from the start: over a smooth trajectory the closest pair moves
    /// little, so most of the tree is pruned at once (the coherence PQP and SWIFT++ use).
    /// It changes the work, never the guarantee; a pair out of range is ignored, and the
    /// measurement counts as one more triangle test in the statistics.
    pub warm_start: Option<Witness>,
}

/// The triangle pair behind a distance answer, as leaf-ordered faces of its two trees: a
/// hint for the next query of the same trees ([`DistanceOptions::warm_start`]).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct Witness {
    face_a: u32,
    face_b: u32,
}

/// The answer of a distance query.
#[derive(Clone, Debug, PartialEq)]
pub struct DistanceResult {
    /// The distance between the two surfaces (0 if they touch), world units.
    pub distance: f64,
    /// Closest point on A, world frame.
    pub point_a: Vector3<f64>,
    /// Closest point on B, world frame.
    pub point_b: Vector3<f64>,
    /// Input-mesh id of the triangle of A holding `point_a`.
    pub tri_a: u32,
    /// Input-mesh id of the triangle of B holding `point_b`.
    pub tri_b: u32,
    /// The same pair as a warm start for the next query of these trees.
    pub witness: Witness,
    /// Work done.
    pub stats: Stats,
}

/// The answer of a tolerance query.
#[derive(Clone, Debug, PartialEq)]
pub struct ToleranceResult {
    /// Whether the surfaces come closer than the tolerance (distance < tolerance).
    pub closer: bool,
    /// When `closer`: a triangle pair closer than the tolerance (not necessarily the
    /// closest), with its distance and points; `None` otherwise.
    pub witness: Option<DistanceResult>,
    /// Work done.
    pub stats: Stats,
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
    limit: f64,
    /// Stop as soon as a pair is closer than this (tolerance queries); `-1` otherwise.
    stop_below: f64,
    best: Best,
}

impl Distance {
    /// Measures one triangle pair and keeps it if it is the best so far.
    fn measure(&mut self, fa: u32, a: &Triangle, fb: u32, b: &Triangle, stats: &mut Stats) -> Flow {
        let d = triangle_distance(a, b);
        if d.distance == 0.0 {
            stats.tri_contact += 1;
        } else {
            stats.tri_separated += 1;
        }
        let first = self.best.faces.is_none() && !d.distance.is_nan();
        if d.distance < self.best.distance || first {
            self.best = Best {
                distance: d.distance,
                point_a: d.point_a,
                point_b: d.point_b,
                faces: Some((fa, fb)),
            };
            // Nothing can be closer than 0.
            if d.distance == 0.0 || d.distance < self.stop_below {
                return Flow::Stop;
            }
        }
        Flow::Continue
    }
}

impl Distance {
    /// Whether a pair below the limit has been measured: from then on the best answer
    /// prunes; before, only the limit does (or the error allowance could hide the pairs
    /// below it, after a warm start beyond it).
    #[inline]
    fn found(&self) -> bool {
        self.best.faces.is_some() && self.best.distance < self.limit
    }

    /// Whether a volume pair with lower bound `key` may hold a pair closer than the best
    /// answer by more than the allowances `rel_err` and `abs_err`.
    #[inline]
    fn may_improve(&self, key: f64, rel_err: f64, abs_err: f64) -> bool {
        // Until a first pair is measured without a limit nothing is pruned: a pose far
        // enough out overflows every bound to infinity, and the answer is then an infinite
        // distance, not none.
        if self.best.faces.is_none() && self.limit == f64::INFINITY {
            return true;
        }
        // (NaN keys and bests compare false: a damaged file's pair is pruned.)
        let within_limit = key < self.limit;
        if !within_limit || !self.found() {
            return within_limit;
        }
        let best = self.best.distance;
        key * (1.0 + rel_err) < best && key + abs_err < best && key < best * (1.0 - RESOLUTION)
    }

    /// A key at or above which [`Policy::keep`] certainly prunes (the limit while nothing
    /// else can): the bound of a pair need not be tightened past it.
    #[inline]
    fn prune_at(&self) -> f64 {
        if !self.found() {
            return self.limit;
        }
        let best = self.best.distance;
        // Each condition of `keep` fails from its own threshold on; the smallest of them
        // is where the first fails. Rounding in these divisions could only make the
        // threshold a little high (a little more work), never prune a kept pair: `keep`
        // still decides on the key itself.
        (best / (1.0 + self.rel_err))
            .min(best - self.abs_err)
            .min(best * (1.0 - RESOLUTION))
            .min(self.limit)
    }
}

impl<B: BoundingVolume> Policy<B> for Distance {
    const ORDERED: bool = true;

    #[inline]
    fn key(&self, a: &B, b: &B, b_to_a: &Pose) -> f64 {
        a.distance_lower_bound_until(b, b_to_a, self.prune_at())
    }

    /// The rank is the mean of the bound and the centres' distance: a bound favours the
    /// larger of two children, which reaches further, not the one nearer the other model.
    /// Dives chosen so land nearer the closest pair, whose answer prunes more of what waits
    /// (README, Benchmarks: `rel_err` 0.01 29% fewer node pairs over 53 poses, touching
    /// models far fewer).
    #[inline]
    fn key_and_rank(&self, a: &B, b: &B, b_to_a: &Pose) -> (f64, f64) {
        let (bound, centres) = a.distance_lower_bound_and_centres_until(b, b_to_a, self.prune_at());
        (bound, 0.5 * (bound + centres))
    }

    #[inline]
    fn keep(&self, key: f64) -> bool {
        self.may_improve(key, self.rel_err, self.abs_err)
    }

    #[inline]
    fn triangles(
        &mut self,
        fa: u32,
        a: &Triangle,
        fb: u32,
        b: &Triangle,
        stats: &mut Stats,
    ) -> Flow {
        self.measure(fa, a, fb, b, stats)
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
/// found below `policy.limit` (any, without a limit), in world terms.
#[allow(clippy::too_many_arguments)]
fn run<B: BoundingVolume>(
    a: &TreeView<'_, B>,
    pose_a: &Pose,
    b: &TreeView<'_, B>,
    pose_b: &Pose,
    mut policy: Distance,
    rule: DescentRule,
    warm_start: Option<Witness>,
    context: &mut QueryContext,
) -> Result<(Option<DistanceResult>, Stats), QueryError> {
    let b_to_a = Pose::relative(pose_a, pose_b);
    let mut warm = Stats::default();
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
    let mut stats = match flow {
        Flow::Continue => traverse(a, b, &b_to_a, rule, &mut policy, context)?,
        Flow::Stop => Stats::default(),
    };
    stats.tri_separated += warm.tri_separated;
    stats.tri_contact += warm.tri_contact;
    let best = policy.best;
    let Some(faces) = best.faces else {
        return Ok((None, stats));
    };
    if !(best.distance < policy.limit || policy.limit == f64::INFINITY) {
        return Ok((None, stats));
    }
    let result = DistanceResult {
        distance: best.distance,
        point_a: pose_a.apply(&best.point_a),
        point_b: pose_a.apply(&best.point_b),
        tri_a: source_id(a, faces.0, Side::A)?,
        tri_b: source_id(b, faces.1, Side::B)?,
        witness: Witness {
            face_a: faces.0,
            face_b: faces.1,
        },
        stats,
    };
    Ok((Some(result), stats))
}

/// The policy of a distance query with these options and limit.
fn policy(options: &DistanceOptions, limit: f64) -> Result<Distance, QueryError> {
    check("rel_err", options.rel_err)?;
    check("abs_err", options.abs_err)?;
    Ok(Distance {
        rel_err: options.rel_err,
        abs_err: options.abs_err,
        limit,
        stop_below: -1.0,
        best: Best {
            distance: f64::INFINITY,
            point_a: Vector3::zeros(),
            point_b: Vector3::zeros(),
            faces: None,
        },
    })
}

/// The distance between two posed trees, exact or within the errors of `options`.
pub fn distance<B: BoundingVolume>(
    a: &TreeView<'_, B>,
    pose_a: &Pose,
    b: &TreeView<'_, B>,
    pose_b: &Pose,
    options: &DistanceOptions,
    context: &mut QueryContext,
) -> Result<DistanceResult, QueryError> {
    let policy = policy(options, f64::INFINITY)?;
    let warm = options.warm_start;
    let (result, _) = run(a, pose_a, b, pose_b, policy, options.rule, warm, context)?;
    // Every tree has a face, so some triangle pair was measured unless the tree is corrupt.
    result.ok_or(QueryError::CorruptTree {
        which: Side::A,
        what: "no triangle pair reached",
    })
}

/// The distance between two posed trees if it is below `limit` (exact, or within the
/// errors of `options`), else `None` (with the work done). Volume pairs at least `limit`
/// apart are never opened: a distance wanted only up to a range costs what its range
/// needs. `None` is exact: the true distance is at least `limit`.
pub fn distance_below<B: BoundingVolume>(
    a: &TreeView<'_, B>,
    pose_a: &Pose,
    b: &TreeView<'_, B>,
    pose_b: &Pose,
    options: &DistanceOptions,
    limit: f64,
    context: &mut QueryContext,
) -> Result<(Option<DistanceResult>, Stats), QueryError> {
    if limit.is_nan() || limit < 0.0 {
        return Err(QueryError::BadOption {
            name: "limit",
            requirement: "a number >= 0",
            value: limit,
        });
    }
    let policy = policy(options, limit)?;
    let warm = options.warm_start;
    run(a, pose_a, b, pose_b, policy, options.rule, warm, context)
}

/// Whether two posed trees come closer than `tolerance`; stops as soon as it knows.
pub fn within_tolerance<B: BoundingVolume>(
    a: &TreeView<'_, B>,
    pose_a: &Pose,
    b: &TreeView<'_, B>,
    pose_b: &Pose,
    tolerance: f64,
    rule: DescentRule,
    context: &mut QueryContext,
) -> Result<ToleranceResult, QueryError> {
    check("tolerance", tolerance)?;
    // Pairs that cannot come closer than the tolerance are pruned from the start.
    let mut policy = policy(&DistanceOptions::default(), tolerance)?;
    policy.stop_below = tolerance;
    let (found, stats) = run(a, pose_a, b, pose_b, policy, rule, None, context)?;
    Ok(ToleranceResult {
        closer: found.is_some(),
        witness: found,
        stats,
    })
}

/// [`distance`] on two files, dispatched once on their volume type and precision.
pub fn distance_files(
    a: &ObbtFile,
    pose_a: &Pose,
    b: &ObbtFile,
    pose_b: &Pose,
    options: &DistanceOptions,
    context: &mut QueryContext,
) -> Result<DistanceResult, QueryError> {
    with_views!(a, b, |va, vb| distance(
        &va, pose_a, &vb, pose_b, options, context
    ))
}

/// [`within_tolerance`] on two files, dispatched once on their volume type and precision.
pub fn within_tolerance_files(
    a: &ObbtFile,
    pose_a: &Pose,
    b: &ObbtFile,
    pose_b: &Pose,
    tolerance: f64,
    rule: DescentRule,
    context: &mut QueryContext,
) -> Result<ToleranceResult, QueryError> {
    with_views!(a, b, |va, vb| within_tolerance(
        &va, pose_a, &vb, pose_b, tolerance, rule, context
    ))
}
