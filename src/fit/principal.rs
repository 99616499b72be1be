//! The fit itself: from a face set to its principal-axes frame, per [`FitMethod`].
//!
//! Steps: gather the distinct vertices; classify their intrinsic dimension (points and
//! lines have fixed answers); accumulate the method's covariance — in the plane, with
//! the plane normal as the last axis, for coplanar sets; diagonalise; choose axes inside
//! any tied eigenspace; normalise signs and handedness. Failures fall back along
//! hull → triangles → vertices, never to an unchecked result.

use nalgebra::Matrix3;

use super::covariance::{FaceMoment, Moments, Sym3};
use super::dimension::{classify, classify_with, Shape};
use super::eigen::{axes2, axes3};
use super::frame::{finish, Directions};
use super::hull::{is_flat, plane_basis};
use super::scratch::Scratch;
use super::symmetry::{refine, LargestTriangles};
use super::{FaceMoments, FitMethod};
use crate::arr3::V3;

/// Where the covariance came from; the same triangles propose axes for tied eigenvalues.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Source {
    /// The 3-D hull triangles in `Scratch::hull.tris`.
    HullSolid,
    /// The 2-D hull polygon in `Scratch::hull.poly`.
    HullFlat,
    /// The input faces.
    Faces,
}

/// The frame of `faces` by `method`; see `super::principal_axes` for the contract. With
/// the hull method, a set of more than `hull_points` distinct vertices has its hull taken
/// over an evenly spaced sample of them (see `super::principal_axes_and_vertices`).
pub(crate) fn fit(
    s: &mut Scratch,
    method: FitMethod,
    hull_points: usize,
    positions: &[[f64; 3]],
    faces: &[[u32; 3]],
    moments: FaceMoments<'_>,
) -> Matrix3<f64> {
    let mut method = method;
    // The triangle covariance decides, by its area, whether the method applies at all,
    // and the vertex method needs welded points: settle the method before gathering.
    let mut tri_cov = None;
    if method == FitMethod::Triangles {
        tri_cov = triangle_covariance(positions, faces, moments);
        if tri_cov.is_none() {
            method = FitMethod::Vertices;
        }
    }
    s.gather(positions, faces, method == FitMethod::Vertices);
    // Only the hull (unsampled) grows from the farthest points; the other fits need the
    // dimension, line and plane alone.
    let hull_needs_simplex = method == FitMethod::Hull && s.pts.len() <= hull_points;
    let shape = classify_with(&s.pts, s.magnitude, &s.extremes, !hull_needs_simplex);
    match shape.dim {
        0 => return Matrix3::identity(),
        1 => {
            let (c0, c1) = Directions::FreeAfter {
                c0: shape.direction,
            }
            .default_columns();
            return finish(c0, c1);
        }
        _ => {}
    }

    let mut result = None;
    if method == FitMethod::Hull {
        let shape = if s.pts.len() > hull_points {
            sample(s, hull_points)
        } else {
            shape
        };
        result = hull_frame(s, &shape);
        if result.is_none() {
            tri_cov = triangle_covariance(positions, faces, moments);
        }
    }
    if result.is_none() {
        if let Some(c) = tri_cov {
            result = cov_frame(&c, &shape).map(|f| (f, Source::Faces));
        }
    }
    if result.is_none() {
        // The vertex covariance; on the hull/triangle fallback path the points are not
        // welded, which only reweights duplicated positions.
        let mut m = Moments::default();
        for &p in &s.pts {
            m.add_point(p);
        }
        result = m
            .covariance()
            .and_then(|c| cov_frame(&c, &shape))
            .map(|f| (f, Source::Faces));
    }
    let Some((frame, source)) = result else {
        return Matrix3::identity();
    };

    let (c0, c1) = if frame.is_free() {
        let tris = largest_triangles(s, source, positions, faces);
        refine(&frame, &s.pts, &tris)
    } else {
        frame.default_columns()
    };
    finish(c0, c1)
}

/// Keeps every `k`-th of the gathered points (in the order the faces reference them, so
/// spread over the node) and the six that attain their bounding box, at most `target + 6`
/// in all (`target ≥ 1`; builds ask for at least 4), and classifies the sample. The hull of the sample lies within the set's hull and
/// reaches its bounding box; the box extents are still taken over every vertex.
fn sample(s: &mut Scratch, target: usize) -> Shape {
    let keep = s.extremes.indices();
    let k = s.pts.len().div_ceil(target.max(1));
    let mut i = 0;
    s.pts.retain(|_| {
        let kept = i % k == 0 || keep.contains(&i);
        i += 1;
        kept
    });
    classify(&s.pts, s.magnitude)
}

/// Area covariance of the hull surface (3-D) or polygon (flat), or `None` on failure.
fn hull_frame(s: &mut Scratch, shape: &Shape) -> Option<(Directions, Source)> {
    if is_flat(shape) {
        s.hull.polygon(&s.pts, shape);
        let poly = &s.hull.poly;
        let plane = &s.hull.plane;
        let at = |i: u32| {
            let q = plane[i as usize];
            [q[0], q[1], 0.0]
        };
        let (&first, rest) = poly.split_first()?;
        let mut m = Moments::default();
        for w in rest.windows(2) {
            if let [a, b] = *w {
                m.add_triangle(at(first), at(a), at(b));
            }
        }
        let c = m.covariance()?;
        let (u, v, n) = plane_basis(shape);
        let [xx, yy, _, xy, _, _] = c.0;
        let frame = axes2(xx, xy, yy, u, v, n)?;
        Some((frame, Source::HullFlat))
    } else {
        s.hull.polyhedron(&s.pts, shape).ok()?;
        let pts = &s.pts;
        let mut m = Moments::default();
        for t in &s.hull.tris {
            m.add_triangle(pts[t[0] as usize], pts[t[1] as usize], pts[t[2] as usize]);
        }
        let c = m.covariance()?;
        Some((axes3(&c)?, Source::HullSolid))
    }
}

/// Area covariance of the given faces, or `None` when their total area is zero.
fn triangle_covariance(
    positions: &[[f64; 3]],
    faces: &[[u32; 3]],
    moments: FaceMoments<'_>,
) -> Option<Sym3> {
    match moments {
        FaceMoments::FromCorners => {
            area_covariance(faces.iter().filter_map(|f| FaceMoment::of(positions, f)))
        }
        FaceMoments::Table { table, ids } => {
            area_covariance(ids.iter().filter_map(|&i| table.get(i as usize)).copied())
        }
    }
}

/// The area covariance of faces given by their moments, or `None` when they have no
/// area. Sums are taken relative to the first face's centroid, which keeps them small.
fn area_covariance(faces: impl Iterator<Item = FaceMoment>) -> Option<Sym3> {
    let mut faces = faces.peekable();
    let origin = faces.peek()?.centroid();
    let mut m = Moments::default();
    for f in faces {
        m.add_face(&f, origin);
    }
    if m.weight() > 0.0 {
        m.covariance()
    } else {
        None
    }
}

/// Principal axes of covariance `c`: in the plane for coplanar sets (normal last), else
/// of the full matrix.
fn cov_frame(c: &Sym3, shape: &Shape) -> Option<Directions> {
    if shape.dim == 2 {
        let (u, v, n) = plane_basis(shape);
        axes2(c.form(u, u), c.form(u, v), c.form(v, v), u, v, n)
    } else {
        axes3(c)
    }
}

/// The largest triangles of the covariance's source, to propose axes for tied
/// eigenvalues.
fn largest_triangles(
    s: &Scratch,
    source: Source,
    positions: &[[f64; 3]],
    faces: &[[u32; 3]],
) -> LargestTriangles {
    let mut best = LargestTriangles::default();
    let pt = |i: u32| -> V3 { s.pts[i as usize] };
    match source {
        Source::HullSolid => {
            for t in &s.hull.tris {
                best.offer(pt(t[0]), pt(t[1]), pt(t[2]));
            }
        }
        Source::HullFlat => {
            if let Some((&first, rest)) = s.hull.poly.split_first() {
                for w in rest.windows(2) {
                    let &[a, b] = w else { continue };
                    best.offer(pt(first), pt(a), pt(b));
                }
            }
        }
        Source::Faces => {
            for f in faces {
                if let (Some(&p), Some(&q), Some(&r)) = (
                    positions.get(f[0] as usize),
                    positions.get(f[1] as usize),
                    positions.get(f[2] as usize),
                ) {
                    best.offer(p, q, r);
                }
            }
        }
    }
    best
}
