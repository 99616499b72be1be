//! Span: the largest distance between a point of A and a point of B.

use super::engine::{traverse, Flow, Policy, QueryContext};
use super::triangle::{triangle_max_distance, Triangle};
use super::{source_id, DescentRule, Pose, QueryError, Side, Witness, Work};
use crate::bv::BoundingVolume;
use crate::tree::TreeView;
use nalgebra::Vector3;

/// How to run a span query.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct SpanOptions {
    /// Which tree to descend when both can be.
    pub rule: DescentRule,
}

/// The answer of a span query.
#[derive(Clone, Debug, PartialEq)]
pub struct SpanResult {
    /// The farthest pair: its distance is the span, attained at vertices.
    pub farthest: Witness,
    /// Work done.
    pub work: Work,
}

impl SpanResult {
    /// The largest distance between a point of A and a point of B, world units.
    pub fn span(&self) -> f64 {
        self.farthest.distance
    }
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
    fn triangles(&mut self, fa: u32, a: &Triangle, fb: u32, b: &Triangle, work: &mut Work) -> Flow {
        let d = triangle_max_distance(a, b);
        work.tri_separated += 1;
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

/// The span (largest distance) between two posed trees, with its witness points: what
/// [`super::PairQuery::span`] runs once it has typed the trees.
///
/// # Errors
///
/// [`QueryError::CorruptTree`] when a tree's nodes are inconsistent (an unverified file).
pub fn span<B: BoundingVolume>(
    a: &TreeView<'_, B>,
    pose_a: &Pose,
    b: &TreeView<'_, B>,
    pose_b: &Pose,
    options: &SpanOptions,
    context: &mut QueryContext,
) -> Result<SpanResult, QueryError> {
    let b_to_a = Pose::relative(pose_a, pose_b);
    let mut policy = Span {
        best: -1.0,
        point_a: Vector3::zeros(),
        point_b: Vector3::zeros(),
        faces: (0, 0),
    };
    let work = traverse(a, b, &b_to_a, options.rule, &mut policy, context)?;
    if policy.best < 0.0 {
        return Err(QueryError::CorruptTree {
            which: Side::A,
            what: "no triangle pair reached",
        });
    }
    Ok(SpanResult {
        farthest: Witness {
            distance: policy.best,
            point_a: pose_a.apply(&policy.point_a),
            point_b: pose_a.apply(&policy.point_b),
            tri_a: source_id(a, policy.faces.0, Side::A)?,
            tri_b: source_id(b, policy.faces.1, Side::B)?,
        },
        work,
    })
}
