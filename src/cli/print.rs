//! Standard output that a closed pipe ends quietly.
//!
//! `obbtree collide ... --pairs | head -2` closes the pipe after two lines. Rust's `println!`
//! panics on the next write ("failed printing to stdout: Broken pipe", exit 101); here the
//! first failed write marks standard output closed, later lines are dropped, and the
//! command finishes its work and exits 0, as ripgrep does. Long producers (batches, scenes)
//! check [`closed`] to stop early; the demo finishes writing its files.

use super::Failure;
use std::io::{ErrorKind, Write};
use std::sync::atomic::{AtomicBool, Ordering};

static CLOSED: AtomicBool = AtomicBool::new(false);

/// Whether a reader closed standard output.
pub fn closed() -> bool {
    CLOSED.load(Ordering::Relaxed)
}

/// Writes one line to standard output. A closed pipe is not an error (see the module
/// docs); any other write error (a full disk behind a redirection) is.
pub fn line(args: std::fmt::Arguments<'_>) -> Result<(), Failure> {
    if closed() {
        return Ok(());
    }
    let mut out = std::io::stdout().lock();
    match out.write_fmt(args).and_then(|()| out.write_all(b"\n")) {
        Ok(()) => Ok(()),
        Err(e) if e.kind() == ErrorKind::BrokenPipe => {
            CLOSED.store(true, Ordering::Relaxed);
            Ok(())
        }
        Err(e) => Err(Failure::from(e).context("cannot write to standard output")),
    }
}

/// `out!(...)` prints a line like `println!`, through [`line`]; it returns the `Result`.
macro_rules! out {
    ($($arg:tt)*) => {
        $crate::cli::print::line(format_args!($($arg)*))
    };
}
pub(crate) use out;
