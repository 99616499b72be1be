//! Collision, distance and span queries between posed triangle meshes, with the oriented
//! bounding box trees of Gottschalk's dissertation *Collision Queries using Oriented
//! Bounding Boxes* (the OBBTree behind RAPID).
//!
//! Build a tree once, offline, into one `.obbt` file ([`build`], `obbtree build`); then map
//! it wherever queries run ([`format::ObbtFile::open`]: constant time for any size, nothing
//! parsed or rebuilt) and query pairs of posed models ([`query`]).
//!
//! # Guide
//!
//! ```
//! use obbtree::build::{build, BuildOptions};
//! use obbtree::format::ObbtFile;
//! use obbtree::mesh::TriMesh;
//! use obbtree::nalgebra::{Isometry3, Vector3};
//! use obbtree::query::{CollideOptions, DistanceOptions, PairQuery, Pose};
//!
//! // Offline: load a mesh (OBJ or STL) and write its tree.
//! let mesh = TriMesh::load(concat!(env!("CARGO_MANIFEST_DIR"), "/assets/cow.obj").as_ref())?;
//! let path = std::env::temp_dir().join(format!("guide-{}.obbt", std::process::id()));
//! build(&mesh, &BuildOptions::default(), None)?.write_atomic(&path)?;
//!
//! // In the application: map the file (O(1)), verify it once if it came from elsewhere.
//! let cow = ObbtFile::open(&path)?;
//! cow.verify()?;
//!
//! // One PairQuery per pair of models: poses and options per call, scratch kept between.
//! let mut pair = PairQuery::new(&cow, &cow)?;
//! let here = Pose::identity();
//! // Poses are f64 rigid motions; nalgebra's types convert (the crate re-exports the
//! // nalgebra it uses, so the versions always match).
//! let there = Pose::from_isometry(&Isometry3::translation(0.3, 0.0, 0.0))?;
//!
//! // Yes/no per frame: stop at the first contact, the cheapest collision answer.
//! let first = CollideOptions { first_contact: true, ..CollideOptions::default() };
//! assert!(pair.collide(&here, &there, &first)?.colliding);
//! // All contacting triangle pairs (input-mesh ids), when they are needed.
//! let contacts = pair.collide(&here, &there, &CollideOptions::default())?;
//! assert!(contacts.pairs.len() > 1);
//! // Separation distance with the closest points, here between copies 2 units apart.
//! let apart = Pose::translation(2.0, 0.0, 0.0);
//! let gap = pair.distance(&here, &apart, &DistanceOptions::default())?;
//! let closest = gap.closest.expect("no maximum distance was set");
//! assert!(closest.distance > 0.9 && closest.distance < 1.1);
//! assert!(((closest.point_b - closest.point_a).norm() - closest.distance).abs() < 1e-9);
//! // Only wanted up to 0.5 apart: pairs of volumes farther than that are never opened.
//! let near = DistanceOptions { max_distance: 0.5, ..DistanceOptions::default() };
//! assert!(pair.distance(&here, &apart, &near)?.closest.is_none());
//! # std::fs::remove_file(&path)?;
//! # Ok::<(), Box<dyn std::error::Error>>(())
//! ```
//!
//! # Modules
//!
//! - [`mesh`]: [`mesh::TriMesh`] and the OBJ / STL loaders;
//! - [`build`]: the top-down builder and its options;
//! - [`format`](mod@format): the `.obbt` file: open (memory-mapped), verify, write;
//! - [`query`]: collision, distance (exact, approximate, up to a maximum distance),
//!   tolerance and span between two posed trees, all through [`query::PairQuery`];
//! - [`scene`]: many models over frames, each pair asking for its own effect;
//! - [`generate`]: the dissertation's test shapes, pose sweeps and random poses, and the
//!   seeded generator behind them;
//! - `experiment` (cargo feature `experiment`, on with the default `cli`): the
//!   dissertation's chapter 5 experiments and the accuracy–time trade-off, as functions
//!   returning what they measured;
//! - [`bv`], [`tree`], [`stats`], [`fit`], [`real`]: bounding volumes, the packed tree
//!   view, tree statistics (the header's, and level by level), frame fitting and stored
//!   precision, for tools that look inside a tree.
//!
//! The library never panics on data it did not make: damaged files, meshes and poses
//! give errors (see docs/DESIGN.md, Robustness).
#![forbid(unsafe_op_in_unsafe_fn)]
// The no-panic lints (no unwrap / expect / panic / unchecked indexing outside tests) are
// in Cargo.toml's `[lints.clippy]`; integer arithmetic and narrowing casts are also linted
// in the modules that parse untrusted bytes (`format`, `mesh`, `tree`, `stats`).

/// The nalgebra this crate's API uses (poses, points), re-exported so an application can
/// name exactly these types without adding a second, possibly different nalgebra.
pub use nalgebra;

mod arr3;
pub mod build;
pub mod bv;
#[cfg(feature = "experiment")]
pub mod experiment;
pub mod fit;
pub mod format;
pub mod generate;
pub mod mesh;
pub mod placement;
mod pose;
pub mod query;
pub mod real;
pub mod scene;
pub mod stats;
pub mod tree;

/// The README's Rust examples, compiled and run as doctests so they cannot drift from the
/// API.
#[doc = include_str!("../README.md")]
#[cfg(doctest)]
pub struct ReadmeDoctests;
