//! Two trees queried together many times, with the poses per call.

use super::{
    collide_into, distance, distance_below, on_views, span, within_tolerance, CollideOptions,
    CollideResult, DescentRule, DistanceOptions, DistanceResult, Pose, QueryContext, QueryError,
    SpanResult, Stats, ToleranceResult, ViewPair,
};
use crate::format::ObbtFile;

/// Model A and model B, checked once to be queryable together, with the traversal scratch
/// kept between queries: the per-frame object of an application (the free functions such
/// as [`super::collide_files`] take six positional arguments, where A and B are easy to
/// swap).
///
/// Results can be written into buffers the caller keeps ([`PairQuery::collide_into`]), so
/// a query per frame allocates nothing once the buffers have grown. For a yes/no answer per
/// frame use [`PairQuery::first_contact`]: it stops at the first contact and is typically
/// tens to hundreds of times faster than listing every contact.
///
/// ```no_run
/// use obbtree::format::ObbtFile;
/// use obbtree::query::{CollideOptions, PairQuery, Pose};
///
/// let gripper = ObbtFile::open("gripper.obbt")?;
/// let part = ObbtFile::open("part.obbt")?;
/// let mut query = PairQuery::new(&gripper, &part)?;
/// for step in 0..100 {
///     let at = Pose::translation(0.01 * f64::from(step), 0.0, 0.0);
///     if let Some((tri_gripper, tri_part)) = query.first_contact(&at, &Pose::identity())? {
///         println!("step {step}: triangle {tri_gripper} touches {tri_part}");
///     }
/// }
/// # Ok::<(), Box<dyn std::error::Error>>(())
/// ```
#[derive(Debug)]
pub struct PairQuery<'f> {
    a: &'f ObbtFile,
    b: &'f ObbtFile,
    /// The typed views of A and B, made once (each query would otherwise make them again).
    views: ViewPair<'f>,
    context: QueryContext,
    /// The pair buffer of first-contact queries, kept so that a yes/no query per frame
    /// allocates nothing.
    first: CollideResult,
}

impl<'f> PairQuery<'f> {
    /// The pair (A, B); an error if they store different volume types or precisions.
    pub fn new(a: &'f ObbtFile, b: &'f ObbtFile) -> Result<PairQuery<'f>, QueryError> {
        Ok(PairQuery {
            a,
            b,
            views: ViewPair::of(a, b)?,
            context: QueryContext::new(),
            first: CollideResult::default(),
        })
    }

    /// Model A.
    pub fn a(&self) -> &'f ObbtFile {
        self.a
    }

    /// Model B.
    pub fn b(&self) -> &'f ObbtFile {
        self.b
    }

    /// Every contacting triangle pair (or the first, with `options.first_contact`).
    pub fn collide(
        &mut self,
        pose_a: &Pose,
        pose_b: &Pose,
        options: &CollideOptions,
    ) -> Result<CollideResult, QueryError> {
        let mut result = CollideResult::default();
        self.collide_into(pose_a, pose_b, options, &mut result)?;
        Ok(result)
    }

    /// [`PairQuery::collide`] into `result`, reusing its pair buffer.
    pub fn collide_into(
        &mut self,
        pose_a: &Pose,
        pose_b: &Pose,
        options: &CollideOptions,
        result: &mut CollideResult,
    ) -> Result<(), QueryError> {
        let context = &mut self.context;
        on_views!(self.views, |va, vb| collide_into(
            &va, pose_a, &vb, pose_b, options, context, result
        ))
    }

    /// The first contacting pair found (input-mesh ids of A's and B's triangles), or
    /// `None` when the models do not touch: the cheapest yes/no collision answer.
    pub fn first_contact(
        &mut self,
        pose_a: &Pose,
        pose_b: &Pose,
    ) -> Result<Option<(u32, u32)>, QueryError> {
        Ok(self.first_contact_stats(pose_a, pose_b)?.0)
    }

    /// [`PairQuery::first_contact`] with the work done.
    pub fn first_contact_stats(
        &mut self,
        pose_a: &Pose,
        pose_b: &Pose,
    ) -> Result<(Option<(u32, u32)>, Stats), QueryError> {
        let options = CollideOptions {
            first_contact: true,
            ..CollideOptions::default()
        };
        let mut result = std::mem::take(&mut self.first);
        let outcome = self.collide_into(pose_a, pose_b, &options, &mut result);
        let answer = (result.pairs.first().copied(), result.stats);
        self.first = result;
        outcome.map(|()| answer)
    }

    /// The distance, exact or within the errors of `options`.
    pub fn distance(
        &mut self,
        pose_a: &Pose,
        pose_b: &Pose,
        options: &DistanceOptions,
    ) -> Result<DistanceResult, QueryError> {
        let context = &mut self.context;
        on_views!(self.views, |va, vb| distance(
            &va, pose_a, &vb, pose_b, options, context
        ))
    }

    /// The distance if it is below `limit`, else `None` (see [`distance_below`]).
    pub fn distance_below(
        &mut self,
        pose_a: &Pose,
        pose_b: &Pose,
        options: &DistanceOptions,
        limit: f64,
    ) -> Result<(Option<DistanceResult>, Stats), QueryError> {
        let context = &mut self.context;
        on_views!(self.views, |va, vb| distance_below(
            &va, pose_a, &vb, pose_b, options, limit, context
        ))
    }

    /// Whether the models come closer than `tolerance`, stopping as soon as it knows.
    pub fn within_tolerance(
        &mut self,
        pose_a: &Pose,
        pose_b: &Pose,
        tolerance: f64,
        rule: DescentRule,
    ) -> Result<ToleranceResult, QueryError> {
        let context = &mut self.context;
        on_views!(self.views, |va, vb| within_tolerance(
            &va, pose_a, &vb, pose_b, tolerance, rule, context
        ))
    }

    /// The span (largest distance) between the models.
    pub fn span(
        &mut self,
        pose_a: &Pose,
        pose_b: &Pose,
        rule: DescentRule,
    ) -> Result<SpanResult, QueryError> {
        let context = &mut self.context;
        on_views!(self.views, |va, vb| span(
            &va, pose_a, &vb, pose_b, rule, context
        ))
    }
}
