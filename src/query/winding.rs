//! Inside or outside: the generalised winding number of one posed model at query points
//! (Jacobson, Kavan and Sorkine-Hornung 2013), summed exactly triangle by triangle or, for
//! far clusters of triangles, by their dipole moment (Barill et al. 2018) under a proven
//! bound on the error.
//!
//! The winding number of a closed, outward-facing surface is 1 inside and 0 outside; of a
//! surface with holes, duplicate or self-intersecting triangles (a soup) it varies smoothly
//! between, and `> 0.5` is the robust inside test.

use super::closest::{closest_points, ClosestOptions};
use super::engine::corrupt;
use super::index::{Slot, SurfaceIndex, WIDTH};
use super::order::map_in_space_order;
use super::triangle::Triangle;
use super::{check_points, QueryError, Side, Work};
use crate::bv::BoundingVolume;
use crate::format::{ObbtFile, TreeVisitor};
use crate::pose::Pose;
use crate::tree::{NodeDefect, TreeView};
use nalgebra::{Matrix3, Vector3};
use std::cmp::Ordering::Greater;
use std::f64::consts::PI;

/// How winding numbers are asked.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct WindingOptions {
    /// Which far clusters of triangles are summed by their moments rather than triangle by
    /// triangle.
    pub accuracy: WindingAccuracy,
}

/// How exactly a winding number is summed: the speed and error of each are measured in
/// `docs/results/2026-11-26-winding-numbers.md`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum WindingAccuracy {
    /// Every triangle's solid angle: the reference, and the cost of one per triangle.
    Exact,
    /// Within `tolerance` (`> 0`) of the exact sum, proven: a cluster is summed by its
    /// moments only while the bound on what that errs by fits its share of the tolerance
    /// by area. Worst cases add up in the proof, not in practice: the errors measured are
    /// far below the tolerance, and so is the speed.
    Bounded {
        /// The largest error allowed.
        tolerance: f64,
    },
    /// Barill et al.'s rule: a cluster seen from more than `beta` (`> 1`) times its radius
    /// (the farthest of its corners from its centroid) is summed by its moments. The fast
    /// choice (`beta` 2, as libigl's default; libigl's clusters are larger for their
    /// contents, and at `beta` 2.25 the errors measured are about libigl's); its error is
    /// not bounded beforehand ([`WindingResult::error_bound`] still bounds what it did),
    /// and is measured small in practice.
    Beta {
        /// How far, in cluster radii, a cluster must be.
        beta: f64,
    },
}

impl Default for WindingAccuracy {
    fn default() -> Self {
        WindingAccuracy::Beta { beta: 2.0 }
    }
}

/// The winding number at one query point.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct WindingResult {
    /// The generalised winding number: 1 inside a closed outward-facing surface, 0
    /// outside, between for open surfaces; the point is inside where it is `> 0.5`. On
    /// a closed surface it is the share of directions looking inside (½ on a face, ¼ on
    /// an edge of a cube), to rounding.
    pub value: f64,
    /// A proven bound on `|value − exact|` from the clusters summed by their moments: 0
    /// for [`WindingAccuracy::Exact`], at most the tolerance for
    /// [`WindingAccuracy::Bounded`], often far above the error made for
    /// [`WindingAccuracy::Beta`] (which bounds a cluster seen from `R` by
    /// `A r³ / (π R⁵ (1 − 1/β)⁵)`, at least the bound below and cheaper). Rounding comes on
    /// top.
    pub error_bound: f64,
    /// Work done: I counts clusters opened, D clusters summed by their moments, S
    /// triangles summed exactly.
    pub work: Work,
}

impl WindingResult {
    /// Whether the point is inside: the winding number is above one half.
    pub fn inside(&self) -> bool {
        self.value > 0.5
    }

    /// `distance` (to the model's surface) made negative where the point is inside: the
    /// signed distance.
    pub fn signed(&self, distance: f64) -> f64 {
        if self.inside() {
            -distance
        } else {
            distance
        }
    }
}

/// The winding number of `model`, posed by `pose` (model frame to world), at each of
/// `points` (world frame), computed in parallel.
///
/// Triangles count with the orientation of their corners' order (counterclockwise seen
/// from outside is outward). Far clusters of triangles are summed by a second-order
/// expansion of the solid-angle kernel about their centroid (their area-weighted normal
/// and its first and second moments over the cluster, Barill et al.'s order 3, libigl's
/// default): for a cluster of area `A` within radius `r` of its centroid, seen from
/// `R > r` away, that errs by at most `A r³ / (π (R − r)⁵)` (the kernel's third derivatives
/// are at most `24 / distance⁵`). Which clusters are summed so is
/// [`WindingOptions::accuracy`]'s choice.
///
/// # Errors
///
/// - [`QueryError::BadInput`] for a query point with a non-finite coordinate, or one
///   beyond [`MAX_COORDINATE`](super::MAX_COORDINATE) in the model's frame ("query
///   point"), or a model triangle beyond it ("model triangle");
///   [`QueryError::BadOption`] for a tolerance not above 0 or a `beta` not above 1.
/// - [`QueryError::CorruptTree`] or [`QueryError::Format`] for a damaged, unverified file.
///
/// # Examples
///
/// ```
/// use obbtree::format::ObbtFile;
/// use obbtree::query::{winding_numbers, Pose, WindingOptions};
///
/// let cow = ObbtFile::open(concat!(env!("CARGO_MANIFEST_DIR"), "/assets/scenes/cow.obbt"))?;
/// let points = [[0.0, 0.0, 0.0], [5.0, 0.0, 0.0]];
/// let w = winding_numbers(&cow, &Pose::identity(), &points, &WindingOptions::default())?;
/// println!("{:.3} (inside: {}), {:.3}", w[0].value, w[0].inside(), w[1].value);
/// # Ok::<(), Box<dyn std::error::Error>>(())
/// ```
pub fn winding_numbers(
    model: &ObbtFile,
    pose: &Pose,
    points: &[[f64; 3]],
    options: &WindingOptions,
) -> Result<Vec<WindingResult>, QueryError> {
    winding_numbers_with(model, pose, points, options, Arithmetic::fastest())
}

/// [`winding_numbers`], with the expansions evaluated in `arithmetic`.
fn winding_numbers_with(
    model: &ObbtFile,
    pose: &Pose,
    points: &[[f64; 3]],
    options: &WindingOptions,
    arithmetic: Arithmetic,
) -> Result<Vec<WindingResult>, QueryError> {
    let bad = |name, requirement, value| QueryError::BadOption {
        name,
        requirement,
        value,
    };
    // (NaN fails too.)
    match options.accuracy {
        WindingAccuracy::Bounded { tolerance } if tolerance.partial_cmp(&0.0) != Some(Greater) => {
            return Err(bad("tolerance", "greater than 0", tolerance))
        }
        WindingAccuracy::Beta { beta } if beta.partial_cmp(&1.0) != Some(Greater) => {
            return Err(bad("beta", "greater than 1", beta))
        }
        _ => {}
    }
    check_points(points, &Pose::relative(pose, &Pose::identity()))?;
    /// The typed descent, run for every point.
    struct Visit<'q> {
        model: &'q ObbtFile,
        pose: &'q Pose,
        points: &'q [[f64; 3]],
        accuracy: WindingAccuracy,
        arithmetic: Arithmetic,
    }
    impl TreeVisitor for Visit<'_> {
        type Output = Result<Vec<WindingResult>, QueryError>;
        fn visit<B: BoundingVolume>(self, tree: TreeView<'_, B>) -> Self::Output {
            // Both made at the file's first such query and kept with it.
            let index = self.model.derived(|| SurfaceIndex::build(&tree))?;
            index.check_reach(&tree, Side::A, "model triangle")?;
            let clusters = self.model.derived(|| Clusters::of(&index))?;
            let to_model = Pose::relative(self.pose, &Pose::identity());
            // The descent is made for each rule, so that no step asks which rule it follows.
            fn run(
                (index, clusters, arithmetic): (&SurfaceIndex, &Clusters, Arithmetic),
                to_model: &Pose,
                points: &[[f64; 3]],
                accept: impl Fn(f64, f64, f64, f64) -> Option<f64> + Sync + Send,
            ) -> Result<Vec<WindingResult>, QueryError> {
                map_in_space_order(points, Vec::new, |stack, p| {
                    let local = to_model.apply(&Vector3::from(*p));
                    match arithmetic {
                        Arithmetic::Separate => {
                            descend::<Separate>(index, clusters, &local, &accept, stack)
                        }
                        #[cfg(target_arch = "x86_64")]
                        // SAFETY: `Arithmetic::Fused` is only made where the CPU has FMA
                        // (`Arithmetic::fastest`), the one feature `descend_fused` needs.
                        Arithmetic::Fused => unsafe {
                            descend_fused(index, clusters, &local, &accept, stack)
                        },
                    }
                })
            }
            let (trees, points) = ((&*index, &*clusters, self.arithmetic), self.points);
            let exact = |_, _, _, _| None;
            match self.accuracy {
                WindingAccuracy::Exact => run(trees, &to_model, points, exact),
                WindingAccuracy::Bounded { tolerance } => {
                    run(trees, &to_model, points, bounded(tolerance, clusters.area))
                }
                WindingAccuracy::Beta { beta } => run(trees, &to_model, points, barill(beta)),
            }
        }
    }
    model.visit(Visit {
        model,
        pose,
        points,
        accuracy: options.accuracy,
        arithmetic,
    })?
}

/// The rule of [`WindingAccuracy::Bounded`] for a model of area `model_area`: a cluster of
/// area `A` may err by `A` times the tolerance per unit area, and its expansion errs by at
/// most `A r³ / (π (d − r)⁵)`. (A model of no area accepts no cluster: its rate is
/// infinite, and `∞ · 0` is NaN.)
fn bounded(
    tolerance: f64,
    model_area: f64,
) -> impl Fn(f64, f64, f64, f64) -> Option<f64> + Sync + Send {
    let rate = tolerance / model_area;
    move |distance: f64, r: f64, area: f64, _| {
        // `A / (d − r)²` and `(r / (d − r))³`: the products `A r³` and `(d − r)⁵` overflow
        // for models whose error is a finite number.
        let error = area / (PI * (distance - r).powi(2)) * (r / (distance - r)).powi(3);
        (error <= rate * area).then_some(error)
    }
}

/// The rule of [`WindingAccuracy::Beta`]: a cluster beyond `beta` radii is accepted, and
/// there `d − r > d (1 − 1/β)` bounds its error from `1/d`, which the expansion needs
/// anyway.
fn barill(beta: f64) -> impl Fn(f64, f64, f64, f64) -> Option<f64> + Sync + Send {
    let bound = 1.0 / (PI * (1.0 - 1.0 / beta).powi(5));
    move |distance, r, area, inverse: f64| {
        // `A / d²` and `(r / d)³`: the product `A r³` overflows, and `d⁻⁵` underflows, for
        // models whose error is a finite number.
        (distance > beta * r).then(|| bound * (area * inverse * inverse) * (r * inverse).powi(3))
    }
}

/// The signed distance of `model`, posed by `pose`, at each of `points` (world frame):
/// the distance to the closest surface point, negative where the winding number (within
/// `options`' tolerance) says the point is inside. Computed in parallel.
///
/// # Errors
///
/// As [`winding_numbers`].
///
/// # Examples
///
/// ```
/// use obbtree::format::ObbtFile;
/// use obbtree::query::{signed_distances, Pose, WindingOptions};
///
/// let cow = ObbtFile::open(concat!(env!("CARGO_MANIFEST_DIR"), "/assets/scenes/cow.obbt"))?;
/// let d = signed_distances(&cow, &Pose::identity(), &[[0.0; 3]], &WindingOptions::default())?;
/// println!("{:.4}", d[0]);
/// # Ok::<(), Box<dyn std::error::Error>>(())
/// ```
pub fn signed_distances(
    model: &ObbtFile,
    pose: &Pose,
    points: &[[f64; 3]],
    options: &WindingOptions,
) -> Result<Vec<f64>, QueryError> {
    let winding = winding_numbers(model, pose, points, options)?;
    let closest = closest_points(model, pose, points, &ClosestOptions::default())?;
    Ok(winding
        .iter()
        .zip(&closest)
        .map(|(w, c)| w.signed(c.distance()))
        .collect())
}

/// What a cluster of triangles (a child of a surface index node) looks like from afar
/// (model frame): its area, its area-weighted normal `N = Σ A n`, its area-weighted
/// centroid `c`, and the moments `spread = Σ n ∫ (x − c)ᵀ dA` and
/// `bend[i] = Σ nᵢ ∫ (x − c)(x − c)ᵀ dA` over its triangles (unit normals `n`).
#[derive(Clone, Copy, Debug, Default)]
struct Moment {
    area: f64,
    normal: Vector3<f64>,
    centroid: Vector3<f64>,
    spread: Matrix3<f64>,
    bend: [Matrix3<f64>; 3],
}

/// The surface index's children as clusters of triangles: for each node, what a descent
/// reads of every child it meets and, after it in memory, the children's [`Expansion`]s,
/// read only for the clusters summed by moments.
struct Clusters {
    /// Node `n`'s children at `n`.
    nodes: Vec<ClusterNode>,
    /// The whole model's area.
    area: f64,
}

/// A node's children as clusters: their centroids (by coordinate), radii and areas side
/// by side, then their expansions. One record, so that the reads of the first part draw
/// the rest into cache behind them.
#[derive(Clone, Copy, Debug)]
struct ClusterNode {
    centroid: [[f64; WIDTH]; 3],
    radius: [f64; WIDTH],
    area: [f64; WIDTH],
    expansions: [Expansion; WIDTH],
}

impl Clusters {
    fn of(index: &SurfaceIndex) -> Result<Clusters, QueryError> {
        let (moments, radii) = slot_moments(index)?;
        let nodes = moments
            .chunks_exact(WIDTH)
            .zip(radii.chunks_exact(WIDTH))
            .map(|(lanes, radius)| {
                let m: [Moment; WIDTH] = lanes.try_into().unwrap_or([Moment::default(); WIDTH]);
                let expansions = m.map(|m| Expansion::of(&m));
                let mut radius: [f64; WIDTH] = radius.try_into().unwrap_or([0.0; WIDTH]);
                // A cluster whose moments overflowed (coordinates beyond about 1e75) is
                // never far enough away: it is opened, down to its triangles' exact angles.
                for (r, e) in radius.iter_mut().zip(&expansions) {
                    if !e.is_finite() {
                        *r = f64::INFINITY;
                    }
                }
                ClusterNode {
                    centroid: [
                        m.map(|m| m.centroid.x),
                        m.map(|m| m.centroid.y),
                        m.map(|m| m.centroid.z),
                    ],
                    radius,
                    area: m.map(|m| m.area),
                    expansions,
                }
            })
            .collect();
        Ok(Clusters {
            nodes,
            area: moments.iter().take(WIDTH).map(|m| m.area).sum(),
        })
    }
}

/// The moment of every child slot of `index`, and the radius about its centroid within
/// which all its corners lie; child `lane` of node `n` at `n * WIDTH + lane` (an empty
/// slot's are zero): a node's children are after it, so in reverse order a child node's
/// slots are done before the slot holding it merges them.
fn slot_moments(index: &SurfaceIndex) -> Result<(Vec<Moment>, Vec<f64>), QueryError> {
    let missing = || corrupt(Side::A, NodeDefect::Missing);
    let mut out = vec![Moment::default(); index.node_count() * WIDTH];
    let mut radii = vec![0.0; index.node_count() * WIDTH];
    // Each slot's triangles, as a range of leaf order holding them all.
    let mut spans = vec![0..0; index.node_count() * WIDTH];
    for node in (0..index.node_count()).rev() {
        let slots = index.node(node as u32).ok_or_else(missing)?.slots();
        for (lane, slot) in slots {
            let (m, span) = match slot {
                Slot::Node(child) => {
                    let kids: Vec<usize> = (index.node(child).ok_or_else(missing)?.slots())
                        .map(|(lane, _)| child as usize * WIDTH + lane)
                        .collect();
                    let moments = kids.iter().map(|&k| out.get(k).copied());
                    let moments = moments.collect::<Option<Vec<_>>>().ok_or_else(missing)?;
                    let kid_spans = kids.iter().filter_map(|&k| spans.get(k));
                    let start = kid_spans.clone().map(|s| s.start).min().unwrap_or(0);
                    let end = kid_spans.map(|s| s.end).max().unwrap_or(0);
                    (merge(&moments), start..end)
                }
                Slot::Triangles(range) => {
                    let triangles = range
                        .clone()
                        .map(|i| index.triangle(i).map(|(t, _)| *t).ok_or_else(missing))
                        .collect::<Result<Vec<Triangle>, _>>()?;
                    (of_triangles(&triangles), range)
                }
            };
            // The radius over the corners themselves (a node's triangles are contiguous in
            // leaf order): merging the children's balls would overstate it, and every
            // cluster that looks larger than it is is opened where its moments would do.
            let mut radius = 0.0f64;
            for i in span.clone() {
                let (t, _) = index.triangle(i).ok_or_else(missing)?;
                for c in t {
                    radius = radius.max((c - m.centroid).norm());
                }
            }
            let at = node * WIDTH + lane;
            *out.get_mut(at).ok_or_else(missing)? = m;
            *radii.get_mut(at).ok_or_else(missing)? = radius;
            *spans.get_mut(at).ok_or_else(missing)? = span;
        }
    }
    Ok((out, radii))
}

/// The moment of the union of clusters.
fn merge(kids: &[Moment]) -> Moment {
    let area = kids.iter().map(|k| k.area).sum::<f64>();
    let normal = kids.iter().map(|k| k.normal).sum();
    let weighted = kids.iter().map(|k| k.centroid * k.area).sum();
    let centroid = centre(weighted, area, kids.iter().map(|k| k.centroid));
    // Each child's spread, moved from its centroid to the parent's.
    let spread = kids
        .iter()
        .map(|k| k.spread + k.normal * (k.centroid - centroid).transpose())
        .sum();
    // And each child's bend: with δ = c_child − c,
    // bend'ᵢ = bendᵢ + sᵢ δᵀ + δ sᵢᵀ + Nᵢ δ δᵀ (sᵢ row i of the child's spread).
    let mut bend = [Matrix3::zeros(); 3];
    for k in kids {
        let delta = k.centroid - centroid;
        let rows = bend
            .iter_mut()
            .zip(&k.bend)
            .zip(k.normal.iter())
            .enumerate();
        for (i, ((b, kb), ni)) in rows {
            let s = k.spread.row(i).transpose();
            *b += kb
                + s * delta.transpose()
                + delta * s.transpose()
                + delta * delta.transpose() * *ni;
        }
    }
    Moment {
        area,
        normal,
        centroid,
        spread,
        bend,
    }
}

/// The moment of a cluster of triangles, from the triangles themselves.
fn of_triangles(triangles: &[Triangle]) -> Moment {
    // Each triangle's area-weighted normal, centroid and corners.
    let parts: Vec<_> = triangles
        .iter()
        .map(|t| {
            (
                (t[1] - t[0]).cross(&(t[2] - t[0])) / 2.0,
                (t[0] + t[1] + t[2]) / 3.0,
                t,
            )
        })
        .collect();
    let area = parts.iter().map(|(n, _, _)| n.norm()).sum::<f64>();
    let normal = parts.iter().map(|(n, _, _)| n).sum();
    let weighted = parts.iter().map(|(n, c, _)| c * n.norm()).sum();
    let centroid = centre(weighted, area, triangles.iter().flatten().copied());
    let spread = parts
        .iter()
        .map(|(n, c, _)| n * (c - centroid).transpose())
        .sum();
    // A triangle's ∫ y yᵀ dA about the centroid is A/12 (Σ vvᵀ + 9 ccᵀ) of its corners v
    // and centroid c taken from it; n = A n̂ takes the A.
    let mut bend = [Matrix3::zeros(); 3];
    for (n, c, t) in &parts {
        let square = |v: &Vector3<f64>| (v - centroid) * (v - centroid).transpose();
        let second = (t.iter().map(square).sum::<Matrix3<f64>>() + square(c) * 9.0) / 12.0;
        for (b, ni) in bend.iter_mut().zip(n.iter()) {
            *b += second * *ni;
        }
    }
    Moment {
        area,
        normal,
        centroid,
        spread,
        bend,
    }
}

/// The area-weighted centroid, or for a cluster of no area the mean of `points`.
fn centre(
    weighted: Vector3<f64>,
    area: f64,
    points: impl Iterator<Item = Vector3<f64>>,
) -> Vector3<f64> {
    if area > 0.0 {
        return weighted / area;
    }
    let (sum, n) = points.fold((Vector3::zeros(), 0.0), |(s, n), p| (s + p, n + 1.0));
    if n > 0.0 {
        sum / n
    } else {
        sum
    }
}

/// The solid angle of triangle `t` seen from the origin, signed by the triangle's
/// orientation (Van Oosterom and Strackee's formula); 0 when the origin lies on it.
fn solid_angle(a: &Vector3<f64>, b: &Vector3<f64>, c: &Vector3<f64>) -> f64 {
    let terms = |a: &Vector3<f64>, b: &Vector3<f64>, c: &Vector3<f64>| {
        let (la, lb, lc) = (a.norm(), b.norm(), c.norm());
        let denominator = la * lb * lc + a.dot(b) * lc + b.dot(c) * la + c.dot(a) * lb;
        (a.dot(&b.cross(c)), denominator)
    };
    let (mut numerator, mut denominator) = terms(a, b, c);
    // In the triangle's plane the formula gives ±2π on the triangle (the sign of a zero)
    // and 0 beside it. 0 on it too is the mean of the two sides' limits, so that a point
    // on a closed surface gets the share of directions looking inside (½ on a face).
    if numerator == 0.0 {
        return 0.0;
    }
    if !(numerator.is_finite() && denominator.is_finite()) {
        // Far from the origin the cubes overflow. The angle does not change with scale,
        // and a power of two scales exactly: once more at about unit size.
        let largest = a.amax().max(b.amax()).max(c.amax());
        let scale = 2f64.powi(-(largest.log2().ceil() as i32));
        (numerator, denominator) = terms(&(a * scale), &(b * scale), &(c * scale));
    }
    2.0 * numerator.atan2(denominator)
}

/// A cluster's moments as its far-field expansion reads them. Seen from a point at `u`
/// from the centroid (`u = c − p`, `d = |u|`), the cluster's solid angle is to second order
/// `(N·u + tr spread) / d³ − (3 uᵀ spread u + v·u) / d⁵ + C(u) / d⁷`: the kernel
/// `g = ∇φ`, `φ(x) = −1/|x − p|`, expanded about the centroid (`∂ᵢφ = uᵢ/d³`,
/// `∂ᵢⱼφ = δᵢⱼ/d³ − 3uᵢuⱼ/d⁵`, `∂ᵢⱼₖφ = −3(δᵢⱼuₖ + δᵢₖuⱼ + δⱼₖuᵢ)/d⁵ + 15uᵢuⱼuₖ/d⁷`)
/// against `N`, `spread` and `bend / 2`. Kept are the coefficients of those forms, the
/// constants folded in: 23 numbers for the 39 of `N`, `spread` and `bend`.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
struct Expansion {
    /// `N`.
    normal: [f64; 3],
    /// `tr spread`.
    trace: f64,
    /// `3 uᵀ spread u`: the coefficients of x², y², z², xy, yz, zx.
    square: [f64; 6],
    /// `v = 3/2 (2 Σᵢ row i of bendᵢ + (tr bendᵢ)ᵢ)`.
    linear: [f64; 3],
    /// `C(u) = 15/2 Σᵢⱼₖ uᵢ bendᵢ[j][k] uⱼ uₖ`: the coefficients of x³, y³, z³, x²y, x²z,
    /// xy², y²z, xz², yz², xyz.
    cubic: [f64; 10],
}

impl Expansion {
    /// Whether every coefficient is a finite number.
    fn is_finite(&self) -> bool {
        let Expansion {
            normal,
            trace,
            square,
            linear,
            cubic,
        } = self;
        normal
            .iter()
            .chain([trace])
            .chain(square)
            .chain(linear)
            .chain(cubic)
            .all(|c| c.is_finite())
    }

    fn of(m: &Moment) -> Expansion {
        let s = &m.spread;
        let bend = &m.bend;
        let rows: Vector3<f64> = bend
            .iter()
            .enumerate()
            .map(|(i, b)| b.row(i).transpose())
            .sum();
        let traces = Vector3::new(bend[0].trace(), bend[1].trace(), bend[2].trace());
        let linear = (rows * 2.0 + traces) * 1.5;
        let mut cubic = [0.0; 10];
        for (i, b) in m.bend.iter().enumerate() {
            for (j, row) in b.row_iter().enumerate() {
                for (k, value) in row.iter().enumerate() {
                    // The monomial by how often x, y and z occur in (i, j, k).
                    let count = |axis| [i, j, k].iter().filter(|&&a| a == axis).count();
                    let slot = match (count(0), count(1), count(2)) {
                        (3, 0, 0) => 0,
                        (0, 3, 0) => 1,
                        (0, 0, 3) => 2,
                        (2, 1, 0) => 3,
                        (2, 0, 1) => 4,
                        (1, 2, 0) => 5,
                        (0, 2, 1) => 6,
                        (1, 0, 2) => 7,
                        (0, 1, 2) => 8,
                        _ => 9,
                    };
                    if let Some(c) = cubic.get_mut(slot) {
                        *c += 7.5 * value;
                    }
                }
            }
        }
        Expansion {
            normal: m.normal.into(),
            trace: s.trace(),
            square: [
                3.0 * s.m11,
                3.0 * s.m22,
                3.0 * s.m33,
                3.0 * (s.m12 + s.m21),
                3.0 * (s.m23 + s.m32),
                3.0 * (s.m13 + s.m31),
            ],
            linear: linear.into(),
            cubic,
        }
    }

    /// The cluster's solid angle seen from `u` away from its centroid, `inverse = 1/|u|`,
    /// each `a b + c` rounded as `A` does. The forms are taken of the unit direction
    /// `w = u/d` and scaled by powers of `1/d`,
    /// `d⁻² (N·w + d⁻¹ (tr spread − 3 wᵀ spread w) + d⁻² (C(w) − v·w))`: no power of the
    /// distance is formed, so a point however far gives a finite angle, not `∞ · 0`.
    #[inline(always)]
    fn solid_angle<A: MulAdd>(&self, u: [f64; 3], inverse: f64) -> f64 {
        let [x, y, z] = u.map(|c| c * inverse);
        let [nx, ny, nz] = self.normal;
        let [xx, yy, zz, xy, yz, zx] = self.square;
        let [vx, vy, vz] = self.linear;
        let [xxx, yyy, zzz, xxy, xxz, xyy, yyz, xzz, yzz, xyz] = self.cubic;
        let f = A::mul_add;
        let first = f(nx, x, f(ny, y, nz * z));
        let square = f(
            x,
            f(xx, x, xy * y),
            f(y, f(yy, y, yz * z), z * f(zz, z, zx * x)),
        );
        let linear = f(vx, x, f(vy, y, vz * z));
        let third = f(
            x * x,
            f(xxx, x, f(xxy, y, xxz * z)),
            f(
                y * y,
                f(yyy, y, f(xyy, x, yyz * z)),
                f(z * z, f(zzz, z, f(xzz, x, yzz * y)), xyz * x * y * z),
            ),
        );
        inverse
            * inverse
            * f(
                inverse,
                f(inverse, third - linear, self.trace - square),
                first,
            )
    }
}

/// How a batch evaluates the clusters' expansions: each `a b + c` rounded twice (any CPU),
/// or fused into one rounding where the CPU has FMA, in fewer instructions. The two differ
/// in the last bits of a sum, far within the approximation's error.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Arithmetic {
    Separate,
    #[cfg(target_arch = "x86_64")]
    Fused,
}

impl Arithmetic {
    /// Fused where this CPU has FMA, separate elsewhere.
    fn fastest() -> Arithmetic {
        #[cfg(target_arch = "x86_64")]
        if std::arch::is_x86_feature_detected!("fma") {
            return Arithmetic::Fused;
        }
        Arithmetic::Separate
    }
}

/// `a b + c` as an [`Arithmetic`] rounds it.
trait MulAdd {
    fn mul_add(a: f64, b: f64, c: f64) -> f64;
}

/// Two roundings.
struct Separate;

impl MulAdd for Separate {
    #[inline(always)]
    fn mul_add(a: f64, b: f64, c: f64) -> f64 {
        a * b + c
    }
}

/// One rounding: an FMA instruction where the code is compiled for it (elsewhere a slow
/// library call, so only [`descend_fused`] uses it).
#[cfg(target_arch = "x86_64")]
struct Fused;

#[cfg(target_arch = "x86_64")]
impl MulAdd for Fused {
    #[inline(always)]
    fn mul_add(a: f64, b: f64, c: f64) -> f64 {
        a.mul_add(b, c)
    }
}

/// [`descend`] compiled for CPUs with FMA, its expansions fused.
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "fma")]
fn descend_fused(
    index: &SurfaceIndex,
    clusters: &Clusters,
    p: &Vector3<f64>,
    accept: impl Fn(f64, f64, f64, f64) -> Option<f64>,
    stack: &mut Vec<u32>,
) -> Result<WindingResult, QueryError> {
    descend::<Fused>(index, clusters, p, accept, stack)
}

/// One point's winding number: clusters the rule accepts are summed by their expansions,
/// leaves' triangles exactly, the rest opened; a node's children are met together. The
/// rule, `accept(d, r, A, 1/d)` for a cluster of radius `r` and area `A` at distance
/// `d > r`, gives the bound on what its expansion errs by, or `None` to open it.
// Lanes count to WIDTH, the length of every array they index: no index can fail.
#[allow(clippy::indexing_slicing)]
#[inline(always)]
fn descend<A: MulAdd>(
    index: &SurfaceIndex,
    clusters: &Clusters,
    p: &Vector3<f64>,
    accept: impl Fn(f64, f64, f64, f64) -> Option<f64>,
    stack: &mut Vec<u32>,
) -> Result<WindingResult, QueryError> {
    let missing = || corrupt(Side::A, NodeDefect::Missing);
    let (mut sum, mut bound, mut work) = (0.0, 0.0, Work::default());
    stack.clear();
    stack.push(0);
    while let Some(node) = stack.pop() {
        let (Some(children), Some(reach)) = (index.node(node), clusters.nodes.get(node as usize))
        else {
            return Err(missing());
        };
        // The children's offsets and distances, all at once.
        let mut u = [[0.0; 3]; WIDTH];
        let mut distance = [0.0; WIDTH];
        for lane in 0..WIDTH {
            let [x, y, z] = [0, 1, 2].map(|k| reach.centroid[k][lane] - p[k]);
            u[lane] = [x, y, z];
            distance[lane] = (x * x + y * y + z * z).sqrt();
        }
        for lane in 0..WIDTH {
            let Some(slot) = children.slot(lane) else {
                continue;
            };
            work.nodes_visited += 1;
            let (distance, r, area) = (distance[lane], reach.radius[lane], reach.area[lane]);
            if distance > r {
                let inverse = 1.0 / distance;
                if let Some(error) = accept(distance, r, area, inverse) {
                    sum += reach.expansions[lane].solid_angle::<A>(u[lane], inverse);
                    bound += error;
                    work.bv_disjoint += 1;
                    continue;
                }
            }
            match slot {
                Slot::Node(child) => {
                    work.bv_overlap += 1;
                    stack.push(child);
                }
                Slot::Triangles(range) => {
                    for i in range {
                        let (t, _) = index.triangle(i).ok_or_else(missing)?;
                        sum += solid_angle(&(t[0] - p), &(t[1] - p), &(t[2] - p));
                        work.tri_separated += 1;
                    }
                }
            }
        }
    }
    Ok(WindingResult {
        value: sum / (4.0 * PI),
        error_bound: bound,
        work,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::build::{build, BuildOptions};

    /// The index of a small sphere's file.
    fn sphere_index() -> SurfaceIndex {
        let mesh = crate::generate::lat_long_sphere(1.0, 7, 9).expect("a sphere");
        let file = build(&mesh, &BuildOptions::default(), None).expect("builds");
        struct Index;
        impl TreeVisitor for Index {
            type Output = SurfaceIndex;
            fn visit<B: BoundingVolume>(self, tree: TreeView<'_, B>) -> SurfaceIndex {
                SurfaceIndex::build(&tree).expect("an index")
            }
        }
        file.visit(Index).expect("a view")
    }

    /// Merging children's moments gives what the subtree's triangles give directly.
    #[test]
    fn merged_moments_equal_the_moments_of_the_triangles() {
        let index = sphere_index();
        let (merged, radii) = slot_moments(&index).expect("moments");
        // The triangles under a slot.
        fn under(index: &SurfaceIndex, slot: &Slot) -> Vec<Triangle> {
            match slot {
                Slot::Triangles(range) => range
                    .clone()
                    .map(|i| *index.triangle(i).expect("a triangle").0)
                    .collect(),
                Slot::Node(n) => index
                    .node(*n)
                    .expect("a node")
                    .slots()
                    .flat_map(|(_, s)| under(index, &s))
                    .collect(),
            }
        }
        let mut slots = 0;
        for node in 0..index.node_count() {
            for (lane, slot) in index.node(node as u32).expect("a node").slots() {
                let m = &merged[node * WIDTH + lane];
                let direct = of_triangles(&under(&index, &slot));
                let close = |a: f64, b: f64| (a - b).abs() <= 1e-12 * (1.0 + b.abs());
                assert!(close(m.area, direct.area));
                assert!((m.centroid - direct.centroid).norm() < 1e-12);
                assert!((m.normal - direct.normal).norm() < 1e-12);
                assert!((m.spread - direct.spread).norm() < 1e-12, "node {node}");
                for i in 0..3 {
                    assert!((m.bend[i] - direct.bend[i]).norm() < 1e-12, "node {node}");
                }
                let corners = under(&index, &slot).into_iter().flatten();
                let reach = corners
                    .map(|c| (c - direct.centroid).norm())
                    .fold(0.0, f64::max);
                assert!(
                    (radii[node * WIDTH + lane] - reach).abs() < 1e-12,
                    "node {node}"
                );
                slots += 1;
            }
        }
        // Nodes of nodes were merged, not only leaves read.
        assert!(slots > index.node_count() * 2, "{slots} slots");
    }

    /// A cluster of no area (degenerate triangles only) is centred on its corners' mean: its
    /// radius stays finite, and merging it leaves its parent's moments as they were. (An
    /// undefined centroid would reach every ancestor through the merge and open them all.)
    #[test]
    fn a_cluster_of_no_area_sits_at_its_corners_mean() {
        let v = Vector3::new;
        let line = [v(0.0, 0.0, 0.0), v(1.0, 0.0, 0.0), v(2.0, 0.0, 0.0)];
        let point = [v(3.0, 1.0, 1.0); 3];
        let flat = of_triangles(&[line, point]);
        assert_eq!(flat.area, 0.0);
        assert!(
            (flat.centroid - v(2.0, 0.5, 0.5)).norm() < 1e-15,
            "{}",
            flat.centroid
        );
        let real = of_triangles(&[[v(0.0, 0.0, 1.0), v(2.0, 0.0, 1.0), v(0.0, 3.0, 1.0)]]);
        let both = merge(&[real, flat]);
        assert_eq!(both.area, real.area);
        assert!((both.centroid - real.centroid).norm() < 1e-15);
        assert!((both.spread - real.spread).norm() < 1e-15);
        for (b, r) in both.bend.iter().zip(&real.bend) {
            assert!((b - r).norm() < 1e-15);
        }
        // And a cluster of nothing at all sits at the origin.
        assert_eq!(
            centre(Vector3::zeros(), 0.0, std::iter::empty()),
            Vector3::zeros()
        );
    }

    /// The expansion's folded coefficients give the second-order formula term by term:
    /// `N·u/d³ + tr spread/d³ − 3 uᵀ spread u/d⁵ + ½ (−3 (2 Σᵢ bendᵢ row i + tr bendᵢ)·u/d⁵ +
    /// 15 Σᵢ uᵢ uᵀ bendᵢ u/d⁷)`, and that formula approaches the exact solid angle of a
    /// cluster seen from afar.
    #[test]
    fn expansion_is_the_second_order_formula() {
        let index = sphere_index();
        let (merged, _) = slot_moments(&index).expect("moments");
        let formula = |m: &Moment, u: &Vector3<f64>| {
            let d = u.norm();
            let (d3, d5, d7) = (d.powi(3), d.powi(5), d.powi(7));
            let quadratic: f64 = (0..3).map(|i| u[i] * u.dot(&(m.bend[i] * u))).sum();
            let rows: Vector3<f64> = (0..3).map(|i| m.bend[i].row(i).transpose()).sum();
            let traces = Vector3::new(m.bend[0].trace(), m.bend[1].trace(), m.bend[2].trace());
            m.normal.dot(u) / d3 + m.spread.trace() / d3 - 3.0 * u.dot(&(m.spread * u)) / d5
                + 0.5 * (-3.0 * (2.0 * rows.dot(u) + traces.dot(u)) / d5 + 15.0 * quadratic / d7)
        };
        let mut rng = crate::generate::Rng::new(3);
        for m in merged.iter().filter(|m| m.area > 0.0) {
            let e = Expansion::of(m);
            for _ in 0..20 {
                let u = Vector3::new(rng.signed(), rng.signed(), rng.signed()) * 5.0;
                let theirs = formula(m, &u);
                let separate = e.solid_angle::<Separate>(u.into(), 1.0 / u.norm());
                #[cfg(target_arch = "x86_64")]
                let fused = e.solid_angle::<Fused>(u.into(), 1.0 / u.norm());
                #[cfg(not(target_arch = "x86_64"))]
                let fused = separate;
                for ours in [separate, fused] {
                    assert!(
                        (ours - theirs).abs() <= 1e-12 * (1.0 + theirs.abs()),
                        "{ours} {theirs}"
                    );
                }
            }
        }
        // The whole sphere seen from outside subtends nothing, to second order in r/d.
        let root: Vec<Moment> = index
            .node(0)
            .expect("the root")
            .slots()
            .map(|(lane, _)| merged[lane])
            .collect();
        let whole = merge(&root);
        let far = Vector3::new(30.0, -20.0, 10.0);
        let angle = Expansion::of(&whole).solid_angle::<Separate>(far.into(), 1.0 / far.norm());
        assert!(angle.abs() < 1e-5, "{angle}");
    }

    /// Barill's rule bounds a cluster's error by at least the proven bound
    /// `A r³ / (π (d − r)⁵)`, and by that bound itself just beyond β radii.
    #[test]
    fn the_beta_rule_bounds_at_least_the_proven_error() {
        let proven = bounded(f64::MAX, 1.0);
        for beta in [1.5, 2.0, 3.0] {
            let rule = barill(beta);
            for (r, area) in [(0.5, 3.0), (2.0, 0.25)] {
                assert_eq!(rule(beta * r, r, area, 1.0 / (beta * r)), None);
                for stretch in [1.0 + 1e-9, 1.25, 2.0, 8.0] {
                    let d = beta * r * stretch;
                    let ours = rule(d, r, area, 1.0 / d).expect("accepted");
                    let truth = proven(d, r, area, 1.0 / d).expect("accepted");
                    assert!(
                        ours >= truth * (1.0 - 1e-12),
                        "{beta} {r} {d}: {ours} {truth}"
                    );
                    if stretch < 1.1 {
                        assert!(ours <= truth * (1.0 + 1e-6), "{beta} {r}: {ours} {truth}");
                    }
                }
            }
        }
        // A model of no area has every cluster summed exactly.
        assert_eq!(bounded(0.1, 0.0)(10.0, 1.0, 0.0, 0.1), None);
    }

    /// A triangle's solid angle does not change with scale, and far from the origin (where
    /// the formula's cubes overflow) it is the unit-size angle to the bit: a power of two
    /// scales exactly. Both ways to overflow: the numerator and the denominator together,
    /// and the denominator alone (a triangle seen almost edge-on, its triple product tiny).
    #[test]
    fn solid_angles_are_the_same_far_from_the_origin() {
        let v = Vector3::new;
        let far = 2f64.powi(400);
        for [a, b, c] in [
            [v(1.0, 0.2, 0.5), v(-0.3, 1.0, 0.4), v(0.1, -0.6, 0.9)],
            [v(0.5, -1.0, -2.0), v(0.25, 1.0, -1.5), v(-1.0, 0.0, -0.75)],
            [v(1.0, 0.0, 0.0), v(0.0, 1.0, 0.0), v(1.0, 1.0, 1e-60)],
        ] {
            let unit = solid_angle(&a, &b, &c);
            assert!(unit != 0.0 && unit.is_finite(), "{unit}");
            let (x, y) = (
                (a * far).dot(&(b * far).cross(&(c * far))),
                (a * far).norm(),
            );
            assert!(
                !(x.is_finite() && (y * y * y).is_finite()),
                "no overflow at this scale"
            );
            assert_eq!(solid_angle(&(a * far), &(b * far), &(c * far)), unit);
            // Seen from the other side: the sign changes, the size to rounding.
            let flipped = solid_angle(&(b * far), &(a * far), &(c * far));
            assert_eq!(flipped, solid_angle(&b, &a, &c));
            assert!((flipped + unit).abs() <= 4.0 * f64::EPSILON * unit.abs());
        }
    }

    /// A model so large that its large clusters' moments overflow (sums of fourth powers
    /// of its size) while its triangles' areas do not (a few times larger and they would,
    /// and no cluster could be placed) is still answered: such clusters are never taken as
    /// far away but opened down to their triangles, whose exact angles are finite. Inside
    /// and outside, at every accuracy.
    #[test]
    fn clusters_whose_moments_overflow_are_opened() {
        let mesh = crate::generate::lat_long_sphere(1.0, 7, 9).expect("a sphere");
        let options = BuildOptions {
            scale: 1.5e77,
            precision: crate::real::Precision::F64,
            ..BuildOptions::default()
        };
        let huge = build(&mesh, &options, None).expect("builds");
        let points = [[0.0; 3], [0.0, 0.2e77, 0.1e77], [4.5e77, 0.0, 0.0]];
        let answer = |accuracy| {
            let options = WindingOptions { accuracy };
            winding_numbers_with(
                &huge,
                &Pose::identity(),
                &points,
                &options,
                Arithmetic::Separate,
            )
            .expect("answers")
        };
        let exact = answer(WindingAccuracy::Exact);
        for (w, inside) in exact.iter().zip([1.0, 1.0, 0.0]) {
            assert!((w.value - inside).abs() < 1e-9, "{w:?}");
        }
        for accuracy in [
            WindingAccuracy::Beta { beta: 2.0 },
            WindingAccuracy::Bounded { tolerance: 1e-3 },
        ] {
            for (w, e) in answer(accuracy).iter().zip(&exact) {
                assert!(
                    (w.value - e.value).abs() <= w.error_bound + 1e-9,
                    "{accuracy:?}: {w:?} against {e:?}"
                );
            }
        }
    }

    /// Where this CPU has FMA, batches take the fused descent: its answers are the separate
    /// one's up to rounding, with the same error bounds and work.
    #[test]
    fn fused_and_separate_descents_agree() {
        let mesh = crate::mesh::TriMesh::load(
            concat!(env!("CARGO_MANIFEST_DIR"), "/assets/cow.obj").as_ref(),
        )
        .expect("the cow");
        let cow = build(&mesh, &BuildOptions::default(), None).expect("builds");
        let mut rng = crate::generate::Rng::new(5);
        let points: Vec<[f64; 3]> = (0..500)
            .map(|_| [0.6 * rng.signed(), 0.4 * rng.signed(), 0.3 * rng.signed()])
            .collect();
        let fastest = Arithmetic::fastest();
        for accuracy in [
            WindingAccuracy::Beta { beta: 2.0 },
            WindingAccuracy::Bounded { tolerance: 1e-3 },
        ] {
            let options = WindingOptions { accuracy };
            let answer = |arithmetic| {
                winding_numbers_with(&cow, &Pose::identity(), &points, &options, arithmetic)
                    .expect("answers")
            };
            let separate = answer(Arithmetic::Separate);
            let other = answer(fastest);
            for (s, o) in separate.iter().zip(&other) {
                assert!((s.value - o.value).abs() < 1e-12, "{s:?} {o:?}");
                assert_eq!((s.error_bound, s.work), (o.error_bound, o.work));
            }
            assert!(separate.iter().any(WindingResult::inside));
            assert!(separate.iter().any(|w| !w.inside()));
        }
    }
}
