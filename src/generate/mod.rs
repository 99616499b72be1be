//! Shapes and poses for experiments: the lat/long spheres, plates and boxes of the
//! dissertation's chapter 5, pose sweeps and random poses, and the one seeded generator
//! they (and the tests) draw from. `obbtree mesh` and `obbtree poses` are these functions
//! on the command line.

mod poses;
mod rng;
mod shapes;

pub use poses::{pose_line, random_poses, sweep, Axis, PosePair, Sweep, SweepRotation, MAX_POSES};
pub use rng::Rng;
pub use shapes::{cuboid, lat_long_sphere, plate, MAX_GENERATED_TRIANGLES};

use crate::mesh::MeshError;

/// Why a shape or a pose batch cannot be made: one parameter named, with what it must be.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum GenerateError {
    /// A number out of its range.
    #[error("{name} {value} is out of range: it must be {expected}")]
    Parameter {
        /// The parameter, as the command line names it.
        name: &'static str,
        /// The value given.
        value: f64,
        /// What it must be.
        expected: &'static str,
    },
    /// A count below its least value.
    #[error("{name} {count} is out of range: it must be at least {least}")]
    Count {
        /// The parameter, as the command line names it.
        name: &'static str,
        /// The count given.
        count: u32,
        /// The least count.
        least: u32,
    },
    /// The shape would have more triangles than [`MAX_GENERATED_TRIANGLES`].
    #[error(
        "the shape would have {count} triangles; at most {MAX_GENERATED_TRIANGLES} are generated"
    )]
    TooManyTriangles {
        /// The triangles asked for.
        count: u64,
    },
    /// More poses than [`MAX_POSES`].
    #[error("{count:.3e} poses asked for; at most {MAX_POSES} are made at once")]
    TooManyPoses {
        /// The poses asked for.
        count: f64,
    },
    /// The mesh failed its own checks (a bug: the shapes are made valid).
    #[error("the generated mesh is invalid")]
    Mesh(#[from] MeshError),
}
