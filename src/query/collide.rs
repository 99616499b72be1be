//! Collision: every contacting triangle pair, or the first one found.

use super::engine::{traverse, triangle, Flow, Policy, QueryContext};
use super::triangle::{triangle_intersection, triangles_intersect, Triangle, TriangleIntersection};
use super::{source_id, DescentRule, Pose, QueryError, Side, Work};
use crate::bv::pair::{Guard, OFFSET_ROUNDING, SAT_GUARD};
use crate::bv::BoundingVolume;
use crate::tree::TreeView;
use nalgebra::Vector3;

/// How to run a collision query.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct CollideOptions {
    /// Stop at the first contact (a yes/no answer with one witness pair).
    pub first_contact: bool,
    /// Which tree to descend when both can be.
    pub rule: DescentRule,
    /// Separating-axis guard (§4.5); keep the default [`SAT_GUARD`] outside experiments.
    pub guard: f64,
    /// How box pairs are tested; keep the default outside experiments.
    pub box_test: BoxTest,
    /// Also compute where each contacting pair meets ([`CollideResult::contacts`]).
    pub geometry: bool,
}

/// How a collision query tests two boxes (OBB or AABB trees; sphere trees always test
/// spheres).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub enum BoxTest {
    /// The 15 separating axes of §4.3: exact up to the guard (the default).
    #[default]
    SeparatingAxes,
    /// B's box re-wrapped in a box aligned with A's, tested on A's three axes: how the
    /// dissertation's experiments tested AABBs (for AABB trees it is the classic AABB
    /// test after the update of §2.3). Cheaper per test, looser, so more tests.
    Rewrapped,
}

impl Default for CollideOptions {
    fn default() -> Self {
        CollideOptions {
            first_contact: false,
            rule: DescentRule::default(),
            guard: SAT_GUARD,
            box_test: BoxTest::default(),
            geometry: false,
        }
    }
}

/// The answer of a collision query (the default is "not colliding": an empty buffer for
/// [`super::PairQuery::collide_into`]).
#[derive(Clone, Debug, Default, PartialEq)]
pub struct CollideResult {
    /// Whether any triangle of A touches any triangle of B.
    pub colliding: bool,
    /// Contacting pairs as input-mesh ids `(id_a, id_b)`, sorted; one pair at most with
    /// `first_contact`.
    pub pairs: Vec<(u32, u32)>,
    /// With [`CollideOptions::geometry`], where each pair of `pairs` meets, in the same
    /// order; empty otherwise.
    pub contacts: Vec<Contact>,
    /// Work done.
    pub work: Work,
}

/// Where a contacting triangle pair meets, world frame.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Contact {
    /// Input-mesh id of A's triangle.
    pub tri_a: u32,
    /// Input-mesh id of B's triangle.
    pub tri_b: u32,
    /// The segment where they cross, or the polygon they share when coplanar.
    pub intersection: TriangleIntersection,
}

impl CollideResult {
    /// The length of the intersection curve: the summed lengths of the crossing pairs'
    /// segments (world units; coplanar overlaps count in [`Self::overlap_area`]).
    pub fn curve_length(&self) -> f64 {
        self.contacts.iter().map(|c| c.intersection.length()).sum()
    }

    /// The summed area of the polygons coplanar pairs share.
    pub fn overlap_area(&self) -> f64 {
        self.contacts.iter().map(|c| c.intersection.area()).sum()
    }

    /// The axis-aligned box (world frame) of every contact point: `(min, max)`, `None`
    /// without contacts.
    pub fn contact_bounds(&self) -> Option<([f64; 3], [f64; 3])> {
        let mut points = self.contacts.iter().flat_map(|c| c.intersection.points());
        let first = points.next()?;
        let (lo, hi) = points.fold((*first, *first), |(lo, hi), p| (lo.inf(p), hi.sup(p)));
        Some((lo.into(), hi.into()))
    }
}

struct Collide {
    guard: Guard,
    rewrapped: bool,
    first: bool,
    faces: Vec<(u32, u32)>,
}

impl<B: BoundingVolume> Policy<B> for Collide {
    const ORDERED: bool = false;

    #[inline]
    fn key(&self, a: &B, b: &B, b_to_a: &Pose) -> f64 {
        let overlap = if self.rewrapped {
            a.overlaps_rewrapped(b, b_to_a, self.guard)
        } else {
            a.overlaps(b, b_to_a, self.guard)
        };
        if overlap {
            0.0
        } else {
            f64::INFINITY
        }
    }

    #[inline]
    fn keep(&self, key: f64) -> bool {
        key == 0.0
    }

    #[inline]
    fn nearest_first(&self) -> bool {
        self.first
    }

    #[inline]
    fn triangles(&mut self, fa: u32, a: &Triangle, fb: u32, b: &Triangle, work: &mut Work) -> Flow {
        if triangles_intersect(a, b) {
            work.tri_contact += 1;
            self.faces.push((fa, fb));
            if self.first {
                return Flow::Stop;
            }
        } else {
            work.tri_separated += 1;
        }
        Flow::Continue
    }
}

/// All contacting triangle pairs of two posed trees (or the first found): what
/// [`super::PairQuery::collide`] runs once it has typed the trees.
///
/// # Errors
///
/// [`QueryError::CorruptTree`] when a tree's nodes are inconsistent (an unverified file).
pub fn collide<B: BoundingVolume>(
    a: &TreeView<'_, B>,
    pose_a: &Pose,
    b: &TreeView<'_, B>,
    pose_b: &Pose,
    options: &CollideOptions,
    context: &mut QueryContext,
) -> Result<CollideResult, QueryError> {
    let mut result = CollideResult::default();
    collide_into(a, pose_a, b, pose_b, options, context, &mut result)?;
    Ok(result)
}

/// [`collide`] writing into `result`, whose pair buffer is reused (cleared, not freed), so
/// that a query per frame allocates nothing once the buffers have grown.
///
/// # Errors
///
/// As [`collide`].
pub fn collide_into<B: BoundingVolume>(
    a: &TreeView<'_, B>,
    pose_a: &Pose,
    b: &TreeView<'_, B>,
    pose_b: &Pose,
    options: &CollideOptions,
    context: &mut QueryContext,
    result: &mut CollideResult,
) -> Result<(), QueryError> {
    let b_to_a = Pose::relative(pose_a, pose_b);
    result.pairs.clear();
    result.colliding = false;
    // (Empty trees have no root and nothing to guard.)
    let mut guard = Guard::rotation_only(options.guard);
    if let (Some(ra), Some(rb)) = (a.node(0), b.node(0)) {
        let (ball_a, ball_b) = (ra.bv.enclosing_ball(), rb.bv.enclosing_ball());
        if balls_apart(ball_a, ball_b, &b_to_a) {
            // The root pair, tested and found disjoint (the boxes lie in the balls).
            result.work = Work {
                bv_disjoint: 1,
                nodes_visited: 1,
                ..Work::default()
            };
            return Ok(());
        }
        guard = Guard::for_models(options.guard, ball_a, ball_b, &b_to_a);
    }
    let mut faces = std::mem::take(&mut context.faces);
    faces.clear();
    let mut policy = Collide {
        guard,
        rewrapped: options.box_test == BoxTest::Rewrapped,
        first: options.first_contact,
        faces,
    };
    let traversal = traverse(a, b, &b_to_a, options.rule, &mut policy, context);
    context.faces = policy.faces;
    result.work = traversal?;
    for &(fa, fb) in &context.faces {
        result
            .pairs
            .push((source_id(a, fa, Side::A)?, source_id(b, fb, Side::B)?));
    }
    result.pairs.sort_unstable();
    result.colliding = !result.pairs.is_empty();
    result.contacts.clear();
    if options.geometry {
        for &(fa, fb) in &context.faces {
            let ta = triangle(a, fa, None, Side::A)?;
            let tb = triangle(b, fb, Some(&b_to_a), Side::B)?;
            // (Always found: the exact test said these touch.)
            if let Some(meet) = triangle_intersection(&ta, &tb) {
                result.contacts.push(Contact {
                    tri_a: source_id(a, fa, Side::A)?,
                    tri_b: source_id(b, fb, Side::B)?,
                    intersection: meet.posed(pose_a),
                });
            }
        }
        result.contacts.sort_unstable_by_key(|c| (c.tri_a, c.tri_b));
    }
    Ok(())
}

/// Whether the enclosing balls (centre, radius) of two volumes are certainly apart: the
/// first test of a collision query, since models far apart (most of the pairs a scene asks
/// about) are culled at their roots, and a ball test costs a tenth of a box test (two 3×3
/// products and the separating axes).
#[inline]
fn balls_apart((ca, ra): ([f64; 3], f64), (cb, rb): ([f64; 3], f64), b_to_a: &Pose) -> bool {
    let (ca, cb) = (Vector3::from(ca), b_to_a.apply(&Vector3::from(cb)));
    // Mapping B's centre and the difference round by a few ulps of their magnitudes. A
    // rotation rigid to rounding (`Pose::new`) stretches B's ball by a few ulps of its
    // radius, which this covers too: where it can say apart, the centres are more than
    // `rb` apart, so their magnitudes sum to more than `rb`.
    let rounding = OFFSET_ROUNDING * (ca.abs().sum() + cb.abs().sum());
    (cb - ca).norm() > ra + rb + rounding
}
