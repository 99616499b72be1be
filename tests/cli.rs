//! The command-line contract: exit statuses, one-line errors, `info --json` fields.

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

fn obbtree(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_obbtree"))
        .args(args)
        .output()
        .expect("the binary runs")
}

fn scratch(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("obbtree-cli-{}-{name}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

fn cow() -> String {
    concat!(env!("CARGO_MANIFEST_DIR"), "/assets/cow.obj").to_string()
}

fn stderr(o: &Output) -> String {
    String::from_utf8_lossy(&o.stderr).into_owned()
}

/// Exit 1 with exactly one line on stderr that contains `needle`.
fn assert_bad_input(o: &Output, needle: &str) {
    let err = stderr(o);
    assert_eq!(o.status.code(), Some(1), "stderr: {err}");
    assert_eq!(
        err.trim_end().lines().count(),
        1,
        "one line expected: {err}"
    );
    assert!(err.contains(needle), "{needle:?} not in {err:?}");
}

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
    std::fs::remove_dir_all(dir).unwrap();
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
    std::fs::remove_dir_all(dir).unwrap();
}

#[test]
fn two_builds_are_byte_identical() {
    let dir = scratch("determinism");
    build(&dir.join("a.obbt"), &["--leaf-size", "4"]);
    build(&dir.join("b.obbt"), &["--leaf-size", "4"]);
    assert!(
        std::fs::read(dir.join("a.obbt")).unwrap() == std::fs::read(dir.join("b.obbt")).unwrap()
    );
    std::fs::remove_dir_all(dir).unwrap();
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
    std::fs::remove_dir_all(dir).unwrap();
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
    std::fs::remove_dir_all(dir).unwrap();
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
        assert!(c["stats"][k].is_u64(), "stats.{k}");
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
    for k in ["point_a", "point_b", "stats", "seconds"] {
        assert!(!s[k].is_null(), "span lacks {k}");
    }
    std::fs::remove_dir_all(dir).unwrap();
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
    std::fs::write(&poses, format!("{identity} {identity}\n1 2 3\n")).unwrap();
    assert_bad_input(
        &obbtree(&["collide", f, f, "--poses", poses.to_str().unwrap()]),
        "poses.txt:2",
    );
    std::fs::remove_dir_all(dir).unwrap();
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
    assert_bad_input(&obbtree(&["distance", f, f, "--rel-err", "-1"]), "rel_err");
    let aabb = dir.join("aabb.obbt");
    build(&aabb, &["--bv", "aabb"]);
    assert_bad_input(&obbtree(&["span", f, aabb.to_str().unwrap()]), "differ");
    std::fs::remove_dir_all(dir).unwrap();
}

/// Writes the bundled cow as an OBJ in `dir`, every vertex `p` written as `factor · p + shift`
/// (shortest round-trip decimals), same faces.
fn cow_in_other_units(dir: &Path, factor: f64, shift: [f64; 3]) -> PathBuf {
    use std::fmt::Write;
    let mesh = obbtree::mesh::TriMesh::load(Path::new(&cow())).unwrap();
    let mut text = String::new();
    for v in mesh.vertices() {
        let [x, y, z]: [f64; 3] = std::array::from_fn(|k| factor * v[k] + shift[k]);
        writeln!(text, "v {x:?} {y:?} {z:?}").unwrap();
    }
    for f in mesh.faces() {
        writeln!(text, "f {} {} {}", f[0] + 1, f[1] + 1, f[2] + 1).unwrap();
    }
    let path = dir.join("cow-mm.obj");
    std::fs::write(&path, text).unwrap();
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
    std::fs::remove_dir_all(dir).unwrap();
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
    std::fs::remove_dir_all(dir).unwrap();
}
