//! Node layouts (format 1.2): the compact layout's quantised boxes give the answers of the
//! fast layout in under a third of the bytes, are recorded in the header, and a header that
//! asks for a layout that does not exist is refused by name.
// Test code outside `#[test]` functions (helpers, property bodies): a failure is a failed test.
#![allow(clippy::expect_used, clippy::indexing_slicing)]

use crate::common;

use common::seal::seal;
use obbtree::build::{build, BuildError, BuildOptions};
use obbtree::bv::{BvKind, Layout};
use obbtree::format::layout::{Header, LAYOUT_MINOR_VERSION};
use obbtree::format::{AlignedBytes, FormatError, ObbtFile};
use obbtree::query::{CollideOptions, DistanceOptions, PairQuery, QueryError};
use obbtree::real::Precision;

/// The options of the compact layout, at its default leaf size.
fn compact() -> BuildOptions {
    BuildOptions {
        layout: Layout::Compact,
        leaf_size: Layout::Compact.default_leaf_size(),
        ..BuildOptions::default()
    }
}

#[test]
fn compact_cow_is_recorded_verifies_and_takes_under_a_third_of_the_bytes() {
    let cow = common::cow();
    let fast = build(&cow, &BuildOptions::default(), None).expect("fast build");
    let small = build(&cow, &compact(), None).expect("compact build");
    let info = small.info();
    assert_eq!(info.layout, Layout::Compact);
    assert_eq!(info.version, (1, LAYOUT_MINOR_VERSION));
    assert_eq!(
        small.bytes()[Header::AT.layout.offset],
        Layout::Compact.tag()
    );
    assert_eq!(small.node_type().to_string(), "obb f32 compact");
    // A fast file stays the version its sections need (1.0 without a placement).
    assert_eq!(fast.info().version, (1, 0));
    assert_eq!(fast.info().layout, Layout::Fast);
    let ratio = info.file_bytes as f64 / fast.info().file_bytes as f64;
    assert!(ratio < 1.0 / 3.0, "compact / fast bytes = {ratio}");
    // Every decoded box contains the corners below it, as tight as the f32 tests require.
    common::assert_tight_enough(&small, 1e-6);
    // The bytes read back as the same tree.
    let reopened = ObbtFile::from_aligned(AlignedBytes::copy_from(small.bytes())).expect("opens");
    assert_eq!(reopened.info(), info);
}

#[test]
fn compact_trees_answer_as_fast_trees_on_the_cow() {
    let cow = common::cow();
    let fast = build(&cow, &BuildOptions::default(), None).expect("fast build");
    let small = build(&cow, &compact(), None).expect("compact build");
    let mut fast_pair = PairQuery::new(&fast, &fast).expect("a pair");
    let mut small_pair = PairQuery::new(&small, &small).expect("a pair");
    let (mut touching, mut apart) = (0, 0);
    for seed in 0..40 {
        let pose_a = common::turned_pose(seed, 0.0);
        let pose_b = common::turned_pose(seed + 1000, 0.3 + 0.05 * seed as f64);
        let options = CollideOptions::default();
        let a = fast_pair
            .collide(&pose_a, &pose_b, &options)
            .expect("collide");
        let b = small_pair
            .collide(&pose_a, &pose_b, &options)
            .expect("collide");
        assert_eq!(a.pairs, b.pairs, "seed {seed}");
        let options = DistanceOptions::default();
        let a = fast_pair
            .distance(&pose_a, &pose_b, &options)
            .expect("distance");
        let b = small_pair
            .distance(&pose_a, &pose_b, &options)
            .expect("distance");
        // Both exact: the same distance up to the rounding of the triangle tests.
        let (da, db) = (a.distance(), b.distance());
        assert!(
            (da - db).abs() <= 1e-12 * (1.0 + da),
            "seed {seed}: {da} {db}"
        );
        if da > 0.0 {
            apart += 1
        } else {
            touching += 1
        }
    }
    assert!(
        touching >= 5 && apart >= 5,
        "{touching} touching, {apart} apart"
    );
}

#[test]
fn compact_layout_is_refused_where_it_does_not_exist() {
    let cow = common::cow();
    for (bv, precision) in [
        (BvKind::Obb, Precision::F64),
        (BvKind::Aabb, Precision::F32),
        (BvKind::Sphere, Precision::F32),
    ] {
        let options = BuildOptions {
            bv,
            precision,
            ..compact()
        };
        let error = build(&cow, &options, None).expect_err("no such layout");
        assert!(matches!(error, BuildError::Layout(_)), "{error}");
        assert!(error.to_string().contains("compact layout"), "{error}");
    }
    // Trees of two layouts are not queried together.
    let fast = build(&cow, &BuildOptions::default(), None).expect("fast build");
    let small = build(&cow, &compact(), None).expect("compact build");
    let Err(error) = PairQuery::new(&fast, &small) else {
        panic!("trees of two layouts were paired");
    };
    assert!(
        matches!(error, QueryError::MismatchedTrees { .. }),
        "{error}"
    );
    assert!(error.to_string().contains("obb f32 compact"), "{error}");
}

#[test]
fn open_refuses_an_unknown_layout_and_a_compact_f64_header() {
    let cow = common::cow();
    let small = build(&cow, &compact(), None).expect("compact build");
    let at = Header::AT;
    for (offset, value, expected) in [
        (at.layout.offset, 7u8, "unknown tag 7"),
        (at.precision.offset, Precision::F64.tag(), "compact layout"),
    ] {
        let mut bytes = small.bytes().to_vec();
        bytes[offset] = value;
        seal(&mut bytes);
        let error = ObbtFile::from_aligned(AlignedBytes::copy_from(&bytes)).expect_err("refused");
        assert!(matches!(error, FormatError::HeaderField { .. }), "{error}");
        let message = error.to_string();
        assert!(
            message.contains("layout") && message.contains(expected),
            "{message}"
        );
    }
}

#[test]
fn compact_builds_refuse_coordinates_beyond_their_range() {
    let cow = common::cow();
    // Coordinates up to 2e38: finite in f32 and in the fast layout's boxes, beyond what
    // the compact layout's bfloat16 half-widths can span.
    let scale = 4e38;
    let fast = BuildOptions {
        scale,
        ..BuildOptions::default()
    };
    build(&cow, &fast, None)
        .expect("a fast build")
        .verify()
        .expect("verifies");
    let error = build(&cow, &BuildOptions { scale, ..compact() }, None).expect_err("refused");
    assert!(matches!(error, BuildError::CompactRange { .. }), "{error}");
    assert!(error.to_string().contains("--layout fast"), "{error}");
    // Just inside the range, a compact build verifies.
    let inside = BuildOptions {
        scale: 1.9e38,
        ..compact()
    };
    build(&cow, &inside, None)
        .expect("a compact build")
        .verify()
        .expect("verifies");
}
