//! Laying a built tree out as a `.obbt` image, and writing files atomically.

use super::aligned::AlignedBytes;
use super::layout::{
    align_up, header_crc, Header, SectionEntry, SectionKind, ENTRY_SIZE, FLAG_REQUIRED,
    HEADER_SIZE, SIGNATURE, VERSION_MAJOR, VERSION_MINOR,
};
use super::open::ObbtFile;
use crate::build::{BuildOptions, BuiltTree};
use crate::bv::BoundingVolume;
use crate::real::Real;
use std::io::Write;
use std::path::Path;
use zerocopy::IntoBytes;

/// Serializes a finished tree. The layout is fully determined by the tree and options, so
/// equal inputs give byte-identical images.
pub(crate) fn serialize<B: BoundingVolume>(
    tree: &BuiltTree<B>,
    options: &BuildOptions,
) -> ObbtFile {
    let mut payloads: Vec<(SectionKind, u64, u32, Vec<u8>)> = Vec::with_capacity(4);
    let mut vertices = Vec::with_capacity(tree.vertices.len() * 3 * std::mem::size_of::<B::Real>());
    for v in tree.vertices.iter().flatten() {
        v.write_le(&mut vertices);
    }
    payloads.push((
        SectionKind::Vertices,
        tree.vertices.len() as u64,
        3 * std::mem::size_of::<B::Real>() as u32,
        vertices,
    ));
    let faces: Vec<u8> = tree
        .faces
        .iter()
        .flatten()
        .flat_map(|i| i.to_le_bytes())
        .collect();
    payloads.push((SectionKind::Faces, tree.faces.len() as u64, 12, faces));
    let ids: Vec<u8> = tree
        .source_ids
        .iter()
        .flat_map(|i| i.to_le_bytes())
        .collect();
    payloads.push((SectionKind::SourceIds, tree.source_ids.len() as u64, 4, ids));
    let mut nodes = Vec::with_capacity(tree.nodes.len() * crate::bv::Node::<B>::SIZE);
    for n in &tree.nodes {
        n.write_le(&mut nodes);
    }
    payloads.push((
        SectionKind::Nodes,
        tree.nodes.len() as u64,
        crate::bv::Node::<B>::SIZE as u32,
        nodes,
    ));

    let header_bytes = HEADER_SIZE + ENTRY_SIZE * payloads.len();
    let mut offset = align64(header_bytes as u64);
    let mut entries = Vec::with_capacity(payloads.len());
    for (kind, count, stride, data) in &payloads {
        entries.push(SectionEntry {
            kind: kind.tag().into(),
            flags: FLAG_REQUIRED.into(),
            offset: offset.into(),
            length: (data.len() as u64).into(),
            count: (*count).into(),
            stride: (*stride).into(),
            crc32: crc32fast::hash(data).into(),
        });
        offset = align64(offset + data.len() as u64);
    }
    let total = offset;
    let mut image = AlignedBytes::zeroed(total as usize);
    let bytes = image.as_mut_bytes();
    for (entry, (_, _, _, data)) in entries.iter().zip(&payloads) {
        let start = entry.offset.get() as usize;
        bytes[start..start + data.len()].copy_from_slice(data);
    }
    let s = &tree.stats;
    let mut header = Header {
        signature: SIGNATURE,
        version_major: VERSION_MAJOR.into(),
        version_minor: VERSION_MINOR.into(),
        header_bytes: (header_bytes as u32).into(),
        file_bytes: total.into(),
        bv_kind: options.bv.tag(),
        precision: options.precision.tag(),
        encoding: tree.encoding.tag(),
        fit_method: options.fit.tag(),
        leaf_size: (options.leaf_size as u16).into(),
        section_count: (payloads.len() as u16).into(),
        triangles: (tree.faces.len() as u32).into(),
        vertices: (tree.vertices.len() as u32).into(),
        nodes: (tree.nodes.len() as u32).into(),
        leaves: s.leaves.into(),
        depth: s.depth.into(),
        degenerate_triangles: s.degenerate_triangles.into(),
        max_leaf_faces: s.max_leaf_faces.into(),
        reserved0: 0.into(),
        bounds_min: s.bounds_min.map(Into::into),
        bounds_max: s.bounds_max.map(Into::into),
        reserved1: [0; 12],
        header_crc: 0.into(),
    };
    let directory: Vec<u8> = entries
        .iter()
        .flat_map(|e| e.as_bytes().iter().copied())
        .collect();
    header.header_crc = header_crc(header.as_bytes(), &directory).into();
    bytes[..HEADER_SIZE].copy_from_slice(header.as_bytes());
    bytes[HEADER_SIZE..header_bytes].copy_from_slice(&directory);
    ObbtFile::from_aligned(image).expect("the writer lays out a valid header and directory")
}

fn align64(n: u64) -> u64 {
    align_up(n).expect("section sizes are bounded by memory")
}

/// Writes `bytes` to `path` atomically: a temporary file in the same directory, flushed to
/// disk, then renamed over `path`, then the directory flushed. On any error the temporary
/// file is removed and `path` is untouched.
pub fn write_atomic(path: &Path, bytes: &[u8]) -> std::io::Result<()> {
    let dir = match path.parent() {
        Some(d) if !d.as_os_str().is_empty() => d.to_path_buf(),
        _ => std::path::PathBuf::from("."),
    };
    let name = path
        .file_name()
        .map(|n| n.to_string_lossy().into_owned())
        .unwrap_or_else(|| "out".into());
    static COUNTER: std::sync::atomic::AtomicU64 = std::sync::atomic::AtomicU64::new(0);
    let unique = COUNTER.fetch_add(1, std::sync::atomic::Ordering::Relaxed);
    let tmp = dir.join(format!(".{name}.{}.{unique}.tmp", std::process::id()));
    let result = (|| {
        let mut f = std::fs::OpenOptions::new()
            .write(true)
            .create_new(true)
            .open(&tmp)?;
        f.write_all(bytes)?;
        f.sync_all()?;
        drop(f);
        std::fs::rename(&tmp, path)?;
        // The rename is durable only once the directory entry is; best effort where
        // directories cannot be opened as files.
        if let Ok(d) = std::fs::File::open(&dir) {
            let _ = d.sync_all();
        }
        Ok(())
    })();
    if result.is_err() {
        let _ = std::fs::remove_file(&tmp);
    }
    result
}
