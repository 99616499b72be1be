//! obbtree's Hausdorff distance against CGAL 5.5's
//! `Polygon_mesh_processing::bounded_error_Hausdorff_distance` and dense point sampling
//! (MeshLab's method, as CGAL's `approximate_Hausdorff_distance`) in one run, one thread.
//!
//! The peer is the harness in `benches/harnesses/cgal-hausdorff/` (Debian's libcgal-dev),
//! built outside the repository by its `build.sh`; this benchmark looks for
//! `bench_cgal_hausdorff` in `$OBBTREE_PEERS` (default `/tmp/peers`) and prints obbtree's
//! figures alone without it. Cases (meshes from `../shared/meshes`, skipped without them):
//! a mesh against a noisy copy (every vertex moved by up to 10⁻³ of the diagonal), against
//! a turned and moved copy, CAD parts against turned copies, and two different models.
//!
//! Each case measures h(A, B) one-sided at the same absolute error `e` = 10⁻⁴ of A's
//! bounding-box diagonal for both (CGAL's default is 10⁻⁴ absolute), and obbtree also
//! exactly. CGAL's call builds its AABB trees inside (its API: no prebuilt tree); the
//! obbtree time is the query on trees built beforehand, as an application shipping `.obbt`
//! files runs it, and the build time is printed beside it. Answers are checked against each
//! other: CGAL's within `e` of obbtree's bounds, the sampled value never above obbtree's
//! upper bound. Run: `cargo bench --bench hausdorff`.
// A benchmark of known-good inputs: a setup that fails is a broken benchmark, not bad input.
#![allow(clippy::expect_used, clippy::indexing_slicing)]

#[path = "../tests/common/mod.rs"]
mod common;
#[path = "support/peers.rs"]
mod peers;

use obbtree::build::{build, BuildOptions};
use obbtree::mesh::TriMesh;
use obbtree::query::{hausdorff, HausdorffOptions, Pose};
use obbtree::real::Precision;
use peers::{median_time, number, pose_entry, pose_line, run_peer_with};
use std::path::PathBuf;
use std::time::Instant;

/// Random points per sampled answer: about MeshLab's default density on these meshes.
const SAMPLES: usize = 100_000;

fn diagonal(mesh: &TriMesh) -> f64 {
    let (mut lo, mut hi) = ([f64::INFINITY; 3], [f64::NEG_INFINITY; 3]);
    for v in mesh.vertices() {
        for k in 0..3 {
            lo[k] = lo[k].min(v[k]);
            hi[k] = hi[k].max(v[k]);
        }
    }
    (0..3).map(|k| (hi[k] - lo[k]).powi(2)).sum::<f64>().sqrt()
}

/// A small turn and a shift of a hundredth of `scale`.
fn turned(scale: f64) -> Pose {
    let r = nalgebra::Rotation3::from_euler_angles(0.02, -0.01, 0.03);
    Pose::new(
        r.into_inner(),
        nalgebra::Vector3::new(0.01, 0.0, 0.005) * scale,
    )
    .expect("a rotation")
}

fn main() {
    let peers =
        PathBuf::from(std::env::var("OBBTREE_PEERS").unwrap_or_else(|_| "/tmp/peers".into()));
    if !peers.join("bench_cgal_hausdorff").exists() {
        eprintln!(
            "bench_cgal_hausdorff not found in {}: build it with benches/harnesses/cgal-hausdorff/build.sh; obbtree alone follows",
            peers.display()
        );
    }
    let mesh = |name: &str| common::shared_mesh(name);
    let mut cases: Vec<(String, TriMesh, TriMesh, Pose)> = Vec::new();
    if let Some(bunny) = mesh("bunny.obj") {
        let d = diagonal(&bunny);
        cases.push((
            "bunny/noisy copy".into(),
            bunny.clone(),
            common::noisy(&bunny, 1e-3 * d, 3),
            Pose::identity(),
        ));
        cases.push((
            "bunny/turned copy".into(),
            bunny.clone(),
            bunny.clone(),
            turned(d),
        ));
        if let Some(fandisk) = mesh("fandisk.stl") {
            cases.push((
                "fandisk/turned copy".into(),
                fandisk.clone(),
                fandisk.clone(),
                turned(diagonal(&fandisk)),
            ));
            cases.push(("bunny/fandisk".into(), bunny, fandisk, Pose::identity()));
        }
    }
    for part in ["boeing.obj", "anchor.obj", "ALSTOM_TEST4.obj"] {
        if let Some(m) = mesh(&format!("cad/{part}")) {
            let d = diagonal(&m);
            cases.push((format!("{part}/turned copy"), m.clone(), m, turned(d)));
        }
    }
    let scratch =
        std::env::temp_dir().join(format!("obbtree-bench-hausdorff-{}", std::process::id()));
    std::fs::create_dir_all(&scratch).expect("scratch");
    println!(
        "{:<26} {:>8} {:>8} {:>12} {:>10} {:>10} {:>10} {:>8} {:>10} {:>10} {:>8}",
        "case",
        "tris A",
        "tris B",
        "h",
        "build ms",
        "exact ms",
        "e ms",
        "CGAL ms",
        "ratio e",
        "sample ms",
        "sample err"
    );
    let mut ratios = Vec::new();
    let options = BuildOptions {
        precision: Precision::F64,
        ..BuildOptions::default()
    };
    for (name, a, b, pose_b) in &cases {
        let started = Instant::now();
        let (ta, tb) = (
            build(a, &options, None).expect("builds"),
            build(b, &options, None).expect("builds"),
        );
        let build_s = started.elapsed().as_secs_f64();
        let e = 1e-4 * diagonal(a);
        let pa = Pose::identity();
        let run = |abs_err: f64| {
            let o = HausdorffOptions {
                abs_err,
                ..HausdorffOptions::default()
            };
            hausdorff(&ta, &pa, &tb, pose_b, &o).expect("answers")
        };
        let exact = run(0.0);
        let exact_s = median_time(|| {
            std::hint::black_box(run(0.0));
        });
        let bounded_s = median_time(|| {
            std::hint::black_box(run(e));
        });
        // The peer, on the same meshes and poses.
        let dir = scratch.join(name.replace('/', "-"));
        std::fs::create_dir_all(&dir).expect("case dir");
        std::fs::write(dir.join("a.obj"), common::obj_text(a)).expect("writes");
        std::fs::write(dir.join("b.obj"), common::obj_text(b)).expect("writes");
        std::fs::write(dir.join("poses.txt"), pose_line(&pa, pose_b) + "\n").expect("writes");
        let (e_text, samples) = (format!("{e:?}"), SAMPLES.to_string());
        let lines = run_peer_with(
            &peers,
            "bench_cgal_hausdorff",
            &dir,
            &["--error", &e_text, "--samples", &samples],
        );
        let line = pose_entry(&lines, 0);
        let (cgal, cgal_s) = (number(line, "bounded"), number(line, "bounded_s"));
        let (sampled, sampled_s) = (number(line, "sampled"), number(line, "sampled_s"));
        if let Some(c) = cgal {
            assert!(
                c >= exact.distance - e - 1e-12 && c <= exact.upper_bound + e + 1e-12,
                "{name}: CGAL {c} outside obbtree's [{}, {}] widened by {e}",
                exact.distance,
                exact.upper_bound
            );
        }
        if let Some(s) = sampled {
            assert!(
                s <= exact.upper_bound + 1e-12,
                "{name}: sampled {s} above {}",
                exact.upper_bound
            );
        }
        let ratio = cgal_s.map(|c| bounded_s / c);
        if let Some(r) = ratio {
            ratios.push(r);
        }
        let show =
            |v: Option<f64>, scale: f64| v.map_or("-".to_string(), |v| format!("{:.1}", v * scale));
        println!(
            "{:<26} {:>8} {:>8} {:>12.6e} {:>10.1} {:>10.2} {:>10.2} {:>8} {:>10} {:>10} {:>8}",
            name,
            a.faces().len(),
            b.faces().len(),
            exact.distance,
            build_s * 1e3,
            exact_s * 1e3,
            bounded_s * 1e3,
            show(cgal_s, 1e3),
            ratio.map_or("-".to_string(), |r| format!("{r:.3}")),
            show(sampled_s, 1e3),
            sampled.map_or("-".to_string(), |s| format!("{:.1e}", exact.distance - s)),
        );
    }
    if !ratios.is_empty() {
        let geomean = (ratios.iter().map(|r| r.ln()).sum::<f64>() / ratios.len() as f64).exp();
        let worst = ratios.iter().copied().fold(0.0, f64::max);
        println!("obbtree / CGAL at the same error, one thread: geomean {geomean:.3}, worst {worst:.3} ({} cases)", ratios.len());
    }
    std::fs::remove_dir_all(&scratch).ok();
}
