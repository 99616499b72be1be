//! obbtree: collision queries on triangle meshes with oriented bounding box trees.
#![forbid(unsafe_op_in_unsafe_fn)]
// The library never panics on data it did not make (files, meshes, poses): outside tests,
// no unwrap / expect / panic, and every index or slice is checked (`get`) or, where it is in
// bounds by construction, allowed narrowly with the reason. Integer arithmetic and narrowing
// casts are also linted in the modules that parse untrusted bytes (`format`, `mesh`, `tree`).
#![cfg_attr(
    not(test),
    deny(
        clippy::unwrap_used,
        clippy::expect_used,
        clippy::panic,
        clippy::unreachable,
        clippy::todo,
        clippy::unimplemented,
        clippy::indexing_slicing,
        clippy::string_slice,
        clippy::unwrap_in_result
    )
)]

mod arr3;
pub mod build;
pub mod bv;
pub mod fit;
pub mod format;
pub mod mesh;
pub mod placement;
pub mod query;
pub mod real;
pub mod tree;
