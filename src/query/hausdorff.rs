//! The Hausdorff distance between two posed models (dissertation App. A.3, §8.0.4):
//! h(A, B) = max over points a of A of the distance from a to B, bounded from both sides.
//!
//! A's surface is cut into pieces, starting from its triangles. A piece's corners, each
//! with its distance to B found by a closest-point descent of B's tree, give a lower bound
//! on h (any surface point does). Its upper bound is convexity: the distance to one
//! triangle `t` of B is a convex function, so over the piece it is largest at a corner, and
//! `max over the piece of d(a, B) <= max over corners of d(corner, t)` for every `t`; the
//! candidates are the triangles nearest the piece's corners. Pieces whose upper bound
//! cannot raise the best lower bound (within the error asked) are dropped; the others are
//! split in four at their edges' midpoints, largest upper bound first. Where one triangle
//! of B is nearest a whole piece the bounds meet, so most pieces end at once; where the
//! farthest point sits on the boundary between two triangles' regions, the bounds close
//! linearly with the piece's size and splitting stops at a floor, the gap left reported.

use super::closest::{descend, Found, Waiting, WARM_RUN};
use super::engine::triangle;
use super::triangle::closest_point_on_triangle;
use super::{QueryError, Side, Work};
use crate::bv::BoundingVolume;
use crate::format::{ObbtFile, TreeVisitor};
use crate::pose::Pose;
use crate::tree::TreeView;
use nalgebra::Vector3;
use rayon::prelude::*;
use std::cmp::Ordering;
use std::collections::{BinaryHeap, HashMap};

/// How a Hausdorff distance is asked.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct HausdorffOptions {
    /// Relative error allowed (`>= 0`): the answer `h` and the true `h*` satisfy
    /// `h <= h* <= h (1 + rel_err)` (or within `abs_err`, whichever is larger). With both
    /// 0 (the default) the answer is exact to f64 rounding, but see
    /// [`HausdorffResult::upper_bound`].
    pub rel_err: f64,
    /// Absolute error allowed (`>= 0`, world units).
    pub abs_err: f64,
    /// Also measure h(B, A) and answer the larger: the symmetric Hausdorff distance.
    pub symmetric: bool,
}

/// Which one-sided distance a [`HausdorffResult`] is.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum HausdorffDirection {
    /// h(A, B): the witness lies on A, its closest point on B.
    AToB,
    /// h(B, A) (only with [`HausdorffOptions::symmetric`]): the witness lies on B.
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
    /// error asked above `distance` (with errors 0, a few ulps of the models' coordinates:
    /// exact to f64 rounding), or above it by the floor of the refinement where the
    /// farthest point lies where two triangles of the other model are equally near.
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
    /// Work done: the closest-point descents' volume and triangle tests, plus the
    /// triangle tests of the upper bounds; `nodes_visited` also counts the pieces split.
    pub work: Work,
}

/// Pieces are not split below this fraction of their model's bounding-box diagonal: there
/// the bounds of a piece on a boundary between two triangles' regions are as close as
/// splitting can make them in reasonable time.
const FLOOR: f64 = 1.0 / (1u64 << 24) as f64;

/// The Hausdorff distance from `a` posed by `pose_a` to `b` posed by `pose_b` (world
/// frame): the largest distance from a point of A's surface to B's, with the point where
/// it is reached and its closest point on B; with [`HausdorffOptions::symmetric`] the
/// larger of h(A, B) and h(B, A). The two trees may be of any volume types and precisions.
///
/// # Errors
///
/// - [`QueryError::BadOption`] for a negative or non-finite `rel_err` or `abs_err`.
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
    let ab = one_sided(a, pose_a, b, pose_b, options)?;
    let forward = HausdorffResult {
        distance: ab.distance,
        upper_bound: ab.upper_bound,
        direction: HausdorffDirection::AToB,
        point_a: ab.from_point,
        point_b: ab.to_point,
        tri_a: ab.from_triangle,
        tri_b: ab.to_triangle,
        work: ab.work,
    };
    if !options.symmetric {
        return Ok(forward);
    }
    let ba = one_sided(b, pose_b, a, pose_a, options)?;
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
    work: Work,
}

fn one_sided(
    from: &ObbtFile,
    pose_from: &Pose,
    to: &ObbtFile,
    pose_to: &Pose,
    options: &HausdorffOptions,
) -> Result<OneSided, QueryError> {
    /// `from`'s triangles (with their input ids) in `to`'s model frame.
    struct Triangles {
        from_to_to: Pose,
    }
    impl TreeVisitor for Triangles {
        type Output = Result<Vec<([Vector3<f64>; 3], u32)>, QueryError>;
        fn visit<B: BoundingVolume>(self, tree: TreeView<'_, B>) -> Self::Output {
            let faces = u32::try_from(tree.faces().len()).map_err(|_| QueryError::CorruptTree {
                which: Side::A,
                what: "more faces than ids",
            })?;
            (0..faces)
                .map(|face| {
                    let t = triangle(&tree, face, Some(&self.from_to_to), Side::A)?;
                    Ok((t, super::source_id(&tree, face, Side::A)?))
                })
                .collect()
        }
    }
    let triangles = from.visit(Triangles {
        from_to_to: Pose::relative(pose_to, pose_from),
    })??;
    /// The bounds, run on `to`'s typed tree.
    struct Bounds<'q> {
        triangles: &'q [([Vector3<f64>; 3], u32)],
        options: &'q HausdorffOptions,
    }
    impl TreeVisitor for Bounds<'_> {
        type Output = Result<Local, QueryError>;
        fn visit<B: BoundingVolume>(self, tree: TreeView<'_, B>) -> Self::Output {
            bound(&tree, self.triangles, self.options)
        }
    }
    let local = to.visit(Bounds {
        triangles: &triangles,
        options,
    })??;
    Ok(OneSided {
        distance: local.distance,
        upper_bound: local.upper_bound,
        from_point: pose_to.apply(&local.from_point).into(),
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

/// The nearest point of `to` to `p`, the search started from `seed`.
fn near<B: BoundingVolume>(
    tree: &TreeView<'_, B>,
    p: &Vector3<f64>,
    seed: Option<u32>,
    heap: &mut BinaryHeap<Waiting>,
    work: &mut Work,
) -> Result<Near, QueryError> {
    let Found {
        best,
        distance,
        work: done,
    } = descend(tree, p, f64::INFINITY, seed, heap)?;
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

/// A point of `from`'s surface measured on the way (a piece's centroid), and what is
/// nearest it.
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

impl PartialEq for Piece {
    fn eq(&self, other: &Self) -> bool {
        self.cmp(other) == Ordering::Equal
    }
}
impl Eq for Piece {}
impl PartialOrd for Piece {
    fn partial_cmp(&self, other: &Self) -> Option<Ordering> {
        Some(self.cmp(other))
    }
}
impl Ord for Piece {
    fn cmp(&self, other: &Self) -> Ordering {
        self.upper.total_cmp(&other.upper)
    }
}

/// The convexity bound of a piece for one candidate triangle `face` of B: the largest
/// distance from a corner to it (over the piece, the distance to one triangle is largest
/// at a corner).
fn candidate_bound<B: BoundingVolume>(
    tree: &TreeView<'_, B>,
    corners: &[Vector3<f64>; 3],
    near: &[Near; 3],
    face: u32,
    work: &mut Work,
) -> Result<f64, QueryError> {
    let t = triangle(tree, face, None, Side::B)?;
    let mut worst: f64 = 0.0;
    for (corner, n) in corners.iter().zip(near) {
        // The nearest triangle's distance is known.
        let d = if n.face == face {
            n.distance
        } else {
            work.tri_separated += 1;
            let (q, _) = closest_point_on_triangle(corner, &t);
            (corner - q).norm()
        };
        worst = worst.max(d);
    }
    Ok(worst)
}

/// The convexity bound of a piece over the candidate triangles nearest its corners: the
/// least of their [`candidate_bound`]s.
fn upper_bound<B: BoundingVolume>(
    tree: &TreeView<'_, B>,
    corners: &[Vector3<f64>; 3],
    near: &[Near; 3],
    work: &mut Work,
) -> Result<f64, QueryError> {
    let mut best = f64::INFINITY;
    for (k, n) in near.iter().enumerate() {
        if near.iter().take(k).all(|m| m.face != n.face) {
            best = best.min(candidate_bound(tree, corners, near, n.face, work)?);
        }
    }
    Ok(best)
}

/// A piece's bound, and its centroid with what is nearest it when the corners' candidates
/// alone leave the bound above `threshold`: the triangle nearest the middle often bounds a
/// piece whose corners each see another (a corner of A shared by several triangles of B).
fn bounded_piece<B: BoundingVolume>(
    tree: &TreeView<'_, B>,
    corners: [Vector3<f64>; 3],
    near: [Near; 3],
    triangle_id: u32,
    threshold: f64,
    (heap, work): (&mut BinaryHeap<Waiting>, &mut Work),
) -> Result<(Piece, Option<Measured>), QueryError> {
    let mut upper = upper_bound(tree, &corners, &near, work)?;
    let mut middle = None;
    if upper > threshold {
        let c = (corners[0] + corners[1] + corners[2]) / 3.0;
        let n = self::near(tree, &c, Some(near[0].face), heap, work)?;
        // (A corner's triangle is bounded already.)
        if near.iter().all(|m| m.face != n.face) {
            upper = upper.min(candidate_bound(tree, &corners, &near, n.face, work)?);
        }
        middle = Some((c, n));
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

fn bound<B: BoundingVolume>(
    tree: &TreeView<'_, B>,
    triangles: &[([Vector3<f64>; 3], u32)],
    options: &HausdorffOptions,
) -> Result<Local, QueryError> {
    // Corners shared by triangles are measured once.
    let mut index: HashMap<[u64; 3], usize> = HashMap::new();
    let mut vertices: Vec<Vector3<f64>> = Vec::new();
    let corners: Vec<[usize; 3]> = triangles
        .iter()
        .map(|(t, _)| {
            t.map(|p| {
                *index.entry(p.map(f64::to_bits).into()).or_insert_with(|| {
                    vertices.push(p);
                    vertices.len() - 1
                })
            })
        })
        .collect();
    let (lo, hi) = vertices.iter().fold(
        (
            Vector3::repeat(f64::INFINITY),
            Vector3::repeat(f64::NEG_INFINITY),
        ),
        |(lo, hi), p| (lo.inf(p), hi.sup(p)),
    );
    let floor = FLOOR * (hi - lo).norm();
    // Distances between points of this magnitude are only known to a few ulps of it:
    // bounds that close to each other are exact to f64 rounding.
    let rounding = 8.0 * f64::EPSILON * lo.abs().sup(&hi.abs()).max();
    // Every vertex, in runs seeded as closest points are.
    let measured: Vec<Vec<(Near, Work)>> = vertices
        .par_chunks(WARM_RUN)
        .map_init(BinaryHeap::new, |heap, run| {
            let mut seed = None;
            run.iter()
                .map(|p| {
                    let mut work = Work::default();
                    let n = near(tree, p, seed, heap, &mut work)?;
                    seed = Some(n.face);
                    Ok((n, work))
                })
                .collect::<Result<Vec<_>, QueryError>>()
        })
        .collect::<Result<_, QueryError>>()?;
    let mut work = Work::default();
    let mut nearest = Vec::with_capacity(vertices.len());
    for (n, w) in measured.into_iter().flatten() {
        work += w;
        nearest.push(n);
    }
    // The farthest vertex is the first lower bound.
    let mut witness: Option<Witness> = None;
    for ((t, id), c) in triangles.iter().zip(&corners) {
        for (k, &v) in c.iter().enumerate() {
            if let (Some(n), Some(p)) = (nearest.get(v), t.get(k)) {
                if witness.is_none_or(|w| n.distance > w.near.distance) {
                    witness = Some(Witness {
                        point: *p,
                        near: *n,
                        triangle: *id,
                    });
                }
            }
        }
    }
    let Some(mut witness) = witness else {
        return Err(QueryError::CorruptTree {
            which: Side::A,
            what: "a tree without triangles",
        });
    };
    let enough = |lower: f64| lower + (options.rel_err * lower).max(options.abs_err).max(rounding);
    // Every triangle's bound; those that might raise the lower bound are refined.
    let first = enough(witness.near.distance);
    let bounded: Vec<(Piece, Option<Measured>, Work)> = triangles
        .par_iter()
        .zip(&corners)
        .map_init(BinaryHeap::new, |heap, ((t, id), c)| {
            let mut work = Work::default();
            let [Some(n0), Some(n1), Some(n2)] = c.map(|v| nearest.get(v).copied()) else {
                return Err(QueryError::CorruptTree {
                    which: Side::A,
                    what: "a corner without its distance",
                });
            };
            let (p, middle) = bounded_piece(tree, *t, [n0, n1, n2], *id, first, (heap, &mut work))?;
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
    let mut upper: f64 = witness.near.distance;
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
    while let Some(piece) = heap.pop() {
        if piece.upper <= enough(witness.near.distance) {
            // No piece left can raise the lower bound by more than the error allowed.
            upper = upper.max(piece.upper);
            break;
        }
        let [p0, p1, p2] = piece.corners;
        let longest = (p1 - p0).norm().max((p2 - p1).norm()).max((p0 - p2).norm());
        if longest <= floor {
            upper = upper.max(piece.upper);
            continue;
        }
        work.nodes_visited += 1;
        let [n0, n1, n2] = piece.near;
        let mut midpoint = |a: &Vector3<f64>, b: &Vector3<f64>, seed: &Near| {
            let m = (a + b) / 2.0;
            near(tree, &m, Some(seed.face), &mut scratch, &mut work).map(|n| (m, n))
        };
        let (m01, k01) = midpoint(&p0, &p1, &n0)?;
        let (m12, k12) = midpoint(&p1, &p2, &n1)?;
        let (m20, k20) = midpoint(&p2, &p0, &n2)?;
        for (m, k) in [(m01, k01), (m12, k12), (m20, k20)] {
            if k.distance > witness.near.distance {
                witness = Witness {
                    point: m,
                    near: k,
                    triangle: piece.triangle,
                };
            }
        }
        for (corners, near) in [
            ([p0, m01, m20], [n0, k01, k20]),
            ([m01, p1, m12], [k01, n1, k12]),
            ([m20, m12, p2], [k20, k12, n2]),
            ([m01, m12, m20], [k01, k12, k20]),
        ] {
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
