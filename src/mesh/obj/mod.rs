//! Wavefront OBJ, parsed by the `tobj` crate with our own line scans around it.
//!
//! tobj alone does not fit a triangle soup with stable ids: it renumbers
//! vertices per object in order of first use and drops unused ones (so the
//! file's vertex ids are lost), turns `l` polylines of 3+ points into
//! triangles, rejects harmless files (mixed per-vertex colours, a bare
//! `usemtl`, a Latin-1 comment), reports no line numbers, and overflows (a
//! panic, even in release) on crafted texture or normal indices. So
//! [`filter`] hands it only the `v` and `f` statements, reduced to positions
//! and position indices, plus one leading point statement per vertex; tobj then
//! yields a single object whose vertex numbering is the file's. When tobj
//! rejects the input, [`diagnose`] finds the line.

mod diagnose;
mod filter;

use tobj::Mesh;

use super::text::decode;
use super::{MeshError, TriMesh};

/// Parses OBJ text; `file` names it in errors.
pub(crate) fn parse(bytes: &[u8], file: &str) -> Result<TriMesh, MeshError> {
    let text = decode(bytes);
    let input = filter::build(&text, file)?;
    let options = tobj::LoadOptions {
        // One position index per corner; texture and normal data are filtered out anyway.
        single_index: false,
        // Fan triangulation: (a b c d e) gives (a b c), (a c d), (a d e), in order.
        triangulate: true,
        // Our leading point statements must come through (as triangles [k, k, k]).
        ignore_points: false,
        ignore_lines: true,
    };
    let no_materials = |_: &std::path::Path| Err(tobj::LoadError::OpenFileFailed);
    let models = match tobj::load_obj_buf(&mut input.text.as_bytes(), &options, no_materials) {
        Ok((models, _materials)) => models,
        Err(error) => {
            let located = diagnose::rejection(&text, file, input.vertex_count);
            return Err(located.unwrap_or_else(|| MeshError::Obj {
                file: file.to_owned(),
                message: error.to_string(),
            }));
        }
    };
    let unpacked = match models.as_slice() {
        [model] => unpack(&model.mesh, input.vertex_count, input.triangle_count),
        _ => None,
    };
    let Some((vertices, faces)) = unpacked else {
        return Err(MeshError::Obj {
            file: file.to_owned(),
            message: format!("unexpected output ({} objects)", models.len()),
        });
    };
    let non_finite = vertices
        .iter()
        .enumerate()
        .find_map(|(id, p)| p.iter().find(|c| !c.is_finite()).map(|&value| (id, value)));
    if let Some((id, value)) = non_finite {
        return Err(diagnose::non_finite(&text, file, id, value));
    }
    TriMesh::validated(file, vertices, faces)
}

/// Vertex positions and triangles.
type Soup = (Vec<[f64; 3]>, Vec<[u32; 3]>);

/// The vertices and triangles of tobj's single object, if it has the expected
/// shape: `vertex_count` positions, then our point statements as triangles
/// `[k, k, k]` for every vertex `k` in order (dropped here), then `triangle_count`
/// triangles of the file.
fn unpack(mesh: &Mesh, vertex_count: usize, triangle_count: usize) -> Option<Soup> {
    if mesh.positions.len() != vertex_count.checked_mul(3)?
        || mesh.indices.len() != vertex_count.checked_add(triangle_count)?.checked_mul(3)?
    {
        return None;
    }
    let vertices = mesh.positions.chunks_exact(3).filter_map(|c| match *c {
        [x, y, z] => Some([x, y, z]),
        _ => None,
    });
    let mut triangles = mesh.indices.chunks_exact(3).filter_map(|c| match *c {
        [a, b, c] => Some([a, b, c]),
        _ => None,
    });
    for k in 0..vertex_count {
        let k = u32::try_from(k).ok()?;
        if triangles.next()? != [k; 3] {
            return None;
        }
    }
    Some((vertices.collect(), triangles.collect()))
}
