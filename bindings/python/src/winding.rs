//! `obbtree.winding_number` and `obbtree.signed_distance`: inside or outside one posed model.

use crate::errors::{Failure, Kind};
use crate::poses::single_pose;
use crate::queries::detached;
use crate::tree::Tree;
use numpy::{PyArray1, PyReadonlyArray2};
use obbtree::query::{signed_distances, winding_numbers, WindingAccuracy, WindingOptions};
use pyo3::prelude::*;

/// `points` as rows of three, or the error naming their shape.
pub fn point_rows(points: &PyReadonlyArray2<'_, f64>) -> Result<Vec<[f64; 3]>, Failure> {
    let view = points.as_array();
    if view.ncols() != 3 {
        return Err(Failure::new(
            Kind::Option,
            format!("points must be an (N, 3) array, got (N, {})", view.ncols()),
        ));
    }
    Ok(match view.as_slice() {
        // C-contiguous (as the Python side passes them): read as a flat slice, without
        // the views' per-element index arithmetic.
        Some(flat) => flat.chunks_exact(3).map(row_of_three).collect(),
        None => view
            .rows()
            .into_iter()
            .map(|r| [r[0], r[1], r[2]])
            .collect(),
    })
}

/// A row of `chunks_exact(3)` as an array. (A `map`, unlike a `filter_map` of `try_from`,
/// keeps the iterator's exact length, so that collecting allocates once.)
#[inline(always)]
pub fn row_of_three(row: &[f64]) -> [f64; 3] {
    std::array::from_fn(|k| row.get(k).copied().unwrap_or(f64::NAN))
}

/// The options of `beta` and `tolerance` as `obbtree.winding_number` documents them:
/// `tolerance` given, 0 for the exact sum, else within it; else Barill's rule at `beta`.
fn accuracy(beta: f64, tolerance: Option<f64>) -> WindingOptions {
    let accuracy = match tolerance {
        Some(0.0) => WindingAccuracy::Exact,
        Some(tolerance) => WindingAccuracy::Bounded { tolerance },
        None => WindingAccuracy::Beta { beta },
    };
    WindingOptions { accuracy }
}

/// The native half of `obbtree.winding_number` and `obbtree.signed_distance` (which
/// document it): `points` an (N, 3) float64 array. Returns the (N,) winding numbers, or
/// with `signed` the (N,) signed distances.
#[pyfunction]
#[pyo3(signature = (tree, pose, points, beta, tolerance, orthonormalize, threads, signed))]
#[allow(clippy::too_many_arguments)]
pub fn _inside<'py>(
    py: Python<'py>,
    tree: PyRef<'_, Tree>,
    pose: &Bound<'py, PyAny>,
    points: PyReadonlyArray2<'py, f64>,
    beta: f64,
    tolerance: Option<f64>,
    orthonormalize: bool,
    threads: Option<i64>,
    signed: bool,
) -> PyResult<Bound<'py, PyArray1<f64>>> {
    let file = tree.file()?;
    let pose = single_pose("pose", pose, orthonormalize)?;
    let query = point_rows(&points)?;
    let options = accuracy(beta, tolerance);
    let values = detached(py, threads, || {
        Ok(if signed {
            signed_distances(&file, &pose, &query, &options)?
        } else {
            winding_numbers(&file, &pose, &query, &options)?
                .iter()
                .map(|w| w.value)
                .collect()
        })
    })?;
    Ok(PyArray1::from_vec(py, values))
}
