//! An app that ships precomputed `.obbt` assets and queries them.
//!
//! Offline (once, at asset-build time) the trees are built with `obbtree build`; here the
//! example does that step itself if no files are given, so it runs out of the box:
//!
//!     cargo run --release --example shipped_assets                # builds assets/cow.obj first
//!     cargo run --release --example shipped_assets -- a.obbt b.obbt
//!
//! At run time the app maps the files (O(1), nothing parsed), verifies them once, and then
//! answers collision, distance and span queries from several threads sharing the maps.
// A tool developers run by hand: stopping loudly on a broken input is what it should do.
#![allow(clippy::expect_used, clippy::indexing_slicing)]

use obbtree::build::{build, BuildOptions};
use obbtree::format::ObbtFile;
use obbtree::mesh::TriMesh;
use obbtree::query::{CollideOptions, DistanceOptions, PairQuery, Pose, SpanOptions};
use std::path::PathBuf;

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let paths: Vec<PathBuf> = if args.len() == 2 {
        args.iter().map(PathBuf::from).collect()
    } else {
        // The asset pipeline: mesh in, .obbt out.
        let dir = std::env::temp_dir().join(format!("obbtree-example-{}", std::process::id()));
        std::fs::create_dir_all(&dir)?;
        let mesh = TriMesh::load(concat!(env!("CARGO_MANIFEST_DIR"), "/assets/cow.obj").as_ref())?;
        let path = dir.join("cow.obbt");
        build(&mesh, &BuildOptions::default(), None)?.write_atomic(&path)?;
        println!("built asset {}", path.display());
        vec![path.clone(), path]
    };

    // Run time: map the shipped files; verify once (O(n)), e.g. at install or first launch.
    let a = ObbtFile::open(&paths[0])?;
    let b = ObbtFile::open(&paths[1])?;
    a.verify()?;
    b.verify()?;
    println!(
        "A: {} triangles, B: {} triangles",
        a.info().triangles,
        b.info().triangles
    );

    // Four threads share the two maps; each keeps its own PairQuery (its traversal stack).
    let extent = (0..3)
        .map(|k| a.info().stats.bounds_max[k] - a.info().stats.bounds_min[k])
        .fold(0.0, f64::max);
    std::thread::scope(|scope| {
        for thread in 0..4 {
            let (a, b) = (&a, &b);
            scope.spawn(move || -> Result<(), obbtree::query::QueryError> {
                let mut pair = PairQuery::new(a, b)?;
                let angle = 0.4 * f64::from(thread);
                let rotation = *nalgebra::Rotation3::from_euler_angles(0.0, angle, 0.0).matrix();
                let offset = nalgebra::Vector3::new(0.3 * extent * f64::from(thread), 0.0, 0.0);
                let pose_b = Pose::new(rotation, offset).expect("a rotation");
                let here = Pose::identity();
                let hit = pair.collide(&here, &pose_b, &CollideOptions::default())?;
                let gap = pair.distance(&here, &pose_b, &DistanceOptions::default())?;
                let far = pair.span(&here, &pose_b, &SpanOptions::default())?;
                println!(
                    "thread {thread}: B shifted {:.3}: {} contacts, distance {:.6}, span {:.4}",
                    offset.x,
                    hit.pairs.len(),
                    gap.distance(),
                    far.span()
                );
                Ok(())
            });
        }
    });
    Ok(())
}
