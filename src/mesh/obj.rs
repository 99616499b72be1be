//! Wavefront OBJ, read as a triangle soup: the `v` and `f` statements, in file order.
//!
//! - `v x y z [w | r g b]`: a vertex. Only the position is read: a `w` weight is for
//!   rational curves and colours are not geometry.
//! - `f c1 c2 c3 …`: a polygon, fan-triangulated in order: `(a b c d e)` gives `(a b c)`,
//!   `(a c d)`, `(a d e)`. A corner is `v`, `v/vt`, `v//vn` or `v/vt/vn`; only `v` is read
//!   (texture and normal indices name nothing a soup keeps, so they are not checked).
//!   `v` is 1-based and may name a vertex defined later; a negative `v` counts back from
//!   the vertices defined so far.
//! - Everything else is skipped: `vt`, `vn`, objects, groups, materials, smoothing, `l`
//!   and `p` (not surfaces), comments. Objects and groups merge into one soup, so vertex
//!   ids are the order of the `v` statements and triangle ids the fan order of the faces.
//!
//! Errors name the line of the first problem in reading order.

use std::str::SplitWhitespace;

use super::error::{quote, shorten};
use super::text::{coordinate, decode, numbered_lines};
use super::{Location, MeshError, Place, TriMesh, MAX_TRIANGLES, MAX_VERTICES};

/// `mesh` as OBJ text: one `v` line per vertex (each coordinate with the fewest digits
/// that read back exactly) and one 1-based `f` line per face, in order, so that
/// [`parse`] gives the same mesh back, ids and all.
pub(crate) fn write(mesh: &TriMesh) -> String {
    use std::fmt::Write as _;
    let mut text = String::new();
    // Writing to a String cannot fail.
    for [x, y, z] in mesh.vertices() {
        let _ = writeln!(text, "v {x:?} {y:?} {z:?}");
    }
    for face in mesh.faces() {
        let [a, b, c] = face.map(|v| u64::from(v).saturating_add(1));
        let _ = writeln!(text, "f {a} {b} {c}");
    }
    text
}

/// Parses OBJ text; `file` names it in errors.
pub(crate) fn parse(bytes: &[u8], file: &str) -> Result<TriMesh, MeshError> {
    let text = decode(bytes);
    // Positive indices may name vertices defined later, so they are checked against this
    // count, taken first; so is the cap, before anything is allocated.
    let vertex_count = statements(&text)
        .filter(|&(_, keyword, _)| keyword == "v")
        .count();
    if vertex_count > MAX_VERTICES {
        return Err(MeshError::too_large(
            file,
            "vertices",
            vertex_count,
            MAX_VERTICES,
        ));
    }
    let mut vertices = Vec::new();
    let mut faces = Vec::new();
    // The corners of the current face, reused from face to face.
    let mut corners = Vec::new();
    for (line, keyword, words) in statements(&text) {
        let at = Line { file, line };
        match keyword {
            "v" => vertices.push(at.vertex(words)?),
            "f" => {
                corners.clear();
                for corner in words {
                    corners.push(at.vertex_id(corner, vertices.len(), vertex_count)?);
                }
                at.fan(&corners, &mut faces)?;
            }
            _ => {}
        }
    }
    TriMesh::validated(file, vertices, faces)
}

/// The statements of `text`: line number, keyword, and the words after the keyword. Blank
/// lines have no statement.
fn statements(text: &str) -> impl Iterator<Item = (usize, &str, SplitWhitespace<'_>)> {
    numbered_lines(text).filter_map(|(line, statement)| {
        let mut words = statement.split_whitespace();
        words.next().map(|keyword| (line, keyword, words))
    })
}

/// The line being read, which every error names.
#[derive(Clone, Copy)]
struct Line<'a> {
    file: &'a str,
    line: usize,
}

impl Line<'_> {
    /// A syntax error at this line.
    fn syntax(self, message: String) -> MeshError {
        MeshError::syntax(self.file, self.line, message)
    }

    /// The position of a `v` statement: its first three words.
    fn vertex(self, mut words: SplitWhitespace<'_>) -> Result<[f64; 3], MeshError> {
        let xyz: [Option<&str>; 3] = std::array::from_fn(|_| words.next());
        let [Some(x), Some(y), Some(z)] = xyz else {
            let found = xyz.iter().flatten().count();
            return Err(self.syntax(format!("vertex needs 3 coordinates, found {found}")));
        };
        let read = |word| coordinate(word, self.file, self.line);
        Ok([read(x)?, read(y)?, read(z)?])
    }

    /// The 0-based vertex id a face corner names, with `defined` vertices before this line
    /// and `vertex_count` in the file.
    fn vertex_id(
        self,
        corner: &str,
        defined: usize,
        vertex_count: usize,
    ) -> Result<u32, MeshError> {
        let index = corner.split('/').next().unwrap_or_default();
        if index.is_empty() {
            let message = format!("face corner {} has no vertex index", quote(corner));
            return Err(self.syntax(message));
        }
        let backwards = index.starts_with('-');
        let digits = index.strip_prefix(['-', '+']).unwrap_or(index);
        if digits.is_empty() || !digits.bytes().all(|b| b.is_ascii_digit()) {
            return Err(self.syntax(format!("bad face index in {}", quote(corner))));
        }
        // A relative index can only reach back over the vertices defined so far.
        let range = if backwards { defined } else { vertex_count };
        // Too many digits for a usize is out of range like any other too large index.
        let distance = digits.parse::<usize>().unwrap_or(usize::MAX);
        let id = if backwards {
            range.checked_sub(distance)
        } else {
            distance.checked_sub(1)
        };
        id.filter(|&id| id < range)
            .and_then(|id| u32::try_from(id).ok())
            .ok_or_else(|| MeshError::IndexOutOfRange {
                place: Place::new(self.file, Location::Line(self.line)),
                index: shorten(index),
                vertex_count: range,
            })
    }

    /// Appends the fan of a face's `corners` to `faces`, within the triangle cap.
    fn fan(self, corners: &[u32], faces: &mut Vec<[u32; 3]>) -> Result<(), MeshError> {
        let Some((&first, rest)) = corners.split_first().filter(|_| corners.len() >= 3) else {
            let message = format!("face has {} vertices, needs at least 3", corners.len());
            return Err(self.syntax(message));
        };
        let count = faces.len().saturating_add(rest.len().saturating_sub(1));
        if count > MAX_TRIANGLES {
            return Err(MeshError::too_large(
                self.file,
                "triangles",
                count,
                MAX_TRIANGLES,
            ));
        }
        faces.extend(rest.windows(2).filter_map(|pair| match *pair {
            [b, c] => Some([first, b, c]),
            _ => None,
        }));
        Ok(())
    }
}
