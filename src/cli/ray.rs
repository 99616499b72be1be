//! `obbtree ray`: where rays meet one posed model.

use super::build::TreeArgs;
use super::poses::ModelPoseArgs;
use super::print::out;
use super::query::open_model;
use super::rows::{numeric_rows, ThreadArgs};
use super::{number, with_threads, Failure};
use clap::{Args, ValueEnum};
use obbtree::query::{all_ray_hits, cast_rays, QueryError, Ray, RayHit, RayMode, RayOptions, Work};
use serde_json::json;
use std::path::PathBuf;

/// Cast rays at a posed model: the closest hit, any hit, or every hit along each ray.
///
/// A ray is an origin and a direction, world frame; its points are origin + t·direction
/// for t ≥ 0 (t is the distance when the direction has length 1). Prints, per hit, t, the
/// point, the triangle (input mesh id), the point's barycentric weights on the triangle's
/// corners and the triangle's unit normal (world frame, from its corners' order). Hits are
/// watertight: a ray through an edge or a corner shared by triangles hits one of them.
///
/// Example: obbtree ray level.obbt --ray 0,1.7,-5,0,0,1 --json
///
/// Example: obbtree ray part.obbt --rays camera.txt --mode any --t-max 10 --csv
#[derive(Args, Debug)]
pub struct RayArgs {
    /// The model: a .obbt file, or a mesh (.obj, .stl) built in memory first.
    pub model: PathBuf,
    /// One ray, world frame: its origin then its direction, ox,oy,oz,dx,dy,dz.
    #[arg(
        long,
        value_name = "OX,OY,OZ,DX,DY,DZ",
        allow_hyphen_values = true,
        conflicts_with = "rays"
    )]
    pub ray: Option<String>,
    /// Rays, world frame: a file (`-` for stdin) of lines `ox oy oz dx dy dz` (or
    /// comma-separated); blank lines and lines starting with `#` are skipped. Cast in
    /// parallel, printed in input order, each with "ray": its index from 0.
    #[arg(long, value_name = "FILE")]
    pub rays: Option<PathBuf>,
    #[command(flatten)]
    pub pose: ModelPoseArgs,
    #[command(flatten)]
    pub threads: ThreadArgs,
    /// Which hits: the closest, any one (stops at the first found: line of sight), or
    /// all of them by increasing t.
    #[arg(long, value_enum, default_value_t = Mode::Closest)]
    pub mode: Mode,
    /// Only hits with t up to T count (> 0; the ray is a segment).
    #[arg(long, value_name = "T", allow_negative_numbers = true)]
    pub t_max: Option<f64>,
    /// Print JSON lines, one object per ray.
    #[arg(long, conflicts_with = "csv")]
    pub json: bool,
    /// Print CSV: a header, then one row per hit (a ray without hits gets one row).
    #[arg(long)]
    pub csv: bool,
    /// How a mesh model is built in memory (not for .obbt models).
    #[command(
        flatten,
        next_help_heading = "Mesh input (built in memory; not for .obbt models)"
    )]
    pub tree: TreeArgs,
}

/// Which hits `obbtree ray` looks for.
#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
pub enum Mode {
    /// The hit of smallest t.
    Closest,
    /// One hit, the first found.
    Any,
    /// Every hit.
    All,
}

pub fn run(args: &RayArgs) -> Result<(), Failure> {
    let pose = args.pose.pose()?;
    let rows = numeric_rows::<6>(
        args.ray.as_deref(),
        "--ray OX,OY,OZ,DX,DY,DZ",
        args.rays.as_deref(),
        "--rays",
        "ox oy oz dx dy dz",
    )?;
    let rays: Vec<Ray> = rows
        .values
        .iter()
        .map(|[ox, oy, oz, dx, dy, dz]| Ray {
            origin: [*ox, *oy, *oz],
            direction: [*dx, *dy, *dz],
        })
        .collect();
    let model = open_model(&args.model, &args.tree)?;
    let t_max = args.t_max.unwrap_or(f64::INFINITY);
    // Each ray's hits (at most one unless --mode all) and work.
    let cast = || -> Result<Vec<(Vec<RayHit>, Work)>, QueryError> {
        Ok(match args.mode {
            Mode::All => all_ray_hits(&model, &pose, &rays, t_max)?
                .into_iter()
                .map(|r| (r.hits, r.work))
                .collect(),
            Mode::Closest | Mode::Any => {
                let mode = if args.mode == Mode::Any {
                    RayMode::Any
                } else {
                    RayMode::Closest
                };
                cast_rays(&model, &pose, &rays, &RayOptions { mode, t_max })?
                    .into_iter()
                    .map(|r| (r.hit.into_iter().collect(), r.work))
                    .collect()
            }
        })
    };
    let answers = with_threads(args.threads.threads, cast)?.map_err(|e| rows.locate(e))?;
    if args.csv {
        out!("ray,hit,t,x,y,z,tri,b0,b1,b2,nx,ny,nz,bv_tests,tri_tests")?;
    }
    let many = rays.len() > 1;
    for (index, (ray, (hits, work))) in rays.iter().zip(&answers).enumerate() {
        print_ray(args, index, ray, hits, work, many)?;
    }
    Ok(())
}

fn print_ray(
    args: &RayArgs,
    index: usize,
    ray: &Ray,
    hits: &[RayHit],
    work: &Work,
    many: bool,
) -> Result<(), Failure> {
    let (bv, tri) = (work.bv_tests(), work.tri_tests());
    if args.csv {
        if hits.is_empty() {
            out!("{index},false,inf,,,,,,,,,,,{bv},{tri}")?;
        }
        for h in hits {
            let [x, y, z] = ray.at(h.t);
            let ([b0, b1, b2], [nx, ny, nz]) = (h.barycentric, h.normal);
            out!(
                "{index},true,{},{x},{y},{z},{},{b0},{b1},{b2},{nx},{ny},{nz},{bv},{tri}",
                h.t,
                h.triangle
            )?;
        }
        return Ok(());
    }
    if args.json {
        let hit_json = |h: &RayHit| {
            json!({"t": h.t, "point": ray.at(h.t), "tri": h.triangle,
                   "barycentric": h.barycentric, "normal": h.normal})
        };
        let work = json!({"bv_tests": bv, "tri_tests": tri});
        let object = if args.mode == Mode::All {
            json!({"ray": index, "hits": hits.iter().map(hit_json).collect::<Vec<_>>(), "work": work})
        } else {
            let mut object = json!({"ray": index, "hit": !hits.is_empty(), "work": work});
            if let (Some(h), Some(fields)) = (hits.first(), object.as_object_mut()) {
                if let Some(more) = hit_json(h).as_object() {
                    fields.extend(more.clone());
                }
            }
            object
        };
        return out!("{object}");
    }
    // Text lines name their ray when there are several.
    let prefix = if many {
        format!("ray {index}: ")
    } else {
        String::new()
    };
    if hits.is_empty() {
        return out!("{prefix}no hit; bv tests {bv}, triangle tests {tri}");
    }
    for h in hits {
        let [x, y, z] = ray.at(h.t).map(number);
        let [nx, ny, nz] = h.normal.map(number);
        out!(
            "{prefix}hit triangle {} at t {}, point ({x}, {y}, {z}), normal ({nx}, {ny}, {nz}); bv tests {bv}, triangle tests {tri}",
            h.triangle,
            number(h.t)
        )?;
    }
    Ok(())
}
