//! Poses: of models in the world, and of one model in another's frame; their number
//! formats and validation.

use nalgebra::{Isometry3, Matrix3, Quaternion, Rotation3, Translation3, UnitQuaternion, Vector3};

/// Largest deviation of `RᵀR` from the identity accepted for a rotation.
pub const ORTHONORMAL_TOLERANCE: f64 = 1e-6;

/// Largest deviation of `RᵀR` from the identity that [`Pose::new`] keeps as given: the
/// rounding of a rotation computed in f64 (a few ulps), which the volume tests' rounding
/// slack covers. Anything above it is projected onto the nearest rotation.
const RIGID: f64 = 8.0 * f64::EPSILON;

/// A rigid motion placing one frame in another: a point `p` of the placed frame is
/// `rotation * p + translation` in the other. Always f64, whatever the stored precision of
/// the trees.
///
/// A model's pose places its model frame in the world (translation in world units). The
/// relative pose of a pair, [`Pose::relative`], places model B's frame in model A's
/// (translation in A's model units): queries compute it once and the volume tests of
/// [`crate::bv`] take it, named `b_to_a` for what it maps.
///
/// The rotation is a rotation to f64 rounding: [`Pose::new`] and the constructors built on
/// it refuse non-finite numbers, reflections and matrices farther than
/// [`ORTHONORMAL_TOLERANCE`] from orthonormal, and replace one within it (a rotation
/// printed with 7 digits, or computed in f32) by the nearest rotation, so that every query
/// answers for a rigid motion, as its volume tests assume. [`Pose::identity`] and
/// [`Pose::translation`] have the identity rotation (the latter takes its numbers as given).
/// A relative pose, composed of two such poses, is rigid to a few ulps more.
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
    #[error("rotation is not orthonormal: |RᵀR − I| reaches {deviation:.3e} (tolerance {ORTHONORMAL_TOLERANCE:e}; the orthonormalize option takes the nearest rotation)")]
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
    /// Not as many numbers as the format has.
    #[error("a pose in format {} has {} numbers ({}), got {got}", format.name(), format.numbers(), format.layout())]
    WrongCount {
        /// The format expected.
        format: PoseFormat,
        /// How many numbers were given.
        got: usize,
    },
    /// A quaternion whose norm is not 1 within [`ORTHONORMAL_TOLERANCE`].
    #[error("quaternion norm {norm} is not 1 within {ORTHONORMAL_TOLERANCE:e} (--orthonormalize normalises it)")]
    NotUnitQuaternion {
        /// Its norm.
        norm: f64,
    },
    /// A 4×4 matrix whose last row is not `0 0 0 1`.
    #[error("a 4x4 pose matrix must end in the row 0 0 0 1, got {row:?}")]
    NotRigid {
        /// The last row as given.
        row: [f64; 4],
    },
    /// A repair asked for would change the rotation by more than [`MAX_REPAIR`]: the
    /// numbers are not a rounded rotation but something else (a scale, a shear).
    #[error("the nearest rotation is {correction:.3e} away (more than {MAX_REPAIR:e}): a scaled or sheared matrix, not a rounded rotation")]
    BeyondRepair {
        /// The largest entry change the repair would make.
        correction: f64,
    },
}

/// The largest change [`PoseFormat::parse`] makes when asked to repair a rotation: enough
/// for rotations printed with 3 or 4 decimals (errors near 1e-4), far too little to turn a
/// scaled or sheared matrix into a rotation silently.
pub const MAX_REPAIR: f64 = 1e-2;

/// How the numbers of a pose are laid out. Nothing is guessed: the count must match.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub enum PoseFormat {
    /// 12 numbers: the rotation row-major, then the translation (`world = R p + T`).
    #[default]
    RotationTranslation,
    /// 7 numbers: the translation, then a unit quaternion `w x y z` (Eigen's constructor
    /// order).
    TranslationQuaternionWxyz,
    /// 7 numbers: the translation, then a unit quaternion `x y z w` (ROS messages, Eigen's
    /// `coeffs()`, SciPy).
    TranslationQuaternionXyzw,
    /// 16 numbers: a 4×4 homogeneous matrix, row-major, `[R T; 0 0 0 1]`.
    Matrix4,
}

/// A pose read from numbers, and how much it was repaired.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ParsedPose {
    /// The pose: as given when no repair was asked for, but for the projection of
    /// [`Pose::new`] (a change within [`ORTHONORMAL_TOLERANCE`]).
    pub pose: Pose,
    /// The repair made: the largest change of a rotation entry (nearest rotation), or the
    /// quaternion's distance from norm 1; 0 without repair.
    pub correction: f64,
}

/// The repairs made while reading many poses with repair asked for: how many rotations
/// changed by more than [`ORTHONORMAL_TOLERANCE`], and where the largest change was, so
/// that a reader can report them once at the end instead of correcting silently.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Repairs {
    /// Poses corrected by more than [`ORTHONORMAL_TOLERANCE`].
    pub count: usize,
    /// The largest of those corrections (0 when `count` is 0).
    pub largest: f64,
    /// Where the largest was, in the reader's words (empty when `count` is 0).
    pub at: String,
}

impl Repairs {
    /// Counts `parsed`'s correction if it is above [`ORTHONORMAL_TOLERANCE`], naming its
    /// place by `at` when it is the largest so far; returns the pose.
    pub fn note(&mut self, parsed: &ParsedPose, at: impl FnOnce() -> String) -> Pose {
        if parsed.correction > ORTHONORMAL_TOLERANCE {
            self.count += 1;
            if parsed.correction > self.largest {
                self.largest = parsed.correction;
                self.at = at();
            }
        }
        parsed.pose
    }
}

impl PoseFormat {
    /// Every format, default first.
    pub const ALL: [PoseFormat; 4] = [
        PoseFormat::RotationTranslation,
        PoseFormat::TranslationQuaternionWxyz,
        PoseFormat::TranslationQuaternionXyzw,
        PoseFormat::Matrix4,
    ];

    /// The CLI and scene-file name: `rt`, `tq-wxyz`, `tq-xyzw`, `matrix4`.
    pub fn name(self) -> &'static str {
        match self {
            PoseFormat::RotationTranslation => "rt",
            PoseFormat::TranslationQuaternionWxyz => "tq-wxyz",
            PoseFormat::TranslationQuaternionXyzw => "tq-xyzw",
            PoseFormat::Matrix4 => "matrix4",
        }
    }

    /// Inverse of [`PoseFormat::name`].
    pub fn from_name(name: &str) -> Option<PoseFormat> {
        PoseFormat::ALL.into_iter().find(|f| f.name() == name)
    }

    /// How many numbers a pose has in this format.
    pub fn numbers(self) -> usize {
        match self {
            PoseFormat::RotationTranslation => 12,
            PoseFormat::TranslationQuaternionWxyz | PoseFormat::TranslationQuaternionXyzw => 7,
            PoseFormat::Matrix4 => 16,
        }
    }

    /// What the numbers are, in order.
    pub fn layout(self) -> &'static str {
        match self {
            PoseFormat::RotationTranslation => "rotation row-major, then translation",
            PoseFormat::TranslationQuaternionWxyz => "tx ty tz, then quaternion qw qx qy qz",
            PoseFormat::TranslationQuaternionXyzw => "tx ty tz, then quaternion qx qy qz qw",
            PoseFormat::Matrix4 => "4x4 matrix row-major, last row 0 0 0 1",
        }
    }

    /// Reads a pose. Without `repair`, the rules of [`Pose::new`] apply (and a quaternion
    /// must have norm 1 within 1e-6); with it, a rotation matrix is replaced by the nearest
    /// rotation and a quaternion is normalised, refusing changes beyond [`MAX_REPAIR`] and
    /// reflections.
    ///
    /// # Errors
    ///
    /// - [`PoseError::WrongCount`] if `values` is not [`PoseFormat::numbers`] long.
    /// - [`PoseError::NotFinite`] for a NaN or infinite number (with its index).
    /// - [`PoseError::NotRigid`] for a [`PoseFormat::Matrix4`] whose last row is not
    ///   `0 0 0 1`.
    /// - Without `repair`: [`PoseError::NotUnitQuaternion`] for a quaternion whose norm is
    ///   not 1 within 1e-6, and the errors of [`Pose::new`] for a matrix.
    /// - With `repair`: [`PoseError::Reflection`] for a matrix with determinant ≤ 0, and
    ///   [`PoseError::BeyondRepair`] for a change beyond [`MAX_REPAIR`].
    ///
    /// # Examples
    ///
    /// ```
    /// use obbtree::query::{PoseError, PoseFormat};
    ///
    /// // Translation (1, 2, 3), then the quaternion w x y z of a half turn about z.
    /// let format = PoseFormat::from_name("tq-wxyz").expect("a format");
    /// let parsed = format.parse(&[1.0, 2.0, 3.0, 0.0, 0.0, 0.0, 1.0], false)?;
    /// assert_eq!(parsed.pose.translation_vector().x, 1.0);
    /// assert_eq!(parsed.correction, 0.0);
    ///
    /// // A slightly denormalised quaternion: refused as given, normalised with repair.
    /// let rough = [1.0, 2.0, 3.0, 0.0, 0.0, 0.0, 1.001];
    /// assert!(matches!(format.parse(&rough, false), Err(PoseError::NotUnitQuaternion { .. })));
    /// assert!(format.parse(&rough, true)?.correction > 0.0);
    /// assert!(matches!(format.parse(&rough[..6], true), Err(PoseError::WrongCount { .. })));
    /// # Ok::<(), PoseError>(())
    /// ```
    pub fn parse(self, values: &[f64], repair: bool) -> Result<ParsedPose, PoseError> {
        if values.len() != self.numbers() {
            return Err(PoseError::WrongCount {
                format: self,
                got: values.len(),
            });
        }
        for (index, &value) in values.iter().enumerate() {
            if !value.is_finite() {
                return Err(PoseError::NotFinite { index, value });
            }
        }
        let at = |i: usize| values.get(i).copied().unwrap_or(f64::NAN);
        let matrix = |r: [usize; 9], t: [usize; 3]| {
            let rotation = Matrix3::from_fn(|i, j| at(r.get(3 * i + j).copied().unwrap_or(0)));
            (rotation, Vector3::new(at(t[0]), at(t[1]), at(t[2])))
        };
        let quaternion = |w: usize, x: usize, y: usize, z: usize| {
            let q = Quaternion::new(at(w), at(x), at(y), at(z));
            let translation = Vector3::new(at(0), at(1), at(2));
            let error = (q.norm() - 1.0).abs();
            if error > ORTHONORMAL_TOLERANCE && !repair {
                return Err(PoseError::NotUnitQuaternion { norm: q.norm() });
            }
            if error > MAX_REPAIR {
                return Err(PoseError::BeyondRepair { correction: error });
            }
            let pose = Pose::from_quaternion(&UnitQuaternion::from_quaternion(q), &translation)?;
            let correction = if repair { error } else { 0.0 };
            Ok(ParsedPose { pose, correction })
        };
        let (rotation, translation) = match self {
            PoseFormat::TranslationQuaternionWxyz => return quaternion(3, 4, 5, 6),
            PoseFormat::TranslationQuaternionXyzw => return quaternion(6, 3, 4, 5),
            PoseFormat::RotationTranslation => matrix([0, 1, 2, 3, 4, 5, 6, 7, 8], [9, 10, 11]),
            PoseFormat::Matrix4 => {
                let row = [at(12), at(13), at(14), at(15)];
                if row != [0.0, 0.0, 0.0, 1.0] {
                    return Err(PoseError::NotRigid { row });
                }
                matrix([0, 1, 2, 4, 5, 6, 8, 9, 10], [3, 7, 11])
            }
        };
        if !repair {
            let pose = Pose::new(rotation, translation)?;
            return Ok(ParsedPose {
                pose,
                correction: 0.0,
            });
        }
        let (nearest, correction) = nearest_rotation(&rotation)?;
        Ok(ParsedPose {
            pose: Pose::new(nearest, translation)?,
            correction,
        })
    }
}

/// The rotation nearest to `m` (Frobenius norm; the polar factor `U Vᵀ` of its SVD) and
/// the largest entry change. A reflection (determinant < 0) has no nearest rotation worth
/// taking, and a change beyond [`MAX_REPAIR`] is not a repair.
fn nearest_rotation(m: &Matrix3<f64>) -> Result<(Matrix3<f64>, f64), PoseError> {
    let determinant = m.determinant();
    if determinant <= 0.0 {
        return Err(PoseError::Reflection { determinant });
    }
    let svd = m.svd(true, true);
    let (Some(u), Some(v_t)) = (svd.u, svd.v_t) else {
        return Err(PoseError::BeyondRepair {
            correction: f64::INFINITY,
        });
    };
    let nearest = u * v_t;
    let correction = (nearest - m).abs().max();
    if correction > MAX_REPAIR {
        return Err(PoseError::BeyondRepair { correction });
    }
    Ok((nearest, correction))
}

/// The largest entry of `|rᵀr − I|`: the column products' departures from 1 and 0.
#[inline]
fn deviation(r: &Matrix3<f64>) -> f64 {
    let (c0, c1, c2) = (r.column(0), r.column(1), r.column(2));
    let square = |c: &nalgebra::VectorView3<f64>| (c.dot(c) - 1.0).abs();
    let diagonal = square(&c0).max(square(&c1)).max(square(&c2));
    let off = c0
        .dot(&c1)
        .abs()
        .max(c0.dot(&c2).abs())
        .max(c1.dot(&c2).abs());
    diagonal.max(off)
}

/// The nearest rotation to `r`, a rotation with determinant +1 orthonormal within
/// [`ORTHONORMAL_TOLERANCE`] but not within [`RIGID`]: Newton–Schulz steps
/// `r ← r (3I − rᵀr) / 2` converge to its polar factor, squaring the deviation each step,
/// so two reach rounding from 1e-6; the loop stops at [`RIGID`] or after four.
fn made_rigid(mut r: Matrix3<f64>) -> Matrix3<f64> {
    let identity = Matrix3::identity();
    for _ in 0..4 {
        r = r * (identity * 3.0 - r.transpose() * r) * 0.5;
        if deviation(&r) <= RIGID {
            break;
        }
    }
    r
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
    ///
    /// A matrix orthonormal within the tolerance but beyond f64 rounding is replaced by
    /// the nearest rotation (its polar factor; entries move by about the deviation):
    /// the box and sphere tests take the rotation as rigid, and a stretch of 1e-6 would
    /// let them miss contacts that deep. A rotation within 8 ulps of orthonormal, as one
    /// computed in f64 from a quaternion or angles is, is kept bit for bit (a product of
    /// many rotations may be projected, by a few ulps).
    ///
    /// # Errors
    ///
    /// - [`PoseError::NotFinite`] for a NaN or infinite entry (index in row-major order,
    ///   rotation first).
    /// - [`PoseError::NotOrthonormal`] if `rotationᵀ · rotation` differs from the identity
    ///   by more than [`ORTHONORMAL_TOLERANCE`].
    /// - [`PoseError::Reflection`] for a negative determinant.
    ///
    /// # Examples
    ///
    /// ```
    /// use obbtree::nalgebra::{Matrix3, Rotation3, Vector3};
    /// use obbtree::query::{Pose, PoseError};
    ///
    /// let turn = Rotation3::from_euler_angles(0.0, 0.0, std::f64::consts::FRAC_PI_2);
    /// let pose = Pose::new(*turn.matrix(), Vector3::new(0.0, 0.0, 1.0))?;
    /// let p = pose.apply(&Vector3::new(1.0, 0.0, 0.0)); // turned onto y, lifted by 1
    /// assert!((p - Vector3::new(0.0, 1.0, 1.0)).norm() < 1e-12);
    ///
    /// let mirror = Matrix3::from_diagonal(&Vector3::new(1.0, 1.0, -1.0));
    /// assert!(matches!(Pose::new(mirror, Vector3::zeros()), Err(PoseError::Reflection { .. })));
    /// assert!(matches!(Pose::new(2.0 * Matrix3::identity(), Vector3::zeros()), Err(PoseError::NotOrthonormal { .. })));
    /// # Ok::<(), PoseError>(())
    /// ```
    pub fn new(rotation: Matrix3<f64>, translation: Vector3<f64>) -> Result<Pose, PoseError> {
        // Every pose of a batch passes here: plain arithmetic on the columns (nalgebra's
        // generic product, `abs` and `max` cost several times as much), and the error's
        // index found only once something is not finite.
        let all_finite = rotation
            .iter()
            .chain(translation.iter())
            .all(|v| v.is_finite());
        if !all_finite {
            let row_major = rotation.transpose();
            for (index, &value) in row_major.iter().chain(translation.iter()).enumerate() {
                if !value.is_finite() {
                    return Err(PoseError::NotFinite { index, value });
                }
            }
        }
        let deviation = deviation(&rotation);
        if deviation > ORTHONORMAL_TOLERANCE {
            return Err(PoseError::NotOrthonormal { deviation });
        }
        let (c0, c1, c2) = (rotation.column(0), rotation.column(1), rotation.column(2));
        let determinant = c0.dot(&c1.cross(&c2));
        if determinant < 0.0 {
            return Err(PoseError::Reflection { determinant });
        }
        let rotation = if deviation > RIGID {
            made_rigid(rotation)
        } else {
            rotation
        };
        Ok(Pose {
            rotation,
            translation,
        })
    }

    /// A pose from 12 numbers: the rotation row by row, then the translation
    /// ([`PoseFormat::RotationTranslation`], no repair).
    ///
    /// # Errors
    ///
    /// [`PoseError::WrongCount`] unless there are 12 numbers, then the errors of
    /// [`Pose::new`].
    ///
    /// # Examples
    ///
    /// ```
    /// use obbtree::query::Pose;
    ///
    /// let values = [1.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0, 4.0, 5.0, 6.0];
    /// let pose = Pose::from_row_major(&values)?;
    /// assert_eq!(pose, Pose::translation(4.0, 5.0, 6.0));
    /// assert_eq!(pose.row_major(), values);
    /// # Ok::<(), obbtree::query::PoseError>(())
    /// ```
    pub fn from_row_major(values: &[f64]) -> Result<Pose, PoseError> {
        Ok(PoseFormat::RotationTranslation.parse(values, false)?.pose)
    }

    /// The 12 numbers [`Pose::from_row_major`] reads: the rotation row by row, then the
    /// translation.
    pub fn row_major(&self) -> [f64; 12] {
        let (r, t) = (&self.rotation, &self.translation);
        [
            r.m11, r.m12, r.m13, r.m21, r.m22, r.m23, r.m31, r.m32, r.m33, t.x, t.y, t.z,
        ]
    }

    /// A pose from a unit quaternion and a translation (world units). nalgebra keeps
    /// `UnitQuaternion` normalised, so only non-finite numbers are refused.
    ///
    /// # Errors
    ///
    /// [`PoseError::NotFinite`] for a NaN or infinite number (and, in principle, the other
    /// errors of [`Pose::new`] for the rotation matrix of the quaternion).
    pub fn from_quaternion(
        rotation: &UnitQuaternion<f64>,
        translation: &Vector3<f64>,
    ) -> Result<Pose, PoseError> {
        Pose::new(*rotation.to_rotation_matrix().matrix(), *translation)
    }

    /// A pose from a nalgebra isometry (`world = iso * p`).
    ///
    /// # Errors
    ///
    /// As [`Pose::from_quaternion`]: [`PoseError::NotFinite`] for a NaN or infinite number.
    ///
    /// # Examples
    ///
    /// ```
    /// use obbtree::nalgebra::{Isometry3, Point3, Vector3};
    /// use obbtree::query::Pose;
    ///
    /// let iso = Isometry3::new(Vector3::new(1.0, 2.0, 3.0), Vector3::new(0.0, 0.0, 0.5));
    /// let pose = Pose::from_isometry(&iso)?;
    /// let p = Vector3::new(1.0, 1.0, 1.0);
    /// assert!((pose.apply(&p) - (iso * Point3::from(p)).coords).norm() < 1e-12);
    /// assert!(Pose::from_isometry(&Isometry3::translation(f64::NAN, 0.0, 0.0)).is_err());
    /// # Ok::<(), obbtree::query::PoseError>(())
    /// ```
    pub fn from_isometry(isometry: &Isometry3<f64>) -> Result<Pose, PoseError> {
        Pose::from_quaternion(&isometry.rotation, &isometry.translation.vector)
    }

    /// The pose as a nalgebra isometry.
    pub fn to_isometry(&self) -> Isometry3<f64> {
        let rotation = Rotation3::from_matrix_unchecked(self.rotation);
        Isometry3::from_parts(
            Translation3::from(self.translation),
            UnitQuaternion::from_rotation_matrix(&rotation),
        )
    }

    /// A pure translation.
    pub fn translation(x: f64, y: f64, z: f64) -> Pose {
        Pose {
            rotation: Matrix3::identity(),
            translation: Vector3::new(x, y, z),
        }
    }

    /// The rotation.
    #[inline]
    pub fn rotation(&self) -> &Matrix3<f64> {
        &self.rotation
    }

    /// The translation, in the units of the frame the pose places into (world units for a
    /// model's pose, A's model units for [`Pose::relative`]).
    #[inline]
    pub fn translation_vector(&self) -> &Vector3<f64> {
        &self.translation
    }

    /// Maps a point of the placed frame into the other (a model point to the world, for a
    /// model's pose).
    #[inline]
    pub fn apply(&self, p: &Vector3<f64>) -> Vector3<f64> {
        self.rotation * p + self.translation
    }

    /// The pose of model B's frame in model A's, given their poses in the world: it maps
    /// `p_b` to `p_a = Raᵀ (Rb p_b + Tb − Ta)`. Queries compute it once and then work in
    /// A's frame (dissertation §2.3.3). Not validated again: its rotation is the product
    /// of two checked ones.
    pub fn relative(a: &Pose, b: &Pose) -> Pose {
        let rt = a.rotation.transpose();
        Pose {
            rotation: rt * b.rotation,
            translation: rt * (b.translation - a.translation),
        }
    }
}
