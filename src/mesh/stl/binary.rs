//! Binary STL: an 80-byte header, a little-endian u32 triangle count, then
//! 50 bytes per triangle (normal, 3 corners as 3 × f32 each, u16 attribute).

use zerocopy::little_endian::{F32, U16};
use zerocopy::{FromBytes, Immutable, KnownLayout, Unaligned};

use super::{HEADER_LEN, RECORD_LEN};
use crate::mesh::weld::Welder;
use crate::mesh::{Location, MeshError, Place, TriMesh, MAX_TRIANGLES, MAX_VERTICES};

/// One triangle record as stored (little-endian, unaligned).
#[derive(FromBytes, KnownLayout, Immutable, Unaligned)]
#[repr(C)]
struct Record {
    /// Facet normal; ignored (often zero or stale), faces are oriented by their corners.
    _normal: [F32; 3],
    corners: [[F32; 3]; 3],
    /// "Attribute byte count"; ignored.
    _attribute: U16,
}

const _: () = assert!(std::mem::size_of::<Record>() == RECORD_LEN);

/// Byte offset of the first corner inside a record.
const CORNERS_OFFSET: usize = 12;

/// The triangle count of the header, if there is a whole header.
fn header_count(bytes: &[u8]) -> Option<u32> {
    let count = bytes.get(80..HEADER_LEN)?.try_into().ok()?;
    Some(u32::from_le_bytes(count))
}

/// The file length the header's triangle count calls for, if there is a header.
pub(super) fn expected_len(bytes: &[u8]) -> Option<u64> {
    let count = u64::from(header_count(bytes)?);
    count
        .checked_mul(RECORD_LEN as u64)?
        .checked_add(HEADER_LEN as u64)
}

/// Parses a binary STL; the length is checked against the count before
/// anything is allocated for the triangles.
pub(super) fn parse(bytes: &[u8], file: &str) -> Result<TriMesh, MeshError> {
    let length_error = |triangles, expected_len| MeshError::BinaryStlLength {
        file: file.to_owned(),
        triangles,
        expected_len,
        actual_len: bytes.len() as u64,
    };
    let (Some(count), Some(expected)) = (header_count(bytes), expected_len(bytes)) else {
        return Err(length_error(None, HEADER_LEN as u64));
    };
    let records = bytes
        .get(HEADER_LEN..)
        .filter(|_| expected == bytes.len() as u64)
        .and_then(|data| <[Record]>::ref_from_bytes(data).ok())
        .ok_or_else(|| length_error(Some(count), expected))?;
    // The length check bounds the count by the file size; the cap bounds memory.
    if records.len() > MAX_TRIANGLES {
        return Err(MeshError::too_large(
            file,
            "triangles",
            records.len(),
            MAX_TRIANGLES,
        ));
    }
    let mut welder = Welder::with_capacity(records.len());
    for (id, record) in records.iter().enumerate() {
        // Within the file, whose length was checked against the count.
        let record_offset = id.saturating_mul(RECORD_LEN).saturating_add(HEADER_LEN);
        let corners = corners_of(record, record_offset, file)?;
        welder
            .push_triangle(corners)
            .map_err(|_| MeshError::too_large(file, "vertices", MAX_VERTICES + 1, MAX_VERTICES))?;
    }
    let (vertices, faces) = welder.finish();
    TriMesh::validated(file, vertices, faces)
}

/// The corners of `record` (stored at `record_offset`), converted exactly from
/// f32 to f64 and checked to be finite.
fn corners_of(
    record: &Record,
    record_offset: usize,
    file: &str,
) -> Result<[[f64; 3]; 3], MeshError> {
    let mut corners = [[0.0; 3]; 3];
    for (corner, (stored, out)) in record.corners.iter().zip(&mut corners).enumerate() {
        for (axis, (value, coordinate)) in stored.iter().zip(out).enumerate() {
            let value = f64::from(value.get());
            if !value.is_finite() {
                let offset = record_offset
                    .saturating_add(CORNERS_OFFSET)
                    .saturating_add(corner.saturating_mul(12))
                    .saturating_add(axis.saturating_mul(4));
                return Err(MeshError::NonFinite {
                    place: Place::new(file, Location::Byte(offset as u64)),
                    value,
                });
            }
            *coordinate = value;
        }
    }
    Ok(corners)
}
