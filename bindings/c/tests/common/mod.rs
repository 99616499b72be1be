//! What the C API's tests share: the cow's tree, built from the repository's asset through
//! the root library, as an application would ship it.

#![allow(dead_code)]

use obbtree::build::{build, BuildOptions};
use obbtree::format::ObbtFile;
use obbtree::mesh::TriMesh;
use std::path::{Path, PathBuf};

/// The repository's root (two levels above this crate).
pub fn repo_root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../..")
}

/// A fresh scratch directory for one test.
pub fn scratch(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("obbtree-c-{name}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).expect("scratch directory");
    dir
}

/// assets/cow.obj built with `options` into `dir/name`, returning the path.
pub fn build_cow(dir: &Path, name: &str, options: &BuildOptions) -> PathBuf {
    let mesh = TriMesh::load(&repo_root().join("assets/cow.obj")).expect("assets/cow.obj loads");
    let path = dir.join(name);
    build(&mesh, options, None)
        .expect("the cow builds")
        .write_atomic(&path)
        .expect("the tree is written");
    ObbtFile::open(&path).expect("the tree opens");
    path
}
