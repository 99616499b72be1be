//! Fitting frames to point sets (dissertation chapter 3).
//!
//! [`principal_axes`] computes the orientation of an OBB: the principal axes of one of
//! three covariances of a face set, chosen by [`FitMethod`]. The box extents are taken
//! later, by the caller, over all vertices along these axes, so the frame only decides
//! how tight the box is, never whether it contains the geometry.
//!
//! The pieces, one concept per file (3-vector arithmetic is `crate::arr3`): `scratch` (per-thread buffers,
//! distinct vertices), `dimension` (intrinsic dimension, §3.3.5), `covariance` (moments,
//! §3.3–3.4), [`hull`] with `quickhull` and `polygon` (convex hulls), `eigen` (sorted
//! eigen-decomposition, ties), `frame` (deterministic completion, signs, handedness),
//! `symmetry` (axes inside tied eigenspaces), `principal` (the pipeline).

// why: fit/ indexes only its own buffers (scratch points, hull faces, horizon edges),
// in bounds by the invariants it establishes itself; a broken one is a bug that must fail
// loudly (a panic in tests and fuzzing), not turn into a silent fallback frame. Indices
// that come from a mesh are checked where they enter (`Scratch::gather`, the one-face
// case below), so untrusted data still never panics here.
#![allow(clippy::indexing_slicing)]

use std::cell::RefCell;

use nalgebra::Matrix3;

mod covariance;
mod dimension;
mod eigen;
mod frame;
pub mod hull;
mod polygon;
mod principal;
mod quickhull;
mod scratch;
mod symmetry;
mod triangle;

pub(crate) use covariance::FaceMoment;

/// Where a fit finds the area moments of its faces (for [`FitMethod::Triangles`], and the
/// hull's fallback).
#[derive(Clone, Copy, Debug)]
pub(crate) enum FaceMoments<'a> {
    /// Computed from the corners, face by face.
    FromCorners,
    /// `table[ids[k]]` is the moment of `faces[k]`: a build's table of every face (see
    /// [`FaceMoment`]), made once and summed at every level.
    Table {
        table: &'a [FaceMoment],
        ids: &'a [u32],
    },
}

/// Which covariance the OBB frame is computed from.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub enum FitMethod {
    /// Area-weighted covariance of the convex-hull surface of the vertices (§3.4); the
    /// default. Insensitive to how densely, or how unevenly, the surface is sampled.
    #[default]
    Hull,
    /// Area-weighted covariance of the triangles themselves; falls back to
    /// [`FitMethod::Vertices`] when their total area is zero.
    Triangles,
    /// Covariance of the distinct vertices (point masses; positions welded bitwise).
    Vertices,
}

impl FitMethod {
    /// Every method, in tag order.
    pub const ALL: [FitMethod; 3] = [FitMethod::Hull, FitMethod::Triangles, FitMethod::Vertices];

    /// The method's name on the command line: `"hull"`, `"triangles"` or `"vertices"`.
    pub fn name(self) -> &'static str {
        match self {
            FitMethod::Hull => "hull",
            FitMethod::Triangles => "triangles",
            FitMethod::Vertices => "vertices",
        }
    }

    /// The method named `s` (exactly as [`FitMethod::name`] spells it), if any.
    pub fn from_name(s: &str) -> Option<FitMethod> {
        FitMethod::ALL.into_iter().find(|m| m.name() == s)
    }

    /// The method's tag in a file header: 1, 2 or 3.
    pub fn tag(self) -> u8 {
        match self {
            FitMethod::Hull => 1,
            FitMethod::Triangles => 2,
            FitMethod::Vertices => 3,
        }
    }

    /// The method with tag `t`, if any.
    pub fn from_tag(t: u8) -> Option<FitMethod> {
        FitMethod::ALL.into_iter().find(|m| m.tag() == t)
    }
}

thread_local! {
    static SCRATCH: RefCell<scratch::Scratch> = RefCell::new(scratch::Scratch::default());
}

/// Orthonormal right-handed frame (determinant +1) whose columns are the principal axes of
/// the vertices of `faces` (indices into `positions`), sorted by decreasing variance:
/// column 0 is the axis of greatest spread.
///
/// The columns are unit directions in model coordinates; the frame maps box coordinates
/// to model coordinates (`model = R · local`). Orthonormal to ~1e-15.
///
/// Degenerate sets (§3.3.5) are decided by the intrinsic dimension of the vertices, with
/// extents below 1e-12 of the bounding-box diagonal counting as zero:
/// * one point (all coincident): the identity;
/// * collinear: column 0 along the line; column 1 the first world axis (x, y, z) at least
///   ~35° away from the line, made orthogonal to it;
/// * coplanar: column 2 is the plane normal, computed from the points (not from the
///   eigen-solver), and columns 0 and 1 the principal axes within the plane; with
///   [`FitMethod::Hull`] the covariance is that of the convex polygon. The hull method
///   also treats sets thinner than [`hull::HULL_TOLERANCE`] as planar.
///
/// Where eigenvalues tie (within 1e-9 relative: a cube, a square plate, a regular prism)
/// the axes in the tied eigenspace are chosen deterministically: the world axes projected
/// into it (Gram–Schmidt), unless an edge or normal direction of the largest triangles at
/// hand gives a box at least 1e-9 smaller; so an axis-aligned cube gets the identity and
/// a rotated cube its own axes. Each of columns 0 and 1 has its largest-magnitude
/// component positive; column 2 = column 0 × column 1.
///
/// Deterministic (same input, bitwise same output), never panics, and has no error case:
/// empty `faces` gives the identity, out-of-range indices are ignored, and non-finite
/// coordinates (outside the contract) still give some orthonormal frame. Uses per-thread
/// scratch buffers (including a `u32` per entry of `positions`), so repeated calls do not
/// allocate once warmed up.
pub fn principal_axes(
    method: FitMethod,
    positions: &[[f64; 3]],
    faces: &[[u32; 3]],
) -> Matrix3<f64> {
    let frame = match faces {
        [] => Matrix3::identity(),
        [[a, b, c]] => match (
            positions.get(*a as usize),
            positions.get(*b as usize),
            positions.get(*c as usize),
        ) {
            (Some(&p), Some(&q), Some(&r)) => triangle::triangle_frame(p, q, r),
            _ => Matrix3::identity(),
        },
        _ => with_scratch(|s| {
            let from_corners = FaceMoments::FromCorners;
            principal::fit(s, method, usize::MAX, positions, faces, from_corners)
        }),
    };
    if frame.iter().all(|v| v.is_finite()) {
        frame
    } else {
        Matrix3::identity()
    }
}

/// [`principal_axes`], also setting `vertices` to the distinct vertex indices of `faces`
/// (in range, each once, in some deterministic order), which the fit finds anyway. With
/// [`FitMethod::Hull`], a face set of more than `hull_points` distinct vertices has its
/// hull taken over an evenly spaced sample of `hull_points` of them and the six that reach
/// its bounding box (`usize::MAX`: every vertex, as [`principal_axes`] does). `moments`
/// says where the faces' area moments come from; a table gives the same frame as
/// computing them, faster.
pub(crate) fn principal_axes_and_vertices(
    method: FitMethod,
    hull_points: usize,
    positions: &[[f64; 3]],
    faces: &[[u32; 3]],
    moments: FaceMoments<'_>,
    vertices: &mut Vec<u32>,
) -> Matrix3<f64> {
    vertices.clear();
    if let [face] = faces {
        vertices.extend_from_slice(face);
    }
    if faces.len() <= 1 {
        return principal_axes(method, positions, faces);
    }
    let frame = with_scratch(|s| {
        let frame = principal::fit(s, method, hull_points, positions, faces, moments);
        vertices.extend_from_slice(&s.ids);
        frame
    });
    if frame.iter().all(|v| v.is_finite()) {
        frame
    } else {
        Matrix3::identity()
    }
}

/// Runs `f` on this thread's scratch buffers (fresh ones if those are unavailable).
fn with_scratch(mut f: impl FnMut(&mut scratch::Scratch) -> Matrix3<f64>) -> Matrix3<f64> {
    let shared = SCRATCH.try_with(|cell| cell.try_borrow_mut().ok().map(|mut s| f(&mut s)));
    match shared {
        Ok(Some(frame)) => frame,
        // Re-entrant use (impossible today) or the thread is being torn down: fresh
        // buffers.
        _ => f(&mut scratch::Scratch::default()),
    }
}
