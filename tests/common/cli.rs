//! Running the `obbtree` binary from tests, and what its contract says about the outcome.

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

/// Runs the binary with `args`.
pub fn obbtree(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_obbtree"))
        .args(args)
        .output()
        .expect("the binary runs")
}

/// A fresh directory for one test, under the system temporary directory, removed with
/// everything in it when the guard is dropped (also when the test fails: rerun it with
/// the removal commented out to keep the files).
pub fn scratch(name: &str) -> ScratchDir {
    let dir = std::env::temp_dir().join(format!("obbtree-cli-{}-{name}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    ScratchDir(dir)
}

/// A test's scratch directory; see [`scratch`].
#[derive(Debug)]
pub struct ScratchDir(PathBuf);

impl std::ops::Deref for ScratchDir {
    type Target = Path;
    fn deref(&self) -> &Path {
        &self.0
    }
}

impl AsRef<Path> for ScratchDir {
    fn as_ref(&self) -> &Path {
        &self.0
    }
}

impl Drop for ScratchDir {
    fn drop(&mut self) {
        let _ = std::fs::remove_dir_all(&self.0);
    }
}

/// The bundled cow's path.
pub fn cow() -> String {
    concat!(env!("CARGO_MANIFEST_DIR"), "/assets/cow.obj").to_string()
}

/// Standard error as text.
pub fn stderr(o: &Output) -> String {
    String::from_utf8_lossy(&o.stderr).into_owned()
}

/// Exit 1 with exactly one line on stderr that contains `needle`.
pub fn assert_bad_input(o: &Output, needle: &str) {
    let err = stderr(o);
    assert_eq!(o.status.code(), Some(1), "stderr: {err}");
    assert_eq!(
        err.trim_end().lines().count(),
        1,
        "one line expected: {err}"
    );
    assert!(err.contains(needle), "{needle:?} not in {err:?}");
}
