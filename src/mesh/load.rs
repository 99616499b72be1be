//! Entry points of the loaders: by path (choosing the format) or on bytes.

use std::path::Path;

use super::{obj, stl, text, MeshError, TriMesh};

/// The mesh file formats the crate reads.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Format {
    Obj,
    Stl,
}

impl TriMesh {
    /// Loads a mesh file. The format comes from the extension (`.obj` / `.stl`,
    /// any case); for another or no extension it is sniffed from the content:
    /// a binary STL by its size rule, an ASCII STL by its leading `solid`, an
    /// OBJ by a `v` statement; anything else is [`MeshError::UnknownFormat`].
    /// Errors name the path as given.
    pub fn load(path: &Path) -> Result<TriMesh, MeshError> {
        let file = path.display().to_string();
        let bytes = std::fs::read(path).map_err(|source| MeshError::Io {
            file: file.clone(),
            source,
        })?;
        let by_extension = path
            .extension()
            .and_then(|ext| ext.to_str())
            .and_then(|ext| match ext.to_ascii_lowercase().as_str() {
                "obj" => Some(Format::Obj),
                "stl" => Some(Format::Stl),
                _ => None,
            });
        let format = match by_extension.or_else(|| sniff(&bytes)) {
            Some(format) => format,
            None => {
                return Err(MeshError::UnknownFormat {
                    file,
                    reason: "the extension is not .obj or .stl, and the content is neither \
                             STL (binary size rule, ASCII 'solid') nor OBJ ('v' lines)"
                        .to_owned(),
                })
            }
        };
        match format {
            Format::Obj => obj::parse(&bytes, &file),
            Format::Stl => stl::parse(&bytes, &file),
        }
    }

    /// Parses Wavefront OBJ text (all objects and groups merged in file order,
    /// polygons fan-triangulated); `name` is the input name used in errors.
    pub fn from_obj_bytes(bytes: &[u8], name: &str) -> Result<TriMesh, MeshError> {
        obj::parse(bytes, name)
    }

    /// Parses a binary or ASCII STL (detected from the content) with
    /// bitwise-identical positions merged into shared vertices; `name` is the
    /// input name used in errors.
    pub fn from_stl_bytes(bytes: &[u8], name: &str) -> Result<TriMesh, MeshError> {
        stl::parse(bytes, name)
    }
}

/// The format `bytes` look like, for files whose extension says nothing.
fn sniff(bytes: &[u8]) -> Option<Format> {
    if stl::has_binary_size(bytes) || stl::starts_with_solid(bytes) {
        return Some(Format::Stl);
    }
    // OBJ is text: a NUL byte rules it out; a vertex statement makes it likely.
    if bytes.contains(&0) {
        return None;
    }
    let text = text::decode(bytes);
    let has_vertex =
        text::numbered_lines(&text).any(|(_, line)| line.split_whitespace().next() == Some("v"));
    has_vertex.then_some(Format::Obj)
}
