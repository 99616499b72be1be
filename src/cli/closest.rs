//! `obbtree closest`: the closest point of one posed model to query points.

use super::build::TreeArgs;
use super::poses::ModelPoseArgs;
use super::print::out;
use super::query::open_model;
use super::rows::{PointArgs, ThreadArgs};
use super::{number, with_threads, Failure};
use clap::Args;
use obbtree::query::{closest_points, ClosestOptions, ClosestResult};
use serde_json::json;
use std::path::PathBuf;

/// Find the closest point of a posed model's surface to each query point.
///
/// Prints, per point, the distance, the closest point (world frame), its triangle (input
/// mesh id) and where on the triangle it lies (face, edge or vertex). Points far from the
/// model get no answer with --max-distance, sooner.
///
/// Example: obbtree closest part.obbt --point 0.1,0.2,0.3 --json
///
/// Example: obbtree closest part.obbt --points cloud.xyz --csv > nearest.csv
#[derive(Args, Debug)]
pub struct ClosestArgs {
    /// The model: a .obbt file, or a mesh (.obj, .stl) built in memory first.
    pub model: PathBuf,
    #[command(flatten)]
    pub query: PointArgs,
    #[command(flatten)]
    pub pose: ModelPoseArgs,
    #[command(flatten)]
    pub threads: ThreadArgs,
    /// Only surface points nearer than D count (world units, > 0).
    #[arg(long, value_name = "D", allow_negative_numbers = true)]
    pub max_distance: Option<f64>,
    /// Print JSON lines, one object per point.
    #[arg(long, conflicts_with = "csv")]
    pub json: bool,
    /// Print CSV: a header, then one row per point.
    #[arg(long)]
    pub csv: bool,
    /// How a mesh model is built in memory (not for .obbt models).
    #[command(
        flatten,
        next_help_heading = "Mesh input (built in memory; not for .obbt models)"
    )]
    pub tree: TreeArgs,
}

pub fn run(args: &ClosestArgs) -> Result<(), Failure> {
    let pose = args.pose.pose()?;
    let rows = args.query.rows()?;
    let points = &rows.values;
    let model = open_model(&args.model, &args.tree)?;
    let options = ClosestOptions {
        max_distance: args.max_distance.unwrap_or(f64::INFINITY),
    };
    let answers = with_threads(args.threads.threads, || {
        closest_points(&model, &pose, points, &options)
    })?
    .map_err(|e| rows.locate(e))?;
    if args.csv {
        out!("point,distance,x,y,z,tri,feature,feature_index,bv_tests,tri_tests")?;
    }
    for (i, (p, answer)) in points.iter().zip(&answers).enumerate() {
        print_answer(args, i, p, answer, points.len() > 1)?;
    }
    Ok(())
}

fn print_answer(
    args: &ClosestArgs,
    index: usize,
    p: &[f64; 3],
    answer: &ClosestResult,
    many: bool,
) -> Result<(), Failure> {
    let work = &answer.work;
    // Text lines name their point when there are several.
    let prefix = if many {
        format!("point {index}: ")
    } else {
        String::new()
    };
    match (&answer.closest, args.csv, args.json) {
        (Some(c), true, _) => out!(
            "{index},{},{},{},{},{},{},{},{},{}",
            c.distance,
            c.point[0],
            c.point[1],
            c.point[2],
            c.triangle,
            c.feature.name(),
            c.feature.index(),
            work.bv_tests(),
            work.tri_tests()
        )?,
        (None, true, _) => out!("{index},inf,,,,,,,{},{}", work.bv_tests(), work.tri_tests())?,
        (c, false, true) => {
            let null = serde_json::Value::Null;
            let object = json!({
                "point": index,
                "query": p,
                "found": c.is_some(),
                "distance": c.map_or(null.clone(), |c| json!(c.distance)),
                "closest": c.map_or(null.clone(), |c| json!(c.point)),
                "tri": c.map_or(null.clone(), |c| json!(c.triangle)),
                "feature": c.map_or(null, |c| json!({"kind": c.feature.name(), "index": c.feature.index()})),
                "work": {"bv_tests": work.bv_tests(), "tri_tests": work.tri_tests()},
            });
            out!("{object}")?;
        }
        (Some(c), false, false) => out!(
            "{prefix}distance {} to ({}, {}, {}) on triangle {} ({} {}); bv tests {}, triangle tests {}",
            number(c.distance),
            number(c.point[0]),
            number(c.point[1]),
            number(c.point[2]),
            c.triangle,
            c.feature.name(),
            c.feature.index(),
            work.bv_tests(),
            work.tri_tests()
        )?,
        (None, false, false) => out!(
            "{prefix}nothing within {}; bv tests {}",
            number(args.max_distance.unwrap_or(f64::INFINITY)),
            work.bv_tests()
        )?,
    }
    Ok(())
}
