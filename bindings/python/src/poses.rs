//! Poses from Python: one pose or a batch, as NumPy arrays (or anything `numpy.asarray`
//! takes), checked by the library's rules (those of the CLI).

use crate::errors::{Failure, Kind};
use numpy::{AllowTypeChange, PyArrayDyn, PyArrayLikeDyn, PyArrayMethods};
use obbtree::query::{Pose, PoseFormat};
use pyo3::prelude::*;
use pyo3::types::PyTuple;

/// Poses read out of Python and checked, so that a batch runs without the GIL. `single`
/// when one pose was given rather than a batch.
pub struct Poses {
    /// The poses, in order.
    pub poses: Vec<Pose>,
    /// A single pose rather than a batch.
    pub single: bool,
}

const SHAPES: &str =
    "expected a (4, 4) matrix, (12,) numbers (R row-major, then t), an (R, t) pair, \
     or a batch (N, 4, 4) or (N, 12)";

fn shape_text(shape: &[usize]) -> String {
    match shape {
        [one] => format!("({one},)"),
        _ => format!(
            "({})",
            shape
                .iter()
                .map(usize::to_string)
                .collect::<Vec<_>>()
                .join(", ")
        ),
    }
}

fn bad(name: &str, message: impl Into<String>) -> PyErr {
    Failure::new(Kind::Pose, format!("{name}: {}", message.into())).into()
}

/// An array of f64 from anything NumPy converts (lists, other float or int dtypes).
fn array<'py>(
    name: &str,
    obj: &Bound<'py, PyAny>,
) -> PyResult<PyArrayLikeDyn<'py, f64, AllowTypeChange>> {
    obj.extract::<PyArrayLikeDyn<'py, f64, AllowTypeChange>>()
        .map_err(|e| bad(name, format!("not an array of numbers ({e}); {SHAPES}")))
}

/// Calls `read` with the shape and the numbers (row-major) of an array argument: the
/// array's own memory where it is a contiguous float64 array, else a row-major copy of
/// what NumPy makes of it.
fn with_numbers<T>(
    name: &str,
    obj: &Bound<'_, PyAny>,
    read: impl FnOnce(&[usize], &[f64]) -> PyResult<T>,
) -> PyResult<T> {
    if let Ok(a) = obj.cast::<PyArrayDyn<f64>>() {
        // SAFETY: the array is read while this thread holds the GIL, only within this
        // call, and `read` runs no Python code (callers keep it so); this extension never
        // makes a writable view of an array it is given, so nothing else writes to it
        // meanwhile. (This skips rust-numpy's borrow tracking, which costs more than the
        // read for one pose.)
        let view = unsafe { a.as_array() };
        if let Some(values) = view.as_slice() {
            return read(view.shape(), values);
        }
    }
    let a = array(name, obj)?;
    let view = a.as_array();
    // Iterates in logical (row-major) order whatever the strides.
    let values: Vec<f64> = view.iter().copied().collect();
    read(view.shape(), &values)
}

impl Poses {
    /// Reads and checks the pose argument `name`: (4, 4), (12,), (R, t), (N, 4, 4),
    /// (N, 12), or a batch pair (R (N, 3, 3), t (N, 3)); rotations are repaired to the
    /// nearest rotation with `orthonormalize`, as the CLI's `--orthonormalize`. The error
    /// names the argument and the index of the first bad pose.
    pub fn extract(name: &str, obj: &Bound<'_, PyAny>, orthonormalize: bool) -> PyResult<Poses> {
        if let Ok(pair) = obj.cast::<PyTuple>() {
            if pair.len() == 2 {
                let (r, t) = (pair.get_item(0)?, pair.get_item(1)?);
                let rt = Poses::rotation_translation(name, &r, &t, orthonormalize);
                // Not an (R, t) pair: maybe a tuple of two poses, a batch like any sequence.
                return rt.or_else(|e| Poses::array(name, obj, orthonormalize).map_err(|_| e));
            }
        }
        Poses::array(name, obj, orthonormalize)
    }

    /// Reads a pose or batch given as one array: (4, 4), (12,), (N, 4, 4) or (N, 12).
    fn array(name: &str, obj: &Bound<'_, PyAny>, orthonormalize: bool) -> PyResult<Poses> {
        with_numbers(name, obj, |shape, values| {
            let (format, single) = match shape {
                [4, 4] => (PoseFormat::Matrix4, true),
                [12] => (PoseFormat::RotationTranslation, true),
                [_, 4, 4] => (PoseFormat::Matrix4, false),
                [_, 12] => (PoseFormat::RotationTranslation, false),
                _ => {
                    return Err(bad(
                        name,
                        format!(
                            "an array of shape {} is not a pose; {SHAPES}",
                            shape_text(shape)
                        ),
                    ))
                }
            };
            let poses = parse(name, single, format, values, orthonormalize)?;
            Ok(Poses { poses, single })
        })
    }

    fn rotation_translation(
        name: &str,
        r: &Bound<'_, PyAny>,
        t: &Bound<'_, PyAny>,
        orthonormalize: bool,
    ) -> PyResult<Poses> {
        // R's numbers are copied before t is read: reading t may run Python code (its
        // conversion to an array), which must not happen while R's memory is borrowed.
        let (r_shape, r) = with_numbers(name, r, |shape, values| {
            Ok((shape.to_vec(), values.to_vec()))
        })?;
        let (r_shape, r) = (r_shape.as_slice(), r.as_slice());
        with_numbers(name, t, |t_shape, t| {
            let (count, single) = match (r_shape, t_shape) {
                ([3, 3], [3]) => (1, true),
                ([n, 3, 3], [m, 3]) if n == m => (*n, false),
                (rs, ts) => {
                    return Err(bad(
                        name,
                        format!(
                            "an (R, t) pair needs R (3, 3) and t (3,), or R (N, 3, 3) and t (N, 3); got R {} and t {}",
                            shape_text(rs),
                            shape_text(ts)
                        ),
                    ))
                }
            };
            let mut values = Vec::with_capacity(12 * count);
            for (rotation, translation) in r.chunks_exact(9).zip(t.chunks_exact(3)) {
                values.extend_from_slice(rotation);
                values.extend_from_slice(translation);
            }
            let format = PoseFormat::RotationTranslation;
            let poses = parse(name, single, format, &values, orthonormalize)?;
            Ok(Poses { poses, single })
        })
    }
}

/// The poses of `values` (whole poses of `format`, one after the other), checked as
/// [`Poses::extract`] says.
fn parse(
    name: &str,
    single: bool,
    format: PoseFormat,
    values: &[f64],
    orthonormalize: bool,
) -> PyResult<Vec<Pose>> {
    let per = format.numbers();
    let mut poses = Vec::with_capacity(values.len() / per);
    for (index, numbers) in values.chunks_exact(per).enumerate() {
        match format.parse(numbers, orthonormalize) {
            Ok(parsed) => poses.push(parsed.pose),
            Err(e) => {
                return Err(if single {
                    bad(name, e.to_string())
                } else {
                    bad(name, format!("pose {index}: {e}"))
                })
            }
        }
    }
    Ok(poses)
}

/// One pose (a scene frame's), in any of the single-pose forms.
pub fn single_pose(name: &str, obj: &Bound<'_, PyAny>, orthonormalize: bool) -> PyResult<Pose> {
    let read = Poses::extract(name, obj, orthonormalize)?;
    if !read.single {
        return Err(bad(name, "takes one pose, not a batch"));
    }
    read.poses
        .into_iter()
        .next()
        .ok_or_else(|| bad(name, "no pose"))
}
