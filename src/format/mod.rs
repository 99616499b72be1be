//! The `.obbt` file: writing, opening (O(1), memory-mapped), typed views and verification.
//!
//! `formats/obbt.md` is the specification; this module follows it. The split of checks is
//! the one the spec prescribes: [`ObbtFile::open`] and [`ObbtFile::from_aligned`] check the
//! header and section directory only, and decode the 32-byte placement record (constant
//! time, whatever the file size); the O(n) checks live in [`ObbtFile::verify`]. Queries on
//! an unverified file use checked access, so a corrupt file gives an error or a
//! wrong-but-safe answer, never undefined behaviour.

// Everything here reads untrusted bytes: on top of the crate's no-panic lints, integer
// arithmetic must be checked or saturating and narrowing casts must be `try_from`.
#![cfg_attr(
    not(test),
    deny(clippy::arithmetic_side_effects, clippy::cast_possible_truncation)
)]

mod aligned;
mod error;
pub mod layout;
mod open;
mod verify;
mod write;

pub use aligned::AlignedBytes;
pub use error::{FormatError, OpenError, VerifyError};
pub use open::{Info, ObbtFile, SectionInfo, TreeVisitor};
pub use write::{abandon_writes, remove_stale_temporaries, write_atomic};
pub(crate) use write::{serialize, NodeRun, TreeImage, WriteError};
