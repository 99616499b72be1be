//! Triangle soups: the validated input of the builder, and the OBJ / STL loaders.
//!
//! Every loader ends in the same checks as [`TriMesh::new`], so a `TriMesh`
//! always satisfies its invariants however it was made.

// Everything here parses untrusted files: on top of the crate's no-panic lints, integer
// arithmetic must be checked or saturating and narrowing casts must be `try_from`.
#![cfg_attr(
    not(test),
    deny(clippy::arithmetic_side_effects, clippy::cast_possible_truncation)
)]

mod error;
mod limits;
mod load;
mod obj;
mod stl;
mod text;
mod weld;

pub use error::{Location, MeshError, Place};
pub use limits::{MAX_TRIANGLES, MAX_VERTICES};

/// Input name used in the errors of [`TriMesh::new`].
const MEMORY: &str = "<memory>";

/// A validated triangle soup: finite vertex positions and faces whose indices are in range.
///
/// Invariants: at least one vertex and one face; at most [`MAX_VERTICES`]
/// vertices and [`MAX_TRIANGLES`] faces; every coordinate finite; every index
/// `< vertices().len()`. Zero-area triangles are allowed (see
/// [`TriMesh::degenerate_triangle_count`]).
///
/// Triangle ids are positions in `faces` (0-based, file order after triangulation).
#[derive(Clone, Debug, PartialEq)]
pub struct TriMesh {
    vertices: Vec<[f64; 3]>,
    faces: Vec<[u32; 3]>,
}

impl TriMesh {
    /// Validates and wraps a vertex and face list: at least one vertex and one
    /// face, at most [`MAX_VERTICES`] / [`MAX_TRIANGLES`], every index
    /// `< vertices.len()`, every coordinate finite. Errors name `<memory>` and
    /// the 0-based vertex or face id at fault.
    ///
    /// # Errors
    ///
    /// - [`MeshError::EmptyMesh`] / [`MeshError::NoFaces`] for no vertices / no faces.
    /// - [`MeshError::TooLarge`] above [`MAX_VERTICES`] or [`MAX_TRIANGLES`].
    /// - [`MeshError::NonFinite`] for a NaN or infinite coordinate.
    /// - [`MeshError::IndexOutOfRange`] for an index `>= vertices.len()`.
    ///
    /// # Examples
    ///
    /// ```
    /// use obbtree::mesh::{MeshError, TriMesh};
    ///
    /// let triangle = TriMesh::new(vec![[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]], vec![[0, 1, 2]])?;
    /// assert_eq!(triangle.faces(), &[[0, 1, 2]]);
    /// let dangling = TriMesh::new(vec![[0.0; 3]], vec![[0, 1, 2]]);
    /// assert!(matches!(dangling, Err(MeshError::IndexOutOfRange { .. })));
    /// # Ok::<(), MeshError>(())
    /// ```
    pub fn new(vertices: Vec<[f64; 3]>, faces: Vec<[u32; 3]>) -> Result<TriMesh, MeshError> {
        TriMesh::validated(MEMORY, vertices, faces)
    }

    /// [`TriMesh::new`] with the input name `file` in the errors; the loaders'
    /// last step (they check coordinates and indices first, with line numbers).
    pub(crate) fn validated(
        file: &str,
        vertices: Vec<[f64; 3]>,
        faces: Vec<[u32; 3]>,
    ) -> Result<TriMesh, MeshError> {
        if vertices.is_empty() {
            return Err(MeshError::EmptyMesh {
                file: file.to_owned(),
            });
        }
        if faces.is_empty() {
            return Err(MeshError::NoFaces {
                file: file.to_owned(),
                vertex_count: vertices.len(),
            });
        }
        if vertices.len() > MAX_VERTICES {
            return Err(MeshError::too_large(
                file,
                "vertices",
                vertices.len(),
                MAX_VERTICES,
            ));
        }
        if faces.len() > MAX_TRIANGLES {
            return Err(MeshError::too_large(
                file,
                "triangles",
                faces.len(),
                MAX_TRIANGLES,
            ));
        }
        for (id, position) in vertices.iter().enumerate() {
            if let Some(&value) = position.iter().find(|c| !c.is_finite()) {
                return Err(MeshError::NonFinite {
                    place: Place::new(file, Location::Vertex(id)),
                    value,
                });
            }
        }
        for (id, face) in faces.iter().enumerate() {
            if let Some(&index) = face.iter().find(|&&i| i as usize >= vertices.len()) {
                return Err(MeshError::IndexOutOfRange {
                    place: Place::new(file, Location::Face(id)),
                    index: index.to_string(),
                    vertex_count: vertices.len(),
                });
            }
        }
        Ok(TriMesh { vertices, faces })
    }

    /// The vertex positions, in model units.
    pub fn vertices(&self) -> &[[f64; 3]] {
        &self.vertices
    }

    /// The triangles, as indices into [`TriMesh::vertices`]; a triangle's id is its position here.
    pub fn faces(&self) -> &[[u32; 3]] {
        &self.faces
    }

    /// The mesh as OBJ text, which [`TriMesh::load`] reads back to the same mesh: the same
    /// vertices bit for bit, the same faces and triangle ids.
    pub fn to_obj(&self) -> String {
        obj::write(self)
    }

    /// Number of zero-area triangles: a repeated vertex index, or coincident or
    /// collinear positions (an exactly zero cross product in f64). They are
    /// kept in the mesh because they can still touch other geometry.
    pub fn degenerate_triangle_count(&self) -> usize {
        degenerate_count(&self.vertices, &self.faces)
    }
}

/// Number of `faces` of zero area over `vertices` (see [`triangle_is_degenerate`]): of a
/// mesh as loaded, or of a tree's stored vertices for its header. A face with an index
/// past `vertices` counts as degenerate (callers have checked every index).
pub(crate) fn degenerate_count(vertices: &[[f64; 3]], faces: &[[u32; 3]]) -> usize {
    let degenerate = |face: &&[u32; 3]| match face.map(|i| vertices.get(i as usize)) {
        [Some(&p), Some(&q), Some(&r)] => triangle_is_degenerate(p, q, r),
        _ => true,
    };
    faces.iter().filter(degenerate).count()
}

/// Whether a triangle has zero area: its edge cross product is exactly zero in f64
/// (repeated, coincident or collinear corners). Such triangles are kept: they can touch.
pub fn triangle_is_degenerate(a: [f64; 3], b: [f64; 3], c: [f64; 3]) -> bool {
    let u = [b[0] - a[0], b[1] - a[1], b[2] - a[2]];
    let v = [c[0] - a[0], c[1] - a[1], c[2] - a[2]];
    let n = [
        u[1] * v[2] - u[2] * v[1],
        u[2] * v[0] - u[0] * v[2],
        u[0] * v[1] - u[1] * v[0],
    ];
    n == [0.0; 3]
}
