//! Files that outlive their version: `.obbt` files of every format version so far, written
//! once by the builder of their time and kept in `tests/fixtures/golden/`, each opened,
//! verified and asked the same queries with the answers recorded in `answers.json` when it
//! was added. An answer that changes is a bug in the reader or the queries, or a decision
//! about the format that its changelog must state; the files and the recorded answers are
//! never rewritten (a new format version adds its own file and answers). A version this
//! reader does not implement is refused naming the version and what to do.
// Test code outside `#[test]` functions (helpers): a failure is a failed test.
#![allow(clippy::expect_used, clippy::indexing_slicing, clippy::panic)]

use crate::common::seal::seal;

use obbtree::format::{AlignedBytes, FormatError, ObbtFile};
use obbtree::query::{
    cast_rays, closest_points, hausdorff, winding_numbers, ClosestOptions, CollideOptions,
    DistanceOptions, HausdorffOptions, PairQuery, Pose, Ray, RayOptions, SpanOptions,
    WindingAccuracy, WindingOptions,
};
use serde_json::{json, Value};
use std::path::{Path, PathBuf};

fn golden_dir() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/fixtures/golden")
}

/// B's pose in the contact queries: exact 3-4-5 cosines and sines about z then x, and a
/// small translation. Written out, not generated, so it cannot drift.
fn crossing() -> Pose {
    Pose::from_row_major(&[
        0.6, -0.48, 0.64, //
        0.8, 0.36, -0.48, //
        0.0, 0.8, 0.6, //
        0.25, -0.125, 0.0625,
    ])
    .expect("a rotation")
}

/// The same turn, B moved well clear of A.
fn apart() -> Pose {
    Pose::from_row_major(&[
        0.6, -0.48, 0.64, //
        0.8, 0.36, -0.48, //
        0.0, 0.8, 0.6, //
        5.0, 1.0, -0.5,
    ])
    .expect("a rotation")
}

/// What a file says of itself and answers: the file against itself for the pair queries,
/// the file alone for the one-model ones. Triangle ids are recorded where the answer names
/// one triangle (contacts, the ray's hit: ties go to the smallest id); a closest pair or
/// point at a shared vertex may name any triangle around it, so there the distance alone.
fn answers(file: &ObbtFile) -> Value {
    let info = file.info();
    let id = Pose::identity();
    let mut pair = PairQuery::new(file, file).expect("views");
    let collide = pair
        .collide(&id, &crossing(), &CollideOptions::default())
        .expect("collides");
    let distance = pair
        .distance(&id, &apart(), &DistanceOptions::default())
        .expect("measures");
    let span = pair
        .span(&id, &crossing(), &SpanOptions::default())
        .expect("spans");
    let closest = closest_points(file, &id, &[[0.3, 0.2, 2.5]], &ClosestOptions::default())
        .expect("answers")[0]
        .closest
        .expect("a closest point");
    let ray = Ray {
        origin: [0.01, 0.02, 5.0],
        direction: [0.05, 0.02, -1.0],
    };
    let hit = cast_rays(file, &id, &[ray], &RayOptions::default()).expect("casts")[0]
        .hit
        .expect("a hit");
    let winding = winding_numbers(
        file,
        &id,
        &[[0.05, -0.02, 0.01]],
        &WindingOptions {
            accuracy: WindingAccuracy::Exact,
        },
    )
    .expect("answers")[0]
        .value;
    let h =
        hausdorff(file, &id, file, &crossing(), &HausdorffOptions::default()).expect("measures");
    let w = distance.closest.expect("a closest pair");
    json!({
        "version": format!("{}.{}", info.version.0, info.version.1),
        "bv": info.bv.name(),
        "precision": info.precision.name(),
        "layout": info.layout.name(),
        "triangles": info.triangles,
        "nodes": info.nodes,
        "contacts": collide.pairs,
        "distance": w.distance,
        "span": span.span(),
        "closest": closest.distance,
        "ray": [hit.t, hit.triangle],
        "winding": winding,
        "hausdorff": h.distance,
        "hausdorff_upper": h.upper_bound,
    })
}

/// The Hausdorff answers are proven intervals, `[hausdorff, hausdorff_upper]`, which an
/// exact query may narrow where its bounds close before the floor of its refinement (the
/// answer of a later obbtree is then better, not different): the interval found must lie
/// within the recorded one. Taken out of both answers.
fn same_hausdorff(found: &mut Value, recorded: &mut Value) -> bool {
    let interval = |v: &mut Value| {
        let mut take = |key| {
            v.as_object_mut()
                .and_then(|o| o.remove(key))
                .and_then(|x| x.as_f64())
                .unwrap_or(f64::NAN)
        };
        (take("hausdorff"), take("hausdorff_upper"))
    };
    let ((lo, hi), (then_lo, then_hi)) = (interval(found), interval(recorded));
    let slack = 1e-12 * hi.max(then_hi).max(1.0);
    lo <= hi && then_lo <= lo + slack && hi <= then_hi + slack
}

/// Numbers equal to 1e-12 (relative, or absolute below 1), the rest exactly.
fn same(found: &Value, recorded: &Value) -> bool {
    match (found, recorded) {
        (Value::Number(x), Value::Number(y)) if x.is_f64() || y.is_f64() => {
            let (x, y) = (
                x.as_f64().unwrap_or(f64::NAN),
                y.as_f64().unwrap_or(f64::NAN),
            );
            (x - y).abs() <= 1e-12 * x.abs().max(y.abs()).max(1.0)
        }
        (Value::Array(x), Value::Array(y)) => {
            x.len() == y.len() && x.iter().zip(y).all(|(a, b)| same(a, b))
        }
        (Value::Object(x), Value::Object(y)) => {
            x.len() == y.len() && x.iter().all(|(k, v)| y.get(k).is_some_and(|w| same(v, w)))
        }
        _ => found == recorded,
    }
}

/// Every golden file opens, verifies and answers as recorded; every version so far has
/// one. `OBBTREE_GOLDEN_RECORD=1` records the answers of files not yet in `answers.json`
/// (a new version's), never those of files already there.
#[test]
fn every_format_version_answers_as_recorded() {
    let dir = golden_dir();
    let recorded_path = dir.join("answers.json");
    let mut recorded: serde_json::Map<String, Value> = std::fs::read_to_string(&recorded_path)
        .map(|text| serde_json::from_str(&text).expect("answers.json is JSON"))
        .unwrap_or_default();
    let mut files: Vec<PathBuf> = std::fs::read_dir(&dir)
        .expect("tests/fixtures/golden")
        .map(|e| e.expect("an entry").path())
        .filter(|p| p.extension().is_some_and(|e| e == "obbt"))
        .collect();
    files.sort();
    let mut versions = std::collections::BTreeSet::new();
    let mut added = false;
    for path in &files {
        let name = path
            .file_name()
            .and_then(|n| n.to_str())
            .expect("a name")
            .to_string();
        let file = ObbtFile::open(path).unwrap_or_else(|e| panic!("{name}: {e}"));
        file.verify().unwrap_or_else(|e| panic!("{name}: {e}"));
        let found = answers(&file);
        versions.insert(found["version"].as_str().expect("a version").to_string());
        match recorded.get(&name) {
            Some(expected) => {
                let (mut now, mut then) = (found.clone(), expected.clone());
                assert!(
                    same_hausdorff(&mut now, &mut then) && same(&now, &then),
                    "{name} answers otherwise than when it was recorded:\nnow {found}\nthen {expected}"
                );
            }
            None if std::env::var_os("OBBTREE_GOLDEN_RECORD").is_some() => {
                recorded.insert(name, found);
                added = true;
            }
            None => panic!(
                "{name} has no recorded answers: run once with OBBTREE_GOLDEN_RECORD=1 and commit answers.json"
            ),
        }
    }
    if added {
        let text = serde_json::to_string_pretty(&Value::Object(recorded)).expect("JSON");
        std::fs::write(&recorded_path, text + "\n").expect("writes answers.json");
    }
    assert_eq!(
        versions.into_iter().collect::<Vec<_>>(),
        ["1.0", "1.1", "1.2"],
        "a golden file for every format version"
    );
}

/// A file of a later major version is refused at open, naming its version and what to do.
#[test]
fn a_later_major_version_is_refused_saying_what_to_do() {
    let bytes = std::fs::read(golden_dir().join("v1.0-obb-f32.obbt")).expect("reads");
    let mut later = bytes.clone();
    // version_major, bytes 8..10, little-endian; re-sealed so the checksum passes.
    later[8..10].copy_from_slice(&2u16.to_le_bytes());
    seal(&mut later);
    let error = ObbtFile::from_aligned(AlignedBytes::copy_from(&later)).expect_err("refused");
    assert!(
        matches!(
            error,
            FormatError::UnsupportedVersion { major: 2, minor: 0 }
        ),
        "{error}"
    );
    let message = error.to_string();
    assert!(
        message.contains("2.0") && message.contains("rebuild"),
        "{message}"
    );
}
