//! The text tobj is given: the file's `v` and `f` statements only, reduced to
//! what a triangle soup needs, after one point statement per vertex.

use std::fmt::Write as _;

use crate::mesh::error::quote;
use crate::mesh::text::numbered_lines;
use crate::mesh::{MeshError, MAX_TRIANGLES, MAX_VERTICES};

/// The input for tobj and what was learnt building it.
pub(super) struct TobjInput {
    /// `f 1` … `f N` (one point statement per vertex, so that tobj's
    /// first-use vertex numbering is the file's), then every `v` statement as
    /// `v x y z` and every `f` statement as `f i j k …` with position indices
    /// only, in file order.
    pub(super) text: String,
    /// Number of `v` statements of the file.
    pub(super) vertex_count: usize,
    /// Number of triangles the file's faces fan into.
    pub(super) triangle_count: usize,
}

/// Builds tobj's input from the OBJ `text`, rejecting (with its line) a vertex
/// of fewer than 3 coordinates, a face of fewer than 3 corners, a corner
/// without a position index, and counts above the caps. Numbers are left for
/// tobj to parse.
///
/// Everything else is dropped: texture coordinates and normals (their indices
/// are ignored, so they cannot make tobj fail or overflow), per-vertex colours
/// and `w` weights (`w` is for rational curves; tobj would divide by it),
/// objects, groups and materials (the soup merges them; they would split
/// tobj's output), `l` and `p` statements (not surfaces), comments.
pub(super) fn build(text: &str, file: &str) -> Result<TobjInput, MeshError> {
    let mut body = String::with_capacity(text.len());
    let mut vertex_count: usize = 0;
    let mut triangle_count: usize = 0;
    for (line, statement) in numbered_lines(text) {
        let mut words = statement.split_whitespace();
        match words.next() {
            Some("v") => {
                if vertex_count >= MAX_VERTICES {
                    let count = MAX_VERTICES + 1;
                    return Err(MeshError::too_large(file, "vertices", count, MAX_VERTICES));
                }
                vertex_count = vertex_count.saturating_add(1); // below the cap, just checked
                body.push('v');
                let mut coordinates: usize = 0;
                for word in words.take(3) {
                    body.push(' ');
                    body.push_str(word);
                    coordinates = coordinates.saturating_add(1);
                }
                if coordinates < 3 {
                    let message = format!("vertex needs 3 coordinates, found {coordinates}");
                    return Err(MeshError::syntax(file, line, message));
                }
                body.push('\n');
            }
            Some("f") => {
                body.push('f');
                let mut corners: usize = 0;
                for corner in words {
                    // A corner is `v`, `v/vt`, `v//vn` or `v/vt/vn`; only `v` is kept.
                    let position = corner.split('/').next().unwrap_or_default();
                    if position.is_empty() {
                        let message = format!("face corner {} has no vertex index", quote(corner));
                        return Err(MeshError::syntax(file, line, message));
                    }
                    body.push(' ');
                    body.push_str(position);
                    corners = corners.saturating_add(1);
                }
                if corners < 3 {
                    let message = format!("face has {corners} vertices, needs at least 3");
                    return Err(MeshError::syntax(file, line, message));
                }
                triangle_count = triangle_count.saturating_add(corners.saturating_sub(2));
                if triangle_count > MAX_TRIANGLES {
                    return Err(MeshError::too_large(
                        file,
                        "triangles",
                        triangle_count,
                        MAX_TRIANGLES,
                    ));
                }
                body.push('\n');
            }
            _ => {}
        }
    }
    let mut text = String::with_capacity(body.len().saturating_add(vertex_count.saturating_mul(8)));
    for k in 1..=vertex_count {
        // Writing to a String cannot fail.
        let _ = writeln!(text, "f {k}");
    }
    text.push_str(&body);
    Ok(TobjInput {
        text,
        vertex_count,
        triangle_count,
    })
}
