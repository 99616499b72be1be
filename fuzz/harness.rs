//! Fuzz harness logic, shared by the cargo-fuzz targets in `fuzz/fuzz_targets/` and by the
//! stable test `tests/it/fuzz_corpus.rs`, which replays the checked-in corpus through it.
//!
//! Depends only on `obbtree`, `crc32fast` and the re-sealing of `tests/common/seal.rs`, which
//! the mutation suites share (no libFuzzer), so it compiles in both places. Every
//! function takes arbitrary bytes and must never panic, hang or abort on them: the library
//! answers untrusted input with an error. The `assert!`s below only run on inputs the
//! library accepted (a file that passed `verify`, a mesh that loaded and built), and check
//! invariants that must then hold; a failure is a bug in the library.

// Each fuzz target uses one of the three entry points.
#![allow(dead_code)]
// The panics are the assertions above (a bug in the library, not bad input), and the
// indexing is into constant arrays, modulo their length.
#![allow(clippy::panic, clippy::indexing_slicing)]

#[path = "../tests/common/seal.rs"]
mod seal;

use obbtree::build::{
    build, BuildError, BuildOptions, SphereFit, DEFAULT_HULL_MAX_POINTS, DEFAULT_HULL_MIN_FACES,
};
use obbtree::bv::{BvKind, Layout};
use obbtree::fit::FitMethod;
use obbtree::format::{AlignedBytes, ObbtFile};
use obbtree::mesh::TriMesh;
use obbtree::query::{
    CollideOptions, CollideResult, DescentRule, DistanceOptions, DistanceResult, PairQuery, Pose,
    QueryError, SpanOptions, SpanResult, ToleranceOptions, ToleranceResult,
};
use obbtree::real::Precision;
use obbtree::tree::Encoding;

/// Largest mesh the loader targets build (a build is O(n log n) with a convex hull per node).
const MAX_BUILD_TRIANGLES: usize = 2_000;

/// Tolerance of the tolerance queries.
const TOLERANCE: f64 = 0.5;

/// Fuzz an `.obbt` image: open it, query it against itself (before `verify`, so queries on
/// unverified files are exercised), verify it, and check invariants if it verifies. The same
/// is done on a "re-sealed" copy whose header and section CRCs are recomputed, so that byte
/// mutations get past the checksums and reach the section, query and verify code.
pub fn obbt_reader(data: &[u8]) {
    check_image(data);
    let mut sealed = data.to_vec();
    seal::seal(&mut sealed);
    if sealed != data {
        check_image(&sealed);
    }
}

/// Fuzz the OBJ loader: parse, and build and verify small meshes.
pub fn obj_loader(data: &[u8]) {
    if let Ok(mesh) = TriMesh::from_obj_bytes(data, "fuzz.obj") {
        check_mesh(&mesh, data);
    }
}

/// Fuzz the STL loader (binary and ASCII): parse, and build and verify small meshes.
pub fn stl_loader(data: &[u8]) {
    if let Ok(mesh) = TriMesh::from_stl_bytes(data, "fuzz.stl") {
        check_mesh(&mesh, data);
    }
}

/// A loaded mesh must satisfy `TriMesh`'s invariants; a small one must build into a file
/// that verifies and answers queries soundly.
fn check_mesh(mesh: &TriMesh, data: &[u8]) {
    let vertex_count = mesh.vertices().len();
    assert!(vertex_count >= 1, "a loaded mesh has no vertex");
    assert!(!mesh.faces().is_empty(), "a loaded mesh has no face");
    assert!(
        mesh.faces()
            .iter()
            .flatten()
            .all(|&i| (i as usize) < vertex_count),
        "a loaded mesh has a vertex index out of range"
    );
    assert!(
        mesh.vertices().iter().flatten().all(|c| c.is_finite()),
        "a loaded mesh has a non-finite coordinate"
    );
    if mesh.faces().len() > MAX_BUILD_TRIANGLES {
        return;
    }
    // The default options, and one more combination picked from the input's bytes so the
    // other volumes, precisions, fits, the variable encoding and placements get built too.
    let pick = data.iter().fold(0usize, |h, &b| {
        h.wrapping_mul(31).wrapping_add(usize::from(b))
    });
    let bv = [BvKind::Obb, BvKind::Aabb, BvKind::Sphere][pick % 3];
    let precision = [Precision::F32, Precision::F64][(pick / 3) % 2];
    let other = BuildOptions {
        bv,
        precision,
        // The compact layout exists for f32 boxes only.
        layout: if (bv, precision) == (BvKind::Obb, Precision::F32) && (pick / 6912) % 2 == 1 {
            Layout::Compact
        } else {
            Layout::Fast
        },
        fit: [FitMethod::Hull, FitMethod::Triangles, FitMethod::Vertices][(pick / 6) % 3],
        leaf_size: [1, 2, 4, 128][(pick / 18) % 4],
        scale: [1.0, 1e-3, 1e3][(pick / 72) % 3],
        center: (pick / 216) % 2 == 1,
        hull_min_faces: [2, DEFAULT_HULL_MIN_FACES][(pick / 432) % 2],
        // Small enough that fuzzed meshes get sampled hulls too.
        hull_max_points: [4, DEFAULT_HULL_MAX_POINTS][(pick / 864) % 2],
        model_axes: (pick / 1728) % 2 == 0,
        split_by_volume: (pick / 6912) % 2 == 0,
        // Minimal balls apply to sphere trees only.
        sphere_fit: if bv == BvKind::Sphere && (pick / 3456) % 2 == 1 {
            SphereFit::Minimal
        } else {
            SphereFit::BoxCentre
        },
    };
    // Fuzzed meshes are small: with the default threshold the hull fit would never run.
    let hull_everywhere = BuildOptions {
        hull_min_faces: 1,
        ..BuildOptions::default()
    };
    for options in [hull_everywhere, other] {
        match build(mesh, &options, None) {
            Ok(file) => {
                if let Err(error) = file.verify() {
                    panic!("a built file fails verify ({options:?}): {error}");
                }
                let before = Queries::run(&file);
                check_verified(&file, &before);
                // The built image, copied and opened as a reader would, is the same tree.
                match ObbtFile::from_aligned(AlignedBytes::copy_from(file.bytes())) {
                    Ok(reopened) => assert_eq!(
                        reopened.info(),
                        file.info(),
                        "a reopened file reports other info"
                    ),
                    Err(error) => panic!("a built file does not open ({options:?}): {error}"),
                }
            }
            // Coordinates beyond the f32 range are refused for f32 files, by design.
            Err(BuildError::CoordinateOverflow { .. }) if options.precision == Precision::F32 => {}
            // So are coordinates that scaling or centring takes beyond the f64 range.
            Err(BuildError::PlacementOverflow { .. }) if options.scale > 1.0 || options.center => {}
            Err(error) => panic!(
                "a loaded mesh of {} triangles does not build ({options:?}): {error}",
                mesh.faces().len()
            ),
        }
    }
}

/// Opens, queries and verifies one image.
fn check_image(data: &[u8]) {
    let Ok(file) = ObbtFile::from_aligned(AlignedBytes::copy_from(data)) else {
        return;
    };
    let info = file.info();
    let _ = format!("{info:?} {:?}", file.sections());
    // Queries before verify: an error or an answer, never a panic or a hang.
    let before = Queries::run(&file);
    if file.verify().is_ok() {
        check_verified(&file, &before);
    }
}

/// The fixed non-identity pose of B in the posed queries: a rotation (exact 3-4-5
/// cosines and sines about z then x) and a small translation.
fn posed() -> Option<Pose> {
    Pose::from_row_major(&[
        0.6, -0.48, 0.64, //
        0.8, 0.36, -0.48, //
        0.0, 0.8, 0.6, //
        0.25, -0.125, 0.0625,
    ])
    .ok()
}

/// The answers of the queries run before `verify`: the file against itself, A at the
/// identity and B at [`posed`].
struct Queries {
    collide: Option<Result<CollideResult, QueryError>>,
    first: Option<Result<CollideResult, QueryError>>,
    distance: Option<Result<DistanceResult, QueryError>>,
    tolerance: Option<Result<ToleranceResult, QueryError>>,
    span: Option<Result<SpanResult, QueryError>>,
}

impl Queries {
    fn run(file: &ObbtFile) -> Queries {
        let Some(pose_b) = posed() else {
            return Queries {
                collide: None,
                first: None,
                distance: None,
                tolerance: None,
                span: None,
            };
        };
        let id = Pose::identity();
        let all = CollideOptions::default();
        let first = CollideOptions {
            first_contact: true,
            ..CollideOptions::default()
        };
        let rule = DescentRule::default();
        let mut pair = match PairQuery::new(file, file) {
            Ok(pair) => pair,
            // A file whose sections cannot be viewed: every query refuses it.
            Err(error) => {
                return Queries {
                    collide: Some(Err(error.clone())),
                    first: Some(Err(error.clone())),
                    distance: Some(Err(error.clone())),
                    tolerance: Some(Err(error.clone())),
                    span: Some(Err(error)),
                }
            }
        };
        let tolerance = ToleranceOptions {
            tolerance: TOLERANCE,
            rule,
        };
        Queries {
            collide: Some(pair.collide(&id, &pose_b, &all)),
            first: Some(pair.collide(&id, &pose_b, &first)),
            distance: Some(pair.distance(&id, &pose_b, &DistanceOptions::default())),
            tolerance: Some(pair.within(&id, &pose_b, &tolerance)),
            span: Some(pair.span(&id, &pose_b, &SpanOptions { rule })),
        }
    }
}

/// Unwraps a query answer on a verified file, where an error is a bug.
fn ok<'a, T>(what: &str, result: Option<&'a Result<T, QueryError>>) -> Option<&'a T> {
    match result {
        Some(Ok(value)) => Some(value),
        Some(Err(error)) => panic!("{what} on a verified file failed: {error}"),
        None => None,
    }
}

/// Invariants of a file that passed `verify`; `before` holds the posed queries run on it
/// before it was verified.
fn check_verified(file: &ObbtFile, before: &Queries) {
    let info = file.info();
    let triangles = info.triangles;
    let binary = info.encoding == Encoding::Binary;
    // Largest coordinate magnitude, for the tolerances of the floating-point comparisons.
    let scale = info
        .stats
        .bounds_min
        .iter()
        .chain(info.stats.bounds_max.iter())
        .fold(1.0f64, |m, c| m.max(c.abs()));
    let slack = 1e-9 * scale;
    let diagonal = (0..3)
        .map(|k| {
            let e = info.stats.bounds_max[k] - info.stats.bounds_min[k];
            e * e
        })
        .sum::<f64>()
        .sqrt();
    let mut pair = match PairQuery::new(file, file) {
        Ok(pair) => pair,
        Err(error) => panic!("a verified file cannot be queried: {error}"),
    };
    let id = Pose::identity();
    let rule = DescentRule::default();

    // The file against itself at the same pose: every triangle touches itself.
    match pair.collide(&id, &id, &CollideOptions::default()) {
        Ok(hit) => {
            assert!(
                hit.colliding,
                "a verified file does not collide with itself"
            );
            for t in 0..triangles {
                assert!(
                    hit.pairs.binary_search(&(t, t)).is_ok(),
                    "self-collision misses triangle {t} touching itself"
                );
            }
            check_collide_result(&hit, triangles, binary, "self-collision");
        }
        Err(error) => panic!("self-collision on a verified file failed: {error}"),
    }
    let first = CollideOptions {
        first_contact: true,
        ..CollideOptions::default()
    };
    match pair.collide(&id, &id, &first) {
        Ok(hit) => {
            assert!(hit.colliding, "first contact: no self-collision");
            assert_eq!(hit.pairs.len(), 1, "first contact returned several pairs");
            check_collide_result(&hit, triangles, false, "first-contact self-collision");
        }
        Err(error) => panic!("first-contact self-collision on a verified file failed: {error}"),
    }
    match pair.distance(&id, &id, &DistanceOptions::default()) {
        Ok(d) => {
            let Some(d) = d.closest else {
                panic!("self-distance on a verified file has no closest pair");
            };
            assert!(
                d.distance == 0.0,
                "self-distance is {} (triangles {} and {}), not 0",
                d.distance,
                d.tri_a,
                d.tri_b
            );
            assert!(
                d.tri_a < triangles && d.tri_b < triangles,
                "self-distance ids"
            );
        }
        Err(error) => panic!("self-distance on a verified file failed: {error}"),
    }
    let tolerance = ToleranceOptions {
        tolerance: TOLERANCE,
        rule,
    };
    match pair.within(&id, &id, &tolerance) {
        Ok(w) => assert!(
            w.closer(),
            "a verified file is not within tolerance of itself"
        ),
        Err(error) => panic!("self-tolerance on a verified file failed: {error}"),
    }
    match pair.span(&id, &id, &SpanOptions { rule }) {
        Ok(s) => {
            assert!(s.span() >= 0.0, "self-span is {}", s.span());
            assert!(
                s.span() <= diagonal * (1.0 + 1e-12) + 1e-300,
                "self-span {} exceeds the bounds' diagonal {diagonal}",
                s.span()
            );
        }
        Err(error) => panic!("self-span on a verified file failed: {error}"),
    }

    // The queries run before verify, now on a verified file: all must have answered.
    let all = ok("collide", before.collide.as_ref());
    if let Some(all) = all {
        check_collide_result(all, triangles, binary, "posed collision");
    }
    if let Some(first) = ok("first contact", before.first.as_ref()) {
        check_collide_result(first, triangles, false, "posed first contact");
        if let Some(all) = all {
            assert_eq!(
                first.colliding, all.colliding,
                "first contact and all contacts disagree"
            );
            if let Some(pair) = first.pairs.first() {
                assert!(
                    all.pairs.binary_search(pair).is_ok(),
                    "the first contact {pair:?} is not among all contacts"
                );
            }
        }
    }
    // Without a maximum distance an answer always has its closest pair.
    let distance = ok("distance", before.distance.as_ref()).map(|d| match d.closest {
        Some(closest) => closest,
        None => panic!("a posed distance on a verified file has no closest pair"),
    });
    if let Some(d) = distance {
        assert!(d.distance >= 0.0, "posed distance is {}", d.distance);
        assert!(
            d.tri_a < triangles && d.tri_b < triangles,
            "posed distance ids"
        );
        if let Some(all) = all {
            if all.colliding {
                assert!(
                    d.distance <= slack,
                    "the posed copies collide but their distance is {}",
                    d.distance
                );
            }
        }
        let gap = (d.point_a - d.point_b).norm();
        if d.distance.is_finite() && gap.is_finite() {
            assert!(
                (gap - d.distance).abs() <= slack,
                "the distance points are {gap} apart, the distance is {}",
                d.distance
            );
        }
    }
    if let Some(w) = ok("tolerance", before.tolerance.as_ref()) {
        if let Some(witness) = &w.witness {
            assert!(w.closer(), "a tolerance witness without `closer`");
            assert!(
                witness.distance < TOLERANCE,
                "a tolerance witness at {}",
                witness.distance
            );
        } else {
            assert!(!w.closer(), "`closer` without a witness");
        }
        if let Some(d) = distance {
            if d.distance < TOLERANCE - slack {
                assert!(
                    w.closer(),
                    "distance {} but not within {TOLERANCE}",
                    d.distance
                );
            }
            if d.distance > TOLERANCE + slack {
                assert!(
                    !w.closer(),
                    "distance {} but within {TOLERANCE}",
                    d.distance
                );
            }
            if let Some(witness) = &w.witness {
                assert!(
                    witness.distance >= d.distance - slack,
                    "a tolerance witness at {} is closer than the distance {}",
                    witness.distance,
                    d.distance
                );
            }
        }
    }
    if let Some(s) = ok("span", before.span.as_ref()) {
        let far = &s.farthest;
        assert!(s.span() >= 0.0, "posed span is {}", s.span());
        assert!(
            far.tri_a < triangles && far.tri_b < triangles,
            "posed span ids"
        );
        if let Some(d) = distance {
            assert!(
                s.span() >= d.distance - slack,
                "the span {} is less than the distance {}",
                s.span(),
                d.distance
            );
        }
    }
}

/// Pair ids in range, sorted and distinct; statistics consistent.
fn check_collide_result(hit: &CollideResult, triangles: u32, complete_binary: bool, what: &str) {
    assert_eq!(hit.colliding, !hit.pairs.is_empty(), "{what}: `colliding`");
    assert!(
        hit.pairs
            .iter()
            .all(|&(a, b)| a < triangles && b < triangles),
        "{what}: a pair id out of range"
    );
    assert!(
        hit.pairs.windows(2).all(|w| w[0] < w[1]),
        "{what}: pairs not sorted and distinct"
    );
    let s = hit.work;
    assert_eq!(
        s.nodes_visited,
        s.bv_disjoint + s.bv_overlap,
        "{what}: every visited pair is either pruned or not ({s:?})"
    );
    if complete_binary {
        assert_eq!(
            s.identity_value(),
            1,
            "{what}: 1 = D - I + 2S + 2K fails ({s:?})"
        );
    }
}
