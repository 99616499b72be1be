//! obbtree: collision queries on triangle meshes with oriented bounding box trees.
#![forbid(unsafe_op_in_unsafe_fn)]

pub mod fit;
pub mod mesh;
