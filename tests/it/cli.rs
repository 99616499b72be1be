//! The command-line contract: exit statuses, one-line errors, `info --json` fields.
// Test code outside `#[test]` functions (helpers, property bodies): a failure is a failed test.
#![allow(
    clippy::unwrap_used,
    clippy::expect_used,
    clippy::indexing_slicing,
    clippy::string_slice
)]

use crate::common;

use common::cli::{assert_bad_input, cow, obbtree, scratch, stderr};
use std::path::{Path, PathBuf};
use std::process::Command;

fn build(out: &Path, extra: &[&str]) {
    let mut args = vec!["build", &cow(), "-o", out.to_str().unwrap(), "--quiet"]
        .into_iter()
        .map(String::from)
        .collect::<Vec<_>>();
    args.extend(extra.iter().map(|s| s.to_string()));
    let refs: Vec<&str> = args.iter().map(String::as_str).collect();
    let o = obbtree(&refs);
    assert!(o.status.success(), "build {extra:?}: {}", stderr(&o));
}

#[test]
fn build_info_verify_on_the_bundled_cow() {
    let dir = scratch("basic");
    let out = dir.join("cow.obbt");
    build(&out, &[]);
    let o = obbtree(&["info", "--json", out.to_str().unwrap()]);
    assert!(o.status.success());
    let v: serde_json::Value = serde_json::from_slice(&o.stdout).expect("info --json prints JSON");
    assert_eq!(v["triangles"], 5804);
    assert_eq!(v["vertices"], 2904);
    assert_eq!(v["nodes"], 2 * 5804 - 1);
    assert_eq!(v["leaves"], 5804);
    for key in [
        "depth",
        "bv",
        "precision",
        "fit",
        "leaf_size",
        "encoding",
        "file_bytes",
        "bytes_per_triangle",
        "sections",
    ] {
        assert!(!v[key].is_null(), "info --json lacks {key}");
    }
    assert_eq!(v["bv"], "obb");
    assert_eq!(v["precision"], "f32");
    assert_eq!(v["fit"], "hull");
    assert_eq!(v["encoding"], "binary");
    assert_eq!(v["file_bytes"], std::fs::metadata(&out).unwrap().len());
    let names: Vec<&str> = v["sections"]
        .as_array()
        .unwrap()
        .iter()
        .map(|s| s["name"].as_str().unwrap())
        .collect();
    assert_eq!(names, ["vertices", "faces", "source_ids", "nodes"]);
    for s in v["sections"].as_array().unwrap() {
        assert_eq!(s["offset"].as_u64().unwrap() % 64, 0);
        assert!(s["bytes"].as_u64().is_some());
    }
    let o = obbtree(&["verify", out.to_str().unwrap()]);
    assert!(o.status.success(), "{}", stderr(&o));
    let text = obbtree(&["info", out.to_str().unwrap()]);
    assert!(String::from_utf8_lossy(&text.stdout).contains("5804"));
}

#[test]
fn every_volume_precision_and_leaf_size_builds_and_verifies() {
    let dir = scratch("options");
    for bv in ["obb", "aabb", "sphere"] {
        for precision in ["f32", "f64"] {
            for leaf in ["1", "4"] {
                for fit in ["hull", "triangles", "vertices"] {
                    let out = dir.join(format!("{bv}-{precision}-{leaf}-{fit}.obbt"));
                    build(
                        &out,
                        &[
                            "--bv",
                            bv,
                            "--precision",
                            precision,
                            "--leaf-size",
                            leaf,
                            "--fit",
                            fit,
                        ],
                    );
                    let o = obbtree(&["verify", out.to_str().unwrap()]);
                    assert!(
                        o.status.success(),
                        "{bv} {precision} {leaf} {fit}: {}",
                        stderr(&o)
                    );
                }
            }
        }
    }
}

#[test]
fn two_builds_are_byte_identical() {
    let dir = scratch("determinism");
    build(&dir.join("a.obbt"), &["--leaf-size", "4"]);
    build(&dir.join("b.obbt"), &["--leaf-size", "4"]);
    assert!(
        std::fs::read(dir.join("a.obbt")).unwrap() == std::fs::read(dir.join("b.obbt")).unwrap()
    );
}

#[test]
fn damaged_files_fail_with_one_line() {
    let dir = scratch("damage");
    let out = dir.join("cow.obbt");
    build(&out, &[]);
    let bytes = std::fs::read(&out).unwrap();
    let path = dir.join("damaged.obbt");
    let damaged = path.to_str().unwrap();
    // A flipped byte in the nodes section: open succeeds, verify names the section.
    let mut flipped = bytes.clone();
    let at = bytes.len() - 200;
    flipped[at] ^= 0x40;
    std::fs::write(&path, &flipped).unwrap();
    assert!(
        obbtree(&["info", damaged]).status.success(),
        "info reads only the header"
    );
    assert_bad_input(&obbtree(&["verify", damaged]), "nodes");
    // A flipped header byte: even info refuses.
    let mut header = bytes.clone();
    header[40] ^= 1;
    std::fs::write(&path, &header).unwrap();
    assert_bad_input(&obbtree(&["info", damaged]), "checksum");
    assert_bad_input(&obbtree(&["verify", damaged]), "checksum");
    // Truncated.
    std::fs::write(&path, &bytes[..bytes.len() / 2]).unwrap();
    assert_bad_input(&obbtree(&["info", damaged]), "damaged.obbt");
    std::fs::write(&path, &bytes[..10]).unwrap();
    assert_bad_input(&obbtree(&["info", damaged]), "truncated");
    std::fs::write(&path, b"").unwrap();
    assert_bad_input(&obbtree(&["verify", damaged]), "truncated");
    // Not an .obbt file at all.
    assert_bad_input(&obbtree(&["info", &cow()]), "signature");
}

#[test]
fn bad_input_is_exit_1_and_usage_errors_exit_2() {
    let dir = scratch("bad");
    let out = dir.join("x.obbt");
    let out = out.to_str().unwrap();
    assert_bad_input(
        &obbtree(&["info", "/nonexistent/file.obbt"]),
        "/nonexistent/file.obbt",
    );
    assert_bad_input(
        &obbtree(&["build", "/nonexistent/mesh.obj", "-o", out]),
        "/nonexistent/mesh.obj",
    );
    let broken = dir.join("broken.obj");
    std::fs::write(&broken, "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 9\n").unwrap();
    assert_bad_input(
        &obbtree(&["build", broken.to_str().unwrap(), "-o", out]),
        "broken.obj",
    );
    assert!(!Path::new(out).exists(), "a failed build writes nothing");
    assert_bad_input(
        &obbtree(&["build", &cow(), "-o", "/nonexistent/dir/x.obbt", "--quiet"]),
        "/nonexistent/dir/x.obbt",
    );
    assert_bad_input(
        &obbtree(&["build", &cow(), "-o", out, "--leaf-size", "0", "--quiet"]),
        "leaf size",
    );
    for args in [
        &["build", &cow()][..],
        &["build", &cow(), "-o", out, "--bv", "cone"],
        &["frobnicate"],
        &["info"],
    ] {
        let o = obbtree(args);
        assert_eq!(o.status.code(), Some(2), "{args:?}: {}", stderr(&o));
    }
}

#[test]
fn demo_runs() {
    let o = obbtree(&["demo"]);
    assert!(o.status.success(), "{}", stderr(&o));
    let text = String::from_utf8_lossy(&o.stdout);
    assert!(
        text.contains("5804 triangles") && text.contains("file == memory: yes"),
        "{text}"
    );
    assert!(text
        .trim_end()
        .ends_with("(run with --out DIR to keep the files)"));
    // With --out the files stay, and the last line no longer offers it; the directory is
    // made, never its missing parents, and a file in its place is refused.
    let dir = scratch("demo");
    let kept = dir.join("kept");
    let o = obbtree(&["demo", "--out", kept.to_str().expect("a path")]);
    assert!(o.status.success(), "{}", stderr(&o));
    assert!(!String::from_utf8_lossy(&o.stdout).contains("--out"));
    assert!(kept.join("cow-obb.obbt").is_file());
    let orphan = dir.join("missing").join("out");
    assert_bad_input(
        &obbtree(&["demo", "--out", orphan.to_str().expect("a path")]),
        "out: cannot create",
    );
    assert!(!dir.join("missing").exists());
    let file = dir.join("a-file");
    std::fs::write(&file, "x").expect("writes");
    assert_bad_input(
        &obbtree(&["demo", "--out", file.to_str().expect("a path")]),
        "a-file: exists and is not a directory",
    );
}

const SHIFT_X: &str = "1,0,0,0,1,0,0,0,1,0.2,0,0";

#[test]
fn collide_distance_span_print_the_contract_fields() {
    let dir = scratch("queries");
    let out = dir.join("cow.obbt");
    build(&out, &[]);
    let f = out.to_str().unwrap();
    let json = |args: &[&str]| -> serde_json::Value {
        let o = obbtree(args);
        assert!(o.status.success(), "{args:?}: {}", stderr(&o));
        serde_json::from_slice(&o.stdout).expect("one JSON object")
    };
    let stats_keys = [
        "bv_disjoint",
        "bv_overlap",
        "tri_separated",
        "tri_contact",
        "nodes_visited",
    ];
    let c = json(&["collide", f, f, "--pose-b", SHIFT_X, "--pairs", "--json"]);
    assert_eq!(c["colliding"], true);
    let pairs = c["pairs"].as_array().unwrap();
    assert_eq!(c["contacts"].as_u64().unwrap() as usize, pairs.len());
    let ids: Vec<(u64, u64)> = pairs
        .iter()
        .map(|p| (p[0].as_u64().unwrap(), p[1].as_u64().unwrap()))
        .collect();
    assert!(ids.windows(2).all(|w| w[0] < w[1]), "pairs are sorted");
    assert!(ids.iter().all(|&(a, b)| a < 5804 && b < 5804));
    for k in stats_keys {
        assert!(c["work"][k].is_u64(), "work.{k}");
    }
    assert!(c["seconds"].is_f64());
    // A mesh input is built in memory to match the other file, with the same answer.
    let m = json(&["collide", f, &cow(), "--pose-b", SHIFT_X, "--json"]);
    assert_eq!(m["contacts"], c["contacts"]);
    let first = json(&["collide", f, f, "--pose-b", SHIFT_X, "--first", "--json"]);
    assert_eq!(
        (first["colliding"].clone(), first["contacts"].clone()),
        (true.into(), 1.into())
    );

    let far = "1,0,0,0,1,0,0,0,1,3,0,0";
    let d = json(&["distance", f, f, "--pose-b", far, "--json"]);
    let distance = d["distance"].as_f64().unwrap();
    assert!(distance > 1.0 && distance < 3.0, "{distance}");
    let (pa, pb) = (&d["point_a"], &d["point_b"]);
    let gap: f64 = (0..3)
        .map(|k| (pa[k].as_f64().unwrap() - pb[k].as_f64().unwrap()).powi(2))
        .sum::<f64>()
        .sqrt();
    assert!((gap - distance).abs() < 1e-9);
    assert!(d["tri_a"].is_u64() && d["tri_b"].is_u64());
    let approx = json(&[
        "distance",
        f,
        f,
        "--pose-b",
        far,
        "--rel-err",
        "0.1",
        "--json",
    ]);
    let ad = approx["distance"].as_f64().unwrap();
    assert!(ad >= distance - 1e-12 && ad <= distance * 1.1 + 1e-12);
    let near = json(&[
        "distance",
        f,
        f,
        "--pose-b",
        far,
        "--tolerance",
        &(distance * 1.01).to_string(),
        "--json",
    ]);
    assert_eq!(near["closer_than_tolerance"], true);
    let not = json(&[
        "distance",
        f,
        f,
        "--pose-b",
        far,
        "--tolerance",
        &(distance * 0.99).to_string(),
        "--json",
    ]);
    assert_eq!(not["closer_than_tolerance"], false);

    let s = json(&["span", f, f, "--pose-b", far, "--json"]);
    assert!(s["span"].as_f64().unwrap() > 3.0);
    for k in ["point_a", "point_b", "work", "seconds"] {
        assert!(!s[k].is_null(), "span lacks {k}");
    }
}

#[test]
fn pose_batches_print_one_line_per_pose_in_order() {
    let dir = scratch("batch");
    let out = dir.join("cow.obbt");
    build(&out, &[]);
    let f = out.to_str().unwrap();
    let poses = dir.join("poses.txt");
    let identity = "1 0 0 0 1 0 0 0 1 0 0 0";
    let mut text = String::new();
    for k in 0..20 {
        text.push_str(&format!(
            "{identity}, 1,0,0,0,1,0,0,0,1,{},0,0\n",
            f64::from(k) * 0.1
        ));
        if k == 3 {
            text.push('\n');
        }
    }
    std::fs::write(&poses, text).unwrap();
    let o = obbtree(&["collide", f, f, "--poses", poses.to_str().unwrap()]);
    assert!(o.status.success(), "{}", stderr(&o));
    let lines: Vec<serde_json::Value> = String::from_utf8_lossy(&o.stdout)
        .lines()
        .map(|l| serde_json::from_str(l).unwrap())
        .collect();
    assert_eq!(lines.len(), 20);
    for (k, line) in lines.iter().enumerate() {
        assert_eq!(line["pose"], k);
        // The cow is about one unit long: shifted copies overlap, far ones do not.
        let single = obbtree(&[
            "collide",
            f,
            f,
            "--pose-b",
            &format!("1,0,0,0,1,0,0,0,1,{},0,0", k as f64 * 0.1),
            "--json",
        ]);
        let single: serde_json::Value = serde_json::from_slice(&single.stdout).unwrap();
        assert_eq!(line["contacts"], single["contacts"], "pose {k}");
    }
    // Errors name the line (from 1) and the pose (from 0, as the "pose" field does);
    // comments are skipped as blank lines are.
    std::fs::write(
        &poses,
        format!("# A then B\n{identity} {identity}\n\n1 2 3\n"),
    )
    .unwrap();
    assert_bad_input(
        &obbtree(&["collide", f, f, "--poses", poses.to_str().unwrap()]),
        "poses.txt: line 4 (pose 1): expected 24 numbers",
    );
    // A file with no poses is an error, not an empty answer; `-` reads standard input,
    // as --points and --rays do.
    std::fs::write(&poses, "# nothing yet\n\n").unwrap();
    assert_bad_input(
        &obbtree(&["collide", f, f, "--poses", poses.to_str().unwrap()]),
        "poses.txt: no poses",
    );
    let mut child = std::process::Command::new(env!("CARGO_BIN_EXE_obbtree"))
        .args(["collide", f, f, "--poses", "-", "--first"])
        .stdin(std::process::Stdio::piped())
        .stdout(std::process::Stdio::piped())
        .spawn()
        .unwrap();
    let stdin = child.stdin.take().unwrap();
    std::io::Write::write_all(
        &mut { stdin },
        format!("{identity} {identity}\n").as_bytes(),
    )
    .unwrap();
    let o = child.wait_with_output().unwrap();
    assert!(o.status.success());
    let line: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    assert_eq!(
        (&line["pose"], &line["colliding"]),
        (&0.into(), &true.into())
    );
    assert_bad_input(
        &obbtree(&["collide", f, f, "--poses", "missing.txt"]),
        "missing.txt: cannot read: ",
    );
    assert_bad_input(
        &obbtree(&["collide", "missing.obbt", f]),
        "missing.obbt: cannot read: ",
    );
}

#[test]
fn malformed_poses_and_mismatched_trees_are_exit_1() {
    let dir = scratch("badpose");
    let out = dir.join("cow.obbt");
    build(&out, &[]);
    let f = out.to_str().unwrap();
    assert_bad_input(
        &obbtree(&["collide", f, f, "--pose-b", "1,0,0,0,1,0,0,0,1,x,0,0"]),
        "--pose-b",
    );
    assert_bad_input(
        &obbtree(&["collide", f, f, "--pose-a", "1,0,0"]),
        "12 numbers",
    );
    assert_bad_input(
        &obbtree(&["collide", f, f, "--pose-b", "2,0,0,0,1,0,0,0,1,0,0,0"]),
        "orthonormal",
    );
    assert_bad_input(
        &obbtree(&["collide", f, f, "--pose-b", "-1,0,0,0,1,0,0,0,1,0,0,0"]),
        "reflection",
    );
    assert_bad_input(
        &obbtree(&["distance", f, f, "--pose-b", "1,0,0,0,1,0,0,0,1,NaN,0,0"]),
        "not finite",
    );
    assert_bad_input(
        &obbtree(&["distance", f, f, "--rel-err", "-1"]),
        "--rel-err must be",
    );
    let aabb = dir.join("aabb.obbt");
    build(&aabb, &["--bv", "aabb"]);
    assert_bad_input(&obbtree(&["span", f, aabb.to_str().unwrap()]), "differ");
}

// ---------------------------------------------------------------------------------------
// What the command writes: never its input, never a foreign file unless --force; closed
// pipes; interrupts.

#[test]
fn build_warns_when_f32_is_coarse_for_the_model_and_says_how_to_keep_it() {
    let dir = scratch("rounding");
    let far = dir.join("far.obj");
    let mesh = common::cow();
    let moved = mesh
        .vertices()
        .iter()
        .map(|p| [p[0] + 30_000.0, p[1] - 20_000.0, p[2] + 10_000.0])
        .collect();
    let moved = obbtree::mesh::TriMesh::new(moved, mesh.faces().to_vec()).unwrap();
    std::fs::write(&far, moved.to_obj()).unwrap();
    let out = dir.join("far.obbt");
    let run = |extra: &[&str]| {
        let mut args = vec!["build", far.to_str().unwrap(), "-o", out.to_str().unwrap()];
        args.extend_from_slice(extra);
        let o = obbtree(&args);
        assert!(o.status.success(), "{}", stderr(&o));
        stderr(&o)
    };
    // A warning, not a failure; shown with --quiet too, on one line.
    let warned = run(&["--quiet", "--force"]);
    let lines: Vec<&str> = warned.lines().collect();
    assert_eq!(lines.len(), 1, "{warned}");
    assert!(
        lines[0].starts_with("warning: stored coordinates up to 30000 in f32")
            && lines[0].contains(" collapsed to zero area: ")
            && lines[0].ends_with("build with --center or --precision f64 to keep the detail"),
        "{warned}"
    );
    for keeps in [&["--center"][..], &["--precision", "f64"]] {
        let quiet = run(&[&["--quiet", "--force"][..], keeps].concat());
        assert!(quiet.is_empty(), "{keeps:?}: {quiet}");
    }
    // The bundled cow at its origin: no warning.
    let o = obbtree(&["build", &cow(), "-o", out.to_str().unwrap(), "--quiet"]);
    assert!(
        o.status.success() && stderr(&o).is_empty(),
        "{}",
        stderr(&o)
    );
}

#[test]
fn build_never_overwrites_its_own_input() {
    let dir = scratch("victim");
    let victim = dir.join("victim.obj");
    std::fs::copy(cow(), &victim).unwrap();
    let original = std::fs::read(&victim).unwrap();
    let symlink = dir.join("link.obbt");
    std::os::unix::fs::symlink(&victim, &symlink).unwrap();
    let hardlink = dir.join("hard.obbt");
    std::fs::hard_link(&victim, &hardlink).unwrap();
    let dotted = dir.join(".").join("victim.obj");
    for output in [&victim, &dotted, &symlink, &hardlink] {
        for force in [false, true] {
            let mut args = vec!["build", victim.to_str().unwrap(), "-o"];
            args.push(output.to_str().unwrap());
            if force {
                args.push("--force");
            }
            assert_bad_input(&obbtree(&args), "refusing to overwrite");
            assert_eq!(std::fs::read(&victim).unwrap(), original, "{output:?}");
        }
    }
}

#[test]
fn build_replaces_a_file_that_is_not_obbt_only_with_force() {
    let dir = scratch("foreign");
    let notes = dir.join("notes.txt");
    std::fs::write(&notes, "my notes\n").unwrap();
    let args = ["build", &cow(), "-o", notes.to_str().unwrap(), "--quiet"];
    assert_bad_input(&obbtree(&args), "use --force");
    assert_eq!(std::fs::read(&notes).unwrap(), b"my notes\n");
    // An existing .obbt file is an earlier build: replaced without asking.
    let tree = dir.join("cow.obbt");
    build(&tree, &["--precision", "f64"]);
    build(&tree, &[]);
    let o = obbtree(&["info", "--json", tree.to_str().unwrap()]);
    let v: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    assert_eq!(v["precision"], "f32");
    let o = obbtree(&[&args[..], &["--force"]].concat());
    assert!(o.status.success(), "{}", stderr(&o));
    assert!(obbtree(&["verify", notes.to_str().unwrap()])
        .status
        .success());
    // A directory is never replaced.
    assert_bad_input(
        &obbtree(&["build", &cow(), "-o", dir.to_str().unwrap(), "--force"]),
        "is a directory",
    );
}

#[test]
fn unreadable_tree_inputs_get_the_readers_error() {
    let dir = scratch("unreadable");
    let empty = dir.join("empty.obbt");
    std::fs::write(&empty, b"").unwrap();
    let e = empty.to_str().unwrap();
    assert_bad_input(&obbtree(&["info", e]), "truncated: 0 bytes");
    // Named .obbt, so read as a tree even though its signature is missing.
    assert_bad_input(&obbtree(&["collide", &cow(), e]), "truncated: 0 bytes");
    assert_bad_input(
        &obbtree(&["info", dir.to_str().unwrap()]),
        "is a directory, not a .obbt file",
    );
}

/// Runs `args`, reads `keep` lines of its standard output, closes the pipe, and returns
/// the exit status and standard error.
fn run_into_closed_pipe(args: &[&str], keep: usize) -> (Option<i32>, String) {
    use std::io::{BufRead, Read};
    use std::process::Stdio;
    let mut child = Command::new(env!("CARGO_BIN_EXE_obbtree"))
        .args(args)
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    let mut reader = std::io::BufReader::new(child.stdout.take().unwrap());
    for _ in 0..keep {
        let mut line = String::new();
        reader.read_line(&mut line).unwrap();
    }
    drop(reader);
    let status = child.wait().unwrap();
    let mut err = String::new();
    child
        .stderr
        .take()
        .unwrap()
        .read_to_string(&mut err)
        .unwrap();
    (status.code(), err)
}

#[test]
fn a_closed_pipe_ends_quietly() {
    let dir = scratch("pipe");
    let tree = dir.join("cow.obbt");
    build(&tree, &[]);
    let t = tree.to_str().unwrap();
    let poses = dir.join("poses.txt");
    let line = "1 0 0 0 1 0 0 0 1 0 0 0 1 0 0 0 1 0 0 0 1 0.2 0 0\n";
    std::fs::write(&poses, line.repeat(2000)).unwrap();
    let out = dir.join("demo");
    for (args, keep) in [
        // 78,422 contact lines after the summary.
        (vec!["collide", t, t, "--pairs"], 2),
        (vec!["collide", t, t, "--poses", poses.to_str().unwrap()], 1),
        (vec!["demo", "--out", out.to_str().unwrap()], 1),
    ] {
        let (code, err) = run_into_closed_pipe(&args, keep);
        assert_eq!(code, Some(0), "{args:?}: {err}");
        assert!(err.is_empty(), "{args:?}: {err}");
    }
    // The demo finished its work although nobody read what it printed.
    for bv in ["obb", "aabb", "sphere"] {
        let file = out.join(format!("cow-{bv}.obbt"));
        assert!(obbtree(&["verify", file.to_str().unwrap()])
            .status
            .success());
    }
}

/// The files of `dir` whose names contain `.tmp`.
fn temporaries(dir: &Path) -> Vec<String> {
    std::fs::read_dir(dir)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .filter(|n| n.contains(".tmp"))
        .collect()
}

/// Writes a lat/long sphere of `2 * slices * (stacks - 1)` triangles as OBJ.
fn write_sphere_obj(path: &Path, stacks: u32, slices: u32) {
    std::fs::write(
        path,
        common::obj_text(&common::uv_sphere(1.0, stacks, slices)),
    )
    .unwrap();
}

fn interrupt(child: &std::process::Child, signal: &str) {
    let pid = child.id().to_string();
    assert!(Command::new("kill")
        .args([signal, &pid])
        .status()
        .unwrap()
        .success());
}

/// Ctrl-C while the output is being written (the temporary file exists) leaves neither
/// the output nor the temporary file; at any earlier point, nothing at all.
#[test]
fn an_interrupted_build_leaves_nothing_behind() {
    let dir = scratch("interrupt");
    let mesh = dir.join("sphere.obj");
    write_sphere_obj(&mesh, 300, 600); // 358,800 triangles, a 54 MB file
    let out = dir.join("sphere.obbt");
    let build_args = [
        "build",
        mesh.to_str().unwrap(),
        "-o",
        out.to_str().unwrap(),
        "--fit",
        "vertices",
        "--quiet",
    ];
    // While building: nothing is on disk yet, nothing is left.
    for signal in ["-INT", "-TERM"] {
        let child = Command::new(env!("CARGO_BIN_EXE_obbtree"))
            .args(build_args)
            .spawn()
            .unwrap();
        std::thread::sleep(std::time::Duration::from_millis(150));
        interrupt(&child, signal);
        let status = child.wait_with_output().unwrap().status;
        assert_eq!(status.code(), Some(130), "{signal}");
        assert!(!out.exists());
        assert_eq!(temporaries(&dir), Vec::<String>::new());
    }
    // While writing: caught the moment the temporary file appears. If the write wins the
    // race (it finished before the signal arrived), try again.
    let mut caught = false;
    for _ in 0..5 {
        let mut child = Command::new(env!("CARGO_BIN_EXE_obbtree"))
            .args(build_args)
            .spawn()
            .unwrap();
        while temporaries(&dir).is_empty() && child.try_wait().unwrap().is_none() {
            std::thread::sleep(std::time::Duration::from_micros(200));
        }
        if child.try_wait().unwrap().is_none() {
            interrupt(&child, "-INT");
        }
        let code = child.wait().unwrap().code();
        assert_eq!(temporaries(&dir), Vec::<String>::new());
        if code == Some(130) {
            assert!(!out.exists(), "an interrupted build left its output");
            caught = true;
            break;
        }
        assert_eq!(code, Some(0));
        std::fs::remove_file(&out).unwrap();
    }
    assert!(caught, "never interrupted while writing");
}

/// A build killed outright (SIGKILL, a power cut) cannot clean up; the next build of the
/// same output removes what it left.
#[test]
fn a_build_removes_temporaries_of_a_killed_build() {
    let dir = scratch("stale");
    let out = dir.join("cow.obbt");
    // A process id no process has: past the largest Linux allows by default.
    let stale = dir.join(".cow.obbt.4194305.0.tmp");
    std::fs::write(&stale, b"partial").unwrap();
    // Not ours to touch: another name, and a live process's temporary.
    let other = dir.join(".other.obbt.4194305.0.tmp");
    std::fs::write(&other, b"partial").unwrap();
    let live = dir.join(format!(".cow.obbt.{}.0.tmp", std::process::id()));
    std::fs::write(&live, b"partial").unwrap();
    build(&out, &[]);
    assert!(!stale.exists());
    assert!(other.exists() && live.exists());
}

/// One pose in every --pose-format gives the same answer; a rotation printed with 4
/// decimals is refused, or repaired with --orthonormalize and the repair reported.
#[test]
fn pose_formats_and_orthonormalize() {
    let dir = scratch("pose-formats");
    let tree = dir.join("cow.obbt");
    build(&tree, &[]);
    let t = tree.to_str().unwrap();
    // 30 degrees about z, then 2 along x.
    let (c, s) = (30f64.to_radians().cos(), 30f64.to_radians().sin());
    let (w, z) = (15f64.to_radians().cos(), 15f64.to_radians().sin());
    let forms = [
        ("rt", format!("{c},{},0,{s},{c},0,0,0,1,2,0,0", -s)),
        ("tq-wxyz", format!("2,0,0,{w},0,0,{z}")),
        ("tq-xyzw", format!("2 0 0 0 0 {z} {w}")),
        (
            "matrix4",
            format!("{c},{},0,2,{s},{c},0,0,0,0,1,0,0,0,0,1", -s),
        ),
    ];
    let distance = |extra: &[&str]| -> f64 {
        let o = obbtree(&[&["distance", t, t, "--json"], extra].concat());
        assert!(o.status.success(), "{extra:?}: {}", stderr(&o));
        let v: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
        v["distance"].as_f64().unwrap()
    };
    let reference = distance(&["--pose-b", &forms[0].1]);
    for (format, pose) in &forms {
        let d = distance(&["--pose-format", format, "--pose-b", pose]);
        assert!(
            (d - reference).abs() < 1e-12,
            "{format}: {d} vs {reference}"
        );
    }
    // Batches take the format too: 7 + 7 numbers a line.
    let poses = dir.join("tq.txt");
    std::fs::write(
        &poses,
        format!("0 0 0 1 0 0 0 {}\n", forms[1].1.replace(',', " ")),
    )
    .unwrap();
    let o = obbtree(&[
        "distance",
        t,
        t,
        "--pose-format",
        "tq-wxyz",
        "--poses",
        poses.to_str().unwrap(),
    ]);
    let v: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    assert!((v["distance"].as_f64().unwrap() - reference).abs() < 1e-12);
    // Four decimals: refused, then repaired with a note.
    let four = "0.8660,-0.5,0,0.5,0.8660,0,0,0,1,2,0,0";
    assert_bad_input(
        &obbtree(&["distance", t, t, "--pose-b", four]),
        "the orthonormalize option takes the nearest rotation",
    );
    let o = obbtree(&[
        "distance",
        t,
        t,
        "--pose-b",
        four,
        "--orthonormalize",
        "--json",
    ]);
    assert!(o.status.success());
    let note = stderr(&o);
    assert!(
        note.starts_with("obbtree: note: --pose-b: rotation corrected by 1.9"),
        "{note}"
    );
    let v: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    assert!((v["distance"].as_f64().unwrap() - reference).abs() < 1e-4);
    assert_bad_input(
        &obbtree(&[
            "distance",
            t,
            t,
            "--pose-format",
            "matrix4",
            "--pose-b",
            "1,0,0,2,0,1,0,0,0,0,1,0,0,0,1,1",
        ]),
        "0 0 0 1",
    );
}

/// Mesh-only flags are refused where they cannot apply; numbers and durations print as
/// people read them.
#[test]
fn flags_that_cannot_apply_and_readable_numbers() {
    let dir = scratch("readable");
    let tree = dir.join("cow.obbt");
    build(&tree, &[]);
    let t = tree.to_str().unwrap();
    assert_bad_input(
        &obbtree(&["collide", t, t, "--leaf-size", "4"]),
        "--leaf-size applies to mesh inputs only",
    );
    assert_bad_input(
        &obbtree(&["distance", t, &cow(), "--precision", "f64"]),
        "stores f32",
    );
    // A mesh paired with a tree may still choose its fit and leaf size.
    let o = obbtree(&[
        "collide",
        t,
        &cow(),
        "--fit",
        "vertices",
        "--leaf-size",
        "4",
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    // 1e300 away: not a 301-digit number.
    let o = obbtree(&["distance", t, t, "--pose-b", "1,0,0,0,1,0,0,0,1,1e300,0,0"]);
    let text = String::from_utf8_lossy(&o.stdout);
    assert!(text.starts_with("distance: 1e300 "), "{text}");
    let o = obbtree(&["info", t]);
    let text = String::from_utf8_lossy(&o.stdout);
    let bounds = text.lines().find(|l| l.contains("bounds")).unwrap();
    assert!(
        bounds
            .split(|c: char| !c.is_ascii_digit())
            .all(|digits| digits.len() <= 9),
        "f32 bounds print as f32: {bounds}"
    );
    assert!(text.contains("1 face per leaf"), "{text}");
    let o = obbtree(&["demo"]);
    let text = String::from_utf8_lossy(&o.stdout);
    assert!(!text.contains(" 0 us") && !text.contains(" 0 µs"), "{text}");
}

/// Writes the bundled cow as an OBJ in `dir`, every vertex `p` written as `factor · p + shift`
/// (shortest round-trip decimals), same faces.
fn cow_in_other_units(dir: &Path, factor: f64, shift: [f64; 3]) -> PathBuf {
    let mesh = obbtree::mesh::TriMesh::load(Path::new(&cow())).unwrap();
    let moved = mesh
        .vertices()
        .iter()
        .map(|v| std::array::from_fn(|k| factor * v[k] + shift[k]))
        .collect();
    let moved = obbtree::mesh::TriMesh::new(moved, mesh.faces().to_vec()).unwrap();
    let path = dir.join("cow-mm.obj");
    std::fs::write(&path, common::obj_text(&moved)).unwrap();
    path
}

/// `obbtree ARGS` must succeed and print one JSON object.
fn json_of(args: &[&str]) -> serde_json::Value {
    let o = obbtree(args);
    assert!(o.status.success(), "{args:?}: {}", stderr(&o));
    serde_json::from_slice(&o.stdout).expect("one JSON object")
}

#[test]
fn scale_and_center_are_recorded_shown_and_queried_together() {
    let dir = scratch("units");
    // The cow drawn in millimetres, 982 m out along -x (and 500 m, 3 m along y, z).
    let mm = cow_in_other_units(&dir, 1000.0, [-982_000.0, 500_000.0, 3000.0]);
    let placed = dir.join("placed.obbt");
    let plain = dir.join("plain.obbt");
    let (p, q) = (placed.to_str().unwrap(), plain.to_str().unwrap());
    let o = obbtree(&[
        "build",
        mm.to_str().unwrap(),
        "-o",
        p,
        "--scale",
        "0.001",
        "--center",
        "--precision",
        "f64",
        "--quiet",
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    build(&plain, &["--precision", "f64"]);
    assert!(obbtree(&["verify", p]).status.success());

    let info = json_of(&["info", "--json", p]);
    assert_eq!(info["version"], "1.1");
    assert_eq!(info["placement"]["scale"], 0.001);
    let offset: Vec<f64> = info["placement"]["offset"]
        .as_array()
        .unwrap()
        .iter()
        .map(|c| c.as_f64().unwrap())
        .collect();
    for (got, want) in offset.iter().zip([982.0, -500.0, -3.0]) {
        assert!((got - want).abs() < 1e-9, "offset {offset:?}");
    }
    // Stored in metres around the origin: the plain cow's bounds.
    let plain_info = json_of(&["info", "--json", q]);
    for end in ["min", "max"] {
        for k in 0..3 {
            let (got, want) = (
                info["bounds"][end][k].as_f64().unwrap(),
                plain_info["bounds"][end][k].as_f64().unwrap(),
            );
            assert!(
                (got - want).abs() < 1e-9,
                "bounds.{end}[{k}]: {got} vs {want}"
            );
        }
    }
    let sections = info["sections"].as_array().unwrap();
    assert_eq!(sections.last().unwrap()["name"], "placement");
    // Without the flags: version 1.0, the identity, no section.
    assert_eq!(plain_info["version"], "1.0");
    assert_eq!(
        plain_info["placement"],
        serde_json::json!({"scale": 1.0, "offset": [0.0, 0.0, 0.0]})
    );
    assert_eq!(plain_info["sections"].as_array().unwrap().len(), 4);

    let text = |file: &str| String::from_utf8_lossy(&obbtree(&["info", file]).stdout).into_owned();
    let placed_text = text(p);
    assert!(
        placed_text.contains("placement      scale 0.001, offset [")
            && placed_text.contains("(stored = scale · input + offset)"),
        "{placed_text}"
    );
    assert!(text(q).contains("placement      none"), "{}", text(q));

    // The model made in millimetres far away answers as the one made in metres at home.
    // (A generic rotation: with an exact one such as a quarter turn, some triangle pairs
    // touch exactly, and the rounding of any placement, even a scale of 1 + 2e-16, flips
    // them.)
    let rotation = nalgebra::Rotation3::from_euler_angles(0.3, -0.2, 0.5);
    let pose = |t: [f64; 3]| {
        let r = rotation.matrix();
        let numbers: Vec<String> = (0..3)
            .flat_map(|i| (0..3).map(move |j| r[(i, j)]))
            .chain(t)
            .map(|c| format!("{c:?}"))
            .collect();
        numbers.join(",")
    };
    let (turned, far) = (pose([0.2, 0.05, 0.01]), pose([1.5, 0.3, 0.0]));
    let (turned, far) = (turned.as_str(), far.as_str());
    let contacts =
        |a: &str| json_of(&["collide", a, q, "--pose-b", turned, "--json"])["contacts"].clone();
    assert!(contacts(q).as_u64().unwrap() > 0);
    assert_eq!(contacts(p), contacts(q));
    let distance = |a: &str| {
        json_of(&["distance", a, q, "--pose-b", far, "--json"])["distance"]
            .as_f64()
            .unwrap()
    };
    let (got, want) = (distance(p), distance(q));
    assert!(
        want > 0.0 && (got - want).abs() <= 1e-9 * want,
        "{got} vs {want}"
    );

    // A flipped byte of the placement record: info still reads the header, verify refuses.
    let mut bytes = std::fs::read(&placed).unwrap();
    let at = sections.last().unwrap()["offset"].as_u64().unwrap() as usize;
    bytes[at + 3] ^= 0x04;
    let damaged = dir.join("damaged.obbt");
    std::fs::write(&damaged, &bytes).unwrap();
    assert_bad_input(
        &obbtree(&["verify", damaged.to_str().unwrap()]),
        "placement",
    );
}

#[test]
fn bad_scales_are_exit_1_naming_the_flag() {
    let dir = scratch("badscale");
    let out = dir.join("x.obbt");
    let out = out.to_str().unwrap();
    for scale in ["0", "nan", "-1", "-inf", "inf", "1e-400"] {
        assert_bad_input(
            &obbtree(&["build", &cow(), "-o", out, "--scale", scale, "--quiet"]),
            "--scale",
        );
        assert!(!Path::new(out).exists(), "a refused build writes nothing");
    }
    // The options are checked before the mesh is read.
    assert_bad_input(
        &obbtree(&["build", "/nonexistent/mesh.obj", "-o", out, "--scale", "0"]),
        "--scale",
    );
    // Not a number at all is a usage error, like any malformed value.
    let o = obbtree(&["build", &cow(), "-o", out, "--scale", "ten"]);
    assert_eq!(o.status.code(), Some(2), "{}", stderr(&o));
}

#[test]
fn build_help_states_the_library_defaults() {
    let o = obbtree(&["build", "--help"]);
    assert!(o.status.success());
    let help = String::from_utf8_lossy(&o.stdout).replace('\n', " ");
    let defaults = obbtree::build::BuildOptions::default();
    for (flag, value) in [
        ("--hull-min-faces", defaults.hull_min_faces.to_string()),
        ("--hull-max-points", defaults.hull_max_points.to_string()),
        ("--leaf-size", defaults.leaf_size.to_string()),
        (
            "--model-axes",
            if defaults.model_axes { "yes" } else { "no" }.to_string(),
        ),
        (
            "--split-by-volume",
            if defaults.split_by_volume {
                "yes"
            } else {
                "no"
            }
            .to_string(),
        ),
        ("--layout", defaults.layout.name().to_string()),
    ] {
        // The flag's own entry (`--flag <VALUE>`), not a mention in another's text.
        let at = help
            .find(&format!("{flag} <"))
            .unwrap_or_else(|| panic!("{flag} in the help"));
        let rest = &help[at..];
        let end = rest.find("[default: ").expect("a stated default");
        // `[default: V]`, or `[default: V; ...]` when another flag changes it.
        assert!(
            [']', ';']
                .iter()
                .any(|close| rest[end..].starts_with(&format!("[default: {value}{close}"))),
            "{flag}: {}",
            &rest[end..end + 20]
        );
    }
    let compact = obbtree::bv::Layout::Compact.default_leaf_size();
    assert!(
        help.contains(&format!("{compact} with --layout compact]")),
        "{help}"
    );
}

#[test]
fn hull_min_faces_changes_the_tree_and_one_fits_every_node_to_its_hull() {
    let dir = scratch("hull_min");
    let (default, everywhere, five) = (
        dir.join("default.obbt"),
        dir.join("everywhere.obbt"),
        dir.join("five.obbt"),
    );
    build(&default, &[]);
    build(&everywhere, &["--hull-min-faces", "1"]);
    build(&five, &["--hull-min-faces", "5"]);
    let bytes = |p: &Path| std::fs::read(p).unwrap();
    assert_ne!(bytes(&default), bytes(&everywhere));
    assert_ne!(
        bytes(&five),
        bytes(&everywhere),
        "nodes of 2 to 4 faces differ"
    );
    for p in [&default, &everywhere, &five] {
        let o = obbtree(&["verify", p.to_str().unwrap()]);
        assert!(o.status.success(), "{}", stderr(&o));
    }
}

#[test]
fn hull_options_out_of_range_or_without_the_hull_fit_are_exit_1() {
    let dir = scratch("hull_bad");
    let out = dir.join("x.obbt");
    let out = out.to_str().unwrap();
    let cow = cow();
    for (extra, needle) in [
        (&["--hull-max-points", "3"][..], "--hull-max-points"),
        (&["--hull-min-faces", "0"][..], "--hull-min-faces"),
        (
            &["--fit", "triangles", "--hull-min-faces", "5"][..],
            "applies to --fit hull only",
        ),
        (
            &["--fit", "vertices", "--hull-max-points", "all"][..],
            "applies to --fit hull only",
        ),
    ] {
        let mut args = vec!["build", cow.as_str(), "-o", out, "--quiet"];
        args.extend_from_slice(extra);
        assert_bad_input(&obbtree(&args), needle);
        assert!(!Path::new(out).exists(), "{extra:?} wrote a file");
    }
    // `all` is every vertex.
    let (all, max) = (dir.join("all.obbt"), dir.join("max.obbt"));
    build(&all, &["--hull-max-points", "all"]);
    build(&max, &["--hull-max-points", "4294967295"]);
    assert_eq!(std::fs::read(&all).unwrap(), std::fs::read(&max).unwrap());
}

#[test]
fn model_axes_and_split_by_volume_no_change_the_tree_and_other_words_are_refused() {
    for flag in ["--model-axes", "--split-by-volume"] {
        yes_no_flag_changes_the_tree(flag);
    }
}

/// `flag no` builds another tree than the default, both verify, and a word other than
/// yes or no is refused naming the flag, writing nothing.
fn yes_no_flag_changes_the_tree(flag: &str) {
    let dir = scratch(&flag.replace('-', ""));
    let (default, fitted) = (dir.join("default.obbt"), dir.join("fitted.obbt"));
    build(&default, &[]);
    build(&fitted, &[flag, "no"]);
    assert_ne!(
        std::fs::read(&default).unwrap(),
        std::fs::read(&fitted).unwrap()
    );
    for p in [&default, &fitted] {
        let o = obbtree(&["verify", p.to_str().unwrap()]);
        assert!(o.status.success(), "{}", stderr(&o));
    }
    let out = dir.join("bad.obbt");
    let o = obbtree(&[
        "build",
        cow().as_str(),
        "-o",
        out.to_str().unwrap(),
        flag,
        "maybe",
    ]);
    assert!(!o.status.success());
    assert!(stderr(&o).contains(flag), "{}", stderr(&o));
    assert!(!out.exists());
}

/// `distance --max-distance D` answers as the library's maximum does: models at least D
/// apart print "beyond D" after one volume test, nearer ones the same distance as without.
#[test]
fn distance_with_a_maximum_prints_beyond_it() {
    let dir = scratch("max-distance");
    let out = dir.join("cow.obbt");
    build(&out, &[]);
    let f = out.to_str().unwrap();
    let apart = "1,0,0,0,1,0,0,0,1,2,0,0";
    let json = |extra: &[&str]| -> serde_json::Value {
        let mut args = vec!["distance", f, f, "--pose-b", apart, "--json"];
        args.extend(extra);
        let o = obbtree(&args);
        assert!(o.status.success(), "{}", stderr(&o));
        serde_json::from_slice(&o.stdout).unwrap()
    };
    let beyond = json(&["--max-distance", "0.5"]);
    assert_eq!(beyond["distance"], serde_json::Value::Null, "{beyond}");
    assert_eq!(beyond["beyond"], 0.5);
    assert_eq!(beyond["work"]["bv_tests"], 1);
    let exact = json(&[]);
    assert_eq!(
        json(&["--max-distance", "5"])["distance"],
        exact["distance"]
    );
    let text = obbtree(&["distance", f, f, "--pose-b", apart, "--max-distance", "0.5"]);
    assert!(String::from_utf8_lossy(&text.stdout).starts_with("distance: beyond 0.5 ("));
    assert_bad_input(
        &obbtree(&["distance", f, f, "--max-distance", "-1"]),
        "--max-distance must be",
    );
}
