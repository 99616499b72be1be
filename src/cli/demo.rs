//! `obbtree demo`: the main job on the bundled asset, end to end.

use super::build::build_with_progress;
use super::{human_bytes, Failure};
use clap::Args;
use obbtree::build::BuildOptions;
use obbtree::bv::BvKind;
use obbtree::format::ObbtFile;
use obbtree::mesh::TriMesh;
use std::path::PathBuf;
use std::time::Instant;

/// The bundled asset, compiled in so the demo runs from any directory.
const COW_OBJ: &[u8] = include_bytes!("../../assets/cow.obj");

/// Run the whole pipeline on the bundled cow mesh (5,804 triangles).
///
/// Builds a tree with each bounding volume, writes the files into a directory, opens them
/// memory-mapped, verifies them, and prints what it built.
#[derive(Args, Debug)]
pub struct DemoArgs {
    /// Keep the built files in this directory (default: a temporary one, removed at the end).
    #[arg(long, value_name = "DIR")]
    pub out: Option<PathBuf>,
}

pub fn run(args: &DemoArgs) -> Result<(), Failure> {
    let (dir, temporary) = match &args.out {
        Some(d) => (d.clone(), false),
        None => (
            std::env::temp_dir().join(format!("obbtree-demo-{}", std::process::id())),
            true,
        ),
    };
    std::fs::create_dir_all(&dir).map_err(|e| Failure(format!("{}: {e}", dir.display())))?;
    let result = run_in(&dir);
    if temporary {
        let _ = std::fs::remove_dir_all(&dir);
    }
    result
}

fn run_in(dir: &std::path::Path) -> Result<(), Failure> {
    let mesh = TriMesh::from_obj_bytes(COW_OBJ, "cow.obj")?;
    println!(
        "obbtree demo: bundled mesh cow.obj, {} triangles, {} vertices ({} zero-area)",
        mesh.faces().len(),
        mesh.vertices().len(),
        mesh.degenerate_triangle_count()
    );
    println!("writing into {}", dir.display());
    for bv in BvKind::ALL {
        let options = BuildOptions {
            bv,
            ..BuildOptions::default()
        };
        let started = Instant::now();
        let built = build_with_progress(&mesh, &options, "cow.obj", true)?;
        let build_ms = started.elapsed().as_secs_f64() * 1e3;
        let path = dir.join(format!("cow-{}.obbt", bv.name()));
        built
            .write_atomic(&path)
            .map_err(|e| Failure(format!("{}: {e}", path.display())))?;
        let started = Instant::now();
        let opened = ObbtFile::open(&path)?;
        let open_us = started.elapsed().as_secs_f64() * 1e6;
        let started = Instant::now();
        opened
            .verify()
            .map_err(|e| Failure(format!("{}: {e}", path.display())))?;
        let verify_ms = started.elapsed().as_secs_f64() * 1e3;
        let same = opened.bytes() == built.bytes();
        let info = opened.info();
        println!(
            "  {:<6} {:>9}  {} nodes, depth {:>2}  built {:>6.1} ms, opened {:>6.1} us, verified {:>5.1} ms, file == memory: {}",
            bv.name(),
            human_bytes(info.file_bytes),
            info.nodes,
            info.depth,
            build_ms,
            open_us,
            verify_ms,
            if same { "yes" } else { "NO" }
        );
        if !same {
            return Err(Failure(format!(
                "{}: the file read back differs from the tree built",
                path.display()
            )));
        }
    }
    println!("inspect a file with: obbtree info <file>   (run with --out DIR to keep the files)");
    Ok(())
}
