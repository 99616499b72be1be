//! Opening a `.obbt` image: the O(1) header and directory checks, and typed views.

use super::aligned::AlignedBytes;
use super::error::{FormatError, OpenError, VerifyError};
use super::layout::{
    align_up, header_crc, vertex_stride, Field, Header, PlacementRecord, SectionEntry, SectionKind,
    ENTRY_SIZE, FLAG_REQUIRED, HEADER_SIZE, MAX_SECTIONS, PLACEMENT_STRIDE, SECTION_ALIGN,
    SIGNATURE, VERSION_MAJOR,
};
use crate::bv::{
    dispatch, node_type_of, BoundingVolume, BvKind, Layout, Node, NodeType, VolumeVisitor,
};
use crate::fit::FitMethod;
use crate::placement::Placement;
use crate::real::Precision;
use crate::stats::{level_stats, LevelStats, TreeShape, TreeStats};
use crate::tree::{Encoding, NodeDefect, TreeView, VARIABLE_MAX_LEAF_FACES};
use std::any::Any;
use std::ops::Range;
use std::path::Path;
use std::sync::{Arc, Mutex};
use zerocopy::{FromBytes, FromZeros};

/// Where the bytes live. Both are 64-byte aligned and immutable for the file's lifetime.
enum Backing {
    Mapped(memmap2::Mmap),
    Owned(AlignedBytes),
}

impl Backing {
    fn bytes(&self) -> &[u8] {
        match self {
            Backing::Mapped(m) => m,
            Backing::Owned(b) => b.as_bytes(),
        }
    }
}

/// An opened `.obbt` tree: a memory-mapped file or an in-memory image, with its header and
/// directory checked. Cheap to open whatever the size; `Send + Sync`, so one file can serve
/// queries on many threads.
pub struct ObbtFile {
    backing: Backing,
    meta: Meta,
    derived: Derived,
}

/// Data that queries derive from a file's arrays (the ray index), made at first use and
/// kept while the file is open, one value per type: the arrays never change, so neither
/// does what is made of them.
#[derive(Default)]
struct Derived(Mutex<Vec<Arc<dyn Any + Send + Sync>>>);

/// What `open` learned from the header and directory, checked and decoded once; every
/// accessor reads it from here.
struct Meta {
    /// Everything the header and directory say, with the placement record decoded
    /// (identity without one).
    info: Info,
    /// The node type, a combination `NodeType::new` accepts.
    node: NodeType,
    /// Byte ranges of the four required sections, in [`SectionKind::REQUIRED`] order.
    required: [Range<usize>; 4],
}

impl std::fmt::Debug for ObbtFile {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("ObbtFile")
            .field("info", &self.meta.info)
            .finish()
    }
}

/// One directory entry, decoded.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct SectionInfo {
    /// The kind tag as stored.
    pub kind_tag: u32,
    /// The kind, if this reader knows it.
    pub kind: Option<SectionKind>,
    /// Directory flags.
    pub flags: u32,
    /// Byte offset in the file.
    pub offset: u64,
    /// Byte length.
    pub length: u64,
    /// Record count.
    pub count: u64,
    /// Bytes per record.
    pub stride: u32,
    /// Stored CRC-32 of the section bytes.
    pub crc32: u32,
}

impl SectionInfo {
    /// The section's name: the kind's name, or `kind N` for an unknown optional kind.
    pub fn name(&self) -> String {
        match self.kind {
            Some(k) => k.name().to_string(),
            None => format!("kind {}", self.kind_tag),
        }
    }
}

/// Everything the header says about a tree; reading it touches no section.
#[derive(Clone, Debug, PartialEq)]
pub struct Info {
    /// Format version (major, minor).
    pub version: (u16, u16),
    /// Bounding volume type.
    pub bv: BvKind,
    /// Stored precision.
    pub precision: Precision,
    /// Node layout (fast before format 1.2).
    pub layout: Layout,
    /// Fit method the tree was built with.
    pub fit: FitMethod,
    /// Packed reference encoding.
    pub encoding: Encoding,
    /// Leaf size the tree was built with.
    pub leaf_size: u32,
    /// Triangle count.
    pub triangles: u32,
    /// Vertex count.
    pub vertices: u32,
    /// Node count.
    pub nodes: u32,
    /// The tree's shape, zero-area triangles and bounds (stored units, see `placement`).
    pub stats: TreeStats,
    /// How the stored coordinates were made from the input mesh's (identity when the file
    /// has no `placement` section).
    pub placement: Placement,
    /// File length in bytes.
    pub file_bytes: u64,
    /// The section directory.
    pub sections: Vec<SectionInfo>,
}

impl Info {
    /// The `obbtree info --json` object: the header's facts under stable field names (the
    /// CLI's and the Python binding's `Tree.info`).
    pub fn to_json(&self) -> serde_json::Value {
        let sections: Vec<_> = self
            .sections
            .iter()
            .map(|s| serde_json::json!({"name": s.name(), "offset": s.offset, "bytes": s.length, "count": s.count, "stride": s.stride}))
            .collect();
        serde_json::json!({
            "version": format!("{}.{}", self.version.0, self.version.1),
            "triangles": self.triangles,
            "vertices": self.vertices,
            "nodes": self.nodes,
            "leaves": self.stats.shape.leaves,
            "depth": self.stats.shape.depth,
            "max_leaf_faces": self.stats.shape.max_leaf_faces,
            "degenerate_triangles": self.stats.degenerate_triangles,
            "bv": self.bv.name(),
            "precision": self.precision.name(),
            "layout": self.layout.name(),
            "fit": self.fit.name(),
            "leaf_size": self.leaf_size,
            "encoding": self.encoding.name(),
            "bounds": {"min": self.stats.bounds_min, "max": self.stats.bounds_max},
            "placement": {"scale": self.placement.scale, "offset": self.placement.offset},
            "file_bytes": self.file_bytes,
            "bytes_per_triangle": self.file_bytes as f64 / f64::from(self.triangles.max(1)),
            "sections": sections,
        })
    }
}

/// Code generic over the volume type, run once on the concrete view of a file (static
/// dispatch: the match on the header tags happens once, not per node).
pub trait TreeVisitor {
    /// What the visit returns.
    type Output;
    /// Called with the file's tree, whatever its volume type and precision.
    fn visit<B: BoundingVolume>(self, tree: TreeView<'_, B>) -> Self::Output;
}

/// The stride of one node record of a given type (at most 128 bytes).
fn node_size(node: NodeType) -> usize {
    struct NodeSize;
    impl VolumeVisitor for NodeSize {
        type Output = usize;
        fn visit<B: BoundingVolume>(self) -> usize {
            Node::<B>::SIZE
        }
    }
    dispatch(node, NodeSize)
}

/// [`SECTION_ALIGN`] as a `usize`, for checking a buffer's address.
const SECTION_ALIGN_BYTES: usize = 64;
const _: () = assert!(SECTION_ALIGN_BYTES as u64 == SECTION_ALIGN);

/// The error for header field `at` (offsets from [`Header::AT`]).
fn field(at: Field, problem: impl Into<String>) -> FormatError {
    FormatError::HeaderField {
        field: at.name,
        offset: at.offset,
        problem: problem.into(),
    }
}

impl ObbtFile {
    /// Memory-maps `path`, checks its header and directory and decodes its placement record
    /// (O(1) in the file size).
    ///
    /// This is the one place obbtree maps files. The map is read-only and private to this
    /// value; every later read goes through checked slices of it. See [`ObbtFile::read`]
    /// for files that may be rewritten in place while open.
    ///
    /// # Errors
    ///
    /// - [`OpenError::Io`] if the file cannot be opened or mapped, or is a directory or
    ///   another non-regular file.
    /// - [`OpenError::Format`] with the [`FormatError`] of the header and directory checks
    ///   (those of [`ObbtFile::from_aligned`]).
    ///
    /// # Examples
    ///
    /// ```
    /// use obbtree::format::{ObbtFile, OpenError};
    ///
    /// let table = ObbtFile::open(concat!(env!("CARGO_MANIFEST_DIR"), "/assets/scenes/table.obbt"))?;
    /// assert!(table.info().triangles > 0);
    /// assert!(matches!(ObbtFile::open("no/such/file.obbt"), Err(OpenError::Io { .. })));
    /// # Ok::<(), OpenError>(())
    /// ```
    pub fn open(path: impl AsRef<Path>) -> Result<ObbtFile, OpenError> {
        let path = path.as_ref();
        let io = |source| OpenError::Io {
            path: path.to_path_buf(),
            source,
        };
        let file = std::fs::File::open(path).map_err(io)?;
        let metadata = file.metadata().map_err(io)?;
        if !metadata.is_file() {
            // Mapping a directory fails with an obscure "No such device".
            let what = if metadata.is_dir() {
                "is a directory, not a .obbt file"
            } else {
                "is not a regular file"
            };
            return Err(io(std::io::Error::new(
                std::io::ErrorKind::InvalidInput,
                what,
            )));
        }
        let len = metadata.len();
        // Mapping an empty file fails on some systems; an empty buffer gets the clearer
        // "truncated" error from the header checks instead.
        let backing = if len == 0 {
            Backing::Owned(AlignedBytes::zeroed(0))
        } else {
            // SAFETY: the map is read-only and never handed out mutably. Undefined behaviour
            // is possible only if another process truncates or rewrites the file while it is
            // mapped; obbtree never does (it writes through a temporary file and an atomic
            // rename, which leaves existing maps intact), and this is the documented contract
            // of opening a file: do not modify it in place while it is open.
            let map = unsafe { memmap2::Mmap::map(&file) }.map_err(io)?;
            Backing::Mapped(map)
        };
        ObbtFile::from_backing(backing).map_err(|source| OpenError::Format {
            path: path.to_path_buf(),
            source,
        })
    }

    /// Reads `path` into memory and checks its header and directory: what
    /// [`ObbtFile::open`] does, on a private copy instead of a map.
    ///
    /// Which to use: `open` costs O(1) whatever the file's size and shares the pages with
    /// every other process that maps the file; it needs the file left alone while it is
    /// open. Replacing it by rename (as `obbtree build` writes) is safe, and the open value
    /// keeps answering from the old file; but a file truncated or rewritten in place while
    /// mapped makes the next read of a lost page raise SIGBUS, which kills the process.
    /// `read` costs a copy of the file and owns it: use it for files your program does not
    /// control (downloads, shared folders, files other programs rewrite in place).
    ///
    /// # Errors
    ///
    /// As [`ObbtFile::open`]: [`OpenError::Io`] if the file cannot be read or is not a
    /// regular file, [`OpenError::Format`] for the header and directory checks.
    ///
    /// # Examples
    ///
    /// ```
    /// use obbtree::format::ObbtFile;
    ///
    /// let path = concat!(env!("CARGO_MANIFEST_DIR"), "/assets/scenes/table.obbt");
    /// let (mapped, copied) = (ObbtFile::open(path)?, ObbtFile::read(path)?);
    /// assert_eq!(mapped.info(), copied.info());
    /// # Ok::<(), obbtree::format::OpenError>(())
    /// ```
    pub fn read(path: impl AsRef<Path>) -> Result<ObbtFile, OpenError> {
        let path = path.as_ref();
        let io = |source| OpenError::Io {
            path: path.to_path_buf(),
            source,
        };
        if std::fs::metadata(path).map_err(io)?.is_dir() {
            return Err(io(std::io::Error::new(
                std::io::ErrorKind::InvalidInput,
                "is a directory, not a .obbt file",
            )));
        }
        let bytes = std::fs::read(path).map_err(io)?;
        ObbtFile::from_aligned(AlignedBytes::copy_from(&bytes)).map_err(|source| {
            OpenError::Format {
                path: path.to_path_buf(),
                source,
            }
        })
    }

    /// Takes an in-memory image (for example a copy of an embedded asset) and checks its
    /// header and directory (O(1)).
    ///
    /// # Errors
    ///
    /// - [`FormatError::TooShort`], [`FormatError::BadSignature`],
    ///   [`FormatError::UnsupportedVersion`], [`FormatError::HeaderChecksum`],
    ///   [`FormatError::LengthMismatch`], [`FormatError::HeaderField`],
    ///   [`FormatError::Section`] or [`FormatError::MissingSection`] for the first header or
    ///   directory check that fails.
    /// - [`FormatError::BigEndianHost`] on a big-endian host.
    ///
    /// # Examples
    ///
    /// ```
    /// use obbtree::format::{AlignedBytes, FormatError, ObbtFile};
    ///
    /// # fn main() -> Result<(), Box<dyn std::error::Error>> {
    /// let bytes = std::fs::read(concat!(env!("CARGO_MANIFEST_DIR"), "/assets/scenes/table.obbt"))?;
    /// let table = ObbtFile::from_aligned(AlignedBytes::copy_from(&bytes))?;
    /// table.verify()?;
    /// let cut = ObbtFile::from_aligned(AlignedBytes::copy_from(&bytes[..100]));
    /// assert!(matches!(cut, Err(FormatError::TooShort { .. })));
    /// # Ok(())
    /// # }
    /// ```
    pub fn from_aligned(bytes: AlignedBytes) -> Result<ObbtFile, FormatError> {
        ObbtFile::from_backing(Backing::Owned(bytes))
    }

    /// All bytes of the image.
    pub fn bytes(&self) -> &[u8] {
        self.backing.bytes()
    }

    /// The raw header, as stored (a copy of the image's first 128 bytes; [`ObbtFile::info`]
    /// has it decoded).
    pub fn header(&self) -> Header {
        // `open` checked that the image starts with a whole header: the zeros are never used.
        Header::read_from_prefix(self.bytes())
            .map(|(header, _)| header)
            .unwrap_or_else(|_| Header::new_zeroed())
    }

    /// The decoded section directory.
    pub fn sections(&self) -> &[SectionInfo] {
        &self.meta.info.sections
    }

    /// The volume type stored.
    pub fn bv_kind(&self) -> BvKind {
        self.meta.info.bv
    }

    /// The stored precision.
    pub fn precision(&self) -> Precision {
        self.meta.info.precision
    }

    /// The node layout stored.
    pub fn layout(&self) -> Layout {
        self.meta.info.layout
    }

    /// What the nodes store: volume, precision and layout, checked on open.
    pub fn node_type(&self) -> NodeType {
        self.meta.node
    }

    /// How the stored coordinates were made from the input mesh's: `stored = scale · input +
    /// offset` ([`Placement::IDENTITY`] when the file has no `placement` section). Decoded on
    /// open, unverified: [`ObbtFile::verify`] checks that it is finite with a scale above 0.
    pub fn placement(&self) -> Placement {
        self.meta.info.placement
    }

    /// What the header says about the tree, with the placement decoded on open (reads no
    /// section).
    ///
    /// # Examples
    ///
    /// ```
    /// use obbtree::format::ObbtFile;
    ///
    /// let table = ObbtFile::open(concat!(env!("CARGO_MANIFEST_DIR"), "/assets/scenes/table.obbt"))?;
    /// let info = table.info();
    /// println!("{} {} tree: {} triangles, {} nodes", info.bv.name(), info.precision.name(), info.triangles, info.nodes);
    /// assert_eq!(info.file_bytes, table.bytes().len() as u64);
    /// # Ok::<(), obbtree::format::OpenError>(())
    /// ```
    pub fn info(&self) -> Info {
        self.meta.info.clone()
    }

    /// The O(n) checks of the spec: section checksums, zero padding, indices in bounds, a
    /// well-formed tree, finite values, a placement with a finite scale above 0, and every
    /// volume containing the vertices below it.
    ///
    /// # Errors
    ///
    /// The first problem found, as a [`VerifyError`] naming the region (a section,
    /// `padding`, `header`, ...) and what is wrong there.
    ///
    /// # Examples
    ///
    /// ```
    /// use obbtree::format::{AlignedBytes, ObbtFile};
    ///
    /// # fn main() -> Result<(), Box<dyn std::error::Error>> {
    /// let table = ObbtFile::open(concat!(env!("CARGO_MANIFEST_DIR"), "/assets/scenes/table.obbt"))?;
    /// table.verify()?;
    ///
    /// // One flipped byte in a section: the O(1) open checks pass, verify does not.
    /// let mut bytes = table.bytes().to_vec();
    /// let section = table.sections().iter().rev().find(|s| s.length > 0).expect("a section");
    /// bytes[section.offset as usize] ^= 0x55;
    /// let damaged = ObbtFile::from_aligned(AlignedBytes::copy_from(&bytes))?;
    /// assert!(damaged.verify().is_err());
    /// # Ok(())
    /// # }
    /// ```
    pub fn verify(&self) -> Result<(), VerifyError> {
        super::verify::verify(self)
    }

    /// The tree's volumes measured level by level, root first ([`LevelStats`]). Reads every
    /// node; a damaged, unverified file gives the first defect met.
    ///
    /// # Errors
    ///
    /// A [`VerifyError`] in region `section nodes` for the first malformed node met (a
    /// reference out of bounds, a cycle, ...), or if the file's volume type cannot be viewed.
    pub fn level_stats(&self) -> Result<Vec<LevelStats>, VerifyError> {
        struct Levels;
        impl TreeVisitor for Levels {
            type Output = Result<Vec<LevelStats>, NodeDefect>;
            fn visit<B: BoundingVolume>(self, tree: TreeView<'_, B>) -> Self::Output {
                level_stats(&tree)
            }
        }
        let nodes = |problem: String| VerifyError::new("section nodes", problem);
        self.visit(Levels)
            .map_err(|e| nodes(e.to_string()))?
            .map_err(|d| nodes(d.to_string()))
    }

    /// Writes the image to `path` atomically (temporary file in the same directory, fsync,
    /// rename): readers see the old file or the new one, never a partial one.
    ///
    /// # Errors
    ///
    /// The [`std::io::Error`] of creating, writing, syncing or renaming the temporary file
    /// (the temporary is removed on failure); see [`write_atomic`](super::write_atomic).
    pub fn write_atomic(&self, path: impl AsRef<Path>) -> std::io::Result<()> {
        super::write::write_atomic(path.as_ref(), self.bytes())
    }

    /// The tree typed as volume `B`; an error if the file stores another node type.
    ///
    /// # Errors
    ///
    /// - [`FormatError::WrongType`] if the file stores another volume type, precision or
    ///   layout ([`ObbtFile::visit`] takes whichever it stores).
    /// - [`FormatError::Section`] if a required section cannot be viewed as records.
    ///
    /// # Examples
    ///
    /// ```
    /// use obbtree::bv::{Obb, Sphere};
    /// use obbtree::format::{FormatError, ObbtFile};
    ///
    /// # fn main() -> Result<(), Box<dyn std::error::Error>> {
    /// let table = ObbtFile::open(concat!(env!("CARGO_MANIFEST_DIR"), "/assets/scenes/table.obbt"))?; // an OBB f32 tree
    /// let tree = table.view::<Obb<f32>>()?;
    /// assert_eq!(tree.faces().len() as u32, table.info().triangles);
    /// assert!(matches!(table.view::<Sphere<f64>>(), Err(FormatError::WrongType { .. })));
    /// # Ok(())
    /// # }
    /// ```
    pub fn view<B: BoundingVolume>(&self) -> Result<TreeView<'_, B>, FormatError> {
        let found = self.node_type();
        let requested = node_type_of::<B>();
        if found != requested {
            return Err(FormatError::WrongType {
                found: found.to_string(),
                requested: requested.to_string(),
            });
        }
        let bytes = self.bytes();
        let problem = |k: usize, kind: SectionKind, p: &str| FormatError::Section {
            index: k,
            kind: kind.name().into(),
            problem: p.into(),
        };
        let [vertices, faces, source_ids, nodes] = SectionKind::REQUIRED;
        let section = |k: usize, kind: SectionKind| {
            self.meta
                .required
                .get(k)
                .and_then(|range| bytes.get(range.clone()))
                .ok_or_else(|| problem(k, kind, "out of bounds"))
        };
        let cast_err = |k, kind| {
            problem(
                k,
                kind,
                "cannot be viewed as records (misaligned or bad length)",
            )
        };
        Ok(TreeView {
            encoding: self.meta.info.encoding,
            vertices: <[[B::Real; 3]]>::ref_from_bytes(section(0, vertices)?)
                .map_err(|_| cast_err(0, vertices))?,
            faces: <[[u32; 3]]>::ref_from_bytes(section(1, faces)?)
                .map_err(|_| cast_err(1, faces))?,
            source_ids: <[u32]>::ref_from_bytes(section(2, source_ids)?)
                .map_err(|_| cast_err(2, source_ids))?,
            nodes: <[Node<B>]>::ref_from_bytes(section(3, nodes)?)
                .map_err(|_| cast_err(3, nodes))?,
        })
    }

    /// Runs `visitor` on the tree with its concrete volume type and precision.
    ///
    /// # Errors
    ///
    /// The [`FormatError`] of [`ObbtFile::view`] for the stored type (a required section
    /// that cannot be viewed as records); the visitor's own result is its `Output`.
    ///
    /// # Examples
    ///
    /// ```
    /// use obbtree::bv::BoundingVolume;
    /// use obbtree::format::{ObbtFile, TreeVisitor};
    /// use obbtree::tree::TreeView;
    ///
    /// /// Counts the nodes, whatever the volume type.
    /// struct NodeCount;
    /// impl TreeVisitor for NodeCount {
    ///     type Output = usize;
    ///     fn visit<B: BoundingVolume>(self, tree: TreeView<'_, B>) -> usize {
    ///         tree.nodes().len()
    ///     }
    /// }
    ///
    /// # fn main() -> Result<(), Box<dyn std::error::Error>> {
    /// let table = ObbtFile::open(concat!(env!("CARGO_MANIFEST_DIR"), "/assets/scenes/table.obbt"))?;
    /// assert_eq!(table.visit(NodeCount)? as u32, table.info().nodes);
    /// # Ok(())
    /// # }
    /// ```
    pub fn visit<V: TreeVisitor>(&self, visitor: V) -> Result<V::Output, FormatError> {
        /// The file's view typed by [`dispatch`], handed to the tree visitor.
        struct Typed<'f, V> {
            file: &'f ObbtFile,
            visitor: V,
        }
        impl<V: TreeVisitor> VolumeVisitor for Typed<'_, V> {
            type Output = Result<V::Output, FormatError>;
            fn visit<B: BoundingVolume>(self) -> Self::Output {
                Ok(self.visitor.visit(self.file.view::<B>()?))
            }
        }
        let file = self;
        dispatch(self.node_type(), Typed { file, visitor })
    }

    fn from_backing(backing: Backing) -> Result<ObbtFile, FormatError> {
        if cfg!(target_endian = "big") {
            return Err(FormatError::BigEndianHost);
        }
        let bytes = backing.bytes();
        if !bytes.as_ptr().addr().is_multiple_of(SECTION_ALIGN_BYTES) {
            return Err(FormatError::Misaligned);
        }
        let meta = check_header(bytes)?;
        Ok(ObbtFile {
            backing,
            meta,
            derived: Derived::default(),
        })
    }

    /// The value of type `T` derived from this file by `make`: made at the first call for
    /// `T` and shared by every later one (concurrent first calls may each make one; one is
    /// kept). An error is returned and nothing kept.
    pub(crate) fn derived<T: Any + Send + Sync, E>(
        &self,
        make: impl FnOnce() -> Result<T, E>,
    ) -> Result<Arc<T>, E> {
        let find = |made: &[Arc<dyn Any + Send + Sync>]| {
            made.iter().find_map(|v| Arc::clone(v).downcast::<T>().ok())
        };
        // (A panic elsewhere while holding the lock leaves the list as valid as before.)
        let lock = || self.derived.0.lock().unwrap_or_else(|p| p.into_inner());
        if let Some(value) = find(&lock()) {
            return Ok(value);
        }
        // Made without the lock, so that other derived data stays available meanwhile.
        let value = Arc::new(make()?);
        let mut made = lock();
        if let Some(first) = find(&made) {
            return Ok(first);
        }
        made.push(Arc::clone(&value) as Arc<dyn Any + Send + Sync>);
        Ok(value)
    }
}

/// The O(1) checks: signature, version, header CRC, declared length, tags and counts, and a
/// directory whose sections are in bounds, aligned, disjoint and consistent with the header.
fn check_header(bytes: &[u8]) -> Result<Meta, FormatError> {
    let len = bytes.len() as u64;
    let at = Header::AT;
    let too_short = |needed: u64| FormatError::TooShort { len, needed };
    let head = bytes
        .get(..HEADER_SIZE)
        .ok_or(too_short(HEADER_SIZE as u64))?;
    let header = Header::read_from_bytes(head).map_err(|_| too_short(HEADER_SIZE as u64))?;
    if header.signature != SIGNATURE {
        return Err(FormatError::BadSignature);
    }
    let (major, minor) = (header.version_major.get(), header.version_minor.get());
    if major != VERSION_MAJOR {
        return Err(FormatError::UnsupportedVersion { major, minor });
    }
    let count = header.section_count.get();
    if count == 0 || count > MAX_SECTIONS {
        return Err(field(
            at.section_count,
            format!("{count} is outside 1..={MAX_SECTIONS}"),
        ));
    }
    // At most 128 + 40 * 16 bytes: `count` was just checked.
    let header_bytes = ENTRY_SIZE
        .saturating_mul(usize::from(count))
        .saturating_add(HEADER_SIZE);
    if header.header_bytes.get() as usize != header_bytes {
        return Err(field(
            at.header_bytes,
            format!(
                "{} but {count} sections need {header_bytes}",
                header.header_bytes.get()
            ),
        ));
    }
    let directory = bytes
        .get(HEADER_SIZE..header_bytes)
        .ok_or(too_short(header_bytes as u64))?;
    let computed = header_crc(head, directory);
    if computed != header.header_crc.get() {
        return Err(FormatError::HeaderChecksum {
            stored: header.header_crc.get(),
            computed,
        });
    }
    if header.file_bytes.get() != len {
        return Err(FormatError::LengthMismatch {
            declared: header.file_bytes.get(),
            actual: len,
        });
    }
    let unknown = |at: Field, tag: u8| field(at, format!("unknown tag {tag}"));
    let bv = BvKind::from_tag(header.bv_kind).ok_or_else(|| unknown(at.bv_kind, header.bv_kind))?;
    let precision = Precision::from_tag(header.precision)
        .ok_or_else(|| unknown(at.precision, header.precision))?;
    let encoding =
        Encoding::from_tag(header.encoding).ok_or_else(|| unknown(at.encoding, header.encoding))?;
    let fit = FitMethod::from_tag(header.fit_method)
        .ok_or_else(|| unknown(at.fit_method, header.fit_method))?;
    let layout =
        Layout::from_tag(header.layout).ok_or_else(|| unknown(at.layout, header.layout))?;
    let node = NodeType::new(bv, precision, layout).map_err(|e| {
        let (bv, precision) = (e.bv.name(), e.precision.name());
        let m = format!("the compact layout exists for obb f32 trees only, not {bv} {precision}");
        field(at.layout, m)
    })?;
    let leaf_size = u32::from(header.leaf_size.get());
    if !(1..=VARIABLE_MAX_LEAF_FACES).contains(&leaf_size) {
        return Err(field(
            at.leaf_size,
            format!("{leaf_size} is outside 1..={VARIABLE_MAX_LEAF_FACES}"),
        ));
    }
    for (count, value) in [
        (at.triangles, header.triangles.get()),
        (at.vertices, header.vertices.get()),
        (at.nodes, header.nodes.get()),
    ] {
        if value == 0 {
            return Err(field(count, "is zero"));
        }
    }
    if header.reserved0 != [0; 3] || header.reserved1 != [0; 12] {
        // One message for both reserved fields, at the first.
        let reserved = Field {
            name: "reserved",
            ..at.reserved0
        };
        return Err(field(reserved, "reserved bytes are not zero"));
    }

    let expected = |kind: SectionKind| -> (u64, u32) {
        match kind {
            SectionKind::Vertices => (u64::from(header.vertices.get()), vertex_stride(precision)),
            SectionKind::Faces => (u64::from(header.triangles.get()), 12),
            SectionKind::SourceIds => (u64::from(header.triangles.get()), 4),
            SectionKind::Nodes => (
                u64::from(header.nodes.get()),
                u32::try_from(node_size(node)).unwrap_or(u32::MAX),
            ),
            SectionKind::Placement => (1, PLACEMENT_STRIDE),
        }
    };
    let data_start = align_up(header_bytes as u64).unwrap_or(u64::MAX);
    let mut sections = Vec::with_capacity(usize::from(count));
    // The byte range of each known kind found, in [`SectionKind::ALL`] order.
    let mut found: [Option<Range<usize>>; SectionKind::ALL.len()] = Default::default();
    let mut placement = Placement::IDENTITY;
    for (index, raw) in directory.chunks_exact(ENTRY_SIZE).enumerate() {
        let e = SectionEntry::read_from_bytes(raw).map_err(|_| too_short(header_bytes as u64))?;
        let info = SectionInfo {
            kind_tag: e.kind.get(),
            kind: SectionKind::from_tag(e.kind.get()),
            flags: e.flags.get(),
            offset: e.offset.get(),
            length: e.length.get(),
            count: e.count.get(),
            stride: e.stride.get(),
            crc32: e.crc32.get(),
        };
        let bad = |problem: String| FormatError::Section {
            index,
            kind: info.name(),
            problem,
        };
        if info.flags & !FLAG_REQUIRED != 0 {
            return Err(bad(format!("unknown flags {:#x}", info.flags)));
        }
        if !info.offset.is_multiple_of(SECTION_ALIGN) || info.offset < data_start {
            return Err(bad(format!(
                "offset {} is not a multiple of {SECTION_ALIGN} at or after the directory's end ({data_start})",
                info.offset
            )));
        }
        let end = info.offset.checked_add(info.length).filter(|&e| e <= len);
        let Some(end) = end else {
            return Err(bad(format!(
                "bytes {}..+{} run past the end of the {len}-byte file",
                info.offset, info.length
            )));
        };
        if info.count.checked_mul(u64::from(info.stride)) != Some(info.length) {
            return Err(bad(format!(
                "count {} x stride {} != length {}",
                info.count, info.stride, info.length
            )));
        }
        match info.kind {
            None if info.flags & FLAG_REQUIRED != 0 => {
                return Err(bad("unknown section kind marked required".into()));
            }
            None => {}
            Some(kind) => {
                let slot = found
                    .iter_mut()
                    .zip(SectionKind::ALL)
                    .find_map(|(slot, k)| (k == kind).then_some(slot))
                    .ok_or_else(|| bad("unknown section kind".into()))?;
                if slot.is_some() {
                    return Err(bad("duplicate section".into()));
                }
                let (want_count, want_stride) = expected(kind);
                if info.count != want_count || info.stride != want_stride {
                    return Err(bad(format!(
                        "{} records of {} bytes, but the header implies {want_count} of {want_stride}",
                        info.count, info.stride
                    )));
                }
                // Both are at most the buffer's length, so they fit a `usize`.
                let (Ok(start), Ok(end)) = (usize::try_from(info.offset), usize::try_from(end))
                else {
                    return Err(bad("out of the address space".into()));
                };
                if kind == SectionKind::Placement {
                    // One 32-byte record (count and stride checked just above): O(1).
                    placement = bytes
                        .get(start..end)
                        .and_then(|record| PlacementRecord::read_from_bytes(record).ok())
                        .map(Placement::from)
                        .ok_or_else(|| bad("cannot be read as a placement record".into()))?;
                }
                *slot = Some(start..end);
            }
        }
        sections.push(info);
    }
    let mut spans: Vec<(u64, u64, usize)> = sections
        .iter()
        .enumerate()
        // Offset + length was checked not to overflow above.
        .map(|(i, s)| (s.offset, s.offset.saturating_add(s.length), i))
        .collect();
    spans.sort_unstable();
    for pair in spans.windows(2) {
        if let [(_, end_a, a), (start_b, _, b)] = pair {
            if start_b < end_a {
                return Err(FormatError::Section {
                    index: *b,
                    kind: sections.get(*b).map(SectionInfo::name).unwrap_or_default(),
                    problem: format!("overlaps section entry {a}"),
                });
            }
        }
    }
    let range_of = |kind: SectionKind| {
        SectionKind::ALL
            .iter()
            .zip(&found)
            .find_map(|(&k, range)| (k == kind).then(|| range.clone()))
            .flatten()
    };
    let mut ranges: [Range<usize>; 4] = Default::default();
    for (range, kind) in ranges.iter_mut().zip(SectionKind::REQUIRED) {
        *range = range_of(kind).ok_or(FormatError::MissingSection(kind.name()))?;
    }
    // `triangles` is at least 1 (checked above), and doubling a `u32` fits a `u64`.
    let binary_nodes = u64::from(header.triangles.get())
        .saturating_mul(2)
        .saturating_sub(1);
    if encoding == Encoding::Binary && u64::from(header.nodes.get()) != binary_nodes {
        return Err(field(
            at.nodes,
            "a binary tree with one face per leaf has 2 x triangles - 1 nodes",
        ));
    }
    let stats = TreeStats {
        shape: TreeShape {
            leaves: header.leaves.get(),
            depth: header.depth.get(),
            max_leaf_faces: header.max_leaf_faces.get(),
        },
        degenerate_triangles: header.degenerate_triangles.get(),
        bounds_min: header.bounds_min.map(|v| v.get()),
        bounds_max: header.bounds_max.map(|v| v.get()),
    };
    let info = Info {
        version: (major, minor),
        bv,
        precision,
        layout,
        fit,
        encoding,
        leaf_size,
        triangles: header.triangles.get(),
        vertices: header.vertices.get(),
        nodes: header.nodes.get(),
        stats,
        placement,
        file_bytes: len,
        sections,
    };
    Ok(Meta {
        info,
        node,
        required: ranges,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::sync::atomic::{AtomicUsize, Ordering};

    #[test]
    fn derived_data_is_made_once_per_type_and_errors_are_not_kept() {
        let path = concat!(env!("CARGO_MANIFEST_DIR"), "/assets/scenes/table.obbt");
        let file = ObbtFile::open(path).expect("opens");
        let made = AtomicUsize::new(0);
        let make = |value: u64| {
            made.fetch_add(1, Ordering::Relaxed);
            Ok::<u64, &str>(value)
        };
        let first = file.derived(|| make(7)).expect("made");
        let again = file.derived(|| make(8)).expect("kept");
        assert!(Arc::ptr_eq(&first, &again));
        assert_eq!((*again, made.load(Ordering::Relaxed)), (7, 1));
        // Another type is another value; a failed make leaves nothing behind.
        assert_eq!(file.derived(|| Err::<u32, _>("no")), Err("no"));
        assert_eq!(file.derived(|| Ok::<u32, &str>(3)).map(|v| *v), Ok(3));
        assert_eq!(*file.derived(|| make(9)).expect("kept"), 7);
    }
}
