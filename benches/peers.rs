//! obbtree against RAPID, PQP and FCL in one run: the same meshes, the same poses, the same
//! timing rule, and the answers checked against each other.
//!
//! The peers are the harnesses of `../shared/peers` (`rapid-pqp/build.sh` and
//! `fcl/build.sh`), built outside the repository; this benchmark looks for `bench_rapid`,
//! `bench_pqp` and `bench_fcl_obj` in `$OBBTREE_PEERS` (default `/tmp/peers`) and skips a
//! peer it does not find. Each case writes its meshes and poses (24 numbers per line:
//! `R_A T_A R_B T_B`) to a scratch directory, runs every peer on them, and times obbtree in
//! this process with the peers' rule: one warm-up call, then repeat until at least
//! `MIN_RUNS` calls and `MIN_TIME` seconds, and take the median.
//!
//! Cases (trees with the defaults: OBB, f32, hull fit, leaf size 1):
//!
//! - `spheres`: the sliding spheres of §5.3.1 (40,000-triangle lat/long spheres, radii 1 and
//!   0.8, B at x = 0.2 … 2.2 with a seeded random rotation);
//! - `concentric`: spheres of radii 1 and 1.05, same centre (distance 0.05, the worst case
//!   of distance bounds);
//! - `bunny`, `fandisk`, `bunny-fandisk` (from `../shared/meshes`, skipped without them): B
//!   turned at random and moved along a random direction by 0.3, 0.6, 0.9, 1.2 and 3 times
//!   the larger model's bounding-box diagonal: touching, near and far poses;
//! - `boeing-ALSTOM_TEST4`, `anchor-boeing`, `ALSTOM_TEST4-ALSTOM_TEST4` (CAD parts of long
//!   thin triangles from `../shared/meshes/cad`, unit bounding spheres): 24 random poses,
//!   translations in a ball of radius 1.6.
//!
//! Printed: per pose the times and ratios; per query kind the geometric mean of the ratios
//! (obbtree / peer: below 1 is faster) and the worst case (the case whose ratios have the
//! largest geometric mean); build time and in-memory bytes per triangle. Run: `cargo bench --bench peers` (about 5 minutes with every peer).
// A benchmark of known-good inputs: a setup that fails is a broken benchmark, not bad input.
#![allow(clippy::expect_used, clippy::indexing_slicing)]

#[path = "../tests/common/mod.rs"]
mod common;
#[path = "support/peers.rs"]
mod peers;

use obbtree::build::{build, BuildOptions};
use obbtree::format::ObbtFile;
use obbtree::mesh::TriMesh;
use obbtree::query::{CollideOptions, DistanceOptions, PairQuery, Pose};
use peers::{median_time, number, pose_entry, pose_line, run_peer, run_peer_with};
use serde_json::Value;
use std::path::{Path, PathBuf};
use std::time::Instant;

struct Case {
    name: String,
    a: TriMesh,
    b: TriMesh,
    poses: Vec<(Pose, Pose)>,
}

/// obbtree's answers and times at one pose.
struct Ours {
    contacts: usize,
    first: bool,
    distance: f64,
    all_s: f64,
    first_s: f64,
    exact_s: f64,
    rel_s: f64,
    tri_tests: u64,
}

fn measure(pair: &mut PairQuery<'_>, pa: &Pose, pb: &Pose) -> Ours {
    let all = CollideOptions::default();
    let mut buffer = Default::default();
    pair.collide_into(pa, pb, &all, &mut buffer)
        .expect("collide");
    let contacts = buffer.pairs.len();
    // First contact into a buffer of its own, kept between calls as `all`'s is.
    let first_contact = CollideOptions {
        first_contact: true,
        ..CollideOptions::default()
    };
    let mut first_buffer = Default::default();
    pair.collide_into(pa, pb, &first_contact, &mut first_buffer)
        .expect("first");
    let first = first_buffer.colliding;
    let exact = DistanceOptions::default();
    let rel = DistanceOptions {
        rel_err: 0.01,
        ..DistanceOptions::default()
    };
    let d = pair.distance(pa, pb, &exact).expect("distance");
    let all_s = median_time(|| {
        pair.collide_into(pa, pb, &all, &mut buffer)
            .expect("collide");
    });
    let first_s = median_time(|| {
        pair.collide_into(pa, pb, &first_contact, &mut first_buffer)
            .expect("first");
        std::hint::black_box(first_buffer.pairs.first().copied());
    });
    let exact_s = median_time(|| {
        std::hint::black_box(pair.distance(pa, pb, &exact).expect("distance"));
    });
    let rel_s = median_time(|| {
        std::hint::black_box(pair.distance(pa, pb, &rel).expect("distance"));
    });
    Ours {
        contacts,
        first,
        distance: d.distance(),
        all_s,
        first_s,
        exact_s,
        rel_s,
        tri_tests: d.work.tri_contact + d.work.tri_separated,
    }
}

/// Ratios collected per query kind, for the geometric means.
#[derive(Default)]
struct Ratios {
    /// Per kind: each ratio and the case it came from.
    kinds: Vec<(&'static str, Vec<(f64, String)>)>,
    /// The case running.
    case: String,
}

impl Ratios {
    fn add(&mut self, kind: &'static str, ours: f64, peer: Option<f64>) -> String {
        let Some(peer) = peer.filter(|p| *p > 0.0) else {
            return "—".into();
        };
        let ratio = ours / peer;
        let case = self.case.clone();
        match self.kinds.iter_mut().find(|(k, _)| *k == kind) {
            Some((_, v)) => v.push((ratio, case)),
            None => self.kinds.push((kind, vec![(ratio, case)])),
        }
        format!("{ratio:.2}")
    }
}

/// Seconds as milliseconds with 4 significant digits (culled queries take 0.0001 ms).
/// Builds timed per case and thread count (the median is reported).
const BUILD_REPS: usize = 5;

fn ms(s: f64) -> String {
    if s >= 1e-3 {
        format!("{:.3}", s * 1e3)
    } else {
        format!("{:.2e}", s * 1e3)
    }
}

fn run_case(case: &Case, peers: &Path, scratch: &Path, ratios: &mut Ratios) {
    let dir = scratch.join(&case.name);
    std::fs::create_dir_all(&dir).expect("scratch");
    std::fs::write(dir.join("a.obj"), common::obj_text(&case.a)).expect("write");
    std::fs::write(dir.join("b.obj"), common::obj_text(&case.b)).expect("write");
    let lines: Vec<String> = case.poses.iter().map(|(a, b)| pose_line(a, b)).collect();
    std::fs::write(dir.join("poses.txt"), lines.join("\n") + "\n").expect("write");

    let rapid = run_peer(peers, "bench_rapid", &dir);
    let pqp = run_peer(peers, "bench_pqp", &dir);
    let fcl = run_peer(peers, "bench_fcl_obj", &dir);

    // Loaded back from the OBJ the peers read, so triangle ids and vertices agree.
    let a = TriMesh::load(&dir.join("a.obj")).expect("mesh A");
    let b = TriMesh::load(&dir.join("b.obj")).expect("mesh B");
    let options = BuildOptions::default();
    let build_both = || -> (ObbtFile, ObbtFile) {
        (
            build(&a, &options, None).expect("build"),
            build(&b, &options, None).expect("build"),
        )
    };
    // Median of BUILD_REPS builds of both models, with one thread and with two.
    let timed_build = |threads: usize| {
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .expect("a pool");
        let mut times: Vec<f64> = (0..BUILD_REPS)
            .map(|_| {
                let t0 = Instant::now();
                std::hint::black_box(pool.install(build_both));
                t0.elapsed().as_secs_f64()
            })
            .collect();
        times.sort_by(f64::total_cmp);
        times[times.len() / 2]
    };
    let (build_1, build_s) = (timed_build(1), timed_build(2));
    let (fa, fb) = build_both();
    let rapid_reps = run_peer_with(peers, "bench_rapid", &dir, &["--build-reps", "5"]);
    let rapid_build_median = rapid_reps
        .as_ref()
        .and_then(|l| l.iter().find(|v| v["kind"] == "build_reps"));
    let bytes =
        (fa.bytes().len() + fb.bytes().len()) as f64 / (a.faces().len() + b.faces().len()) as f64;
    let rapid_build = rapid
        .as_ref()
        .and_then(|l| l.iter().find(|v| v["kind"] == "build"));
    let pqp_build = pqp
        .as_ref()
        .and_then(|l| l.iter().find(|v| v["kind"] == "build"));
    let peer_build = |v: Option<&Value>| Some(number(v, "build_a_s")? + number(v, "build_b_s")?);
    let rapid_median = peer_build(rapid_build_median).or(peer_build(rapid_build));
    println!(
        "\n## {} ({} + {} triangles): build {} ms with 1 thread, {} ms with 2 (RAPID {} ms, ratios {} and {}); {:.0} B/triangle (RAPID {}, PQP {})",
        case.name,
        a.faces().len(),
        b.faces().len(),
        ms(build_1),
        ms(build_s),
        rapid_median.map_or("—".into(), ms),
        ratios.add("build (1 thread) / RAPID", build_1, rapid_median),
        ratios.add("build (2 threads) / RAPID", build_s, rapid_median),
        bytes,
        number(rapid_build, "used_bytes_per_tri_a").map_or("—".into(), |v| format!("{v:.0}")),
        number(pqp_build, "bytes_per_tri_a").map_or("—".into(), |v| format!("{v:.0}")),
    );
    println!(
        "{:>4} {:>9} {:>8} | {:>8} {:>8} {:>5} | {:>8} {:>8} {:>5} | {:>8} {:>8} {:>5} {:>7} {:>7} | {:>8} {:>8} {:>5} | {:>5} {:>5}",
        "pose", "contacts", "distance",
        "all ms", "RAPID", "×", "first", "RAPID", "×",
        "exact", "PQP", "×", "tris", "PQP", "rel .01", "PQP", "×", "×FCLc", "×FCLd"
    );
    let mut pair = PairQuery::new(&fa, &fb).expect("pair");
    for (i, (pa, pb)) in case.poses.iter().enumerate() {
        let ours = measure(&mut pair, pa, pb);
        let (r, p, f) = (
            pose_entry(&rapid, i),
            pose_entry(&pqp, i),
            pose_entry(&fcl, i),
        );
        // Answers must agree; a disagreement is a bug to look at, not a timing.
        if let Some(c) = number(r, "contacts") {
            assert_eq!(
                ours.contacts, c as usize,
                "{} pose {i}: contacts differ from RAPID",
                case.name
            );
        }
        if let Some(d) = number(p, "distance") {
            assert!(
                (ours.distance - d).abs() <= 1e-6 * (1.0 + d),
                "{} pose {i}: distance {} vs PQP {d}",
                case.name,
                ours.distance
            );
        }
        let touching = ours.distance == 0.0;
        let culled = !touching && ours.contacts == 0 && number(r, "box_tests") == Some(1.0);
        let all_kind = if culled {
            "culled at the roots / RAPID"
        } else {
            "collide all / RAPID"
        };
        let all_ratio = ratios.add(all_kind, ours.all_s, number(r, "all_s"));
        let first_ratio = if ours.first {
            ratios.add("first contact / RAPID", ours.first_s, number(r, "first_s"))
        } else {
            "—".into()
        };
        let exact_kind = if case.name == "concentric" {
            "distance, concentric / PQP"
        } else if touching {
            "distance, touching / PQP"
        } else {
            "distance, separated / PQP"
        };
        let exact_ratio = ratios.add(exact_kind, ours.exact_s, number(p, "exact_s"));
        let rel_ratio = ratios.add(
            "distance rel_err 0.01 / PQP",
            ours.rel_s,
            number(p, "rel_s"),
        );
        let fcl_c = ratios.add("collide all / FCL", ours.all_s, number(f, "collide_s"));
        let fcl_d = if touching {
            "—".into()
        } else {
            ratios.add(
                "distance, separated / FCL",
                ours.exact_s,
                number(f, "distance_s"),
            )
        };
        println!(
            "{i:>4} {:>9} {:>8.4} | {:>8} {:>8} {:>5} | {:>8} {:>8} {:>5} | {:>8} {:>8} {:>5} {:>7} {:>7} | {:>8} {:>8} {:>5} | {:>5} {:>5}",
            ours.contacts,
            ours.distance,
            ms(ours.all_s),
            number(r, "all_s").map_or("—".into(), ms),
            all_ratio,
            ms(ours.first_s),
            number(r, "first_s").map_or("—".into(), ms),
            first_ratio,
            ms(ours.exact_s),
            number(p, "exact_s").map_or("—".into(), ms),
            exact_ratio,
            ours.tri_tests,
            number(p, "tri_tests").map_or("—".into(), |v| format!("{v:.0}")),
            ms(ours.rel_s),
            number(p, "rel_s").map_or("—".into(), ms),
            rel_ratio,
            fcl_c,
            fcl_d,
        );
    }
}

/// B turned at random and moved by `scales` times the models' size along random directions.
fn posed_pairs(a: &TriMesh, b: &TriMesh, scales: &[f64], seed: u64) -> Vec<(Pose, Pose)> {
    let size = |m: &TriMesh| {
        let (mut lo, mut hi) = ([f64::INFINITY; 3], [f64::NEG_INFINITY; 3]);
        for p in m.vertices() {
            for k in 0..3 {
                lo[k] = lo[k].min(p[k]);
                hi[k] = hi[k].max(p[k]);
            }
        }
        ((0..3).map(|k| (hi[k] - lo[k]).powi(2)).sum::<f64>()).sqrt()
    };
    let centre = |m: &TriMesh| {
        let n = m.vertices().len() as f64;
        let mut c = [0.0; 3];
        for p in m.vertices() {
            for k in 0..3 {
                c[k] += p[k] / n;
            }
        }
        nalgebra::Vector3::from(c)
    };
    let d = size(a).max(size(b));
    let (ca, cb) = (centre(a), centre(b));
    let mut poses = Vec::new();
    for (k, s) in scales.iter().enumerate() {
        for trial in 0..2u64 {
            let seed = seed * 100 + k as u64 * 10 + trial;
            let r = common::rng::seeded_rotation(seed);
            let dir = common::rng::seeded_rotation(seed + 7) * nalgebra::Vector3::x();
            // B's centre lands at A's centre plus the offset.
            let t = ca + dir * (s * d) - r * cb;
            poses.push((Pose::identity(), Pose::new(r, t).expect("rotation")));
        }
    }
    poses
}

fn main() {
    if std::env::args().any(|a| a == "--list") {
        return;
    }
    let peers =
        PathBuf::from(std::env::var("OBBTREE_PEERS").unwrap_or_else(|_| "/tmp/peers".into()));
    for peer in ["bench_rapid", "bench_pqp", "bench_fcl_obj"] {
        if !peers.join(peer).exists() {
            println!(
                "{peer} not found in {} (see ../shared/peers): skipped",
                peers.display()
            );
        }
    }
    let scratch = std::env::temp_dir().join(format!("obbtree-peers-{}", std::process::id()));
    // Names given on the command line pick the cases whose name contains one of them.
    let filters: Vec<String> = std::env::args()
        .skip(1)
        .filter(|a| !a.starts_with('-'))
        .collect();
    let mut cases = vec![];
    let big = common::uv_sphere(1.0, 101, 200);
    let small = common::uv_sphere(0.8, 101, 200);
    let sliding: Vec<(Pose, Pose)> = (1..=11)
        .map(|k| (Pose::identity(), common::sliding_pose(0.2 * k as f64, k)))
        .collect();
    cases.push(Case {
        name: "spheres".into(),
        a: big.clone(),
        b: small,
        poses: sliding,
    });
    cases.push(Case {
        name: "concentric".into(),
        a: big,
        b: common::uv_sphere(1.05, 101, 200),
        poses: vec![(Pose::identity(), Pose::identity())],
    });
    let scales = [0.3, 0.6, 0.9, 1.2, 3.0];
    let shared = [
        ("bunny.obj", "bunny.obj"),
        ("fandisk.stl", "fandisk.stl"),
        ("bunny.obj", "fandisk.stl"),
    ];
    for (k, (na, nb)) in shared.into_iter().enumerate() {
        match (common::shared_mesh(na), common::shared_mesh(nb)) {
            (Some(a), Some(b)) => {
                let poses = posed_pairs(&a, &b, &scales, k as u64 + 1);
                let stem = |n: &str| n.split('.').next().unwrap_or(n).to_string();
                let name = if na == nb {
                    stem(na)
                } else {
                    format!("{}-{}", stem(na), stem(nb))
                };
                cases.push(Case { name, a, b, poses });
            }
            _ => println!("../shared/meshes/{na} or {nb} not found: case skipped"),
        }
    }
    // The CAD parts of issue 25 (long thin triangles; each normalised to a unit bounding
    // sphere), under the poses: `obbtree poses random --count 24 --radius 1.6 --seed 7`.
    let cad = [
        ("boeing", "ALSTOM_TEST4"),
        ("anchor", "boeing"),
        ("ALSTOM_TEST4", "ALSTOM_TEST4"),
    ];
    let cad_poses: Vec<(Pose, Pose)> = obbtree::generate::random_poses(24, 1.6, 7)
        .expect("poses")
        .into_iter()
        .map(|[a, b]| (a, b))
        .collect();
    for (na, nb) in cad {
        let load = |n: &str| common::shared_mesh(&format!("cad/{n}.obj"));
        match (load(na), load(nb)) {
            (Some(a), Some(b)) => cases.push(Case {
                name: format!("{na}-{nb}"),
                a,
                b,
                poses: cad_poses.clone(),
            }),
            _ => println!("../shared/meshes/cad/{na}.obj or {nb}.obj not found: case skipped"),
        }
    }
    let mut ratios = Ratios::default();
    for case in &cases {
        if !filters.is_empty() && !filters.iter().any(|f| case.name.contains(f.as_str())) {
            continue;
        }
        ratios.case.clone_from(&case.name);
        run_case(case, &peers, &scratch, &mut ratios);
    }
    if std::env::var_os("OBBTREE_PEERS_KEEP").is_none() {
        let _ = std::fs::remove_dir_all(&scratch);
    } else {
        println!("cases kept in {}", scratch.display());
    }
    println!(
        "\n## Geometric means of obbtree / peer (below 1: obbtree is faster), and the worst case"
    );
    for (kind, values) in &ratios.kinds {
        let gm = (values.iter().map(|(v, _)| v.ln()).sum::<f64>() / values.len() as f64).exp();
        // The worst case: the largest geometric mean of one case's ratios.
        let mut cases: Vec<&str> = values.iter().map(|(_, c)| c.as_str()).collect();
        cases.dedup();
        let worst = cases
            .iter()
            .map(|c| {
                let of: Vec<f64> = values
                    .iter()
                    .filter(|(_, k)| k == c)
                    .map(|(v, _)| v.ln())
                    .collect();
                ((of.iter().sum::<f64>() / of.len() as f64).exp(), *c)
            })
            .max_by(|x, y| x.0.total_cmp(&y.0))
            .expect("a ratio");
        let (lo, hi) = values
            .iter()
            .fold((f64::INFINITY, 0.0f64), |(l, h), (v, _)| {
                (l.min(*v), h.max(*v))
            });
        println!(
            "{kind:<32} {gm:>6.2}  worst case {:>5.2} ({})  (n = {:>3}, {lo:.2} … {hi:.2})",
            worst.0,
            worst.1,
            values.len()
        );
    }
}
