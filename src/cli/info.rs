//! `obbtree info`: what a file holds, from its header alone.

use super::print::out;
use super::{human_bytes, Failure};
use clap::Args;
use obbtree::format::{Info, ObbtFile};
use obbtree::real::Precision;
use obbtree::stats::LevelStats;
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
    /// Also measure the volumes level by level (reads every node): count, mean and largest
    /// thickness (smallest width), volume and diameter, and how much the mean thickness
    /// shrinks over two levels (the dissertation's Fig. 5.17: about 4x for OBBs on smooth
    /// surfaces).
    #[arg(long)]
    pub levels: bool,
}

pub fn run(args: &InfoArgs) -> Result<(), Failure> {
    let file = ObbtFile::open(&args.file)?;
    let info = file.info();
    let name = args.file.display().to_string();
    let levels = if args.levels {
        let levels = file
            .level_stats()
            .map_err(|e| Failure::msg(format!("{name}: {e} (run obbtree verify)")))?;
        Some(levels)
    } else {
        None
    };
    if args.json {
        let mut value = info.to_json();
        if let (Some(levels), Some(object)) = (&levels, value.as_object_mut()) {
            object.insert("levels".into(), levels_json(levels));
        }
        out!("{value}")?;
    } else {
        print_text(&name, &info)?;
        if let Some(levels) = &levels {
            print_levels(levels)?;
        }
    }
    Ok(())
}

/// How many times thinner a level's mean thickness is than that of two levels up.
fn shrink(levels: &[LevelStats], level: usize) -> Option<f64> {
    let here = levels.get(level)?.thickness.0;
    let above = levels.get(level.checked_sub(2)?)?.thickness.0;
    (here > 0.0).then(|| above / here)
}

fn levels_json(levels: &[LevelStats]) -> serde_json::Value {
    let rows: Vec<_> = levels
        .iter()
        .enumerate()
        .map(|(level, l)| {
            json!({
                "level": level,
                "nodes": l.nodes,
                "thickness_mean": l.thickness.0,
                "thickness_max": l.thickness.1,
                "thickness_shrink_over_two_levels": shrink(levels, level),
                "volume_mean": l.volume.0,
                "volume_max": l.volume.1,
                "diameter_mean": l.diameter.0,
                "diameter_max": l.diameter.1,
            })
        })
        .collect();
    json!(rows)
}

fn print_levels(levels: &[LevelStats]) -> Result<(), Failure> {
    out!("  levels (root = 0; thickness = smallest width; shrink = mean thickness two levels up / here)")?;
    out!(
        "  {:>5} {:>9} {:>11} {:>11} {:>7} {:>11} {:>11} {:>11} {:>11}",
        "level",
        "nodes",
        "thick mean",
        "thick max",
        "shrink",
        "volume mean",
        "volume max",
        "diam mean",
        "diam max"
    )?;
    for (level, l) in levels.iter().enumerate() {
        let shrink = shrink(levels, level).map_or("".into(), |s| format!("{s:.2}"));
        out!(
            "  {level:>5} {:>9} {:>11.4e} {:>11.4e} {shrink:>7} {:>11.4e} {:>11.4e} {:>11.4e} {:>11.4e}",
            l.nodes,
            l.thickness.0,
            l.thickness.1,
            l.volume.0,
            l.volume.1,
            l.diameter.0,
            l.diameter.1
        )?;
    }
    Ok(())
}

fn print_text(name: &str, info: &Info) -> Result<(), Failure> {
    out!(
        "{name}: .obbt version {}.{}",
        info.version.0,
        info.version.1
    )?;
    out!(
        "  triangles      {} ({} zero-area)",
        info.triangles,
        info.stats.degenerate_triangles
    )?;
    out!("  vertices       {}", info.vertices)?;
    let per_leaf = match info.stats.shape.max_leaf_faces {
        1 => "1 face per leaf".to_string(),
        n => format!("up to {n} faces per leaf"),
    };
    out!(
        "  nodes          {} ({} leaves, depth {}, {per_leaf})",
        info.nodes,
        info.stats.shape.leaves,
        info.stats.shape.depth
    )?;
    out!(
        "  built with     --bv {} --precision {} --layout {} --fit {} --leaf-size {} ({} encoding)",
        info.bv.name(),
        info.precision.name(),
        info.layout.name(),
        info.fit.name(),
        info.leaf_size,
        info.encoding.name()
    )?;
    out!(
        "  bounds         {} .. {}",
        stored_point(info, info.stats.bounds_min),
        stored_point(info, info.stats.bounds_max)
    )?;
    if info.placement.is_identity() {
        out!("  placement      none (stored = input coordinates)")?;
    } else {
        out!(
            "  placement      {} (stored = scale · input + offset)",
            info.placement
        )?;
    }
    out!(
        "  size           {} ({:.1} bytes per triangle)",
        human_bytes(info.file_bytes),
        info.file_bytes as f64 / f64::from(info.triangles.max(1))
    )?;
    for s in &info.sections {
        out!(
            "  section {:<11} offset {:>10}  {:>10}  ({} x {} bytes)",
            s.name(),
            s.offset,
            human_bytes(s.length),
            s.count,
            s.stride
        )?;
    }
    Ok(())
}

/// A stored point as the shortest decimals that read back to the stored values: f32 files
/// hold f32 coordinates, which widened to f64 would print with 17 meaningless digits.
fn stored_point(info: &Info, p: [f64; 3]) -> String {
    let shown: Vec<String> = p
        .iter()
        .map(|&v| match info.precision {
            Precision::F32 => format!("{}", v as f32),
            Precision::F64 => format!("{v}"),
        })
        .collect();
    format!("[{}]", shown.join(", "))
}
