//! Builds a mesh repeatedly (for profiling the builder):
//! `cargo run --release --example profile_build -- MESH [FIT] [N] [HULL_MIN_FACES] [HULL_MAX_POINTS|all]`
//! (threads: `RAYON_NUM_THREADS`).
// A tool developers run by hand: stopping loudly on a broken input is what it should do.
#![allow(clippy::expect_used)]

use obbtree::build::{build, BuildOptions};
use obbtree::fit::FitMethod;
use obbtree::mesh::TriMesh;

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let Some(path) = args.get(1) else {
        eprintln!(
            "usage: profile_build MESH [hull|triangles|vertices] [REPEATS] [HULL_MIN_FACES] [HULL_MAX_POINTS|all]"
        );
        std::process::exit(2);
    };
    let mesh = TriMesh::load(path.as_ref()).unwrap_or_else(|e| {
        eprintln!("{e}");
        std::process::exit(1)
    });
    let fit = args
        .get(2)
        .and_then(|s| FitMethod::from_name(s))
        .unwrap_or_default();
    let repeats: usize = args.get(3).and_then(|s| s.parse().ok()).unwrap_or(5);
    let defaults = BuildOptions::default();
    let options = BuildOptions {
        fit,
        hull_min_faces: args
            .get(4)
            .and_then(|s| s.parse().ok())
            .unwrap_or(defaults.hull_min_faces),
        hull_max_points: args
            .get(5)
            .and_then(|s| BuildOptions::parse_hull_max_points(s))
            .unwrap_or(defaults.hull_max_points),
        ..defaults
    };
    for _ in 0..repeats {
        let started = std::time::Instant::now();
        let file = build(&mesh, &options, None).expect("builds");
        println!(
            "{} nodes in {:.1} ms",
            file.info().nodes,
            started.elapsed().as_secs_f64() * 1e3
        );
    }
}
