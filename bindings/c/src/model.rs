//! The one-model queries: rays, closest points, winding numbers and signed distances of
//! one posed tree, for a batch of rays or points in one parallel call.

use super::{
    deref, guard, read_pose, slice, slots, thread_count, work, Error, ObbtreeStatus, ObbtreeTree,
    ObbtreeWork, OBBTREE_NO_TRIANGLE,
};
use obbtree::format::ObbtFile;
use obbtree::query::triangle::Feature;
use obbtree::query::{
    all_ray_hits, cast_rays, closest_points, on_threads, signed_distances, winding_numbers,
    ClosestOptions, Pose, QueryError, Ray, RayHit, RayMode, RayOptions, WindingAccuracy,
    WindingOptions,
};
use std::mem::MaybeUninit;

/// `obbtree_rays` mode: the hit of smallest `t`.
pub const OBBTREE_RAY_CLOSEST: i32 = 0;
/// `obbtree_rays` mode: one hit, the first found (stops there: line of sight, shadows).
pub const OBBTREE_RAY_ANY: i32 = 1;

/// Where a ray meets a triangle. Without a hit (see the result's flag) `t` is +infinity,
/// the vectors are NaN and the triangle is `OBBTREE_NO_TRIANGLE`.
#[repr(C)]
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ObbtreeRayHit {
    /// The ray parameter: the hit is `origin + t * direction` (the distance for a unit
    /// direction).
    pub t: f64,
    /// The hit point, world frame.
    pub point: [f64; 3],
    /// Its weights on the triangle's corners, in the input mesh's corner order.
    pub barycentric: [f64; 3],
    /// The triangle's unit normal, world frame, from its corners' order (whichever side
    /// the ray came from).
    pub normal: [f64; 3],
    /// The input-mesh id of the triangle hit.
    pub triangle: u32,
}

/// The answer of `obbtree_rays` for one ray.
#[repr(C)]
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ObbtreeRayResult {
    /// 1 when the ray meets the model at some `0 <= t <= t_max`.
    pub hit: bool,
    /// The hit (the closest, or the first found).
    pub closest: ObbtreeRayHit,
    /// Work done: D and I volumes missed and entered, S and K triangles missed and hit.
    pub work: ObbtreeWork,
}

/// The answer of `obbtree_ray_all_hits` for one ray: where its hits are in the hits
/// buffer.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct ObbtreeRayHits {
    /// How many hits the ray has (an even number for a ray from outside a closed model).
    pub hit_count: usize,
    /// Where they start in the hits buffer (the hits of every ray follow each other in ray
    /// order, each ray's by increasing `t`).
    pub hit_offset: usize,
    /// Work done.
    pub work: ObbtreeWork,
}

/// Where on its triangle a closest point lies.
#[repr(C)]
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ObbtreeFeature {
    /// Inside the triangle.
    Face = 0,
    /// On edge `feature_index`, from corner `k` to corner `(k + 1) % 3`.
    Edge = 1,
    /// At corner `feature_index`.
    Vertex = 2,
}

/// The answer of `obbtree_closest_points` for one point. Without an answer (see `found`)
/// the distance is +infinity, the point NaN and the triangle `OBBTREE_NO_TRIANGLE`.
#[repr(C)]
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ObbtreeClosestResult {
    /// 0 when the model is at least `max_distance` from the point, 1 otherwise.
    pub found: bool,
    /// Distance from the query point to the model's surface, world units.
    pub distance: f64,
    /// The closest point of the surface, world frame.
    pub point: [f64; 3],
    /// The input-mesh id of its triangle.
    pub triangle: u32,
    /// Where on the triangle it lies.
    pub feature: ObbtreeFeature,
    /// The edge's or corner's number (0 to 2) in the input's corner order; 0 for a face.
    pub feature_index: u32,
    /// Work done: D and I volumes pruned and opened, S and K triangles tested.
    pub work: ObbtreeWork,
}

/// `obbtree_winding_numbers` rule: clusters seen from more than `parameter` (> 1; 2 is
/// libigl's default) times their radius are summed by their moments. Fast; the error is
/// not bounded beforehand and is measured small.
pub const OBBTREE_WINDING_BETA: i32 = 0;
/// `obbtree_winding_numbers` rule: each value proven within `parameter` (> 0) of the exact
/// sum.
pub const OBBTREE_WINDING_BOUNDED: i32 = 1;
/// `obbtree_winding_numbers` rule: every triangle summed exactly (`parameter` ignored).
pub const OBBTREE_WINDING_EXACT: i32 = 2;

/// The batch of one-model queries: the tree, its pose, and the thread count, checked.
struct Model<'a> {
    file: &'a ObbtFile,
    pose: Pose,
    threads: Option<std::num::NonZeroUsize>,
}

impl Model<'_> {
    /// # Safety
    ///
    /// `tree` is NULL or an open tree; `pose` is NULL or points at 12 readable doubles.
    unsafe fn new<'a>(
        tree: *const ObbtreeTree,
        pose: *const f64,
        threads: usize,
    ) -> Result<Model<'a>, Error> {
        // SAFETY: forwarded from the caller's contract.
        let (tree, pose) = unsafe { (deref(tree, "tree")?, read_pose(pose, "pose")?) };
        Ok(Model {
            file: &tree.file,
            pose,
            threads: thread_count(threads)?,
        })
    }

    /// `query` run on the asked threads.
    fn run<T: Send>(
        &self,
        query: impl FnOnce(&ObbtFile, &Pose) -> Result<T, QueryError> + Send,
    ) -> Result<T, Error> {
        Ok(on_threads(self.threads, || query(self.file, &self.pose))??)
    }
}

/// `count` rows of three doubles at `values` (`name` in messages).
///
/// # Safety
///
/// `values` is NULL or points at `3 * count` readable doubles.
unsafe fn rows(values: *const f64, count: usize, name: &str) -> Result<Vec<[f64; 3]>, Error> {
    let len = count
        .checked_mul(3)
        .ok_or_else(|| Error::bad(format!("{name}: count {count} is too large")))?;
    // SAFETY: forwarded from the caller's contract.
    let values = unsafe { slice(values, len, name) }?;
    Ok(values.chunks_exact(3).map(|r| [r[0], r[1], r[2]]).collect())
}

/// The `count` output slots at `ptr`, refused unless `len` (the caller's length) equals
/// `count`.
///
/// # Safety
///
/// `ptr` is NULL or points at `len` writable values.
unsafe fn outputs<'a, T>(
    ptr: *mut T,
    len: usize,
    count: usize,
    name: &str,
) -> Result<&'a mut [MaybeUninit<T>], Error> {
    if len != count {
        return Err(Error::bad(format!(
            "{name} holds {len} values but there are {count} queries"
        )));
    }
    // SAFETY: forwarded from the caller's contract.
    unsafe { slots(ptr, len, name) }
}

/// What every point query reads first: the model, its `count` points (3 doubles each) and
/// the `len` output slots at `out`, which must be `count`.
///
/// # Safety
///
/// `tree` is NULL or an open tree; `pose` NULL or 12 readable doubles; `points` NULL or
/// `3 * count` readable doubles; `out` NULL or `len` writable values.
#[allow(clippy::too_many_arguments, clippy::type_complexity)]
unsafe fn point_query<'a, T>(
    tree: *const ObbtreeTree,
    pose: *const f64,
    threads: usize,
    points: *const f64,
    count: usize,
    out: *mut T,
    len: usize,
    name: &str,
) -> Result<(Model<'a>, Vec<[f64; 3]>, &'a mut [MaybeUninit<T>]), Error> {
    // SAFETY: forwarded from the caller's contract.
    unsafe {
        Ok((
            Model::new(tree, pose, threads)?,
            rows(points, count, "points")?,
            outputs(out, len, count, name)?,
        ))
    }
}

/// The rays of `count` origins and directions (3 doubles each, world frame).
///
/// # Safety
///
/// `origins`, `directions` are NULL or point at `3 * count` readable doubles.
unsafe fn read_rays(
    origins: *const f64,
    directions: *const f64,
    count: usize,
) -> Result<Vec<Ray>, Error> {
    // SAFETY: forwarded from the caller's contract.
    let (o, d) = unsafe {
        (
            rows(origins, count, "origins")?,
            rows(directions, count, "directions")?,
        )
    };
    Ok(o.into_iter()
        .zip(d)
        .map(|(origin, direction)| Ray { origin, direction })
        .collect())
}

fn ray_hit(ray: &Ray, hit: Option<&RayHit>) -> ObbtreeRayHit {
    match hit {
        Some(h) => ObbtreeRayHit {
            t: h.t,
            point: ray.at(h.t),
            barycentric: h.barycentric,
            normal: h.normal,
            triangle: h.triangle,
        },
        None => ObbtreeRayHit {
            t: f64::INFINITY,
            point: [f64::NAN; 3],
            barycentric: [f64::NAN; 3],
            normal: [f64::NAN; 3],
            triangle: OBBTREE_NO_TRIANGLE,
        },
    }
}

/// Casts `count` rays at `tree` posed by `pose`, in parallel: ray `i` is the points
/// `origins[i] + t * directions[i]` for `0 <= t <= t_max` (3 doubles each, world frame;
/// `t_max` > 0, `INFINITY` for none). `mode` is `OBBTREE_RAY_CLOSEST` (the hit of
/// smallest `t`) or `OBBTREE_RAY_ANY` (the first hit found).
/// `results` holds `results_len` answers, which must equal `count`; `threads` as for
/// `obbtree_collide_batch`.
///
/// Hits are watertight: a ray through an edge or corner shared by triangles hits exactly
/// one of them. `OBBTREE_STATUS_BAD_ARGUMENT` names the first ray with a non-finite origin
/// or a zero or non-finite direction, and refuses a `t_max` not above 0.
///
/// # Safety
///
/// `tree` is NULL or an open tree; `pose` NULL or 12 readable doubles; `origins` and
/// `directions` NULL or `3 * count` readable doubles each; `results` NULL or
/// `results_len` writable results, not overlapping the inputs.
#[no_mangle]
#[allow(clippy::too_many_arguments)]
pub unsafe extern "C" fn obbtree_rays(
    tree: *const ObbtreeTree,
    pose: *const f64,
    origins: *const f64,
    directions: *const f64,
    count: usize,
    t_max: f64,
    mode: i32,
    threads: usize,
    results: *mut ObbtreeRayResult,
    results_len: usize,
) -> ObbtreeStatus {
    guard(|| {
        // SAFETY: forwarded from the caller's contract.
        let (model, rays, results) = unsafe {
            (
                Model::new(tree, pose, threads)?,
                read_rays(origins, directions, count)?,
                outputs(results, results_len, count, "results")?,
            )
        };
        let mode = match mode {
            OBBTREE_RAY_CLOSEST => RayMode::Closest,
            OBBTREE_RAY_ANY => RayMode::Any,
            other => {
                return Err(Error::bad(format!(
                    "mode is {other}: not OBBTREE_RAY_CLOSEST or OBBTREE_RAY_ANY"
                )))
            }
        };
        let options = RayOptions { mode, t_max };
        let answers = model.run(|file, pose| cast_rays(file, pose, &rays, &options))?;
        for ((slot, ray), answer) in results.iter_mut().zip(&rays).zip(&answers) {
            slot.write(ObbtreeRayResult {
                hit: answer.hit.is_some(),
                closest: ray_hit(ray, answer.hit.as_ref()),
                work: work(&answer.work),
            });
        }
        Ok(())
    })
}

/// Every hit of `count` rays at `tree` posed by `pose`, in parallel; the rays, `t_max`,
/// `threads` and `results_len` as for `obbtree_rays`. `results[i]` says how many hits ray
/// `i` has and where they start in `hits`, where the hits of every ray follow each other
/// in ray order, each ray's by increasing `t` (ties by triangle id); `*hits_total` (if not
/// NULL) gets the number of them all. Pass NULL and 0 for counts only. When `hits` is too
/// short the call returns `OBBTREE_STATUS_BUFFER_TOO_SMALL` with every result complete and
/// the first `capacity` hits written.
///
/// # Safety
///
/// As `obbtree_rays`, and `hits` NULL or `capacity` writable hits, `hits_total` NULL or
/// writable, no output overlapping another or the inputs.
#[no_mangle]
#[allow(clippy::too_many_arguments)]
pub unsafe extern "C" fn obbtree_ray_all_hits(
    tree: *const ObbtreeTree,
    pose: *const f64,
    origins: *const f64,
    directions: *const f64,
    count: usize,
    t_max: f64,
    threads: usize,
    results: *mut ObbtreeRayHits,
    results_len: usize,
    hits: *mut ObbtreeRayHit,
    capacity: usize,
    hits_total: *mut usize,
) -> ObbtreeStatus {
    guard(|| {
        let counts_only = hits.is_null() && capacity == 0;
        // SAFETY: forwarded from the caller's contract.
        let (model, rays, results, hit_slots) = unsafe {
            (
                Model::new(tree, pose, threads)?,
                read_rays(origins, directions, count)?,
                outputs(results, results_len, count, "results")?,
                if counts_only {
                    &mut []
                } else {
                    slots(hits, capacity, "hits")?
                },
            )
        };
        let total_slot = if hits_total.is_null() {
            None
        } else {
            // SAFETY: non-NULL, so one writable value (the caller's contract).
            Some(unsafe { super::slot(hits_total, "hits_total") }?)
        };
        let answers = model.run(|file, pose| all_ray_hits(file, pose, &rays, t_max))?;
        let mut offset = 0;
        for ((slot, ray), answer) in results.iter_mut().zip(&rays).zip(&answers) {
            slot.write(ObbtreeRayHits {
                hit_count: answer.hits.len(),
                hit_offset: offset,
                work: work(&answer.work),
            });
            for (out, hit) in hit_slots.iter_mut().skip(offset).zip(&answer.hits) {
                out.write(ray_hit(ray, Some(hit)));
            }
            offset += answer.hits.len();
        }
        if let Some(total) = total_slot {
            total.write(offset);
        }
        if offset > capacity && !counts_only {
            return Err(Error::new(
                ObbtreeStatus::BufferTooSmall,
                format!("the hits buffer holds {capacity} hits but {offset} are needed"),
            ));
        }
        Ok(())
    })
}

/// The closest point of `tree` posed by `pose` to each of `count` points (3 doubles each,
/// world frame), in parallel. Points at least `max_distance` (> 0, world units; `INFINITY`
/// for none) from the model get `found = 0`, sooner. `results` holds `results_len`
/// answers, which must equal `count`; `threads` as for `obbtree_collide_batch`.
/// `OBBTREE_STATUS_BAD_ARGUMENT` names the first non-finite point, or the first beyond
/// ±1e150 in the model's frame (`obbtree::query::MAX_COORDINATE`).
///
/// # Safety
///
/// `tree` is NULL or an open tree; `pose` NULL or 12 readable doubles; `points` NULL or
/// `3 * count` readable doubles; `results` NULL or `results_len` writable results, not
/// overlapping the inputs.
#[no_mangle]
#[allow(clippy::too_many_arguments)]
pub unsafe extern "C" fn obbtree_closest_points(
    tree: *const ObbtreeTree,
    pose: *const f64,
    points: *const f64,
    count: usize,
    max_distance: f64,
    threads: usize,
    results: *mut ObbtreeClosestResult,
    results_len: usize,
) -> ObbtreeStatus {
    guard(|| {
        // SAFETY: forwarded from the caller's contract.
        let (model, points, results) = unsafe {
            point_query(
                tree,
                pose,
                threads,
                points,
                count,
                results,
                results_len,
                "results",
            )
        }?;
        let options = ClosestOptions { max_distance };
        let answers = model.run(|file, pose| closest_points(file, pose, &points, &options))?;
        for (slot, answer) in results.iter_mut().zip(&answers) {
            let record = match answer.closest {
                Some(c) => ObbtreeClosestResult {
                    found: true,
                    distance: c.distance,
                    point: c.point,
                    triangle: c.triangle,
                    feature: match c.feature {
                        Feature::Face => ObbtreeFeature::Face,
                        Feature::Edge(_) => ObbtreeFeature::Edge,
                        Feature::Vertex(_) => ObbtreeFeature::Vertex,
                    },
                    feature_index: u32::from(c.feature.index()),
                    work: work(&answer.work),
                },
                None => ObbtreeClosestResult {
                    found: false,
                    distance: f64::INFINITY,
                    point: [f64::NAN; 3],
                    triangle: OBBTREE_NO_TRIANGLE,
                    feature: ObbtreeFeature::Face,
                    feature_index: 0,
                    work: work(&answer.work),
                },
            };
            slot.write(record);
        }
        Ok(())
    })
}

/// The accuracy a rule (`OBBTREE_WINDING_*`) and its parameter ask for (the library
/// refuses parameters out of range, with the CLI's message).
fn winding_options(rule: i32, parameter: f64) -> Result<WindingOptions, Error> {
    let accuracy = match rule {
        OBBTREE_WINDING_BETA => WindingAccuracy::Beta { beta: parameter },
        OBBTREE_WINDING_BOUNDED => WindingAccuracy::Bounded {
            tolerance: parameter,
        },
        OBBTREE_WINDING_EXACT => WindingAccuracy::Exact,
        other => {
            return Err(Error::bad(format!(
                "rule is {other}: not one of the OBBTREE_WINDING_* rules (0 to 2)"
            )))
        }
    };
    Ok(WindingOptions { accuracy })
}

/// The generalised winding number of `tree` posed by `pose` at each of `count` points (3
/// doubles each, world frame), in parallel: 1 inside a closed outward-facing surface, 0
/// outside, between for surfaces with holes; a point is inside where it is above 0.5,
/// which holds for polygon soups too. `rule` (`OBBTREE_WINDING_BETA`, `_BOUNDED` or
/// `_EXACT`) and `parameter` say how far clusters are summed. `values` gets the winding numbers and `error_bounds` (if not NULL) a proven
/// bound on each one's distance from the exact sum (rounding aside); each holds `len`
/// values, which must equal `count`. `threads` as for `obbtree_collide_batch`.
/// `OBBTREE_STATUS_BAD_ARGUMENT` names the first non-finite point, or the first beyond
/// ±1e150 in the model's frame (`obbtree::query::MAX_COORDINATE`), and refuses a `beta`
/// not above 1 or a tolerance not above 0.
///
/// # Safety
///
/// `tree` is NULL or an open tree; `pose` NULL or 12 readable doubles; `points` NULL or
/// `3 * count` readable doubles; `values` NULL and `error_bounds` NULL or `len` writable
/// doubles each, not overlapping each other or the inputs.
#[no_mangle]
#[allow(clippy::too_many_arguments)]
pub unsafe extern "C" fn obbtree_winding_numbers(
    tree: *const ObbtreeTree,
    pose: *const f64,
    points: *const f64,
    count: usize,
    rule: i32,
    parameter: f64,
    threads: usize,
    values: *mut f64,
    error_bounds: *mut f64,
    len: usize,
) -> ObbtreeStatus {
    guard(|| {
        // SAFETY: forwarded from the caller's contract.
        let (model, points, values) =
            unsafe { point_query(tree, pose, threads, points, count, values, len, "values") }?;
        let bounds = if error_bounds.is_null() {
            None
        } else {
            // SAFETY: non-NULL, so `len` writable doubles (the caller's contract).
            Some(unsafe { outputs(error_bounds, len, count, "error_bounds") }?)
        };
        let options = winding_options(rule, parameter)?;
        let answers = model.run(|file, pose| winding_numbers(file, pose, &points, &options))?;
        for (slot, answer) in values.iter_mut().zip(&answers) {
            slot.write(answer.value);
        }
        if let Some(bounds) = bounds {
            for (slot, answer) in bounds.iter_mut().zip(&answers) {
                slot.write(answer.error_bound);
            }
        }
        Ok(())
    })
}

/// The signed distance of `tree` posed by `pose` at each of `count` points (3 doubles
/// each, world frame), in parallel: the distance to the closest surface point, negative
/// where the winding number (computed by `rule` and `parameter` as in
/// `obbtree_winding_numbers`) is above 0.5. `values` holds `len` doubles, which must equal
/// `count`; `threads` as for `obbtree_collide_batch`. Refuses what
/// `obbtree_winding_numbers` refuses.
///
/// # Safety
///
/// `tree` is NULL or an open tree; `pose` NULL or 12 readable doubles; `points` NULL or
/// `3 * count` readable doubles; `values` NULL or `len` writable doubles, not overlapping
/// the inputs.
#[no_mangle]
#[allow(clippy::too_many_arguments)]
pub unsafe extern "C" fn obbtree_signed_distances(
    tree: *const ObbtreeTree,
    pose: *const f64,
    points: *const f64,
    count: usize,
    rule: i32,
    parameter: f64,
    threads: usize,
    values: *mut f64,
    len: usize,
) -> ObbtreeStatus {
    guard(|| {
        // SAFETY: forwarded from the caller's contract.
        let (model, points, values) =
            unsafe { point_query(tree, pose, threads, points, count, values, len, "values") }?;
        let options = winding_options(rule, parameter)?;
        let answers = model.run(|file, pose| signed_distances(file, pose, &points, &options))?;
        for (slot, answer) in values.iter_mut().zip(&answers) {
            slot.write(*answer);
        }
        Ok(())
    })
}
