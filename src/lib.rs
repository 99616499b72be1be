//! obbtree: collision queries on triangle meshes with oriented bounding box trees.
#![forbid(unsafe_op_in_unsafe_fn)]

pub mod build;
pub mod bv;
pub mod fit;
pub mod format;
pub mod mesh;
pub mod query;
pub mod real;
pub mod tree;
