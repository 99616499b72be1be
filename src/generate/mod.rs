//! Shapes and poses for experiments: the lat/long spheres, plates and boxes of the
//! dissertation's chapter 5, pose sweeps and random poses, and the one seeded generator
//! they (and the tests) draw from. `obbtree mesh` and `obbtree poses` are these functions
//! on the command line.
//!
//! ```
//! use obbtree::build::{build, BuildOptions};
//! use obbtree::generate::{lat_long_sphere, random_poses, sweep, Axis, Sweep, SweepRotation};
//! use obbtree::query::{CollideOptions, PairQuery};
//!
//! # fn main() -> Result<(), Box<dyn std::error::Error>> {
//! // §5.3.1's sphere, smaller: 2 · 20 · 9 triangles.
//! let sphere = lat_long_sphere(1.0, 10, 20)?;
//! assert_eq!(sphere.faces().len(), 360);
//! let tree = build(&sphere, &BuildOptions::default(), None)?;
//! let mut pair = PairQuery::new(&tree, &tree)?;
//!
//! // B slides along x from 0 to 3 by 0.5: the unit spheres overlap below 2 and are 1 apart at 3.
//! let poses = sweep(&Sweep { axis: Axis::X, from: 0.0, to: 3.0, step: 0.5, rotation: SweepRotation::Identity, seed: 1 })?;
//! assert_eq!(poses.len(), 7);
//! let first = CollideOptions { first_contact: true, ..Default::default() };
//! let [a, b] = &poses[6];
//! assert!(!pair.collide(a, b, &first)?.colliding);
//!
//! // The same seed draws the same poses.
//! assert_eq!(random_poses(5, 2.0, 7)?, random_poses(5, 2.0, 7)?);
//! assert!(random_poses(0, 2.0, 7).is_err());
//! # Ok(())
//! # }
//! ```

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
        /// The triangles asked for (`u64::MAX` for that many or more).
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
