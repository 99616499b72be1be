//! Any change to a file's bytes is caught: single-byte flips by `open` or `verify`,
//! truncations by `open`. Nothing panics.
// Test code outside `#[test]` functions (helpers, property bodies): a failure is a failed test.
#![allow(clippy::indexing_slicing)]

use crate::common;

use obbtree::build::{build, BuildOptions};
use obbtree::format::{AlignedBytes, FormatError, ObbtFile};

fn assert_rejected(bytes: &[u8], what: &str) {
    match ObbtFile::from_aligned(AlignedBytes::copy_from(bytes)) {
        Err(_) => {}
        Ok(file) => {
            assert!(
                file.verify().is_err(),
                "{what}: verify accepted a modified file"
            );
        }
    }
}

/// Every byte of `file`, XORed with 0x01 and with 0xff, is refused by open or verify.
fn assert_every_flip_rejected(file: &ObbtFile, what: &str) {
    let original = file.bytes().to_vec();
    for i in 0..original.len() {
        for mask in [0x01u8, 0xff] {
            let mut bytes = original.clone();
            bytes[i] ^= mask;
            assert_rejected(&bytes, &format!("{what} byte {i} ^ {mask:#x}"));
        }
    }
}

#[test]
fn every_single_byte_flip_of_a_small_file_is_detected() {
    for options in common::all_options() {
        let file = build(&common::cube(1.0), &options, None).unwrap();
        assert_every_flip_rejected(&file, &format!("{options:?}"));
    }
}

#[test]
fn every_single_byte_flip_of_a_placed_file_is_detected() {
    // With the optional placement section (format 1.1), its directory entry and its record
    // are covered like every other byte.
    let cuboid = common::cuboid([0.5; 3], [3.0, -2.0, 1.0]);
    for options in common::all_options() {
        let options = BuildOptions {
            scale: 0.001,
            center: true,
            ..options
        };
        let file = build(&cuboid, &options, None).unwrap();
        assert!(!file.placement().is_identity());
        assert_every_flip_rejected(&file, &format!("{options:?}"));
    }
}

#[test]
fn sampled_byte_flips_of_a_larger_file_are_detected() {
    let file = build(
        &common::cow(),
        &BuildOptions {
            leaf_size: 4,
            ..BuildOptions::default()
        },
        None,
    )
    .unwrap();
    let original = file.bytes().to_vec();
    let mut rng = common::rng::Rng::new(1);
    for _ in 0..300 {
        let i = rng.below(original.len());
        let mut bytes = original.clone();
        bytes[i] ^= 1 << rng.below(8);
        assert_rejected(&bytes, &format!("byte {i}"));
    }
}

#[test]
fn every_truncation_is_refused_by_open() {
    let file = build(
        &common::uv_sphere(1.0, 6, 8),
        &BuildOptions::default(),
        None,
    )
    .unwrap();
    let bytes = file.bytes();
    for len in 0..bytes.len() {
        let err = ObbtFile::from_aligned(AlignedBytes::copy_from(&bytes[..len])).unwrap_err();
        assert!(
            matches!(
                err,
                FormatError::TooShort { .. } | FormatError::LengthMismatch { .. }
            ),
            "length {len}: {err}"
        );
    }
    // Extra bytes are refused too: the declared length is exact.
    let mut longer = bytes.to_vec();
    longer.extend([0u8; 64]);
    assert!(ObbtFile::from_aligned(AlignedBytes::copy_from(&longer)).is_err());
}

#[test]
fn intact_files_verify_and_errors_name_the_section() {
    let file = build(
        &common::uv_sphere(1.0, 8, 16),
        &BuildOptions::default(),
        None,
    )
    .unwrap();
    file.verify().unwrap();
    let nodes = file
        .sections()
        .iter()
        .find(|s| s.name() == "nodes")
        .unwrap();
    let mut bytes = file.bytes().to_vec();
    bytes[nodes.offset as usize + 3] ^= 0x10;
    let damaged = ObbtFile::from_aligned(AlignedBytes::copy_from(&bytes)).unwrap();
    let err = damaged.verify().unwrap_err();
    assert!(
        err.to_string().contains("nodes") && err.to_string().contains("checksum"),
        "{err}"
    );
}

#[test]
fn misaligned_buffers_are_refused() {
    let file = build(&common::cube(1.0), &BuildOptions::default(), None).unwrap();
    let mut shifted = AlignedBytes::zeroed(file.bytes().len() + 1);
    shifted.as_mut_bytes()[1..].copy_from_slice(file.bytes());
    // Re-wrapping at an odd address is impossible through the public API, so check the
    // copying constructor instead: it always aligns.
    let copy = AlignedBytes::copy_from(&shifted.as_bytes()[1..]);
    assert!(ObbtFile::from_aligned(copy).is_ok());
}

/// `info --levels` walks every node of a file it has not verified: with any byte of a
/// small file flipped it ends, with levels or an error, and never panics.
#[test]
fn level_walks_of_files_with_any_byte_flipped_end_without_panicking() {
    for options in common::all_options() {
        let file = build(&common::cube(1.0), &options, None).unwrap();
        let original = file.bytes().to_vec();
        let intact = file.level_stats().unwrap();
        assert_eq!(
            intact.iter().map(|l| l.nodes).sum::<u64>(),
            u64::from(file.info().nodes)
        );
        for i in 0..original.len() {
            for mask in [0x01u8, 0x80, 0xff] {
                let mut bytes = original.clone();
                bytes[i] ^= mask;
                if let Ok(damaged) = ObbtFile::from_aligned(AlignedBytes::copy_from(&bytes)) {
                    if let Ok(levels) = damaged.level_stats() {
                        // However damaged, a walk visits each node at most once.
                        let nodes: u64 = levels.iter().map(|l| l.nodes).sum();
                        assert!(
                            nodes <= u64::from(damaged.info().nodes),
                            "byte {i} ^ {mask:#x}"
                        );
                    }
                }
            }
        }
    }
}
