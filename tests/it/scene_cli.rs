//! `obbtree scene`: the shipped robot cell, its precomputed assets, and scenes and frames
//! that are wrong in every way the issue lists, each refused with one line naming the
//! file, the line and the field.
// Test code outside `#[test]` functions (helpers, property bodies): a failure is a failed test.
#![allow(clippy::unwrap_used, clippy::indexing_slicing)]

use crate::common;

use common::cli::{assert_bad_input, obbtree, scratch, stderr, ScratchDir};
use obbtree::build::{build, BuildOptions};
use obbtree::mesh::TriMesh;
use serde_json::Value;
use std::path::{Path, PathBuf};

fn shipped(name: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("assets/scenes")
        .join(name)
}

/// The shipped trees are what the builder makes of their meshes today, byte for byte:
/// the assets an app ships are reproducible from the repository.
#[test]
fn shipped_assets_rebuild_to_the_committed_bytes() {
    let mut checked = 0;
    for entry in std::fs::read_dir(shipped("")).unwrap() {
        let path = entry.unwrap().path();
        if path.extension().and_then(|e| e.to_str()) != Some("obbt") {
            continue;
        }
        let stem = path.file_stem().unwrap().to_str().unwrap();
        // The part is the bundled cow.
        let source = match stem {
            "cow" => shipped("../cow.obj"),
            _ => path.with_extension("obj"),
        };
        let mesh = TriMesh::load(&source).unwrap();
        let rebuilt = build(&mesh, &BuildOptions::default(), None).unwrap();
        let committed = std::fs::read(&path).unwrap();
        assert!(
            rebuilt.bytes() == committed.as_slice(),
            "{}",
            path.display()
        );
        checked += 1;
    }
    assert_eq!(checked, 9);
}

fn json_lines(stdout: &[u8]) -> Vec<Value> {
    String::from_utf8_lossy(stdout)
        .lines()
        .map(|l| serde_json::from_str(l).unwrap())
        .collect()
}

/// Witness fields may differ between the fast path and the reference; distances to
/// rounding.
fn comparable(mut frame: Value) -> Value {
    for pair in frame["pairs"].as_array_mut().unwrap() {
        let pair = pair.as_object_mut().unwrap();
        for key in ["witness", "tri_a", "tri_b"] {
            pair.remove(key);
        }
        for key in ["distance", "span"] {
            if let Some(v) = pair.get_mut(key) {
                *v = serde_json::json!((v.as_f64().unwrap() * 1e9).round() / 1e9);
            }
        }
    }
    frame
}

#[test]
fn the_shipped_cell_runs_and_agrees_with_the_reference() {
    let scene = shipped("cell.toml");
    let s = scene.to_str().unwrap();
    let fast = obbtree(&["scene", s, "--json"]);
    assert!(fast.status.success(), "{}", stderr(&fast));
    let naive = obbtree(&["scene", s, "--json", "--naive"]);
    assert!(naive.status.success(), "{}", stderr(&naive));
    let (fast, naive) = (json_lines(&fast.stdout), json_lines(&naive.stdout));
    assert_eq!(fast.len(), 241);
    assert_eq!(naive.len(), 241);
    for (k, (f, n)) in fast.iter().zip(&naive).take(240).enumerate() {
        assert_eq!(f["frame"], k);
        assert_eq!(comparable(f.clone()), comparable(n.clone()), "frame {k}");
    }
    let (fs, ns) = (&fast[240]["summary"], &naive[240]["summary"]);
    assert_eq!(fs["frames"], 240);
    assert_eq!(fs["objects"], 9);
    assert!(fs["culled"].as_u64().unwrap() > 0 && fs["reused"].as_u64().unwrap() > 0);
    let queries = |s: &Value| s["narrow"]["total"]["queries"].as_u64().unwrap();
    assert!(queries(fs) < queries(ns));
    // The story the cell tells: the gripper grasps the part, the arm passes the fence.
    let events: Vec<String> = fast
        .iter()
        .flat_map(|f| f["events"].as_array().cloned().unwrap_or_default())
        .map(|e| format!("{} {} {}", e["a"], e["b"], e["event"]).replace('"', ""))
        .collect();
    for expected in [
        "gripper part contact_started",
        "gripper part contact_ended",
        "gripper fence clearance_violated",
        "table part contact_started",
    ] {
        assert!(
            events.iter().any(|e| e == expected),
            "{expected}: {events:?}"
        );
    }
    // Text mode: events and the summary table; frames from standard input work too.
    let text = obbtree(&["scene", s]);
    let text = String::from_utf8_lossy(&text.stdout);
    assert!(text.contains("gripper / part: contact started"), "{text}");
    assert!(text.contains("summary (fast)"), "{text}");
    let mut child = std::process::Command::new(env!("CARGO_BIN_EXE_obbtree"))
        .args(["scene", s, "--frames", "-", "--json"])
        .stdin(std::fs::File::open(shipped("cell.jsonl")).unwrap())
        .output()
        .unwrap();
    assert!(child.status.success());
    let piped = json_lines(&std::mem::take(&mut child.stdout));
    assert_eq!(piped.len(), 241);
    assert_eq!(
        comparable(piped[117].clone()),
        comparable(fast[117].clone())
    );
}

const CUBE_OBJ: &str = "v -0.5 -0.5 -0.5\nv 0.5 -0.5 -0.5\nv -0.5 0.5 -0.5\nv 0.5 0.5 -0.5\n\
v -0.5 -0.5 0.5\nv 0.5 -0.5 0.5\nv -0.5 0.5 0.5\nv 0.5 0.5 0.5\n\
f 1 3 2\nf 2 3 4\nf 5 6 7\nf 6 8 7\nf 1 2 5\nf 2 6 5\nf 3 7 4\nf 4 7 8\nf 1 5 3\nf 3 5 7\nf 2 4 6\nf 4 8 6\n";

/// A scene directory with a cube mesh, an OBB tree of it and an AABB tree of it.
fn scene_dir(name: &str) -> ScratchDir {
    let dir = scratch(name);
    std::fs::write(dir.join("cube.obj"), CUBE_OBJ).unwrap();
    let obj = dir.join("cube.obj");
    for (out, bv, layout) in [
        ("cube.obbt", "obb", "fast"),
        ("cube-aabb.obbt", "aabb", "fast"),
        ("cube-compact.obbt", "obb", "compact"),
    ] {
        let o = obbtree(&[
            "build",
            obj.to_str().unwrap(),
            "-o",
            dir.join(out).to_str().unwrap(),
            "--bv",
            bv,
            "--layout",
            layout,
            "-q",
        ]);
        assert!(o.status.success(), "{}", stderr(&o));
    }
    std::fs::write(dir.join("corrupt.obbt"), b"\x89OBT\r\n\x1a\nnot really").unwrap();
    dir
}

const GOOD: &str = r#"[[object]]
name = "a"
asset = "cube.obbt"
groups = ["g"]

[[object]]
name = "b"
asset = "cube.obj"
pose = [1,0,0, 0,1,0, 0,0,1, 3,0,0]

[[rule]]
a = "a"
b = "g"
effect = "none"

[[rule]]
a = "*"
b = "*"
effect = "clearance"
clearance = 0.5
"#;

/// Writes `text` as a scene and runs it (with `frames` as its frames when given).
fn run(dir: &Path, text: &str, frames: Option<&str>) -> std::process::Output {
    run_with(dir, text, frames, &[])
}

/// [`run`] with more arguments for `obbtree scene`.
fn run_with(dir: &Path, text: &str, frames: Option<&str>, more: &[&str]) -> std::process::Output {
    let scene = dir.join("scene.toml");
    std::fs::write(&scene, text).unwrap();
    let mut args = vec![
        "scene".to_string(),
        scene.display().to_string(),
        "--json".into(),
    ];
    if let Some(f) = frames {
        let path = dir.join("frames.jsonl");
        std::fs::write(&path, f).unwrap();
        args.extend(["--frames".into(), path.display().to_string()]);
    }
    args.extend(more.iter().map(|&a| a.to_owned()));
    let refs: Vec<&str> = args.iter().map(String::as_str).collect();
    obbtree(&refs)
}

/// Runs [`GOOD`], then `GOOD` with its tree `cube.obbt` replaced by `asset`, on `frames`:
/// the JSON lines of each (the second run must succeed).
fn run_good_and_with_tree(dir: &Path, asset: &str, frames: &str) -> (Vec<Value>, Vec<Value>) {
    let good = run(dir, GOOD, Some(frames));
    let scene = GOOD.replace("asset = \"cube.obbt\"", &format!("asset = \"{asset}\""));
    let other = run(dir, &scene, Some(frames));
    assert!(other.status.success(), "{}", stderr(&other));
    (json_lines(&good.stdout), json_lines(&other.stdout))
}

#[test]
fn a_good_scene_from_a_mesh_and_a_tree_runs() {
    let dir = scene_dir("good");
    let frames = "{\"poses\": {\"b\": [1,0,0, 0,1,0, 0,0,1, 1.2,0,0]}}\n{\"poses\": {}}\n";
    let o = run(&dir, GOOD, Some(frames));
    assert!(o.status.success(), "{}", stderr(&o));
    let lines = json_lines(&o.stdout);
    assert_eq!(lines.len(), 3);
    // Frame 0: 0.2 apart, closer than 0.5; frame 1 reuses it.
    assert_eq!(lines[0]["events"][0]["event"], "clearance_violated");
    assert_eq!(lines[1]["pairs"], lines[0]["pairs"]);
    assert_eq!(lines[2]["summary"]["reused"], 1);
}

/// With `orthonormalize = true`, rotations written with four decimals are repaired, as by
/// the `--orthonormalize` flag, and reported as it reports them: once for the start poses
/// and once for the frames, naming the largest repair's line.
#[test]
fn repaired_rotations_are_noted_as_the_flag_notes_them() {
    let dir = scene_dir("repairs");
    let four = "0.8660,-0.5,0, 0.5,0.8660,0, 0,0,1";
    let scene = format!("orthonormalize = true\n{}", GOOD).replace(
        "pose = [1,0,0, 0,1,0, 0,0,1, 3,0,0]",
        &format!("pose = [{four}, 3,0,0]"),
    );
    let frames = format!(
        "{{\"poses\": {{\"b\": [{four}, 1.2,0,0]}}}}\n{{\"poses\": {{}}}}\n{{\"poses\": {{\"a\": [{four}, 0,0,0], \"b\": [0.8661,-0.5,0, 0.5,0.8661,0, 0,0,1, 1.2,0,0]}}}}\n"
    );
    let o = run(&dir, &scene, Some(&frames));
    assert!(o.status.success(), "{}", stderr(&o));
    let notes: Vec<&str> = std::str::from_utf8(&o.stderr).unwrap().lines().collect();
    assert_eq!(notes.len(), 2, "{notes:?}");
    assert!(
        notes[0].starts_with("obbtree: note: ")
            && notes[0].contains("scene.toml:10: object 2, field pose: rotation corrected by 1.9"),
        "{notes:?}"
    );
    assert!(
        notes[1].contains(
            "frames.jsonl: 3 rotations corrected by more than 1e-6, the most by 5.595e-5"
        ) && notes[1].ends_with("frames.jsonl:3: poses.b)"),
        "{notes:?}"
    );
    // Without the option the same rotation is refused, naming where.
    assert_bad_input(
        &run(
            &dir,
            &scene.replace("orthonormalize = true", ""),
            Some(&frames),
        ),
        "object 2, field pose",
    );
}

/// A distance rule with a maximum lists the pair while it is nearer than the maximum, and
/// not once it is farther.
#[test]
fn a_distance_rule_lists_pairs_within_its_maximum() {
    let dir = scene_dir("distance");
    let scene = GOOD.replace(
        "\"clearance\"\nclearance = 0.5",
        "\"distance\"\nmax_distance = 0.5",
    );
    // b 0.2 from a, then 2 from it.
    let frames = "{\"poses\": {\"b\": [1,0,0, 0,1,0, 0,0,1, 1.2,0,0]}}\n\
                  {\"poses\": {\"b\": [1,0,0, 0,1,0, 0,0,1, 3,0,0]}}\n";
    let o = run(&dir, &scene, Some(frames));
    assert!(o.status.success(), "{}", stderr(&o));
    let lines = json_lines(&o.stdout);
    let listed = |frame: &Value| frame["pairs"].as_array().unwrap().len();
    assert_eq!(listed(&lines[0]), 1, "{}", lines[0]);
    let d = lines[0]["pairs"][0]["distance"].as_f64().unwrap();
    assert!((d - 0.2).abs() < 1e-6, "{}", lines[0]);
    assert_eq!(listed(&lines[1]), 0, "{}", lines[1]);
}

/// Every effect, written in a scene file by its name (`Effect::name`) with its
/// parameters, is read back as that effect.
#[test]
fn every_effect_is_read_back_by_its_name() {
    use obbtree::scene::Effect;
    let dir = scene_dir("effects");
    let effects = [
        (Effect::None, ""),
        (Effect::Contact, ""),
        (Effect::Contacts, ""),
        (Effect::Clearance { clearance: 0.5 }, "clearance = 0.5"),
        (
            Effect::Distance {
                rel_err: 0.25,
                max_distance: Some(2.0),
            },
            "rel_err = 0.25\nmax_distance = 2.0",
        ),
        (
            Effect::Distance {
                rel_err: 0.0,
                max_distance: None,
            },
            "",
        ),
        (Effect::Span, ""),
    ];
    for (effect, parameters) in effects {
        let rule = format!("effect = \"{}\"\n{parameters}\n", effect.name());
        let text = GOOD.replace("effect = \"clearance\"\nclearance = 0.5\n", &rule);
        let path = dir.join("effect.toml");
        std::fs::write(&path, &text).unwrap();
        let loaded = obbtree::scene::load(&path).unwrap_or_else(|e| panic!("{text}\n{e}"));
        assert_eq!(loaded.scene.effect(0, 1), effect, "{text}");
    }
}

/// "Closer than the clearance" and "nearer than the maximum" are strict in the fast path
/// and the naive reference alike: cubes exactly that far apart are not listed, and a hair
/// nearer they are.
#[test]
fn a_gap_of_exactly_the_clearance_or_maximum_is_not_listed() {
    let dir = scene_dir("boundary");
    // Cubes of side 1; b's centre at x = 1.5 leaves a gap of exactly 0.5.
    let frames = "{\"poses\": {\"b\": [1,0,0, 0,1,0, 0,0,1, 1.5,0,0]}}\n\
                  {\"poses\": {\"b\": [1,0,0, 0,1,0, 0,0,1, 1.4999,0,0]}}\n";
    let distance = GOOD.replace(
        "\"clearance\"\nclearance = 0.5",
        "\"distance\"\nmax_distance = 0.5",
    );
    for (scene, effect) in [(GOOD.to_owned(), "clearance"), (distance, "distance")] {
        // Fast: the clearance stops at the violation in frame 1, the limited distance at
        // the maximum in frame 0; the reference never stops early.
        for (naive, early_exits) in [(false, 1), (true, 0)] {
            let more: &[&str] = if naive { &["--naive"] } else { &[] };
            let o = run_with(&dir, &scene, Some(frames), more);
            assert!(o.status.success(), "{}", stderr(&o));
            let lines = json_lines(&o.stdout);
            let listed = |l: &Value| l["pairs"].as_array().unwrap().len();
            assert_eq!(
                [listed(&lines[0]), listed(&lines[1])],
                [0, 1],
                "{effect} {naive}"
            );
            assert_eq!(lines[1]["pairs"][0]["effect"], effect);
            let summary = &lines[2]["summary"];
            assert_eq!(summary["early_exits"], early_exits, "{effect} {naive}");
        }
    }
}

/// A mesh beside a compact tree is built in the compact layout too, so the scene runs and
/// answers as with fast trees.
#[test]
fn a_mesh_beside_a_compact_tree_is_built_to_match() {
    let dir = scene_dir("compact");
    let frames = "{\"poses\": {\"b\": [1,0,0, 0,1,0, 0,0,1, 1.2,0,0]}}\n";
    let (fast, compact) = run_good_and_with_tree(&dir, "cube-compact.obbt", frames);
    assert_eq!(compact[0]["events"], fast[0]["events"]);
    assert_eq!(compact[1]["events"], fast[1]["events"]);
}

/// A tree is known by its signature whatever its file is called: a copy of `cube.obbt`
/// named `cube.tree` loads as that tree (not as a mesh of an unknown format) and answers
/// as it does.
#[test]
fn a_tree_is_known_by_its_signature_whatever_its_name() {
    let dir = scene_dir("signature");
    std::fs::copy(dir.join("cube.obbt"), dir.join("cube.tree")).unwrap();
    let frames = "{\"poses\": {\"b\": [1,0,0, 0,1,0, 0,0,1, 1.2,0,0]}}\n{\"poses\": {}}\n";
    let (named, renamed) = run_good_and_with_tree(&dir, "cube.tree", frames);
    // The two frames (the summary after them holds times).
    assert_eq!((renamed.len(), &renamed[..2]), (3, &named[..2]));
}

#[test]
fn bad_scenes_are_one_line_naming_file_line_and_field() {
    let dir = scene_dir("bad");
    let cases: Vec<(String, &str)> =
        vec![
        (
            GOOD.replace("b = \"g\"", "b = \"robto\""),
            "scene.toml:13: rule 1, field b: no object or group named \"robto\"",
        ),
        (
            GOOD.replace("a = \"a\"", "a = \"robto\""),
            "scene.toml:12: rule 1, field a: no object or group named \"robto\"",
        ),
        (
            GOOD.replace("name = \"b\"", "name = \"a\""),
            "scene.toml:7: object 2, field name: \"a\" is also object 1",
        ),
        (
            GOOD.replace("groups = [\"g\"]", "groups = [\"g\", \"\"]"),
            "scene.toml:4: object 1, field groups: \"\" is not a name of letters, digits, _ . -",
        ),
        (
            GOOD.replace("asset = \"cube.obj\"", "asset = \"missing.obbt\""),
            "scene.toml:8: object 2, field asset: ",
        ),
        (
            GOOD.replace("asset = \"cube.obj\"", "asset = \"corrupt.obbt\""),
            "scene.toml:8: object 2, field asset: ",
        ),
        (
            GOOD.replace("asset = \"cube.obj\"", "asset = \"cube-aabb.obbt\""),
            "scene.toml:8: object 2, field asset: object \"b\" stores aabb f32 but \"a\" stores obb f32",
        ),
        (
            GOOD.replace("effect = \"none\"", "effect = \"explode\""),
            "scene.toml:14: rule 1, field effect: unknown effect \"explode\"",
        ),
        (
            GOOD.replace("clearance = 0.5\n", ""),
            "scene.toml:19: rule 2, field clearance: effect \"clearance\" needs",
        ),
        (
            GOOD.replace("clearance = 0.5", "clearance = -1"),
            "scene.toml:20: rule 2, field clearance: must be a finite number > 0",
        ),
        (
            GOOD.replace("\"clearance\"\nclearance = 0.5", "\"distance\"\nrel_err = -0.1"),
            "scene.toml:20: rule 2, field rel_err: must be a finite number >= 0, got -0.1",
        ),
        (
            GOOD.replace("\"clearance\"\nclearance = 0.5", "\"distance\"\nmax_distance = 0"),
            "scene.toml:20: rule 2, field max_distance: must be a finite number > 0, got 0",
        ),
        (
            GOOD.replace("effect = \"none\"", "effect = \"none\"\nmax_distance = 2"),
            "scene.toml:15: rule 1, field max_distance: max_distance does not apply",
        ),
        (
            GOOD.replace("pose = [1,0,0,", "pose = [2,0,0,"),
            "scene.toml:9: object 2, field pose: rotation is not orthonormal",
        ),
        (
            GOOD.replace("name = \"b\"", "name = \"b c\""),
            "object 2, field name: \"b c\" is not a name",
        ),
        (
            GOOD.replace("groups = [\"g\"]", "grups = [\"g\"]"),
            "scene.toml:4: unknown field `grups`",
        ),
        (format!("{GOOD}\n[[rule]\n"), "scene.toml:22"),
    ];
    for (text, needle) in cases {
        let o = run(&dir, &text, None);
        assert_bad_input(&o, needle);
        assert!(o.stdout.is_empty());
    }
}

#[test]
fn bad_frames_stop_at_their_line_after_printing_the_frames_before() {
    let dir = scene_dir("badframes");
    let good = "{\"poses\": {\"b\": [1,0,0, 0,1,0, 0,0,1, 2,0,0]}}";
    let cases = [
        (
            "{\"poses\": {\"zed\": [1,0,0, 0,1,0, 0,0,1, 0,0,0]}}",
            "frames.jsonl:3: poses.zed: no object named \"zed\"",
        ),
        (
            "{\"poses\": {\"b\": [1,0,0, 0,1,0, 0,0,1, 0,0]}}",
            "frames.jsonl:3: poses.b: a pose in format rt has 12 numbers",
        ),
        (
            "{\"poses\": {\"b\": [-1,0,0, 0,1,0, 0,0,1, 0,0,0]}}",
            "frames.jsonl:3: poses.b: rotation has determinant",
        ),
        (
            "{\"poses\": {\"b\": [1,0,0, 0,1,0, 0,0,1.1, 0,0,0]}}",
            "frames.jsonl:3: poses.b: rotation is not orthonormal",
        ),
        (
            "{\"poses\": {\"b\": [1,0,0, 0,1,0, 0,0,1, 0,0,",
            "frames.jsonl:3: not a frame",
        ),
        (
            "{\"pose\": {}}",
            "frames.jsonl:3: not a frame: unknown field `pose`",
        ),
        ("", "frames.jsonl:3: empty line"),
        // A name holding a newline (JSON's `\n`) is escaped, not printed as a line break.
        (
            "{\"poses\": {\"x\\ny\": [1,0,0, 0,1,0, 0,0,1, 0,0,0]}}",
            "frames.jsonl:3: poses.x\\ny: no object named \"x\\ny\"",
        ),
        (
            "{\"x\\ny\": {}}",
            "frames.jsonl:3: not a frame: unknown field `x\\ny`",
        ),
    ];
    for (bad, needle) in cases {
        let o = run(
            &dir,
            GOOD,
            Some(&format!("{good}\n{good}\n{bad}\n{good}\n")),
        );
        assert_bad_input(&o, needle);
        // The two frames before the bad line were printed.
        assert_eq!(json_lines(&o.stdout).len(), 2, "{needle}");
    }
}
