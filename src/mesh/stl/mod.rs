//! STL, binary and ASCII, told apart by content.
//!
//! Rule: a file whose length is exactly 84 + 50 × (its header's triangle
//! count) is binary, even when its 80-byte header begins with "solid" (many
//! exporters write that); otherwise one starting with "solid" (after optional
//! whitespace) and holding no NUL byte is ASCII; anything else is a binary STL
//! whose size is wrong, and is reported as such. The NUL test keeps a
//! truncated binary file with a "solid" header from being read as text and
//! failing with a confusing syntax error.

mod ascii;
mod binary;

use super::{MeshError, TriMesh};

/// Length of the binary header: 80 free bytes plus the u32 triangle count.
const HEADER_LEN: usize = 84;
/// Length of one binary triangle record: normal, 3 corners, attribute word.
const RECORD_LEN: usize = 50;

/// Parses an STL file of either kind; `file` names it in errors.
pub(crate) fn parse(bytes: &[u8], file: &str) -> Result<TriMesh, MeshError> {
    if !has_binary_size(bytes) && starts_with_solid(bytes) && !bytes.contains(&0) {
        ascii::parse(bytes, file)
    } else {
        binary::parse(bytes, file)
    }
}

/// Whether `bytes` has exactly the length a binary STL with its header's triangle count needs.
pub(crate) fn has_binary_size(bytes: &[u8]) -> bool {
    binary::expected_len(bytes) == Some(bytes.len() as u64)
}

/// Whether `bytes` begins, after optional whitespace, with the ASCII STL keyword "solid".
pub(crate) fn starts_with_solid(bytes: &[u8]) -> bool {
    let start = bytes
        .iter()
        .position(|b| !b.is_ascii_whitespace())
        .unwrap_or(bytes.len());
    bytes
        .get(start..)
        .and_then(|rest| rest.get(..5))
        .is_some_and(|word| word.eq_ignore_ascii_case(b"solid"))
}
