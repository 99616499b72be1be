//! `obbtree inside`: winding numbers (inside or outside) of one posed model at query points.

use super::build::TreeArgs;
use super::poses::ModelPoseArgs;
use super::print::out;
use super::query::open_model;
use super::rows::{PointArgs, ThreadArgs};
use super::{number, with_threads, Failure};
use clap::Args;
use obbtree::query::{
    closest_points, winding_numbers, ClosestOptions, QueryError, WindingAccuracy, WindingOptions,
};
use serde_json::json;
use std::path::PathBuf;

/// Tell which query points lie inside a posed model: its generalised winding number.
///
/// The winding number is 1 inside a closed outward-facing surface and 0 outside; for a
/// surface with holes, duplicate or self-intersecting triangles it lies between, and a
/// point is inside where it is above 0.5. Far clusters of triangles are summed by their
/// moments: by default those seen from more than --beta times their radius (fast; the
/// error measured against the exact sum is small, but the bound printed as error_bound is
/// the proven one, often far larger); with --tolerance each value is proven within it of
/// the exact sum, and --tolerance 0 sums every triangle. Prints, per point, the winding
/// number, inside or not, the error bound, and with --distance the signed distance
/// (negative inside).
///
/// Example: obbtree inside part.obbt --point 0.1,0.2,0.3
///
/// Example: obbtree inside scan.obj --points cloud.xyz --distance --csv > sdf.csv
#[derive(Args, Debug)]
pub struct InsideArgs {
    /// The model: a .obbt file, or a mesh (.obj, .stl) built in memory first.
    pub model: PathBuf,
    #[command(flatten)]
    pub query: PointArgs,
    #[command(flatten)]
    pub pose: ModelPoseArgs,
    #[command(flatten)]
    pub threads: ThreadArgs,
    /// Sum clusters seen from more than B times their radius by their moments (> 1).
    #[arg(
        long,
        value_name = "B",
        default_value_t = 2.0,
        conflicts_with = "tolerance"
    )]
    pub beta: f64,
    /// Prove each winding number within T of the exact sum instead (>= 0; 0 is exact).
    #[arg(long, value_name = "T", allow_negative_numbers = true)]
    pub tolerance: Option<f64>,
    /// Also print the signed distance: the closest surface point's distance, negative
    /// inside.
    #[arg(long)]
    pub distance: bool,
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

pub fn run(args: &InsideArgs) -> Result<(), Failure> {
    let pose = args.pose.pose()?;
    let rows = args.query.rows()?;
    let points = &rows.values;
    let accuracy = match args.tolerance {
        Some(0.0) => WindingAccuracy::Exact,
        Some(tolerance) if tolerance > 0.0 => WindingAccuracy::Bounded { tolerance },
        Some(tolerance) => {
            return Err(Failure::msg(format!(
                "--tolerance must be at least 0 (0 is exact), got {tolerance}"
            )))
        }
        None => WindingAccuracy::Beta { beta: args.beta },
    };
    let model = open_model(&args.model, &args.tree)?;
    let answer = || -> Result<_, QueryError> {
        let winding = winding_numbers(&model, &pose, points, &WindingOptions { accuracy })?;
        // The signed distance: the closest point's distance, signed by the winding number.
        let signed: Vec<Option<f64>> = if args.distance {
            closest_points(&model, &pose, points, &ClosestOptions::default())?
                .iter()
                .zip(&winding)
                .map(|(c, w)| Some(w.signed(c.distance())))
                .collect()
        } else {
            vec![None; points.len()]
        };
        Ok((winding, signed))
    };
    let (winding, signed) =
        with_threads(args.threads.threads, answer)?.map_err(|e| rows.locate(e))?;
    if args.csv {
        let distance = if args.distance {
            ",signed_distance"
        } else {
            ""
        };
        out!("point,winding_number,inside,error_bound{distance}")?;
    }
    let many = points.len() > 1;
    for (index, ((p, w), d)) in points.iter().zip(&winding).zip(&signed).enumerate() {
        if args.csv {
            let distance = d.map_or(String::new(), |d| format!(",{d}"));
            out!(
                "{index},{},{},{}{distance}",
                w.value,
                w.inside(),
                w.error_bound
            )?;
        } else if args.json {
            let mut object = json!({"point": index, "query": p, "winding_number": w.value,
                "inside": w.inside(), "error_bound": w.error_bound});
            if let (Some(d), Some(fields)) = (d, object.as_object_mut()) {
                fields.insert("signed_distance".into(), json!(d));
            }
            out!("{object}")?;
        } else {
            let prefix = if many {
                format!("point {index}: ")
            } else {
                String::new()
            };
            let side = if w.inside() { "inside" } else { "outside" };
            // Beta's bound of what it did is often far above its error: not shown.
            let bound = match accuracy {
                WindingAccuracy::Beta { .. } => String::new(),
                _ => format!(" (error at most {})", number(w.error_bound)),
            };
            let distance = d.map_or(String::new(), |d| {
                format!(", signed distance {}", number(d))
            });
            out!(
                "{prefix}{side}: winding number {}{bound}{distance}",
                number(w.value)
            )?;
        }
    }
    Ok(())
}
