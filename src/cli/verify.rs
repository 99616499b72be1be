//! `obbtree verify`: the full O(n) integrity check.

use super::print::out;
use super::{Failure, WithContext};
use clap::Args;
use obbtree::format::ObbtFile;
use std::path::PathBuf;

/// Check a .obbt file completely: checksums of the header and every section, zero padding,
/// indices in bounds, a well-formed tree, finite values, and every bounding volume
/// containing the triangles below it.
///
/// Exit status 0 if the file is sound; 1 with one line naming the first problem and its
/// section otherwise.
#[derive(Args, Debug)]
pub struct VerifyArgs {
    /// A .obbt file.
    pub file: PathBuf,
}

pub fn run(args: &VerifyArgs) -> Result<(), Failure> {
    let file = ObbtFile::open(&args.file)?;
    file.verify()
        .with_context(|| format!("{}: verify failed", args.file.display()))?;
    let info = file.info();
    out!(
        "{}: ok ({} triangles, {} nodes)",
        args.file.display(),
        info.triangles,
        info.nodes
    )?;
    Ok(())
}
