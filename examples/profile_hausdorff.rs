//! Runs one-sided and symmetric Hausdorff distances between two meshes, for profilers:
//! `cargo run --release --example profile_hausdorff -- A B [REL_ERR [SHIFT]]`. B is turned
//! by a small fixed rotation and moved a little, plus SHIFT along x (default 0). Prints the answer, its bounds, the work and
//! the time.
// A tool developers run by hand: stopping loudly on a broken input is what it should do.
#![allow(clippy::expect_used)]

use obbtree::build::{build, BuildOptions};
use obbtree::mesh::TriMesh;
use obbtree::query::{hausdorff, HausdorffOptions, Pose};
use std::time::Instant;

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let usage = "usage: profile_hausdorff A B [REL_ERR [SHIFT]]";
    let load = |i: usize| {
        let mesh = TriMesh::load(args.get(i).expect(usage).as_ref()).expect("a mesh");
        build(&mesh, &BuildOptions::default(), None).expect("builds")
    };
    let (a, b) = (load(1), load(2));
    let number = |i: usize| args.get(i).and_then(|s| s.parse().ok()).unwrap_or(0.0);
    let (rel_err, shift): (f64, f64) = (number(3), number(4));
    let turn = nalgebra::Rotation3::from_euler_angles(0.02, -0.01, 0.03);
    let pose_b = Pose::new(
        turn.into_inner(),
        nalgebra::Vector3::new(0.001 + shift, 0.0, 0.002),
    )
    .expect("a rotation");
    for symmetric in [false, true] {
        let options = HausdorffOptions {
            rel_err,
            symmetric,
            ..HausdorffOptions::default()
        };
        let started = Instant::now();
        let h = hausdorff(&a, &Pose::identity(), &b, &pose_b, &options).expect("answers");
        println!(
            "symmetric {symmetric}: h {} .. {} ({:?}) in {:.3} s; {:?}",
            h.distance,
            h.upper_bound,
            h.direction,
            started.elapsed().as_secs_f64(),
            h.work
        );
    }
}
