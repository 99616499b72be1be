//! Triangle soups: the validated input of the builder, and the OBJ / STL loaders.

/// A validated triangle soup: finite vertex positions and faces whose indices are in range.
///
/// Triangle ids are positions in `faces` (0-based, file order after triangulation).
#[derive(Clone, Debug, PartialEq)]
pub struct TriMesh {
    vertices: Vec<[f64; 3]>,
    faces: Vec<[u32; 3]>,
}

impl TriMesh {
    /// The vertex positions, in model units.
    pub fn vertices(&self) -> &[[f64; 3]] {
        &self.vertices
    }
    /// The triangles, as indices into [`TriMesh::vertices`].
    pub fn faces(&self) -> &[[u32; 3]] {
        &self.faces
    }
}
