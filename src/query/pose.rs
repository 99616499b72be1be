//! Poses of models in the world, and their validation.

use crate::bv::pair::Transform;
use nalgebra::{Matrix3, Vector3};

/// Largest deviation of `RᵀR` from the identity accepted for a rotation.
pub const ORTHONORMAL_TOLERANCE: f64 = 1e-6;

/// Where a model is: world point = `rotation * p + translation` for a model point `p`.
/// Always f64, whatever the stored precision of the tree.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Pose {
    rotation: Matrix3<f64>,
    translation: Vector3<f64>,
}

/// Why numbers do not form a pose.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum PoseError {
    /// A number is NaN or infinite.
    #[error("pose value {index} is not finite ({value})")]
    NotFinite {
        /// Position in row-major rotation then translation order (0..12).
        index: usize,
        /// The value.
        value: f64,
    },
    /// The rotation is not orthonormal within [`ORTHONORMAL_TOLERANCE`].
    #[error("rotation is not orthonormal: |RᵀR − I| reaches {deviation:.3e} (tolerance {ORTHONORMAL_TOLERANCE:e})")]
    NotOrthonormal {
        /// Largest entry of `|RᵀR − I|`.
        deviation: f64,
    },
    /// The matrix is orthonormal but mirrors (determinant −1).
    #[error("rotation has determinant {determinant:.6}: a reflection, not a rotation")]
    Reflection {
        /// The determinant.
        determinant: f64,
    },
    /// Not 12 numbers.
    #[error("a pose has 12 numbers (rotation row-major, then translation), got {0}")]
    WrongCount(usize),
}

impl Default for Pose {
    fn default() -> Self {
        Pose::identity()
    }
}

impl Pose {
    /// The identity pose: model frame = world frame.
    pub fn identity() -> Pose {
        Pose {
            rotation: Matrix3::identity(),
            translation: Vector3::zeros(),
        }
    }

    /// A pose from a rotation and a translation, refusing non-finite numbers, rotations not
    /// orthonormal within 1e-6, and reflections.
    pub fn new(rotation: Matrix3<f64>, translation: Vector3<f64>) -> Result<Pose, PoseError> {
        let row_major = rotation.transpose();
        for (index, &value) in row_major.iter().chain(translation.iter()).enumerate() {
            if !value.is_finite() {
                return Err(PoseError::NotFinite { index, value });
            }
        }
        let deviation = (rotation.transpose() * rotation - Matrix3::identity())
            .abs()
            .max();
        if deviation > ORTHONORMAL_TOLERANCE {
            return Err(PoseError::NotOrthonormal { deviation });
        }
        let determinant = rotation.determinant();
        if determinant < 0.0 {
            return Err(PoseError::Reflection { determinant });
        }
        Ok(Pose {
            rotation,
            translation,
        })
    }

    /// A pose from 12 numbers: the rotation row by row, then the translation.
    pub fn from_row_major(values: &[f64]) -> Result<Pose, PoseError> {
        let v: &[f64; 12] = values
            .try_into()
            .map_err(|_| PoseError::WrongCount(values.len()))?;
        let rotation = Matrix3::new(v[0], v[1], v[2], v[3], v[4], v[5], v[6], v[7], v[8]);
        Pose::new(rotation, Vector3::new(v[9], v[10], v[11]))
    }

    /// A pure translation.
    pub fn translation(x: f64, y: f64, z: f64) -> Pose {
        Pose {
            rotation: Matrix3::identity(),
            translation: Vector3::new(x, y, z),
        }
    }

    /// The rotation.
    pub fn rotation(&self) -> &Matrix3<f64> {
        &self.rotation
    }

    /// The translation, world units.
    pub fn translation_vector(&self) -> &Vector3<f64> {
        &self.translation
    }

    /// Maps a model point to the world.
    pub fn apply(&self, p: &Vector3<f64>) -> Vector3<f64> {
        self.rotation * p + self.translation
    }

    /// The map from model B's frame (posed by `b`) into model A's frame (posed by `a`):
    /// `p_a = Raᵀ (Rb p_b + Tb − Ta)`. Queries compute it once and then work in A's frame.
    pub fn relative(a: &Pose, b: &Pose) -> Transform {
        let rt = a.rotation.transpose();
        Transform {
            rotation: rt * b.rotation,
            translation: rt * (b.translation - a.translation),
        }
    }
}
