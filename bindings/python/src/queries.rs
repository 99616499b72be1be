//! The pair queries over pose batches: `collide`, `distance`, `within`, `span`.
//!
//! Every query reads and checks the poses while it holds the GIL, then releases it: it
//! makes one `PairQuery` per worker thread, answers every pose in parallel (rayon) and
//! comes back with plain vectors, which become NumPy arrays when first read.

use crate::errors::{Failure, Kind};
use crate::poses::Poses;
use crate::tree::Tree;
use numpy::{PyArray1, PyArrayMethods};
use obbtree::format::ObbtFile;
use obbtree::query::{
    batch, on_threads, BatchOptions, CollideOptions, DescentRule, DistanceOptions,
    HausdorffDirection, HausdorffOptions, PairQuery, Pose, PoseBatch, QueryError, SpanOptions,
    ToleranceOptions, Witness, Work,
};
use pyo3::prelude::*;
use pyo3::sync::PyOnceLock;
use pyo3::types::{PyDict, PyList};
use std::num::NonZeroUsize;
use std::sync::Arc;
use std::time::Instant;

/// `rule=` values: which tree a traversal descends when both can be.
fn rule(name: &str) -> Result<DescentRule, Failure> {
    match name {
        "diameter" => Ok(DescentRule::LargestDiameter),
        "volume" => Ok(DescentRule::LargestVolume),
        "area" => Ok(DescentRule::LargestArea),
        "a" => Ok(DescentRule::AlwaysA),
        "b" => Ok(DescentRule::AlwaysB),
        other => Err(Failure::new(
            Kind::Option,
            format!("rule {other:?} is not one of diameter, volume, area, a, b"),
        )),
    }
}

/// The checked `threads=` argument.
fn threads_arg(threads: Option<i64>) -> Result<Option<usize>, Failure> {
    match threads {
        None => Ok(None),
        Some(n) if (1..=1024).contains(&n) => Ok(usize::try_from(n).ok()),
        Some(n) => Err(Failure::new(
            Kind::Option,
            format!("threads must be None or 1 to 1024, got {n}"),
        )),
    }
}

/// Runs `work` with the GIL released on `threads` threads (`threads=` as the caller gave
/// it: `None` for every core): how the one-model queries run.
pub fn detached<T: Send>(
    py: Python<'_>,
    threads: Option<i64>,
    work: impl FnOnce() -> Result<T, Failure> + Send,
) -> PyResult<T> {
    let threads = threads_arg(threads)?.and_then(NonZeroUsize::new);
    let answer = py
        .detach(|| on_threads(threads, work))
        .map_err(Failure::from)?;
    Ok(answer?)
}

/// Everything a batch needs, owned, so that it runs without the GIL.
pub struct Batch {
    a: Arc<ObbtFile>,
    b: Arc<ObbtFile>,
    poses_a: Vec<Pose>,
    poses_b: Vec<Pose>,
    threads: Option<usize>,
}

impl Batch {
    pub fn new(
        a: &Tree,
        poses_a: &Bound<'_, PyAny>,
        b: &Tree,
        poses_b: &Bound<'_, PyAny>,
        orthonormalize: bool,
        threads: Option<i64>,
    ) -> PyResult<Batch> {
        let (a, b, threads) = (a.file()?, b.file()?, threads_arg(threads)?);
        Ok(Batch {
            a,
            b,
            poses_a: Poses::extract("poses_a", poses_a, orthonormalize)?.poses,
            poses_b: Poses::extract("poses_b", poses_b, orthonormalize)?.poses,
            threads,
        })
    }

    /// Answers every pose pair with `query`, in pose order; runs with the GIL released.
    /// The first error of any pose is the error of the whole batch.
    fn run<T, F>(self, py: Python<'_>, query: F) -> PyResult<Answers<T>>
    where
        T: Send,
        F: Fn(&mut PairQuery<'_>, &Pose, &Pose) -> Result<T, QueryError> + Send + Sync,
    {
        Ok(py.detach(move || self.run_detached(query))?)
    }

    fn run_detached<T, F>(self, query: F) -> Result<Answers<T>, Failure>
    where
        T: Send,
        F: Fn(&mut PairQuery<'_>, &Pose, &Pose) -> Result<T, QueryError> + Send + Sync,
    {
        let poses = PoseBatch::new(&self.poses_a, &self.poses_b)?;
        let options = BatchOptions {
            threads: self.threads.and_then(NonZeroUsize::new),
        };
        let mut answers = batch(&self.a, &self.b, poses, &options, query)?;
        if let Some(first) = answers.iter().position(Result::is_err) {
            if let Err(e) = answers.swap_remove(first) {
                return Err(e.into());
            }
        }
        debug_assert!(answers.iter().all(Result::is_ok));
        Ok(Answers(answers))
    }
}

/// The answers of a batch that has no error, left in the vector the library returned
/// them in: moving them into a vector of their own cost as much again as a batch of
/// poses culled at their roots. Made only by [`Batch::run`], after it checked that no
/// pose failed, so that skipping errors while iterating skips none.
pub struct Answers<T>(Vec<Result<T, QueryError>>);

impl<T> Answers<T> {
    /// The answers, in pose order.
    fn iter(&self) -> impl Iterator<Item = &T> {
        self.0.iter().filter_map(|a| a.as_ref().ok())
    }

    /// How many.
    fn len(&self) -> usize {
        self.0.len()
    }
}

impl<T> IntoIterator for Answers<T> {
    type Item = T;
    type IntoIter = std::iter::FilterMap<
        std::vec::IntoIter<Result<T, QueryError>>,
        fn(Result<T, QueryError>) -> Option<T>,
    >;

    fn into_iter(self) -> Self::IntoIter {
        self.0.into_iter().filter_map(Result::ok)
    }
}

/// A cached NumPy value of a result, made when first read.
fn cached<'py>(
    cell: &PyOnceLock<Py<PyAny>>,
    py: Python<'py>,
    make: impl FnOnce() -> PyResult<Bound<'py, PyAny>>,
) -> PyResult<Bound<'py, PyAny>> {
    let value = cell.get_or_try_init(py, || make().map(Bound::unbind))?;
    Ok(value.bind(py).clone())
}

fn readonly<'py>(array: Bound<'py, PyAny>) -> PyResult<Bound<'py, PyAny>> {
    let kwargs = PyDict::new(array.py());
    kwargs.set_item("write", false)?;
    array.call_method("setflags", (), Some(&kwargs))?;
    Ok(array)
}

/// One count of a [`Work`].
type Count = fn(&Work) -> u64;

/// The work of each pose as a dict of (N,) int64 arrays, keys as the CLI's `stats`.
fn work_dict<'py>(py: Python<'py>, work: &[Work]) -> PyResult<Bound<'py, PyAny>> {
    let dict = PyDict::new(py);
    let column = |f: fn(&Work) -> u64| -> Vec<i64> {
        work.iter()
            .map(|w| i64::try_from(f(w)).unwrap_or(i64::MAX))
            .collect()
    };
    let columns: [(&str, Count); 7] = [
        ("bv_disjoint", |w| w.bv_disjoint),
        ("bv_overlap", |w| w.bv_overlap),
        ("tri_separated", |w| w.tri_separated),
        ("tri_contact", |w| w.tri_contact),
        ("nodes_visited", |w| w.nodes_visited),
        ("bv_tests", |w| w.bv_tests()),
        ("tri_tests", |w| w.tri_tests()),
    ];
    for (name, f) in columns {
        dict.set_item(
            name,
            readonly(PyArray1::from_vec(py, column(f)).into_any())?,
        )?;
    }
    Ok(dict.into_any())
}

/// One pose's contact geometry: each pair's points, the curve length, the overlap area.
type PoseGeometry = (Vec<Vec<[f64; 3]>>, f64, f64);

/// The answers of `collide` for N pose pairs.
///
/// Attributes: `contacts` (N,) int64 — contacting triangle pairs per pose (0 or 1 with
/// `first_contact`); `colliding` (N,) bool; `pairs` — a list of N (k, 2) int64 arrays of
/// input-mesh triangle ids (A's, B's), sorted, or None when called with `pairs=False`;
/// `work` — a dict of (N,) int64 arrays (bv_disjoint, bv_overlap, tri_separated,
/// tri_contact, nodes_visited, bv_tests, tri_tests: the CLI's `stats`); with
/// `geometry=True` also `geometry`, `curve_length` and `overlap_area`. Arrays are
/// read-only.
#[pyclass(module = "obbtree", name = "CollideResult", frozen)]
pub struct CollideResult {
    contacts: Vec<i64>,
    pairs: Option<Vec<Vec<(u32, u32)>>>,
    /// With geometry=True: each pose's contact geometry.
    geometry: Option<Vec<PoseGeometry>>,
    geometry_list: PyOnceLock<Py<PyAny>>,
    work: Vec<Work>,
    contacts_array: PyOnceLock<Py<PyAny>>,
    colliding_array: PyOnceLock<Py<PyAny>>,
    pairs_list: PyOnceLock<Py<PyAny>>,
    work_dict: PyOnceLock<Py<PyAny>>,
}

#[pymethods]
impl CollideResult {
    /// (N,) int64: contacting triangle pairs per pose (first_contact: 0 or 1).
    #[getter]
    fn contacts<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        cached(&self.contacts_array, py, || {
            readonly(PyArray1::from_slice(py, &self.contacts).into_any())
        })
    }

    /// (N,) bool: whether the models touch under each pose.
    #[getter]
    fn colliding<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        cached(&self.colliding_array, py, || {
            let c: Vec<bool> = self.contacts.iter().map(|&k| k > 0).collect();
            readonly(PyArray1::from_vec(py, c).into_any())
        })
    }

    /// A list of N (k, 2) int64 arrays: the contacting pairs (triangle of A, triangle of
    /// B; input-mesh ids), sorted; at most one pair with first_contact. None when the call
    /// passed pairs=False.
    #[getter]
    fn pairs<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        let Some(pairs) = &self.pairs else {
            return Ok(py.None().into_bound(py));
        };
        cached(&self.pairs_list, py, || {
            let list = PyList::empty(py);
            for p in pairs {
                let flat: Vec<i64> = p
                    .iter()
                    .flat_map(|&(x, y)| [i64::from(x), i64::from(y)])
                    .collect();
                let array = PyArray1::from_vec(py, flat).reshape([p.len(), 2])?;
                list.append(readonly(array.into_any())?)?;
            }
            Ok(list.into_any())
        })
    }

    /// With geometry=True, a list of N lists, one (m, 3) float64 array per contacting
    /// pair in the order of `pairs`: the two ends of the segment where the triangles cross
    /// (m = 2, equal when they touch at a point), or the corners of the polygon coplanar
    /// triangles share (m = 1 to 6), world frame. None without geometry=True.
    #[getter]
    fn geometry<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        let Some(geometry) = &self.geometry else {
            return Ok(py.None().into_bound(py));
        };
        cached(&self.geometry_list, py, || {
            let poses = PyList::empty(py);
            for (contacts, _, _) in geometry {
                let list = PyList::empty(py);
                for points in contacts {
                    let flat: Vec<f64> = points.iter().flatten().copied().collect();
                    let array = PyArray1::from_vec(py, flat).reshape([points.len(), 3])?;
                    list.append(readonly(array.into_any())?)?;
                }
                poses.append(list)?;
            }
            Ok(poses.into_any())
        })
    }

    /// With geometry=True, (N,) float64: the length of each pose's intersection curve (the
    /// crossing pairs' segments, summed); None without it.
    #[getter]
    fn curve_length<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        match &self.geometry {
            Some(g) => readonly(PyArray1::from_iter(py, g.iter().map(|x| x.1)).into_any()),
            None => Ok(py.None().into_bound(py)),
        }
    }

    /// With geometry=True, (N,) float64: the area coplanar triangles share, summed; None
    /// without it.
    #[getter]
    fn overlap_area<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        match &self.geometry {
            Some(g) => readonly(PyArray1::from_iter(py, g.iter().map(|x| x.2)).into_any()),
            None => Ok(py.None().into_bound(py)),
        }
    }

    /// The work per pose: a dict of (N,) int64 arrays with the keys of the CLI's `stats`.
    #[getter]
    fn work<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        cached(&self.work_dict, py, || work_dict(py, &self.work))
    }

    fn __len__(&self) -> usize {
        self.contacts.len()
    }

    fn __repr__(&self) -> String {
        let colliding = self.contacts.iter().filter(|&&k| k > 0).count();
        format!(
            "<obbtree.CollideResult: {} poses, {colliding} colliding>",
            self.contacts.len()
        )
    }
}

/// Witness columns of N answers (distance, within, span).
struct Witnesses {
    distance: Vec<f64>,
    point_a: Vec<f64>,
    point_b: Vec<f64>,
    tri_a: Vec<i64>,
    tri_b: Vec<i64>,
    work: Vec<Work>,
}

impl Witnesses {
    /// Columns of the `n` answers of `answers`: (witness or None, work). None gives
    /// `missing` as the distance, NaN points and triangle -1.
    fn new(
        answers: impl Iterator<Item = (Option<Witness>, Work)>,
        n: usize,
        missing: f64,
    ) -> Witnesses {
        let mut w = Witnesses {
            distance: Vec::with_capacity(n),
            point_a: Vec::with_capacity(3 * n),
            point_b: Vec::with_capacity(3 * n),
            tri_a: Vec::with_capacity(n),
            tri_b: Vec::with_capacity(n),
            work: Vec::with_capacity(n),
        };
        for (witness, work) in answers {
            match witness {
                Some(x) => {
                    w.distance.push(x.distance);
                    w.point_a.extend_from_slice(x.point_a.as_slice());
                    w.point_b.extend_from_slice(x.point_b.as_slice());
                    w.tri_a.push(i64::from(x.tri_a));
                    w.tri_b.push(i64::from(x.tri_b));
                }
                None => {
                    w.distance.push(missing);
                    w.point_a.extend_from_slice(&[f64::NAN; 3]);
                    w.point_b.extend_from_slice(&[f64::NAN; 3]);
                    w.tri_a.push(-1);
                    w.tri_b.push(-1);
                }
            }
            w.work.push(work);
        }
        w
    }
}

/// Lazily made arrays of [`Witnesses`].
struct WitnessArrays {
    distance: PyOnceLock<Py<PyAny>>,
    point_a: PyOnceLock<Py<PyAny>>,
    point_b: PyOnceLock<Py<PyAny>>,
    tri_a: PyOnceLock<Py<PyAny>>,
    tri_b: PyOnceLock<Py<PyAny>>,
    work: PyOnceLock<Py<PyAny>>,
}

impl Default for WitnessArrays {
    fn default() -> Self {
        WitnessArrays {
            distance: PyOnceLock::new(),
            point_a: PyOnceLock::new(),
            point_b: PyOnceLock::new(),
            tri_a: PyOnceLock::new(),
            tri_b: PyOnceLock::new(),
            work: PyOnceLock::new(),
        }
    }
}

fn column<'py>(
    cell: &PyOnceLock<Py<PyAny>>,
    py: Python<'py>,
    values: &[f64],
) -> PyResult<Bound<'py, PyAny>> {
    cached(cell, py, || {
        readonly(PyArray1::from_slice(py, values).into_any())
    })
}

fn ids<'py>(
    cell: &PyOnceLock<Py<PyAny>>,
    py: Python<'py>,
    values: &[i64],
) -> PyResult<Bound<'py, PyAny>> {
    cached(cell, py, || {
        readonly(PyArray1::from_slice(py, values).into_any())
    })
}

fn points<'py>(
    cell: &PyOnceLock<Py<PyAny>>,
    py: Python<'py>,
    values: &[f64],
) -> PyResult<Bound<'py, PyAny>> {
    cached(cell, py, || {
        let rows = values.len() / 3;
        let array = PyArray1::from_slice(py, values).reshape([rows, 3])?;
        readonly(array.into_any())
    })
}

/// Defines the shared witness getters of a result class.
macro_rules! witness_getters {
    ($class:ident, $what:literal, { $($extra:tt)* }) => {
        #[pymethods]
        impl $class {
            $($extra)*

            #[doc = concat!("(N, 3) float64: the point on A (world frame) ", $what, "; NaN where there is none.")]
            #[getter]
            fn point_a<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
                points(&self.arrays.point_a, py, &self.columns.point_a)
            }

            #[doc = concat!("(N, 3) float64: the point on B (world frame) ", $what, "; NaN where there is none.")]
            #[getter]
            fn point_b<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
                points(&self.arrays.point_b, py, &self.columns.point_b)
            }

            #[doc = concat!("(N,) int64: the input-mesh triangle of A holding point_a; -1 where there is none.")]
            #[getter]
            fn tri_a<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
                ids(&self.arrays.tri_a, py, &self.columns.tri_a)
            }

            #[doc = concat!("(N,) int64: the input-mesh triangle of B holding point_b; -1 where there is none.")]
            #[getter]
            fn tri_b<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
                ids(&self.arrays.tri_b, py, &self.columns.tri_b)
            }

            /// The work per pose: a dict of (N,) int64 arrays with the keys of the CLI's
            /// `stats`.
            #[getter]
            fn work<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
                cached(&self.arrays.work, py, || work_dict(py, &self.columns.work))
            }

            fn __len__(&self) -> usize {
                self.columns.distance.len()
            }
        }
    };
}

/// The answers of `distance` for N pose pairs.
///
/// Attributes (read-only arrays): `distance` (N,) float64 — the separation distance (0
/// when touching), exact or within the allowed error, +inf where the models are at least
/// `max_distance` apart; `point_a`, `point_b` (N, 3) — closest points, world frame (NaN
/// beyond max_distance); `tri_a`, `tri_b` (N,) int64 — their input-mesh triangles (-1
/// beyond max_distance); `work` — dict of (N,) int64 arrays.
#[pyclass(module = "obbtree", name = "DistanceResult", frozen)]
pub struct DistanceResult {
    columns: Witnesses,
    arrays: WitnessArrays,
}

witness_getters!(DistanceResult, "of the closest pair", {
    /// (N,) float64: the distance; +inf where at least max_distance apart.
    #[getter]
    fn distance<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        column(&self.arrays.distance, py, &self.columns.distance)
    }

    fn __repr__(&self) -> String {
        format!(
            "<obbtree.DistanceResult: {} poses>",
            self.columns.distance.len()
        )
    }
});

/// The answers of `within` for N pose pairs.
///
/// Attributes (read-only arrays): `closer` (N,) bool — whether the models come closer than
/// the tolerance; `distance` (N,) float64 — the distance of the witness pair found (below
/// the tolerance, not necessarily the least), NaN where not closer; `point_a`, `point_b`
/// (N, 3), `tri_a`, `tri_b` (N,) int64 — the witness (NaN / -1 where not closer); `work`.
#[pyclass(module = "obbtree", name = "WithinResult", frozen)]
pub struct WithinResult {
    columns: Witnesses,
    arrays: WitnessArrays,
    closer: Vec<bool>,
    closer_array: PyOnceLock<Py<PyAny>>,
}

witness_getters!(WithinResult, "of the witness pair", {
    /// (N,) bool: whether the models come closer than the tolerance.
    #[getter]
    fn closer<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        cached(&self.closer_array, py, || {
            readonly(PyArray1::from_slice(py, &self.closer).into_any())
        })
    }

    /// (N,) float64: the witness pair's distance (below the tolerance); NaN where not
    /// closer.
    #[getter]
    fn distance<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        column(&self.arrays.distance, py, &self.columns.distance)
    }

    fn __repr__(&self) -> String {
        let closer = self.closer.iter().filter(|&&c| c).count();
        format!(
            "<obbtree.WithinResult: {} poses, {closer} closer than the tolerance>",
            self.closer.len()
        )
    }
});

/// The answers of `span` for N pose pairs.
///
/// Attributes (read-only arrays): `span` (N,) float64 — the largest distance between a
/// point of A and a point of B; `point_a`, `point_b` (N, 3) — the farthest points, world
/// frame; `tri_a`, `tri_b` (N,) int64 — their input-mesh triangles; `work`.
#[pyclass(module = "obbtree", name = "SpanResult", frozen)]
pub struct SpanResult {
    columns: Witnesses,
    arrays: WitnessArrays,
}

witness_getters!(SpanResult, "of the farthest pair", {
    /// (N,) float64: the span.
    #[getter]
    fn span<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        column(&self.arrays.distance, py, &self.columns.distance)
    }

    fn __repr__(&self) -> String {
        format!(
            "<obbtree.SpanResult: {} poses>",
            self.columns.distance.len()
        )
    }
});

/// The answers of `hausdorff` for N pose pairs.
///
/// Attributes (read-only arrays): `distance` (N,) float64 — the Hausdorff distance found,
/// the distance from the witness to the other model; `upper_bound` (N,) float64 — a
/// proven bound the true distance does not exceed; `direction` (N,) str — `a_to_b` (the
/// witness is `point_a`, on A) or `b_to_a` (only with `symmetric`: the witness is
/// `point_b`); `point_a`, `point_b` (N, 3) — the witness and its closest point on the
/// other model, world frame; `tri_a`, `tri_b` (N,) int64; `work`.
#[pyclass(module = "obbtree", name = "HausdorffResult", frozen)]
pub struct HausdorffResult {
    columns: Witnesses,
    arrays: WitnessArrays,
    upper_bound: Vec<f64>,
    upper_bound_array: PyOnceLock<Py<PyAny>>,
    b_to_a: Vec<bool>,
    direction_array: PyOnceLock<Py<PyAny>>,
}

witness_getters!(HausdorffResult, "of the witness pair", {
    /// (N,) float64: the Hausdorff distance found (the true one is at least this).
    #[getter]
    fn distance<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        column(&self.arrays.distance, py, &self.columns.distance)
    }

    /// (N,) float64: a proven bound the true distance does not exceed.
    #[getter]
    fn upper_bound<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        column(&self.upper_bound_array, py, &self.upper_bound)
    }

    /// (N,) str: `a_to_b` where the witness is on A, `b_to_a` where it is on B.
    #[getter]
    fn direction<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        cached(&self.direction_array, py, || {
            let names: Vec<&str> = self
                .b_to_a
                .iter()
                .map(|&b| if b { "b_to_a" } else { "a_to_b" })
                .collect();
            readonly(py.import("numpy")?.call_method1("array", (names,))?)
        })
    }

    fn __repr__(&self) -> String {
        format!(
            "<obbtree.HausdorffResult: {} poses>",
            self.columns.distance.len()
        )
    }
});

/// Which triangle pairs touch, for each pose pair of a batch.
///
/// a, b: `Tree`s (same volume type and precision). poses_a, poses_b: one pose — a (4, 4)
/// rigid matrix, 12 numbers (rotation row-major, then translation) or an (R, t) pair — or
/// a batch (N, 4, 4) or (N, 12) (or (R (N, 3, 3), t (N, 3))). A single pose (or a batch
/// of one) broadcasts against a batch; two single poses give N = 1. World point = R p + t.
///
/// first_contact: stop at the first contact (a yes/no answer with one witness pair; much
/// faster). pairs: False skips building the pair lists. geometry: also where each pair
/// meets (`geometry`, `curve_length`, `overlap_area`). threads: None for every core, or
/// the number of threads for a batch. orthonormalize: replace each rotation by the nearest
/// rotation (as the CLI's --orthonormalize; changes above 1e-2 are refused); without it a
/// rotation must be orthonormal within 1e-6, and is used as its nearest rotation. rule: which tree to descend first (diameter,
/// volume, area, a, b).
///
/// Returns a `CollideResult` (contacts, colliding, pairs, work). The batch runs in parallel
/// with the GIL released. Raises `obbtree.PoseError` (a ValueError) naming the argument and
/// pose index of a bad pose, `obbtree.Error` for trees of different kinds or a closed tree.
#[pyfunction]
#[pyo3(signature = (a, poses_a, b, poses_b, *, first_contact=false, pairs=true, geometry=false, threads=None, orthonormalize=false, rule="diameter"))]
#[allow(clippy::too_many_arguments)]
pub fn collide(
    py: Python<'_>,
    a: PyRef<'_, Tree>,
    poses_a: &Bound<'_, PyAny>,
    b: PyRef<'_, Tree>,
    poses_b: &Bound<'_, PyAny>,
    first_contact: bool,
    pairs: bool,
    geometry: bool,
    threads: Option<i64>,
    orthonormalize: bool,
    rule: &str,
) -> PyResult<CollideResult> {
    let options = CollideOptions {
        first_contact,
        rule: self::rule(rule)?,
        geometry,
        ..CollideOptions::default()
    };
    let batch = Batch::new(&a, poses_a, &b, poses_b, orthonormalize, threads)?;
    // Each pose's answer is its count and work, and only where asked for its pairs and
    // geometry, boxed: the answers of a large batch are written by every worker at once,
    // and their size (their pages' first touches) decides what such a batch costs when
    // its poses are cheap.
    let answers = batch.run(py, |pair, pa, pb| {
        let r = pair.collide(pa, pb, &options)?;
        let count = i64::try_from(r.pairs.len()).unwrap_or(i64::MAX);
        let shapes = geometry.then(|| {
            let points = r
                .contacts
                .iter()
                .map(|c| c.intersection.points().iter().map(|&p| p.into()).collect())
                .collect();
            (points, r.curve_length(), r.overlap_area())
        });
        let list = if pairs { r.pairs } else { Vec::new() };
        let kept = (pairs || geometry).then(|| Box::new((list, shapes)));
        Ok((count, kept, r.work))
    })?;
    let contacts = answers.iter().map(|(count, _, _)| *count).collect();
    let work = answers.iter().map(|(_, _, w)| *w).collect();
    let (mut shapes, mut pair_lists) = (Vec::new(), Vec::new());
    for (_, kept, _) in answers {
        if let Some(kept) = kept {
            let (p, g) = *kept;
            if pairs {
                pair_lists.push(p);
            }
            shapes.extend(g);
        }
    }
    Ok(CollideResult {
        contacts,
        pairs: pairs.then_some(pair_lists),
        geometry: geometry.then_some(shapes),
        geometry_list: PyOnceLock::new(),
        work,
        contacts_array: PyOnceLock::new(),
        colliding_array: PyOnceLock::new(),
        pairs_list: PyOnceLock::new(),
        work_dict: PyOnceLock::new(),
    })
}

/// The separation distance between the surfaces, with the closest points, for each pose
/// pair of a batch (poses as for `collide`).
///
/// Exact by default; with rel_err / abs_err the answer d satisfies
/// d* <= d <= max(d* (1 + rel_err), d* + abs_err) for the true distance d*. max_distance:
/// pairs at least that far apart answer +inf (points NaN, triangles -1) without the work
/// of finding how far (None: no limit).
///
/// Returns a `DistanceResult` (distance, point_a, point_b, tri_a, tri_b, work). Raises
/// `obbtree.OptionError` (a ValueError) for a negative or non-finite error allowance, or a
/// max_distance that is not greater than 0.
#[pyfunction]
#[pyo3(signature = (a, poses_a, b, poses_b, *, rel_err=0.0, abs_err=0.0, max_distance=None, threads=None, orthonormalize=false, rule="diameter"))]
#[allow(clippy::too_many_arguments)]
pub fn distance(
    py: Python<'_>,
    a: PyRef<'_, Tree>,
    poses_a: &Bound<'_, PyAny>,
    b: PyRef<'_, Tree>,
    poses_b: &Bound<'_, PyAny>,
    rel_err: f64,
    abs_err: f64,
    max_distance: Option<f64>,
    threads: Option<i64>,
    orthonormalize: bool,
    rule: &str,
) -> PyResult<DistanceResult> {
    let options = DistanceOptions {
        rel_err,
        abs_err,
        max_distance: max_distance.unwrap_or(f64::INFINITY),
        rule: self::rule(rule)?,
        ..DistanceOptions::default()
    };
    let batch = Batch::new(&a, poses_a, &b, poses_b, orthonormalize, threads)?;
    let answers = batch.run(py, |pair, pa, pb| {
        let r = pair.distance(pa, pb, &options)?;
        Ok((r.closest, r.work))
    })?;
    let n = answers.len();
    Ok(DistanceResult {
        columns: Witnesses::new(answers.into_iter(), n, f64::INFINITY),
        arrays: WitnessArrays::default(),
    })
}

/// Whether the surfaces come closer than `tolerance`, for each pose pair of a batch (poses
/// as for `collide`), stopping as soon as it knows: much cheaper than a distance.
///
/// Returns a `WithinResult`: closer (N,) bool, and a witness pair closer than the
/// tolerance where there is one (distance, point_a, point_b, tri_a, tri_b; NaN and -1
/// elsewhere). Raises `obbtree.OptionError` for a negative or non-finite tolerance.
#[pyfunction]
#[pyo3(signature = (a, poses_a, b, poses_b, tolerance, *, threads=None, orthonormalize=false, rule="diameter"))]
#[allow(clippy::too_many_arguments)]
pub fn within(
    py: Python<'_>,
    a: PyRef<'_, Tree>,
    poses_a: &Bound<'_, PyAny>,
    b: PyRef<'_, Tree>,
    poses_b: &Bound<'_, PyAny>,
    tolerance: f64,
    threads: Option<i64>,
    orthonormalize: bool,
    rule: &str,
) -> PyResult<WithinResult> {
    let options = ToleranceOptions {
        tolerance,
        rule: self::rule(rule)?,
    };
    let batch = Batch::new(&a, poses_a, &b, poses_b, orthonormalize, threads)?;
    let answers = batch.run(py, |pair, pa, pb| {
        let r = pair.within(pa, pb, &options)?;
        Ok((r.witness, r.work))
    })?;
    let n = answers.len();
    let closer = answers.iter().map(|(w, _)| w.is_some()).collect();
    Ok(WithinResult {
        columns: Witnesses::new(answers.into_iter(), n, f64::NAN),
        arrays: WitnessArrays::default(),
        closer,
        closer_array: PyOnceLock::new(),
    })
}

/// The span: the largest distance between a point of A and a point of B, with the two
/// farthest points, for each pose pair of a batch (poses as for `collide`).
///
/// Returns a `SpanResult` (span, point_a, point_b, tri_a, tri_b, work).
#[pyfunction]
#[pyo3(signature = (a, poses_a, b, poses_b, *, threads=None, orthonormalize=false, rule="diameter"))]
#[allow(clippy::too_many_arguments)]
pub fn span(
    py: Python<'_>,
    a: PyRef<'_, Tree>,
    poses_a: &Bound<'_, PyAny>,
    b: PyRef<'_, Tree>,
    poses_b: &Bound<'_, PyAny>,
    threads: Option<i64>,
    orthonormalize: bool,
    rule: &str,
) -> PyResult<SpanResult> {
    let options = SpanOptions {
        rule: self::rule(rule)?,
    };
    let batch = Batch::new(&a, poses_a, &b, poses_b, orthonormalize, threads)?;
    let answers = batch.run(py, |pair, pa, pb| {
        let r = pair.span(pa, pb, &options)?;
        Ok((Some(r.farthest), r.work))
    })?;
    let n = answers.len();
    Ok(SpanResult {
        columns: Witnesses::new(answers.into_iter(), n, f64::NAN),
        arrays: WitnessArrays::default(),
    })
}

/// The Hausdorff distance for each pose pair of a batch (poses as for `collide`): the
/// largest distance from a point of A's surface to B's, with the witness point on A and
/// its closest point on B; with `symmetric`, the larger of that and the reverse.
///
/// rel_err, abs_err: the error allowed, `h <= h* <= max(h (1 + rel_err), h + abs_err)`
/// for the answer h and the true h*; with both 0 (the default) exact to f64 rounding
/// wherever the bounds close, which they do not quite where B curves or where the two
/// surfaces nearly coincide, triangulated differently (then `upper_bound` says how
/// close).
///
/// Returns a `HausdorffResult` (distance, upper_bound, direction, point_a, point_b, tri_a,
/// tri_b, work). Raises `obbtree.OptionError` (a ValueError) for a negative or non-finite
/// error allowance.
#[pyfunction]
#[pyo3(signature = (a, poses_a, b, poses_b, *, rel_err=0.0, abs_err=0.0, symmetric=false, threads=None, orthonormalize=false))]
#[allow(clippy::too_many_arguments)]
pub fn hausdorff(
    py: Python<'_>,
    a: PyRef<'_, Tree>,
    poses_a: &Bound<'_, PyAny>,
    b: PyRef<'_, Tree>,
    poses_b: &Bound<'_, PyAny>,
    rel_err: f64,
    abs_err: f64,
    symmetric: bool,
    threads: Option<i64>,
    orthonormalize: bool,
) -> PyResult<HausdorffResult> {
    let options = HausdorffOptions {
        rel_err,
        abs_err,
        symmetric,
        warm_start: None,
    };
    let (fa, fb) = (a.file()?, b.file()?);
    let batch = Batch::new(&a, poses_a, &b, poses_b, orthonormalize, threads)?;
    let answers = batch.run(py, |_, pa, pb| {
        obbtree::query::hausdorff(&fa, pa, &fb, pb, &options)
    })?;
    let n = answers.len();
    let upper_bound = answers.iter().map(|h| h.upper_bound).collect();
    let b_to_a = answers
        .iter()
        .map(|h| h.direction == HausdorffDirection::BToA)
        .collect();
    let witnesses = answers.into_iter().map(|h| {
        let w = Witness {
            distance: h.distance,
            point_a: h.point_a.into(),
            point_b: h.point_b.into(),
            tri_a: h.tri_a,
            tri_b: h.tri_b,
        };
        (Some(w), h.work)
    });
    Ok(HausdorffResult {
        columns: Witnesses::new(witnesses, n, f64::NAN),
        arrays: WitnessArrays::default(),
        upper_bound,
        upper_bound_array: PyOnceLock::new(),
        b_to_a,
        direction_array: PyOnceLock::new(),
    })
}

/// For measuring the binding's overhead: the seconds per call of `repeat` calls of one
/// query ("first_contact", "collide", "distance") on pose pair `i % N` of the batch, made
/// from Rust with one `PairQuery` (no Python in the loop), with the GIL released.
#[pyfunction]
pub fn _time_rust_loop(
    py: Python<'_>,
    a: PyRef<'_, Tree>,
    poses_a: &Bound<'_, PyAny>,
    b: PyRef<'_, Tree>,
    poses_b: &Bound<'_, PyAny>,
    query: &str,
    repeat: usize,
) -> PyResult<f64> {
    let (fa, fb) = (a.file()?, b.file()?);
    let pa = Poses::extract("poses_a", poses_a, false)?.poses;
    let pb = Poses::extract("poses_b", poses_b, false)?.poses;
    let query = query.to_owned();
    let seconds = py.detach(move || -> Result<f64, Failure> {
        let n = pa.len().max(pb.len()).max(1);
        let mut pair = PairQuery::new(&fa, &fb)?;
        let first = CollideOptions {
            first_contact: true,
            ..CollideOptions::default()
        };
        let all = CollideOptions::default();
        let exact = DistanceOptions::default();
        let pose = |poses: &[Pose], i: usize| {
            poses
                .get(i % poses.len().max(1))
                .copied()
                .unwrap_or_default()
        };
        let started = Instant::now();
        let mut sink = 0usize;
        for i in 0..repeat {
            let (x, y) = (pose(&pa, i % n), pose(&pb, i % n));
            sink += match query.as_str() {
                "first_contact" => pair.collide(&x, &y, &first)?.pairs.len(),
                "collide" => pair.collide(&x, &y, &all)?.pairs.len(),
                "distance" => usize::from(pair.distance(&x, &y, &exact)?.closest.is_some()),
                other => {
                    return Err(Failure::new(
                        Kind::Option,
                        format!("query {other:?} is not first_contact, collide or distance"),
                    ))
                }
            };
        }
        let elapsed = started.elapsed().as_secs_f64();
        std::hint::black_box(sink);
        Ok(elapsed / repeat.max(1) as f64)
    })?;
    Ok(seconds)
}
