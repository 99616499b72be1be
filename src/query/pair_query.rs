//! Two trees queried together many times, with the poses per call: the query API.

use super::details;
use super::{
    CollideOptions, CollideResult, DistanceOptions, DistanceResult, Pose, QueryContext, QueryError,
    SpanOptions, SpanResult, ToleranceOptions, ToleranceResult,
};
use crate::bv::{dispatch, BoundingVolume, VolumeVisitor};
use crate::format::ObbtFile;
use crate::tree::TreeView;

/// Model A and model B, checked once to be queryable together, with the traversal scratch
/// kept between queries: the one way to query a pair of models.
///
/// Every query takes A's pose, B's pose and its options, and returns its answer with the
/// [`super::Work`] it did; results are in the world frame, triangle ids are the input
/// meshes'. The volume type and precision the files store are dispatched once, in
/// [`PairQuery::new`]; a query then costs one indirect call more than the typed functions
/// of [`details`].
///
/// For a yes/no answer per frame ask for [`CollideOptions::first_contact`]: it stops at
/// the first contact and is typically tens to hundreds of times faster than listing every
/// contact. [`PairQuery::collide_into`] writes into a buffer the caller keeps, so a query
/// per frame allocates nothing once the buffer has grown.
///
/// # Examples
///
/// ```no_run
/// use obbtree::format::ObbtFile;
/// use obbtree::query::{CollideOptions, PairQuery, Pose};
///
/// let gripper = ObbtFile::open("gripper.obbt")?;
/// let part = ObbtFile::open("part.obbt")?;
/// let mut pair = PairQuery::new(&gripper, &part)?;
/// let first = CollideOptions { first_contact: true, ..CollideOptions::default() };
/// for step in 0..100 {
///     let at = Pose::translation(0.01 * f64::from(step), 0.0, 0.0);
///     if let Some((tri_gripper, tri_part)) = pair.collide(&at, &Pose::identity(), &first)?.pairs.first() {
///         println!("step {step}: triangle {tri_gripper} touches {tri_part}");
///     }
/// }
/// # Ok::<(), Box<dyn std::error::Error>>(())
/// ```
pub struct PairQuery<'f> {
    a: &'f ObbtFile,
    b: &'f ObbtFile,
    /// The typed views of A and B, made once (typing a file's sections per query would
    /// cost a good part of a query culled at the roots).
    trees: Box<dyn TypedPair + Send + Sync + 'f>,
    context: QueryContext,
}

impl std::fmt::Debug for PairQuery<'_> {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("PairQuery")
            .field("a", &self.a.info().bv)
            .field("b", &self.b.info().bv)
            .field("precision", &self.a.precision())
            .finish_non_exhaustive()
    }
}

impl<'f> PairQuery<'f> {
    /// The pair (A, B).
    ///
    /// # Errors
    ///
    /// [`QueryError::MismatchedTrees`] if the files store different volume types or
    /// precisions; [`QueryError::Format`] if a file's sections cannot be viewed.
    pub fn new(a: &'f ObbtFile, b: &'f ObbtFile) -> Result<PairQuery<'f>, QueryError> {
        PairQuery::with_context(a, b, QueryContext::new())
    }

    /// [`PairQuery::new`] with the traversal scratch of an earlier pair
    /// ([`PairQuery::into_context`]): a program that queries many short-lived pairs (a
    /// scene's narrow phase) keeps one scratch per thread and allocates nothing per pair.
    ///
    /// # Errors
    ///
    /// As [`PairQuery::new`].
    pub fn with_context(
        a: &'f ObbtFile,
        b: &'f ObbtFile,
        context: QueryContext,
    ) -> Result<PairQuery<'f>, QueryError> {
        if a.node_type() != b.node_type() {
            return Err(QueryError::MismatchedTrees {
                a: a.node_type().to_string(),
                b: b.node_type().to_string(),
            });
        }
        Ok(PairQuery {
            a,
            b,
            trees: dispatch(a.node_type(), Typing { a, b })?,
            context,
        })
    }

    /// The traversal scratch, for [`PairQuery::with_context`].
    pub fn into_context(self) -> QueryContext {
        self.context
    }

    /// The traversal scratch, leaving an empty one (for a holder that cannot move the pair
    /// out, such as a `Drop`).
    pub(crate) fn take_context(&mut self) -> QueryContext {
        std::mem::take(&mut self.context)
    }

    /// Model A.
    pub fn a(&self) -> &'f ObbtFile {
        self.a
    }

    /// Model B.
    pub fn b(&self) -> &'f ObbtFile {
        self.b
    }

    /// Every contacting triangle pair, sorted (or the first one found, with
    /// [`CollideOptions::first_contact`]).
    ///
    /// # Errors
    ///
    /// [`QueryError::CorruptTree`] when a tree's nodes are inconsistent (an unverified file).
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
    ///
    /// # Errors
    ///
    /// As [`PairQuery::collide`].
    pub fn collide_into(
        &mut self,
        pose_a: &Pose,
        pose_b: &Pose,
        options: &CollideOptions,
        result: &mut CollideResult,
    ) -> Result<(), QueryError> {
        let context = &mut self.context;
        self.trees
            .collide_into(pose_a, pose_b, options, context, result)
    }

    /// The distance between the surfaces with its closest points, exact or within the
    /// errors of `options`, up to [`DistanceOptions::max_distance`].
    ///
    /// # Errors
    ///
    /// [`QueryError::BadOption`] for an error allowance or maximum distance out of range;
    /// [`QueryError::CorruptTree`] when a tree's nodes are inconsistent.
    pub fn distance(
        &mut self,
        pose_a: &Pose,
        pose_b: &Pose,
        options: &DistanceOptions,
    ) -> Result<DistanceResult, QueryError> {
        self.trees
            .distance(pose_a, pose_b, options, &mut self.context)
    }

    /// Whether the surfaces come closer than [`ToleranceOptions::tolerance`], stopping as
    /// soon as it knows.
    ///
    /// # Errors
    ///
    /// [`QueryError::BadOption`] for a negative or non-finite tolerance;
    /// [`QueryError::CorruptTree`] when a tree's nodes are inconsistent.
    pub fn within(
        &mut self,
        pose_a: &Pose,
        pose_b: &Pose,
        options: &ToleranceOptions,
    ) -> Result<ToleranceResult, QueryError> {
        self.trees
            .within(pose_a, pose_b, options, &mut self.context)
    }

    /// The span: the largest distance between a point of A and a point of B.
    ///
    /// # Errors
    ///
    /// [`QueryError::CorruptTree`] when a tree's nodes are inconsistent.
    pub fn span(
        &mut self,
        pose_a: &Pose,
        pose_b: &Pose,
        options: &SpanOptions,
    ) -> Result<SpanResult, QueryError> {
        self.trees.span(pose_a, pose_b, options, &mut self.context)
    }
}

/// The queries of [`details`] on two typed views, behind one indirect call.
trait TypedPair {
    fn collide_into(
        &self,
        pose_a: &Pose,
        pose_b: &Pose,
        options: &CollideOptions,
        context: &mut QueryContext,
        result: &mut CollideResult,
    ) -> Result<(), QueryError>;
    fn distance(
        &self,
        pose_a: &Pose,
        pose_b: &Pose,
        options: &DistanceOptions,
        context: &mut QueryContext,
    ) -> Result<DistanceResult, QueryError>;
    fn within(
        &self,
        pose_a: &Pose,
        pose_b: &Pose,
        options: &ToleranceOptions,
        context: &mut QueryContext,
    ) -> Result<ToleranceResult, QueryError>;
    fn span(
        &self,
        pose_a: &Pose,
        pose_b: &Pose,
        options: &SpanOptions,
        context: &mut QueryContext,
    ) -> Result<SpanResult, QueryError>;
}

/// A's and B's trees typed as volume `B`.
struct Views<'f, B: BoundingVolume> {
    a: TreeView<'f, B>,
    b: TreeView<'f, B>,
}

impl<B: BoundingVolume> TypedPair for Views<'_, B> {
    fn collide_into(
        &self,
        pose_a: &Pose,
        pose_b: &Pose,
        options: &CollideOptions,
        context: &mut QueryContext,
        result: &mut CollideResult,
    ) -> Result<(), QueryError> {
        details::collide_into(&self.a, pose_a, &self.b, pose_b, options, context, result)
    }

    fn distance(
        &self,
        pose_a: &Pose,
        pose_b: &Pose,
        options: &DistanceOptions,
        context: &mut QueryContext,
    ) -> Result<DistanceResult, QueryError> {
        details::distance(&self.a, pose_a, &self.b, pose_b, options, context)
    }

    fn within(
        &self,
        pose_a: &Pose,
        pose_b: &Pose,
        options: &ToleranceOptions,
        context: &mut QueryContext,
    ) -> Result<ToleranceResult, QueryError> {
        details::within(&self.a, pose_a, &self.b, pose_b, options, context)
    }

    fn span(
        &self,
        pose_a: &Pose,
        pose_b: &Pose,
        options: &SpanOptions,
        context: &mut QueryContext,
    ) -> Result<SpanResult, QueryError> {
        details::span(&self.a, pose_a, &self.b, pose_b, options, context)
    }
}

/// Types both files' views as the volume type they store (checked equal by the caller).
struct Typing<'f> {
    a: &'f ObbtFile,
    b: &'f ObbtFile,
}

impl<'f> VolumeVisitor for Typing<'f> {
    type Output = Result<Box<dyn TypedPair + Send + Sync + 'f>, QueryError>;

    fn visit<B: BoundingVolume>(self) -> Self::Output {
        Ok(Box::new(Views::<'f, B> {
            a: self.a.view()?,
            b: self.b.view()?,
        }))
    }
}
