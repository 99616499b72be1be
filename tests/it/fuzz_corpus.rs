//! Replays the fuzz corpus on stable Rust: every file of `fuzz/corpus/<target>/` (the
//! checked-in seeds) and of `fuzz/regressions/<target>/` (inputs that once crashed a target,
//! kept after the fix) goes through the same harness function the cargo-fuzz target runs.
//! See `fuzz/README.md`.
// Test code outside `#[test]` functions (helpers, property bodies): a failure is a failed test.
#![allow(clippy::panic)]

// The harness brings its own copy of `common::seal`: the fuzz crate, where it also
// compiles, has no `tests/common`.
#[allow(clippy::duplicate_mod)]
#[path = "../../fuzz/harness.rs"]
mod harness;

// The differential harness brings its own copy of `common::oracle`, for the same reason.
#[allow(clippy::duplicate_mod)]
#[path = "../../fuzz/differential.rs"]
mod differential;

use std::path::{Path, PathBuf};

/// The regular files of `dir` (skipping dot files), sorted; empty if `dir` does not exist.
fn inputs(dir: &Path) -> Vec<PathBuf> {
    let Ok(entries) = std::fs::read_dir(dir) else {
        return Vec::new();
    };
    let mut files: Vec<PathBuf> = entries
        .filter_map(|entry| entry.ok().map(|e| e.path()))
        .filter(|path| path.is_file())
        .filter(|path| {
            path.file_name()
                .and_then(|name| name.to_str())
                .is_some_and(|name| !name.starts_with('.'))
        })
        .collect();
    files.sort();
    files
}

/// Feeds the seed corpus (which must not be empty) and the regressions of `target` to `run`.
fn replay(target: &str, run: fn(&[u8])) {
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("fuzz");
    let corpus = inputs(&root.join("corpus").join(target));
    assert!(
        !corpus.is_empty(),
        "fuzz/corpus/{target}/ holds no seed input"
    );
    let regressions = inputs(&root.join("regressions").join(target));
    for path in corpus.iter().chain(regressions.iter()) {
        let data =
            std::fs::read(path).unwrap_or_else(|e| panic!("cannot read {}: {e}", path.display()));
        // Name the input if the harness panics on it.
        eprintln!("{target}: {}", path.display());
        run(&data);
    }
}

#[test]
fn obbt_reader_corpus() {
    replay("obbt_reader", harness::obbt_reader);
}

#[test]
fn obj_loader_corpus() {
    replay("obj_loader", harness::obj_loader);
}

#[test]
fn stl_loader_corpus() {
    replay("stl_loader", harness::stl_loader);
}

#[test]
fn differential_corpus() {
    replay("differential", differential::differential);
}

// The scene targets bring their own copy of the byte reader, as the differential one does.
#[allow(clippy::duplicate_mod)]
#[path = "../../fuzz/scene.rs"]
mod scene;

#[test]
fn scene_differential_corpus() {
    replay("scene_differential", scene::scene_differential);
}

#[test]
fn scene_file_corpus() {
    replay("scene_file", scene::scene_file);
}

#[test]
fn frame_stream_corpus() {
    replay("frame_stream", scene::frame_stream);
}
