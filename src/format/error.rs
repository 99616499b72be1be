//! What can be wrong with a `.obbt` file, precisely enough to act on.

use std::fmt;
use std::path::PathBuf;

/// A file or buffer that `open` (the O(1) header and directory checks) refuses, or a view of
/// the wrong type.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
#[non_exhaustive]
pub enum FormatError {
    /// Shorter than the fixed header or than the header plus directory it declares.
    #[error("truncated: {len} bytes, but the header needs {needed}")]
    TooShort {
        /// Actual length.
        len: u64,
        /// Bytes needed to read what the header declares.
        needed: u64,
    },
    /// The first 8 bytes are not the `.obbt` signature.
    #[error("not an .obbt file: bad signature at byte 0")]
    BadSignature,
    /// A major version this reader does not implement.
    #[error("unsupported format version {major}.{minor}: this reader reads version 1.x; rebuild the file from its mesh with this obbtree (`obbtree build`), or read it with the obbtree that wrote it")]
    UnsupportedVersion {
        /// Major version found.
        major: u16,
        /// Minor version found.
        minor: u16,
    },
    /// Sections are read as native little-endian numbers.
    #[error(".obbt files can only be read on little-endian hosts")]
    BigEndianHost,
    /// The buffer does not start on a 64-byte boundary (copy it into [`super::AlignedBytes`]).
    #[error("buffer is not aligned to 64 bytes")]
    Misaligned,
    /// The header CRC does not match the header and directory bytes.
    #[error("header checksum mismatch (stored {stored:#010x}, computed {computed:#010x}): header or section directory is corrupt")]
    HeaderChecksum {
        /// CRC stored at byte 124.
        stored: u32,
        /// CRC computed over the header and directory.
        computed: u32,
    },
    /// The file length differs from the declared total.
    #[error("file is {actual} bytes but its header declares {declared} (truncated or padded)")]
    LengthMismatch {
        /// Declared in the header.
        declared: u64,
        /// Actual length.
        actual: u64,
    },
    /// A header field has a value the spec does not allow.
    #[error("header field `{field}` (byte {offset}): {problem}")]
    HeaderField {
        /// Field name, as in the spec.
        field: &'static str,
        /// Byte offset of the field in the file.
        offset: usize,
        /// What is wrong.
        problem: String,
    },
    /// A directory entry is malformed or contradicts the header.
    #[error("section directory entry {index} ({kind}): {problem}")]
    Section {
        /// Entry index in the directory.
        index: usize,
        /// The section name, or `kind N` for unknown kinds.
        kind: String,
        /// What is wrong.
        problem: String,
    },
    /// A section every reader needs is absent.
    #[error("missing required section `{0}`")]
    MissingSection(&'static str),
    /// `view::<B>()` asked for a volume type or precision the file does not store.
    #[error("the tree stores {found} nodes, not {requested}")]
    WrongType {
        /// What the file stores, e.g. `obb f32`.
        found: String,
        /// What was requested.
        requested: String,
    },
}

/// A file that could not be opened: its path and why.
///
/// The message is `path: cause` (`path: cannot read: cause` for the operating system's, as
/// the mesh loaders say), the cause's text included (callers that keep only the message,
/// such as a scene's error lines, show it), so `source()` does not return the cause too:
/// a printer of the whole chain would show it twice. The cause stays in the
/// variant's `source` field. (thiserror would return a field named `source` from
/// `source()`, hence the hand-written impls.)
#[derive(Debug)]
#[non_exhaustive]
pub enum OpenError {
    /// The operating system refused to open or map the file.
    Io {
        /// The file.
        path: PathBuf,
        /// The OS error.
        source: std::io::Error,
    },
    /// The bytes are not a valid `.obbt` header and directory.
    Format {
        /// The file.
        path: PathBuf,
        /// What is wrong.
        source: FormatError,
    },
}

impl fmt::Display for OpenError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            OpenError::Io { path, source } => {
                write!(f, "{}: cannot read: {source}", path.display())
            }
            OpenError::Format { path, source } => write!(f, "{}: {source}", path.display()),
        }
    }
}

/// No `source()`: the cause's text is in the message (see [`OpenError`]).
impl std::error::Error for OpenError {}

/// The first problem the O(n) verification found, with the section (or region) it is in.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
#[error("{region}: {problem}")]
pub struct VerifyError {
    /// Where: `section nodes`, `padding`, `header`, ...
    pub region: String,
    /// What is wrong, with the record index or byte offset.
    pub problem: String,
}

impl VerifyError {
    pub(crate) fn new(region: impl Into<String>, problem: impl Into<String>) -> VerifyError {
        VerifyError {
            region: region.into(),
            problem: problem.into(),
        }
    }
}
