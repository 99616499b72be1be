//! What accuracy and size cost in time: the choices that trade one for the other (the
//! distance and Hausdorff error allowed, tolerance queries, f32 or f64 storage, the fit,
//! the leaf size, the compact layout), each measured by the time it takes, the error it actually incurs
//! against an exact f64 reference and the bytes its trees take, on the sliding spheres and
//! on any mesh against a turned copy of itself.
//!
//! A choice is worth making when no other is both faster and more accurate: the Pareto
//! front of each scene's (error, time) points ([`Trade::pareto`]). Size is the third
//! axis: the compact layout answers exactly, slower, from smaller files
//! ([`Trade::bytes_per_triangle`]).

use super::{median_time, turned_pair, ExperimentError, Size};
use crate::build::{build, BuildOptions};
use crate::bv::Layout;
use crate::fit::FitMethod;
use crate::format::ObbtFile;
use crate::generate::{lat_long_sphere, PosePair, Rng};
use crate::mesh::TriMesh;
use crate::query::{
    hausdorff, CollideOptions, DistanceOptions, HausdorffOptions, PairQuery, Pose, QueryError,
    ToleranceOptions,
};
use crate::real::Precision;
use nalgebra::Vector3;
use std::collections::BTreeSet;

/// Two models and the poses each query kind is measured at.
#[derive(Clone, Debug)]
pub struct Workload {
    /// Its name in tables and files.
    pub name: String,
    /// Model A.
    pub a: TriMesh,
    /// Model B.
    pub b: TriMesh,
    /// Poses where the models are apart (distance queries).
    pub apart: Vec<PosePair>,
    /// Poses where they cross (collision and Hausdorff queries).
    pub crossing: Vec<PosePair>,
}

/// The sliding spheres (§5.3.1) at 8 separated positions (x from 1.85 to 2.2) and 3
/// crossing ones (x = 0.5, 1.0, 1.5), both turned at random.
///
/// # Errors
///
/// [`ExperimentError::Generate`] if the spheres or poses cannot be made (a bug: the
/// parameters are fixed).
pub fn spheres(size: Size, seed: u64) -> Result<Workload, ExperimentError> {
    let (stacks, slices) = match size {
        Size::Full => (101, 200),
        Size::Quick => (21, 40),
    };
    let mut rng = Rng::new(seed);
    let mut at = |x: f64| turned_pair(&mut rng, Vector3::new(x, 0.0, 0.0));
    let apart = (0..8).map(|i| at(1.85 + 0.05 * f64::from(i))).collect();
    let crossing = [0.5, 1.0, 1.5].map(&mut at).to_vec();
    Ok(Workload {
        name: "spheres".into(),
        a: lat_long_sphere(1.0, stacks, slices)?,
        b: lat_long_sphere(0.8, stacks, slices)?,
        apart,
        crossing,
    })
}

/// `mesh` against a turned copy of itself: 8 poses with the copy's centre 1.1 bounding-box
/// diagonals away in random directions, and 3 with it a quarter of a diagonal away.
pub fn turned_copy(name: &str, mesh: &TriMesh, seed: u64) -> Workload {
    let (lo, hi) = crate::arr3::bounds(mesh.vertices());
    let diagonal = Vector3::from(crate::arr3::sub(hi, lo)).norm();
    let centre = (Vector3::from(lo) + Vector3::from(hi)) / 2.0;
    let mut rng = Rng::new(seed);
    let mut at = |distance: f64| -> PosePair {
        let direction = rng.uniform_rotation() * Vector3::x();
        let turn = rng.uniform_rotation();
        // B turned about its centre, which lands `distance` from A's.
        let offset = centre + direction * distance - turn * centre;
        [
            Pose::identity(),
            Pose::new(turn, offset).unwrap_or_default(),
        ]
    };
    let apart = (0..8).map(|_| at(1.1 * diagonal)).collect();
    let crossing = (0..3).map(|_| at(0.25 * diagonal)).collect();
    Workload {
        name: name.into(),
        a: mesh.clone(),
        b: mesh.clone(),
        apart,
        crossing,
    }
}

/// One choice measured on one scene and query kind.
#[derive(Clone, Debug, PartialEq)]
pub struct Trade {
    /// The scene's name.
    pub scene: String,
    /// `distance`, `collision` or `hausdorff`.
    pub query: &'static str,
    /// The choice, as the command line spells it (`f32, --rel-err 0.01`).
    pub choice: String,
    /// Seconds for the scene's poses: the sum over poses of each pose's median time.
    pub seconds: f64,
    /// The error incurred, mean over the poses: for distance and Hausdorff distance the
    /// relative difference from the exact f64 answer, for collision the share of contacting
    /// pairs that differ from the exact f64 answer (gained or lost).
    pub error_mean: f64,
    /// The largest error over the poses.
    pub error_max: f64,
    /// Mean volume tests per query.
    pub bv_tests: f64,
    /// The bytes of both models' tree files per triangle they hold.
    pub bytes_per_triangle: f64,
    /// Whether the exact answer was asked for (every collision; a distance or Hausdorff
    /// distance without an error allowance or tolerance): what differs between such trades
    /// is the tree.
    pub exact: bool,
    /// Whether no other choice of the same scene and query is at least as fast and at
    /// least as accurate (by the largest error), and better in one.
    pub pareto: bool,
}

impl Trade {
    /// A trade of trees of `bytes_per_triangle` with nothing measured yet.
    fn new(scene: &str, query: &'static str, choice: String, bytes_per_triangle: f64) -> Trade {
        Trade {
            scene: scene.into(),
            query,
            choice,
            seconds: 0.0,
            error_mean: 0.0,
            error_max: 0.0,
            bv_tests: 0.0,
            bytes_per_triangle,
            exact: true,
            pareto: false,
        }
    }
}

/// A tree choice: storage precision, layout, fit and leaf size.
#[derive(Clone, Copy, Debug)]
struct TreeChoice {
    precision: Precision,
    layout: Layout,
    fit: FitMethod,
    leaf_size: u32,
}

impl TreeChoice {
    const DEFAULT: TreeChoice = TreeChoice {
        precision: Precision::F32,
        layout: Layout::Fast,
        fit: FitMethod::Hull,
        leaf_size: 1,
    };

    /// The flags that differ from the defaults.
    fn flags(self) -> Vec<String> {
        let mut flags = vec![self.precision.name().to_string()];
        if self.layout != Layout::Fast {
            flags.push(format!("--layout {}", self.layout.name()));
        }
        if self.fit != FitMethod::Hull {
            flags.push(format!("--fit {}", self.fit.name()));
        }
        if self.leaf_size != self.layout.default_leaf_size() {
            flags.push(format!("--leaf-size {}", self.leaf_size));
        }
        flags
    }

    fn options(self) -> BuildOptions {
        BuildOptions {
            precision: self.precision,
            layout: self.layout,
            fit: self.fit,
            leaf_size: self.leaf_size,
            ..BuildOptions::default()
        }
    }
}

/// The tree choices measured: f32 and f64, the compact layout, the two other fits, and
/// larger leaves.
fn tree_choices() -> Vec<TreeChoice> {
    let d = TreeChoice::DEFAULT;
    vec![
        d,
        TreeChoice {
            precision: Precision::F64,
            ..d
        },
        TreeChoice {
            layout: Layout::Compact,
            leaf_size: Layout::Compact.default_leaf_size(),
            ..d
        },
        TreeChoice {
            fit: FitMethod::Triangles,
            ..d
        },
        TreeChoice {
            fit: FitMethod::Vertices,
            ..d
        },
        TreeChoice { leaf_size: 4, ..d },
        TreeChoice { leaf_size: 16, ..d },
    ]
}

/// How a distance is asked for.
#[derive(Clone, Copy, Debug)]
enum Ask {
    /// `--rel-err r` (0: exact).
    RelErr(f64),
    /// `--tolerance (1 + t)·d*`: is the distance below a bound a share `t` above it? The
    /// witness's distance is the answer measured. Spelt `--tolerance 1.1d` for `t` = 0.1.
    Tolerance(f64),
}

impl Ask {
    fn flag(self) -> String {
        match self {
            Ask::RelErr(0.0) => "exact".into(),
            Ask::RelErr(r) => format!("--rel-err {r}"),
            Ask::Tolerance(t) => format!("--tolerance {}d", 1.0 + t),
        }
    }
}

/// The distance asks measured on the default tree (the others are asked exactly).
const ASKS: [Ask; 8] = [
    Ask::RelErr(0.0),
    Ask::RelErr(1e-3),
    Ask::RelErr(1e-2),
    Ask::RelErr(0.05),
    Ask::RelErr(0.1),
    Ask::RelErr(0.3),
    Ask::Tolerance(0.1),
    Ask::Tolerance(1.0),
];

/// Runs every choice on every scene, one query at a time (the times are the point), each
/// pose's time the median of `repeat` runs.
///
/// # Errors
///
/// [`ExperimentError::Build`] if a scene's tree cannot be built, and
/// [`ExperimentError::Query`] if a query fails.
pub fn run(scenes: &[Workload], repeat: u32) -> Result<Vec<Trade>, ExperimentError> {
    let mut trades = Vec::new();
    for scene in scenes {
        let mut trades_of = measure_workload(scene, repeat)?;
        mark_pareto(&mut trades_of);
        trades.extend(trades_of);
    }
    Ok(trades)
}

fn measure_workload(scene: &Workload, repeat: u32) -> Result<Vec<Trade>, ExperimentError> {
    let exact = TreeChoice {
        precision: Precision::F64,
        ..TreeChoice::DEFAULT
    };
    let reference = trees(scene, exact)?;
    let mut pair = PairQuery::new(&reference.0, &reference.1)?;
    // The exact f64 answers every choice is held to.
    let mut distances = Vec::new();
    for [pa, pb] in &scene.apart {
        let r = pair.distance(pa, pb, &DistanceOptions::default())?;
        distances.push(r.distance());
    }
    let mut contacts = Vec::new();
    for [pa, pb] in &scene.crossing {
        let r = pair.collide(pa, pb, &CollideOptions::default())?;
        contacts.push(r.pairs.into_iter().collect::<BTreeSet<_>>());
    }
    let mut hausdorffs = Vec::new();
    for [pa, pb] in &scene.crossing {
        let h = hausdorff(
            &reference.0,
            pa,
            &reference.1,
            pb,
            &HausdorffOptions::default(),
        )?;
        hausdorffs.push(h.distance);
    }
    let mut out = Vec::new();
    for choice in tree_choices() {
        let (a, b) = trees(scene, choice)?;
        let bytes_per_triangle = (a.info().file_bytes + b.info().file_bytes) as f64
            / (f64::from(a.info().triangles) + f64::from(b.info().triangles));
        let mut pair = PairQuery::new(&a, &b)?;
        let default_tree = matches!(choice.precision, Precision::F32)
            && choice.layout == Layout::Fast
            && choice.fit == FitMethod::Hull
            && choice.leaf_size == 1;
        let asks: &[Ask] = if default_tree {
            &ASKS
        } else {
            &[Ask::RelErr(0.0)]
        };
        for &ask in asks {
            let choice = [choice.flags(), vec![ask.flag()]].concat().join(", ");
            let mut trade = Trade::new(&scene.name, "distance", choice, bytes_per_triangle);
            trade.exact = matches!(ask, Ask::RelErr(r) if r == 0.0);
            for ([pa, pb], &d) in scene.apart.iter().zip(&distances) {
                let ((found, tests), seconds) =
                    median_time(repeat, || -> Result<_, QueryError> {
                        match ask {
                            Ask::RelErr(rel_err) => {
                                let options = DistanceOptions {
                                    rel_err,
                                    ..DistanceOptions::default()
                                };
                                let r = pair.distance(pa, pb, &options)?;
                                Ok((r.distance(), r.work.bv_tests()))
                            }
                            Ask::Tolerance(t) => {
                                let options = ToleranceOptions::new((1.0 + t) * d);
                                let r = pair.within(pa, pb, &options)?;
                                let found = r.witness.map_or(f64::INFINITY, |w| w.distance);
                                Ok((found, r.work.bv_tests()))
                            }
                        }
                    })?;
                let error = relative_error(found, d);
                add(&mut trade, seconds, error, tests);
            }
            finish(&mut trade, scene.apart.len());
            out.push(trade);
        }
        let label = choice.flags().join(", ");
        let mut trade = Trade::new(&scene.name, "collision", label, bytes_per_triangle);
        for ([pa, pb], expected) in scene.crossing.iter().zip(&contacts) {
            let ((found, tests), seconds) = median_time(repeat, || -> Result<_, QueryError> {
                let r = pair.collide(pa, pb, &CollideOptions::default())?;
                Ok((
                    r.pairs.into_iter().collect::<BTreeSet<_>>(),
                    r.work.bv_tests(),
                ))
            })?;
            let differing = found.symmetric_difference(expected).count();
            let error = differing as f64 / expected.len().max(1) as f64;
            add(&mut trade, seconds, error, tests);
        }
        finish(&mut trade, scene.crossing.len());
        out.push(trade);
        for rel_err in asks.iter().filter_map(|ask| match ask {
            Ask::RelErr(r) => Some(*r),
            Ask::Tolerance(_) => None,
        }) {
            let flags = [choice.flags(), vec![Ask::RelErr(rel_err).flag()]].concat();
            let mut trade = Trade::new(
                &scene.name,
                "hausdorff",
                flags.join(", "),
                bytes_per_triangle,
            );
            trade.exact = rel_err == 0.0;
            let options = HausdorffOptions {
                rel_err,
                ..HausdorffOptions::default()
            };
            for ([pa, pb], &h) in scene.crossing.iter().zip(&hausdorffs) {
                let ((found, tests), seconds) = median_time(repeat, || {
                    let r = hausdorff(&a, pa, &b, pb, &options)?;
                    Ok::<_, QueryError>((r.distance, r.work.bv_tests()))
                })?;
                let error = relative_error(found, h);
                add(&mut trade, seconds, error, tests);
            }
            finish(&mut trade, scene.crossing.len());
            out.push(trade);
        }
    }
    Ok(out)
}

/// `found`'s error against the exact answer `exact`: relative, or absolute at 0.
fn relative_error(found: f64, exact: f64) -> f64 {
    if exact > 0.0 {
        (found - exact).abs() / exact
    } else {
        found.abs()
    }
}

fn add(trade: &mut Trade, seconds: f64, error: f64, bv_tests: u64) {
    trade.seconds += seconds;
    trade.error_mean += error;
    trade.error_max = trade.error_max.max(error);
    trade.bv_tests += bv_tests as f64;
}

fn finish(trade: &mut Trade, poses: usize) {
    let n = poses.max(1) as f64;
    trade.error_mean /= n;
    trade.bv_tests /= n;
}

/// Builds both models' trees for `choice`.
fn trees(scene: &Workload, choice: TreeChoice) -> Result<(ObbtFile, ObbtFile), ExperimentError> {
    let options = choice.options();
    Ok((
        build(&scene.a, &options, None)?,
        build(&scene.b, &options, None)?,
    ))
}

/// Marks the trades no other of the same query kind beats on both time and largest
/// error.
fn mark_pareto(trades: &mut [Trade]) {
    let points: Vec<(&'static str, f64, f64)> = trades
        .iter()
        .map(|t| (t.query, t.seconds, t.error_max))
        .collect();
    for trade in trades.iter_mut() {
        let dominated = points.iter().any(|&(query, seconds, error)| {
            query == trade.query
                && seconds <= trade.seconds
                && error <= trade.error_max
                && (seconds < trade.seconds || error < trade.error_max)
        });
        trade.pareto = !dominated;
    }
}
