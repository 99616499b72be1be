//! What happens to an open file when its path changes under it: replaced by an atomic
//! rename while queries run, a mapped file keeps answering from the old contents; a copy
//! read into memory (`ObbtFile::read`) survives even the file being truncated in place,
//! which a map would not (SIGBUS: not tested, it kills the process).
// Test code outside `#[test]` functions (helpers): a failure is a failed test.
#![allow(clippy::expect_used)]

use crate::common::cli::{scratch, ScratchDir};

use obbtree::format::{ObbtFile, OpenError};
use obbtree::query::{PairQuery, Pose, SpanOptions};
use std::path::{Path, PathBuf};

fn asset(name: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("assets/scenes")
        .join(name)
}

/// A scratch directory holding a copy of the bundled cow's tree, and the copy's path.
fn cow_copy(name: &str) -> (ScratchDir, PathBuf) {
    let dir = scratch(name);
    let path = dir.join("model.obbt");
    std::fs::copy(asset("cow.obbt"), &path).expect("copies");
    (dir, path)
}

fn span(file: &ObbtFile) -> f64 {
    let pose = Pose::translation(0.1, 0.0, 0.0);
    PairQuery::new(file, file)
        .expect("views")
        .span(&Pose::identity(), &pose, &SpanOptions::default())
        .expect("spans")
        .span()
}

#[test]
fn a_file_replaced_by_rename_keeps_answering_from_the_old_one() {
    let (dir, path) = cow_copy("mapped-rename");
    let cow = ObbtFile::open(&path).expect("opens");
    let expected = span(&cow);
    let table = ObbtFile::open(asset("table.obbt")).expect("opens");
    std::thread::scope(|scope| {
        let workers: Vec<_> = (0..2)
            .map(|_| scope.spawn(|| (0..200).all(|_| span(&cow) == expected)))
            .collect();
        // Replaced while the workers query it, as `obbtree build` replaces its output.
        for _ in 0..20 {
            table.write_atomic(&path).expect("replaces");
            std::fs::copy(asset("cow.obbt"), dir.join("next.obbt")).expect("copies");
            std::fs::rename(dir.join("next.obbt"), &path).expect("renames");
        }
        table.write_atomic(&path).expect("replaces");
        for worker in workers {
            assert!(worker.join().expect("no panic"), "an answer changed");
        }
    });
    cow.verify().expect("the old contents are intact");
    let reopened = ObbtFile::open(&path).expect("opens");
    assert_eq!(reopened.info(), table.info());
}

#[test]
fn a_file_read_into_memory_survives_truncation_in_place() {
    let (dir, path) = cow_copy("mapped-truncate");
    let copied = ObbtFile::read(&path).expect("reads");
    assert_eq!(copied.info(), ObbtFile::open(&path).expect("opens").info());
    let expected = span(&copied);
    std::fs::OpenOptions::new()
        .write(true)
        .open(&path)
        .expect("opens for writing")
        .set_len(100)
        .expect("truncates");
    copied.verify().expect("the copy is intact");
    assert_eq!(span(&copied), expected);
    for error in [
        ObbtFile::read(&path).expect_err("truncated"),
        ObbtFile::open(&path).expect_err("truncated"),
    ] {
        assert!(matches!(error, OpenError::Format { .. }), "{error}");
        assert!(error.to_string().contains("model.obbt"), "{error}");
    }
    assert!(matches!(ObbtFile::read(&dir), Err(OpenError::Io { .. })));
}
