//! On-disk structures of `.obbt` files, exactly as `formats/obbt.md` specifies them.
//!
//! All integers and floats are little-endian. The header and directory use zerocopy's
//! byte-order types (alignment 1), so they can be read from any offset on any host; the
//! sections are read zero-copy as native types, which is why big-endian hosts are refused.

use crate::placement::Placement;
use crate::real::Precision;
use zerocopy::byteorder::little_endian::{F64, U16, U32, U64};
use zerocopy::{FromBytes, Immutable, IntoBytes, KnownLayout, Unaligned};

/// The first 8 bytes of every file: a high byte (catches 7-bit transfers), the name, CR LF
/// (catches line-ending conversion), ^Z (stops `type` on DOS) and LF, as in PNG.
pub const SIGNATURE: [u8; 8] = [0x89, b'O', b'B', b'T', b'\r', b'\n', 0x1a, b'\n'];
/// Major version written and read: a reader refuses any other major version.
pub const VERSION_MAJOR: u16 = 1;
/// Newest minor version this crate reads and writes: 2 (1.1 added the optional `placement`
/// section, 1.2 the compact node layout). Readers accept any minor version of their major
/// version. Writers write the lowest minor version that defines everything a file holds
/// ([`SectionKind::minor_version`], [`LAYOUT_MINOR_VERSION`]), so a fast-layout file
/// without a placement is a 1.0 file, byte for byte what a 1.0 writer wrote.
pub const VERSION_MINOR: u16 = 2;
/// The minor version that defined the header's `layout` field (and the compact layout): a
/// file in the compact layout is at least this version.
pub const LAYOUT_MINOR_VERSION: u16 = 2;
/// Every section starts at a multiple of this many bytes (a cache line), and the file length
/// is a multiple of it too.
pub const SECTION_ALIGN: u64 = 64;
/// Size of the fixed header, bytes.
pub const HEADER_SIZE: usize = 128;
/// Size of one directory entry, bytes.
pub const ENTRY_SIZE: usize = 40;
/// Cap on the number of directory entries, checked before the directory is read.
pub const MAX_SECTIONS: u16 = 16;
/// Directory flag: a reader that does not know this section's kind must refuse the file.
pub const FLAG_REQUIRED: u32 = 1;

/// Where one field of a record (the header, or a directory entry) lies in the record's
/// bytes. Derived from the record's definition, so that no offset is ever written down twice:
/// `open` names the byte of a bad header field with it, and tools and tests that edit raw
/// files find fields with it ([`Header::AT`], [`SectionEntry::AT`]).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Field {
    /// The field's name, as in the struct and in `formats/obbt.md`.
    pub name: &'static str,
    /// Bytes from the start of the record (for the header, from the start of the file).
    pub offset: usize,
    /// Bytes the field occupies.
    pub width: usize,
}

/// Declares an on-disk record and, from the same field list, `$fields`: a struct with one
/// [`Field`] per field, filled by `offset_of!` and `size_of` as the record's `AT` constant.
/// The field list is written once, so the table cannot drift from the layout.
macro_rules! record {
    (
        $fields:ident;
        $(#[$meta:meta])*
        pub struct $name:ident {
            $( $(#[$field_meta:meta])* pub $field:ident: $ty:ty, )*
        }
    ) => {
        $(#[$meta])*
        pub struct $name {
            $( $(#[$field_meta])* pub $field: $ty, )*
        }

        #[doc = concat!("Where each field of [`", stringify!($name), "`] lies: [`",
            stringify!($name), "::AT`].")]
        #[derive(Clone, Copy, Debug)]
        pub struct $fields {
            $(
                #[doc = concat!("Where `", stringify!($field), "` lies.")]
                pub $field: Field,
            )*
        }

        impl $name {
            /// Where each field lies, computed from this definition.
            pub const AT: $fields = $fields {
                $(
                    $field: Field {
                        name: stringify!($field),
                        offset: std::mem::offset_of!($name, $field),
                        width: std::mem::size_of::<$ty>(),
                    },
                )*
            };
        }
    };
}

record! {
    HeaderFields;
    /// The fixed 128-byte header at offset 0.
    ///
    /// # Memory Layout
    ///
    /// `#[repr(C)]`, alignment 1, 128 bytes; offsets are listed in `formats/obbt.md` § Header
    /// and, computed from this definition, in [`Header::AT`]. `header_crc` is the CRC-32
    /// (IEEE) of bytes `0..124` followed by the whole directory.
    #[derive(Clone, Copy, Debug, FromBytes, IntoBytes, KnownLayout, Immutable, Unaligned)]
    #[repr(C)]
    pub struct Header {
        /// [`SIGNATURE`].
        pub signature: [u8; 8],
        /// [`VERSION_MAJOR`].
        pub version_major: U16,
        /// The lowest minor version that defines every section of the file (0 or 1 from this
        /// writer, see [`VERSION_MINOR`]); readers accept any.
        pub version_minor: U16,
        /// Bytes of header plus directory: `128 + 40 * section_count`.
        pub header_bytes: U32,
        /// Total file length in bytes; must equal the actual length.
        pub file_bytes: U64,
        /// Bounding volume tag: 1 OBB, 2 AABB, 3 sphere.
        pub bv_kind: u8,
        /// Stored scalar size: 4 (f32) or 8 (f64).
        pub precision: u8,
        /// Packed reference encoding: 1 binary, 2 variable branching.
        pub encoding: u8,
        /// Fit method tag: 1 hull, 2 triangles, 3 vertices.
        pub fit_method: u8,
        /// Leaf size the tree was built with (1 to 128).
        pub leaf_size: U16,
        /// Number of directory entries (1 to [`MAX_SECTIONS`]).
        pub section_count: U16,
        /// Number of triangles (faces), at least 1.
        pub triangles: U32,
        /// Number of vertices, at least 1.
        pub vertices: U32,
        /// Number of nodes, at least 1.
        pub nodes: U32,
        /// Number of leaf nodes.
        pub leaves: U32,
        /// Nodes on the longest root-to-leaf path.
        pub depth: U32,
        /// Zero-area triangles as stored.
        pub degenerate_triangles: U32,
        /// Most faces in one leaf.
        pub max_leaf_faces: U32,
        /// Node layout tag (1.2): 0 fast, 1 compact; 0 in older files.
        pub layout: u8,
        /// Zero.
        pub reserved0: [u8; 3],
        /// Componentwise minimum of the stored vertices.
        pub bounds_min: [F64; 3],
        /// Componentwise maximum of the stored vertices.
        pub bounds_max: [F64; 3],
        /// Zero.
        pub reserved1: [u8; 12],
        /// CRC-32 of bytes `0..124` and the directory.
        pub header_crc: U32,
    }
}

record! {
    EntryFields;
    /// One directory entry; the directory follows the header immediately.
    ///
    /// # Memory Layout
    ///
    /// `#[repr(C)]`, alignment 1, 40 bytes: kind, flags, offset, length, count, stride, crc32
    /// (offsets in [`SectionEntry::AT`]).
    #[derive(Clone, Copy, Debug, FromBytes, IntoBytes, KnownLayout, Immutable, Unaligned)]
    #[repr(C)]
    pub struct SectionEntry {
        /// What the section holds; see [`SectionKind`].
        pub kind: U32,
        /// Bit 0: [`FLAG_REQUIRED`]; other bits zero.
        pub flags: U32,
        /// Byte offset from the start of the file, a multiple of [`SECTION_ALIGN`].
        pub offset: U64,
        /// Byte length: `count * stride`.
        pub length: U64,
        /// Number of records.
        pub count: U64,
        /// Bytes per record.
        pub stride: U32,
        /// CRC-32 (IEEE) of the section's `length` bytes.
        pub crc32: U32,
    }
}

const _: () = {
    assert!(std::mem::size_of::<Header>() == HEADER_SIZE);
    assert!(std::mem::size_of::<SectionEntry>() == ENTRY_SIZE);
};

/// The placement record of the optional `placement` section (format 1.1): how the stored
/// coordinates were made from the input mesh's, `stored = scale · input + offset`.
///
/// # Memory Layout
///
/// `#[repr(C)]`, alignment 1, 32 bytes: `scale: f64`, `offset: f64[3]`, little-endian
/// (`formats/obbt.md` §5.6).
#[derive(Clone, Copy, Debug, FromBytes, IntoBytes, KnownLayout, Immutable, Unaligned)]
#[repr(C)]
pub struct PlacementRecord {
    /// Stored units per input unit; finite and greater than 0 in a sound file.
    pub scale: F64,
    /// Added after scaling, stored units; finite in a sound file.
    pub offset: [F64; 3],
}

/// Bytes of one [`PlacementRecord`]: the stride of the `placement` section.
pub const PLACEMENT_STRIDE: u32 = 32;

const _: () = assert!(std::mem::size_of::<PlacementRecord>() == PLACEMENT_STRIDE as usize);

impl From<Placement> for PlacementRecord {
    fn from(p: Placement) -> Self {
        PlacementRecord {
            scale: p.scale.into(),
            offset: p.offset.map(Into::into),
        }
    }
}

impl From<PlacementRecord> for Placement {
    fn from(r: PlacementRecord) -> Self {
        Placement {
            scale: r.scale.get(),
            offset: r.offset.map(|v| v.get()),
        }
    }
}

/// The section kinds this version defines: four required ones and, since 1.1, the optional
/// `placement`.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum SectionKind {
    /// Vertex positions: `[R; 3]` per vertex.
    Vertices,
    /// Triangles in leaf order: `[u32; 3]` vertex indices.
    Faces,
    /// Input-mesh triangle id of each leaf-ordered face: `u32`.
    SourceIds,
    /// Tree nodes: volume + packed reference (see `bv::Node`).
    Nodes,
    /// Optional (1.1): one [`PlacementRecord`], written when the placement is not the
    /// identity.
    Placement,
}

impl SectionKind {
    /// The sections every file has, in the order the writer lays them out.
    pub const REQUIRED: [SectionKind; 4] = [
        SectionKind::Vertices,
        SectionKind::Faces,
        SectionKind::SourceIds,
        SectionKind::Nodes,
    ];

    /// Every kind this reader knows: the required ones, then the optional ones, in the order
    /// the writer lays them out.
    pub const ALL: [SectionKind; 5] = [
        SectionKind::Vertices,
        SectionKind::Faces,
        SectionKind::SourceIds,
        SectionKind::Nodes,
        SectionKind::Placement,
    ];

    /// The directory tag.
    pub fn tag(self) -> u32 {
        match self {
            SectionKind::Vertices => 1,
            SectionKind::Faces => 2,
            SectionKind::SourceIds => 3,
            SectionKind::Nodes => 4,
            SectionKind::Placement => 5,
        }
    }

    /// Whether every file has this section; writers set the directory's REQUIRED flag
    /// exactly on these.
    pub fn is_required(self) -> bool {
        SectionKind::REQUIRED.contains(&self)
    }

    /// The minor version (of major version 1) that defined this kind.
    pub fn minor_version(self) -> u16 {
        match self {
            SectionKind::Vertices
            | SectionKind::Faces
            | SectionKind::SourceIds
            | SectionKind::Nodes => 0,
            SectionKind::Placement => 1,
        }
    }

    /// Inverse of [`SectionKind::tag`]; `None` for kinds this reader does not know.
    pub fn from_tag(tag: u32) -> Option<SectionKind> {
        SectionKind::ALL.into_iter().find(|k| k.tag() == tag)
    }

    /// The name used in messages and `info`.
    pub fn name(self) -> &'static str {
        match self {
            SectionKind::Vertices => "vertices",
            SectionKind::Faces => "faces",
            SectionKind::SourceIds => "source_ids",
            SectionKind::Nodes => "nodes",
            SectionKind::Placement => "placement",
        }
    }
}

/// The stride of one vertex record in bytes: three scalars of `precision` (whose tag is a
/// scalar's size in bytes), 12 or 24.
pub(crate) fn vertex_stride(precision: Precision) -> u32 {
    u32::from(precision.tag()).saturating_mul(3)
}

/// Rounds `n` up to the next multiple of [`SECTION_ALIGN`], or `None` on overflow.
pub fn align_up(n: u64) -> Option<u64> {
    n.checked_next_multiple_of(SECTION_ALIGN)
}

/// CRC-32 of the header (without its CRC field) followed by the directory.
pub fn header_crc(header_bytes: &[u8], directory: &[u8]) -> u32 {
    let mut h = crc32fast::Hasher::new();
    h.update(
        header_bytes
            .get(..Header::AT.header_crc.offset)
            .unwrap_or(header_bytes),
    );
    h.update(directory);
    h.finalize()
}
