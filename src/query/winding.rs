//! Inside or outside: the generalised winding number of one posed model at query points
//! (Jacobson, Kavan and Sorkine-Hornung 2013), summed exactly triangle by triangle or, for
//! far clusters of triangles, by their dipole moment (Barill et al. 2018) under a proven
//! bound on the error.
//!
//! The winding number of a closed, outward-facing surface is 1 inside and 0 outside; of a
//! surface with holes, duplicate or self-intersecting triangles (a soup) it varies smoothly
//! between, and `> 0.5` is the robust inside test.

use super::closest::{closest_points, ClosestOptions};
use super::engine::{corrupt, triangle};
use super::triangle::Triangle;
use super::{check_points, QueryError, Side, Work};
use crate::bv::BoundingVolume;
use crate::format::{ObbtFile, TreeVisitor};
use crate::pose::Pose;
use crate::tree::{NodeDefect, NodeKind, TreeView};
use nalgebra::{Matrix3, Vector3};
use rayon::prelude::*;
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
    /// is summed by its moments. The fast choice (as libigl's default, `beta` 2); its
    /// error is not bounded beforehand ([`WindingResult::error_bound`] still bounds what it
    /// did), and is measured small in practice.
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
    /// outside, between for open surfaces; the point is inside where it is `> 0.5`.
    pub value: f64,
    /// A proven bound on `|value − exact|` from the clusters summed by their moments: 0
    /// for [`WindingAccuracy::Exact`], at most the tolerance for
    /// [`WindingAccuracy::Bounded`], often far above the error made for
    /// [`WindingAccuracy::Beta`]. Rounding comes on top.
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
/// - [`QueryError::BadInput`] for a query point with a non-finite coordinate,
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
    check_points(points)?;
    /// The typed descent, run for every point.
    struct Visit<'q> {
        model: &'q ObbtFile,
        pose: &'q Pose,
        points: &'q [[f64; 3]],
        accuracy: WindingAccuracy,
    }
    impl TreeVisitor for Visit<'_> {
        type Output = Result<Vec<WindingResult>, QueryError>;
        fn visit<B: BoundingVolume>(self, tree: TreeView<'_, B>) -> Self::Output {
            // Made at the file's first winding query and kept with it, as the surface index.
            let clusters = self.model.derived(|| Clusters::of(&tree))?;
            let (moments, reach) = (&clusters.moments, &clusters.reach);
            let rule = match self.accuracy {
                WindingAccuracy::Exact => Rule::Exact,
                // Bound per unit area: a cluster of area A may err by A times this.
                WindingAccuracy::Bounded { tolerance } => match moments.first().map(|m| m.area) {
                    Some(total) if total > 0.0 => Rule::Rate(tolerance / total),
                    _ => Rule::Exact,
                },
                WindingAccuracy::Beta { beta } => Rule::Beta(beta),
            };
            let to_model = Pose::relative(self.pose, &Pose::identity());
            self.points
                .par_iter()
                .map_init(Vec::new, |stack, p| {
                    let local = to_model.apply(&Vector3::from(*p));
                    descend(&tree, reach, moments, &local, rule, stack)
                })
                .collect()
        }
    }
    model.visit(Visit {
        model,
        pose,
        points,
        accuracy: options.accuracy,
    })?
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

/// What a cluster of triangles (a node's) looks like from afar (model frame): its area, its
/// area-weighted normal `N = Σ A n`, its area-weighted centroid `c`, the moments
/// `spread = Σ n ∫ (x − c)ᵀ dA` and `bend[i] = Σ nᵢ ∫ (x − c)(x − c)ᵀ dA` over its
/// triangles (unit normals `n`), and the radius about `c` within which all its corners lie.
#[derive(Clone, Copy, Debug, Default)]
struct Moment {
    area: f64,
    normal: Vector3<f64>,
    centroid: Vector3<f64>,
    spread: Matrix3<f64>,
    bend: [Matrix3<f64>; 3],
    /// `Σᵢ bend[i]` row `i`, and the traces of `bend`: what the expansion reads of it.
    bend_rows: Vector3<f64>,
    bend_traces: Vector3<f64>,
    radius: f64,
}

impl Moment {
    /// The moment of these parts, with what the expansion reads of `bend`.
    fn new(
        area: f64,
        normal: Vector3<f64>,
        centroid: Vector3<f64>,
        spread: Matrix3<f64>,
        bend: [Matrix3<f64>; 3],
        radius: f64,
    ) -> Moment {
        Moment {
            area,
            normal,
            centroid,
            spread,
            bend,
            bend_rows: bend
                .iter()
                .enumerate()
                .map(|(i, b)| b.row(i).transpose())
                .sum(),
            bend_traces: Vector3::new(bend[0].trace(), bend[1].trace(), bend[2].trace()),
            radius,
        }
    }
}

/// What a descent reads of every node it reaches: the moment's centroid, radius and area,
/// apart from the rest, which it reads only for the clusters it sums by moments (a tenth
/// of the bytes, for the nodes a point opens).
#[derive(Clone, Copy, Debug)]
struct Reach {
    centroid: Vector3<f64>,
    radius: f64,
    area: f64,
}

/// Every node's moments, and the part of them a descent reads for every cluster it meets.
struct Clusters {
    moments: Vec<Moment>,
    reach: Vec<Reach>,
}

impl Clusters {
    fn of<B: BoundingVolume>(tree: &TreeView<'_, B>) -> Result<Clusters, QueryError> {
        let moments = moments(tree)?;
        let reach = moments
            .iter()
            .map(|m| Reach {
                centroid: m.centroid,
                radius: m.radius,
                area: m.area,
            })
            .collect();
        Ok(Clusters { moments, reach })
    }
}

/// Every node's moment, children before parents (children follow their parent in the
/// node array, checked by `node_kind`).
fn moments<B: BoundingVolume>(tree: &TreeView<'_, B>) -> Result<Vec<Moment>, QueryError> {
    let mut out = vec![Moment::default(); tree.nodes().len()];
    for node in (0..tree.nodes().len() as u32).rev() {
        let m = match tree.node_kind(node).map_err(|d| corrupt(Side::A, d))? {
            NodeKind::Faces(faces) => {
                let triangles = faces
                    .map(|face| triangle(tree, face, None, Side::A))
                    .collect::<Result<Vec<_>, _>>()?;
                of_triangles(&triangles)
            }
            NodeKind::Children(range) => {
                let kids = out
                    .get(range.start as usize..range.end as usize)
                    .ok_or_else(|| corrupt(Side::A, NodeDefect::BadChildren))?;
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
                let radius = kids
                    .iter()
                    .map(|k| (k.centroid - centroid).norm() + k.radius)
                    .fold(0.0, f64::max);
                Moment::new(area, normal, centroid, spread, bend, radius)
            }
        };
        if let Some(slot) = out.get_mut(node as usize) {
            *slot = m;
        }
    }
    Ok(out)
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
    let radius = triangles
        .iter()
        .flatten()
        .map(|c| (c - centroid).norm())
        .fold(0.0, f64::max);
    Moment::new(area, normal, centroid, spread, bend, radius)
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
    let (la, lb, lc) = (a.norm(), b.norm(), c.norm());
    let numerator = a.dot(&b.cross(c));
    let denominator = la * lb * lc + a.dot(b) * lc + b.dot(c) * la + c.dot(a) * lb;
    2.0 * numerator.atan2(denominator)
}

/// Which clusters a descent sums by their moments.
#[derive(Clone, Copy, Debug)]
enum Rule {
    /// None.
    Exact,
    /// Those whose error bound is within this many times their area.
    Rate(f64),
    /// Those farther than this many times their radius.
    Beta(f64),
}

/// One point's winding number: clusters the rule accepts are summed by moments, leaves
/// exactly, the rest opened.
fn descend<B: BoundingVolume>(
    tree: &TreeView<'_, B>,
    reach: &[Reach],
    moments: &[Moment],
    p: &Vector3<f64>,
    rule: Rule,
    stack: &mut Vec<u32>,
) -> Result<WindingResult, QueryError> {
    let (mut sum, mut bound, mut work) = (0.0, 0.0, Work::default());
    stack.clear();
    stack.push(0);
    while let Some(node) = stack.pop() {
        work.nodes_visited += 1;
        let missing = || corrupt(Side::A, NodeDefect::Missing);
        let near = reach.get(node as usize).ok_or_else(missing)?;
        let offset = near.centroid - p;
        let distance = offset.norm();
        if distance > near.radius {
            let (gap, r) = (distance - near.radius, near.radius);
            // The bound on what summing by moments errs by.
            let error = || near.area * r * r * r / (PI * gap * gap * gap * gap * gap);
            // The bound of a cluster summed by moments, computed once and only when needed.
            let accepted = match rule {
                Rule::Exact => None,
                Rule::Rate(rate) => Some(error()).filter(|e| *e <= rate * near.area),
                Rule::Beta(beta) => (distance > beta * r).then(error),
            };
            if let Some(error) = accepted {
                let m = moments.get(node as usize).ok_or_else(missing)?;
                // The kernel g = ∇φ, φ(x) = −1/|x − p|, to second order about the
                // centroid, u = c − p: ∂ᵢφ = uᵢ/d³, ∂ᵢⱼφ = δᵢⱼ/d³ − 3uᵢuⱼ/d⁵,
                // ∂ᵢⱼₖφ = −3(δᵢⱼuₖ + δᵢₖuⱼ + δⱼₖuᵢ)/d⁵ + 15uᵢuⱼuₖ/d⁷, against N, spread
                // and bend/2.
                let u = offset;
                let d2 = distance * distance;
                let d3 = d2 * distance;
                let (d5, d7) = (d3 * d2, d3 * d2 * d2);
                let quadratic: f64 = m
                    .bend
                    .iter()
                    .zip(u.iter())
                    .map(|(b, ui)| ui * u.dot(&(b * u)))
                    .sum();
                sum += m.normal.dot(&u) / d3 + m.spread.trace() / d3
                    - 3.0 * u.dot(&(m.spread * u)) / d5
                    + 0.5
                        * (-3.0 * (2.0 * m.bend_rows.dot(&u) + m.bend_traces.dot(&u)) / d5
                            + 15.0 * quadratic / d7);
                bound += error;
                work.bv_disjoint += 1;
                continue;
            }
        }
        match tree.node_kind(node).map_err(|d| corrupt(Side::A, d))? {
            NodeKind::Faces(faces) => {
                for face in faces {
                    let t = triangle(tree, face, None, Side::A)?;
                    sum += solid_angle(&(t[0] - p), &(t[1] - p), &(t[2] - p));
                    work.tri_separated += 1;
                }
            }
            NodeKind::Children(range) => {
                work.bv_overlap += 1;
                stack.extend(range);
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

    /// Merging children's moments gives what the subtree's triangles give directly.
    #[test]
    fn merged_moments_equal_the_moments_of_the_triangles() {
        let mesh = crate::generate::lat_long_sphere(1.0, 7, 9).expect("a sphere");
        let file = build(&mesh, &BuildOptions::default(), None).expect("builds");
        struct Check;
        impl TreeVisitor for Check {
            type Output = ();
            fn visit<B: BoundingVolume>(self, tree: TreeView<'_, B>) {
                let merged = moments(&tree).expect("moments");
                // Each node's faces: a leaf's own, else its children's.
                let mut faces: Vec<Vec<u32>> = vec![Vec::new(); merged.len()];
                for node in (0..merged.len() as u32).rev() {
                    faces[node as usize] = match tree.node_kind(node).expect("a node") {
                        NodeKind::Faces(range) => range.collect(),
                        NodeKind::Children(range) => {
                            range.flat_map(|c| faces[c as usize].clone()).collect()
                        }
                    };
                }
                for (node, m) in merged.iter().enumerate() {
                    let ts: Vec<Triangle> = faces[node]
                        .iter()
                        .map(|&f| triangle(&tree, f, None, Side::A).expect("a triangle"))
                        .collect();
                    let direct = of_triangles(&ts);
                    let close = |a: f64, b: f64| (a - b).abs() <= 1e-12 * (1.0 + b.abs());
                    assert!(close(m.area, direct.area));
                    assert!((m.centroid - direct.centroid).norm() < 1e-12);
                    assert!((m.normal - direct.normal).norm() < 1e-12);
                    assert!((m.spread - direct.spread).norm() < 1e-12, "node {node}");
                    for i in 0..3 {
                        assert!((m.bend[i] - direct.bend[i]).norm() < 1e-12, "node {node}");
                    }
                    assert!(m.radius >= direct.radius - 1e-12);
                }
            }
        }
        file.visit(Check).expect("a view");
    }
}
