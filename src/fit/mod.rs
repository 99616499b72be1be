//! Fitting frames to point sets (dissertation chapter 3).
use nalgebra::Matrix3;

/// Which covariance the OBB frame is computed from.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub enum FitMethod {
    /// Area-weighted covariance of the convex-hull surface (§3.4); the default.
    #[default]
    Hull,
    /// Area-weighted covariance of the triangles themselves.
    Triangles,
    /// Covariance of the (distinct) vertices.
    Vertices,
}

/// Orthonormal right-handed frame whose columns are the principal axes of the
/// vertices of `faces`, sorted by decreasing variance.
pub fn principal_axes(
    method: FitMethod,
    positions: &[[f64; 3]],
    faces: &[[u32; 3]],
) -> Matrix3<f64> {
    let _ = (method, positions, faces);
    Matrix3::identity()
}

impl FitMethod {
    /// All methods, default first.
    pub const ALL: [FitMethod; 3] = [FitMethod::Hull, FitMethod::Triangles, FitMethod::Vertices];
    /// `"hull"`, `"triangles"` or `"vertices"`.
    pub fn name(self) -> &'static str {
        match self {
            FitMethod::Hull => "hull",
            FitMethod::Triangles => "triangles",
            FitMethod::Vertices => "vertices",
        }
    }
    /// Inverse of [`FitMethod::name`].
    pub fn from_name(s: &str) -> Option<FitMethod> {
        FitMethod::ALL.into_iter().find(|m| m.name() == s)
    }
    /// Header tag: 1, 2, 3.
    pub fn tag(self) -> u8 {
        match self {
            FitMethod::Hull => 1,
            FitMethod::Triangles => 2,
            FitMethod::Vertices => 3,
        }
    }
    /// Inverse of [`FitMethod::tag`].
    pub fn from_tag(t: u8) -> Option<FitMethod> {
        FitMethod::ALL.into_iter().find(|m| m.tag() == t)
    }
}
