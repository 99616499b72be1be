//! `obbtree info`: what a file holds, from its header alone.

use super::{human_bytes, Failure};
use clap::Args;
use obbtree::format::{Info, ObbtFile};
use serde_json::json;
use std::path::PathBuf;

/// Show what a .obbt file holds: counts, tree shape, build options, sections.
///
/// Reads only the header, the section directory and the 32-byte placement record (the scale
/// and offset `build --scale / --center` applied), so it takes the same time for any file
/// size. It does not check the sections: use `obbtree verify` for that.
#[derive(Args, Debug)]
pub struct InfoArgs {
    /// A .obbt file.
    pub file: PathBuf,
    /// Print one JSON object instead of text.
    #[arg(long)]
    pub json: bool,
}

pub fn run(args: &InfoArgs) -> Result<(), Failure> {
    let file = ObbtFile::open(&args.file)?;
    let info = file.info();
    if args.json {
        println!("{}", to_json(&info));
    } else {
        print_text(&args.file.display().to_string(), &info);
    }
    Ok(())
}

/// The `info --json` object (field names are part of the CLI contract).
pub fn to_json(info: &Info) -> serde_json::Value {
    let sections: Vec<_> = info
        .sections
        .iter()
        .map(|s| json!({"name": s.name(), "offset": s.offset, "bytes": s.length, "count": s.count, "stride": s.stride}))
        .collect();
    json!({
        "version": format!("{}.{}", info.version.0, info.version.1),
        "triangles": info.triangles,
        "vertices": info.vertices,
        "nodes": info.nodes,
        "leaves": info.leaves,
        "depth": info.depth,
        "max_leaf_faces": info.max_leaf_faces,
        "degenerate_triangles": info.degenerate_triangles,
        "bv": info.bv.name(),
        "precision": info.precision.name(),
        "fit": info.fit.name(),
        "leaf_size": info.leaf_size,
        "encoding": info.encoding.name(),
        "bounds": {"min": info.bounds_min, "max": info.bounds_max},
        "placement": {"scale": info.placement.scale, "offset": info.placement.offset},
        "file_bytes": info.file_bytes,
        "bytes_per_triangle": info.file_bytes as f64 / f64::from(info.triangles.max(1)),
        "sections": sections,
    })
}

fn print_text(name: &str, info: &Info) {
    println!(
        "{name}: .obbt version {}.{}",
        info.version.0, info.version.1
    );
    println!(
        "  triangles      {} ({} zero-area)",
        info.triangles, info.degenerate_triangles
    );
    println!("  vertices       {}", info.vertices);
    println!(
        "  nodes          {} ({} leaves, depth {}, up to {} faces per leaf)",
        info.nodes, info.leaves, info.depth, info.max_leaf_faces
    );
    println!(
        "  built with     --bv {} --precision {} --fit {} --leaf-size {} ({} encoding)",
        info.bv.name(),
        info.precision.name(),
        info.fit.name(),
        info.leaf_size,
        info.encoding.name()
    );
    println!(
        "  bounds         {:?} .. {:?}",
        info.bounds_min, info.bounds_max
    );
    if info.placement.is_identity() {
        println!("  placement      none (stored = input coordinates)");
    } else {
        println!(
            "  placement      {} (stored = scale · input + offset)",
            info.placement
        );
    }
    println!(
        "  size           {} ({:.1} bytes per triangle)",
        human_bytes(info.file_bytes),
        info.file_bytes as f64 / f64::from(info.triangles.max(1))
    );
    for s in &info.sections {
        println!(
            "  section {:<11} offset {:>10}  {:>10}  ({} x {} bytes)",
            s.name(),
            s.offset,
            human_bytes(s.length),
            s.count,
            s.stride
        );
    }
}
