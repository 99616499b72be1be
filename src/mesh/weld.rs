//! Turning a list of independent triangles (STL) into shared vertices.

use std::collections::HashMap;

use super::MAX_VERTICES;

/// The vertex cap was reached while welding.
#[derive(Debug)]
pub(crate) struct VertexLimit;

/// Merges bitwise-identical positions into one vertex, numbered in order of
/// first occurrence, so the result depends only on the input order.
#[derive(Debug, Default)]
pub(crate) struct Welder {
    /// Position bits (with -0.0 made 0.0) to vertex id.
    ids: HashMap<[u64; 3], u32>,
    vertices: Vec<[f64; 3]>,
    faces: Vec<[u32; 3]>,
}

impl Welder {
    /// A welder with room for `triangles` faces; `triangles` must already be
    /// checked against the caps and the input size.
    pub(crate) fn with_capacity(triangles: usize) -> Welder {
        // A closed mesh has about half as many vertices as triangles.
        let vertices = (triangles / 2).saturating_add(3);
        Welder {
            ids: HashMap::with_capacity(vertices),
            vertices: Vec::with_capacity(vertices),
            faces: Vec::with_capacity(triangles),
        }
    }

    /// Appends a triangle of finite corner positions.
    pub(crate) fn push_triangle(&mut self, corners: [[f64; 3]; 3]) -> Result<(), VertexLimit> {
        let [a, b, c] = corners;
        let face = [self.id_of(a)?, self.id_of(b)?, self.id_of(c)?];
        self.faces.push(face);
        Ok(())
    }

    /// Number of triangles pushed so far.
    pub(crate) fn triangle_count(&self) -> usize {
        self.faces.len()
    }

    /// The vertices and faces.
    pub(crate) fn finish(self) -> (Vec<[f64; 3]>, Vec<[u32; 3]>) {
        (self.vertices, self.faces)
    }

    /// The id of `position`, adding it as a new vertex on first sight.
    fn id_of(&mut self, position: [f64; 3]) -> Result<u32, VertexLimit> {
        // Adding 0.0 turns -0.0 into 0.0 and leaves every other value alone,
        // so the two zeros (equal as numbers) weld together.
        let position = position.map(|x| x + 0.0);
        let key = position.map(f64::to_bits);
        if let Some(&id) = self.ids.get(&key) {
            return Ok(id);
        }
        if self.vertices.len() >= MAX_VERTICES {
            return Err(VertexLimit);
        }
        let id = u32::try_from(self.vertices.len()).map_err(|_| VertexLimit)?;
        self.vertices.push(position);
        self.ids.insert(key, id);
        Ok(id)
    }
}
