//! The queries as generic functions over typed tree views, for tools that already hold a
//! [`TreeView`](crate::tree::TreeView) of a known volume type (see
//! [`ObbtFile::view`](crate::format::ObbtFile::view)) and manage their own
//! [`QueryContext`]. [`PairQuery`](super::PairQuery) runs exactly these after its one
//! dispatch; applications should use it.

pub use super::collide::{collide, collide_into};
pub use super::distance::{distance, within};
pub use super::engine::QueryContext;
pub use super::span::span;
