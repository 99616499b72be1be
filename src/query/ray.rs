//! Rays against one posed model: the closest hit, any hit, or every hit, by a front-to-back
//! descent of the model's surface index ([`super::index`]) pruned by where the ray enters
//! each box.

use super::engine::corrupt;
use super::index::ray::Slabs;
use super::index::{Child, SurfaceIndex, WIDTH};
use super::triangle::ray::LANES;
use super::triangle::{RaySpace, Triangle};
use super::{source_id, QueryError, Side, Work};
use crate::bv::BoundingVolume;
use crate::format::{ObbtFile, TreeVisitor};
use crate::pose::Pose;
use crate::tree::{NodeDefect, TreeView};
use nalgebra::Vector3;
use rayon::prelude::*;
use std::sync::Mutex;

/// A ray: the points `origin + t · direction` for `t ≥ 0`, world frame.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Ray {
    /// Where it starts (world units).
    pub origin: [f64; 3],
    /// Where it goes: any non-zero length. `t` counts in lengths of it, so with a unit
    /// direction `t` is the distance from the origin.
    pub direction: [f64; 3],
}

impl Ray {
    /// The ray's point at parameter `t`.
    pub fn at(&self, t: f64) -> [f64; 3] {
        let [(o0, d0), (o1, d1), (o2, d2)] = crate::arr3::zip(self.origin, self.direction);
        [o0 + t * d0, o1 + t * d1, o2 + t * d2]
    }
}

/// Which hit a ray query looks for.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub enum RayMode {
    /// The hit of smallest `t` (of smallest input triangle id among equal `t`): what a
    /// camera, a bullet or a depth sensor sees.
    #[default]
    Closest,
    /// Whether anything is hit up to `t_max`, and one hit that shows it (line of sight,
    /// shadow rays): the descent stops at the first hit found.
    Any,
}

/// How a ray query is asked.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RayOptions {
    /// Which hit is wanted.
    pub mode: RayMode,
    /// Hits farther along the ray than this parameter do not count (`> 0`, may be
    /// infinite).
    pub t_max: f64,
}

impl Default for RayOptions {
    fn default() -> Self {
        RayOptions {
            mode: RayMode::Closest,
            t_max: f64::INFINITY,
        }
    }
}

/// Where a ray meets the model.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RayHit {
    /// The ray parameter: the point is [`Ray::at`]`(t)`.
    pub t: f64,
    /// The triangle hit, as an input-mesh triangle id.
    pub triangle: u32,
    /// The point's weights on the triangle's corners, in the input's vertex order
    /// (non-negative, summing to 1).
    pub barycentric: [f64; 3],
    /// The triangle's unit geometric normal, world frame: `(v1 − v0) × (v2 − v0)` of its
    /// corners in input order, whichever side the ray came from. Zero for a triangle whose
    /// corners are collinear.
    pub normal: [f64; 3],
}

/// The answer for one ray of [`cast_rays`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RayResult {
    /// The hit, `None` when the ray meets nothing up to `t_max`.
    pub hit: Option<RayHit>,
    /// Work done: D and I count volumes missed or pruned and entered, S and K triangles
    /// missed and hit.
    pub work: Work,
}

/// The answer for one ray of [`all_ray_hits`].
#[derive(Clone, Debug, PartialEq)]
pub struct RayHits {
    /// Every hit up to `t_max`, by increasing `t` (then input triangle id).
    pub hits: Vec<RayHit>,
    /// Work done, counted as in [`RayResult::work`].
    pub work: Work,
}

/// Where each of `rays` (world frame) first meets `model`, posed by `pose` (model frame to
/// world), or whether it meets it at all ([`RayMode::Any`]), computed in parallel.
///
/// Hits are watertight: a ray through an edge shared by two triangles, or through a
/// corner, meets exactly one of the triangles there (a ray grazing the surface along a
/// fold meets both or neither, and a ray in a triangle's plane misses it).
///
/// # Errors
///
/// - [`QueryError::BadInput`] for a ray with a non-finite origin or a zero or non-finite
///   direction, [`QueryError::BadOption`] for a `t_max` that is not greater than 0.
/// - [`QueryError::CorruptTree`] or [`QueryError::Format`] for a damaged, unverified file.
///
/// # Examples
///
/// ```
/// use obbtree::format::ObbtFile;
/// use obbtree::query::{cast_rays, Pose, Ray, RayOptions};
///
/// let table = ObbtFile::open(concat!(env!("CARGO_MANIFEST_DIR"), "/assets/scenes/table.obbt"))?;
/// let down = Ray { origin: [0.0, 0.0, 5.0], direction: [0.0, 0.0, -1.0] };
/// let results = cast_rays(&table, &Pose::identity(), &[down], &RayOptions::default())?;
/// if let Some(hit) = results[0].hit {
///     println!("triangle {} at t = {:.3}, point {:?}", hit.triangle, hit.t, down.at(hit.t));
/// }
/// # Ok::<(), Box<dyn std::error::Error>>(())
/// ```
pub fn cast_rays(
    model: &ObbtFile,
    pose: &Pose,
    rays: &[Ray],
    options: &RayOptions,
) -> Result<Vec<RayResult>, QueryError> {
    let mode = options.mode;
    run(model, pose, rays, options.t_max, || First {
        mode,
        hit: None,
    })
}

/// Every hit of each of `rays` (world frame) on `model`, posed by `pose`, up to parameter
/// `t_max`, computed in parallel: a ray through a closed model hits it an even number of
/// times (edges and corners count once, as in [`cast_rays`]).
///
/// # Errors
///
/// As [`cast_rays`].
///
/// # Examples
///
/// ```
/// use obbtree::format::ObbtFile;
/// use obbtree::query::{all_ray_hits, Pose, Ray};
///
/// let cow = ObbtFile::open(concat!(env!("CARGO_MANIFEST_DIR"), "/assets/scenes/cow.obbt"))?;
/// let through = Ray { origin: [-10.0, 0.01, 0.02], direction: [1.0, 0.0, 0.0] };
/// let hits = &all_ray_hits(&cow, &Pose::identity(), &[through], f64::INFINITY)?[0].hits;
/// println!("{} crossings at t = {:?}", hits.len(), hits.iter().map(|h| h.t).collect::<Vec<_>>());
/// # Ok::<(), Box<dyn std::error::Error>>(())
/// ```
pub fn all_ray_hits(
    model: &ObbtFile,
    pose: &Pose,
    rays: &[Ray],
    t_max: f64,
) -> Result<Vec<RayHits>, QueryError> {
    run(model, pose, rays, t_max, || All(Vec::new()))
}

/// What a descent keeps of the hits it finds.
trait Collect {
    /// The answer for one ray.
    type Output: Send;
    /// The largest parameter still wanted: volumes entered beyond it are pruned, and a
    /// triangle hit beyond it is not reported.
    fn horizon(&self, t_max: f64) -> f64;
    /// Takes a hit of input triangle `triangle` (its `t` within the horizon); `true` ends
    /// the descent.
    fn take(&mut self, hit: RayHit) -> bool;
    /// The answer, with the work the descent did.
    fn finish(self, work: Work) -> Self::Output;
}

/// The closest hit, or the first found.
struct First {
    mode: RayMode,
    hit: Option<RayHit>,
}

impl Collect for First {
    type Output = RayResult;
    #[inline]
    fn horizon(&self, t_max: f64) -> f64 {
        self.hit.map_or(t_max, |h| h.t)
    }
    #[inline]
    fn take(&mut self, hit: RayHit) -> bool {
        let better = self
            .hit
            .is_none_or(|best| (hit.t, hit.triangle) < (best.t, best.triangle));
        if better {
            self.hit = Some(hit);
        }
        self.mode == RayMode::Any
    }
    fn finish(self, work: Work) -> RayResult {
        RayResult {
            hit: self.hit,
            work,
        }
    }
}

/// Every hit.
struct All(Vec<RayHit>);

impl Collect for All {
    type Output = RayHits;
    #[inline]
    fn horizon(&self, t_max: f64) -> f64 {
        t_max
    }
    #[inline]
    fn take(&mut self, hit: RayHit) -> bool {
        self.0.push(hit);
        false
    }
    fn finish(self, work: Work) -> RayHits {
        let mut hits = self.0;
        hits.sort_unstable_by(|a, b| a.t.total_cmp(&b.t).then(a.triangle.cmp(&b.triangle)));
        RayHits { hits, work }
    }
}

/// A ray mapped into the model's frame, ready for box and triangle tests.
struct LocalRay<'a> {
    slabs: Slabs,
    space: RaySpace,
    /// Model to world, for the normals.
    pose: &'a Pose,
}

/// Checks the inputs, then runs one descent per ray on the typed tree, in parallel (one
/// traversal stack per worker), each keeping its hits in a fresh `make()`.
fn run<C: Collect>(
    model: &ObbtFile,
    pose: &Pose,
    rays: &[Ray],
    t_max: f64,
    make: impl Fn() -> C + Sync,
) -> Result<Vec<C::Output>, QueryError> {
    super::require_positive("t_max", t_max)?;
    for (index, ray) in rays.iter().enumerate() {
        check_ray(index, ray)?;
    }
    /// The typed descent, run for every ray.
    struct Visit<'q, F> {
        model: &'q ObbtFile,
        pose: &'q Pose,
        rays: &'q [Ray],
        t_max: f64,
        make: F,
    }
    impl<C: Collect, F: Fn() -> C + Sync> TreeVisitor for Visit<'_, F> {
        type Output = Result<Vec<C::Output>, QueryError>;
        fn visit<B: BoundingVolume>(self, tree: TreeView<'_, B>) -> Self::Output {
            let ray_index = self.model.derived(|| SurfaceIndex::build(&tree))?;
            // World to model: the world frame posed in the model's.
            let to_model = Pose::relative(self.pose, &Pose::identity());
            let answer = |stack: &mut Vec<Child>, index: usize, ray: &Ray| {
                let origin = to_model.apply(&Vector3::from(ray.origin));
                let direction = to_model.rotation() * Vector3::from(ray.direction);
                // (Only a direction so short that turning it underflows fails here.)
                let space =
                    RaySpace::new(&origin, &direction).ok_or_else(|| QueryError::BadInput {
                        what: "ray",
                        index,
                        requirement: "direction must be longer",
                        value: direction.norm(),
                    })?;
                let local = LocalRay {
                    slabs: Slabs::new(origin.into(), direction.into()),
                    space,
                    pose: self.pose,
                };
                let mut collect = (self.make)();
                let work = descend(&ray_index, &tree, &local, self.t_max, stack, &mut collect)?;
                Ok(collect.finish(work))
            };
            // Answers go straight into one vector (collecting results would copy them
            // through a list of chunks, a cost the size of the answers); the error of the
            // first ray that fails is kept aside.
            let failed: Mutex<Option<(usize, QueryError)>> = Mutex::new(None);
            let mut answers = Vec::new();
            self.rays
                .par_iter()
                .enumerate()
                .map_init(Vec::new, |stack, (index, ray)| {
                    answer(stack, index, ray).unwrap_or_else(|error| {
                        let mut failed = failed.lock().unwrap_or_else(|p| p.into_inner());
                        if failed.as_ref().is_none_or(|(first, _)| index < *first) {
                            *failed = Some((index, error));
                        }
                        (self.make)().finish(Work::default())
                    })
                })
                .collect_into_vec(&mut answers);
            match failed.into_inner().unwrap_or_else(|p| p.into_inner()) {
                Some((_, error)) => Err(error),
                None => Ok(answers),
            }
        }
    }
    model.visit(Visit {
        model,
        pose,
        rays,
        t_max,
        make,
    })?
}

/// The error naming ray `index` when its origin is not finite or its direction is zero or
/// not finite.
fn check_ray(index: usize, ray: &Ray) -> Result<(), QueryError> {
    let bad = |requirement, value| QueryError::BadInput {
        what: "ray",
        index,
        requirement,
        value,
    };
    if let Some(x) = ray.origin.iter().find(|x| !x.is_finite()) {
        return Err(bad("origin coordinates must be finite", *x));
    }
    if let Some(x) = ray.direction.iter().find(|x| !x.is_finite()) {
        return Err(bad("direction coordinates must be finite", *x));
    }
    if ray.direction == [0.0; 3] {
        return Err(bad("direction must not be zero", 0.0));
    }
    Ok(())
}

/// How far past the horizon a box may be entered and still be opened: the entry is a
/// bound on exact parameters, a triangle's `t` is rounded, and a triangle at the horizon
/// must still be found to break a tie by its id.
const PRUNE_MARGIN: f64 = 64.0 * f64::EPSILON;

/// Front to back through the ray index: a node's child boxes are tested when it is
/// opened, the descent goes on into the nearest the ray enters and the others wait on the
/// stack; a child taken whose entry lies past the horizon is pruned. Each box test counts
/// once, in D or I (the root, which has no box, as one entered).
fn descend<B: BoundingVolume, C: Collect>(
    index: &SurfaceIndex,
    tree: &TreeView<'_, B>,
    ray: &LocalRay,
    t_max: f64,
    stack: &mut Vec<Child>,
    collect: &mut C,
) -> Result<Work, QueryError> {
    let missing = || corrupt(Side::A, NodeDefect::Missing);
    let mut work = Work::default();
    stack.clear();
    work.nodes_visited += 1;
    let mut next = Some(Child::ROOT);
    while let Some(taken) = next.take().or_else(|| stack.pop()) {
        let horizon = collect.horizon(t_max);
        let reach = horizon + horizon * PRUNE_MARGIN;
        if taken.key > reach {
            work.bv_disjoint += 1;
            continue;
        }
        work.bv_overlap += 1;
        if taken.count == 0 {
            // Children come after their parent (as the index is made): the descent ends.
            let node = index.node(taken.start).ok_or_else(missing)?;
            let (entered, n, tested) = ray.slabs.entered(node, reach.min(t_max));
            work.nodes_visited += tested as u64;
            work.bv_disjoint += (tested - n) as u64;
            // The nearest is taken next, the others wait, farthest deepest.
            if let Some((nearest, others)) = entered.get(WIDTH - n..).and_then(|e| e.split_last()) {
                next = Some(*nearest);
                stack.extend_from_slice(others);
            }
            continue;
        }
        let (start, end) = (
            taken.start as usize,
            taken.start as usize + taken.count as usize,
        );
        // A leaf's triangles are prepared together, `LANES` at a time.
        for first in (start..end).step_by(LANES) {
            let lanes = first..end.min(first + LANES);
            let prepared = ray
                .space
                .prepare(index.triangles(lanes.clone()).ok_or_else(missing)?);
            for (lane, i) in lanes.enumerate() {
                let Some(hit) = prepared.intersect(lane, collect.horizon(t_max)) else {
                    work.tri_separated += 1;
                    continue;
                };
                work.tri_contact += 1;
                let (t, face) = index.triangle(i).ok_or_else(missing)?;
                let hit = RayHit {
                    t: hit.t,
                    triangle: source_id(tree, face, Side::A)?,
                    barycentric: hit.barycentric,
                    normal: (ray.pose.rotation() * unit_normal(t)).into(),
                };
                if collect.take(hit) {
                    return Ok(work);
                }
            }
        }
    }
    Ok(work)
}

/// `(v1 − v0) × (v2 − v0)` made unit, zero when it has no direction. Scaled by its
/// largest component first, so that the sum of squares neither underflows (triangles
/// below about 1e-81 across) nor overflows (above about 1e77).
fn unit_normal(t: &Triangle) -> Vector3<f64> {
    let n = (t[1] - t[0]).cross(&(t[2] - t[0]));
    let largest = n.amax();
    if largest > 0.0 && largest.is_finite() {
        let scaled = n / largest;
        scaled / scaled.norm()
    } else {
        Vector3::zeros()
    }
}
