//! What the command may write, and what an interrupt leaves behind.
//!
//! A build never overwrites its own input (compared by file identity, so `./m.obj`, a
//! symbolic or a hard link to it are all caught), and never replaces an existing file that
//! is not a `.obbt` file (by its signature) unless `--force` says so. On Ctrl-C (or
//! SIGTERM, SIGHUP) the temporary files of unfinished writes are removed before exiting
//! with status 130.

use super::{Failure, WithContext};
use obbtree::format::layout::SIGNATURE;
use std::io::Read;
use std::path::Path;

/// Whether `path` is a readable file starting with the `.obbt` signature.
pub fn is_obbt(path: &Path) -> bool {
    let mut head = [0u8; 8];
    std::fs::File::open(path)
        .and_then(|mut f| f.read_exact(&mut head))
        .is_ok()
        && head == SIGNATURE
}

/// Refuses to write `output` when it is one of `inputs`, or when it exists, is not a
/// `.obbt` file and `force` is off.
pub fn check_output(output: &Path, inputs: &[&Path], force: bool) -> Result<(), Failure> {
    check(output, inputs, |output| force || is_obbt(output))
}

/// Refuses to write `output` (a generated mesh or pose file) when it exists and `force`
/// is off.
pub fn check_new_output(output: &Path, force: bool) -> Result<(), Failure> {
    check(output, &[], |_| force)
}

/// Refuses `output` when it is one of `inputs`, is a directory, or exists and may not be
/// replaced.
fn check(
    output: &Path,
    inputs: &[&Path],
    may_replace: impl Fn(&Path) -> bool,
) -> Result<(), Failure> {
    let shown = output.display();
    for input in inputs {
        if same_file::is_same_file(input, output).unwrap_or(false) {
            return Err(Failure::msg(format!(
                "{shown}: is the input {}; refusing to overwrite it (choose another -o)",
                input.display()
            )));
        }
    }
    match std::fs::metadata(output) {
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => Ok(()),
        Err(e) => Err(Failure::from(e).context(format!("{shown}: cannot check the output"))),
        Ok(m) if m.is_dir() => Err(Failure::msg(format!("{shown}: is a directory"))),
        Ok(_) if may_replace(output) => Ok(()),
        Ok(_) if inputs.is_empty() => Err(Failure::msg(format!(
            "{shown}: exists; refusing to replace it (use --force)"
        ))),
        Ok(_) => Err(Failure::msg(format!(
            "{shown}: exists and is not an .obbt file; refusing to replace it (use --force)"
        ))),
    }
}

/// Writes `bytes` to `path` atomically (nothing partial is ever left behind, and the
/// temporaries of an earlier writer that was killed are removed first).
pub fn write_file(path: &Path, bytes: &[u8]) -> Result<(), Failure> {
    let _ = obbtree::format::remove_stale_temporaries(path);
    obbtree::format::write_atomic(path, bytes)
        .with_context(|| format!("{}: cannot write", path.display()))
}

/// Makes Ctrl-C, SIGTERM and SIGHUP remove unfinished temporary files and exit with 130.
pub fn handle_interrupts() {
    // Fails only if a handler is already set (never, in this binary); the default
    // behaviour (exit at once) is then what remains.
    let _ = ctrlc::set_handler(|| {
        obbtree::format::abandon_writes();
        eprintln!("obbtree: interrupted");
        std::process::exit(130);
    });
}
