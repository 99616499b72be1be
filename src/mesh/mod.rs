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
    /// Provisional constructor (replaced by the loader module).
    pub fn new(vertices: Vec<[f64; 3]>, faces: Vec<[u32; 3]>) -> Result<TriMesh, String> {
        if vertices.is_empty()
            || faces.is_empty()
            || faces
                .iter()
                .flatten()
                .any(|&i| i as usize >= vertices.len())
        {
            return Err("bad mesh".into());
        }
        Ok(TriMesh { vertices, faces })
    }
    /// Provisional.
    pub fn load(path: &std::path::Path) -> Result<TriMesh, String> {
        let bytes = std::fs::read(path).map_err(|e| e.to_string())?;
        Self::from_obj_bytes(&bytes, "x")
    }
    /// Provisional.
    pub fn from_obj_bytes(bytes: &[u8], _name: &str) -> Result<TriMesh, String> {
        let text = String::from_utf8_lossy(bytes);
        let mut v = Vec::new();
        let mut f = Vec::new();
        for line in text.lines() {
            let t: Vec<&str> = line.split_whitespace().collect();
            match t.first() {
                Some(&"v") => v.push([
                    t[1].parse().unwrap(),
                    t[2].parse().unwrap(),
                    t[3].parse().unwrap(),
                ]),
                Some(&"f") => {
                    let ix: Vec<u32> = t[1..]
                        .iter()
                        .map(|s| s.split('/').next().unwrap().parse::<u32>().unwrap() - 1)
                        .collect();
                    for k in 1..ix.len() - 1 {
                        f.push([ix[0], ix[k], ix[k + 1]]);
                    }
                }
                _ => {}
            }
        }
        Self::new(v, f)
    }
    /// Provisional.
    pub fn degenerate_triangle_count(&self) -> usize {
        0
    }
    /// The vertex positions, in model units.
    pub fn vertices(&self) -> &[[f64; 3]] {
        &self.vertices
    }
    /// The triangles, as indices into [`TriMesh::vertices`].
    pub fn faces(&self) -> &[[u32; 3]] {
        &self.faces
    }
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
