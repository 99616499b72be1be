//! Re-sealing a damaged `.obbt` image: every checksum that can be recomputed is, so that the
//! damage gets past the CRCs and reaches the structural checks of `open` and `verify`, and
//! the queries. Shared by the mutation suites (`tests/common/mutate.rs`) and the fuzz harness
//! (`fuzz/harness.rs`, which includes this file by path), so it depends only on `obbtree`
//! and `crc32fast` and never panics, whatever the bytes.

use obbtree::format::layout::{header_crc, Header, SectionEntry, ENTRY_SIZE, HEADER_SIZE};

/// Offset of the header's little-endian u16 section count.
const SECTION_COUNT_AT: usize = Header::AT.section_count.offset;
/// Offsets inside a directory entry of its offset (u64), length (u64) and CRC (u32).
const ENTRY_OFFSET_AT: usize = SectionEntry::AT.offset.offset;
const ENTRY_LENGTH_AT: usize = SectionEntry::AT.length.offset;
const ENTRY_CRC_AT: usize = SectionEntry::AT.crc32.offset;
/// Offset of the header CRC (u32), the header's last field.
const HEADER_CRC_AT: usize = Header::AT.header_crc.offset;

/// Recomputes the CRC of every section whose directory entry and bytes are in bounds, then
/// the header CRC over the header and the declared directory (cut at the end of `bytes`).
/// An image shorter than the header is left as it is.
pub fn seal(bytes: &mut [u8]) {
    let Some(&[lo, hi]) = bytes.get(SECTION_COUNT_AT..SECTION_COUNT_AT + 2) else {
        return;
    };
    if bytes.len() < HEADER_SIZE {
        return;
    }
    let count = usize::from(u16::from_le_bytes([lo, hi]));
    for index in 0..count {
        let entry = HEADER_SIZE + index * ENTRY_SIZE;
        let (Some(offset), Some(length)) = (
            read_u64(bytes, entry + ENTRY_OFFSET_AT),
            read_u64(bytes, entry + ENTRY_LENGTH_AT),
        ) else {
            break;
        };
        let section = usize::try_from(offset).ok().and_then(|start| {
            let end = start.checked_add(usize::try_from(length).ok()?)?;
            bytes.get(start..end)
        });
        if let Some(section) = section {
            let crc = crc32fast::hash(section);
            if let Some(field) = bytes.get_mut(entry + ENTRY_CRC_AT..entry + ENTRY_CRC_AT + 4) {
                field.copy_from_slice(&crc.to_le_bytes());
            }
        }
    }
    let directory_end = (HEADER_SIZE + count * ENTRY_SIZE).min(bytes.len());
    let (head, rest) = bytes.split_at(HEADER_SIZE);
    let crc = header_crc(
        head,
        rest.get(..directory_end - HEADER_SIZE).unwrap_or(rest),
    );
    if let Some(field) = bytes.get_mut(HEADER_CRC_AT..HEADER_SIZE) {
        field.copy_from_slice(&crc.to_le_bytes());
    }
}

/// The little-endian u64 at `at`, if in bounds.
fn read_u64(bytes: &[u8], at: usize) -> Option<u64> {
    let field: [u8; 8] = bytes.get(at..at.checked_add(8)?)?.try_into().ok()?;
    Some(u64::from_le_bytes(field))
}
