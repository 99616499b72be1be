//! An owned byte buffer aligned to a cache line, so that an in-memory tree can be viewed
//! zero-copy exactly like a mapped file (mappings are page-aligned).

use zerocopy::{FromBytes, Immutable, IntoBytes, KnownLayout};

#[derive(Clone, Copy, FromBytes, IntoBytes, KnownLayout, Immutable)]
#[repr(C, align(64))]
struct Block([u8; 64]);

/// A heap buffer whose first byte is 64-byte aligned.
#[derive(Clone)]
pub struct AlignedBytes {
    blocks: Vec<Block>,
    len: usize,
}

impl AlignedBytes {
    /// `len` zero bytes.
    pub fn zeroed(len: usize) -> AlignedBytes {
        AlignedBytes {
            blocks: vec![Block([0; 64]); len.div_ceil(64)],
            len,
        }
    }

    /// `len` zero bytes, written by all threads: a fresh large buffer costs a page fault
    /// per page on first touch, and this spreads those over the cores.
    pub(crate) fn zeroed_in_parallel(len: usize) -> AlignedBytes {
        use rayon::prelude::*;
        let mut blocks = Vec::new();
        (0..len.div_ceil(64))
            .into_par_iter()
            .map(|_| Block([0; 64]))
            .collect_into_vec(&mut blocks);
        AlignedBytes { blocks, len }
    }

    /// An aligned copy of `bytes` (for trees embedded with `include_bytes!` or read by hand).
    pub fn copy_from(bytes: &[u8]) -> AlignedBytes {
        let mut out = AlignedBytes::zeroed(bytes.len());
        out.as_mut_bytes().copy_from_slice(bytes);
        out
    }

    /// The bytes.
    pub fn as_bytes(&self) -> &[u8] {
        // `len` never exceeds the blocks' bytes (both are set together above).
        self.blocks.as_bytes().get(..self.len).unwrap_or_default()
    }

    /// The bytes, mutable.
    pub fn as_mut_bytes(&mut self) -> &mut [u8] {
        self.blocks
            .as_mut_bytes()
            .get_mut(..self.len)
            .unwrap_or_default()
    }
}

impl std::fmt::Debug for AlignedBytes {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "AlignedBytes({} bytes)", self.len)
    }
}
