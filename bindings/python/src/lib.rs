//! The native module `obbtree._obbtree` behind the Python package `obbtree`.
//!
//! Trees are `obbtree::format::ObbtFile`s behind an `Arc`: queries clone it, release the
//! GIL and run; NumPy views of a tree's bytes hold it through their base object. No Rust
//! panic crosses into Python: PyO3 turns one into `pyo3_runtime.PanicException`, and the
//! library itself does not panic on data it did not make.

mod closest;
mod errors;
mod json;
mod poses;
mod queries;
mod ray;
mod scene;
mod tree;
mod winding;

use pyo3::prelude::*;

/// The native half of `obbtree.build` (which documents it): builds from a mesh file, or
/// from (n, 3) float64 vertices and (m, 3) int64 faces.
#[pyfunction]
#[pyo3(signature = (mesh_path, vertices, faces, out, bv, precision, layout, fit, leaf_size, scale, center, hull_min_faces, hull_max_points, model_axes, split_by_volume, sphere_fit, force))]
#[allow(clippy::too_many_arguments)]
fn _build(
    py: Python<'_>,
    mesh_path: Option<std::path::PathBuf>,
    vertices: Option<numpy::PyReadonlyArray2<'_, f64>>,
    faces: Option<numpy::PyReadonlyArray2<'_, i64>>,
    out: Option<std::path::PathBuf>,
    bv: &str,
    precision: &str,
    layout: &str,
    fit: &str,
    leaf_size: Option<u32>,
    scale: f64,
    center: bool,
    hull_min_faces: Option<u32>,
    hull_max_points: Option<u32>,
    model_axes: bool,
    split_by_volume: bool,
    sphere_fit: &str,
    force: bool,
) -> PyResult<tree::Tree> {
    let options = tree::build_options(
        bv,
        precision,
        layout,
        fit,
        leaf_size,
        scale,
        center,
        hull_min_faces,
        hull_max_points,
        model_axes,
        split_by_volume,
        sphere_fit,
    )?;
    let source = match (mesh_path, vertices, faces) {
        (Some(path), None, None) => tree::MeshSource::Path(path),
        (None, Some(v), Some(f)) => {
            let vertices = mesh_vertices(&v)?;
            let faces = mesh_faces(&f, vertices.len())?;
            tree::MeshSource::Arrays(vertices, faces)
        }
        _ => {
            return Err(errors::Failure::new(
                errors::Kind::Base,
                "_build takes a mesh path, or vertices and faces",
            )
            .into())
        }
    };
    tree::build_tree_from(py, source, out, options, force)
}

fn mesh_vertices(v: &numpy::PyReadonlyArray2<'_, f64>) -> PyResult<Vec<[f64; 3]>> {
    let view = v.as_array();
    if view.ncols() != 3 {
        return Err(errors::Failure::new(
            errors::Kind::Mesh,
            format!(
                "<memory>: vertices must be an (n, 3) array, got (n, {})",
                view.ncols()
            ),
        )
        .into());
    }
    Ok(view
        .rows()
        .into_iter()
        .map(|r| [r[0], r[1], r[2]])
        .collect())
}

fn mesh_faces(
    f: &numpy::PyReadonlyArray2<'_, i64>,
    vertex_count: usize,
) -> PyResult<Vec<[u32; 3]>> {
    let view = f.as_array();
    if view.ncols() != 3 {
        return Err(errors::Failure::new(
            errors::Kind::Mesh,
            format!(
                "<memory>: faces must be an (m, 3) array of vertex indices, got (m, {})",
                view.ncols()
            ),
        )
        .into());
    }
    let mut faces = Vec::with_capacity(view.nrows());
    for (id, row) in view.rows().into_iter().enumerate() {
        let mut face = [0u32; 3];
        for (slot, &index) in face.iter_mut().zip(row.iter()) {
            *slot = u32::try_from(index).map_err(|_| {
                errors::Failure::new(
                    errors::Kind::Mesh,
                    format!("<memory>: face {id}: face index {index} out of range ({vertex_count} vertices)"),
                )
            })?;
        }
        faces.push(face);
    }
    Ok(faces)
}

#[pymodule]
fn _obbtree(m: &Bound<'_, PyModule>) -> PyResult<()> {
    errors::register(m)?;
    m.add_class::<tree::Tree>()?;
    m.add_class::<tree::TreeBytes>()?;
    m.add_class::<queries::CollideResult>()?;
    m.add_class::<queries::DistanceResult>()?;
    m.add_class::<queries::WithinResult>()?;
    m.add_class::<queries::SpanResult>()?;
    m.add_class::<queries::HausdorffResult>()?;
    m.add_class::<scene::Scene>()?;
    m.add_function(wrap_pyfunction!(tree::open, m)?)?;
    m.add_function(wrap_pyfunction!(tree::_from_bytes, m)?)?;
    m.add_function(wrap_pyfunction!(_build, m)?)?;
    m.add_function(wrap_pyfunction!(queries::collide, m)?)?;
    m.add_function(wrap_pyfunction!(queries::distance, m)?)?;
    m.add_function(wrap_pyfunction!(queries::within, m)?)?;
    m.add_function(wrap_pyfunction!(queries::span, m)?)?;
    m.add_function(wrap_pyfunction!(queries::hausdorff, m)?)?;
    m.add_function(wrap_pyfunction!(closest::_closest, m)?)?;
    m.add_function(wrap_pyfunction!(ray::_ray, m)?)?;
    m.add_function(wrap_pyfunction!(ray::_ray_all, m)?)?;
    m.add_function(wrap_pyfunction!(winding::_inside, m)?)?;
    m.add_function(wrap_pyfunction!(queries::_time_rust_loop, m)?)?;
    m.add("__version__", env!("CARGO_PKG_VERSION"))?;
    Ok(())
}
