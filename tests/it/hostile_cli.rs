//! The `obbtree` binary on thousands of hostile inputs: damaged `.obbt` files, malformed OBJ
//! and STL meshes, and hostile poses. Every run must end in exit 0, or exit 1 with one line
//! on stderr that says what is wrong; never a panic, a signal (abort, stack overflow,
//! segfault) or a hang (each run has a 60 s deadline, far above its few milliseconds).
//!
//! The number of damaged files and meshes defaults to 300 each; the environment variable
//! `OBBTREE_HOSTILE_RUNS` sets it (docs/DEVELOPMENT.md quotes a long run).
// Test code outside `#[test]` functions (helpers, property bodies): a failure is a failed test.
#![allow(clippy::expect_used, clippy::panic, clippy::indexing_slicing)]

use crate::common;

use common::mutate::{
    entry_field, entry_offset, extreme_values, header_field, read_uint, write_uint, ENTRY_FIELDS,
    HEADER_FIELDS,
};
use common::rng::Rng;
use common::seal::seal;
use obbtree::build::{build, BuildOptions};
use obbtree::bv::BvKind;
use obbtree::real::Precision;
use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};
use std::sync::atomic::{AtomicUsize, Ordering};
use std::sync::Mutex;
use std::time::{Duration, Instant};

/// How long one run may take before it counts as a hang.
const DEADLINE: Duration = Duration::from_secs(60);

fn runs() -> usize {
    std::env::var("OBBTREE_HOSTILE_RUNS")
        .ok()
        .and_then(|v| v.parse().ok())
        .unwrap_or(300)
}

fn scratch(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("obbtree-hostile-{}-{name}", std::process::id()));
    std::fs::create_dir_all(&dir).expect("a scratch directory");
    dir
}

/// How one run ended.
#[derive(Debug)]
enum Ending {
    Ok,
    BadInput(String),
}

/// Runs the binary with `args`, enforcing the deadline and the exit-status contract.
fn obbtree(args: &[&str]) -> Ending {
    // (A file of its own, removed once read: the runs go on in parallel threads.)
    let stderr_path = std::env::temp_dir().join(format!(
        "obbtree-hostile-{}-stderr-{}",
        std::process::id(),
        COUNTER.fetch_add(1, Ordering::Relaxed)
    ));
    let stderr_file = std::fs::File::create(&stderr_path).expect("a stderr file");
    let mut child = Command::new(env!("CARGO_BIN_EXE_obbtree"))
        .args(args)
        .stdin(Stdio::null())
        .stdout(Stdio::null())
        .stderr(stderr_file)
        .spawn()
        .expect("the binary runs");
    let start = Instant::now();
    let status = loop {
        if let Some(status) = child.try_wait().expect("wait") {
            break status;
        }
        if start.elapsed() > DEADLINE {
            let _ = child.kill();
            let _ = child.wait();
            panic!("obbtree {args:?} hung (killed after {DEADLINE:?})");
        }
        std::thread::sleep(Duration::from_millis(1));
    };
    let stderr = std::fs::read_to_string(&stderr_path).unwrap_or_default();
    let _ = std::fs::remove_file(&stderr_path);
    match status.code() {
        Some(0) => Ending::Ok,
        Some(1) => {
            let lines: Vec<&str> = stderr.trim_end().lines().collect();
            assert!(
                lines.len() == 1 && lines[0].starts_with("obbtree: error: "),
                "obbtree {args:?}: exit 1 needs exactly one `obbtree: error:` line, got {stderr:?}"
            );
            assert!(!stderr.contains("panicked"), "obbtree {args:?}: {stderr}");
            Ending::BadInput(stderr)
        }
        other => panic!("obbtree {args:?} ended with {other:?} (signal or panic): {stderr}"),
    }
}

static COUNTER: AtomicUsize = AtomicUsize::new(0);

/// Runs `job` on every item from two worker threads (the machine has two cores).
fn in_parallel<T: Sync>(items: &[T], job: impl Fn(usize, &T) + Sync) {
    let next = AtomicUsize::new(0);
    std::thread::scope(|s| {
        for _ in 0..2 {
            s.spawn(|| loop {
                let i = next.fetch_add(1, Ordering::Relaxed);
                let Some(item) = items.get(i) else { break };
                job(i, item);
            });
        }
    });
}

/// Tallies of exit statuses, printed at the end of each suite.
#[derive(Default, Debug)]
struct Statuses {
    runs: usize,
    ok: usize,
    bad_input: usize,
}

impl Statuses {
    fn add(&mut self, e: &Ending) {
        self.runs += 1;
        match e {
            Ending::Ok => self.ok += 1,
            Ending::BadInput(_) => self.bad_input += 1,
        }
    }
}

// ---------------------------------------------------------------------------------------
// Damaged .obbt files
// ---------------------------------------------------------------------------------------

/// One seeded damage of `original`: a flip (raw or re-sealed), a truncation (raw or with
/// its length declared), an extreme header or directory value, or a rewritten node record.
fn damage(original: &[u8], rng: &mut Rng) -> (String, Vec<u8>) {
    let mut bytes = original.to_vec();
    let len = bytes.len();
    let what = match rng.below(8) {
        0 | 1 => {
            let i = rng.below(len);
            bytes[i] ^= 1 << rng.below(8);
            format!("flip at {i}")
        }
        2 | 3 => {
            for _ in 0..1 + rng.below(4) {
                let i = rng.below(len);
                bytes[i] = rng.next_u64() as u8;
            }
            seal(&mut bytes);
            "random bytes, re-sealed".to_string()
        }
        4 => {
            let cut = rng.below(len);
            bytes.truncate(cut);
            if cut >= 128 && rng.below(2) == 0 {
                let (at, width) = header_field("file_bytes");
                write_uint(&mut bytes, at, width, cut as u64);
                seal(&mut bytes);
            }
            format!("truncated at {cut}")
        }
        5 => {
            let (field, at, width) = HEADER_FIELDS[rng.below(HEADER_FIELDS.len())];
            let values = extreme_values(width, len as u64);
            let value = values[rng.below(values.len())];
            write_uint(&mut bytes, at, width, value);
            seal(&mut bytes);
            format!("header {field} = {value}")
        }
        6 => {
            let (count_at, count_width) = header_field("section_count");
            let sections = read_uint(&bytes, count_at, count_width) as usize;
            let index = rng.below(sections.max(1));
            let (field, at, width) = ENTRY_FIELDS[rng.below(ENTRY_FIELDS.len())];
            let values = extreme_values(width, len as u64);
            let value = values[rng.below(values.len())];
            write_uint(&mut bytes, entry_offset(index) + at, width, value);
            seal(&mut bytes);
            format!("entry {index} {field} = {value}")
        }
        _ => {
            // A 4-byte word inside the last section (the nodes), so packed references and
            // volumes get absurd values; re-sealed so that queries see them.
            let (offset_at, offset_width) = entry_field(3, "offset");
            let nodes_at = read_uint(&bytes, offset_at, offset_width) as usize;
            let at = (nodes_at + rng.below(len - nodes_at)) & !3;
            let value = [
                0,
                1,
                u64::from(u32::MAX),
                0x8000_0000,
                0x7fc0_0000,
                rng.next_u64(),
            ][rng.below(6)];
            write_uint(&mut bytes, at, 4, value);
            seal(&mut bytes);
            format!("node word at {at} = {value:#x}")
        }
    };
    (what, bytes)
}

/// Intact seeds of every volume type and both encodings, written to `dir`.
fn obbt_seeds(dir: &Path) -> Vec<Vec<u8>> {
    let mut seeds = Vec::new();
    for (bv, precision, leaf_size) in [
        (BvKind::Obb, Precision::F32, 1),
        (BvKind::Obb, Precision::F64, 4),
        (BvKind::Aabb, Precision::F32, 4),
        (BvKind::Sphere, Precision::F64, 1),
    ] {
        let options = BuildOptions {
            bv,
            precision,
            leaf_size,
            ..BuildOptions::default()
        };
        let file = build(&common::uv_sphere(1.0, 8, 12), &options, None).expect("builds");
        let path = dir.join(format!(
            "seed-{}-{}-{leaf_size}.obbt",
            bv.name(),
            precision.name()
        ));
        file.write_atomic(&path).expect("writes");
        seeds.push(file.bytes().to_vec());
    }
    seeds
}

const POSES: &str = "1 0 0 0 1 0 0 0 1 0 0 0  0 0 1 1 0 0 0 1 0 0.3 0.1 0\n\
                     1 0 0 0 1 0 0 0 1 0 0 0  1 0 0 0 1 0 0 0 1 2.5 0 0\n\
                     1 0 0 0 1 0 0 0 1 0 0 0  1 0 0 0 1 0 0 0 1 1e308 0 0\n";

#[test]
fn damaged_obbt_files_end_in_exit_0_or_1() {
    let dir = scratch("obbt");
    let seeds = obbt_seeds(&dir);
    let poses = dir.join("poses.txt");
    std::fs::write(&poses, POSES).expect("writes");
    let poses = poses.to_str().expect("a UTF-8 path").to_string();
    let count = runs();
    let files: Vec<(String, PathBuf, PathBuf)> = (0..count)
        .map(|i| {
            let mut rng = Rng::new(i as u64);
            let seed = i % seeds.len();
            let (what, bytes) = damage(&seeds[seed], &mut rng);
            let path = dir.join(format!("damaged-{i}.obbt"));
            std::fs::write(&path, bytes).expect("writes");
            let intact = dir.join(format!("intact-{seed}.obbt"));
            if !intact.exists() {
                std::fs::write(&intact, &seeds[seed]).expect("writes");
            }
            (what, path, intact)
        })
        .collect();
    let statuses = Mutex::new(Statuses::default());
    let verified = AtomicUsize::new(0);
    in_parallel(&files, |_, (what, path, intact)| {
        let f = path.to_str().expect("UTF-8");
        let g = intact.to_str().expect("UTF-8");
        let verify = obbtree(&["verify", f]);
        if matches!(verify, Ending::Ok) {
            verified.fetch_add(1, Ordering::Relaxed);
        }
        let endings = [
            obbtree(&["info", "--json", f]),
            obbtree(&["collide", f, f, "--poses", &poses, "--pairs"]),
            obbtree(&["collide", g, f, "--first", "--json"]),
            obbtree(&["distance", f, g, "--poses", &poses]),
            obbtree(&[
                "distance",
                f,
                f,
                "--tolerance",
                "0.1",
                "--pose-b",
                "1,0,0,0,1,0,0,0,1,2.5,0,0",
            ]),
            obbtree(&["span", f, f, "--json"]),
            verify,
        ];
        let mut s = statuses.lock().expect("not poisoned");
        for e in &endings {
            s.add(e);
        }
        // A damaged file that `open` refuses is refused by every command alike.
        if let Ending::BadInput(message) = &endings[0] {
            assert!(
                endings.iter().all(|e| matches!(e, Ending::BadInput(_))),
                "{what}: info refused it ({message}) but another command accepted it"
            );
        }
    });
    let s = statuses.into_inner().expect("not poisoned");
    println!(
        "{count} damaged .obbt files, {} runs: {} exit 0, {} exit 1; {} files still verify",
        s.runs,
        s.ok,
        s.bad_input,
        verified.into_inner()
    );
    let _ = std::fs::remove_dir_all(&dir);
}

// ---------------------------------------------------------------------------------------
// Malformed meshes
// ---------------------------------------------------------------------------------------

const OBJ_SEED: &str = "# a pyramid with a quad base\n\
    o pyramid\n\
    v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nv 0.5 0.5 1\n\
    vt 0 0\nvn 0 0 1\n\
    g sides\n\
    f 1 2 5\nf 2/1 3/1 5/1\nf 3//1 4//1 5//1\nf -2 -5 -1\n\
    g base\nusemtl none\n\
    f 1 4 3 2\n";

fn ascii_stl_seed() -> String {
    let mut s = String::from("solid tetra\n");
    for [a, b, c] in [
        [[0., 0., 0.], [1., 0., 0.], [0., 1., 0.]],
        [[0., 0., 0.], [0., 0., 1.], [1., 0., 0.]],
        [[0., 0., 0.], [0., 1., 0.], [0., 0., 1.]],
        [[1., 0., 0.], [0., 0., 1.], [0., 1., 0.]],
    ] {
        s += "  facet normal 0 0 0\n    outer loop\n";
        for p in [a, b, c] {
            s += &format!("      vertex {} {} {}\n", p[0], p[1], p[2]);
        }
        s += "    endloop\n  endfacet\n";
    }
    s + "endsolid tetra\n"
}

fn binary_stl_seed() -> Vec<u8> {
    let mesh = common::uv_sphere(1.0, 4, 6);
    let mut out = vec![0u8; 80];
    out.extend((mesh.faces().len() as u32).to_le_bytes());
    for f in mesh.faces() {
        out.extend([0u8; 12]);
        for &v in f {
            for c in mesh.vertices()[v as usize] {
                out.extend((c as f32).to_le_bytes());
            }
        }
        out.extend([0u8; 2]);
    }
    out
}

/// Tokens that stress a text parser when they replace a number or an index.
const HOSTILE_TOKENS: [&str; 14] = [
    "nan",
    "inf",
    "-inf",
    "1e999",
    "-0",
    "0",
    "-1",
    "4294967296",
    "-4294967297",
    "99999999999999999999",
    "1/2/3/4",
    "//",
    "",
    "\u{0}",
];

/// One seeded malformation of a text mesh: a token replaced, a line duplicated or dropped,
/// bytes flipped, a cut.
fn malform_text(seed: &str, rng: &mut Rng) -> Vec<u8> {
    let mut lines: Vec<String> = seed.lines().map(String::from).collect();
    match rng.below(5) {
        0 | 1 => {
            let l = rng.below(lines.len());
            let mut tokens: Vec<String> = lines[l].split(' ').map(String::from).collect();
            let t = rng.below(tokens.len());
            tokens[t] = HOSTILE_TOKENS[rng.below(HOSTILE_TOKENS.len())].to_string();
            lines[l] = tokens.join(" ");
        }
        2 => {
            let l = rng.below(lines.len());
            if rng.below(2) == 0 {
                lines.remove(l);
            } else {
                let copy = lines[l].clone();
                lines.insert(rng.below(lines.len()), copy);
            }
        }
        _ => {
            let mut bytes = lines.join("\n").into_bytes();
            return malform_bytes(&mut bytes, rng);
        }
    }
    lines.join("\n").into_bytes()
}

/// Flips a few bytes, or cuts the file, or (binary STL) lies about the triangle count.
fn malform_bytes(bytes: &mut Vec<u8>, rng: &mut Rng) -> Vec<u8> {
    match rng.below(3) {
        0 => {
            for _ in 0..1 + rng.below(3) {
                let i = rng.below(bytes.len());
                bytes[i] ^= 1 << rng.below(8);
            }
        }
        1 => bytes.truncate(rng.below(bytes.len())),
        _ if bytes.len() >= 84 => {
            let count = [0u32, 1, u32::MAX, 0x0400_0000, 178_956_971][rng.below(5)];
            bytes[80..84].copy_from_slice(&count.to_le_bytes());
        }
        _ => bytes.clear(),
    }
    bytes.clone()
}

#[test]
fn malformed_meshes_end_in_exit_0_or_1_and_what_builds_verifies() {
    let dir = scratch("meshes");
    let count = runs();
    let stl_text = ascii_stl_seed();
    let stl_binary = binary_stl_seed();
    let meshes: Vec<PathBuf> = (0..count)
        .map(|i| {
            let mut rng = Rng::new(1_000_000 + i as u64);
            let (ext, bytes) = match i % 3 {
                0 => ("obj", malform_text(OBJ_SEED, &mut rng)),
                1 => ("stl", malform_text(&stl_text, &mut rng)),
                _ => ("stl", malform_bytes(&mut stl_binary.clone(), &mut rng)),
            };
            let path = dir.join(format!("mesh-{i}.{ext}"));
            std::fs::write(&path, bytes).expect("writes");
            path
        })
        .collect();
    let statuses = Mutex::new(Statuses::default());
    in_parallel(&meshes, |i, mesh| {
        let m = mesh.to_str().expect("UTF-8");
        let out = dir.join(format!("built-{i}.obbt"));
        let o = out.to_str().expect("UTF-8");
        let built = obbtree(&["build", m, "-o", o, "--quiet"]);
        let mut endings = vec![];
        if matches!(built, Ending::Ok) {
            // What the builder accepts must be a sound file.
            let verify = obbtree(&["verify", o]);
            assert!(
                matches!(verify, Ending::Ok),
                "{m}: built but does not verify: {verify:?}"
            );
            endings.push(verify);
        } else {
            assert!(!out.exists(), "{m}: a failed build left {o} behind");
        }
        endings.push(obbtree(&[
            "collide",
            m,
            m,
            "--pose-b",
            "1,0,0,0,1,0,0,0,1,0.25,0,0",
        ]));
        endings.push(built);
        let mut s = statuses.lock().expect("not poisoned");
        for e in &endings {
            s.add(e);
        }
    });
    let s = statuses.into_inner().expect("not poisoned");
    println!(
        "{count} malformed meshes, {} runs: {} exit 0, {} exit 1",
        s.runs, s.ok, s.bad_input
    );
    let _ = std::fs::remove_dir_all(&dir);
}

// ---------------------------------------------------------------------------------------
// Hostile poses
// ---------------------------------------------------------------------------------------

#[test]
fn hostile_poses_are_refused_with_one_line_or_answered() {
    let dir = scratch("poses");
    let file = build(&common::cube(1.0), &BuildOptions::default(), None).expect("builds");
    let path = dir.join("cube.obbt");
    file.write_atomic(&path).expect("writes");
    let f = path.to_str().expect("UTF-8");
    let refused = [
        "1,0,0,0,1,0,0,0,1,0,0",         // 11 numbers
        "1,0,0,0,1,0,0,0,1,0,0,0,0",     // 13 numbers
        "1,0,0,0,1,0,0,0,1,nan,0,0",     // not finite
        "1,0,0,0,1,0,0,0,1,inf,0,0",     // not finite
        "1,0,0,0,1,0,0,0,1,1e999,0,0",   // overflows to infinity
        "2,0,0,0,1,0,0,0,1,0,0,0",       // not orthonormal
        "1,0,0,0,1,0,0,0,-1,0,0,0",      // a reflection
        "1.00001,0,0,0,1,0,0,0,1,0,0,0", // off by 1e-5
        "0,0,0,0,0,0,0,0,0,0,0,0",       // singular
        "1,0,0,0,1,0,0,0,1,0,0,x",       // not a number
        "",                              // nothing
    ];
    for pose in refused {
        for command in ["collide", "distance", "span"] {
            let e = obbtree(&[command, f, f, "--pose-b", pose]);
            assert!(
                matches!(e, Ending::BadInput(_)),
                "{command} --pose-b {pose:?}: {e:?}"
            );
        }
    }
    // Valid poses far out: translations that overflow the coordinates to infinity still
    // answer (no contact, infinite distance), never hang or crash.
    for pose in [
        "1,0,0,0,1,0,0,0,1,1e308,0,0",
        "1,0,0,0,1,0,0,0,1,-1.7e308,1.7e308,0",
        "1,0,0,0,1,0,0,0,1,1e-300,0,0",
        "0,-1,0,1,0,0,0,0,1,1e15,1e15,1e15",
        "1,0,0,0,1,0,0,0,1.0000002,0,0,0", // within the 1e-6 tolerance
    ] {
        for command in ["collide", "distance", "span"] {
            let e = obbtree(&[command, f, f, "--pose-b", pose, "--json"]);
            assert!(
                matches!(e, Ending::Ok),
                "{command} --pose-b {pose:?}: {e:?}"
            );
        }
    }
    let _ = std::fs::remove_dir_all(&dir);
}
