//! `obbtree build`: mesh file in, `.obbt` file out.

use super::files::check_output;
use super::progress::with_progress;
use super::{human_bytes, Failure, WithContext};
use clap::{Args, ValueEnum};
use obbtree::build::{build, rounding_loss, BuildOptions, SphereFit};
use obbtree::bv::{BvKind, Layout};
use obbtree::fit::FitMethod;
use obbtree::format::{remove_stale_temporaries, ObbtFile};
use obbtree::mesh::TriMesh;
use obbtree::real::Precision;
use std::io::IsTerminal;
use std::path::{Path, PathBuf};
use std::sync::atomic::AtomicU64;
use std::time::Instant;

/// Build the tree of a mesh and write it as one `.obbt` file.
///
/// Loads an OBJ or STL triangle soup (format from the extension, or sniffed), fits a
/// bounding volume to every node top-down, and writes vertices, faces and nodes into one
/// aligned, checksummed file, atomically (a crash never leaves a partial file; Ctrl-C
/// leaves neither the output nor a temporary file).
///
/// OUT is never the input mesh, and an existing OUT that is not an .obbt file is replaced
/// only with --force.
///
/// Units: --scale 0.001 turns a mesh in millimetres into one in metres; --center moves the
/// centre of its bounding box to the origin and records the offset applied. The file stores
/// scale · input + offset (`obbtree info` shows both), and queries, poses, tolerances and
/// every coordinate or distance they report are in those stored units and that stored frame,
/// so models built from meshes in different units can be queried together.
///
/// Example: obbtree build bunny.obj -o bunny.obbt
///
/// Example (a part drawn in millimetres, stored in metres around its centre):
/// obbtree build part_mm.stl -o part.obbt --scale 0.001 --center
#[derive(Args, Debug)]
pub struct BuildArgs {
    /// Input mesh: .obj or .stl (binary or ASCII).
    pub mesh: PathBuf,
    /// Output file (conventionally *.obbt).
    #[arg(short, long, value_name = "OUT.obbt")]
    pub output: PathBuf,
    #[command(flatten)]
    pub tree: TreeArgs,
    /// Multiply every coordinate by S before storing it: stored units per input unit, a
    /// finite number above 0 (e.g. 0.001 turns millimetres into metres, 1000 metres into
    /// millimetres). Recorded in the file.
    #[arg(
        long,
        value_name = "S",
        default_value_t = 1.0,
        allow_hyphen_values = true
    )]
    pub scale: f64,
    /// Move the centre of the (scaled) mesh's bounding box to the origin; the offset applied
    /// is recorded in the file and shown by `obbtree info`.
    #[arg(long)]
    pub center: bool,
    /// No progress bar and no summary line.
    #[arg(short, long)]
    pub quiet: bool,
    /// Replace OUT even if it exists and is not an .obbt file. The input mesh itself is
    /// never overwritten, with or without --force.
    #[arg(long)]
    pub force: bool,
}

/// Options that shape a tree, shared by every command that builds one. Each is optional so
/// that a query can tell a flag given from a default (it refuses flags that cannot apply).
#[derive(Args, Debug, Clone)]
pub struct TreeArgs {
    /// Bounding volume of every node [default: obb].
    #[arg(long, value_enum)]
    pub bv: Option<BvArg>,
    /// What the box frames are fitted to: the convex-hull surface (best boxes), the
    /// triangles (area-weighted), or the vertices [default: hull].
    #[arg(long, value_enum)]
    pub fit: Option<FitArg>,
    /// With --fit hull, the fewest triangles (at least 1) a node needs to be fitted to its
    /// convex hull; smaller nodes are fitted to their triangles, which is as tight there
    /// and much cheaper. 1 fits every node to its hull (over every vertex too with
    /// --hull-max-points all, --model-axes no and --split-by-volume no: the dissertation's
    /// §3.4 exactly)
    /// [default: 512].
    #[arg(long, value_name = "N")]
    pub hull_min_faces: Option<u32>,
    /// With --fit hull, the most vertices (at least 4) a node's hull is computed over:
    /// larger nodes take it over an evenly spaced sample of this many and the 6 that reach
    /// their bounding box; box extents still cover every vertex. `all` takes every hull
    /// over every vertex [default: 512].
    #[arg(long, value_name = "N|all", value_parser = parse_hull_points)]
    pub hull_max_points: Option<u32>,
    /// Also fit each node's box to the model's own axes, and keep that box wherever it is
    /// smaller: parts modelled along their axes (CAD) get much tighter boxes [default: yes].
    #[arg(long, value_name = "yes|no", value_parser = parse_yes_no)]
    pub model_axes: Option<bool>,
    /// Split each node along whichever of its box's axes halves it into the least total
    /// volume, the axis of greatest spread unless another is clearly better: far fewer tests
    /// on CAD parts of long, thin triangles; `no` always splits along the greatest spread,
    /// as §3.4 does [default: yes].
    #[arg(long, value_name = "yes|no", value_parser = parse_yes_no)]
    pub split_by_volume: Option<bool>,
    /// With --bv sphere, where each sphere is centred: on its node's box centre, or on
    /// the centre of the smallest ball of its vertices (tighter, slower to build; the
    /// spheres the dissertation's comparisons used) [default: box-centre].
    #[arg(long, value_enum)]
    pub sphere_fit: Option<SphereFitArg>,
    /// Most triangles per leaf, 1 to 128. 1 gives a binary tree with the binary encoding
    /// [default: 1; 4 with --layout compact].
    #[arg(long, value_name = "N")]
    pub leaf_size: Option<u32>,
    /// How nodes are stored: `fast` (plain boxes, the fastest queries) or `compact`
    /// (quantised boxes, with four triangles per leaf unless --leaf-size says otherwise:
    /// about a third of the default file size on typical meshes, slower queries; f32 OBB trees only)
    /// [default: fast].
    #[arg(long, value_enum)]
    pub layout: Option<LayoutArg>,
    /// Stored precision of vertices and volumes (queries always compute in f64)
    /// [default: f32].
    #[arg(long, value_enum)]
    pub precision: Option<PrecisionArg>,
}

/// `--model-axes`: `yes` or `no`.
fn parse_yes_no(text: &str) -> Result<bool, String> {
    match text {
        "yes" => Ok(true),
        "no" => Ok(false),
        _ => Err(format!("{text:?} is not yes or no")),
    }
}

/// `--hull-max-points`: a count, or `all` (no sampling).
fn parse_hull_points(text: &str) -> Result<u32, String> {
    BuildOptions::parse_hull_max_points(text)
        .ok_or_else(|| format!("{text:?} is not a count of points (or all)"))
}

/// `--bv` values.
#[derive(ValueEnum, Clone, Copy, Debug)]
pub enum BvArg {
    /// Oriented bounding box.
    Obb,
    /// Axis-aligned bounding box.
    Aabb,
    /// Bounding sphere.
    Sphere,
}

/// `--fit` values.
#[derive(ValueEnum, Clone, Copy, Debug)]
pub enum FitArg {
    /// Covariance of the convex-hull surface.
    Hull,
    /// Area-weighted covariance of the triangles.
    Triangles,
    /// Covariance of the vertices.
    Vertices,
}

/// `--sphere-fit` values.
#[derive(ValueEnum, Clone, Copy, Debug)]
pub enum SphereFitArg {
    /// The centre of the node's box along its fitted frame.
    BoxCentre,
    /// The centre of the smallest ball containing the node's vertices.
    Minimal,
}

/// `--layout` values.
#[derive(ValueEnum, Clone, Copy, Debug)]
pub enum LayoutArg {
    /// Plain boxes: the fastest queries.
    Fast,
    /// Quantised boxes: the smallest files.
    Compact,
}

/// `--precision` values.
#[derive(ValueEnum, Clone, Copy, Debug)]
pub enum PrecisionArg {
    /// 32-bit floats.
    F32,
    /// 64-bit floats.
    F64,
}

impl TreeArgs {
    /// The library options these flags stand for (defaults where absent).
    pub fn options(&self) -> BuildOptions {
        let default = BuildOptions::default();
        let layout = self.layout.map_or(default.layout, |l| match l {
            LayoutArg::Fast => Layout::Fast,
            LayoutArg::Compact => Layout::Compact,
        });
        BuildOptions {
            layout,
            bv: self.bv.map_or(default.bv, |bv| match bv {
                BvArg::Obb => BvKind::Obb,
                BvArg::Aabb => BvKind::Aabb,
                BvArg::Sphere => BvKind::Sphere,
            }),
            fit: self.fit.map_or(default.fit, |fit| match fit {
                FitArg::Hull => FitMethod::Hull,
                FitArg::Triangles => FitMethod::Triangles,
                FitArg::Vertices => FitMethod::Vertices,
            }),
            precision: self.precision.map_or(default.precision, |p| match p {
                PrecisionArg::F32 => Precision::F32,
                PrecisionArg::F64 => Precision::F64,
            }),
            hull_min_faces: self.hull_min_faces.unwrap_or(default.hull_min_faces),
            hull_max_points: self.hull_max_points.unwrap_or(default.hull_max_points),
            leaf_size: self.leaf_size.unwrap_or(layout.default_leaf_size()),
            model_axes: self.model_axes.unwrap_or(default.model_axes),
            split_by_volume: self.split_by_volume.unwrap_or(default.split_by_volume),
            sphere_fit: self.sphere_fit.map_or(default.sphere_fit, |f| match f {
                SphereFitArg::BoxCentre => SphereFit::BoxCentre,
                SphereFitArg::Minimal => SphereFit::Minimal,
            }),
            ..default
        }
    }

    /// The flags given on the command line, by name.
    pub fn given(&self) -> Vec<&'static str> {
        [
            ("--bv", self.bv.is_some()),
            ("--fit", self.fit.is_some()),
            ("--hull-min-faces", self.hull_min_faces.is_some()),
            ("--hull-max-points", self.hull_max_points.is_some()),
            ("--model-axes", self.model_axes.is_some()),
            ("--split-by-volume", self.split_by_volume.is_some()),
            ("--sphere-fit", self.sphere_fit.is_some()),
            ("--leaf-size", self.leaf_size.is_some()),
            ("--precision", self.precision.is_some()),
            ("--layout", self.layout.is_some()),
        ]
        .into_iter()
        .filter_map(|(name, given)| given.then_some(name))
        .collect()
    }
}

/// Builds `mesh` with a progress bar on stderr that appears only if the build takes more
/// than a second and stderr is a terminal (and `quiet` is off).
pub fn build_with_progress(
    mesh: &TriMesh,
    options: &BuildOptions,
    label: &str,
    quiet: bool,
) -> Result<ObbtFile, Failure> {
    let total = AtomicU64::new(mesh.faces().len() as u64);
    let done = AtomicU64::new(0);
    let show = !quiet && std::io::stderr().is_terminal();
    let work = || build(mesh, options, Some(&done));
    match with_progress(
        &format!("building {label}"),
        "triangles",
        show,
        &done,
        &total,
        work,
    ) {
        Some(result) => result.with_context(|| label),
        None => Err(Failure::msg(format!("{label}: the builder crashed"))),
    }
}

/// Loads a mesh file, naming it in any error.
pub fn load_mesh(path: &Path) -> Result<TriMesh, Failure> {
    Ok(TriMesh::load(path)?)
}

pub fn run(args: &BuildArgs) -> Result<(), Failure> {
    let started = Instant::now();
    let options = BuildOptions {
        scale: args.scale,
        center: args.center,
        ..args.tree.options()
    };
    // Bad option values and a refused output are reported before a (possibly large) mesh
    // is read.
    options.validate()?;
    if options.fit != FitMethod::Hull {
        let given = args.tree.given();
        if let Some(flag) = given.iter().find(|flag| flag.starts_with("--hull-")) {
            return Err(Failure::msg(format!(
                "{flag} applies to --fit hull only (this build fits {})",
                options.fit.name()
            )));
        }
    }
    check_output(&args.output, &[&args.mesh], args.force)?;
    let mesh = load_mesh(&args.mesh)?;
    let label = args.mesh.display().to_string();
    let file = build_with_progress(&mesh, &options, &label, args.quiet)?;
    // Temporaries of an earlier build of this output that was killed outright.
    let _ = remove_stale_temporaries(&args.output);
    file.write_atomic(&args.output)
        .with_context(|| format!("{}: cannot write", args.output.display()))?;
    if !args.quiet {
        let info = file.info();
        eprintln!(
            "built {}: {} triangles, {} nodes, depth {} ({}, {} fit, leaf size {}), {} in {:.2} s",
            args.output.display(),
            info.triangles,
            info.nodes,
            info.stats.shape.depth,
            file.node_type(),
            info.fit.name(),
            info.leaf_size,
            human_bytes(info.file_bytes),
            started.elapsed().as_secs_f64()
        );
        if !info.placement.is_identity() {
            eprintln!(
                "placed: {} (stored = scale · input + offset)",
                info.placement
            );
        }
    }
    // A warning, so shown with --quiet too.
    if let Some(loss) = rounding_loss(&mesh, &file) {
        eprintln!("warning: {}", loss.warning("--center", "--precision f64"));
    }
    Ok(())
}
