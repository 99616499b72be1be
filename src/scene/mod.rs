//! Scenes: many models moving over frames, and only the effects each pair asks for.
//!
//! A scene is a set of objects (each a `.obbt` tree, shared between objects through an
//! [`std::sync::Arc`], and a pose) and rules that give each pair of objects an
//! [`Effect`]: nothing, contact, all contacts, a clearance check, a distance, or a span.
//! [`Scene::step`] moves the objects a [`Frame`] names and answers every pair with an
//! effect, doing no more work than each answer needs (see [`Scene`] for the scheduler);
//! [`Scene::set_naive`] switches to the reference that computes everything.
//!
//! Scene files (TOML) and frame streams (JSON Lines) are read by [`load`] and
//! [`FrameReader`]; the `obbtree scene` command runs them.
//!
//! ```
//! use obbtree::build::{build, BuildOptions};
//! use obbtree::mesh::TriMesh;
//! use obbtree::query::Pose;
//! use obbtree::scene::{Effect, Frame, SceneBuilder};
//! use std::sync::Arc;
//!
//! let cow = TriMesh::load(concat!(env!("CARGO_MANIFEST_DIR"), "/assets/cow.obj").as_ref())?;
//! let cow = Arc::new(build(&cow, &BuildOptions::default(), None)?);
//! let mut scene = SceneBuilder::new();
//! let a = scene.object("left", cow.clone(), &["herd"], Pose::identity());
//! let b = scene.object("right", cow, &["herd"], Pose::translation(3.0, 0.0, 0.0));
//! scene.rule("herd", "herd", Effect::Contact);
//! let mut scene = scene.build()?;
//! // Frame 0: apart, nothing to report.
//! assert!(scene.step(&Frame::new())?.pairs.is_empty());
//! // Frame 1: the right cow moves into the left one: a contact, and an event.
//! let report = scene.step(Frame::new().set(b, Pose::translation(0.5, 0.0, 0.0)))?;
//! assert_eq!((report.pairs[0].a, report.pairs[0].b), (a, b));
//! assert_eq!(report.events.len(), 1);
//! # Ok::<(), Box<dyn std::error::Error>>(())
//! ```

pub mod broad;
mod builder;
mod error;
mod file;
mod frame;
mod frame_reader;
mod narrow;
mod object;
mod report;
mod rules;
mod schedule;
mod simulate;

pub use builder::SceneBuilder;
pub use error::SceneError;
pub use file::{load, LoadedScene};
pub use frame::Frame;
pub use frame_reader::FrameReader;
pub use object::SceneObject;
pub use report::{
    Answer, EffectWork, Event, EventKind, FrameReport, NarrowWork, ObjectId, PairReport, Summary,
};
pub use rules::{Effect, Rule};
pub use simulate::Scene;
