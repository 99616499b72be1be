//! `obbtree.ray`: where rays meet one posed model.

use crate::errors::{Failure, Kind};
use crate::poses::single_pose;
use crate::queries::detached;
use crate::tree::Tree;
use numpy::{PyArray1, PyArrayMethods, PyReadonlyArray2};
use obbtree::query::{all_ray_hits, cast_rays, Ray, RayHit, RayMode, RayOptions};
use pyo3::prelude::*;

/// The native half of `obbtree.ray` (which documents it): `origins` and `directions`
/// (N, 3) float64 arrays, `mode` one of `closest`, `any`, `all`. Returns the hits of
/// every ray, ray by ray: `(ray, t, tri, barycentric, normal)` as (M,) int64, (M,)
/// float64, (M,) int64, (M, 3) float64, (M, 3) float64 arrays, where M is the number of
/// hits (at most one per ray unless `mode` is `all`).
#[pyfunction]
#[pyo3(signature = (tree, pose, origins, directions, t_max, mode, orthonormalize, threads))]
#[allow(clippy::type_complexity, clippy::too_many_arguments)]
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
) -> PyResult<(
    Bound<'py, PyArray1<i64>>,
    Bound<'py, PyArray1<f64>>,
    Bound<'py, PyArray1<i64>>,
    Bound<'py, numpy::PyArray2<f64>>,
    Bound<'py, numpy::PyArray2<f64>>,
)> {
    let file = tree.file()?;
    let pose = single_pose("pose", pose, orthonormalize)?;
    let (o, d) = (origins.as_array(), directions.as_array());
    if o.ncols() != 3 || d.ncols() != 3 || o.nrows() != d.nrows() {
        return Err(Failure::new(
            Kind::Option,
            format!(
                "origins and directions must be (N, 3) arrays of one N, got {:?} and {:?}",
                o.shape(),
                d.shape()
            ),
        )
        .into());
    }
    let rays: Vec<Ray> = o
        .rows()
        .into_iter()
        .zip(d.rows())
        .map(|(o, d)| Ray {
            origin: [o[0], o[1], o[2]],
            direction: [d[0], d[1], d[2]],
        })
        .collect();
    let mode = match mode {
        "closest" => Some(RayMode::Closest),
        "any" => Some(RayMode::Any),
        "all" => None,
        other => {
            return Err(Failure::new(
                Kind::Option,
                format!("mode must be \"closest\", \"any\" or \"all\", got {other:?}"),
            )
            .into())
        }
    };
    // The hits with their rays' indices, in ray order (no vector per ray: for one hit
    // per ray, those allocations would cost as much as the rays).
    let hits: Vec<(usize, RayHit)> = detached(py, threads, || -> Result<_, Failure> {
        Ok(match mode {
            Some(mode) => cast_rays(&file, &pose, &rays, &RayOptions { mode, t_max })?
                .into_iter()
                .enumerate()
                .filter_map(|(i, r)| Some((i, r.hit?)))
                .collect(),
            None => all_ray_hits(&file, &pose, &rays, t_max)?
                .into_iter()
                .enumerate()
                .flat_map(|(i, r)| r.hits.into_iter().map(move |h| (i, h)))
                .collect(),
        })
    })?;
    let m = hits.len();
    let (mut ray, mut t, mut tri, mut bary, mut normal) = (
        Vec::with_capacity(m),
        Vec::with_capacity(m),
        Vec::with_capacity(m),
        Vec::with_capacity(3 * m),
        Vec::with_capacity(3 * m),
    );
    for (index, h) in hits {
        ray.push(index as i64);
        t.push(h.t);
        tri.push(i64::from(h.triangle));
        bary.extend(h.barycentric);
        normal.extend(h.normal);
    }
    Ok((
        PyArray1::from_vec(py, ray),
        PyArray1::from_vec(py, t),
        PyArray1::from_vec(py, tri),
        PyArray1::from_vec(py, bary).reshape([m, 3])?,
        PyArray1::from_vec(py, normal).reshape([m, 3])?,
    ))
}
