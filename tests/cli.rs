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
