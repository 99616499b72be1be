//! Caps on sizes read from untrusted input, checked before anything is
//! allocated for them. Both stay far below `u32::MAX`, so vertex indices and
//! triangle ids always fit a `u32`.

/// Most vertices a [`TriMesh`](super::TriMesh) may have (2^28, about 6 GiB of positions).
pub const MAX_VERTICES: usize = 1 << 28;

/// Most triangles a [`TriMesh`](super::TriMesh) may have (2^28, about 3 GiB of faces).
pub const MAX_TRIANGLES: usize = 1 << 28;
