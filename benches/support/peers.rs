//! Running the peer harnesses of `../shared/peers` and timing obbtree by their rule: what
//! the benchmarks against peers share.
// A benchmark of known-good inputs: a setup that fails is a broken benchmark, not bad input.
#![allow(dead_code, clippy::expect_used, clippy::indexing_slicing)]

use obbtree::query::Pose;
use serde_json::Value;
use std::path::Path;
use std::process::Command;
use std::time::Instant;

pub const MIN_RUNS: usize = 5;
pub const MIN_TIME: f64 = 0.02;

/// Median seconds per call of `f`, with the peers' rule (warm-up, then at least `MIN_RUNS`
/// calls and `MIN_TIME` seconds).
pub fn median_time(mut f: impl FnMut()) -> f64 {
    f();
    let mut times = Vec::new();
    let mut total = 0.0;
    while times.len() < MIN_RUNS || total < MIN_TIME {
        let t0 = Instant::now();
        f();
        let dt = t0.elapsed().as_secs_f64();
        times.push(dt);
        total += dt;
    }
    times.sort_by(f64::total_cmp);
    times[times.len() / 2]
}

/// One line of the poses file: `R_A T_A R_B T_B`, full precision.
pub fn pose_line(a: &Pose, b: &Pose) -> String {
    let mut numbers = Vec::new();
    for p in [a, b] {
        let r = p.rotation();
        for i in 0..3 {
            for j in 0..3 {
                numbers.push(r[(i, j)]);
            }
        }
        numbers.extend(p.translation_vector().iter());
    }
    let text: Vec<String> = numbers.iter().map(|v| format!("{v:?}")).collect();
    text.join(" ")
}

/// The JSON lines a peer prints for a case, or `None` when the peer is not built.
pub fn run_peer(dir: &Path, peer: &str, case: &Path) -> Option<Vec<Value>> {
    run_peer_with(dir, peer, case, &[])
}

/// [`run_peer`] with extra arguments (`--build-reps N`: only the median build times).
pub fn run_peer_with(dir: &Path, peer: &str, case: &Path, extra: &[&str]) -> Option<Vec<Value>> {
    let binary = dir.join(peer);
    if !binary.exists() {
        return None;
    }
    let output = Command::new(&binary)
        .arg(case.join("a.obj"))
        .arg(case.join("b.obj"))
        .arg(case.join("poses.txt"))
        .args(["--min-runs", &MIN_RUNS.to_string()])
        .args(["--min-time", &MIN_TIME.to_string()])
        .args(extra)
        .output()
        .expect("runs the peer");
    assert!(
        output.status.success(),
        "{peer} failed: {}",
        String::from_utf8_lossy(&output.stderr)
    );
    let text = String::from_utf8(output.stdout).expect("UTF-8");
    Some(
        text.lines()
            .map(|l| serde_json::from_str(l).expect("a JSON line"))
            .collect(),
    )
}

/// The line of pose `index` among a peer's lines.
pub fn pose_entry(lines: &Option<Vec<Value>>, index: usize) -> Option<&Value> {
    lines
        .as_ref()?
        .iter()
        .find(|v| v["pose"].as_u64() == Some(index as u64))
}

pub fn number(v: Option<&Value>, key: &str) -> Option<f64> {
    v?.get(key)?.as_f64()
}
