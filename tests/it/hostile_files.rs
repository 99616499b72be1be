//! Hostile `.obbt` files: whatever the bytes, `open`, `verify` and a query on the unverified
//! file each end in an error or a valid answer, never a panic, a hang or an out-of-bounds
//! read. Four families, each run raw and re-sealed (checksums recomputed, so that the damage
//! reaches the structural checks and the queries):
//!
//! - byte flips: every byte of small files of every kind, and a seeded 100,000-flip sample
//!   of a large one;
//! - truncations at every section boundary and at random points;
//! - header and directory fields rewritten with extreme values (counts near `u32::MAX`,
//!   offsets past the end, overlapping and misaligned sections);
//! - node references that cycle, point backwards, share children or make an exponential
//!   DAG, and records holding NaN, infinities, negative extents and absurd indices.
//!
//! Where a damaged file still verifies, its collision answer must equal a brute force over
//! the triangles it stores. Each suite prints its tallies (`--nocapture` shows them).
// Test code outside `#[test]` functions (helpers, property bodies): a failure is a failed test.
#![allow(clippy::expect_used, clippy::panic)]

use crate::common;

use common::mutate::{
    entry_field, entry_offset, exercise, extreme_values, header_field, read_uint, write_uint,
    Outcome, Poses, Tally, ENTRY_FIELDS, HEADER_FIELDS,
};
use common::rng::Rng;
use common::seal::seal;
use obbtree::build::{build, BuildOptions};
use obbtree::bv::BvKind;
use obbtree::format::{AlignedBytes, FormatError, ObbtFile};
use obbtree::query::{CollideOptions, PairQuery, Pose, QueryError};
use obbtree::real::Precision;
use rayon::prelude::*;

/// An intact file to damage, with the partner file (same volume type and precision) and
/// the poses its queries use.
struct Subject {
    name: String,
    bytes: Vec<u8>,
    partner: ObbtFile,
    poses: Poses,
}

impl Subject {
    fn new(name: String, file: &ObbtFile, partner: ObbtFile) -> Subject {
        Subject {
            name,
            bytes: file.bytes().to_vec(),
            partner,
            poses: Poses::for_file(file),
        }
    }

    /// Runs [`exercise`] on damaged `bytes` and names the damage if it panics.
    fn run(&self, bytes: &[u8], check_answers: bool, what: &dyn Fn() -> String) -> Outcome {
        let outcome = std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| {
            exercise(bytes, &self.partner, &self.poses, check_answers)
        }));
        match outcome {
            Ok(outcome) => outcome,
            Err(_) => panic!("{}: {} panicked (message above)", self.name, what()),
        }
    }

    /// Writes `value` into the `width`-byte field at byte `at`, re-seals the checksums so the
    /// damage reaches the structural checks, and runs the result. A `refused` field must not
    /// verify with any value but its own.
    fn run_with_field(
        &self,
        at: usize,
        width: usize,
        value: u64,
        refused: bool,
        what: &dyn Fn() -> String,
    ) -> Outcome {
        let mut bytes = self.bytes.clone();
        write_uint(&mut bytes, at, width, value);
        seal(&mut bytes);
        let outcome = self.run(&bytes, true, what);
        if refused {
            assert!(!outcome.verified, "{}: {} accepted", self.name, what());
        }
        outcome
    }
}

/// A small file of every option combination: a unit cube (12 triangles).
fn small_files() -> Vec<Subject> {
    common::all_options()
        .into_iter()
        .map(|options| {
            let file = build(&common::cube(0.5), &options, None).expect("builds");
            let partner = build(&common::uv_sphere(0.6, 4, 6), &options, None).expect("builds");
            Subject::new(format!("{options:?}"), &file, partner)
        })
        .collect()
}

/// The large file of the sampled suites: the bundled cow (5,804 triangles, 870 KB), with the
/// default options.
fn large_file() -> Subject {
    let options = BuildOptions::default();
    let file = build(&common::cow(), &options, None).expect("builds");
    let partner = build(&common::uv_sphere(0.3, 8, 12), &options, None).expect("builds");
    Subject::new("cow".into(), &file, partner)
}

fn print_tally(suite: &str, t: &Tally) {
    println!(
        "{suite}: {} images; refused by open {}, by verify {}, accepted {}; \
         queries on unverified images: {} answered, {} refused",
        t.tried,
        t.refused_by_open,
        t.refused_by_verify,
        t.accepted,
        t.queries_answered,
        t.queries_refused
    );
}

// ---------------------------------------------------------------------------------------
// Byte flips
// ---------------------------------------------------------------------------------------

#[test]
fn every_byte_flip_of_small_files_ends_in_an_error_or_an_exact_answer() {
    let mut raw = Tally::default();
    let mut sealed = Tally::default();
    for subject in small_files() {
        let original = &subject.bytes;
        let per_file: Vec<(Tally, Tally)> = (0..original.len())
            .into_par_iter()
            .map(|i| {
                let mut t = (Tally::default(), Tally::default());
                for mask in [0x01u8, 0x80, 0xff] {
                    let mut bytes = original.clone();
                    bytes[i] ^= mask;
                    let what = || format!("byte {i} ^ {mask:#04x}");
                    let o = subject.run(&bytes, true, &what);
                    assert!(
                        !o.verified,
                        "{}: {} accepted unsealed",
                        subject.name,
                        what()
                    );
                    t.0.add(o);
                    seal(&mut bytes);
                    t.1.add(subject.run(&bytes, true, &|| format!("{} sealed", what())));
                }
                t
            })
            .collect();
        for (r, s) in per_file {
            raw = raw.merge(r);
            sealed = sealed.merge(s);
        }
    }
    print_tally("small files, every byte flip", &raw);
    print_tally("small files, every byte flip, re-sealed", &sealed);
    assert_eq!(raw.accepted, 0);
}

/// How many seeded flips the large-file suite tries raw, and re-sealed. The environment
/// variable `OBBTREE_HOSTILE_FLIPS` overrides the raw count (the re-sealed count is a tenth).
fn large_flips() -> (usize, usize) {
    let raw = std::env::var("OBBTREE_HOSTILE_FLIPS")
        .ok()
        .and_then(|v| v.parse().ok())
        .unwrap_or(100_000);
    (raw, raw / 10)
}

#[test]
fn sampled_flips_of_a_large_file_end_in_an_error_or_an_answer() {
    let subject = large_file();
    let original = &subject.bytes;
    let chunks = 80;
    let flips = |count: usize, sealed: bool, seed: u64| -> Tally {
        (0..chunks)
            .into_par_iter()
            .map(|chunk| {
                let mut rng = Rng::new(seed + chunk as u64);
                let mut bytes = original.clone();
                let mut tally = Tally::default();
                for _ in 0..count / chunks {
                    let i = rng.below(bytes.len());
                    let mask = match rng.below(3) {
                        0 => 0xff,
                        _ => 1u8 << rng.below(8),
                    };
                    bytes[i] ^= mask;
                    let what = || format!("byte {i} ^ {mask:#04x} (sealed: {sealed})");
                    let o = if sealed {
                        let mut copy = bytes.clone();
                        seal(&mut copy);
                        subject.run(&copy, false, &what)
                    } else {
                        let o = subject.run(&bytes, false, &what);
                        assert!(!o.verified, "{}: accepted unsealed", what());
                        o
                    };
                    tally.add(o);
                    bytes[i] ^= mask;
                }
                tally
            })
            .reduce(Tally::default, Tally::merge)
    };
    let (raw_count, sealed_count) = large_flips();
    let raw = flips(raw_count, false, 1);
    let sealed = flips(sealed_count, true, 1_000);
    print_tally("large file, sampled flips", &raw);
    print_tally("large file, sampled flips, re-sealed", &sealed);
    assert_eq!(raw.tried as usize, raw_count / chunks * chunks);
    // A flip inside a section passes `open` (which reads no section), so most of these
    // reach the queries on damaged data: that is the point of the suite.
    assert!(raw.queries_answered + raw.queries_refused > 0);
}

// ---------------------------------------------------------------------------------------
// Truncations
// ---------------------------------------------------------------------------------------

/// Every section boundary (start and end) with neighbours, and `random` seeded points.
fn truncation_points(file: &ObbtFile, random: usize) -> Vec<usize> {
    let len = file.bytes().len();
    let mut points = vec![0, 1, 8, 127, 128, 129];
    let directory_end = entry_offset(file.sections().len());
    points.extend([directory_end - 1, directory_end, directory_end + 1]);
    for s in file.sections() {
        for edge in [s.offset, s.offset + s.length] {
            for delta in [-64i64, -1, 0, 1, 64] {
                points.push((edge as i64 + delta).clamp(0, len as i64) as usize);
            }
        }
    }
    let mut rng = Rng::new(7);
    points.extend((0..random).map(|_| rng.below(len)));
    points.retain(|&p| p < len);
    points.sort_unstable();
    points.dedup();
    points
}

#[test]
fn truncations_at_section_boundaries_and_random_points_are_refused() {
    let subject = large_file();
    let original = &subject.bytes;
    let file = ObbtFile::from_aligned(AlignedBytes::copy_from(original)).expect("opens");
    let points = truncation_points(&file, 1_000);
    let mut raw = Tally::default();
    let mut declared = Tally::default();
    for &len in &points {
        let bytes = &original[..len];
        let err = ObbtFile::from_aligned(AlignedBytes::copy_from(bytes))
            .expect_err("a truncated file is refused");
        assert!(
            matches!(
                err,
                FormatError::TooShort { .. } | FormatError::LengthMismatch { .. }
            ),
            "length {len}: {err}"
        );
        raw.add(subject.run(bytes, false, &|| format!("truncated at {len}")));
        // The same cut with the header claiming the new length, re-sealed: now the
        // directory must notice that sections run past the end.
        if len >= 128 {
            let mut cut = bytes.to_vec();
            let (at, width) = header_field("file_bytes");
            write_uint(&mut cut, at, width, len as u64);
            seal(&mut cut);
            let o = subject.run(&cut, false, &|| format!("cut at {len}, length declared"));
            assert!(
                !o.opened,
                "cut at {len} with its length declared was opened"
            );
            declared.add(o);
        }
    }
    print_tally("large file, truncations", &raw);
    print_tally(
        "large file, truncations with the length declared",
        &declared,
    );
    assert_eq!(raw.refused_by_open, points.len() as u64);
}

// ---------------------------------------------------------------------------------------
// Header and directory fields with extreme values
// ---------------------------------------------------------------------------------------

/// Header fields any change of which must be refused by `open` or `verify`: the rest
/// (minor version, fit method, leaf size upwards, bounds within rounding) may legitimately
/// take other values.
const HEADER_FIELDS_CHECKED: [&str; 16] = [
    "version_major",
    "header_bytes",
    "file_bytes",
    "bv_kind",
    "precision",
    "encoding",
    "section_count",
    "triangles",
    "vertices",
    "nodes",
    "leaves",
    "depth",
    "degenerate_triangles",
    "max_leaf_faces",
    "reserved0",
    "bounds_max.z",
];

#[test]
fn header_fields_with_extreme_values_are_refused_or_harmless() {
    let mut tally = Tally::default();
    for subject in small_files() {
        let original = &subject.bytes;
        let len = original.len() as u64;
        for (field, at, width) in HEADER_FIELDS {
            let old = read_uint(original, at, width);
            for value in extreme_values(width, len) {
                if value == old {
                    continue;
                }
                let what = || format!("header {field} = {value} (was {old})");
                let refused = HEADER_FIELDS_CHECKED.contains(&field);
                tally.add(subject.run_with_field(at, width, value, refused, &what));
            }
        }
    }
    print_tally("header fields, extreme values", &tally);
}

/// Directory fields any change of which must be refused (`flags` may drop the REQUIRED bit
/// of a known kind: a reader that knows the kind needs no flag).
const ENTRY_FIELDS_CHECKED: [&str; 5] = ["kind", "offset", "length", "count", "stride"];

#[test]
fn directory_fields_with_extreme_values_are_refused_or_harmless() {
    let mut tally = Tally::default();
    for subject in small_files() {
        let original = &subject.bytes;
        let len = original.len() as u64;
        let (count_at, count_width) = header_field("section_count");
        let sections = read_uint(original, count_at, count_width) as usize;
        for index in 0..sections {
            for (field, at, width) in ENTRY_FIELDS {
                let at = entry_offset(index) + at;
                let old = read_uint(original, at, width);
                let mut values = extreme_values(width, len);
                // Near misses: misaligned by one, by 8, by 32; one record more or less.
                values.extend([old + 1, old.wrapping_sub(1), old + 8, old + 32, old ^ 64]);
                for value in values {
                    if value == old {
                        continue;
                    }
                    let what = || format!("entry {index} {field} = {value} (was {old})");
                    let refused = ENTRY_FIELDS_CHECKED.contains(&field);
                    tally.add(subject.run_with_field(at, width, value, refused, &what));
                }
            }
        }
    }
    print_tally("directory fields, extreme values", &tally);
}

/// Named layouts that `open` must refuse with a message that says what is wrong.
#[test]
fn overlapping_misaligned_and_oversized_sections_are_named() {
    let file = build(&common::cube(1.0), &BuildOptions::default(), None).expect("builds");
    let original = file.bytes().to_vec();
    let len = original.len() as u64;
    let refused = |edits: &[(usize, &str, u64)], needle: &str| {
        let mut bytes = original.clone();
        for &(index, field, value) in edits {
            let (at, width) = entry_field(index, field);
            write_uint(&mut bytes, at, width, value);
        }
        seal(&mut bytes);
        let err = ObbtFile::from_aligned(AlignedBytes::copy_from(&bytes))
            .expect_err("refused")
            .to_string();
        assert!(err.contains(needle), "{edits:?}: {needle:?} not in {err:?}");
    };
    let offset_of = |index: usize| {
        let (at, width) = entry_field(index, "offset");
        read_uint(&original, at, width)
    };
    // Faces moved onto the vertices: same length, aligned, in bounds, but overlapping.
    refused(&[(1, "offset", offset_of(0))], "overlaps");
    refused(&[(2, "offset", offset_of(2) + 8)], "multiple of 64");
    refused(&[(3, "offset", len)], "past the end");
    refused(&[(3, "offset", u64::MAX - 63)], "past the end");
    refused(&[(3, "length", u64::MAX)], "past the end");
    // A count whose byte length overflows u64 is refused, not wrapped.
    refused(
        &[(0, "count", u64::MAX / 12 + 1), (0, "length", 12)],
        "count",
    );
    // Header counts near u32::MAX contradict the directory (checked before any use).
    let mut bytes = original.clone();
    let (at, width) = header_field("triangles");
    write_uint(&mut bytes, at, width, u64::from(u32::MAX));
    seal(&mut bytes);
    let err = ObbtFile::from_aligned(AlignedBytes::copy_from(&bytes)).expect_err("refused");
    assert!(
        matches!(
            err,
            FormatError::Section { .. } | FormatError::HeaderField { .. }
        ),
        "{err}"
    );
}

// ---------------------------------------------------------------------------------------
// Node references and record values
// ---------------------------------------------------------------------------------------

/// Byte offset of the packed reference inside a node record: it follows the volume's
/// scalars (OBB 15, AABB 6, sphere 4).
fn packed_offset(bv: BvKind, precision: Precision) -> usize {
    let scalars = match bv {
        BvKind::Obb => 15,
        BvKind::Aabb => 6,
        BvKind::Sphere => 4,
    };
    let width = match precision {
        Precision::F32 => 4,
        Precision::F64 => 8,
    };
    scalars * width
}

/// A built file whose nodes can be rewritten: bytes, nodes section offset and stride, and
/// the offset of `packed` inside a record.
struct Editable {
    bytes: Vec<u8>,
    nodes_at: usize,
    stride: usize,
    packed_at: usize,
    node_count: usize,
    faces_at: usize,
    vertices_at: usize,
    source_ids_at: usize,
    scalar: usize,
}

impl Editable {
    fn new(file: &ObbtFile) -> Editable {
        let section = |name: &str| {
            file.sections()
                .iter()
                .find(|s| s.name() == name)
                .cloned()
                .expect("a required section")
        };
        let nodes = section("nodes");
        Editable {
            bytes: file.bytes().to_vec(),
            nodes_at: nodes.offset as usize,
            stride: nodes.stride as usize,
            packed_at: packed_offset(file.bv_kind(), file.precision()),
            node_count: nodes.count as usize,
            faces_at: section("faces").offset as usize,
            vertices_at: section("vertices").offset as usize,
            source_ids_at: section("source_ids").offset as usize,
            scalar: match file.precision() {
                Precision::F32 => 4,
                Precision::F64 => 8,
            },
        }
    }

    fn set_packed(&mut self, node: usize, packed: u32) {
        let at = self.nodes_at + node * self.stride + self.packed_at;
        write_uint(&mut self.bytes, at, 4, u64::from(packed));
    }

    fn packed(&self, node: usize) -> u32 {
        read_uint(
            &self.bytes,
            self.nodes_at + node * self.stride + self.packed_at,
            4,
        ) as u32
    }

    /// Writes scalar `k` of node `node`'s volume.
    fn set_node_scalar(&mut self, node: usize, k: usize, value: f64) {
        let at = self.nodes_at + node * self.stride + k * self.scalar;
        self.set_scalar(at, value);
    }

    fn set_scalar(&mut self, at: usize, value: f64) {
        if self.scalar == 4 {
            write_uint(&mut self.bytes, at, 4, u64::from((value as f32).to_bits()));
        } else {
            write_uint(&mut self.bytes, at, 8, value.to_bits());
        }
    }

    /// Seals the edited bytes and opens them (the damage is in a section, which `open`
    /// does not read).
    fn open(mut self) -> ObbtFile {
        seal(&mut self.bytes);
        ObbtFile::from_aligned(AlignedBytes::copy_from(&self.bytes)).expect("open reads no section")
    }
}

/// Binary-encoded packed value of an internal node whose children are `first, first + 1`.
fn binary_internal(first: u32) -> u32 {
    (first as i32).wrapping_neg() as u32
}

/// Variable-encoded packed value of an internal node with `count` children from `first`.
fn variable_internal(first: u32, count: u32) -> u32 {
    first | ((count - 1) << 25)
}

/// Variable-encoded packed value of a leaf with `count` faces from `first`.
fn variable_leaf(first: u32, count: u32) -> u32 {
    (1 << 31) | first | ((count - 1) << 24)
}

/// Verify refuses the file naming `needle`, and no query on it panics; returns the error
/// of a collision query of the file against itself, if any.
fn refused_by_verify(file: &ObbtFile, needle: &str, what: &str) -> Option<QueryError> {
    let err = file.verify().expect_err(what).to_string();
    assert!(err.contains(needle), "{what}: {needle:?} not in {err:?}");
    let partner = build(&common::cube(0.5), &BuildOptions::default(), None).expect("builds");
    let poses = Poses::for_size(2.0);
    exercise(file.bytes(), &partner, &poses, false);
    PairQuery::new(file, file)
        .and_then(|mut pair| {
            pair.collide(&Pose::identity(), &poses.span, &CollideOptions::default())
        })
        .err()
}

fn binary_file() -> ObbtFile {
    build(
        &common::uv_sphere(1.0, 6, 8),
        &BuildOptions::default(),
        None,
    )
    .expect("builds")
}

fn variable_file() -> ObbtFile {
    let options = BuildOptions {
        leaf_size: 4,
        ..BuildOptions::default()
    };
    build(&common::uv_sphere(1.0, 6, 8), &options, None).expect("builds")
}

/// The first internal node after the root, and its children's first index.
fn some_internal_node(e: &Editable, binary: bool) -> (usize, u32) {
    (1..e.node_count)
        .find_map(|i| {
            let p = e.packed(i);
            let internal = if binary { (p as i32) < 0 } else { p >> 31 == 0 };
            let first = if binary {
                (p as i32).unsigned_abs()
            } else {
                p & ((1 << 25) - 1)
            };
            internal.then_some((i, first))
        })
        .expect("an internal node below the root")
}

#[test]
fn child_references_that_cycle_point_backwards_or_past_the_end_are_caught() {
    for (binary, file) in [(true, binary_file()), (false, variable_file())] {
        let base = Editable::new(&file);
        let (i, first) = some_internal_node(&base, binary);
        let n = base.node_count as u32;
        let internal = |first: u32| {
            if binary {
                binary_internal(first)
            } else {
                variable_internal(first, 2)
            }
        };
        // (In the binary encoding "children at the root" is the packed value 0, which is a
        // leaf holding face 0: a different damage, covered by the flip suites.)
        let mut cases: Vec<(&str, u32, &str)> = vec![
            (
                "a node that is its own child",
                internal(i as u32),
                "not after it",
            ),
            ("children before their parent", internal(1), "not after it"),
            (
                "children past the last node",
                internal(n - 1),
                "not after it",
            ),
            (
                "children far past the end",
                internal(n + 1_000),
                "not after it",
            ),
            (
                "children shared with another node",
                internal(first + 1),
                "parent",
            ),
        ];
        if !binary {
            cases.push(("children at the root", internal(0), "not after it"));
        }
        for (what, packed, needle) in cases {
            let what = format!(
                "{}: node {i} -> {what}",
                if binary { "binary" } else { "variable" }
            );
            let mut e = Editable::new(&file);
            e.set_packed(i, packed);
            let damaged = e.open();
            let query_error = refused_by_verify(&damaged, needle, &what);
            if needle == "not after it" {
                assert!(
                    matches!(query_error, Some(QueryError::CorruptTree { .. })),
                    "{what}: a query must refuse a backwards reference, got {query_error:?}"
                );
            }
        }
        if !binary {
            // The widest child range and the widest leaf, pointing past the end.
            for (what, packed) in [
                ("64 children", variable_internal(n - 2, 64)),
                ("128 faces past the end", variable_leaf(0, 128)),
            ] {
                let mut e = Editable::new(&file);
                e.set_packed(i, packed);
                let damaged = e.open();
                let err = damaged.verify().expect_err(what).to_string();
                assert!(err.contains("node"), "{what}: {err}");
                refused_by_verify(&damaged, "node", what);
            }
        }
    }
}

/// Every internal node pointing at the next two nodes, all with the root's box: a DAG with
/// Fibonacci-many paths, every one of them overlapping. A query visits each node pair of a
/// true tree at most once, so it stops after `nodes_a x nodes_b` visits with an error
/// instead of running for ever.
#[test]
fn an_exponential_dag_of_shared_children_ends_in_an_error() {
    let file = build(
        &common::uv_sphere(1.0, 16, 24),
        &BuildOptions::default(),
        None,
    )
    .expect("builds");
    let mut e = Editable::new(&file);
    let n = e.node_count;
    let root = e.bytes[e.nodes_at..e.nodes_at + e.stride].to_vec();
    for i in 0..n {
        let at = e.nodes_at + i * e.stride;
        e.bytes[at..at + e.stride].copy_from_slice(&root);
    }
    for i in 0..n - 2 {
        e.set_packed(i, binary_internal(i as u32 + 1));
    }
    e.set_packed(n - 2, 0);
    e.set_packed(n - 1, 1);
    let damaged = e.open();
    let err = refused_by_verify(&damaged, "already has parent", "exponential DAG");
    assert!(
        matches!(err, Some(QueryError::CorruptTree { .. })),
        "the pair budget must stop the query: {err:?}"
    );
}

#[test]
fn records_with_non_finite_negative_or_absurd_values_are_caught() {
    type Edit = Box<dyn Fn(&mut Editable)>;
    let cases: Vec<(&str, Edit, &str)> = vec![
        (
            "vertex 0 NaN",
            Box::new(|e| {
                let at = e.vertices_at;
                e.set_scalar(at, f64::NAN)
            }),
            "not finite",
        ),
        (
            "vertex 1 infinite",
            Box::new(|e| {
                let at = e.vertices_at + 3 * e.scalar;
                e.set_scalar(at, f64::INFINITY)
            }),
            "not finite",
        ),
        (
            "face 0 vertex u32::MAX",
            Box::new(|e| {
                let at = e.faces_at;
                write_uint(&mut e.bytes, at, 4, u64::from(u32::MAX))
            }),
            "uses vertex",
        ),
        (
            "source id out of range",
            Box::new(|e| {
                let at = e.source_ids_at;
                write_uint(&mut e.bytes, at, 4, u64::from(u32::MAX))
            }),
            "source_ids",
        ),
        (
            "source id repeated",
            Box::new(|e| {
                let at = e.source_ids_at;
                let second = read_uint(&e.bytes, at + 4, 4);
                write_uint(&mut e.bytes, at, 4, second)
            }),
            "repeats",
        ),
        (
            "root axis NaN",
            Box::new(|e| e.set_node_scalar(0, 0, f64::NAN)),
            "node 0",
        ),
        (
            "root half-width negative",
            Box::new(|e| e.set_node_scalar(0, 12, -1.0)),
            "node 0",
        ),
        (
            "root half-width infinite",
            Box::new(|e| e.set_node_scalar(0, 13, f64::INFINITY)),
            "node 0",
        ),
        (
            "leaf shrunk to nothing",
            Box::new(|e| {
                let last = e.node_count - 1;
                for k in 12..15 {
                    e.set_node_scalar(last, k, 0.0);
                }
            }),
            "node",
        ),
    ];
    for (what, edit, needle) in &cases {
        for file in [binary_file(), variable_file()] {
            let mut e = Editable::new(&file);
            edit(&mut e);
            let damaged = e.open();
            refused_by_verify(&damaged, needle, what);
        }
    }
}
