//! `obbtree mesh` and `obbtree poses`: the shapes and pose batches of experiments, written
//! as files every other command reads.

use super::files::{check_new_output, write_file as write};
use super::print::out;
use super::Failure;
use clap::{Args, Subcommand, ValueEnum};
use obbtree::generate::{
    cuboid, lat_long_sphere, plate, pose_line, random_poses, sweep, Axis, PosePair, Sweep,
    SweepRotation,
};
use obbtree::mesh::TriMesh;
use std::path::{Path, PathBuf};

/// Write a test shape as an OBJ mesh: the spheres, plates and boxes of the dissertation's
/// experiments (chapter 5).
///
/// Example (a sphere of §5.3.1, 40,000 triangles): obbtree mesh sphere -o big.obj
///
/// Example: obbtree mesh sphere --radius 0.8 --stacks 101 --slices 200 -o small.obj
#[derive(Args, Debug)]
pub struct MeshArgs {
    #[command(subcommand)]
    pub shape: ShapeCommand,
}

/// Where a shape is written.
#[derive(Args, Debug)]
pub struct MeshOutput {
    /// Output mesh (.obj).
    #[arg(short, long, value_name = "OUT.obj")]
    pub output: PathBuf,
    /// Replace OUT if it exists.
    #[arg(long)]
    pub force: bool,
}

/// The shapes of `obbtree mesh`.
#[derive(Subcommand, Debug)]
pub enum ShapeCommand {
    /// A latitude/longitude sphere about the origin, poles on the z axis:
    /// 2 · slices · (stacks − 1) triangles.
    Sphere {
        /// Radius, model units.
        #[arg(long, default_value_t = 1.0, allow_negative_numbers = true)]
        radius: f64,
        /// Bands from pole to pole (at least 2).
        #[arg(long, default_value_t = 101)]
        stacks: u32,
        /// Sectors around the poles' axis (at least 3).
        #[arg(long, default_value_t = 200)]
        slices: u32,
        #[command(flatten)]
        out: MeshOutput,
    },
    /// A flat plate in the z = 0 plane, centred on the origin, cut into squares of two
    /// triangles: 2 · cells-x · cells-y triangles.
    Plate {
        /// Width (along x) and height (along y), model units.
        #[arg(long, num_args = 2, value_names = ["W", "H"], default_values_t = [1.0, 1.0], allow_negative_numbers = true)]
        size: Vec<f64>,
        /// Cells along x and along y.
        #[arg(long, num_args = 2, value_names = ["NX", "NY"], default_values_t = [100, 100])]
        cells: Vec<u32>,
        #[command(flatten)]
        out: MeshOutput,
    },
    /// An axis-aligned box: 12 triangles.
    Box {
        /// Half-widths along x, y and z, model units.
        #[arg(long, num_args = 3, value_names = ["X", "Y", "Z"], default_values_t = [0.5, 0.5, 0.5], allow_negative_numbers = true)]
        half: Vec<f64>,
        /// Centre, model units.
        #[arg(long, num_args = 3, value_names = ["X", "Y", "Z"], default_values_t = [0.0, 0.0, 0.0], allow_negative_numbers = true)]
        center: Vec<f64>,
        #[command(flatten)]
        out: MeshOutput,
    },
}

/// Write a batch of poses, one line per pose pair, for `--poses` of the query commands:
/// A at the identity and B swept along an axis or placed at random. Numbers are printed
/// with the fewest digits that read back exactly, so a batch reproduces bit for bit.
///
/// Example (the sliding spheres of §5.3.1, a fresh random rotation at each of 1,001 steps):
/// obbtree poses sweep --from 0 --to 2 --step 0.002 --rotation fresh -o sliding.txt
#[derive(Args, Debug)]
pub struct PosesArgs {
    #[command(subcommand)]
    pub kind: PosesCommand,
    /// Output file (default: standard output).
    #[arg(short, long, value_name = "FILE", global = true)]
    pub output: Option<PathBuf>,
    /// Replace FILE if it exists.
    #[arg(long, global = true)]
    pub force: bool,
}

/// The pose batches of `obbtree poses`.
#[derive(Subcommand, Debug)]
pub enum PosesCommand {
    /// B translated along an axis: offsets from, from + step, ... up to to.
    Sweep {
        /// The axis of travel.
        #[arg(long, value_enum, default_value_t = AxisArg::X)]
        axis: AxisArg,
        /// First offset, model units.
        #[arg(long, allow_negative_numbers = true)]
        from: f64,
        /// Last offset, model units (included when a whole number of steps reaches it).
        #[arg(long, allow_negative_numbers = true)]
        to: f64,
        /// Distance between offsets, model units.
        #[arg(long, allow_negative_numbers = true)]
        step: f64,
        /// How B is turned: not at all, by one random rotation, or by a fresh random
        /// rotation at every pose (uniform over rotations, drawn from --seed).
        #[arg(long, value_enum, default_value_t = RotationArg::Identity)]
        rotation: RotationArg,
        /// Seed of the random rotations.
        #[arg(long, default_value_t = 1)]
        seed: u64,
    },
    /// B at uniformly random rotations and at translations uniform in a ball about A's
    /// origin.
    Random {
        /// Number of poses.
        #[arg(long)]
        count: u64,
        /// Radius of the ball of translations, model units.
        #[arg(long, allow_negative_numbers = true)]
        radius: f64,
        /// Seed.
        #[arg(long, default_value_t = 1)]
        seed: u64,
    },
}

/// `--axis` values.
#[derive(ValueEnum, Clone, Copy, Debug)]
pub enum AxisArg {
    X,
    Y,
    Z,
}

/// `--rotation` values.
#[derive(ValueEnum, Clone, Copy, Debug)]
pub enum RotationArg {
    /// B is not turned.
    Identity,
    /// One random rotation for every pose.
    Fixed,
    /// A fresh random rotation at every pose.
    Fresh,
}

/// The `N` values of a `num_args = N` flag (clap gives exactly that many; `missing`
/// fills in otherwise, and the shape refuses it).
fn values<const N: usize, T: Copy>(given: &[T], missing: T) -> [T; N] {
    std::array::from_fn(|k| given.get(k).copied().unwrap_or(missing))
}

pub fn mesh(args: &MeshArgs) -> Result<(), Failure> {
    let out = match &args.shape {
        ShapeCommand::Sphere { out, .. }
        | ShapeCommand::Plate { out, .. }
        | ShapeCommand::Box { out, .. } => out,
    };
    let output = &out.output;
    if !output
        .extension()
        .is_some_and(|e| e.eq_ignore_ascii_case("obj"))
    {
        return Err(Failure::msg(format!(
            "{}: meshes are written as OBJ; name the output *.obj",
            output.display()
        )));
    }
    check_new_output(output, out.force)?;
    let mesh = match &args.shape {
        ShapeCommand::Sphere {
            radius,
            stacks,
            slices,
            ..
        } => lat_long_sphere(*radius, *stacks, *slices)?,
        ShapeCommand::Plate { size, cells, .. } => plate(values(size, f64::NAN), values(cells, 0))?,
        ShapeCommand::Box { half, center, .. } => {
            cuboid(values(half, f64::NAN), values(center, f64::NAN))?
        }
    };
    write(output, mesh.to_obj().as_bytes())?;
    summary(output, &mesh)
}

fn summary(output: &Path, mesh: &TriMesh) -> Result<(), Failure> {
    out!(
        "wrote {}: {} triangles, {} vertices",
        output.display(),
        mesh.faces().len(),
        mesh.vertices().len()
    )
}

pub fn poses(args: &PosesArgs) -> Result<(), Failure> {
    if let Some(output) = &args.output {
        check_new_output(output, args.force)?;
    }
    let batch: Vec<PosePair> = match args.kind {
        PosesCommand::Sweep {
            axis,
            from,
            to,
            step,
            rotation,
            seed,
        } => sweep(&Sweep {
            axis: match axis {
                AxisArg::X => Axis::X,
                AxisArg::Y => Axis::Y,
                AxisArg::Z => Axis::Z,
            },
            from,
            to,
            step,
            rotation: match rotation {
                RotationArg::Identity => SweepRotation::Identity,
                RotationArg::Fixed => SweepRotation::Fixed,
                RotationArg::Fresh => SweepRotation::Fresh,
            },
            seed,
        })?,
        PosesCommand::Random {
            count,
            radius,
            seed,
        } => random_poses(count, radius, seed)?,
    };
    match &args.output {
        Some(output) => {
            let mut text = String::new();
            for pair in &batch {
                text.push_str(&pose_line(pair));
                text.push('\n');
            }
            write(output, text.as_bytes())?;
            out!("wrote {}: {} poses", output.display(), batch.len())?;
        }
        None => {
            for pair in &batch {
                out!("{}", pose_line(pair))?;
            }
        }
    }
    Ok(())
}
