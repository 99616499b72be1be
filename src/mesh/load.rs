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
    ///
    /// When the extension's format fails to parse and the content is recognisably
    /// another (a binary STL named `.obj`), the error is [`MeshError::Misnamed`],
    /// saying so, instead of the parse's symptom ("no vertices").
    ///
    /// # Errors
    ///
    /// - [`MeshError::Io`] if the file cannot be read.
    /// - [`MeshError::UnknownFormat`] if neither the extension nor the content
    ///   says OBJ or STL.
    /// - [`MeshError::Misnamed`] if the extension's format does not parse and the
    ///   content is another format or binary data.
    /// - Any error of [`TriMesh::from_obj_bytes`] or [`TriMesh::from_stl_bytes`]
    ///   for the content.
    ///
    /// # Examples
    ///
    /// ```
    /// use obbtree::mesh::TriMesh;
    ///
    /// let cow = TriMesh::load(concat!(env!("CARGO_MANIFEST_DIR"), "/assets/cow.obj").as_ref())?;
    /// assert!(cow.faces().len() > 1000);
    /// assert!(TriMesh::load("no/such/file.obj".as_ref()).is_err());
    /// # Ok::<(), obbtree::mesh::MeshError>(())
    /// ```
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
        let parsed = match format {
            Format::Obj => obj::parse(&bytes, &file),
            Format::Stl => stl::parse(&bytes, &file),
        };
        // The extension chose the parser; if it failed, say what the content is
        // instead, when that is something else.
        match (parsed, by_extension) {
            (Err(error), Some(named)) => Err(misnamed(&bytes, named, &file).unwrap_or(error)),
            (parsed, _) => parsed,
        }
    }

    /// Parses Wavefront OBJ text (all objects and groups merged in file order,
    /// polygons fan-triangulated); `name` is the input name used in errors.
    ///
    /// # Errors
    ///
    /// - [`MeshError::Syntax`] for a malformed statement or token (with its line).
    /// - [`MeshError::IndexOutOfRange`] for a face index with no such vertex.
    /// - [`MeshError::NonFinite`] for a NaN, infinite or overflowing coordinate.
    /// - [`MeshError::EmptyMesh`] / [`MeshError::NoFaces`] for no vertices / no faces.
    /// - [`MeshError::TooLarge`] above [`MAX_VERTICES`](super::MAX_VERTICES) or
    ///   [`MAX_TRIANGLES`](super::MAX_TRIANGLES).
    ///
    /// # Examples
    ///
    /// ```
    /// use obbtree::mesh::{MeshError, TriMesh};
    ///
    /// let quad = TriMesh::from_obj_bytes(b"v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nf 1 2 3 4\n", "quad")?;
    /// assert_eq!(quad.faces().len(), 2); // fan-triangulated
    /// let bad = TriMesh::from_obj_bytes(b"v 0 0 0\nf 1 2 3\n", "bad");
    /// assert!(matches!(bad, Err(MeshError::IndexOutOfRange { .. })));
    /// # Ok::<(), MeshError>(())
    /// ```
    pub fn from_obj_bytes(bytes: &[u8], name: &str) -> Result<TriMesh, MeshError> {
        obj::parse(bytes, name)
    }

    /// Parses a binary or ASCII STL (detected from the content) with
    /// bitwise-identical positions merged into shared vertices; `name` is the
    /// input name used in errors.
    ///
    /// # Errors
    ///
    /// - [`MeshError::BinaryStlLength`] for a binary STL whose length disagrees with
    ///   its triangle count.
    /// - [`MeshError::Syntax`] for a malformed ASCII STL statement (with its line).
    /// - [`MeshError::NonFinite`] for a NaN or infinite coordinate.
    /// - [`MeshError::EmptyMesh`] for no triangles.
    /// - [`MeshError::TooLarge`] above [`MAX_VERTICES`](super::MAX_VERTICES) or
    ///   [`MAX_TRIANGLES`](super::MAX_TRIANGLES).
    ///
    /// # Examples
    ///
    /// ```
    /// use obbtree::mesh::TriMesh;
    ///
    /// let stl = b"solid t\nfacet normal 0 0 1\nouter loop\nvertex 0 0 0\nvertex 1 0 0\n\
    ///             vertex 0 1 0\nendloop\nendfacet\nendsolid t\n";
    /// let triangle = TriMesh::from_stl_bytes(stl, "triangle.stl")?;
    /// assert_eq!((triangle.vertices().len(), triangle.faces().len()), (3, 1));
    /// # Ok::<(), obbtree::mesh::MeshError>(())
    /// ```
    pub fn from_stl_bytes(bytes: &[u8], name: &str) -> Result<TriMesh, MeshError> {
        stl::parse(bytes, name)
    }
}

/// The error for a file whose extension names `named` but whose content is
/// recognisably another format or binary data; `None` when the content could be
/// `named` (the parse's own error then says what is wrong).
fn misnamed(bytes: &[u8], named: Format, file: &str) -> Option<MeshError> {
    let (extension, content, rename_to) = match (named, sniff(bytes)) {
        (Format::Obj, Some(Format::Stl)) if stl::has_binary_size(bytes) => {
            ("OBJ", "a binary STL", Some(".stl"))
        }
        (Format::Obj, Some(Format::Stl)) => ("OBJ", "an ASCII STL", Some(".stl")),
        (Format::Obj, None) if bytes.contains(&0) => ("OBJ", "binary data, not text", None),
        (Format::Stl, Some(Format::Obj)) => ("STL", "OBJ text", Some(".obj")),
        _ => return None,
    };
    Some(MeshError::Misnamed {
        file: file.to_owned(),
        extension,
        content,
        rename_to,
    })
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
