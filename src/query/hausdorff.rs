//! The Hausdorff distance between two posed models (dissertation App. A.3, §8.0.4):
//! h(A, B) = max over points a of A of the distance from a to B, bounded from both sides.
//!
//! A's surface is cut into pieces, starting from its triangles. A piece's corners, each
//! with its distance to B found by a closest-point descent of B's tree, give a lower bound
//! on h (any surface point does). Its upper bound is convexity: the distance to one
//! triangle `t` of B is a convex function, so at a point of the piece it is at most the
//! corners' distances to `t` interpolated there, and `d(a, B)` at most the least of these
//! planes over the candidate triangles (those nearest the corners and points measured
//! inside); the envelope's peak over the piece is exact ([`interpolated_envelope`]). Pieces
//! whose upper bound cannot raise the best lower bound (within the error asked) are
//! dropped; the others are split in four at their edges' midpoints, largest upper bound
//! first. Where one triangle of B is nearest a whole piece, or two faces of B meet at a
//! ridge across it, the bounds meet once the peak is measured, so most pieces end at once;
//! where B's nearest part curves (an edge or a corner) they close quadratically with the
//! piece's size, helped by a second bound, the distance to the nearest of the points of B
//! measured ([`point_bound`]). With an error asked, splitting goes on until it is met; exact
//! answers stop at a floor where the peak of that bound is measured, the gap left reported.
//!
//! Before any piece, A's own tree culls: a sample of A's vertices gives a first lower
//! bound, and a node whose ball (centre's distance to B plus radius) cannot exceed it is
//! dropped with its triangles, whose vertices are then never measured. Far apart models,
//! where the distance varies little over A, lose most of their nodes near the root.

use super::closest::WARM_RUN;
use super::engine::{corrupt, triangle};
use super::index::point::Found;
use super::index::{Child, SurfaceIndex};
use super::triangle::{closest_point_on_triangle, convex_union, Triangle};
use super::{check_reach, QueryError, Side, Work};
use crate::bv::BoundingVolume;
use crate::format::{ObbtFile, TreeVisitor};
use crate::pose::Pose;
use crate::real::point_to_f64;
use crate::tree::{NodeDefect, NodeKind, TreeView};
use nalgebra::Vector3;
use rayon::prelude::*;
use std::cmp::Ordering;
use std::collections::BinaryHeap;

/// How a Hausdorff distance is asked.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct HausdorffOptions {
    /// Relative error allowed (`>= 0`): the answer `h` and the true `h*` satisfy
    /// `h <= h* <= h (1 + rel_err)` (or within `abs_err`, whichever is larger). With both
    /// 0 (the default) the answer is exact to f64 rounding where the bounds close, and
    /// splitting stops at a floor (2⁻¹⁶ of the measured model's diagonal) where they close
    /// only slowly (B's nearest part curving, near-coincident surfaces); the same floor
    /// stays for an allowance below 2⁻²⁴ of that diagonal (a relative error of an h about
    /// 0). [`HausdorffResult::upper_bound`] is always what is proven.
    pub rel_err: f64,
    /// Absolute error allowed (`>= 0`, world units).
    pub abs_err: f64,
    /// Also measure h(B, A) and answer the larger: the symmetric Hausdorff distance.
    pub symmetric: bool,
    /// Where an earlier query of the same two trees was answered
    /// ([`HausdorffResult::warm_start`]): measured first, it bounds h from below from the
    /// start, so that more of the measured model is culled at once when the poses moved
    /// little. It changes the work, never the answer's guarantee.
    pub warm_start: Option<HausdorffWarmStart>,
}

/// The witness of a Hausdorff answer in its own model's frame, to start the next query of
/// the same two trees from ([`HausdorffOptions::warm_start`]).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct HausdorffWarmStart {
    /// Which one-sided distance the witness was for.
    pub direction: HausdorffDirection,
    /// The witness, in its model's frame (A's for [`HausdorffDirection::AToB`], else B's).
    pub point: [f64; 3],
    /// Input-mesh id of the witness's triangle.
    pub triangle: u32,
}

/// Which one-sided distance a [`HausdorffResult`] is.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum HausdorffDirection {
    /// h(A, B): the witness lies on A, its closest point on B.
    AToB,
    /// h(B, A) (only with [`HausdorffOptions::symmetric`], where it is larger than h(A, B):
    /// a tie answers [`HausdorffDirection::AToB`]): the witness lies on B.
    BToA,
}

/// The answer of [`hausdorff`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct HausdorffResult {
    /// The Hausdorff distance found (world units): the distance between `point_a` and
    /// `point_b`, a point of one model and the closest point of the other to it, so the
    /// true distance is at least this.
    pub distance: f64,
    /// A proven bound the true distance does not exceed (rounding aside): at most the
    /// error asked above `distance`, or with errors 0 a few ulps of the models'
    /// coordinates (exact to f64 rounding) where the bounds close before the floor of the
    /// refinement, the gap left at the floor otherwise; an allowance below 2⁻²⁴ of the
    /// diagonal also stops at the floor (see [`HausdorffOptions::rel_err`]).
    pub upper_bound: f64,
    /// Which one-sided distance the witness realises.
    pub direction: HausdorffDirection,
    /// The point of A, world frame (the witness for [`HausdorffDirection::AToB`], the
    /// closest point of A to the witness on B otherwise).
    pub point_a: [f64; 3],
    /// The point of B, world frame.
    pub point_b: [f64; 3],
    /// Input-mesh id of A's triangle holding `point_a`.
    pub tri_a: u32,
    /// Input-mesh id of B's triangle holding `point_b`.
    pub tri_b: u32,
    /// The witness in its model's frame, for [`HausdorffOptions::warm_start`].
    pub warm_start: HausdorffWarmStart,
    /// Work done: the closest-point descents' volume and triangle tests, plus the
    /// triangle tests of the upper bounds; `nodes_visited` also counts A's nodes examined
    /// for culling and the pieces split.
    pub work: Work,
}

/// For exact answers, pieces are not split below this fraction of their model's
/// bounding-box diagonal: there the bounds of a piece on a ridge where B's nearest part
/// curves are about its square apart, and such a ridge across the model costs millions of
/// descents. (At 2⁻²⁴ a fuzzed ridge of a few triangles took half a minute.)
const FLOOR: f64 = 1.0 / (1u64 << 16) as f64;

/// The least error allowed, as a fraction of the measured model's bounding-box diagonal,
/// that splitting goes below [`FLOOR`] to meet (a small `abs_err`, or a small `rel_err` of
/// a small h). The case it is for: near-coincident surfaces triangulated differently have
/// bounds that close only linearly, and h about 0, so a relative error of that is an
/// absolute one too fine to reach.
const FINEST: f64 = 1.0 / (1u64 << 24) as f64;

/// The Hausdorff distance from `a` posed by `pose_a` to `b` posed by `pose_b` (world
/// frame): the largest distance from a point of A's surface to B's, with the point where
/// it is reached and its closest point on B; with [`HausdorffOptions::symmetric`] the
/// larger of h(A, B) and h(B, A). The two trees may be of any volume types and precisions.
///
/// # Errors
///
/// - [`QueryError::BadOption`] for a negative or non-finite `rel_err` or `abs_err`.
/// - [`QueryError::BadInput`] for a vertex of one model posed beyond
///   [`MAX_COORDINATE`](super::MAX_COORDINATE) in the other's frame ("model A vertex"), or a
///   triangle beyond it in its own ("model B triangle"), before any search.
/// - [`QueryError::CorruptTree`] or [`QueryError::Format`] for a damaged, unverified file.
///
/// # Examples
///
/// ```
/// use obbtree::format::ObbtFile;
/// use obbtree::query::{hausdorff, HausdorffOptions, Pose};
///
/// let cow = ObbtFile::open(concat!(env!("CARGO_MANIFEST_DIR"), "/assets/scenes/cow.obbt"))?;
/// let moved = Pose::translation(0.01, 0.0, 0.0);
/// let h = hausdorff(&cow, &Pose::identity(), &cow, &moved, &HausdorffOptions::default())?;
/// // Every point of A has its twin 0.01 away in B, up to rounding.
/// assert!((h.distance - 0.01).abs() < 1e-12 && h.distance <= h.upper_bound);
/// println!("h = {} at {:?} (triangle {})", h.distance, h.point_a, h.tri_a);
/// # Ok::<(), Box<dyn std::error::Error>>(())
/// ```
pub fn hausdorff(
    a: &ObbtFile,
    pose_a: &Pose,
    b: &ObbtFile,
    pose_b: &Pose,
    options: &HausdorffOptions,
) -> Result<HausdorffResult, QueryError> {
    for (name, value) in [("rel_err", options.rel_err), ("abs_err", options.abs_err)] {
        if !(value.is_finite() && value >= 0.0) {
            return Err(QueryError::BadOption {
                name,
                requirement: "finite and at least 0",
                value,
            });
        }
    }
    let seed = |direction| {
        options
            .warm_start
            .filter(|w| w.direction == direction)
            .map(|w| (w.point, w.triangle))
    };
    // Every refusal before any search: each direction's vertices and the model measured.
    let from_a = flatten((a, pose_a), pose_b, Side::B, seed(HausdorffDirection::AToB))?;
    check_model_reach(b, Side::B)?;
    let from_b = if options.symmetric {
        let from_b = flatten((b, pose_b), pose_a, Side::A, seed(HausdorffDirection::BToA))?;
        check_model_reach(a, Side::A)?;
        Some(from_b)
    } else {
        None
    };
    let ab = one_sided(&from_a, pose_a, (b, pose_b), options)?;
    let forward = HausdorffResult {
        distance: ab.distance,
        upper_bound: ab.upper_bound,
        direction: HausdorffDirection::AToB,
        point_a: ab.from_point,
        point_b: ab.to_point,
        tri_a: ab.from_triangle,
        tri_b: ab.to_triangle,
        warm_start: HausdorffWarmStart {
            direction: HausdorffDirection::AToB,
            point: ab.from_model_point,
            triangle: ab.from_triangle,
        },
        work: ab.work,
    };
    let Some(from_b) = from_b else {
        return Ok(forward);
    };
    drop(from_a);
    let ba = one_sided(&from_b, pose_b, (a, pose_a), options)?;
    let mut work = ab.work;
    work += ba.work;
    let upper_bound = ab.upper_bound.max(ba.upper_bound);
    Ok(if ba.distance > ab.distance {
        HausdorffResult {
            distance: ba.distance,
            upper_bound,
            direction: HausdorffDirection::BToA,
            point_a: ba.to_point,
            point_b: ba.from_point,
            tri_a: ba.to_triangle,
            tri_b: ba.from_triangle,
            warm_start: HausdorffWarmStart {
                direction: HausdorffDirection::BToA,
                point: ba.from_model_point,
                triangle: ba.from_triangle,
            },
            work,
        }
    } else {
        HausdorffResult {
            upper_bound,
            work,
            ..forward
        }
    })
}

/// h(from, to): the witness on `from` and its closest point on `to` (world frame).
struct OneSided {
    distance: f64,
    upper_bound: f64,
    from_point: [f64; 3],
    to_point: [f64; 3],
    from_triangle: u32,
    to_triangle: u32,
    /// The witness in `from`'s model frame.
    from_model_point: [f64; 3],
    work: Work,
}

/// The names of a one-sided search's refusals (see [`super::MAX_COORDINATE`]): of a vertex
/// of `from`, of a triangle of `to`, and what the vertex must be, for `to` the model
/// `to_side`.
fn reach_names(to_side: Side) -> (&'static str, &'static str, &'static str) {
    match to_side {
        Side::B => (
            "model A vertex",
            "model B triangle",
            "coordinates must be within ±1e150 in model B's frame",
        ),
        Side::A => (
            "model B vertex",
            "model A triangle",
            "coordinates must be within ±1e150 in model A's frame",
        ),
    }
}

/// The error naming the first triangle of `model` (model `side`) beyond
/// [`super::MAX_COORDINATE`] in its own frame, where a search toward it measures.
fn check_model_reach(model: &ObbtFile, side: Side) -> Result<(), QueryError> {
    struct Check<'q> {
        model: &'q ObbtFile,
        side: Side,
    }
    impl TreeVisitor for Check<'_> {
        type Output = Result<(), QueryError>;
        fn visit<B: BoundingVolume>(self, tree: TreeView<'_, B>) -> Self::Output {
            let index = self.model.derived(|| SurfaceIndex::build(&tree))?;
            index.check_reach(&tree, self.side, reach_names(self.side).1)
        }
    }
    model.visit(Check { model, side })?
}

/// `from`'s surface in `to`'s model frame (`to` is model `to_side`), checked against
/// [`super::MAX_COORDINATE`], with `seed` (a point of `from` in its model frame, and its
/// triangle's input id) to start its search from.
fn flatten(
    (from, pose_from): (&ObbtFile, &Pose),
    pose_to: &Pose,
    to_side: Side,
    seed: Option<([f64; 3], u32)>,
) -> Result<FromModel, QueryError> {
    /// `from`'s vertices, faces (with their input ids) and nodes, in `to`'s model frame.
    struct Flatten {
        from_to_to: Pose,
        seed: Option<([f64; 3], u32)>,
    }
    impl TreeVisitor for Flatten {
        type Output = Result<FromModel, QueryError>;
        fn visit<B: BoundingVolume>(self, tree: TreeView<'_, B>) -> Self::Output {
            let vertices: Vec<Vector3<f64>> = tree
                .vertices()
                .iter()
                .map(|v| self.from_to_to.apply(&point_to_f64(v).into()))
                .collect();
            let faces: Vec<[usize; 3]> =
                tree.faces().iter().map(|f| f.map(|v| v as usize)).collect();
            if faces.iter().flatten().any(|&v| v >= vertices.len()) {
                return Err(QueryError::CorruptTree {
                    which: Side::A,
                    what: "face or vertex index out of bounds",
                });
            }
            let ids = tree.source_ids().to_vec();
            if ids.len() != faces.len() {
                return Err(QueryError::CorruptTree {
                    which: Side::A,
                    what: "face index out of bounds",
                });
            }
            let nodes = (0..tree.nodes().len())
                .map(|index| {
                    let index = u32::try_from(index).map_err(|_| QueryError::CorruptTree {
                        which: Side::A,
                        what: "more nodes than ids",
                    })?;
                    let kind = tree.node_kind(index).map_err(|d| corrupt(Side::A, d))?;
                    let node = tree
                        .node(index)
                        .ok_or_else(|| corrupt(Side::A, NodeDefect::Missing))?;
                    let (centre, radius) = node.bv.enclosing_ball();
                    Ok(Ball {
                        centre: self.from_to_to.apply(&centre.into()),
                        radius,
                        kind,
                    })
                })
                .collect::<Result<_, QueryError>>()?;
            Ok(FromModel {
                vertices,
                faces,
                ids,
                nodes,
                seed: self
                    .seed
                    .map(|(p, id)| (self.from_to_to.apply(&p.into()), id)),
            })
        }
    }
    let from = from.visit(Flatten {
        from_to_to: Pose::relative(pose_to, pose_from),
        seed,
    })??;
    // Distances are compared squared in `to`'s frame. Only vertices of faces are measured
    // (a mesh file may list others).
    let (from_vertex, _, in_to_frame) = reach_names(to_side);
    let used = from.faces.iter().flatten();
    let posed = used.filter_map(|&v| Some((v, *from.vertices.get(v)?)));
    check_reach(from_vertex, in_to_frame, posed)?;
    Ok(from)
}

/// h(from, to) for `from` flattened into `to`'s frame ([`flatten`]; `pose_from` its pose),
/// `to` checked against [`super::MAX_COORDINATE`] ([`check_model_reach`]).
fn one_sided(
    from: &FromModel,
    pose_from: &Pose,
    (to, pose_to): (&ObbtFile, &Pose),
    options: &HausdorffOptions,
) -> Result<OneSided, QueryError> {
    /// The bounds, run on `to`'s typed tree.
    struct Bounds<'q> {
        to: &'q ObbtFile,
        from: &'q FromModel,
        options: &'q HausdorffOptions,
    }
    impl TreeVisitor for Bounds<'_> {
        type Output = Result<Local, QueryError>;
        fn visit<B: BoundingVolume>(self, tree: TreeView<'_, B>) -> Self::Output {
            let index = self.to.derived(|| SurfaceIndex::build(&tree))?;
            let to = To {
                tree: &tree,
                index: &index,
            };
            bound(&to, self.from, self.options)
        }
    }
    let local = to.visit(Bounds { to, from, options })??;
    let from_point = pose_to.apply(&local.from_point);
    Ok(OneSided {
        distance: local.distance,
        upper_bound: local.upper_bound,
        from_model_point: Pose::relative(pose_from, &Pose::identity())
            .apply(&from_point)
            .into(),
        from_point: from_point.into(),
        to_point: pose_to.apply(&local.to_point).into(),
        from_triangle: local.from_triangle,
        to_triangle: local.to_triangle,
        work: local.work,
    })
}

/// A one-sided answer in `to`'s model frame.
struct Local {
    distance: f64,
    upper_bound: f64,
    from_point: Vector3<f64>,
    to_point: Vector3<f64>,
    from_triangle: u32,
    to_triangle: u32,
    work: Work,
}

/// A point of `from`'s surface and what is nearest it on `to`.
#[derive(Clone, Copy, Debug)]
struct Near {
    distance: f64,
    /// The nearest triangle (a face of `to`'s tree) and its input id.
    face: u32,
    id: u32,
    /// The nearest point, `to`'s model frame.
    point: Vector3<f64>,
}

/// `to`'s tree, and its surface index, which finds the nearest points; read as the tree
/// everywhere else.
struct To<'a, 't, B: BoundingVolume> {
    tree: &'a TreeView<'t, B>,
    index: &'a SurfaceIndex,
}

impl<'t, B: BoundingVolume> std::ops::Deref for To<'_, 't, B> {
    type Target = TreeView<'t, B>;
    fn deref(&self) -> &Self::Target {
        self.tree
    }
}

/// The nearest point of `to` to `p`, the search started from `seed`.
fn near<B: BoundingVolume>(
    tree: &To<'_, '_, B>,
    p: &Vector3<f64>,
    seed: Option<u32>,
    heap: &mut BinaryHeap<Child>,
    work: &mut Work,
) -> Result<Near, QueryError> {
    let Found {
        best,
        distance,
        work: done,
    } = tree
        .index
        .nearest(tree.tree, p, f64::INFINITY, seed, heap)?;
    *work += done;
    let best = best.ok_or(QueryError::CorruptTree {
        which: Side::B,
        what: "a tree without triangles",
    })?;
    Ok(Near {
        distance,
        face: best.face,
        id: best.id,
        point: best.point,
    })
}

/// A point of `from`'s surface measured on the way (inside a piece), and what is nearest
/// it.
type Measured = (Vector3<f64>, Near);

/// A piece of a triangle of `from`: its corners (`to`'s frame) with what is nearest each,
/// the input id of its triangle, and its upper bound.
#[derive(Clone, Copy, Debug)]
struct Piece {
    upper: f64,
    corners: [Vector3<f64>; 3],
    near: [Near; 3],
    triangle: u32,
}

/// The two ends of a piece two of whose corners are one point (a segment, or a point when
/// all three are), and their nearest points on B.
fn segment_ends(piece: &Piece) -> Option<([Vector3<f64>; 2], [Near; 2])> {
    let [p0, p1, p2] = piece.corners;
    let [n0, n1, n2] = piece.near;
    if p0 == p1 {
        Some(([p0, p2], [n0, n2]))
    } else if p1 == p2 || p2 == p0 {
        Some(([p0, p1], [n0, n1]))
    } else {
        None
    }
}

/// Orders a heap entry by its `upper` bound alone (largest first in a `BinaryHeap`).
macro_rules! by_upper {
    ($t:ty) => {
        impl PartialEq for $t {
            fn eq(&self, other: &Self) -> bool {
                self.cmp(other) == Ordering::Equal
            }
        }
        impl Eq for $t {}
        impl PartialOrd for $t {
            fn partial_cmp(&self, other: &Self) -> Option<Ordering> {
                Some(self.cmp(other))
            }
        }
        impl Ord for $t {
            fn cmp(&self, other: &Self) -> Ordering {
                self.upper.total_cmp(&other.upper)
            }
        }
    };
}
by_upper!(Piece);

/// The distances from a piece's corners to one candidate triangle `face` of B (a corner's
/// own nearest triangle's distance is known), and the triangle.
fn corner_distances<B: BoundingVolume>(
    tree: &To<'_, '_, B>,
    corners: &[Vector3<f64>; 3],
    near: &[Near; 3],
    face: u32,
    work: &mut Work,
) -> Result<(Vector3<f64>, Triangle), QueryError> {
    let t = triangle(tree, face, None, Side::B)?;
    let mut distances = Vector3::zeros();
    for ((corner, n), d) in corners.iter().zip(near).zip(distances.iter_mut()) {
        *d = if n.face == face {
            n.distance
        } else {
            work.tri_separated += 1;
            let (q, _) = closest_point_on_triangle(corner, &t);
            (corner - q).norm()
        };
    }
    Ok((distances, t))
}

/// The triangles of B tried as a piece's nearest (those nearest its corners, its centroid
/// and the peak of its nearest-points bound), each with its distances from the corners;
/// and the convex quadrilaterals two of them make, with theirs.
#[derive(Default)]
struct Candidates {
    faces: [u32; Candidates::MAX],
    triangles: [Triangle; Candidates::MAX],
    distances: [Vector3<f64>; Candidates::MAX],
    len: usize,
    /// The corners' distances to convex unions of two candidates (see
    /// [`Candidates::add`]).
    unions: [Vector3<f64>; Candidates::UNIONS],
    unions_len: usize,
}

impl Candidates {
    /// The corners' and the probes'.
    const MAX: usize = 3 + PROBES;

    /// Convex unions kept at most: each adds to the envelope's work, and one is what a
    /// piece lying across an edge inside a flat region of B needs.
    const UNIONS: usize = 3;

    /// Tries `face` too (once; beyond [`Candidates::MAX`] the bound just stays looser).
    ///
    /// Where `face` and a candidate lie in one plane and make a convex quadrilateral (exact
    /// predicates), the distance to that quadrilateral, a part of B, is convex too, and at
    /// a corner it is the nearer of the two triangles' distances: the envelope gets that
    /// plane as well. It closes what no single triangle can: a piece lying on two
    /// triangles of B (coincident surfaces triangulated differently), where each
    /// triangle's distance grows across their shared edge and the bound only shrank with
    /// the piece's size.
    fn add<B: BoundingVolume>(
        &mut self,
        tree: &To<'_, '_, B>,
        (corners, near): (&[Vector3<f64>; 3], &[Near; 3]),
        face: u32,
        work: &mut Work,
    ) -> Result<(), QueryError> {
        if self.faces.iter().take(self.len).any(|&f| f == face) {
            return Ok(());
        }
        let (distances, t) = corner_distances(tree, corners, near, face, work)?;
        let earlier = self.triangles.iter().zip(&self.distances).take(self.len);
        for (other, d) in earlier {
            if convex_union(other, &t) {
                if let Some(slot) = self.unions.get_mut(self.unions_len) {
                    *slot = distances.inf(d);
                    self.unions_len += 1;
                }
            }
        }
        if let (Some(f), Some(tri), Some(d)) = (
            self.faces.get_mut(self.len),
            self.triangles.get_mut(self.len),
            self.distances.get_mut(self.len),
        ) {
            *f = face;
            *tri = t;
            *d = distances;
            self.len += 1;
        }
        Ok(())
    }

    /// The corners' distances to every candidate and every convex union kept.
    fn planes(&self) -> impl Iterator<Item = &Vector3<f64>> {
        let candidates = self.distances.iter().take(self.len);
        candidates.chain(self.unions.iter().take(self.unions_len))
    }

    /// The convexity bound of the piece and the barycentric coordinates where it peaks:
    /// see [`interpolated_envelope`].
    fn bound(&self) -> (f64, Vector3<f64>) {
        let mut planes = [Vector3::zeros(); Candidates::MAX + Candidates::UNIONS];
        let mut n = 0;
        for (slot, d) in planes.iter_mut().zip(self.planes()) {
            *slot = *d;
            n += 1;
        }
        interpolated_envelope(planes.get(..n).unwrap_or_default())
    }

    /// The convexity bound where it may decide the piece, else a cheaper, looser one at
    /// most `threshold` off: the least over planes of their largest corner distance
    /// (which the envelope never exceeds) when that is already within `threshold`.
    fn bound_against(&self, threshold: f64) -> f64 {
        let loose = self.planes().map(|d| d.max()).fold(f64::INFINITY, f64::min);
        if loose <= threshold {
            loose
        } else {
            self.bound().0
        }
    }
}

/// The convexity bound of a piece from its corners' distances to some convex parts `t` of
/// B, triangles or two-triangle quadrilaterals (`distances[t]`, one per corner). The
/// distance to a convex set is convex, so at the
/// point of barycentric coordinates `λ` it is at most `λ · distances[t]`, and the distance
/// to B at most the least of these planes. That lower envelope is concave and piecewise
/// linear, so its largest value over the piece is at a vertex of its pieces: a corner,
/// where two planes cross on an edge, or where three meet inside, all of which are tried.
/// Where the nearest triangle changes inside the piece between two faces of B (a ridge),
/// the planes are the distances themselves and the bound is exact at any size; the
/// largest over corners of one triangle's distances, the bound before, closed only linearly.
fn interpolated_envelope(distances: &[Vector3<f64>]) -> (f64, Vector3<f64>) {
    let at = |l: &Vector3<f64>| {
        distances
            .iter()
            .map(|d| d.dot(l))
            .fold(f64::INFINITY, f64::min)
    };
    let (x, y, z) = (Vector3::x(), Vector3::y(), Vector3::z());
    let mut best = (at(&x), x);
    let mut offer = |l: Vector3<f64>| {
        let e = at(&l);
        if e > best.0 {
            best = (e, l);
        }
    };
    offer(y);
    offer(z);
    let edges = [(x, y), (y, z), (z, x)];
    for (s, ds) in distances.iter().enumerate() {
        for (t, dt) in distances.iter().enumerate().skip(s + 1) {
            let gap = ds - dt;
            for (e, f) in &edges {
                let (ge, gf) = (gap.dot(e), gap.dot(f));
                if (ge > 0.0 && gf < 0.0) || (ge < 0.0 && gf > 0.0) {
                    let u = ge / (ge - gf);
                    offer(e * (1.0 - u) + f * u);
                }
            }
            for du in distances.iter().skip(t + 1) {
                // Where the three planes meet: `gap · λ = 0`, `other · λ = 0` with
                // `λ.z = 1 - λ.x - λ.y`, two equations in `λ.x`, `λ.y` (Cramer's rule).
                let other = ds - du;
                let row = |g: &Vector3<f64>| (g.x - g.z, g.y - g.z, -g.z);
                let ((a, b, c), (d, e, f)) = (row(&gap), row(&other));
                let det = a * e - b * d;
                if det != 0.0 {
                    let (x, y) = ((c * e - b * f) / det, (a * f - c * d) / det);
                    let l = Vector3::new(x, y, 1.0 - x - y);
                    if l.iter().all(|&v| v >= 0.0) {
                        offer(l);
                    }
                }
            }
        }
    }
    best
}

/// The nearest-points bound of a piece: no point `x` of it is farther from B than from the
/// nearest of the points `q` of B measured (`d(x, B) <= min_i |x - q_i|`), and that
/// envelope's largest value over the piece is found exactly. Over the part of the piece
/// nearest one `q_i` the envelope is that point's distance, convex, so it peaks at a vertex
/// of that part: a corner of the piece, where an edge crosses the bisector of two points,
/// or where the bisectors of three points cross the piece's plane. It helps where B's
/// nearest part curves (an edge or a corner, whose distance the convexity bound
/// overestimates between corners): a point moved by `s` along a face of B gets farther
/// from the measured point by about `s² / 2d`, not `s`. Also returns where the envelope
/// peaks: near where the true distance peaks, the point measured at the floor.
fn point_bound(corners: &[Vector3<f64>; 3], points: &[Vector3<f64>]) -> (f64, Vector3<f64>) {
    let envelope = |x: &Vector3<f64>| {
        points
            .iter()
            .map(|q| (x - q).norm())
            .fold(f64::INFINITY, f64::min)
    };
    let mut best = (envelope(&corners[0]), corners[0]);
    let mut offer = |x: Vector3<f64>| {
        let e = envelope(&x);
        if e > best.0 {
            best = (e, x);
        }
    };
    offer(corners[1]);
    offer(corners[2]);
    let pairs = || (0..points.len()).flat_map(move |i| (i + 1..points.len()).map(move |j| (i, j)));
    // The bisector of `q_i` and `q_j`: the plane through their middle across `q_j - q_i`.
    let bisector = |i: usize, j: usize| {
        let (qi, qj) = (points.get(i)?, points.get(j)?);
        Some(((qi + qj) / 2.0, qj - qi))
    };
    for k in 0..3 {
        let (Some(a), Some(b)) = (corners.get(k), corners.get((k + 1) % 3)) else {
            continue;
        };
        for (i, j) in pairs() {
            let Some((m, w)) = bisector(i, j) else {
                continue;
            };
            let along = (b - a).dot(&w);
            if along != 0.0 {
                let t = (m - a).dot(&w) / along;
                if (0.0..=1.0).contains(&t) {
                    offer(a + (b - a) * t);
                }
            }
        }
    }
    let [c0, c1, c2] = corners;
    let normal = (c1 - c0).cross(&(c2 - c0));
    if normal != Vector3::zeros() {
        for (i, j) in pairs() {
            for k in j + 1..points.len() {
                let (Some((m1, w1)), Some((m2, w2))) = (bisector(i, j), bisector(i, k)) else {
                    continue;
                };
                let rows = nalgebra::Matrix3::from_rows(&[
                    w1.transpose(),
                    w2.transpose(),
                    normal.transpose(),
                ]);
                let rhs = Vector3::new(m1.dot(&w1), m2.dot(&w2), c0.dot(&normal));
                let Some(x) = rows.lu().solve(&rhs) else {
                    continue;
                };
                // Inside the piece: on the inner side of each edge (barycentric signs).
                let inside = [(c0, c1), (c1, c2), (c2, c0)]
                    .iter()
                    .all(|&(p, q)| (q - p).cross(&(x - p)).dot(&normal) >= 0.0);
                if inside {
                    offer(x);
                }
            }
        }
    }
    best
}

/// A piece's bound, and the farthest of the points measured inside it with what is nearest
/// it. While the bound is above `threshold`, points inside are measured ([`PROBES`]), each
/// adding its nearest triangle to the candidates and its nearest point to the
/// nearest-points bound: the centroid (the triangle nearest the middle often bounds a piece
/// whose corners each see another: a corner of A shared by several triangles of B), then
/// where the convexity bound peaks (on a ridge between two faces of B, the ridge itself:
/// the distance there is the bound, and measuring it closes the piece). (A third probe at
/// the nearest-points bound's peak cost more descents than it saved on the test meshes.)
fn bounded_piece<B: BoundingVolume>(
    tree: &To<'_, '_, B>,
    corners: [Vector3<f64>; 3],
    near: [Near; 3],
    triangle_id: u32,
    threshold: f64,
    (heap, work): (&mut BinaryHeap<Child>, &mut Work),
) -> Result<(Piece, Option<Measured>), QueryError> {
    let mut candidates = Candidates::default();
    for n in &near {
        candidates.add(tree, (&corners, &near), n.face, work)?;
    }
    // The nearest points of B measured: the corners', then those of the probes.
    let mut points = [near[0].point; 3 + PROBES];
    for (slot, n) in points.iter_mut().zip(&near) {
        *slot = n.point;
    }
    let mut measured = 3;
    let bound = |points: &[Vector3<f64>; 3 + PROBES], measured: usize| {
        point_bound(&corners, points.get(..measured).unwrap_or_default())
    };
    let mut upper = candidates.bound_against(threshold);
    if upper > threshold {
        upper = upper.min(bound(&points, measured).0);
    }
    let mut middle: Option<Measured> = None;
    let mut seed = near[0].face;
    for probe in 0..PROBES {
        if upper <= threshold {
            break;
        }
        let x = if probe == 0 {
            (corners[0] + corners[1] + corners[2]) / 3.0
        } else {
            let (_, l) = candidates.bound();
            corners[0] * l.x + corners[1] * l.y + corners[2] * l.z
        };
        let m = self::near(tree, &x, Some(seed), heap, work)?;
        seed = m.face;
        candidates.add(tree, (&corners, &near), m.face, work)?;
        if let Some(slot) = points.get_mut(measured) {
            *slot = m.point;
            measured += 1;
        }
        upper = upper.min(candidates.bound_against(threshold));
        if upper > threshold {
            upper = upper.min(bound(&points, measured).0);
        }
        if middle.is_none_or(|(_, k)| m.distance > k.distance) {
            middle = Some((x, m));
        }
    }
    let piece = Piece {
        upper,
        corners,
        near,
        triangle: triangle_id,
    };
    Ok((piece, middle))
}

/// The best lower bound so far: the farthest surface point found and what is nearest it.
#[derive(Clone, Copy, Debug)]
struct Witness {
    point: Vector3<f64>,
    near: Near,
    triangle: u32,
}

/// `from`'s surface as the bounds read it, in `to`'s model frame.
struct FromModel {
    /// The vertices.
    vertices: Vec<Vector3<f64>>,
    /// Leaf-ordered faces: indices into `vertices`, checked.
    faces: Vec<[usize; 3]>,
    /// The faces' input ids.
    ids: Vec<u32>,
    /// A point of `from` to measure first (an earlier witness) with its triangle's id.
    seed: Option<(Vector3<f64>, u32)>,
    /// `from`'s tree, the root first.
    nodes: Vec<Ball>,
}

impl FromModel {
    /// Node `index` of `from`'s tree.
    fn node(&self, index: u32) -> Result<&Ball, QueryError> {
        self.nodes
            .get(index as usize)
            .ok_or(QueryError::CorruptTree {
                which: Side::A,
                what: "a child past the node array",
            })
    }
}

/// A node of `from`'s tree: a ball holding its part of the surface, and what it holds.
struct Ball {
    centre: Vector3<f64>,
    radius: f64,
    kind: NodeKind,
}

/// The points measured inside a piece whose corners leave its bound open, the centroid and
/// the convexity bound's peak: see [`bounded_piece`].
const PROBES: usize = 2;

/// One vertex in this many is measured before the nodes of `from` are culled, for a first
/// lower bound; the rest only where their triangles survive.
const SAMPLE_STRIDE: usize = 16;

/// Measures the vertices `which` (indices into `vertices`) into `nearest`, in runs seeded as
/// closest points are.
fn measure<B: BoundingVolume>(
    tree: &To<'_, '_, B>,
    vertices: &[Vector3<f64>],
    which: &[usize],
    nearest: &mut [Option<Near>],
    work: &mut Work,
) -> Result<(), QueryError> {
    let measured: Vec<Vec<(usize, Near, Work)>> = which
        .par_chunks(WARM_RUN)
        .map_init(BinaryHeap::new, |heap, run| {
            let mut seed = None;
            run.iter()
                .filter_map(|&v| vertices.get(v).map(|p| (v, p)))
                .map(|(v, p)| {
                    let mut done = Work::default();
                    let n = near(tree, p, seed, heap, &mut done)?;
                    seed = Some(n.face);
                    Ok((v, n, done))
                })
                .collect::<Result<Vec<_>, QueryError>>()
        })
        .collect::<Result<_, QueryError>>()?;
    for (v, n, done) in measured.into_iter().flatten() {
        *work += done;
        if let Some(slot) = nearest.get_mut(v) {
            *slot = Some(n);
        }
    }
    Ok(())
}

/// A node of `from` waiting in [`cull`]: its upper bound, and the last centre measured on
/// the way to it with what is nearest that centre.
struct Open {
    upper: f64,
    index: u32,
    known: Option<(Vector3<f64>, Near)>,
}

by_upper!(Open);

/// What [`cull`] reads and raises: the vertices measured and the farthest of them.
struct Measures<'m> {
    nearest: &'m mut [Option<Near>],
    witness: &'m mut Witness,
    /// A vertex's witness triangle (input id).
    owner: &'m [u32],
}

/// The nodes of `from` that may hold a point farther from `to` than the lower bound
/// allows (`enough` of it): the faces of the leaves kept (sorted), and the largest upper
/// bound of those culled. A node's points are within its ball, so none is farther from
/// `to` than the distance of the ball's centre plus its radius; a child first tries its
/// parent's measurement moved by the distance between the centres, and a centre is
/// measured only where that can cull (the radius alone within the allowance). Nodes are
/// taken largest bound first, and a leaf reached under a finite bound has its vertices
/// measured at once: the farthest part of `from` comes first and raises the lower bound
/// that culls the rest. (Leaves reached without a bound, as when the models nearly
/// coincide, leave their vertices to the parallel pass after.)
fn cull<B: BoundingVolume>(
    tree: &To<'_, '_, B>,
    from: &FromModel,
    enough: impl Fn(f64) -> f64,
    measures: Measures<'_>,
    work: &mut Work,
) -> Result<(Vec<u32>, f64), QueryError> {
    let Measures {
        nearest,
        witness,
        owner,
    } = measures;
    let mut live = Vec::new();
    let mut culled: f64 = 0.0;
    let mut scratch = BinaryHeap::new();
    let mut open = BinaryHeap::from([Open {
        upper: f64::INFINITY,
        index: 0,
        known: None,
    }]);
    while let Some(Open {
        upper,
        index,
        known,
    }) = open.pop()
    {
        let threshold = enough(witness.near.distance);
        if upper <= threshold {
            // Every node still open is bounded by this one.
            culled = culled.max(upper);
            break;
        }
        let ball = from.node(index)?;
        work.nodes_visited += 1;
        let mut here = known;
        let mut upper = upper;
        if ball.radius < threshold && known.is_none_or(|(c, _)| c != ball.centre) {
            let seed = known.map(|(_, n)| n.face);
            let n = near(tree, &ball.centre, seed, &mut scratch, work)?;
            upper = n.distance + ball.radius;
            if upper <= threshold {
                culled = culled.max(upper);
                continue;
            }
            here = Some((ball.centre, n));
        }
        match &ball.kind {
            NodeKind::Faces(faces) => {
                if upper.is_finite() {
                    let mut seed = here.map(|(_, n)| n.face);
                    for face in faces.clone() {
                        for &v in from.faces.get(face as usize).into_iter().flatten() {
                            let (Some(slot), Some(p)) = (nearest.get_mut(v), from.vertices.get(v))
                            else {
                                continue;
                            };
                            let n = match slot {
                                Some(n) => *n,
                                None => *slot.insert(near(tree, p, seed, &mut scratch, work)?),
                            };
                            seed = Some(n.face);
                            if n.distance > witness.near.distance {
                                *witness = Witness {
                                    point: *p,
                                    near: n,
                                    triangle: owner.get(v).copied().unwrap_or_default(),
                                };
                            }
                        }
                    }
                }
                live.extend(faces.clone());
            }
            // (Children come after their parent: the pass ends on any file.)
            NodeKind::Children(children) => {
                for child in children.clone() {
                    let ball = from.node(child)?;
                    let upper = here.map_or(f64::INFINITY, |(c, n)| {
                        n.distance + (ball.centre - c).norm() + ball.radius
                    });
                    open.push(Open {
                        upper,
                        index: child,
                        known: here,
                    });
                }
            }
        }
    }
    live.sort_unstable();
    Ok((live, culled))
}

/// The farthest measured vertex from `to`: a lower bound on the distance.
fn farthest(nearest: &[Option<Near>], vertices: &[Vector3<f64>], owner: &[u32]) -> Option<Witness> {
    let mut witness: Option<Witness> = None;
    for ((n, p), triangle) in nearest.iter().zip(vertices).zip(owner) {
        if let Some(n) = n {
            if witness.is_none_or(|w| n.distance > w.near.distance) {
                witness = Some(Witness {
                    point: *p,
                    near: *n,
                    triangle: *triangle,
                });
            }
        }
    }
    witness
}

/// The length of piece that is not split further, for a lower bound `lower` on h and the
/// measured model's bounding-box diagonal `diagonal` (both world units): the error allowed,
/// where it lies between [`FINEST`] and [`FLOOR`] of the diagonal, else `FLOOR` of it.
/// Pieces smaller than the error allowed are within it (a point of a piece is no farther
/// from B than a corner is plus its distance to that corner), so with an error asked
/// splitting goes on until the bounds meet it; below `FINEST` of the diagonal (only a
/// relative error, and h about 0), and for exact answers, it stops at `FLOOR`.
fn split_floor(options: &HausdorffOptions, lower: f64, diagonal: f64) -> f64 {
    let allowed = (options.rel_err * lower).max(options.abs_err);
    if allowed >= FINEST * diagonal {
        allowed.min(FLOOR * diagonal)
    } else {
        FLOOR * diagonal
    }
}

fn bound<B: BoundingVolume>(
    tree: &To<'_, '_, B>,
    from: &FromModel,
    options: &HausdorffOptions,
) -> Result<Local, QueryError> {
    let vertices = &from.vertices;
    // A vertex's witness triangle: the first face that has it.
    let mut owner: Vec<u32> = vec![0; vertices.len()];
    for (face, id) in from.faces.iter().zip(&from.ids).rev() {
        for &v in face {
            if let Some(o) = owner.get_mut(v) {
                *o = *id;
            }
        }
    }
    let (lo, hi) = vertices.iter().fold(
        (
            Vector3::repeat(f64::INFINITY),
            Vector3::repeat(f64::NEG_INFINITY),
        ),
        |(lo, hi), p| (lo.inf(p), hi.sup(p)),
    );
    let diagonal = (hi - lo).norm();
    let floor = |lower: f64| split_floor(options, lower, diagonal);
    // Distances between points of this magnitude are only known to a few ulps of it:
    // bounds that close to each other are exact to f64 rounding.
    let rounding = 8.0 * f64::EPSILON * lo.abs().sup(&hi.abs()).max();
    let enough = |lower: f64| lower + (options.rel_err * lower).max(options.abs_err).max(rounding);
    let no_triangles = QueryError::CorruptTree {
        which: Side::A,
        what: "a tree without triangles",
    };
    // A sample of the vertices first: its farthest lets whole nodes of `from` go unmeasured.
    let mut work = Work::default();
    let mut nearest: Vec<Option<Near>> = vec![None; vertices.len()];
    // (In leaf order, where neighbours are near: each run's descents seed the next.)
    let mut seen = vec![false; vertices.len()];
    let in_leaf_order = from
        .faces
        .iter()
        .flatten()
        .filter(|&&v| match seen.get_mut(v) {
            Some(s) if !*s => {
                *s = true;
                true
            }
            _ => false,
        });
    let sample: Vec<usize> = in_leaf_order.step_by(SAMPLE_STRIDE).copied().collect();
    measure(tree, vertices, &sample, &mut nearest, &mut work)?;
    let mut witness = farthest(&nearest, vertices, &owner).ok_or(no_triangles.clone())?;
    if let Some((point, triangle)) = from.seed {
        let n = near(
            tree,
            &point,
            Some(witness.near.face),
            &mut BinaryHeap::new(),
            &mut work,
        )?;
        if n.distance > witness.near.distance {
            witness = Witness {
                point,
                near: n,
                triangle,
            };
        }
    }
    let (live, culled) = cull(
        tree,
        from,
        enough,
        Measures {
            nearest: &mut nearest,
            witness: &mut witness,
            owner: &owner,
        },
        &mut work,
    )?;
    // Then every vertex of the triangles kept.
    let mut queued = vec![false; vertices.len()];
    let mut rest = Vec::new();
    for face in &live {
        for &v in from.faces.get(*face as usize).into_iter().flatten() {
            if nearest.get(v).is_some_and(Option::is_none)
                && !queued.get(v).copied().unwrap_or(true)
            {
                if let Some(q) = queued.get_mut(v) {
                    *q = true;
                }
                rest.push(v);
            }
        }
    }
    measure(tree, vertices, &rest, &mut nearest, &mut work)?;
    let vertex = farthest(&nearest, vertices, &owner).ok_or(no_triangles)?;
    if vertex.near.distance > witness.near.distance {
        witness = vertex;
    }
    // Every kept triangle's bound; those that might raise the lower bound are refined.
    let first = enough(witness.near.distance);
    let bounded: Vec<(Piece, Option<Measured>, Work)> = live
        .par_iter()
        .map_init(BinaryHeap::new, |heap, &face| {
            let mut work = Work::default();
            let corner_lost = QueryError::CorruptTree {
                which: Side::A,
                what: "a corner without its distance",
            };
            let (Some(c), Some(id)) = (from.faces.get(face as usize), from.ids.get(face as usize))
            else {
                return Err(corner_lost);
            };
            let [Some(p0), Some(p1), Some(p2)] = c.map(|v| vertices.get(v).copied()) else {
                return Err(corner_lost);
            };
            let [Some(n0), Some(n1), Some(n2)] = c.map(|v| nearest.get(v).copied().flatten())
            else {
                return Err(corner_lost);
            };
            let (p, middle) = bounded_piece(
                tree,
                [p0, p1, p2],
                [n0, n1, n2],
                *id,
                first,
                (heap, &mut work),
            )?;
            Ok((p, middle, work))
        })
        .collect::<Result<_, QueryError>>()?;
    for (p, middle, _) in &bounded {
        if let Some((c, n)) = middle {
            if n.distance > witness.near.distance {
                witness = Witness {
                    point: *c,
                    near: *n,
                    triangle: p.triangle,
                };
            }
        }
    }
    let mut upper: f64 = witness.near.distance.max(culled);
    let mut heap = BinaryHeap::new();
    for (p, _, w) in bounded {
        work += w;
        if p.upper > enough(witness.near.distance) {
            heap.push(p);
        } else {
            upper = upper.max(p.upper);
        }
    }
    let mut scratch = BinaryHeap::new();
    let longest = |piece: &Piece| {
        let [p0, p1, p2] = piece.corners;
        (p1 - p0).norm().max((p2 - p1).norm()).max((p0 - p2).norm())
    };
    // Pieces that reached the floor: back to splitting if the allowance grows past it.
    let mut parked: Vec<Piece> = Vec::new();
    loop {
        while let Some(piece) = heap.pop() {
            if piece.upper <= enough(witness.near.distance) {
                // No piece left can raise the lower bound by more than the error allowed.
                upper = upper.max(piece.upper);
                heap.clear();
                break;
            }
            if longest(&piece) <= floor(witness.near.distance) {
                // Split no further; where the nearest-points bound peaks is where the distance
                // most likely does (where B's nearest part curves, the corners and middles
                // sampled so far fall short of it).
                let (_, peak) = point_bound(&piece.corners, &piece.near.map(|n| n.point));
                let n = near(
                    tree,
                    &peak,
                    Some(piece.near[0].face),
                    &mut scratch,
                    &mut work,
                )?;
                if n.distance > witness.near.distance {
                    witness = Witness {
                        point: peak,
                        near: n,
                        triangle: piece.triangle,
                    };
                }
                parked.push(piece);
                continue;
            }
            work.nodes_visited += 1;
            let [p0, p1, p2] = piece.corners;
            let [n0, n1, n2] = piece.near;
            let mut midpoint = |a: &Vector3<f64>, b: &Vector3<f64>, seed: &Near| {
                let m = (a + b) / 2.0;
                near(tree, &m, Some(seed.face), &mut scratch, &mut work).map(|n| (m, n))
            };
            let mut offer = |m: Vector3<f64>, k: Near| {
                if k.distance > witness.near.distance {
                    witness = Witness {
                        point: m,
                        near: k,
                        triangle: piece.triangle,
                    };
                }
            };
            let halves;
            let quarters;
            let children: &[([Vector3<f64>; 3], [Near; 3])] = match segment_ends(&piece) {
                // A piece with two corners in one point is a segment, and is halved: the four
                // triangles of a midpoint split would cover its first half three times over,
                // so where the bounds close slowly the pieces would triple at every level.
                Some(([a, b], [na, nb])) => {
                    let (m, k) = midpoint(&a, &b, &na)?;
                    offer(m, k);
                    halves = [([a, a, m], [na, na, k]), ([m, m, b], [k, k, nb])];
                    &halves
                }
                None => {
                    let (m01, k01) = midpoint(&p0, &p1, &n0)?;
                    let (m12, k12) = midpoint(&p1, &p2, &n1)?;
                    let (m20, k20) = midpoint(&p2, &p0, &n2)?;
                    for (m, k) in [(m01, k01), (m12, k12), (m20, k20)] {
                        offer(m, k);
                    }
                    quarters = [
                        ([p0, m01, m20], [n0, k01, k20]),
                        ([m01, p1, m12], [k01, n1, k12]),
                        ([m20, m12, p2], [k20, k12, n2]),
                        ([m01, m12, m20], [k01, k12, k20]),
                    ];
                    &quarters
                }
            };
            for &(corners, near) in children {
                let threshold = enough(witness.near.distance);
                let (child, middle) = bounded_piece(
                    tree,
                    corners,
                    near,
                    piece.triangle,
                    threshold,
                    (&mut scratch, &mut work),
                )?;
                if let Some((c, n)) = middle {
                    if n.distance > witness.near.distance {
                        witness = Witness {
                            point: c,
                            near: n,
                            triangle: piece.triangle,
                        };
                    }
                }
                if child.upper > enough(witness.near.distance) {
                    heap.push(child);
                } else {
                    upper = upper.max(child.upper);
                }
            }
        }
        let lower = witness.near.distance;
        for piece in std::mem::take(&mut parked) {
            match unpark(piece.upper, longest(&piece), enough(lower), floor(lower)) {
                Unpark::Within => upper = upper.max(piece.upper),
                Unpark::Split => heap.push(piece),
                Unpark::Stays => parked.push(piece),
            }
        }
        if heap.is_empty() {
            break;
        }
    }
    for piece in &parked {
        upper = upper.max(piece.upper);
    }
    Ok(Local {
        distance: witness.near.distance,
        upper_bound: upper.max(witness.near.distance),
        from_point: witness.point,
        to_point: witness.near.point,
        from_triangle: witness.triangle,
        to_triangle: witness.near.id,
        work,
    })
}

/// What becomes of a parked piece once the search has a lower bound on h again.
#[derive(Debug, PartialEq, Eq)]
enum Unpark {
    /// Its upper bound is within the error allowed: it only counts toward the upper bound.
    Within,
    /// It is longer than the split floor now is: back to splitting.
    Split,
    /// Still too small to split, and not yet within the allowance.
    Stays,
}

/// The fate of a parked piece whose bound is `upper` and longest edge `longest`, where the
/// search's answer is good enough up to `enough` and pieces are split down to `floor` (all
/// world units). A piece parked under a small allowance (below [`FINEST`] of the diagonal,
/// so split only down to [`FLOOR`] of it) splits on once the lower bound has grown the
/// allowance past `FINEST` and the piece's size.
fn unpark(upper: f64, longest: f64, enough: f64, floor: f64) -> Unpark {
    if upper <= enough {
        Unpark::Within
    } else if longest > floor {
        Unpark::Split
    } else {
        Unpark::Stays
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Pieces are split down to the error allowed where it lies between 2⁻²⁴ and 2⁻¹⁶ of
    /// the diagonal, and to 2⁻¹⁶ of it otherwise: exact answers, allowances above, and
    /// allowances below (a relative error of an h about 0). A diagonal far from 1 tells
    /// each fraction from its inverse.
    #[test]
    fn pieces_split_to_the_allowance_between_two_fractions_of_the_diagonal() {
        let d = 1000.0;
        let absolute = |abs_err| HausdorffOptions {
            abs_err,
            ..HausdorffOptions::default()
        };
        let floor = FLOOR * d;
        assert_eq!(split_floor(&absolute(0.0), 5.0, d), floor);
        for between in [FINEST * d, 1e-6 * d, floor / 2.0] {
            assert_eq!(split_floor(&absolute(between), 5.0, d), between);
        }
        for beyond in [1e-9 * d, FINEST * d / 2.0, floor * 2.0, 0.1 * d] {
            assert_eq!(split_floor(&absolute(beyond), 5.0, d), floor, "{beyond}");
        }
        // A relative error allows that fraction of the lower bound, the larger of the two
        // allowances counting.
        let relative = HausdorffOptions {
            rel_err: 1e-6,
            abs_err: 1e-6,
            ..HausdorffOptions::default()
        };
        assert_eq!(split_floor(&relative, d, d), 1e-6 * d);
        assert_eq!(split_floor(&relative, 1.0, d), floor);
    }

    /// A piece parked while a relative error allowed almost nothing (h about 0, so split
    /// only to `FLOOR` of the diagonal) splits again once the lower bound has grown that
    /// allowance past `FINEST` of the diagonal and past the piece; it is done once its bound
    /// is within the allowance, and stays parked while it is shorter than the floor.
    #[test]
    fn a_parked_piece_splits_again_once_the_allowance_passes_it() {
        let d = 1000.0;
        let options = HausdorffOptions {
            rel_err: 1e-3,
            ..HausdorffOptions::default()
        };
        let floor = |lower| split_floor(&options, lower, d);
        let enough = |lower| lower * (1.0 + options.rel_err);
        let (tiny, grown) = (FINEST * d, FINEST * d * 4.0 / options.rel_err);
        assert_eq!(floor(tiny), FLOOR * d);
        let piece = FLOOR * d / 2.0;
        let bound = grown * 1.01;
        assert_eq!(
            unpark(bound, piece, enough(tiny), floor(tiny)),
            Unpark::Stays
        );
        assert!(floor(grown) < piece);
        assert_eq!(
            unpark(bound, piece, enough(grown), floor(grown)),
            Unpark::Split
        );
        let allowed = enough(grown);
        for within in [grown, allowed] {
            assert_eq!(unpark(within, piece, allowed, floor(grown)), Unpark::Within);
        }
        assert_eq!(
            unpark(bound, floor(grown), enough(grown), floor(grown)),
            Unpark::Stays
        );
    }

    /// The least of the planes at `l`, the function [`interpolated_envelope`] maximises.
    fn least(distances: &[Vector3<f64>], l: &Vector3<f64>) -> f64 {
        distances
            .iter()
            .map(|d| d.dot(l))
            .fold(f64::INFINITY, f64::min)
    }

    /// The envelope's peak is where it says, and no point of a fine barycentric grid is
    /// above it nor, at the grid's spacing, much below: for one to five candidates with
    /// pseudo-random corner distances.
    #[test]
    fn the_envelope_peak_is_the_largest_value_over_the_piece() {
        let mut rng = crate::generate::Rng::new(7);
        let mut next = move || rng.unit();
        const N: u32 = 60;
        for case in 0..300 {
            let count = 1 + case % 5;
            let distances: Vec<Vector3<f64>> = (0..count)
                .map(|_| Vector3::new(next(), next(), next()) * 4.0)
                .collect();
            let (peak, at) = interpolated_envelope(&distances);
            assert!(at.iter().all(|&v| v >= 0.0) && (at.sum() - 1.0).abs() < 1e-12);
            assert!((least(&distances, &at) - peak).abs() < 1e-12, "case {case}");
            let mut sampled = f64::NEG_INFINITY;
            for i in 0..=N {
                for j in 0..=N - i {
                    let l = Vector3::new(f64::from(i), f64::from(j), f64::from(N - i - j))
                        / f64::from(N);
                    sampled = sampled.max(least(&distances, &l));
                }
            }
            assert!(
                sampled <= peak + 1e-12,
                "case {case}: {sampled} above {peak}"
            );
            // Each plane's slope is at most 4 per unit of λ; a grid point is within 1/N.
            assert!(
                peak <= sampled + 8.0 / f64::from(N),
                "case {case}: {peak} vs {sampled}"
            );
        }
    }

    /// Two faces' distances crossing inside the piece: the peak is where they are equal,
    /// below both planes' largest corner values (the bound before this one).
    #[test]
    fn two_crossing_planes_peak_on_their_crossing() {
        let distances = [Vector3::new(0.0, 2.0, 1.0), Vector3::new(2.0, 0.0, 1.0)];
        let (peak, at) = interpolated_envelope(&distances);
        assert!((peak - 1.0).abs() < 1e-15, "{peak} at {at:?}");
        assert!((at.x - at.y).abs() < 1e-15);
        // Three planes equal at the centroid, lower at every corner.
        let three = [
            Vector3::new(0.0, 3.0, 3.0),
            Vector3::new(3.0, 0.0, 3.0),
            Vector3::new(3.0, 3.0, 0.0),
        ];
        let (peak, at) = interpolated_envelope(&three);
        assert!((peak - 2.0).abs() < 1e-12, "{peak} at {at:?}");
        assert!((at - Vector3::repeat(1.0 / 3.0)).norm() < 1e-12);
    }
}
