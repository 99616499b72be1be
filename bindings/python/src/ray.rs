//! `obbtree.ray`: where rays meet one posed model.

use crate::errors::{Failure, Kind};
use crate::poses::single_pose;
use crate::queries::detached;
use crate::tree::Tree;
use crate::winding::{point_rows, row_of_three};
use numpy::{PyArray1, PyArray2, PyArrayMethods, PyReadonlyArray2};
use obbtree::query::{all_ray_hits, cast_rays, QueryError, Ray, RayHit, RayMode, RayOptions};
use pyo3::prelude::*;

/// The native half of `obbtree.ray` (which documents it) in modes `closest` and `any`:
/// `origins` and `directions` (N, 3) float64 arrays. Returns, ray by ray, `(hit, t, tri,
/// point, barycentric, normal)` as (N,) bool, (N,) float64 (inf on a miss), (N,) int64
/// (-1), and three (N, 3) float64 arrays (NaN).
#[pyfunction]
#[pyo3(signature = (tree, pose, origins, directions, t_max, mode, orthonormalize, threads))]
#[allow(clippy::too_many_arguments)]
pub fn _ray<'py>(
    py: Python<'py>,
    tree: PyRef<'_, Tree>,
    pose: &Bound<'py, PyAny>,
    origins: PyReadonlyArray2<'py, f64>,
    directions: PyReadonlyArray2<'py, f64>,
    t_max: f64,
    mode: &str,
    orthonormalize: bool,
    threads: Option<i64>,
) -> PyResult<Answers<'py, bool>> {
    let file = tree.file()?;
    let pose = single_pose("pose", pose, orthonormalize)?;
    let rays = ray_rows(&origins, &directions)?;
    let mode = match mode {
        "closest" => RayMode::Closest,
        "any" => RayMode::Any,
        other => {
            return Err(Failure::new(
                Kind::Option,
                format!("mode must be \"closest\", \"any\" or \"all\", got {other:?}"),
            )
            .into())
        }
    };
    let options = RayOptions { mode, t_max };
    // Dense columns filled here (scattering hits into them with NumPy took about as long
    // as casting the rays), a chunk of rays at a time, so that the library's answers are
    // still in cache when they are copied.
    let (hit, columns) = detached(py, threads, || {
        let mut columns = Columns::with_capacity(rays.len());
        let mut hit = Vec::with_capacity(rays.len());
        // (An empty batch still makes one call, which checks the options.)
        let chunks = rays
            .chunks(CHUNK)
            .chain(rays.is_empty().then_some(&rays[..]));
        for (k, chunk) in chunks.enumerate() {
            let answers = cast_rays(&file, &pose, chunk, &options)
                .map_err(|e| Failure::from(offset_by(e, k * CHUNK)))?;
            for (ray, answer) in chunk.iter().zip(&answers) {
                columns.push(ray, answer.hit.as_ref());
                hit.push(answer.hit.is_some());
            }
        }
        Ok((hit, columns))
    })?;
    let (t, tri, point, bary, normal) = columns.into_arrays(py)?;
    Ok((PyArray1::from_vec(py, hit), t, tri, point, bary, normal))
}

/// Rays per library call in `_ray`: their answers fit in a core's L2 cache.
const CHUNK: usize = 4096;

/// `error` of a chunk of rays, naming the ray by its index in the whole batch when it
/// names one.
fn offset_by(error: QueryError, first: usize) -> QueryError {
    match error {
        QueryError::BadInput {
            what,
            index,
            requirement,
            value,
        } => QueryError::BadInput {
            what,
            index: index + first,
            requirement,
            value,
        },
        other => other,
    }
}

/// The native half of `obbtree.ray` in mode `all`: every hit of every ray, ray by ray and
/// by increasing `t`, as `(ray, t, tri, point, barycentric, normal)`: (M,) int64, (M,)
/// float64, (M,) int64 and three (M, 3) float64 arrays, where M is the number of hits.
#[pyfunction]
#[pyo3(signature = (tree, pose, origins, directions, t_max, orthonormalize, threads))]
#[allow(clippy::too_many_arguments)]
pub fn _ray_all<'py>(
    py: Python<'py>,
    tree: PyRef<'_, Tree>,
    pose: &Bound<'py, PyAny>,
    origins: PyReadonlyArray2<'py, f64>,
    directions: PyReadonlyArray2<'py, f64>,
    t_max: f64,
    orthonormalize: bool,
    threads: Option<i64>,
) -> PyResult<Answers<'py, i64>> {
    let file = tree.file()?;
    let pose = single_pose("pose", pose, orthonormalize)?;
    let rays = ray_rows(&origins, &directions)?;
    let answers = detached(py, threads, || {
        all_ray_hits(&file, &pose, &rays, t_max).map_err(Failure::from)
    })?;
    let m = answers.iter().map(|a| a.hits.len()).sum();
    let (mut index, mut columns) = (Vec::with_capacity(m), Columns::with_capacity(m));
    for (i, (ray, answer)) in rays.iter().zip(&answers).enumerate() {
        for hit in &answer.hits {
            index.push(i as i64);
            columns.push(ray, Some(hit));
        }
    }
    let (t, tri, point, bary, normal) = columns.into_arrays(py)?;
    Ok((PyArray1::from_vec(py, index), t, tri, point, bary, normal))
}

/// The rays of (N, 3) origin and direction rows.
fn ray_rows(
    origins: &PyReadonlyArray2<'_, f64>,
    directions: &PyReadonlyArray2<'_, f64>,
) -> Result<Vec<Ray>, Failure> {
    let (o, d) = (origins.as_array(), directions.as_array());
    if o.ncols() != 3 || d.ncols() != 3 || o.nrows() != d.nrows() {
        return Err(Failure::new(
            Kind::Option,
            format!(
                "origins and directions must be (N, 3) arrays of one N, got {:?} and {:?}",
                o.shape(),
                d.shape()
            ),
        ));
    }
    let ray = |(origin, direction)| Ray { origin, direction };
    Ok(match (o.as_slice(), d.as_slice()) {
        // C-contiguous (as the Python side passes them): one pass over both flat slices.
        (Some(o), Some(d)) => o
            .chunks_exact(3)
            .map(row_of_three)
            .zip(d.chunks_exact(3).map(row_of_three))
            .map(ray)
            .collect(),
        _ => point_rows(origins)?
            .into_iter()
            .zip(point_rows(directions)?)
            .map(ray)
            .collect(),
    })
}

/// Hits as flat columns: `t`, `tri`, and the rows of `point`, `barycentric` and `normal`
/// (inf, -1 and NaN for a miss).
struct Columns {
    t: Vec<f64>,
    tri: Vec<i64>,
    point: Vec<f64>,
    bary: Vec<f64>,
    normal: Vec<f64>,
}

/// What `_ray` and `_ray_all` return: a first (n,) column (which rays hit, or the ray of
/// each hit), then the [`Arrays`].
type Answers<'py, First> = (
    Bound<'py, PyArray1<First>>,
    Bound<'py, PyArray1<f64>>,
    Bound<'py, PyArray1<i64>>,
    Bound<'py, PyArray2<f64>>,
    Bound<'py, PyArray2<f64>>,
    Bound<'py, PyArray2<f64>>,
);

/// The columns as NumPy arrays: (n,), (n,) and three (n, 3).
type Arrays<'py> = (
    Bound<'py, PyArray1<f64>>,
    Bound<'py, PyArray1<i64>>,
    Bound<'py, PyArray2<f64>>,
    Bound<'py, PyArray2<f64>>,
    Bound<'py, PyArray2<f64>>,
);

impl Columns {
    fn with_capacity(n: usize) -> Columns {
        Columns {
            t: Vec::with_capacity(n),
            tri: Vec::with_capacity(n),
            point: Vec::with_capacity(3 * n),
            bary: Vec::with_capacity(3 * n),
            normal: Vec::with_capacity(3 * n),
        }
    }

    /// One row: `ray`'s `hit`, or a miss.
    #[inline]
    fn push(&mut self, ray: &Ray, hit: Option<&RayHit>) {
        match hit {
            Some(h) => {
                self.t.push(h.t);
                self.tri.push(i64::from(h.triangle));
                self.point.extend(ray.at(h.t));
                self.bary.extend(h.barycentric);
                self.normal.extend(h.normal);
            }
            None => {
                self.t.push(f64::INFINITY);
                self.tri.push(-1);
                for rows in [&mut self.point, &mut self.bary, &mut self.normal] {
                    rows.extend([f64::NAN; 3]);
                }
            }
        }
    }

    fn into_arrays(self, py: Python<'_>) -> PyResult<Arrays<'_>> {
        let n = self.t.len();
        Ok((
            PyArray1::from_vec(py, self.t),
            PyArray1::from_vec(py, self.tri),
            PyArray1::from_vec(py, self.point).reshape([n, 3])?,
            PyArray1::from_vec(py, self.bary).reshape([n, 3])?,
            PyArray1::from_vec(py, self.normal).reshape([n, 3])?,
        ))
    }
}
