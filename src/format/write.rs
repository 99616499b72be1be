//! Laying a built tree out as a `.obbt` image, and writing files atomically.

use super::aligned::AlignedBytes;
use super::layout::{
    align_up, header_crc, vertex_stride, Header, PlacementRecord, SectionEntry, SectionKind,
    ENTRY_SIZE, FLAG_REQUIRED, HEADER_SIZE, LAYOUT_MINOR_VERSION, PLACEMENT_STRIDE, SIGNATURE,
    VERSION_MAJOR,
};
use super::open::ObbtFile;
use crate::bv::{BoundingVolume, Layout, Node};
use crate::fit::FitMethod;
use crate::placement::Placement;
use crate::real::{Precision, Real};
use crate::stats::{TreeShape, TreeStats};
use crate::tree::{Draft, EncodeError, Encoding};
use rayon::prelude::*;
use std::io::Write;
use std::ops::Range;
use std::path::{Path, PathBuf};
use std::sync::{Mutex, MutexGuard, PoisonError};
use zerocopy::IntoBytes;

/// Number of required sections, laid out first.
const REQUIRED: usize = SectionKind::REQUIRED.len();

/// A finished tree, as the writer takes it: the contents of every section and the header
/// fields that a build decides. The volume type and precision are `B`'s; everything else
/// in the header (counts, version, layout, checksums) the writer derives.
pub(crate) struct TreeImage<'a, B: BoundingVolume> {
    /// Stored vertices (stored frame), in input order.
    pub vertices: &'a [[B::Real; 3]],
    /// Faces in leaf order, as vertex indices.
    pub faces: &'a [[u32; 3]],
    /// The input id of each leaf-ordered face.
    pub source_ids: &'a [u32],
    /// The node array (node 0 the root), as consecutive runs.
    pub nodes: Vec<NodeRun<'a, B>>,
    /// The fit method the volumes were made with (informative).
    pub fit: FitMethod,
    /// The most faces a leaf was allowed, 1 to 128.
    pub leaf_size: u16,
    /// The header's statistics; `stats.shape` also decides the encoding.
    pub stats: TreeStats,
    /// How the stored vertices were made from the input's; written only when it is not the
    /// identity.
    pub placement: Placement,
}

/// A run of consecutive nodes of the node array: `drafts`, whose child indices become final
/// once `shift` is added. A builder places subtrees built apart this way, without copying
/// them.
pub(crate) struct NodeRun<'a, B> {
    /// The nodes, child indices `shift` short of their final value.
    pub drafts: &'a [Draft<B>],
    /// What to add to every child index of the run.
    pub shift: u32,
}

/// Why a tree could not be laid out as an image.
#[derive(Debug, thiserror::Error)]
pub(crate) enum WriteError {
    /// A node reference does not fit the tree's encoding: the model is too large for it.
    #[error(transparent)]
    Encode(#[from] EncodeError),
    /// The image is larger than this platform can address (32-bit hosts), or (a bug) the
    /// header written fails the reader's checks.
    #[error("{0}")]
    Image(String),
}

/// The error for a size this platform cannot address, or a count the format cannot hold.
fn too_large(what: &str) -> WriteError {
    WriteError::Image(format!(
        "{what} exceeds this platform's or the format's limits"
    ))
}

/// The encoding this writer uses for a tree of `shape` (`formats/obbt.md` §5.5): binary
/// exactly when every leaf holds one face. Every internal node of a built tree has two
/// children, so single-face leaves make a binary tree; an empty mesh is one leaf of no
/// faces, which only the variable encoding holds.
fn encoding_for(shape: TreeShape) -> Encoding {
    if shape.max_leaf_faces == 1 {
        Encoding::Binary
    } else {
        Encoding::Variable
    }
}

/// Serializes a finished tree. The layout is fully determined by the tree, so equal inputs
/// give byte-identical images.
///
/// Every section is encoded straight into its place in the (zero-initialised) image, so the
/// image is the only large buffer the writer touches.
///
/// Fails if a node reference does not fit the tree's encoding, or the image does not fit
/// this platform's address space.
pub(crate) fn serialize<B: BoundingVolume>(tree: &TreeImage<B>) -> Result<ObbtFile, WriteError> {
    let scalar = std::mem::size_of::<B::Real>();
    let encoding = encoding_for(tree.stats.shape);
    let node_count = tree
        .nodes
        .iter()
        .try_fold(0usize, |n, run| n.checked_add(run.drafts.len()))
        .ok_or_else(|| too_large("the node count"))?;
    // The optional placement record, written only when it says something.
    let placement = (!tree.placement.is_identity()).then(|| PlacementRecord::from(tree.placement));
    // (kind, count, stride) in file order; the byte length of each is count * stride.
    let mut sections = vec![
        (
            SectionKind::Vertices,
            tree.vertices.len() as u64,
            vertex_stride(<B::Real as Real>::PRECISION),
        ),
        (SectionKind::Faces, tree.faces.len() as u64, 12),
        (SectionKind::SourceIds, tree.source_ids.len() as u64, 4),
        (
            SectionKind::Nodes,
            node_count as u64,
            u32::try_from(Node::<B>::SIZE).map_err(|_| too_large("the node size"))?,
        ),
    ];
    if placement.is_some() {
        sections.push((SectionKind::Placement, 1, PLACEMENT_STRIDE));
    }
    let header_bytes = ENTRY_SIZE
        .checked_mul(sections.len())
        .and_then(|directory| directory.checked_add(HEADER_SIZE))
        .ok_or_else(|| too_large("the header"))?;

    // Sizes come from the mesh, so every step is checked: on a 32-bit host a large mesh
    // can exceed the address space.
    let mut offset = align_up(header_bytes as u64).ok_or_else(|| too_large("the header"))?;
    let mut ranges: Vec<Range<usize>> = Vec::with_capacity(sections.len());
    for &(kind, count, stride) in &sections {
        let end = count
            .checked_mul(u64::from(stride))
            .and_then(|length| offset.checked_add(length));
        let (Ok(start), Some(Ok(end))) = (usize::try_from(offset), end.map(usize::try_from)) else {
            return Err(too_large(kind.name()));
        };
        ranges.push(start..end);
        offset = align_up(end as u64).ok_or_else(|| too_large(kind.name()))?;
    }
    let total = offset;
    let len = usize::try_from(total)
        .ok()
        .filter(|&n| isize::try_from(n).is_ok())
        .ok_or_else(|| too_large("the image"))?;
    let mut image = AlignedBytes::zeroed_in_parallel(len);
    let bytes = image.as_mut_bytes();

    let layout_error = || WriteError::Image("sections out of bounds".into());
    let required: [Range<usize>; REQUIRED] = ranges
        .get(..REQUIRED)
        .and_then(|r| r.to_vec().try_into().ok())
        .ok_or_else(layout_error)?;
    let [vertices, faces, ids, nodes] = bytes
        .get_disjoint_mut(required)
        .map_err(|_| layout_error())?;
    let chunks = vertices.chunks_exact_mut(scalar);
    for (out, v) in chunks.zip(tree.vertices.iter().flatten()) {
        put_real(*v, out);
    }
    for (out, i) in faces.chunks_exact_mut(4).zip(tree.faces.iter().flatten()) {
        out.copy_from_slice(&i.to_le_bytes());
    }
    for (out, i) in ids.chunks_exact_mut(4).zip(tree.source_ids) {
        out.copy_from_slice(&i.to_le_bytes());
    }
    let mut crcs = vec![
        crc32fast::hash(vertices),
        crc32fast::hash(faces),
        crc32fast::hash(ids),
        write_nodes(&tree.nodes, encoding, nodes)?,
    ];
    if let Some(record) = placement {
        let out = ranges
            .get(REQUIRED)
            .and_then(|range| bytes.get_mut(range.clone()))
            .ok_or_else(layout_error)?;
        out.copy_from_slice(record.as_bytes());
        crcs.push(crc32fast::hash(out));
    }

    let entries: Vec<SectionEntry> = sections
        .iter()
        .zip(&ranges)
        .zip(crcs)
        .map(|((&(kind, count, stride), range), crc)| SectionEntry {
            kind: kind.tag().into(),
            flags: if kind.is_required() { FLAG_REQUIRED } else { 0 }.into(),
            offset: (range.start as u64).into(),
            length: (range.len() as u64).into(),
            count: count.into(),
            stride: stride.into(),
            crc32: crc.into(),
        })
        .collect();
    let s = &tree.stats;
    // The builder checked these counts against the format's limits; a failure here is a
    // count the format cannot hold.
    let count32 = |n: usize, what: &str| u32::try_from(n).map_err(|_| too_large(what));
    let mut header = Header {
        signature: SIGNATURE,
        version_major: VERSION_MAJOR.into(),
        // The lowest minor version that defines every section and the layout written.
        version_minor: sections
            .iter()
            .map(|&(kind, ..)| kind.minor_version())
            .chain((B::NODE_LAYOUT != Layout::Fast).then_some(LAYOUT_MINOR_VERSION))
            .max()
            .unwrap_or_default()
            .into(),
        header_bytes: count32(header_bytes, "the header")?.into(),
        file_bytes: total.into(),
        bv_kind: B::KIND.tag(),
        precision: <B::Real as Real>::PRECISION.tag(),
        encoding: encoding.tag(),
        fit_method: tree.fit.tag(),
        leaf_size: tree.leaf_size.into(),
        section_count: u16::try_from(sections.len())
            .map_err(|_| too_large("the section count"))?
            .into(),
        triangles: count32(tree.faces.len(), "the triangle count")?.into(),
        vertices: count32(tree.vertices.len(), "the vertex count")?.into(),
        nodes: count32(node_count, "the node count")?.into(),
        leaves: s.shape.leaves.into(),
        depth: s.shape.depth.into(),
        degenerate_triangles: s.degenerate_triangles.into(),
        max_leaf_faces: s.shape.max_leaf_faces.into(),
        layout: B::NODE_LAYOUT.tag(),
        reserved0: [0; 3],
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
    let mut head = header.as_bytes().to_vec();
    head.extend_from_slice(&directory);
    bytes
        .get_mut(..head.len())
        .ok_or_else(layout_error)?
        .copy_from_slice(&head);
    // The reader's O(1) checks double as a check of the writer.
    ObbtFile::from_aligned(image)
        .map_err(|e| WriteError::Image(format!("the written header fails its own checks: {e}")))
}

/// Encodes the node runs `nodes` into `out` (exactly their size) and returns its CRC-32.
///
/// The nodes are most of the file: they are encoded in parallel, in runs of at most
/// `CHUNK` nodes (cut at the same places whatever the number of threads), each run's CRC
/// taken while its bytes are still in cache and the CRCs combined in order. The first
/// reference (in node order) that the encoding cannot hold is the error.
fn write_nodes<B: BoundingVolume>(
    nodes: &[NodeRun<'_, B>],
    encoding: Encoding,
    out: &mut [u8],
) -> Result<u32, WriteError> {
    const CHUNK: usize = 2048;
    let size = Node::<B>::SIZE;
    // (drafts, their shift, output) of each run, in order.
    let mut runs = Vec::new();
    let mut out = out;
    for &NodeRun { drafts, shift } in nodes {
        for drafts in drafts.chunks(CHUNK) {
            let Some((o, rest)) =
                std::mem::take(&mut out).split_at_mut_checked(drafts.len().saturating_mul(size))
            else {
                return Err(WriteError::Image(
                    "more nodes than the node section holds".into(),
                ));
            };
            runs.push((drafts, shift, o));
            out = rest;
        }
    }
    let hashers: Vec<Result<crc32fast::Hasher, WriteError>> = runs
        .into_par_iter()
        .map(|(drafts, shift, out)| {
            for (out, d) in out.chunks_exact_mut(size).zip(drafts) {
                let packed = encoding.encode(d.shifted(shift).refs)?;
                Node::new(d.bv, packed).write_le(out);
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

/// Writes the little-endian encoding of `x` into `out` (exactly its size).
#[inline]
fn put_real<R: Real>(x: R, out: &mut [u8]) {
    match R::PRECISION {
        // Widening to f64 is exact, so narrowing back gives `x` itself.
        Precision::F32 => out.copy_from_slice(&f32::from_f64_nearest(x.to_f64()).to_le_bytes()),
        Precision::F64 => out.copy_from_slice(&x.to_f64().to_le_bytes()),
    }
}

/// Temporary files this process is writing right now, and whether writes were abandoned:
/// the bookkeeping behind [`abandon_writes`].
struct InFlight {
    abandoned: bool,
    paths: Vec<PathBuf>,
}

static IN_FLIGHT: Mutex<InFlight> = Mutex::new(InFlight {
    abandoned: false,
    paths: Vec::new(),
});

/// The registry, whatever a panicking holder left (its contents stay meaningful).
fn in_flight() -> MutexGuard<'static, InFlight> {
    IN_FLIGHT.lock().unwrap_or_else(PoisonError::into_inner)
}

fn interrupted() -> std::io::Error {
    std::io::Error::new(
        std::io::ErrorKind::Interrupted,
        "the write was abandoned (interrupted)",
    )
}

/// Removes every temporary file that [`write_atomic`] is writing in this process and makes
/// all later and unfinished writes fail without touching their destination.
///
/// For a program about to exit on a signal (the `obbtree` command calls it from its Ctrl-C
/// handler, then exits): no temporary file is left behind, and no destination is replaced
/// after this returns. A write that had already renamed its file into place has finished
/// and stays.
pub fn abandon_writes() {
    let mut flight = in_flight();
    flight.abandoned = true;
    for path in flight.paths.drain(..) {
        let _ = std::fs::remove_file(path);
    }
}

/// The temporary name of a write to `path` by this process: `.NAME.PID.N.tmp` in the same
/// directory (the one place the pattern is written; [`remove_stale_temporaries`] parses it).
fn temporary_name(name: &str, pid: u32, unique: u64) -> String {
    format!(".{name}.{pid}.{unique}.tmp")
}

/// The directory and file name of `path` (`.` and `out` when they are missing).
fn split(path: &Path) -> (PathBuf, String) {
    let dir = match path.parent() {
        Some(d) if !d.as_os_str().is_empty() => d.to_path_buf(),
        _ => PathBuf::from("."),
    };
    let name = path
        .file_name()
        .map(|n| n.to_string_lossy().into_owned())
        .unwrap_or_else(|| "out".into());
    (dir, name)
}

/// Removes the temporary files of writes to `path` whose process no longer runs (killed
/// before it could clean up: `SIGKILL`, a power cut), and returns how many it removed.
///
/// Only files named as [`write_atomic`] names them for `path` are considered, and only on
/// systems where a process's liveness can be checked (Linux, through `/proc`); elsewhere
/// nothing is removed.
///
/// # Errors
///
/// The [`std::io::Error`] of listing `path`'s directory (for example, it does not exist).
/// A stale temporary that cannot be removed is skipped, not an error.
pub fn remove_stale_temporaries(path: &Path) -> std::io::Result<usize> {
    let proc_dir = Path::new("/proc/self");
    if !proc_dir.exists() {
        return Ok(0);
    }
    let (dir, name) = split(path);
    let prefix = format!(".{name}.");
    let mut removed: usize = 0;
    for entry in std::fs::read_dir(&dir)? {
        let entry = entry?;
        let file_name = entry.file_name();
        let Some(rest) = file_name
            .to_str()
            .and_then(|n| n.strip_prefix(&prefix))
            .and_then(|n| n.strip_suffix(".tmp"))
        else {
            continue;
        };
        let Some((pid, unique)) = rest.split_once('.') else {
            continue;
        };
        let (Ok(pid), Ok(unique)) = (pid.parse::<u32>(), unique.parse::<u64>()) else {
            continue;
        };
        // Exactly the name a writer would give it, and its writer is gone.
        let own = pid == std::process::id();
        if file_name.to_str() == Some(temporary_name(&name, pid, unique).as_str())
            && !own
            && !Path::new(&format!("/proc/{pid}")).exists()
            && std::fs::remove_file(entry.path()).is_ok()
        {
            removed = removed.saturating_add(1);
        }
    }
    Ok(removed)
}

/// Writes `bytes` to `path` atomically: a temporary file in the same directory, flushed to
/// disk, then renamed over `path`, then the directory flushed. On any error the temporary
/// file is removed and `path` is untouched; after [`abandon_writes`] it fails with
/// [`std::io::ErrorKind::Interrupted`], also leaving `path` untouched.
///
/// # Errors
///
/// The [`std::io::Error`] of creating, writing, syncing or renaming the temporary file
/// (for example, the directory does not exist or is not writable), or
/// [`std::io::ErrorKind::Interrupted`] after [`abandon_writes`].
///
/// # Examples
///
/// ```
/// let path = std::env::temp_dir().join(format!("obbtree-doc-write-{}.txt", std::process::id()));
/// obbtree::format::write_atomic(&path, b"old")?;
/// obbtree::format::write_atomic(&path, b"new")?;
/// assert_eq!(std::fs::read(&path)?, b"new");
/// std::fs::remove_file(&path)?;
/// assert!(obbtree::format::write_atomic("no/such/dir/file".as_ref(), b"x").is_err());
/// # Ok::<(), std::io::Error>(())
/// ```
pub fn write_atomic(path: &Path, bytes: &[u8]) -> std::io::Result<()> {
    let (dir, name) = split(path);
    static COUNTER: std::sync::atomic::AtomicU64 = std::sync::atomic::AtomicU64::new(0);
    let unique = COUNTER.fetch_add(1, std::sync::atomic::Ordering::Relaxed);
    let tmp = dir.join(temporary_name(&name, std::process::id(), unique));
    // Created and registered under the lock, so an abandon either sees it or prevents it.
    let mut file = {
        let mut flight = in_flight();
        if flight.abandoned {
            return Err(interrupted());
        }
        let f = std::fs::OpenOptions::new()
            .write(true)
            .create_new(true)
            .open(&tmp)?;
        flight.paths.push(tmp.clone());
        f
    };
    let result = (|| {
        file.write_all(bytes)?;
        file.sync_all()?;
        drop(file);
        // Renamed under the lock: after an abandon no destination is replaced.
        let mut flight = in_flight();
        if flight.abandoned {
            return Err(interrupted());
        }
        let renamed = std::fs::rename(&tmp, path);
        flight.paths.retain(|p| p != &tmp);
        drop(flight);
        renamed?;
        // The rename is durable only once the directory entry is; best effort where
        // directories cannot be opened as files.
        if let Ok(d) = std::fs::File::open(&dir) {
            let _ = d.sync_all();
        }
        Ok(())
    })();
    if result.is_err() {
        let _ = std::fs::remove_file(&tmp);
        in_flight().paths.retain(|p| p != &tmp);
    }
    result
}
