//! The experiment tools from the command line (issue: chapter 5 as commands): generated
//! shapes and poses, batch controls (`--csv`, `--repeat`, `--threads`) and `info --levels`,
//! checked against the identities of the dissertation's chapter 2.

mod common;

use common::cli::{assert_bad_input, cow, obbtree, scratch, stderr};
use std::collections::HashMap;
use std::path::Path;

fn run(args: &[&str]) -> String {
    let o = obbtree(args);
    assert!(o.status.success(), "{args:?}: {}", stderr(&o));
    String::from_utf8(o.stdout).unwrap()
}

fn path(p: &Path) -> &str {
    p.to_str().unwrap()
}

/// CSV rows as maps from header to field.
fn rows(csv: &str) -> Vec<HashMap<String, String>> {
    let mut lines = csv.lines();
    let header: Vec<&str> = lines.next().expect("a header").split(',').collect();
    lines
        .map(|line| {
            let fields: Vec<&str> = line.split(',').collect();
            assert_eq!(fields.len(), header.len(), "{line}");
            header
                .iter()
                .zip(fields)
                .map(|(h, f)| (h.to_string(), f.to_string()))
                .collect()
        })
        .collect()
}

fn int(row: &HashMap<String, String>, key: &str) -> i64 {
    row[key]
        .parse()
        .unwrap_or_else(|_| panic!("{key} = {:?}", row[key]))
}

/// A small sliding-spheres experiment (§5.3.1 at 1/25 of the size): every row keeps the
/// BVTT identity 1 = D − I + 2S + 2K, makes at least the §2.6.3 least number of box tests,
/// and every volume type finds the same contacts.
#[test]
fn sliding_spheres_rows_keep_the_bvtt_identity_and_the_lower_bound_for_every_volume() {
    let dir = scratch("sliding");
    let (big, small, poses) = (
        dir.join("big.obj"),
        dir.join("small.obj"),
        dir.join("p.txt"),
    );
    run(&[
        "mesh",
        "sphere",
        "--stacks",
        "21",
        "--slices",
        "40",
        "-o",
        path(&big),
    ]);
    run(&[
        "mesh",
        "sphere",
        "--radius",
        "0.8",
        "--stacks",
        "21",
        "--slices",
        "40",
        "-o",
        path(&small),
    ]);
    run(&[
        "poses",
        "sweep",
        "--from",
        "0",
        "--to",
        "2",
        "--step",
        "0.05",
        "--rotation",
        "fresh",
        "--seed",
        "5",
        "-o",
        path(&poses),
    ]);
    let mut contacts_by_bv = Vec::new();
    for bv in ["obb", "aabb", "sphere"] {
        let csv = run(&[
            "collide",
            path(&big),
            path(&small),
            "--poses",
            path(&poses),
            "--csv",
            "--bv",
            bv,
            "--threads",
            "1",
            "--repeat",
            "2",
        ]);
        let rows = rows(&csv);
        assert_eq!(rows.len(), 41);
        let mut touching = 0;
        for (i, row) in rows.iter().enumerate() {
            assert_eq!(int(row, "pose"), i as i64);
            let (d, n, s, k) = (
                int(row, "bv_disjoint"),
                int(row, "bv_overlap"),
                int(row, "tri_separated"),
                int(row, "tri_contact"),
            );
            assert_eq!(d - n + 2 * s + 2 * k, 1, "{bv} pose {i}: {row:?}");
            assert_eq!(int(row, "bv_tests"), d + n);
            assert_eq!(int(row, "tri_tests"), s + k);
            assert_eq!(int(row, "contacts"), k);
            if k > 0 {
                touching += 1;
                let bound: f64 = row["bv_test_lower_bound"].parse().unwrap();
                let cells = 1600.0 * 1600.0;
                let expected = 2.0 * (cells / k as f64).log2() + 2.0 * k as f64 - 1.0;
                assert!((bound - expected).abs() < 1e-9 * expected);
                assert!((d + n) as f64 >= bound, "{bv} pose {i} below the bound");
            } else {
                assert_eq!(row["bv_test_lower_bound"], "");
            }
            assert!(row["seconds"].parse::<f64>().unwrap() >= 0.0);
        }
        // The spheres touch from about x = 0.2 to 1.8.
        assert!(
            (25..=35).contains(&touching),
            "{bv}: {touching} poses touch"
        );
        contacts_by_bv.push(rows.iter().map(|r| int(r, "contacts")).collect::<Vec<_>>());
    }
    assert_eq!(contacts_by_bv[0], contacts_by_bv[1]);
    assert_eq!(contacts_by_bv[0], contacts_by_bv[2]);
}

/// CSV and JSON lines report the same answers, for every query command.
#[test]
fn csv_rows_carry_what_json_lines_carry() {
    let dir = scratch("csv-json");
    let poses = dir.join("p.txt");
    run(&[
        "poses",
        "random",
        "--count",
        "6",
        "--radius",
        "0.6",
        "--seed",
        "2",
        "-o",
        path(&poses),
    ]);
    let cow = cow();
    for (command, extra, key) in [
        ("collide", vec![], "contacts"),
        ("distance", vec![], "distance"),
        (
            "distance",
            vec!["--tolerance", "0.05"],
            "closer_than_tolerance",
        ),
        ("span", vec![], "span"),
    ] {
        let mut args = vec![command, cow.as_str(), cow.as_str(), "--poses", path(&poses)];
        args.extend(extra.iter().copied());
        let json: Vec<serde_json::Value> = run(&args)
            .lines()
            .map(|l| serde_json::from_str(l).unwrap())
            .collect();
        args.push("--csv");
        let csv = rows(&run(&args));
        assert_eq!(json.len(), 6);
        assert_eq!(csv.len(), 6);
        for (j, c) in json.iter().zip(&csv) {
            match &j[key] {
                serde_json::Value::Null => assert_eq!(c[key], ""),
                // (serde_json's own parse of a float may be an ulp off: compare values.)
                serde_json::Value::Number(n) => {
                    let (shown, parsed) = (c[key].parse::<f64>().unwrap(), n.as_f64().unwrap());
                    assert!(
                        (shown - parsed).abs() <= 1e-15 * parsed.abs(),
                        "{command} {extra:?}"
                    );
                }
                other => assert_eq!(c[key], other.to_string(), "{command} {extra:?}"),
            }
            assert_eq!(c["bv_tests"], j["stats"]["bv_tests"].to_string());
        }
    }
}

/// `info --levels` on the cow: one root, the levels' nodes add up to the tree's, and the
/// mean box thickness shrinks level by level as Fig. 5.17 shows (by more than 1.5x over
/// every two levels in the middle of the tree, 2x on average; the cow's creases keep it
/// from the smooth surfaces' 4x).
#[test]
fn info_levels_count_every_node_and_show_boxes_thinning() {
    let dir = scratch("levels");
    let tree = dir.join("cow.obbt");
    run(&["build", &cow(), "-o", path(&tree), "--quiet"]);
    let info: serde_json::Value =
        serde_json::from_str(&run(&["info", "--json", "--levels", path(&tree)])).unwrap();
    let levels = info["levels"].as_array().unwrap();
    assert_eq!(levels.len() as u64, info["depth"].as_u64().unwrap());
    assert_eq!(levels[0]["nodes"], 1);
    let total: u64 = levels.iter().map(|l| l["nodes"].as_u64().unwrap()).sum();
    assert_eq!(total, info["nodes"].as_u64().unwrap());
    for l in levels {
        let (mean, max) = (
            l["thickness_mean"].as_f64().unwrap(),
            l["thickness_max"].as_f64().unwrap(),
        );
        assert!(mean <= max * (1.0 + 1e-12) && mean >= 0.0);
    }
    let middle: Vec<f64> = levels[4..10]
        .iter()
        .map(|l| l["thickness_shrink_over_two_levels"].as_f64().unwrap())
        .collect();
    assert!(middle.iter().all(|&s| s > 1.5), "{middle:?}");
    assert!(
        middle.iter().sum::<f64>() / middle.len() as f64 > 2.0,
        "{middle:?}"
    );
    let text = run(&["info", "--levels", path(&tree)]);
    assert!(text.contains("shrink"), "{text}");
}

/// Generated files are written only where asked, never over an existing file without
/// --force, and the same seed gives the same bytes.
#[test]
fn generators_replay_from_their_seed_and_refuse_bad_requests_in_one_line() {
    let dir = scratch("generators");
    let (a, b) = (dir.join("a.txt"), dir.join("b.txt"));
    run(&[
        "poses",
        "random",
        "--count",
        "20",
        "--radius",
        "2",
        "--seed",
        "11",
        "-o",
        path(&a),
    ]);
    run(&[
        "poses",
        "random",
        "--count",
        "20",
        "--radius",
        "2",
        "--seed",
        "11",
        "-o",
        path(&b),
    ]);
    assert_eq!(std::fs::read(&a).unwrap(), std::fs::read(&b).unwrap());
    let stdout = run(&[
        "poses", "random", "--count", "20", "--radius", "2", "--seed", "11",
    ]);
    assert_eq!(stdout.as_bytes(), std::fs::read(&a).unwrap());
    assert_bad_input(
        &obbtree(&[
            "poses",
            "random",
            "--count",
            "3",
            "--radius",
            "1",
            "-o",
            path(&a),
        ]),
        "refusing to replace",
    );
    run(&[
        "poses",
        "random",
        "--count",
        "3",
        "--radius",
        "1",
        "-o",
        path(&a),
        "--force",
    ]);
    assert_eq!(std::fs::read_to_string(&a).unwrap().lines().count(), 3);
    let mesh = dir.join("m.obj");
    assert_bad_input(
        &obbtree(&["mesh", "sphere", "--stacks", "1", "-o", path(&mesh)]),
        "stacks 1",
    );
    assert_bad_input(
        &obbtree(&["mesh", "plate", "--size", "1", "0", "-o", path(&mesh)]),
        "height 0",
    );
    assert_bad_input(
        &obbtree(&["mesh", "box", "-o", path(&dir.join("m.stl"))]),
        "OBJ",
    );
    assert_bad_input(
        &obbtree(&["poses", "sweep", "--from", "0", "--to", "1", "--step", "-1"]),
        "step -1",
    );
    assert_bad_input(
        &obbtree(&[
            "poses", "sweep", "--from", "0", "--to", "1e9", "--step", "1e-3",
        ]),
        "poses",
    );
    assert!(!mesh.exists());
    run(&["mesh", "box", "--half", "1", "2", "3", "-o", path(&mesh)]);
    let o = obbtree(&[
        "build",
        path(&mesh),
        "-o",
        path(&dir.join("m.obbt")),
        "--quiet",
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
}
