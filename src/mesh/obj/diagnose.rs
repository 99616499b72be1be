//! Finding the line at fault once tobj (or a later check) has rejected a file:
//! tobj reports only the kind of problem, so the text is scanned again with
//! tobj's own rules. Runs on the error path only.

use crate::mesh::error::{quote, shorten};
use crate::mesh::text::numbered_lines;
use crate::mesh::{Location, MeshError, Place};

/// The first statement tobj rejects in the OBJ `text` (which has
/// `vertex_count` vertices): a coordinate that is not a number, a face index
/// that is not an integer, or one out of range. `None` if there is none.
pub(super) fn rejection(text: &str, file: &str, vertex_count: usize) -> Option<MeshError> {
    let mut vertices_so_far: usize = 0;
    for (line, statement) in numbered_lines(text) {
        let mut words = statement.split_whitespace();
        match words.next() {
            Some("v") => {
                // tobj parses a coordinate as `f64::from_str`, as here.
                if let Some(bad) = words.take(3).find(|word| word.parse::<f64>().is_err()) {
                    let message = format!("bad vertex coordinate {}", quote(bad));
                    return Some(MeshError::syntax(file, line, message));
                }
                vertices_so_far = vertices_so_far.saturating_add(1);
            }
            Some("f") => {
                let place = || Place::new(file, Location::Line(line));
                for corner in words {
                    let index = corner.split('/').next().unwrap_or_default();
                    match check_index(index, vertices_so_far, vertex_count) {
                        Ok(()) => {}
                        Err(Problem::OutOfRange { vertex_count }) => {
                            return Some(MeshError::IndexOutOfRange {
                                place: place(),
                                index: shorten(index),
                                vertex_count,
                            })
                        }
                        Err(Problem::NotAnInteger) => {
                            return Some(MeshError::Syntax {
                                place: place(),
                                message: format!("bad face index in {}", quote(corner)),
                            })
                        }
                    }
                }
            }
            _ => {}
        }
    }
    None
}

/// The error for the non-finite coordinate `value` of vertex `id` (0-based),
/// placed at its `v` line.
pub(super) fn non_finite(text: &str, file: &str, id: usize, value: f64) -> MeshError {
    let line = numbered_lines(text)
        .filter(|(_, statement)| statement.split_whitespace().next() == Some("v"))
        .nth(id)
        .map(|(line, _)| line);
    let at = line.map_or(Location::Vertex(id), Location::Line);
    MeshError::NonFinite {
        place: Place::new(file, at),
        value,
    }
}

/// What is wrong with a face index.
enum Problem {
    /// It names no vertex; `vertex_count` is how many it could have named.
    OutOfRange {
        vertex_count: usize,
    },
    NotAnInteger,
}

/// Checks a position index as tobj resolves it: `i > 0` is 1-based, `i < 0`
/// counts back from the vertices defined so far; the result must name one of
/// the file's vertices (even one defined later). A decimal too large for
/// `isize` (which tobj fails to parse) is out of range.
fn check_index(index: &str, vertices_so_far: usize, vertex_count: usize) -> Result<(), Problem> {
    let backwards = index.starts_with('-');
    let range = if backwards {
        vertices_so_far
    } else {
        vertex_count
    };
    let out_of_range = Problem::OutOfRange {
        vertex_count: range,
    };
    let Ok(value) = index.parse::<isize>() else {
        let digits = index.strip_prefix(['-', '+']).unwrap_or(index);
        let integer = !digits.is_empty() && digits.bytes().all(|b| b.is_ascii_digit());
        return Err(if integer {
            out_of_range
        } else {
            Problem::NotAnInteger
        });
    };
    // 1-based forward, or counted back from the end; either way 1..=range.
    let distance = value.unsigned_abs();
    if distance == 0 || distance > range {
        return Err(out_of_range);
    }
    Ok(())
}
