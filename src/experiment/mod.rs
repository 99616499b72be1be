//! The experiments of the dissertation's chapter 5 as functions: each builds its shapes,
//! runs its collision queries for OBB, AABB and sphere trees, and returns what it measured
//! with what the dissertation reported beside it. `obbtree experiment` runs them and
//! writes their CSV files and plots.
//!
//! - [`sliding`]: the sliding spheres (§5.3.1);
//! - [`proximity`]: parallel close proximity (§5.3.2);
//! - [`transverse`]: transverse contact as the tessellation grows (§5.3.3.1).
//!
//! Every query is an all-pairs collision query whose work is counted as the dissertation
//! counts it: D disjoint and I overlapping volume pairs, S separated and K contacting
//! triangle pairs (so 1 = D − I + 2S + 2K for binary trees, and the volume tests are
//! D + I). Queries run on rayon's pool: in a pool of one thread the times are those of a
//! query alone; with more they are inflated by the work beside them.

pub mod accuracy;
pub mod proximity;
pub mod sliding;
pub mod transverse;

use crate::build::{build, BuildError, BuildOptions, SphereFit};
use crate::bv::BvKind;
use crate::format::ObbtFile;
use crate::generate::{GenerateError, PosePair, Rng};
use crate::mesh::TriMesh;
use crate::query::{BoxTest, CollideOptions, PairQuery, Pose, QueryContext, QueryError, Work};
use crate::real::Precision;
use crate::stats::LevelStats;
use nalgebra::Vector3;
use rayon::prelude::*;
use std::sync::atomic::{AtomicU64, Ordering};
use std::time::Instant;

/// How far an experiment has got, for a progress display on another thread: queries done
/// of the queries it will run (set when it starts).
#[derive(Debug, Default)]
pub struct Progress {
    /// Queries run so far.
    pub done: AtomicU64,
    /// Queries the experiment runs in all.
    pub total: AtomicU64,
}

impl Progress {
    fn plan(progress: Option<&Progress>, queries: u64) {
        if let Some(p) = progress {
            p.total.fetch_add(queries, Ordering::Relaxed);
        }
    }
}

/// How large an experiment is.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Size {
    /// The dissertation's sizes (meshes, steps and repetitions).
    Full,
    /// A reduced size that runs in seconds, with the same shape of results (for tests and
    /// a first look).
    Quick,
}

/// Why an experiment stopped.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum ExperimentError {
    /// A shape or pose could not be made.
    #[error(transparent)]
    Generate(#[from] GenerateError),
    /// A tree could not be built.
    #[error(transparent)]
    Build(#[from] BuildError),
    /// A query failed.
    #[error(transparent)]
    Query(#[from] QueryError),
    /// A tree's levels could not be measured (a bug: the experiments' trees are sound).
    #[error("measuring a tree's levels")]
    Levels(#[source] crate::format::VerifyError),
}

/// How the trees are built and their volumes tested, beyond the volume type: today's
/// defaults, or how the dissertation's experiments did it where that differs.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub enum Variant {
    /// The defaults: the 15-axis box test, spheres centred on their box.
    #[default]
    Standard,
    /// Boxes tested as the dissertation tested AABBs: B's re-wrapped in a box aligned with
    /// A's ([`BoxTest::Rewrapped`]).
    Rewrapped,
    /// Spheres centred on their smallest enclosing ball ([`SphereFit::Minimal`]).
    MinimalSpheres,
}

/// One measured point: one volume type at one value of the experiment's parameter,
/// averaged over its queries.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Point {
    /// The volume type of both trees.
    pub bv: BvKind,
    /// How they were built and tested.
    pub variant: Variant,
    /// The experiment's parameter (an offset, a gap, a triangle count).
    pub x: f64,
    /// Queries averaged.
    pub queries: u32,
    /// Mean contacting triangle pairs (K).
    pub contacts: f64,
    /// Mean disjoint volume pairs (D).
    pub disjoint: f64,
    /// Mean overlapping volume pairs (I).
    pub overlap: f64,
    /// Mean separated triangle pairs (S).
    pub separated: f64,
    /// Mean of the least number of volume tests that can find each query's contacts
    /// ([`lower_bound`]; a query without contacts counts 0).
    pub lower_bound: f64,
    /// Median time of one query, seconds.
    pub seconds: f64,
}

impl Point {
    /// The setup's name: the volume type (`obb`, `aabb`, `sphere`), with `-rewrapped` or
    /// `-minimal` for the dissertation's variants.
    pub fn label(&self) -> String {
        let suffix = match self.variant {
            Variant::Standard => "",
            Variant::Rewrapped => "-rewrapped",
            Variant::MinimalSpheres => "-minimal",
        };
        format!("{}{suffix}", self.bv.name())
    }

    /// Mean volume tests, D + I.
    pub fn bv_tests(&self) -> f64 {
        self.disjoint + self.overlap
    }

    /// Mean triangle tests, S + K.
    pub fn tri_tests(&self) -> f64 {
        self.separated + self.contacts
    }
}

/// A figure of the dissertation beside the one measured.
#[derive(Clone, Debug, PartialEq)]
pub struct Comparison {
    /// What is compared.
    pub what: String,
    /// The dissertation's figure, as it states it.
    pub dissertation: String,
    /// What this run measured.
    pub measured: String,
}

impl Comparison {
    fn new(what: &str, dissertation: &str, measured: String) -> Comparison {
        Comparison {
            what: what.into(),
            dissertation: dissertation.into(),
            measured,
        }
    }
}

/// What an experiment measured.
#[derive(Clone, Debug, PartialEq)]
pub struct Outcome {
    /// The experiment's name (`sliding`, `proximity`, `transverse`).
    pub name: &'static str,
    /// What the points' `x` is, with its unit.
    pub x_name: &'static str,
    /// The CSV column of `x` (`offset`, `gap`, `triangles`).
    pub x_column: &'static str,
    /// Every point, volume type by volume type, each in order of x.
    pub points: Vec<Point>,
    /// Lines fitted on log-log axes.
    pub fits: Vec<Fit>,
    /// The dissertation's figures beside this run's.
    pub comparisons: Vec<Comparison>,
    /// The volumes of one tree per volume type measured level by level, where the
    /// experiment looks at them (Fig. 5.17); empty otherwise.
    pub levels: Vec<(BvKind, Vec<LevelStats>)>,
}

/// A line fitted to `log10(measure)` against `log10(x)` over part of the points.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Fit {
    /// The volume type whose points were fitted.
    pub bv: BvKind,
    /// The measure fitted: `"bv_tests"` or `"contacts"`.
    pub measure: &'static str,
    /// The fitted line (its slope is the exponent of the power law).
    pub line: Line,
    /// The range of x fitted.
    pub from: f64,
    /// The range of x fitted.
    pub to: f64,
}

/// A straight line `y = slope · x + intercept` fitted by least squares.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Line {
    /// The slope.
    pub slope: f64,
    /// The value at x = 0.
    pub intercept: f64,
}

/// The least-squares line through `points`; `None` for fewer than two distinct x.
pub fn fit_line(points: &[(f64, f64)]) -> Option<Line> {
    let n = points.len() as f64;
    let (sx, sy) = points
        .iter()
        .fold((0.0, 0.0), |(sx, sy), (x, y)| (sx + x, sy + y));
    let (mx, my) = (sx / n, sy / n);
    let (sxx, sxy) = points.iter().fold((0.0, 0.0), |(sxx, sxy), (x, y)| {
        (sxx + (x - mx) * (x - mx), sxy + (x - mx) * (y - my))
    });
    (points.len() >= 2 && sxx > 0.0).then(|| {
        let slope = sxy / sxx;
        Line {
            slope,
            intercept: my - slope * mx,
        }
    })
}

/// The trees of the experiments: default builds (hull fit, OBB frames also tried on the
/// model's axes) in f64, as the dissertation's were in double precision; minimal-ball
/// spheres for [`Variant::MinimalSpheres`].
fn tree(mesh: &TriMesh, bv: BvKind, variant: Variant) -> Result<ObbtFile, BuildError> {
    let sphere_fit = if variant == Variant::MinimalSpheres {
        SphereFit::Minimal
    } else {
        SphereFit::BoxCentre
    };
    let options = BuildOptions {
        bv,
        precision: Precision::F64,
        sphere_fit,
        ..BuildOptions::default()
    };
    build(mesh, &options, None)
}

/// Both models turned at random (uniformly, drawn from `rng`) and B's centre at
/// `offset`: "the two spheres are given random orientation".
fn turned_pair(rng: &mut Rng, offset: Vector3<f64>) -> PosePair {
    let a = Pose::new(rng.uniform_rotation(), Vector3::zeros()).unwrap_or_default();
    let b = Pose::new(rng.uniform_rotation(), offset).unwrap_or_default();
    [a, b]
}

/// A point's queries: the trees and, for each query, its pose pair.
struct Job<'t> {
    a: &'t ObbtFile,
    b: &'t ObbtFile,
    bv: BvKind,
    variant: Variant,
    x: f64,
    poses: Vec<PosePair>,
}

/// Runs every job's queries (in parallel over all queries of all jobs) and averages each
/// job's into a [`Point`], counting each query done in `progress`.
fn measure(jobs: &[Job<'_>], progress: Option<&Progress>) -> Result<Vec<Point>, ExperimentError> {
    let queries: Vec<(usize, &Job<'_>, &PosePair)> = jobs
        .iter()
        .enumerate()
        .flat_map(|(j, job)| job.poses.iter().map(move |p| (j, job, p)))
        .collect();
    let results: Vec<Result<(usize, Work, usize, f64), QueryError>> = queries
        .par_iter()
        .map_init(QueryContext::new, |context, &(j, job, [pa, pb])| {
            let options = CollideOptions {
                box_test: if job.variant == Variant::Rewrapped {
                    BoxTest::Rewrapped
                } else {
                    BoxTest::SeparatingAxes
                },
                ..CollideOptions::default()
            };
            let mut pair = PairQuery::with_context(job.a, job.b, std::mem::take(context))?;
            let started = Instant::now();
            let r = pair.collide(pa, pb, &options);
            let seconds = started.elapsed().as_secs_f64();
            *context = pair.into_context();
            let r = r?;
            if let Some(p) = progress {
                p.done.fetch_add(1, Ordering::Relaxed);
            }
            Ok((j, r.work, r.pairs.len(), seconds))
        })
        .collect();
    let mut sums = vec![(Work::default(), 0.0f64, Vec::new()); jobs.len()];
    for result in results {
        let (j, stats, contacts, seconds) = result?;
        let (Some((sum, bound, times)), Some(job)) = (sums.get_mut(j), jobs.get(j)) else {
            continue;
        };
        sum.bv_disjoint += stats.bv_disjoint;
        sum.bv_overlap += stats.bv_overlap;
        sum.tri_separated += stats.tri_separated;
        sum.tri_contact += stats.tri_contact;
        *bound += lower_bound(job.a, job.b, contacts).unwrap_or(0.0);
        times.push(seconds);
    }
    Ok(jobs
        .iter()
        .zip(sums)
        .map(|(job, (sum, bound, mut times))| {
            let n = job.poses.len().max(1) as f64;
            times.sort_by(f64::total_cmp);
            Point {
                bv: job.bv,
                variant: job.variant,
                x: job.x,
                queries: job.poses.len() as u32,
                contacts: sum.tri_contact as f64 / n,
                disjoint: sum.bv_disjoint as f64 / n,
                overlap: sum.bv_overlap as f64 / n,
                separated: sum.tri_separated as f64 / n,
                lower_bound: bound / n,
                seconds: times.get(times.len() / 2).copied().unwrap_or(0.0),
            }
        })
        .collect())
}

/// The least number of volume tests that can locate `contacts` contacting triangle pairs
/// between two trees (§2.6.3: ideal volumes, balanced binary trees, the contacts in one
/// block of the n_a · n_b pairs): `2 log2(n_a n_b / k) + 2k − 1`. `None` without
/// contacts, or when a leaf holds more than one triangle (the bound counts single-triangle
/// leaves).
pub fn lower_bound(a: &ObbtFile, b: &ObbtFile, contacts: usize) -> Option<f64> {
    let single = |f: &ObbtFile| f.info().stats.shape.max_leaf_faces == 1;
    if contacts == 0 || !single(a) || !single(b) {
        return None;
    }
    let cells = f64::from(a.info().triangles) * f64::from(b.info().triangles);
    let k = contacts as f64;
    Some(2.0 * (cells / k).log2() + 2.0 * k - 1.0)
}

/// The points of one volume type with the default setup, in order of x.
pub fn of_kind(points: &[Point], bv: BvKind) -> Vec<Point> {
    of_variant(points, bv, Variant::Standard)
}

/// The points of one volume type and variant, in order of x.
pub fn of_variant(points: &[Point], bv: BvKind, variant: Variant) -> Vec<Point> {
    let kept = points.iter().filter(|p| p.bv == bv && p.variant == variant);
    kept.copied().collect()
}

/// Runs `query` `repeat` times (at least once): its last answer, and the median time of
/// one run in seconds.
///
/// # Errors
///
/// The first error `query` returns; the runs stop there.
///
/// # Examples
///
/// ```
/// use obbtree::experiment::median_time;
///
/// let (answer, seconds) = median_time(5, || Ok::<_, String>(6 * 7))?;
/// assert_eq!(answer, 42);
/// assert!(seconds >= 0.0);
/// assert_eq!(median_time(5, || Err::<u32, _>("no")), Err("no"));
/// # Ok::<(), String>(())
/// ```
pub fn median_time<T, E>(
    repeat: u32,
    mut query: impl FnMut() -> Result<T, E>,
) -> Result<(T, f64), E> {
    let started = Instant::now();
    let mut answer = query()?;
    let mut times = vec![started.elapsed().as_secs_f64()];
    for _ in 1..repeat {
        let started = Instant::now();
        answer = query()?;
        times.push(started.elapsed().as_secs_f64());
    }
    Ok((answer, median(times).unwrap_or(0.0)))
}

/// The median: the middle value, or the mean of the two middle ones.
fn median(mut values: Vec<f64>) -> Option<f64> {
    values.sort_by(f64::total_cmp);
    let n = values.len();
    let upper = *values.get(n / 2)?;
    if n % 2 == 1 {
        return Some(upper);
    }
    Some((values.get(n / 2 - 1).copied().unwrap_or(upper) + upper) / 2.0)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_fitted_line_recovers_slope_and_intercept() {
        let points: Vec<(f64, f64)> = (0..10)
            .map(|i| (f64::from(i), 3.0 - 1.5 * f64::from(i)))
            .collect();
        let line = fit_line(&points).unwrap();
        assert!((line.slope + 1.5).abs() < 1e-12 && (line.intercept - 3.0).abs() < 1e-12);
        assert!(fit_line(&[(1.0, 2.0)]).is_none());
        assert!(fit_line(&[(1.0, 2.0), (1.0, 3.0)]).is_none());
    }
}
