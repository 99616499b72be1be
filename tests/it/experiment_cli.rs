//! The experiment tools from the command line (issue: chapter 5 as commands): generated
//! shapes and poses, batch controls (`--csv`, `--repeat`, `--threads`) and `info --levels`,
//! checked against the identities of the dissertation's chapter 2.
// Test code outside `#[test]` functions (helpers, property bodies): a failure is a failed test.
#![allow(
    clippy::unwrap_used,
    clippy::expect_used,
    clippy::panic,
    clippy::indexing_slicing
)]

use crate::common;

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

/// A CSV row: header to field.
type Row = HashMap<String, String>;

/// CSV rows as maps from header to field.
fn rows(csv: &str) -> Vec<Row> {
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

fn int(row: &Row, key: &str) -> i64 {
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
            assert_eq!(c["bv_tests"], j["work"]["bv_tests"].to_string());
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
    for file in [&a, &b] {
        let args = [
            "--count",
            "20",
            "--radius",
            "2",
            "--seed",
            "11",
            "-o",
            path(file),
        ];
        run(&[&["poses", "random"][..], &args].concat());
    }
    assert_eq!(std::fs::read(&a).unwrap(), std::fs::read(&b).unwrap());
    let stdout = run(&[
        "poses", "random", "--count", "20", "--radius", "2", "--seed", "11",
    ]);
    assert_eq!(stdout.as_bytes(), std::fs::read(&a).unwrap());
    let three = [
        "poses",
        "random",
        "--count",
        "3",
        "--radius",
        "1",
        "-o",
        path(&a),
    ];
    assert_bad_input(&obbtree(&three), "refusing to replace");
    run(&[&three[..], &["--force"]].concat());
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
    assert_bad_input(
        &obbtree(&[
            "experiment",
            "sliding",
            "--quick",
            "--mesh",
            &cow(),
            "--out",
            path(&dir),
        ]),
        "--mesh applies to the accuracy experiment only",
    );
    assert_bad_input(
        &obbtree(&[
            "experiment",
            "sliding",
            "--quick",
            "--out",
            path(&dir.join("a.txt")),
        ]),
        "is not a directory",
    );
    assert_bad_input(
        &obbtree(&[
            "experiment",
            "accuracy",
            "--quick",
            "--mesh",
            path(&dir.join("none.obj")),
            "--out",
            path(&dir),
        ]),
        "none.obj",
    );
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

/// Runs `obbtree experiment NAME --quick` into a scratch directory: the rows of its CSV
/// and, if it fits lines, the rows of its fits CSV.
fn quick_experiment(name: &str) -> (Vec<Row>, Vec<Row>, String) {
    let dir = scratch(&format!("experiment-{name}"));
    let stdout = run(&["experiment", name, "--quick", "--out", path(&dir)]);
    let points = rows(&std::fs::read_to_string(dir.join(format!("{name}.csv"))).unwrap());
    let fits = std::fs::read_to_string(dir.join(format!("{name}-fits.csv")))
        .map(|text| rows(&text))
        .unwrap_or_default();
    for entry in std::fs::read_dir(&dir).unwrap() {
        let file = entry.unwrap().path();
        if file.extension().is_some_and(|e| e == "svg") {
            let svg = std::fs::read_to_string(&file).unwrap();
            assert!(
                svg.starts_with("<svg") && svg.contains("</svg>"),
                "{}",
                file.display()
            );
        }
    }
    (points, fits, stdout)
}

fn float(row: &Row, key: &str) -> f64 {
    row[key]
        .parse()
        .unwrap_or_else(|_| panic!("{key} = {:?}", row[key]))
}

/// Every row of every experiment: the BVTT identity holds for its mean counts (it holds
/// for each query, and it is linear), no row makes fewer volume tests than the §2.6.3
/// bound, and every volume type and variant finds the same contacts at every point.
fn check_rows(name: &str, points: &[Row]) {
    let mut contacts: HashMap<String, Vec<String>> = HashMap::new();
    for row in points {
        let identity = float(row, "bv_disjoint") - float(row, "bv_overlap")
            + 2.0 * float(row, "tri_separated")
            + 2.0 * float(row, "tri_contact");
        assert!((identity - 1.0).abs() < 1e-9, "{name}: {row:?}");
        // An empty bound: no contacts, no bound.
        if !row["bv_test_lower_bound"].is_empty() {
            let bound = float(row, "bv_test_lower_bound");
            assert!(float(row, "bv_tests") + 1e-9 >= bound, "{name}: {row:?}");
            assert!(float(row, "contacts") > 0.0, "{name}: {row:?}");
        }
        assert!(float(row, "queries") >= 1.0);
        contacts
            .entry(row["volume"].clone())
            .or_default()
            .push(row["contacts"].clone());
    }
    assert!(contacts.len() >= 3, "{name}: every volume type");
    for (label, found) in &contacts {
        assert_eq!(&contacts["obb"], found, "{name}: {label}");
    }
}

fn slope(fits: &[Row], bv: &str, measure: &str) -> f64 {
    let fit = fits
        .iter()
        .find(|f| f["bv"] == bv && f["measure"] == measure)
        .unwrap_or_else(|| panic!("no {bv} {measure} fit in {fits:?}"));
    float(fit, "slope")
}

#[test]
fn quick_sliding_spheres_touch_from_0_2_to_1_8_and_obbs_prune_most() {
    let (points, _, stdout) = quick_experiment("sliding");
    check_rows("sliding", &points);
    // OBB, AABB, sphere, and the dissertation's AABB test and minimal spheres.
    assert_eq!(points.len(), 5 * 101);
    let touching: Vec<f64> = points
        .iter()
        .filter(|r| r["volume"] == "obb" && float(r, "contacts") > 0.0)
        .map(|r| float(r, "offset"))
        .collect();
    assert!((0.18..=0.22).contains(&touching[0]), "{touching:?}");
    assert!(
        (1.76..=1.8).contains(touching.last().unwrap()),
        "{touching:?}"
    );
    // In contact, AABB and sphere trees test more volumes than OBB trees at every step.
    let tests = |bv: &str| -> Vec<f64> {
        points
            .iter()
            .filter(|r| r["volume"] == bv)
            .map(|r| float(r, "bv_tests"))
            .collect()
    };
    let (obb, aabb, sphere) = (tests("obb"), tests("aabb"), tests("sphere"));
    // The dissertation's AABB test is looser: it visits every pair the exact test does.
    let rewrapped = tests("aabb-rewrapped");
    assert!(rewrapped.iter().zip(&aabb).all(|(r, a)| r >= a));
    assert!(rewrapped.iter().sum::<f64>() > 1.2 * aabb.iter().sum::<f64>());
    for (k, r) in points.iter().filter(|r| r["volume"] == "obb").enumerate() {
        if float(r, "contacts") > 0.0 {
            assert!(
                aabb[k] > obb[k] && sphere[k] > obb[k],
                "x = {}",
                r["offset"]
            );
        }
    }
    assert!(
        stdout.contains("measured against the dissertation"),
        "{stdout}"
    );
}

#[test]
fn quick_parallel_close_proximity_has_the_dissertations_slopes() {
    let (points, fits, stdout) = quick_experiment("proximity");
    check_rows("proximity", &points);
    let obb = slope(&fits, "obb", "bv_tests");
    assert!((-1.3..=-1.0).contains(&obb), "OBB slope {obb}");
    for bv in ["aabb", "sphere"] {
        let s = slope(&fits, bv, "bv_tests");
        assert!((-2.3..=-1.7).contains(&s), "{bv} slope {s}");
    }
    // The right ledge: 15 tests for OBBs, as §5.3.2.1 reports.
    let fewest = points
        .iter()
        .filter(|r| r["volume"] == "obb")
        .map(|r| float(r, "bv_tests"))
        .fold(f64::INFINITY, f64::min);
    assert_eq!(fewest, 15.0);
    assert!(stdout.contains("ramp slope"), "{stdout}");
}

#[test]
fn quick_transverse_contact_grows_as_the_square_root_of_the_tessellation() {
    let (points, fits, _) = quick_experiment("transverse");
    check_rows("transverse", &points);
    for bv in ["obb", "aabb", "sphere"] {
        for measure in ["contacts", "bv_tests"] {
            let s = slope(&fits, bv, measure);
            assert!((0.4..=0.6).contains(&s), "{bv} {measure} slope {s}");
        }
    }
}

/// The accuracy experiment on the sliding spheres and the bundled cow (distance, collision
/// and Hausdorff distance): every answer is within what its choice promises against the
/// exact f64 answer, the f64 tree's answers are the reference itself, and the Pareto marks
/// are the undominated choices.
#[test]
fn quick_accuracy_keeps_every_choice_within_its_promise() {
    let dir = scratch("experiment-accuracy");
    let stdout = run(&[
        "experiment",
        "accuracy",
        "--quick",
        "--mesh",
        &cow(),
        "--out",
        path(&dir),
    ]);
    assert!(stdout.contains("Pareto front"), "{stdout}");
    let text = std::fs::read_to_string(dir.join("accuracy.csv")).unwrap();
    // Quoted fields (the scene and the choice) may hold commas.
    let fields = |line: &str| -> Vec<String> {
        let (mut out, mut field, mut quoted) = (Vec::new(), String::new(), false);
        for c in line.chars() {
            match c {
                '"' => quoted = !quoted,
                ',' if !quoted => out.push(std::mem::take(&mut field)),
                c => field.push(c),
            }
        }
        out.push(field);
        out
    };
    let mut bytes_per_triangle = std::collections::BTreeMap::new();
    let trades: Vec<(String, String, String, f64, f64, bool)> = text
        .lines()
        .skip(1)
        .map(|line| {
            let f = fields(line);
            assert_eq!(f.len(), 9, "{line}");
            let bytes: f64 = f[7].parse().unwrap();
            bytes_per_triangle.insert((f[0].clone(), f[1].clone(), f[2].clone()), bytes);
            (
                f[0].clone(),
                f[1].clone(),
                f[2].clone(),
                f[3].parse().unwrap(),
                f[5].parse().unwrap(),
                f[8] == "true",
            )
        })
        .collect();
    // The compact layout is measured on every scene and query, in under a third of the bytes.
    for scene in ["cow", "spheres"] {
        let of =
            |choice: &str| bytes_per_triangle[&(scene.into(), "collision".into(), choice.into())];
        let (fast, compact) = (of("f32"), of("f32, --layout compact"));
        assert!(
            compact < fast / 3.0,
            "{scene}: {compact} vs {fast} bytes per triangle"
        );
    }
    assert!(dir.join("accuracy-size.svg").exists());
    let scenes: std::collections::BTreeSet<&str> = trades.iter().map(|t| t.0.as_str()).collect();
    assert_eq!(scenes.into_iter().collect::<Vec<_>>(), ["cow", "spheres"]);
    // Every query has its rows on every scene, the Hausdorff distance at each error asked.
    for scene in ["cow", "spheres"] {
        let rows = |query: &str| {
            trades
                .iter()
                .filter(|t| t.0 == scene && t.1 == query)
                .count()
        };
        assert!(rows("distance") > 0 && rows("collision") > 0, "{scene}");
        assert_eq!(rows("hausdorff"), 12, "{scene}: 6 errors and 6 other trees");
    }
    assert!(dir.join("accuracy-hausdorff.svg").exists());
    // f32 coordinates are within 6e-8 of the f64 ones: distances move by about that.
    let storage = 1e-5;
    for (scene, query, choice, _, error_max, _) in &trades {
        let promise = if choice.starts_with("f64") {
            0.0
        } else if let Some(r) = choice.split("--rel-err ").nth(1) {
            r.parse::<f64>().unwrap() + storage
        } else if let Some(t) = choice.split("--tolerance ").nth(1) {
            t.trim_end_matches('d').parse::<f64>().unwrap() - 1.0 + storage
        } else {
            storage
        };
        assert!(
            *error_max <= promise,
            "{scene} {query} {choice}: {error_max} > {promise}"
        );
    }
    for (scene, query, choice, seconds, error, pareto) in &trades {
        let dominated = trades.iter().any(|(s, q, _, t, e, _)| {
            s == scene && q == query && t <= seconds && e <= error && (t < seconds || e < error)
        });
        assert_eq!(*pareto, !dominated, "{scene} {query} {choice}");
    }
}
