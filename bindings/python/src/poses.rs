//! Poses from Python: one pose or a batch, as NumPy arrays (or anything `numpy.asarray`
//! takes), checked by the library's rules (those of the CLI).

use crate::errors::{Failure, Kind};
use numpy::{AllowTypeChange, PyArrayDyn, PyArrayLikeDyn, PyArrayMethods};
use obbtree::query::{Pose, PoseFormat};
use pyo3::prelude::*;
use pyo3::types::PyTuple;

/// Poses as given, copied out of Python so that they can be read without the GIL: `count`
/// poses of `format` (16 numbers of a 4x4 matrix or 12 of R then t), row-major, one after
/// the other. `single` when one pose was given rather than a batch.
pub struct RawPoses {
    /// The argument's name, for errors (`poses_a`).
    pub name: String,
    /// The numbers, `count * format.numbers()` of them.
    pub values: Vec<f64>,
    /// How the numbers of one pose are laid out.
    pub format: PoseFormat,
    /// How many poses.
    pub count: usize,
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

/// The shape and the numbers (row-major) of an array argument, copied out at once.
fn numbers(name: &str, obj: &Bound<'_, PyAny>) -> PyResult<(Vec<usize>, Vec<f64>)> {
    if let Ok(a) = obj.cast::<PyArrayDyn<f64>>() {
        // SAFETY: the array is read while this thread holds the GIL (no Python code runs)
        // and copied at once; this extension never makes a writable view of an array it is
        // given, so nothing else writes to it meanwhile. (This skips rust-numpy's borrow
        // tracking, which costs more than the copy for one pose.)
        let view = unsafe { a.as_array() };
        let values = view
            .as_slice()
            .map(<[f64]>::to_vec)
            .unwrap_or_else(|| view.iter().copied().collect());
        return Ok((view.shape().to_vec(), values));
    }
    let a = array(name, obj)?;
    let view = a.as_array();
    // Iterates in logical (row-major) order whatever the strides.
    Ok((view.shape().to_vec(), view.iter().copied().collect()))
}

impl RawPoses {
    /// Reads the pose argument `name`: (4, 4), (12,), (R, t), (N, 4, 4), (N, 12), or a
    /// batch pair (R (N, 3, 3), t (N, 3)).
    pub fn extract(name: &str, obj: &Bound<'_, PyAny>) -> PyResult<RawPoses> {
        if let Ok(pair) = obj.cast::<PyTuple>() {
            if pair.len() == 2 {
                let rt =
                    RawPoses::rotation_translation(name, &pair.get_item(0)?, &pair.get_item(1)?);
                // Not an (R, t) pair: maybe a tuple of two poses, a batch like any sequence.
                return rt.or_else(|e| RawPoses::array(name, obj).map_err(|_| e));
            }
        }
        RawPoses::array(name, obj)
    }

    /// Reads a pose or batch given as one array: (4, 4), (12,), (N, 4, 4) or (N, 12).
    fn array(name: &str, obj: &Bound<'_, PyAny>) -> PyResult<RawPoses> {
        let (shape, values) = numbers(name, obj)?;
        let (format, count, single) = match shape.as_slice() {
            [4, 4] => (PoseFormat::Matrix4, 1, true),
            [12] => (PoseFormat::RotationTranslation, 1, true),
            [n, 4, 4] => (PoseFormat::Matrix4, *n, false),
            [n, 12] => (PoseFormat::RotationTranslation, *n, false),
            _ => {
                return Err(bad(
                    name,
                    format!(
                        "an array of shape {} is not a pose; {SHAPES}",
                        shape_text(&shape)
                    ),
                ))
            }
        };
        Ok(RawPoses {
            name: name.to_owned(),
            values,
            format,
            count,
            single,
        })
    }

    fn rotation_translation(
        name: &str,
        r: &Bound<'_, PyAny>,
        t: &Bound<'_, PyAny>,
    ) -> PyResult<RawPoses> {
        let ((r_shape, r), (t_shape, t)) = (numbers(name, r)?, numbers(name, t)?);
        let (count, single) = match (r_shape.as_slice(), t_shape.as_slice()) {
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
        Ok(RawPoses {
            name: name.to_owned(),
            values,
            format: PoseFormat::RotationTranslation,
            count,
            single,
        })
    }

    /// The checked poses (repaired to the nearest rotation with `orthonormalize`, as the
    /// CLI's `--orthonormalize`). The error names the argument and the index of the first
    /// bad pose. Needs no GIL.
    pub fn parse(&self, orthonormalize: bool) -> Result<Vec<Pose>, Failure> {
        let per = self.format.numbers();
        let mut poses = Vec::with_capacity(self.count);
        for (index, values) in self.values.chunks_exact(per).enumerate() {
            match self.format.parse(values, orthonormalize) {
                Ok(parsed) => poses.push(parsed.pose),
                Err(e) => {
                    let message = if self.single {
                        format!("{}: {e}", self.name)
                    } else {
                        format!("{}: pose {index}: {e}", self.name)
                    };
                    return Err(Failure::new(Kind::Pose, message));
                }
            }
        }
        Ok(poses)
    }
}

/// One pose (a scene frame's), in any of the single-pose forms.
pub fn single_pose(name: &str, obj: &Bound<'_, PyAny>, orthonormalize: bool) -> PyResult<Pose> {
    let raw = RawPoses::extract(name, obj)?;
    if !raw.single {
        return Err(bad(name, "takes one pose, not a batch"));
    }
    let poses = raw.parse(orthonormalize)?;
    poses.into_iter().next().ok_or_else(|| bad(name, "no pose"))
}
