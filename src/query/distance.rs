//! Separation distance: exact, approximate within error bounds, and "closer than t?".

use super::engine::{traverse, Flow, Policy, QueryContext};
use super::triangle::{triangle_distance, Triangle};
use super::{source_id, with_views, DescentRule, Pose, QueryError, Stats};
use crate::bv::pair::Transform;
use crate::bv::BoundingVolume;
use crate::format::ObbtFile;
use crate::tree::TreeView;
use nalgebra::Vector3;

/// How to run a distance query.
///
/// With both errors 0 the distance is exact. Otherwise a pair of volumes is skipped once
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
    /// Stop as soon as a pair is closer than this (tolerance queries); `-1` otherwise.
    stop_below: f64,
    best: Best,
    /// No pair measured yet in a distance query (tolerance queries prune from the start).
    unmeasured: bool,
}

impl<B: BoundingVolume> Policy<B> for Distance {
    const ORDERED: bool = true;

    #[inline]
    fn key(&self, a: &B, b: &B, xf: &Transform) -> f64 {
        a.distance_lower_bound(b, xf)
    }

    #[inline]
    fn keep(&self, key: f64) -> bool {
        let best = self.best.distance;
        // Until a first pair is measured nothing is pruned: a pose far enough out overflows
        // every bound to infinity, and the answer is then an infinite distance, not none.
        (key * (1.0 + self.rel_err) < best && key + self.abs_err < best) || self.unmeasured
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
        let d = triangle_distance(a, b);
        if d.distance == 0.0 {
            stats.tri_contact += 1;
        } else {
            stats.tri_separated += 1;
        }
        let first = self.unmeasured && !d.distance.is_nan();
        if first {
            self.unmeasured = false;
        }
        if d.distance < self.best.distance || first {
            self.best = Best {
                distance: d.distance,
                point_a: d.point_a,
                point_b: d.point_b,
                faces: Some((fa, fb)),
            };
            if d.distance == 0.0 || d.distance < self.stop_below {
                return Flow::Stop;
            }
        }
        Flow::Continue
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

fn run<B: BoundingVolume>(
    a: &TreeView<'_, B>,
    pose_a: &Pose,
    b: &TreeView<'_, B>,
    pose_b: &Pose,
    mut policy: Distance,
    rule: DescentRule,
    context: &mut QueryContext,
) -> Result<(Option<DistanceResult>, Stats), QueryError> {
    let xf = Pose::relative(pose_a, pose_b);
    let stats = traverse(a, b, &xf, rule, &mut policy, context)?;
    let best = policy.best;
    let Some(faces) = best.faces else {
        return Ok((None, stats));
    };
    let result = DistanceResult {
        distance: best.distance,
        point_a: pose_a.apply(&best.point_a),
        point_b: pose_a.apply(&best.point_b),
        tri_a: source_id(a, faces.0, 'A')?,
        tri_b: source_id(b, faces.1, 'B')?,
        stats,
    };
    Ok((Some(result), stats))
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
    check("rel_err", options.rel_err)?;
    check("abs_err", options.abs_err)?;
    let none = Best {
        distance: f64::INFINITY,
        point_a: Vector3::zeros(),
        point_b: Vector3::zeros(),
        faces: None,
    };
    let policy = Distance {
        rel_err: options.rel_err,
        abs_err: options.abs_err,
        stop_below: -1.0,
        best: none,
        unmeasured: true,
    };
    let (result, _) = run(a, pose_a, b, pose_b, policy, options.rule, context)?;
    // Every tree has a face, so some triangle pair was measured unless the tree is corrupt.
    result.ok_or(QueryError::CorruptTree {
        which: 'A',
        what: "no triangle pair reached",
    })
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
    // Starting the best at the tolerance prunes every pair that cannot come closer.
    let start = Best {
        distance: tolerance,
        point_a: Vector3::zeros(),
        point_b: Vector3::zeros(),
        faces: None,
    };
    let policy = Distance {
        rel_err: 0.0,
        abs_err: 0.0,
        stop_below: tolerance,
        best: start,
        unmeasured: false,
    };
    let mut found = None;
    let (result, stats) = run(a, pose_a, b, pose_b, policy, rule, context)?;
    if let Some(r) = result {
        if r.distance < tolerance {
            found = Some(r);
        }
    }
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
