//! Span: the largest distance between a point of A and a point of B.

use super::engine::{traverse, Flow, Policy, QueryContext};
use super::triangle::{triangle_max_distance, Triangle};
use super::{source_id, with_views, DescentRule, Pose, QueryError, Side, Stats};
use crate::bv::BoundingVolume;
use crate::format::ObbtFile;
use crate::tree::TreeView;
use nalgebra::Vector3;

/// The answer of a span query.
#[derive(Clone, Debug, PartialEq)]
pub struct SpanResult {
    /// The largest distance between the two surfaces, world units (attained at vertices).
    pub span: f64,
    /// Witness on A, world frame.
    pub point_a: Vector3<f64>,
    /// Witness on B, world frame.
    pub point_b: Vector3<f64>,
    /// Input-mesh id of a triangle of A holding `point_a`.
    pub tri_a: u32,
    /// Input-mesh id of a triangle of B holding `point_b`.
    pub tri_b: u32,
    /// Work done.
    pub stats: Stats,
}

struct Span {
    best: f64,
    point_a: Vector3<f64>,
    point_b: Vector3<f64>,
    faces: (u32, u32),
}

impl<B: BoundingVolume> Policy<B> for Span {
    const ORDERED: bool = true;

    /// The negated upper bound, so that the farthest pairs come first.
    #[inline]
    fn key(&self, a: &B, b: &B, b_to_a: &Pose) -> f64 {
        -a.max_distance_upper_bound(b, b_to_a)
    }

    #[inline]
    fn keep(&self, key: f64) -> bool {
        -key > self.best
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
        let d = triangle_max_distance(a, b);
        stats.tri_separated += 1;
        if d.distance > self.best {
            *self = Span {
                best: d.distance,
                point_a: d.point_a,
                point_b: d.point_b,
                faces: (fa, fb),
            };
        }
        Flow::Continue
    }
}

/// The span (maximum distance) between two posed trees, with witness points.
pub fn span<B: BoundingVolume>(
    a: &TreeView<'_, B>,
    pose_a: &Pose,
    b: &TreeView<'_, B>,
    pose_b: &Pose,
    rule: DescentRule,
    context: &mut QueryContext,
) -> Result<SpanResult, QueryError> {
    let b_to_a = Pose::relative(pose_a, pose_b);
    let mut policy = Span {
        best: -1.0,
        point_a: Vector3::zeros(),
        point_b: Vector3::zeros(),
        faces: (0, 0),
    };
    let stats = traverse(a, b, &b_to_a, rule, &mut policy, context)?;
    if policy.best < 0.0 {
        return Err(QueryError::CorruptTree {
            which: Side::A,
            what: "no triangle pair reached",
        });
    }
    Ok(SpanResult {
        span: policy.best,
        point_a: pose_a.apply(&policy.point_a),
        point_b: pose_a.apply(&policy.point_b),
        tri_a: source_id(a, policy.faces.0, Side::A)?,
        tri_b: source_id(b, policy.faces.1, Side::B)?,
        stats,
    })
}

/// [`span`] on two files, dispatched once on their volume type and precision.
pub fn span_files(
    a: &ObbtFile,
    pose_a: &Pose,
    b: &ObbtFile,
    pose_b: &Pose,
    rule: DescentRule,
    context: &mut QueryContext,
) -> Result<SpanResult, QueryError> {
    with_views!(a, b, |va, vb| span(&va, pose_a, &vb, pose_b, rule, context))
}
