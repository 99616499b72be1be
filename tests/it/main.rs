//! The integration tests, one module per concern, linked into one binary: one link of the
//! crate and its dependencies instead of one per suite, and one test run whose threads
//! share the machine across suites.
//! Run one module with `cargo test --release --test it MODULE::`.

#[path = "../common/mod.rs"]
mod common;

mod build_roundtrip;
mod bv_pair;
mod cad_work;
mod cli;
mod closest;
mod concurrency;
mod contact_geometry;
mod contact_work;
mod corruption;
mod dev_config;
mod distance_work;
mod doc_examples;
mod doc_links;
mod encoding;
mod experiment_cli;
mod far_apart;
mod fit;
mod fuzz_corpus;
mod golden;
mod hard_cases;
mod hausdorff;
mod hostile_cli;
mod hostile_files;
mod layouts;
mod mapped_files;
mod mesh_loaders;
mod poses;
mod queries;
mod rays;
mod scene_broad;
mod scene_cli;
mod scene_equivalence;
mod scene_work;
mod scenes;
mod triangle_primitives;
mod units;
mod winding;
mod work_pins;
