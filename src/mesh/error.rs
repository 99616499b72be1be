//! Errors of mesh loading and validation, and where in the input they were found.

use std::fmt;

/// Where inside an input an error was found.
///
/// Vertex and face numbers are 0-based ids of the mesh being built (the ids
/// [`TriMesh::vertices`](super::TriMesh::vertices) and
/// [`TriMesh::faces`](super::TriMesh::faces) would have); lines are 1-based.
#[derive(Clone, Debug, PartialEq, Eq)]
#[non_exhaustive]
pub enum Location {
    /// The input as a whole.
    Whole,
    /// A 1-based line of a text file (OBJ, ASCII STL).
    Line(usize),
    /// A 0-based byte offset into a binary file (binary STL).
    Byte(u64),
    /// A 0-based vertex id of in-memory data given to [`TriMesh::new`](super::TriMesh::new).
    Vertex(usize),
    /// A 0-based face id of in-memory data given to [`TriMesh::new`](super::TriMesh::new).
    Face(usize),
}

/// An input name plus a location inside it; displays as `cow.obj:123`,
/// `pig.stl: byte 84`, `<memory>: face 7`, ...
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Place {
    /// The file name (or the name given to a `from_*_bytes` parser).
    pub file: String,
    /// The position inside that input.
    pub at: Location,
}

impl Place {
    /// A place in input `file`.
    pub(crate) fn new(file: &str, at: Location) -> Place {
        Place {
            file: file.to_owned(),
            at,
        }
    }
}

impl fmt::Display for Place {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let file = &self.file;
        match self.at {
            Location::Whole => write!(f, "{file}"),
            Location::Line(line) => write!(f, "{file}:{line}"),
            Location::Byte(offset) => write!(f, "{file}: byte {offset}"),
            Location::Vertex(id) => write!(f, "{file}: vertex {id}"),
            Location::Face(id) => write!(f, "{file}: face {id}"),
        }
    }
}

/// Why a mesh could not be loaded or built. Each message is one line naming
/// the input and, where there is one, the line or byte offset at fault.
///
/// [`MeshError::Io`]'s message ends with the OS error's text (callers that keep only
/// the message, such as a scene's error lines, show it), so [`source`] does not return
/// that error too: a printer of the whole chain would show it twice. It stays in the
/// variant's `source` field. (thiserror would return a field named `source` from
/// [`source`], hence the hand-written impls.)
///
/// [`source`]: std::error::Error::source
#[derive(Debug)]
#[non_exhaustive]
pub enum MeshError {
    /// The file could not be read (missing, unreadable, a directory, ...).
    Io {
        /// The path as given.
        file: String,
        /// The OS error.
        source: std::io::Error,
    },
    /// The extension is neither `.obj` nor `.stl` and the content looks like neither.
    UnknownFormat {
        /// The path as given.
        file: String,
        /// What was tried.
        reason: String,
    },
    /// The extension names one format, its parse failed, and the content is
    /// recognisably something else (a binary STL named `.obj`, OBJ text named
    /// `.stl`, binary data named `.obj`): the error says what to rename, not the
    /// failed parse's symptom.
    Misnamed {
        /// The path as given.
        file: String,
        /// The format the extension names: `"OBJ"` or `"STL"`.
        extension: &'static str,
        /// What the content is, as a phrase: `"a binary STL"`, `"an ASCII STL"`,
        /// `"OBJ text"` or `"binary data, not text"`.
        content: &'static str,
        /// The remedy: the extension to use, or `None` when the content is no mesh format.
        rename_to: Option<&'static str>,
    },
    /// A malformed statement or token in a text format (OBJ, ASCII STL).
    Syntax {
        /// The input and line.
        place: Place,
        /// What is wrong, quoting the offending token.
        message: String,
    },
    /// A face refers to a vertex that does not exist.
    IndexOutOfRange {
        /// The input and line (OBJ) or face id ([`TriMesh::new`](super::TriMesh::new)).
        place: Place,
        /// The index as written (OBJ: 1-based or negative/relative).
        index: String,
        /// Vertices the index could refer to (for a relative OBJ index: those
        /// defined before its line).
        vertex_count: usize,
    },
    /// A vertex coordinate is NaN or infinite (also: a decimal too large for f64).
    NonFinite {
        /// The input and line, byte offset or vertex id.
        place: Place,
        /// The offending value.
        value: f64,
    },
    /// The mesh has no vertices (e.g. an empty file).
    EmptyMesh {
        /// The input name.
        file: String,
    },
    /// The mesh has vertices but no faces.
    NoFaces {
        /// The input name.
        file: String,
        /// How many vertices there were.
        vertex_count: usize,
    },
    /// A binary STL whose length disagrees with its triangle count (truncated,
    /// trailing data, or too short for the 84-byte header).
    BinaryStlLength {
        /// The input name.
        file: String,
        /// The triangle count of the header (`None`: no complete header).
        triangles: Option<u32>,
        /// Bytes that count needs: 84 + 50 × triangles (84 without a header).
        expected_len: u64,
        /// Bytes present.
        actual_len: u64,
    },
    /// A count above the crate's caps ([`MAX_VERTICES`](super::MAX_VERTICES),
    /// [`MAX_TRIANGLES`](super::MAX_TRIANGLES)).
    TooLarge {
        /// The input name.
        file: String,
        /// `"vertices"` or `"triangles"`.
        what: &'static str,
        /// The count found (or reached when loading stopped).
        count: u64,
        /// The cap.
        limit: u64,
    },
}

impl fmt::Display for MeshError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            MeshError::Io { file, source } => write!(f, "{file}: cannot read: {source}"),
            MeshError::UnknownFormat { file, reason } => {
                write!(f, "{file}: unknown mesh format: {reason}")
            }
            MeshError::Misnamed {
                file,
                extension,
                content,
                rename_to,
            } => {
                write!(
                    f,
                    "{file}: not an {extension} file: the content is {content}"
                )?;
                match rename_to {
                    Some(ext) => write!(f, "; name it {ext}"),
                    None => Ok(()),
                }
            }
            MeshError::Syntax { place, message } => write!(f, "{place}: {message}"),
            MeshError::IndexOutOfRange {
                place,
                index,
                vertex_count,
            } => write!(
                f,
                "{place}: face index {index} out of range ({vertex_count} vertices)"
            ),
            MeshError::NonFinite { place, value } => {
                write!(f, "{place}: non-finite vertex coordinate {value}")
            }
            MeshError::EmptyMesh { file } => write!(f, "{file}: empty mesh (no vertices)"),
            MeshError::NoFaces { file, vertex_count } => write!(
                f,
                "{file}: no faces ({vertex_count} vertices but not a single triangle)"
            ),
            MeshError::BinaryStlLength {
                file,
                triangles,
                expected_len,
                actual_len,
            } => {
                let why = describe_stl_length(*triangles, *expected_len, *actual_len);
                write!(f, "{file}: {why}")
            }
            MeshError::TooLarge {
                file,
                what,
                count,
                limit,
            } => write!(f, "{file}: too many {what}: {count} (limit {limit})"),
        }
    }
}

/// No `source()`: every cause's text is in the message (see [`MeshError`]).
impl std::error::Error for MeshError {}

/// The explanation of a [`MeshError::BinaryStlLength`].
fn describe_stl_length(triangles: Option<u32>, expected: u64, actual: u64) -> String {
    let Some(count) = triangles else {
        return format!(
            "not an STL file: {actual} bytes, shorter than the 84-byte binary header, \
             and no ASCII 'solid' start"
        );
    };
    if actual < expected {
        format!(
            "truncated binary STL: header declares {count} triangles ({expected} bytes) \
             but the data ends at byte {actual}"
        )
    } else {
        format!(
            "inconsistent binary STL: header declares {count} triangles ({expected} bytes) \
             but the file has {actual} bytes (not ASCII STL either: no 'solid' start, or NUL bytes)"
        )
    }
}

impl MeshError {
    /// A [`MeshError::Syntax`] at `line` of `file`.
    pub(crate) fn syntax(file: &str, line: usize, message: String) -> MeshError {
        MeshError::Syntax {
            place: Place::new(file, Location::Line(line)),
            message,
        }
    }

    /// A [`MeshError::TooLarge`] for `what` (`"vertices"` / `"triangles"`).
    pub(crate) fn too_large(
        file: &str,
        what: &'static str,
        count: usize,
        limit: usize,
    ) -> MeshError {
        MeshError::TooLarge {
            file: file.to_owned(),
            what,
            count: count as u64,
            limit: limit as u64,
        }
    }
}

/// `token` cut to a sane length, so a message stays one short line even when
/// the token is a thousand digits or binary garbage.
pub(crate) fn shorten(token: &str) -> String {
    const MAX_CHARS: usize = 40;
    let mut cut: String = token.chars().take(MAX_CHARS).collect();
    if cut.len() < token.len() {
        cut.push('…');
    }
    cut
}

/// `token` shortened and quoted (with control characters escaped).
pub(crate) fn quote(token: &str) -> String {
    format!("{:?}", shorten(token))
}
