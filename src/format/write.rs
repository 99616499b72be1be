//! Laying a built tree out as a `.obbt` image, and writing files atomically.

use super::aligned::AlignedBytes;
use super::layout::{
    align_up, header_crc, Header, SectionEntry, SectionKind, ENTRY_SIZE, FLAG_REQUIRED,
    HEADER_SIZE, SIGNATURE, VERSION_MAJOR, VERSION_MINOR,
};
use super::open::ObbtFile;
use crate::build::{BuildOptions, BuiltTree};
use crate::bv::{BoundingVolume, Node};
use crate::real::{Precision, Real};
use crate::tree::EncodeError;
use rayon::prelude::*;
use std::io::Write;
use std::ops::Range;
use std::path::Path;
use zerocopy::IntoBytes;

/// Serializes a finished tree. The layout is fully determined by the tree and options, so
/// equal inputs give byte-identical images.
///
/// Every section is encoded straight into its place in the (zero-initialised) image, so the
/// image is the only large buffer the writer touches.
///
/// Fails if a node reference does not fit the tree's encoding.
pub(crate) fn serialize<B: BoundingVolume>(
    tree: &BuiltTree<B>,
    options: &BuildOptions,
) -> Result<ObbtFile, EncodeError> {
    let scalar = std::mem::size_of::<B::Real>();
    // (kind, count, stride) in file order; the byte length of each is count * stride.
    let sections = [
        (
            SectionKind::Vertices,
            tree.vertices.len() as u64,
            3 * scalar as u32,
        ),
        (SectionKind::Faces, tree.faces.len() as u64, 12),
        (SectionKind::SourceIds, tree.source_ids.len() as u64, 4),
        (
            SectionKind::Nodes,
            tree.node_count as u64,
            Node::<B>::SIZE as u32,
        ),
    ];

    let header_bytes = HEADER_SIZE + ENTRY_SIZE * sections.len();
    let mut offset = align64(header_bytes as u64);
    let mut ranges = Vec::with_capacity(sections.len());
    for &(_, count, stride) in &sections {
        let length = count * u64::from(stride);
        ranges.push(offset as usize..(offset + length) as usize);
        offset = align64(offset + length);
    }
    let total = offset;
    let mut image = AlignedBytes::zeroed_in_parallel(total as usize);
    let bytes = image.as_mut_bytes();

    let [vertices, faces, ids, nodes] = sections_mut(bytes, &ranges);
    let chunks = vertices.chunks_exact_mut(scalar);
    for (out, v) in chunks.zip(tree.vertices.iter().flatten()) {
        put_real(*v, out);
    }
    for (out, i) in faces.chunks_exact_mut(4).zip(tree.faces.iter().flatten()) {
        out.copy_from_slice(&i.to_le_bytes());
    }
    for (out, i) in ids.chunks_exact_mut(4).zip(&tree.source_ids) {
        out.copy_from_slice(&i.to_le_bytes());
    }
    let nodes_crc = write_nodes(tree, nodes)?;

    let entries: Vec<SectionEntry> = sections
        .iter()
        .zip(&ranges)
        .map(|(&(kind, count, stride), range)| SectionEntry {
            kind: kind.tag().into(),
            flags: FLAG_REQUIRED.into(),
            offset: (range.start as u64).into(),
            length: (range.len() as u64).into(),
            count: count.into(),
            stride: stride.into(),
            crc32: match kind {
                SectionKind::Nodes => nodes_crc,
                _ => crc32fast::hash(&bytes[range.clone()]),
            }
            .into(),
        })
        .collect();
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
        section_count: (sections.len() as u16).into(),
        triangles: (tree.faces.len() as u32).into(),
        vertices: (tree.vertices.len() as u32).into(),
        nodes: (tree.node_count as u32).into(),
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
    Ok(ObbtFile::from_aligned(image).expect("the writer lays out a valid header and directory"))
}

/// Encodes the nodes of `tree` into `out` (exactly their size) and returns its CRC-32.
///
/// The nodes are most of the file: they are encoded in parallel, in runs of at most
/// `CHUNK` nodes (cut at the same places whatever the number of threads), each run's CRC
/// taken while its bytes are still in cache and the CRCs combined in order. The first
/// reference (in node order) that the encoding cannot hold is the error.
fn write_nodes<B: BoundingVolume>(tree: &BuiltTree<B>, out: &mut [u8]) -> Result<u32, EncodeError> {
    const CHUNK: usize = 2048;
    let size = Node::<B>::SIZE;
    // (drafts, their shift, output) of each run, in order.
    let mut runs = Vec::new();
    let mut out = out;
    for piece in &tree.nodes {
        let (drafts, shift) = piece.raw();
        for drafts in drafts.chunks(CHUNK) {
            let (o, rest) = std::mem::take(&mut out).split_at_mut(drafts.len() * size);
            runs.push((drafts, shift, o));
            out = rest;
        }
    }
    let encoding = tree.encoding;
    let hashers: Vec<Result<crc32fast::Hasher, EncodeError>> = runs
        .into_par_iter()
        .map(|(drafts, shift, out)| {
            let mut record = Vec::with_capacity(size);
            for (out, d) in out.chunks_exact_mut(size).zip(drafts) {
                let packed = encoding.encode(d.shifted(shift).refs)?;
                record.clear();
                Node::new(d.bv, packed).write_le(&mut record);
                out.copy_from_slice(&record);
            }
            let mut h = crc32fast::Hasher::new();
            h.update(out);
            Ok(h)
        })
        .collect();
    let mut crc = crc32fast::Hasher::new();
    for h in hashers {
        crc.combine(&h?);
    }
    Ok(crc.finalize())
}

/// The four section slices of `bytes` at the (ascending, disjoint) `ranges`.
fn sections_mut<'a>(bytes: &'a mut [u8], ranges: &[Range<usize>]) -> [&'a mut [u8]; 4] {
    let mut rest = bytes;
    let mut consumed = 0;
    let mut out: [&mut [u8]; 4] = Default::default();
    for (slot, range) in out.iter_mut().zip(ranges) {
        let (_, tail) = std::mem::take(&mut rest).split_at_mut(range.start - consumed);
        let (section, tail) = tail.split_at_mut(range.len());
        *slot = section;
        rest = tail;
        consumed = range.end;
    }
    out
}

/// Writes the little-endian encoding of `x` into `out` (exactly its size).
#[inline]
fn put_real<R: Real>(x: R, out: &mut [u8]) {
    match R::PRECISION {
        // Widening to f64 is exact, so narrowing back gives `x` itself.
        Precision::F32 => out.copy_from_slice(&(x.to_f64() as f32).to_le_bytes()),
        Precision::F64 => out.copy_from_slice(&x.to_f64().to_le_bytes()),
    }
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
