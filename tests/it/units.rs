//! Units and origins (`BuildOptions::scale`, `BuildOptions::center`; `obbtree build --scale S
//! --center`): what a build stores and records, that models made in different units or far
//! from their origin can then be queried together, and the `placement` section of format 1.1
//! (written only when it says something, checked by `open` and `verify`, skipped by readers
//! that do not know it).
// Test code outside `#[test]` functions (helpers, property bodies): a failure is a failed test.
#![allow(clippy::expect_used, clippy::indexing_slicing)]

use crate::common;

use common::mutate::{entry_field, write_uint};
use common::seal::seal;
use obbtree::build::{build, rounding_loss, BuildError, BuildOptions, REPORTED_ROUNDING};
use obbtree::format::layout::{SectionKind, PLACEMENT_STRIDE};
use obbtree::format::{AlignedBytes, ObbtFile};
use obbtree::mesh::TriMesh;
use obbtree::query::{CollideOptions, DistanceOptions, PairQuery, Pose};
use obbtree::real::Precision;

/// Where the far-away copies of the cow sit: the "offset of −982 from their origin" of real
/// meshes.
const FAR: [f64; 3] = [-982.0, 500.0, 3.0];

/// `mesh` with every vertex mapped by `f`, same faces.
fn moved(mesh: &TriMesh, f: impl Fn([f64; 3]) -> [f64; 3]) -> TriMesh {
    let vertices = mesh.vertices().iter().map(|&p| f(p)).collect();
    TriMesh::new(vertices, mesh.faces().to_vec()).expect("a valid mesh")
}

/// Componentwise extremes of the vertices of `mesh`.
fn bounds(mesh: &TriMesh) -> ([f64; 3], [f64; 3]) {
    let mut lo = [f64::INFINITY; 3];
    let mut hi = [f64::NEG_INFINITY; 3];
    for p in mesh.vertices() {
        for k in 0..3 {
            lo[k] = lo[k].min(p[k]);
            hi[k] = hi[k].max(p[k]);
        }
    }
    (lo, hi)
}

fn f64_options() -> BuildOptions {
    BuildOptions {
        precision: Precision::F64,
        ..BuildOptions::default()
    }
}

/// The directory entry of the placement section, if the file has one.
fn placement_entry(file: &ObbtFile) -> Option<(usize, obbtree::format::SectionInfo)> {
    file.sections()
        .iter()
        .enumerate()
        .find(|(_, s)| s.kind == Some(SectionKind::Placement))
        .map(|(i, s)| (i, s.clone()))
}

/// Poses of B (the cow is about 1 x 0.6 x 0.3): overlapping ones for collisions, apart ones
/// for distances, each with its own seeded rotation.
fn poses(shifts: &[f64]) -> Vec<Pose> {
    shifts
        .iter()
        .enumerate()
        .map(|(seed, &x)| {
            let t = nalgebra::Vector3::new(x, 0.1 * x, -0.05);
            Pose::new(common::rng::seeded_rotation(seed as u64 + 7), t).expect("a rotation")
        })
        .collect()
}

/// Asserts that `(a, pose_a)` against `(b, pose_b)` gives the same contacts as the reference
/// pair, and distances equal within `rel` (relative), for every pose of B given.
fn assert_same_answers(
    (a, pose_a): (&ObbtFile, &Pose),
    (reference, reference_pose): (&ObbtFile, &Pose),
    b: &ObbtFile,
    rel: f64,
) {
    // The pair under test, then the reference pair.
    let mut sides = [(a, pose_a), (reference, reference_pose)].map(|(file, pose)| {
        let pair = PairQuery::new(file, b).expect("same volume and precision");
        (pair, pose)
    });
    let mut contacts = 0;
    for pose_b in poses(&[0.15, 0.4, 0.7]) {
        let [got, want] = sides.each_mut().map(|(pair, pose)| {
            pair.collide(pose, &pose_b, &CollideOptions::default())
                .expect("collides")
        });
        assert_eq!(got.pairs, want.pairs, "contacts at {pose_b:?}");
        contacts += want.pairs.len();
    }
    assert!(
        contacts > 100,
        "the collision poses must touch ({contacts})"
    );
    for pose_b in poses(&[1.3, 2.0, 7.5]) {
        let [got, want] = sides.each_mut().map(|(pair, pose)| {
            pair.distance(pose, &pose_b, &DistanceOptions::default())
                .expect("a distance")
                .closest
                .expect("no maximum distance")
        });
        assert!(want.distance > 0.0, "the distance poses must be apart");
        assert!(
            (got.distance - want.distance).abs() <= rel * want.distance,
            "distance {} against {} at {pose_b:?}",
            got.distance,
            want.distance
        );
        assert!((got.point_b - want.point_b).norm() <= rel * (1.0 + want.point_b.norm()));
    }
}

#[test]
fn scale_and_center_place_the_model_and_are_recorded() {
    let input = moved(&common::cow(), |p| std::array::from_fn(|k| p[k] + FAR[k]));
    let (lo, hi) = bounds(&input);
    let dir = std::env::temp_dir().join(format!("obbtree-units-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    for precision in Precision::ALL {
        let options = BuildOptions {
            precision,
            scale: 1000.0,
            center: true,
            ..BuildOptions::default()
        };
        let built = build(&input, &options, None).expect("builds");
        built.verify().expect("verifies");
        let path = dir.join(format!("placed-{}.obbt", precision.name()));
        built.write_atomic(&path).unwrap();
        let file = ObbtFile::open(&path).expect("opens");
        file.verify().expect("verifies after the round trip");

        // Recorded and read back: scale 1000, offset −1000 · (centre of the input box).
        let p = file.placement();
        assert_eq!(p, built.placement());
        assert_eq!(p.scale, 1000.0);
        let centre: [f64; 3] = std::array::from_fn(|k| 0.5 * lo[k] + 0.5 * hi[k]);
        assert_eq!(p.offset, centre.map(|c| 0.0 - 1000.0 * c));
        let info = file.info();
        assert_eq!(info.placement, p);
        assert_eq!(
            info.version,
            (1, 1),
            "a file with a placement is a 1.1 file"
        );

        // Stored bounds are 1000 (input bounds − centre), within the rounding of the f64
        // placement (coordinates near 1e6) and of the stored precision (near 500).
        let tolerance = match precision {
            Precision::F32 => 1e-4,
            Precision::F64 => 1e-8,
        };
        for k in 0..3 {
            let (want_lo, want_hi) = (1000.0 * (lo[k] - centre[k]), 1000.0 * (hi[k] - centre[k]));
            assert!(
                (info.stats.bounds_min[k] - want_lo).abs() <= tolerance
                    && (info.stats.bounds_max[k] - want_hi).abs() <= tolerance,
                "{precision:?} axis {k}: {:?} .. {:?}, want {want_lo} .. {want_hi}",
                info.stats.bounds_min,
                info.stats.bounds_max
            );
        }
        // Every stored corner is the placement applied in f64, then rounded once.
        for (id, corners) in common::file_triangles(&file) {
            let face = input.faces()[id as usize];
            for (corner, &v) in corners.iter().zip(&face) {
                let placed = p.apply(input.vertices()[v as usize]);
                let want = placed.map(|c| match precision {
                    Precision::F32 => f64::from(c as f32),
                    Precision::F64 => c,
                });
                assert_eq!(*corner, want, "{precision:?} triangle {id}");
            }
        }
        // The placement's inverse maps stored points back to the input frame.
        let first = input.vertices()[0];
        let back = p.to_input(p.apply(first));
        assert!(back.iter().zip(first).all(|(b, f)| (b - f).abs() < 1e-9));

        // The section: last, optional (REQUIRED clear), one 32-byte record.
        let (index, entry) = placement_entry(&file).expect("a placement section");
        assert_eq!(index, file.sections().len() - 1);
        assert_eq!(
            (entry.kind_tag, entry.flags, entry.count, entry.stride),
            (5, 0, 1, PLACEMENT_STRIDE)
        );
    }
    std::fs::remove_dir_all(&dir).unwrap();
}

/// CRC-32 and length of the default cow build and of an AABB f64 leaf-size-4 build, as
/// written before the placement existed (format 1.0), when the hull fit ran at every node
/// over every vertex, never on the model's axes and split along the greatest spread only
/// (`hull_min_faces` 1, `hull_max_points` unlimited, `model_axes` and `split_by_volume` off).
/// A file built without a placement must stay exactly what a 1.0 writer wrote.
const COW_1_0: [(u32, usize); 2] = [(0x7335_ee6c, 870_976), (0x74b6_8c4e, 375_488)];

#[test]
fn files_without_a_placement_are_unchanged_1_0_files() {
    let cow = common::cow();
    let hull_everywhere = BuildOptions {
        hull_min_faces: 1,
        hull_max_points: u32::MAX,
        model_axes: false,
        split_by_volume: false,
        ..BuildOptions::default()
    };
    let options = [
        hull_everywhere,
        BuildOptions {
            bv: obbtree::bv::BvKind::Aabb,
            precision: Precision::F64,
            leaf_size: 4,
            ..hull_everywhere
        },
    ];
    for (options, (crc, len)) in options.iter().zip(COW_1_0) {
        let file = build(&cow, options, None).expect("builds");
        assert_eq!(
            (crc32fast::hash(file.bytes()), file.bytes().len()),
            (crc, len),
            "{options:?}: not the bytes a 1.0 writer wrote"
        );
        assert_eq!(file.info().version, (1, 0));
        assert_eq!(file.sections().len(), 4);
        assert!(placement_entry(&file).is_none());
        assert!(file.placement().is_identity());
    }
    // Centring a model whose box is already centred, at scale 1, changes nothing: the
    // placement is the identity and is not written.
    let cube = common::cube(0.5);
    let plain = build(&cube, &BuildOptions::default(), None).expect("builds");
    let centred = BuildOptions {
        center: true,
        ..BuildOptions::default()
    };
    let centred = build(&cube, &centred, None).expect("builds");
    assert!(plain.bytes() == centred.bytes());
}

#[test]
fn a_model_in_millimetres_queries_like_the_model_in_metres() {
    let metres = common::cow();
    let millimetres = moved(&metres, |p| p.map(|c| c * 1000.0));
    let plain = build(&metres, &f64_options(), None).expect("builds");
    let from_mm = BuildOptions {
        scale: 0.001,
        ..f64_options()
    };
    let from_mm = build(&millimetres, &from_mm, None).expect("builds");
    from_mm.verify().expect("verifies");
    assert_eq!(from_mm.placement().scale, 0.001);
    let identity = Pose::identity();
    // The model made in millimetres, stored in metres, answers as the model made in metres,
    // as A and as B.
    assert_same_answers((&from_mm, &identity), (&plain, &identity), &plain, 1e-9);
    assert_same_answers((&plain, &identity), (&plain, &identity), &from_mm, 1e-9);
}

#[test]
fn center_brings_a_far_model_to_its_origin() {
    let cow = common::cow();
    let far = moved(&cow, |p| std::array::from_fn(|k| p[k] + FAR[k]));
    let centred = BuildOptions {
        center: true,
        ..f64_options()
    };
    let centred = build(&far, &centred, None).expect("builds");
    centred.verify().expect("verifies");
    let offset = centred.placement().offset;
    // The stored model is the far one moved by the offset, so the plain cow moved by
    // FAR + offset (the cow's box is centred on its origin, so that is nearly nothing).
    let shift: [f64; 3] = std::array::from_fn(|k| FAR[k] + offset[k]);
    assert!(shift.iter().all(|c| c.abs() < 1e-9), "{offset:?}");
    let plain = build(&cow, &f64_options(), None).expect("builds");
    let posed = Pose::translation(shift[0], shift[1], shift[2]);
    assert_same_answers(
        (&centred, &Pose::identity()),
        (&plain, &posed),
        &plain,
        1e-9,
    );

    // Why it matters for f32 files: f32 rounds a coordinate near 0.5 by up to 3e-8, one
    // near 982 by up to 3e-5. The far cow stored as it is (and posed back by −FAR) answers
    // with that error; centred, it answers like the cow built at its origin.
    let pose_b = Pose::translation(1.3, 0.2, 0.0);
    let distance = |a: &ObbtFile, pose_a: &Pose, b: &ObbtFile| {
        PairQuery::new(a, b)
            .expect("same volume and precision")
            .distance(pose_a, &pose_b, &DistanceOptions::default())
            .expect("a distance")
            .distance()
    };
    let reference = distance(&plain, &Pose::identity(), &plain);
    let f32_centred = build(
        &far,
        &BuildOptions {
            center: true,
            ..BuildOptions::default()
        },
        None,
    )
    .expect("builds");
    let f32_plain = build(&cow, &BuildOptions::default(), None).expect("builds");
    let error = (distance(&f32_centred, &Pose::identity(), &f32_plain) - reference).abs();
    assert!(error < 1e-7, "centred f32 file: distance off by {error}");
    let f32_far = build(&far, &BuildOptions::default(), None).expect("builds");
    let back = Pose::translation(-FAR[0], -FAR[1], -FAR[2]);
    let far_error = (distance(&f32_far, &back, &f32_plain) - reference).abs();
    assert!(
        far_error > 10.0 * error,
        "uncentred f32 file: distance off by {far_error}, centred by {error}"
    );
}

/// The cow moved this far (a part in millimetres 30 m from its assembly's origin): f32
/// rounds its coordinates by up to 1e-3, a thousandth of its size, which collapses some of
/// its smallest triangles.
const VERY_FAR: [f64; 3] = [30_000.0, -20_000.0, 10_000.0];

#[test]
fn a_build_reports_rounding_that_is_coarse_for_the_model() {
    let cow = common::cow();
    let shifted = |by: [f64; 3]| moved(&cow, |p| std::array::from_fn(|k| p[k] + by[k]));
    let (far, very_far) = (shifted(FAR), shifted(VERY_FAR));
    let loss = |mesh: &TriMesh, options: &BuildOptions| {
        rounding_loss(mesh, &build(mesh, options, None).expect("builds"))
    };
    let f32_options = BuildOptions::default();
    // At its origin f32 costs the cow about 2e-8 of its size: nothing to report.
    assert_eq!(loss(&cow, &f32_options), None);
    // 982 away, 3e-5 per coordinate: above the reported share, nothing collapsed.
    let at_far = loss(&far, &f32_options).expect("reported");
    assert_eq!(at_far.collapsed, 0);
    assert_eq!(at_far.precision, Precision::F32);
    assert_eq!(at_far.largest_coordinate, far_coordinate(&far));
    assert_eq!(at_far.rounding, 2f64.powi(-15), "half an ulp of f32 at 982");
    assert!(at_far.rounding > REPORTED_ROUNDING * at_far.size);
    let (lo, hi) = bounds(&far);
    let diagonal = (0..3).map(|k| (hi[k] - lo[k]).powi(2)).sum::<f64>().sqrt();
    assert!(
        (at_far.size - diagonal).abs() < 1e-3 * diagonal,
        "{at_far:?}"
    );
    let both = "build with --center or --precision f64 to keep the detail";
    assert_eq!(
        at_far.remedy("--center", "--precision f64").as_deref(),
        Some(both)
    );
    // 3·10⁴ away: some triangles lose their area, and the warning names them.
    let at_very_far = loss(&very_far, &f32_options).expect("reported");
    let stored = build(&very_far, &f32_options, None).expect("builds");
    let collapsed = stored.info().stats.degenerate_triangles as usize;
    assert!(collapsed > 0 && cow.degenerate_triangle_count() == 0);
    assert_eq!(at_very_far.collapsed, collapsed);
    let line = at_very_far.to_string();
    assert!(
        line.starts_with("stored coordinates up to 30000 in f32 move by up to 9.8e-4")
            && line.ends_with(&format!("; {collapsed} triangles collapsed to zero area")),
        "{line}"
    );
    // Centred, or in f64 (stored exactly as given), the same models keep their detail.
    let centred = BuildOptions {
        center: true,
        ..BuildOptions::default()
    };
    assert_eq!(loss(&very_far, &centred), None);
    assert_eq!(loss(&very_far, &f64_options()), None);
    // In f64 with a placement, storing rounds: by a few 1e-12 here, nothing to report.
    let placed = BuildOptions {
        scale: 3.0,
        ..f64_options()
    };
    assert_eq!(loss(&very_far, &placed), None);
}

#[test]
fn collapsed_triangles_are_counted_face_by_face() {
    // Near the origin: a sliver whose apex lies 1e-10 off its base at height 1, where f32
    // cannot hold it (it collapses), and a triangle collinear in the input that f32 gives
    // an area. The second does not cancel the first in the count, and centring cannot
    // help: only f64 keeps the sliver.
    let vertices = vec![
        [0.0, 1.0, 0.0],
        [1.0, 1.0, 0.0],
        [0.5, 1.0 + 1e-10, 0.0],
        [0.5, 2.0, 0.0],
        [0.0, 0.0, 0.0],
        [0.2997118905373848, 0.42268722119765845, 0.0],
        [1.498559452686924, 2.113436105988292, 0.0],
    ];
    let faces = vec![[0, 1, 2], [0, 1, 3], [4, 5, 6]];
    let mesh = TriMesh::new(vertices, faces).expect("a mesh");
    assert_eq!(mesh.degenerate_triangle_count(), 1, "the collinear one");
    let file = build(&mesh, &BuildOptions::default(), None).expect("builds");
    assert_eq!(file.info().stats.degenerate_triangles, 1, "the sliver");
    let loss = rounding_loss(&mesh, &file).expect("the sliver collapsed");
    assert_eq!(loss.collapsed, 1);
    assert_eq!(loss.rounding, 2f64.powi(-23), "half an ulp of f32 at 2.1");
    assert!(loss
        .to_string()
        .ends_with("; 1 triangle collapsed to zero area"));
    assert_eq!(
        loss.remedy("--center", "--precision f64").as_deref(),
        Some("build with --precision f64 to keep the detail")
    );
    let f64_file = build(&mesh, &f64_options(), None).expect("builds");
    assert_eq!(rounding_loss(&mesh, &f64_file), None);
    // A model of no size (one point) is not reported, whatever its coordinates.
    let point = TriMesh::new(vec![[1e6; 3]; 3], vec![[0, 1, 2]]).expect("a mesh");
    let file = build(&point, &BuildOptions::default(), None).expect("builds");
    assert_eq!(rounding_loss(&point, &file), None);
}

/// The largest magnitude of a coordinate of `mesh` rounded to f32, as a file stores it.
fn far_coordinate(mesh: &TriMesh) -> f64 {
    let (lo, hi) = bounds(mesh);
    lo.iter()
        .chain(&hi)
        .map(|&x| f64::from(x as f32).abs())
        .fold(0.0, f64::max)
}

#[test]
fn bad_scales_and_placements_beyond_the_range_are_build_errors() {
    let cube = common::cube(1.0);
    for scale in [0.0, -0.0, -1.0, f64::NAN, f64::INFINITY, f64::NEG_INFINITY] {
        let options = BuildOptions {
            scale,
            ..BuildOptions::default()
        };
        assert!(matches!(options.validate(), Err(BuildError::Scale(_))));
        let err = build(&cube, &options, None).expect_err("refused");
        assert!(matches!(err, BuildError::Scale(_)), "{scale}: {err}");
        assert!(err.to_string().contains("--scale"), "{err}");
    }
    // Scaling beyond the f64 range names the vertex and its input coordinate.
    let huge = common::cuboid([1e10; 3], [0.0; 3]);
    let options = BuildOptions {
        scale: 1e300,
        ..f64_options()
    };
    match build(&huge, &options, None) {
        Err(BuildError::PlacementOverflow { vertex, value, .. }) => {
            assert_eq!((vertex, value), (0, -1e10));
        }
        other => panic!("expected a placement overflow, got {other:?}"),
    }
    // Scaling beyond the f32 range is the f32 overflow, reported with the scaled value; the
    // f64 file holds it.
    let options = BuildOptions {
        scale: 1e39,
        ..BuildOptions::default()
    };
    match build(&cube, &options, None) {
        Err(BuildError::CoordinateOverflow { value, .. }) => assert_eq!(value.abs(), 1e39),
        other => panic!("expected an f32 overflow, got {other:?}"),
    }
    let options = BuildOptions {
        scale: 1e39,
        ..f64_options()
    };
    build(&cube, &options, None)
        .expect("f64 holds 1e39")
        .verify()
        .expect("verifies");
}

/// A small placed file: the unit cube at scale 0.001, moved off centre and centred.
fn placed_cube() -> Vec<u8> {
    let cube = common::cuboid([0.5; 3], [3.0, -2.0, 1.0]);
    let options = BuildOptions {
        scale: 0.001,
        center: true,
        ..BuildOptions::default()
    };
    build(&cube, &options, None)
        .expect("builds")
        .bytes()
        .to_vec()
}

/// The image opened (O(1) checks), or the error's text.
fn open(bytes: &[u8]) -> Result<ObbtFile, String> {
    ObbtFile::from_aligned(AlignedBytes::copy_from(bytes)).map_err(|e| e.to_string())
}

#[test]
fn open_checks_the_placement_entry_and_verify_its_values() {
    let original = placed_cube();
    let file = open(&original).expect("opens");
    let (index, entry) = placement_entry(&file).expect("a placement section");
    // A flipped byte of the record: open reads it as it is; verify's checksum refuses it.
    let record = entry.offset as usize;
    for byte in 0..PLACEMENT_STRIDE as usize {
        let mut bytes = original.clone();
        bytes[record + byte] ^= 0x10;
        let err = open(&bytes).expect("opens").verify().expect_err("refused");
        assert!(
            err.to_string().contains("placement") && err.to_string().contains("checksum"),
            "{err}"
        );
    }
    // Re-sealed values that no build writes: verify names the placement.
    let values: [(usize, f64, &str); 6] = [
        (0, 0.0, "scale"),
        (0, -1.0, "scale"),
        (0, f64::NAN, "scale"),
        (0, f64::INFINITY, "scale"),
        (8, f64::NAN, "offset"),
        (24, f64::NEG_INFINITY, "offset"),
    ];
    for (at, value, needle) in values {
        let mut bytes = original.clone();
        bytes[record + at..record + at + 8].copy_from_slice(&value.to_le_bytes());
        seal(&mut bytes);
        let err = open(&bytes).expect("opens").verify().expect_err("refused");
        assert!(
            err.region == "section placement" && err.problem.contains(needle),
            "{value} at {at}: {err}"
        );
    }
    // Count and stride other than 1 x 32: open refuses.
    for edits in [
        &[("count", 2), ("length", 64)][..],
        &[("count", 2), ("stride", 16)],
        &[("count", 0), ("length", 0)],
    ] {
        let mut bytes = original.clone();
        for &(name, value) in edits {
            let (at, width) = entry_field(index, name);
            write_uint(&mut bytes, at, width, value);
        }
        seal(&mut bytes);
        let err = open(&bytes).expect_err("refused");
        assert!(
            err.contains("placement") && err.contains("header implies 1 of 32"),
            "{edits:?}: {err}"
        );
    }
}

#[test]
fn unknown_optional_kinds_are_still_skipped() {
    let original = placed_cube();
    let file = open(&original).expect("opens");
    let (index, _) = placement_entry(&file).expect("a placement section");
    let (kind_at, _) = entry_field(index, "kind");
    let (flags_at, _) = entry_field(index, "flags");
    // As a reader that does not know kind 5 sees it: an optional section of an unknown
    // kind, skipped (its bytes still count for the checksums and the padding).
    let mut unknown = original.clone();
    write_uint(&mut unknown, kind_at, 4, 99);
    seal(&mut unknown);
    let skipped = open(&unknown).expect("an unknown optional kind is skipped");
    skipped.verify().expect("verifies");
    assert!(skipped.placement().is_identity());
    assert_eq!(skipped.sections()[index].name(), "kind 99");
    // Marked REQUIRED, it is refused.
    write_uint(&mut unknown, flags_at, 4, 1);
    seal(&mut unknown);
    let err = open(&unknown).expect_err("refused");
    assert!(err.contains("required"), "{err}");
}
