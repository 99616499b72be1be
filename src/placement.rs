//! Units and origins: how a model's stored coordinates relate to its input mesh.
//!
//! Real meshes come in millimetres, metres, or far from their own origin. The builder can
//! scale a mesh uniformly and move its bounding-box centre to the origin before storing it
//! (`BuildOptions::scale`, `BuildOptions::center`; `obbtree build --scale S --center`), so
//! that models made in different units can be queried together. The file records what was
//! applied (the optional `placement` section, `formats/obbt.md` §5.6), and
//! [`ObbtFile::placement`](crate::format::ObbtFile::placement) reads it back.
//!
//! Everything downstream of the build works in the **stored frame**: the vertices and
//! volumes of the file, query poses and tolerances, and every coordinate and distance a
//! query returns are in stored units. [`Placement::to_input`] maps a stored point back to
//! the input mesh's frame.

use crate::arr3;

/// A uniform scale followed by a translation: for every vertex and every coordinate `k`,
/// `stored[k] = scale · input[k] + offset[k]`, evaluated in f64 (one product, one sum, each
/// rounded to nearest) before the result is rounded once more to the file's stored
/// precision.
///
/// `scale` is stored units per input unit (0.001 turns a mesh in millimetres into one in
/// metres); `offset` is in stored units, in the stored frame. A valid placement has a finite
/// `scale > 0` (no collapse, no mirroring) and a finite `offset`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Placement {
    /// Stored units per input unit: finite and greater than 0.
    pub scale: f64,
    /// Added after scaling, stored units (finite).
    pub offset: [f64; 3],
}

impl Placement {
    /// Stored coordinates are the input's: scale 1, offset 0. Files with this placement do
    /// not carry a `placement` section.
    pub const IDENTITY: Placement = Placement {
        scale: 1.0,
        offset: [0.0; 3],
    };

    /// The placement a build applies to `points` (the input vertices, input units): scale
    /// by `scale`, and with `center` also move the centre of their bounding box to the
    /// origin, i.e. `offset = −scale · (min + max) / 2` per coordinate (0 without `center`,
    /// or for no points).
    pub fn for_points(scale: f64, center: bool, points: &[[f64; 3]]) -> Placement {
        let offset = if center && !points.is_empty() {
            let (lo, hi) = arr3::bounds(points);
            // Halves first, so that the centre of a box spanning the whole f64 range is
            // finite too; `0 − x` rather than `−x`, so that a centre at 0 gives +0.
            arr3::map(arr3::zip(lo, hi), |(l, h)| {
                0.0 - scale * (0.5 * l + 0.5 * h)
            })
        } else {
            [0.0; 3]
        };
        Placement { scale, offset }
    }

    /// Whether this is [`Placement::IDENTITY`] (an offset of −0 counts as 0).
    pub fn is_identity(&self) -> bool {
        *self == Placement::IDENTITY
    }

    /// Whether `scale` can scale a model: finite and greater than 0 (0 would collapse the
    /// model to a point, a negative scale would mirror it, which turns its triangles inside
    /// out).
    pub fn is_valid_scale(scale: f64) -> bool {
        scale.is_finite() && scale > 0.0
    }

    /// The stored coordinates of an input point (`scale · input + offset`, in f64).
    pub fn apply(&self, input: [f64; 3]) -> [f64; 3] {
        arr3::map(arr3::zip(input, self.offset), |(x, o)| self.scale * x + o)
    }

    /// The input coordinates of a stored point (`(stored − offset) / scale`, in f64): the
    /// inverse of [`Placement::apply`] up to rounding. Use it to report a query's points in
    /// the input mesh's units and frame.
    pub fn to_input(&self, stored: [f64; 3]) -> [f64; 3] {
        arr3::map(arr3::zip(stored, self.offset), |(x, o)| {
            (x - o) / self.scale
        })
    }
}

impl Default for Placement {
    /// [`Placement::IDENTITY`].
    fn default() -> Self {
        Placement::IDENTITY
    }
}

impl std::fmt::Display for Placement {
    /// `scale S, offset [X, Y, Z]`.
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "scale {}, offset {:?}", self.scale, self.offset)
    }
}
