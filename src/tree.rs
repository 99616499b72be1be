//! The tree view: typed slices over a tree's bytes, and the only code that encodes and
//! decodes the packed 32-bit node references (dissertation §7.2.2).
//!
//! A tree built in memory and a tree opened from a file are the same [`TreeView`]; queries
//! never know where the bytes came from. Every accessor is checked: a corrupt, unverified
//! file yields `None` (and so an error or a wrong-but-safe answer upstream), never a panic.

// Packed references come from untrusted files: on top of the crate's no-panic lints,
// integer arithmetic must be checked or saturating and narrowing casts must be `try_from`.
#![cfg_attr(
    not(test),
    deny(clippy::arithmetic_side_effects, clippy::cast_possible_truncation)
)]

use crate::bv::{BoundingVolume, Node};
use crate::real::point_to_f64;
use std::ops::Range;

/// How the 32-bit `packed` field of a node is laid out. Chosen by the builder from the
/// tree's shape and recorded in the file header.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Encoding {
    /// Binary tree with one face per leaf. `packed` read as `i32 k`: `k < 0` is an internal
    /// node whose children are nodes `-k` and `-k + 1`; `k >= 0` is a leaf holding face `k`.
    Binary,
    /// Any branching (1 to 64 children) and 1 to 128 faces per leaf. Bit 31 is the leaf flag.
    /// Internal (bit 31 = 0): bits 0..25 first child, bits 25..31 child count − 1.
    /// Leaf (bit 31 = 1): bits 0..24 first face, bits 24..31 face count − 1.
    Variable,
}

/// What a node points at: a run of consecutive child nodes, or a run of consecutive faces.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum NodeRef {
    /// Children are nodes `first .. first + count`.
    Internal {
        /// Index of the first child node.
        first: u32,
        /// Number of children (at least 1).
        count: u32,
    },
    /// Faces are `first .. first + count` (positions in the leaf-ordered face array).
    Leaf {
        /// Index of the first face.
        first: u32,
        /// Number of faces (at least 1).
        count: u32,
    },
}

impl NodeRef {
    /// The referenced range (children or faces), widened so it cannot overflow.
    pub fn range(self) -> Range<u64> {
        let (first, count) = match self {
            NodeRef::Internal { first, count } | NodeRef::Leaf { first, count } => (first, count),
        };
        // Two `u32`s: the sum cannot overflow a `u64`.
        u64::from(first)..u64::from(first).saturating_add(u64::from(count))
    }
}

/// A node before packing: its volume and its reference as a [`NodeRef`]. The builder makes
/// these with indices local to a subtree; the writer moves them into place
/// ([`Draft::shifted`]) and packs them once the tree's [`Encoding`] is known.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Draft<B> {
    /// The node's bounding volume.
    pub bv: B,
    /// The node's children or faces.
    pub refs: NodeRef,
}

impl<B> Draft<B> {
    /// The draft with its child indices moved `by` nodes on (saturating: an index that
    /// large is refused by every encoding).
    pub fn shifted(self, by: u32) -> Draft<B> {
        match self.refs {
            NodeRef::Internal { first, count } => Draft {
                bv: self.bv,
                refs: NodeRef::Internal {
                    first: first.saturating_add(by),
                    count,
                },
            },
            NodeRef::Leaf { .. } => self,
        }
    }
}

/// A node's contents, checked against the arrays it points into ([`TreeView::node_kind`]).
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum NodeKind {
    /// Child nodes, all after the parent and inside the node array.
    Children(Range<u32>),
    /// Leaf-ordered faces, inside the face array.
    Faces(Range<u32>),
}

/// Why a node cannot be used: what a damaged, unverified file can hold.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum NodeDefect {
    /// The node index is past the node array.
    Missing,
    /// The child range runs past the node array or does not lie after its parent.
    BadChildren,
    /// The face range runs past the face array.
    BadFaces,
}

impl NodeDefect {
    /// What is wrong, in a few words.
    pub fn describe(self) -> &'static str {
        match self {
            NodeDefect::Missing => "node index out of bounds",
            NodeDefect::BadChildren => "child reference out of bounds or backwards",
            NodeDefect::BadFaces => "leaf face range out of bounds",
        }
    }
}

impl std::fmt::Display for NodeDefect {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.describe())
    }
}

impl std::error::Error for NodeDefect {}

/// Why a reference cannot be encoded: the model is too large or too wide for the encoding.
#[derive(Clone, Copy, Debug, PartialEq, Eq, thiserror::Error)]
pub enum EncodeError {
    /// The first child or face index exceeds the encoding's field.
    #[error("{what} index {index} exceeds the {encoding:?} encoding's limit of {limit}")]
    IndexTooLarge {
        /// "child" or "face".
        what: &'static str,
        /// The index that did not fit.
        index: u32,
        /// The largest index the field holds.
        limit: u32,
        /// The encoding that refused it.
        encoding: Encoding,
    },
    /// The number of children or faces does not fit (or is zero, or is not 2 / 1 in the
    /// binary encoding).
    #[error("{count} {what} in one node is not representable in the {encoding:?} encoding (allowed: {allowed})")]
    BadCount {
        /// "children" or "faces".
        what: &'static str,
        /// The count that did not fit.
        count: u32,
        /// What the encoding accepts.
        allowed: &'static str,
        /// The encoding that refused it.
        encoding: Encoding,
    },
}

const LEAF_BIT: u32 = 1 << 31;
/// Largest first-child index of a variable-branching internal node (25 bits).
pub const VARIABLE_MAX_CHILD: u32 = (1 << 25) - 1;
/// Largest child count of a variable-branching internal node (6 bits, count − 1).
pub const VARIABLE_MAX_CHILDREN: u32 = 64;
/// Largest first-face index of a variable-branching leaf (24 bits).
pub const VARIABLE_MAX_FACE: u32 = (1 << 24) - 1;
/// Largest face count of a variable-branching leaf (7 bits, count − 1).
pub const VARIABLE_MAX_LEAF_FACES: u32 = 128;
/// Largest face index of a binary leaf (a non-negative i32).
pub const BINARY_MAX_FACE: u32 = i32::MAX as u32;
/// Largest first-child index of a binary internal node (the magnitude of a negative i32).
pub const BINARY_MAX_CHILD: u32 = 1 << 31;

impl Encoding {
    /// The header tag (1 binary, 2 variable).
    pub fn tag(self) -> u8 {
        match self {
            Encoding::Binary => 1,
            Encoding::Variable => 2,
        }
    }

    /// Inverse of [`Encoding::tag`].
    pub fn from_tag(tag: u8) -> Option<Encoding> {
        match tag {
            1 => Some(Encoding::Binary),
            2 => Some(Encoding::Variable),
            _ => None,
        }
    }

    /// `"binary"` or `"variable"`.
    pub fn name(self) -> &'static str {
        match self {
            Encoding::Binary => "binary",
            Encoding::Variable => "variable",
        }
    }

    /// Packs a reference, refusing anything the encoding cannot represent exactly.
    ///
    /// # Errors
    ///
    /// - [`EncodeError::BadCount`] for a child or face count the encoding cannot hold
    ///   (zero, too many, or not exactly 2 children / 1 face in the binary encoding).
    /// - [`EncodeError::IndexTooLarge`] for a first child or face index beyond the
    ///   encoding's field (or a first child of 0, the root).
    ///
    /// # Examples
    ///
    /// ```
    /// use obbtree::tree::{EncodeError, Encoding, NodeRef};
    ///
    /// let leaf = NodeRef::Leaf { first: 7, count: 1 };
    /// let packed = Encoding::Binary.encode(leaf)?;
    /// assert_eq!(Encoding::Binary.decode(packed), leaf);
    /// let wide = NodeRef::Internal { first: 1, count: 3 };
    /// assert!(matches!(Encoding::Binary.encode(wide), Err(EncodeError::BadCount { .. })));
    /// # Ok::<(), EncodeError>(())
    /// ```
    pub fn encode(self, r: NodeRef) -> Result<u32, EncodeError> {
        let too_large = |what, index, limit| EncodeError::IndexTooLarge {
            what,
            index,
            limit,
            encoding: self,
        };
        let bad_count = |what, count, allowed| EncodeError::BadCount {
            what,
            count,
            allowed,
            encoding: self,
        };
        match (self, r) {
            (Encoding::Binary, NodeRef::Internal { first, count }) => {
                if count != 2 {
                    return Err(bad_count("children", count, "exactly 2"));
                }
                // `first` is at least 1 (the root is node 0 and children follow parents),
                // so the packed value is negative; -2^31 is representable.
                if first == 0 || first > BINARY_MAX_CHILD {
                    return Err(too_large("child", first, BINARY_MAX_CHILD));
                }
                // The bits of the i32 `-first`.
                Ok(first.wrapping_neg())
            }
            (Encoding::Binary, NodeRef::Leaf { first, count }) => {
                if count != 1 {
                    return Err(bad_count("faces", count, "exactly 1"));
                }
                if first > BINARY_MAX_FACE {
                    return Err(too_large("face", first, BINARY_MAX_FACE));
                }
                Ok(first)
            }
            (Encoding::Variable, NodeRef::Internal { first, count }) => {
                if !(1..=VARIABLE_MAX_CHILDREN).contains(&count) {
                    return Err(bad_count("children", count, "1 to 64"));
                }
                if first > VARIABLE_MAX_CHILD {
                    return Err(too_large("child", first, VARIABLE_MAX_CHILD));
                }
                Ok(first | (count.saturating_sub(1) << 25))
            }
            (Encoding::Variable, NodeRef::Leaf { first, count }) => {
                if !(1..=VARIABLE_MAX_LEAF_FACES).contains(&count) {
                    return Err(bad_count("faces", count, "1 to 128"));
                }
                if first > VARIABLE_MAX_FACE {
                    return Err(too_large("face", first, VARIABLE_MAX_FACE));
                }
                Ok(LEAF_BIT | first | (count.saturating_sub(1) << 24))
            }
        }
    }

    /// Unpacks a reference. Total: every `u32` decodes to some reference; whether it is in
    /// bounds is the caller's check (see [`TreeView::children`]).
    #[inline]
    pub fn decode(self, packed: u32) -> NodeRef {
        match self {
            Encoding::Binary => {
                let k = packed as i32;
                if k < 0 {
                    NodeRef::Internal {
                        first: k.unsigned_abs(),
                        count: 2,
                    }
                } else {
                    NodeRef::Leaf {
                        first: packed,
                        count: 1,
                    }
                }
            }
            Encoding::Variable => {
                if packed & LEAF_BIT != 0 {
                    NodeRef::Leaf {
                        first: packed & VARIABLE_MAX_FACE,
                        // A 7-bit field plus one: no overflow.
                        count: ((packed >> 24) & 0x7f).saturating_add(1),
                    }
                } else {
                    NodeRef::Internal {
                        first: packed & VARIABLE_MAX_CHILD,
                        count: ((packed >> 25) & 0x3f).saturating_add(1),
                    }
                }
            }
        }
    }
}

/// Typed, borrowed view of one tree: leaf-ordered faces, their source ids, vertices, and
/// nodes (node 0 is the root). Cheap to copy; `Send + Sync`, so many threads can query one
/// mapped file.
#[derive(Debug)]
pub struct TreeView<'a, B: BoundingVolume> {
    pub(crate) encoding: Encoding,
    pub(crate) vertices: &'a [[B::Real; 3]],
    pub(crate) faces: &'a [[u32; 3]],
    pub(crate) source_ids: &'a [u32],
    pub(crate) nodes: &'a [Node<B>],
}

impl<B: BoundingVolume> Clone for TreeView<'_, B> {
    fn clone(&self) -> Self {
        *self
    }
}
impl<B: BoundingVolume> Copy for TreeView<'_, B> {}

impl<'a, B: BoundingVolume> TreeView<'a, B> {
    /// The packed-reference encoding of this tree.
    pub fn encoding(&self) -> Encoding {
        self.encoding
    }
    /// Stored vertex positions, model frame.
    pub fn vertices(&self) -> &'a [[B::Real; 3]] {
        self.vertices
    }
    /// Triangles in leaf order, as vertex indices.
    pub fn faces(&self) -> &'a [[u32; 3]] {
        self.faces
    }
    /// For each leaf-ordered face, its triangle id in the input mesh.
    pub fn source_ids(&self) -> &'a [u32] {
        self.source_ids
    }
    /// All node records; node 0 is the root.
    pub fn nodes(&self) -> &'a [Node<B>] {
        self.nodes
    }

    /// Node `index`, if it exists.
    #[inline]
    pub fn node(&self, index: u32) -> Option<&'a Node<B>> {
        self.nodes.get(index as usize)
    }

    /// The decoded reference of a node.
    #[inline]
    pub fn node_ref(&self, node: &Node<B>) -> NodeRef {
        self.encoding.decode(node.packed)
    }

    /// What node `index` holds, checked: its children (which must lie after it and inside
    /// the node array, so every descent terminates) or its faces (inside the face array).
    /// The one decoder of references that the traversal, `verify` and the tests share.
    ///
    /// # Errors
    ///
    /// [`NodeDefect::Missing`] for an index past the node array,
    /// [`NodeDefect::BadChildren`] for children past the array or not after the node, and
    /// [`NodeDefect::BadFaces`] for faces past the face array: only in a damaged file,
    /// never after [`ObbtFile::verify`](crate::format::ObbtFile::verify).
    #[inline]
    pub fn node_kind(&self, index: u32) -> Result<NodeKind, NodeDefect> {
        let node = self.node(index).ok_or(NodeDefect::Missing)?;
        match self.node_ref(node) {
            NodeRef::Internal { first, count } => {
                let end = first.checked_add(count).ok_or(NodeDefect::BadChildren)?;
                if first > index && end as usize <= self.nodes.len() {
                    Ok(NodeKind::Children(first..end))
                } else {
                    Err(NodeDefect::BadChildren)
                }
            }
            NodeRef::Leaf { first, count } => {
                let end = first.checked_add(count).ok_or(NodeDefect::BadFaces)?;
                if end as usize <= self.faces.len() {
                    Ok(NodeKind::Faces(first..end))
                } else {
                    Err(NodeDefect::BadFaces)
                }
            }
        }
    }

    /// The children of node `index`, or `None` for a leaf, a missing node, or children
    /// that are out of bounds or not after their parent (see [`TreeView::node_kind`]).
    #[inline]
    pub fn children(&self, index: u32) -> Option<Range<u32>> {
        match self.node_kind(index) {
            Ok(NodeKind::Children(range)) => Some(range),
            _ => None,
        }
    }

    /// The faces of leaf `index`, or `None` for an internal node, a missing node, or a face
    /// range out of bounds (see [`TreeView::node_kind`]).
    #[inline]
    pub fn leaf_faces(&self, index: u32) -> Option<Range<u32>> {
        match self.node_kind(index) {
            Ok(NodeKind::Faces(range)) => Some(range),
            _ => None,
        }
    }

    /// The three corners of leaf-ordered face `face`, widened to f64, model frame.
    #[inline]
    pub fn triangle(&self, face: u32) -> Option<[[f64; 3]; 3]> {
        let f = self.faces.get(face as usize)?;
        let v = |i: u32| self.vertices.get(i as usize).map(point_to_f64::<B::Real>);
        Some([v(f[0])?, v(f[1])?, v(f[2])?])
    }

    /// The input-mesh triangle id of leaf-ordered face `face`.
    #[inline]
    pub fn source_id(&self, face: u32) -> Option<u32> {
        self.source_ids.get(face as usize).copied()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_u32_decodes_and_reencodes_to_itself_when_valid() {
        for enc in [Encoding::Binary, Encoding::Variable] {
            for packed in [
                0u32,
                1,
                0x7fff_ffff,
                0x8000_0000,
                0xffff_ffff,
                0x0200_0001,
                0x8100_0005,
            ] {
                let r = enc.decode(packed);
                if let Ok(again) = enc.encode(r) {
                    assert_eq!(again, packed, "{enc:?} {packed:#x}");
                }
            }
        }
    }
}
