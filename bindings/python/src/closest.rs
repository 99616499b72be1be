//! `obbtree.closest`: the closest surface point of one posed model to many points.

use crate::errors::Failure;
use crate::poses::single_pose;
use crate::queries::detached;
use crate::tree::Tree;
use numpy::{PyArray1, PyArray2, PyArrayMethods, PyReadonlyArray2};
use obbtree::query::{closest_points, ClosestOptions};
use pyo3::prelude::*;

/// The native half of `obbtree.closest` (which documents it): `points` an (N, 3) float64
/// array. Returns `(distance, point, tri, feature, feature_index)` arrays: (N,) float64
/// (+inf without an answer), (N, 3) float64 (NaN), (N,) int64 (-1), (N,) int8 (0 face,
/// 1 edge, 2 vertex, -1), (N,) int8.
#[pyfunction]
#[pyo3(signature = (tree, pose, points, max_distance, orthonormalize, threads))]
#[allow(clippy::type_complexity)]
pub fn _closest<'py>(
    py: Python<'py>,
    tree: PyRef<'_, Tree>,
    pose: &Bound<'py, PyAny>,
    points: PyReadonlyArray2<'py, f64>,
    max_distance: f64,
    orthonormalize: bool,
    threads: Option<i64>,
) -> PyResult<(
    Bound<'py, PyArray1<f64>>,
    Bound<'py, PyArray2<f64>>,
    Bound<'py, PyArray1<i64>>,
    Bound<'py, PyArray1<i8>>,
    Bound<'py, PyArray1<i8>>,
)> {
    let file = tree.file()?;
    let pose = single_pose("pose", pose, orthonormalize)?;
    let query = crate::winding::point_rows(&points)?;
    let options = ClosestOptions { max_distance };
    let answers = detached(py, threads, || {
        closest_points(&file, &pose, &query, &options).map_err(Failure::from)
    })?;
    let n = answers.len();
    let (mut distance, mut point, mut tri, mut feature, mut index) = (
        Vec::with_capacity(n),
        Vec::with_capacity(3 * n),
        Vec::with_capacity(n),
        Vec::with_capacity(n),
        Vec::with_capacity(n),
    );
    for answer in &answers {
        match answer.closest {
            Some(c) => {
                distance.push(c.distance);
                point.extend(c.point);
                tri.push(i64::from(c.triangle));
                feature.push(match c.feature {
                    obbtree::query::triangle::Feature::Face => 0,
                    obbtree::query::triangle::Feature::Edge(_) => 1,
                    obbtree::query::triangle::Feature::Vertex(_) => 2,
                });
                index.push(c.feature.index() as i8);
            }
            None => {
                distance.push(f64::INFINITY);
                point.extend([f64::NAN; 3]);
                tri.push(-1);
                feature.push(-1);
                index.push(-1);
            }
        }
    }
    let point = PyArray1::from_vec(py, point).reshape([n, 3])?;
    Ok((
        PyArray1::from_vec(py, distance),
        point,
        PyArray1::from_vec(py, tri),
        PyArray1::from_vec(py, feature),
        PyArray1::from_vec(py, index),
    ))
}
