//! The OBJ and STL loaders and `TriMesh` validation, on the fixtures in
//! `tests/fixtures/mesh/`, the bundled `assets/cow.obj`, and bytes made here.
// Test code outside `#[test]` functions (helpers, property bodies): a failure is a failed test.
#![allow(clippy::expect_used, clippy::panic, clippy::indexing_slicing)]

use std::alloc::{GlobalAlloc, Layout, System};
use std::cell::Cell;
use std::path::{Path, PathBuf};

use obbtree::mesh::{Location, MeshError, TriMesh};
use proptest::prelude::*;

// ---------------------------------------------------------------------------
// Helpers

/// Path of a fixture file.
fn fixture(name: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("tests/fixtures/mesh")
        .join(name)
}

/// Loads a fixture that must load.
fn load_ok(name: &str) -> TriMesh {
    match TriMesh::load(&fixture(name)) {
        Ok(mesh) => mesh,
        Err(error) => panic!("{name} should load: {error}"),
    }
}

/// Loads a fixture that must fail; returns the error and its message.
fn load_err(name: &str) -> (MeshError, String) {
    match TriMesh::load(&fixture(name)) {
        Ok(mesh) => panic!("{name} should fail, loaded {mesh:?}"),
        Err(error) => {
            let message = error.to_string();
            (error, message)
        }
    }
}

/// Parses OBJ text that must fail.
fn obj_err(text: &[u8]) -> (MeshError, String) {
    match TriMesh::from_obj_bytes(text, "gen.obj") {
        Ok(mesh) => panic!("should fail, loaded {mesh:?}"),
        Err(error) => {
            let message = error.to_string();
            (error, message)
        }
    }
}

/// Parses STL bytes that must fail.
fn stl_err(bytes: &[u8]) -> (MeshError, String) {
    match TriMesh::from_stl_bytes(bytes, "gen.stl") {
        Ok(mesh) => panic!("should fail, loaded {mesh:?}"),
        Err(error) => {
            let message = error.to_string();
            (error, message)
        }
    }
}

/// A binary STL with the given 80-byte header start and triangles.
fn binary_stl(header: &[u8], triangles: &[[[f32; 3]; 3]]) -> Vec<u8> {
    let mut bytes = vec![b' '; 80];
    bytes[..header.len()].copy_from_slice(header);
    bytes.extend_from_slice(&(triangles.len() as u32).to_le_bytes());
    for triangle in triangles {
        bytes.extend_from_slice(&[0; 12]); // normal
        for corner in triangle {
            for value in corner {
                bytes.extend_from_slice(&value.to_le_bytes());
            }
        }
        bytes.extend_from_slice(&[0; 2]); // attribute
    }
    bytes
}

/// The corner positions of every face, in face order.
fn corners(mesh: &TriMesh) -> Vec<[[f64; 3]; 3]> {
    let v = mesh.vertices();
    mesh.faces()
        .iter()
        .map(|f| f.map(|i| v[i as usize]))
        .collect()
}

/// An error case: input, variant check, expected message part.
type Case<T> = (T, fn(&MeshError) -> bool, &'static str);

/// A scratch directory for files written by a test.
fn scratch_dir(test: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("obbtree-mesh-{}-{test}", std::process::id()));
    std::fs::create_dir_all(&dir).expect("create scratch dir");
    dir
}

// The largest single allocation made by the current thread, to check that a
// lying binary STL header allocates nothing big. Thread-local, so the other
// tests running in parallel do not disturb it.
thread_local! {
    static LARGEST_ALLOCATION: Cell<usize> = const { Cell::new(0) };
}

/// The system allocator, recording per thread the largest request.
struct TrackingAllocator;

// SAFETY: every call is forwarded unchanged to `System`; the bookkeeping
// touches only a const-initialised thread-local `Cell` (no allocation, no
// destructor), through `try_with` so it is skipped during thread teardown.
unsafe impl GlobalAlloc for TrackingAllocator {
    unsafe fn alloc(&self, layout: Layout) -> *mut u8 {
        let _ =
            LARGEST_ALLOCATION.try_with(|largest| largest.set(largest.get().max(layout.size())));
        // SAFETY: same contract as ours.
        unsafe { System.alloc(layout) }
    }
    unsafe fn dealloc(&self, ptr: *mut u8, layout: Layout) {
        // SAFETY: same contract as ours.
        unsafe { System.dealloc(ptr, layout) }
    }
    unsafe fn realloc(&self, ptr: *mut u8, layout: Layout, new_size: usize) -> *mut u8 {
        let _ = LARGEST_ALLOCATION.try_with(|largest| largest.set(largest.get().max(new_size)));
        // SAFETY: same contract as ours.
        unsafe { System.realloc(ptr, layout, new_size) }
    }
}

#[global_allocator]
static ALLOCATOR: TrackingAllocator = TrackingAllocator;

// ---------------------------------------------------------------------------
// OBJ: valid files

#[test]
fn obj_polygons_fan_triangulate_in_file_order() {
    let mesh = load_ok("polygons.obj");
    assert_eq!(mesh.vertices().len(), 9);
    assert_eq!(mesh.vertices()[7], [2.5, 2.0, 0.0]);
    // quad (1 2 3 4), pentagon (5 6 7 8 9), triangle (1 5 9): ids 0-1, 2-4, 5.
    assert_eq!(
        mesh.faces(),
        &[
            [0, 1, 2],
            [0, 2, 3],
            [4, 5, 6],
            [4, 6, 7],
            [4, 7, 8],
            [0, 4, 8]
        ]
    );
}

#[test]
fn obj_objects_groups_and_materials_merge_into_one_soup() {
    let mesh = load_ok("groups.obj");
    // All five `v` lines, in file order, including the one no face uses.
    assert_eq!(
        mesh.vertices(),
        &[
            [0.0, 0.0, 0.0],
            [1.0, 0.0, 0.0],
            [0.0, 1.0, 0.0],
            [5.0, 5.0, 5.0],
            [0.0, 0.0, 1.0]
        ]
    );
    // Faces of objects "first", "second"/part_a and part_b, in file order,
    // indexing the file's vertices (not per-object renumbered ones).
    assert_eq!(mesh.faces(), &[[0, 1, 2], [4, 2, 1], [0, 4, 1]]);
}

#[test]
fn obj_negative_indices_count_back_from_the_current_line() {
    let mesh = load_ok("negative.obj");
    assert_eq!(mesh.vertices().len(), 4);
    assert_eq!(mesh.faces(), &[[0, 1, 2], [0, 3, 1], [0, 3, 1]]);
}

#[test]
fn obj_corner_forms_keep_only_the_position_index() {
    let mesh = load_ok("corner_forms.obj");
    assert_eq!(mesh.vertices().len(), 4);
    assert_eq!(mesh.faces(), &[[0, 1, 2], [0, 1, 3], [0, 2, 3], [1, 2, 3]]);
}

#[test]
fn obj_statements_other_readers_mishandle_are_tolerated() {
    // CRLF endings, a Latin-1 comment, a UTF-8 BOM, per-vertex colours on one
    // vertex only, a `w` weight, a bare `usemtl`, and `l` / `p` statements:
    // general OBJ readers (tobj, once used here) fail on several of these or
    // turn `l 1 2 3` into a triangle.
    let mut text = b"\xef\xbb\xbfv 0 0 0 1 0 0\r\n# caf\xe9\r\n".to_vec();
    text.extend_from_slice(b"v 1 0 0\r\nv 0 1 0 2\r\nv 0 0 1\r\nusemtl\r\ns off\r\n");
    text.extend_from_slice(b"l 1 2 3\r\np 4\r\nf 1 2 3\r\nf 1 2 4\r\n");
    let mesh = TriMesh::from_obj_bytes(&text, "tolerated.obj").expect("loads");
    assert_eq!(mesh.faces(), &[[0, 1, 2], [0, 1, 3]]);
    assert_eq!(mesh.vertices()[0], [0.0, 0.0, 0.0], "colour dropped");
    assert_eq!(mesh.vertices()[2], [0.0, 1.0, 0.0], "w is not a divisor");
}

#[test]
fn obj_texture_and_normal_indices_are_ignored_even_when_absurd() {
    // These made tobj 4.0.5, once used here, panic (index overflow) even in
    // release builds; a soup reads no texture or normal index.
    let head = "v 0 0 0\nv 1 0 0\nv 0 1 0\nvt 0 0\nvn 0 0 1\n";
    for face in [
        "f 1//6148914691236517206 2//1 3//1",
        "f 1/-5 2/1 3/1",
        "f 1/9223372036854775807/1 2/1/1 3/1/1",
        "f 1/0/0 2/7/7 3/1/1",
    ] {
        let text = format!("{head}{face}\n");
        let mesh = TriMesh::from_obj_bytes(text.as_bytes(), "absurd.obj")
            .unwrap_or_else(|e| panic!("{face}: {e}"));
        assert_eq!(mesh.faces(), &[[0, 1, 2]], "{face}");
    }
}

#[test]
fn obj_values_are_f64_and_unchanged() {
    let text = b"v 0.1 -1e-300 16777217\nv 1 0 0\nv 0 1 0\nf 1 2 3\n";
    let mesh = TriMesh::from_obj_bytes(text, "precise.obj").expect("loads");
    assert_eq!(mesh.vertices()[0], [0.1, -1e-300, 16777217.0]);
}

#[test]
fn bundled_cow_loads_with_its_known_counts() {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("assets/cow.obj");
    let mesh = TriMesh::load(&path).expect("assets/cow.obj loads");
    assert_eq!(mesh.vertices().len(), 2904);
    assert_eq!(mesh.faces().len(), 5804);
    // First line `v 0.281526 0.266379 -1.55991e-08` stays vertex 0, unchanged.
    assert_eq!(mesh.vertices()[0], [0.281526, 0.266379, -1.55991e-08]);
    assert_eq!(mesh.degenerate_triangle_count(), 0);
}

// ---------------------------------------------------------------------------
// OBJ: malformed files

#[test]
fn obj_out_of_range_index_names_file_line_and_index() {
    let (error, message) = load_err("bad_index.obj");
    assert!(
        matches!(
            error,
            MeshError::IndexOutOfRange {
                vertex_count: 4,
                ..
            }
        ),
        "{error:?}"
    );
    assert!(
        message.ends_with("bad_index.obj:7: face index 9000 out of range (4 vertices)"),
        "{message}"
    );
}

#[test]
fn obj_negative_index_out_of_range_counts_only_earlier_vertices() {
    let (error, message) = load_err("bad_negative.obj");
    assert!(
        matches!(
            error,
            MeshError::IndexOutOfRange {
                vertex_count: 3,
                ..
            }
        ),
        "{error:?}"
    );
    assert!(
        message.ends_with("bad_negative.obj:4: face index -5 out of range (3 vertices)"),
        "{message}"
    );
}

#[test]
fn obj_nan_coordinate_names_its_line() {
    let (error, message) = load_err("nan.obj");
    assert!(
        matches!(&error, MeshError::NonFinite { place, value } if value.is_nan() && place.at == Location::Line(3)),
        "{error:?}"
    );
    assert!(message.contains("nan.obj:3:"), "{message}");
}

#[test]
fn obj_coordinate_overflowing_f64_is_non_finite() {
    let (error, message) = obj_err(b"v 0 0 0\nv 1 0 0\n\nv 0 1e999 0\nf 1 2 3\n");
    assert!(
        matches!(error, MeshError::NonFinite { value, .. } if value == f64::INFINITY),
        "{error:?}"
    );
    assert!(message.contains("gen.obj:4:"), "{message}");
}

#[test]
fn obj_without_faces_is_no_faces() {
    let (error, message) = load_err("no_faces.obj");
    assert!(
        matches!(
            error,
            MeshError::NoFaces {
                vertex_count: 3,
                ..
            }
        ),
        "{error:?}"
    );
    assert!(message.contains("no_faces.obj"), "{message}");
}

#[test]
fn obj_empty_file_is_empty_mesh() {
    let (error, message) = load_err("empty.obj");
    assert!(matches!(error, MeshError::EmptyMesh { .. }), "{error:?}");
    assert!(message.contains("empty.obj"), "{message}");
}

#[test]
fn obj_face_with_two_corners_is_a_syntax_error() {
    let (error, message) = load_err("two_corners.obj");
    assert!(matches!(error, MeshError::Syntax { .. }), "{error:?}");
    assert!(
        message.contains("two_corners.obj:5:") && message.contains("2 vertices"),
        "{message}"
    );
}

#[test]
fn obj_garbage_coordinate_is_a_syntax_error_quoting_it() {
    let (error, message) = load_err("garbage.obj");
    assert!(matches!(error, MeshError::Syntax { .. }), "{error:?}");
    assert!(
        message.contains("garbage.obj:2:") && message.contains("\"zero\""),
        "{message}"
    );
}

#[test]
fn obj_bad_faces_name_their_line() {
    let head = "v 0 0 0\nv 1 0 0\nv 0 1 0\n";
    let cases: [Case<&str>; 7] = [
        (
            "f 1 2 99999999999999999999999999",
            |e| matches!(e, MeshError::IndexOutOfRange { .. }),
            "99999999999999999999999999",
        ),
        (
            "f 0 1 2",
            |e| matches!(e, MeshError::IndexOutOfRange { .. }),
            "face index 0 out of range (4 vertices)",
        ),
        (
            "f 1 2 -9223372036854775808",
            |e| matches!(e, MeshError::IndexOutOfRange { .. }),
            "-9223372036854775808",
        ),
        (
            "f 1 2 x",
            |e| matches!(e, MeshError::Syntax { .. }),
            "\"x\"",
        ),
        (
            "f 1 2 3.5",
            |e| matches!(e, MeshError::Syntax { .. }),
            "\"3.5\"",
        ),
        (
            "f 1 2 //3",
            |e| matches!(e, MeshError::Syntax { .. }),
            "no vertex index",
        ),
        ("f", |e| matches!(e, MeshError::Syntax { .. }), "0 vertices"),
    ];
    for (face, is_expected, quoted) in cases {
        let (error, message) = obj_err(format!("{head}{face}\nv 1 1 1\n").as_bytes());
        assert!(is_expected(&error), "{face}: {error:?}");
        assert!(message.starts_with("gen.obj:4: "), "{face}: {message}");
        assert!(message.contains(quoted), "{face}: {message}");
    }
}

#[test]
fn obj_reports_the_first_problem_in_reading_order() {
    // A NaN on line 2 comes before a short face on line 4 and an index out of range on
    // line 3; within a line, the corners are read left to right before their count.
    let text = b"v 0 0 0\nv nan 0 0\nf 1 2 7\nf 1 2\n";
    let (error, message) = obj_err(text);
    assert!(matches!(error, MeshError::NonFinite { .. }), "{error:?}");
    assert!(message.starts_with("gen.obj:2: "), "{message}");
    let (_, message) = obj_err(b"v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 x\n");
    assert!(
        message.starts_with("gen.obj:4: bad face index"),
        "{message}"
    );
}

#[test]
fn obj_forward_reference_to_a_later_vertex_is_allowed() {
    let mesh =
        TriMesh::from_obj_bytes(b"f 1 2 3\nv 0 0 0\nv 1 0 0\nv 0 1 0\n", "fwd.obj").expect("loads");
    assert_eq!(mesh.faces(), &[[0, 1, 2]]);
}

#[test]
fn obj_vertex_with_two_coordinates_is_a_syntax_error() {
    let (error, message) = obj_err(b"v 0 0 0\nv 1 0\nv 0 1 0\nf 1 2 3\n");
    assert!(matches!(error, MeshError::Syntax { .. }), "{error:?}");
    assert!(
        message.starts_with("gen.obj:2: vertex needs 3 coordinates, found 2"),
        "{message}"
    );
}

// ---------------------------------------------------------------------------
// STL

const TWO_TRIANGLES: [[[f32; 3]; 3]; 2] = [
    [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]],
    [[1.0, 0.0, 0.0], [0.1, 0.2, -0.0], [0.0, 1.0, 0.0]],
];

#[test]
fn binary_stl_welds_identical_positions_in_first_occurrence_order() {
    let bytes = binary_stl(b"made by a test", &TWO_TRIANGLES);
    let mesh = TriMesh::from_stl_bytes(&bytes, "two.stl").expect("loads");
    assert_eq!(mesh.faces(), &[[0, 1, 2], [1, 3, 2]]);
    // f32 to f64 exactly: 0.1f32 is not 0.1.
    assert_eq!(
        mesh.vertices()[3],
        [f64::from(0.1f32), f64::from(0.2f32), 0.0]
    );
    assert_eq!(mesh.vertices().len(), 4);
    // Welding keeps every face's geometry.
    let expected: Vec<[[f64; 3]; 3]> = TWO_TRIANGLES
        .iter()
        .map(|t| t.map(|c| c.map(f64::from)))
        .collect();
    assert_eq!(corners(&mesh), expected);
}

#[test]
fn stl_negative_zero_welds_with_zero() {
    let triangles = [
        [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]],
        [[-0.0, 0.0, -0.0], [0.0, -1.0, 0.0], [1.0, -0.0, 0.0]],
    ];
    let mesh = TriMesh::from_stl_bytes(&binary_stl(b"", &triangles), "zeros.stl").expect("loads");
    assert_eq!(mesh.vertices().len(), 4);
    assert_eq!(mesh.faces(), &[[0, 1, 2], [0, 3, 1]]);
    assert!(
        mesh.vertices()[0].iter().all(|x| x.to_bits() == 0),
        "stored as +0.0"
    );
}

#[test]
fn binary_stl_whose_header_starts_with_solid_is_binary() {
    let bytes = binary_stl(b"solid exported_by_a_cad_tool", &TWO_TRIANGLES);
    let mesh = TriMesh::from_stl_bytes(&bytes, "solid_header.stl").expect("loads as binary");
    assert_eq!(mesh.faces().len(), 2);
    assert_eq!(mesh.vertices().len(), 4);
}

#[test]
fn ascii_stl_fixture_loads_with_shared_vertices() {
    let mesh = load_ok("two_facets.stl");
    assert_eq!(
        mesh.vertices(),
        &[
            [0.0, 0.0, 0.0],
            [1.0, 0.0, 0.0],
            [0.0, 1.0, 0.0],
            [0.0, 0.0, -1.5e-3],
            [1.0, 1.0, 0.0]
        ]
    );
    assert_eq!(mesh.faces(), &[[0, 1, 2], [1, 0, 3], [2, 1, 4]]);
}

#[test]
fn stl_loading_is_deterministic() {
    let bytes = binary_stl(b"", &TWO_TRIANGLES);
    let first = TriMesh::from_stl_bytes(&bytes, "a.stl").expect("loads");
    for _ in 0..5 {
        assert_eq!(
            TriMesh::from_stl_bytes(&bytes, "a.stl").expect("loads"),
            first
        );
    }
}

#[test]
fn truncated_binary_stl_reports_expected_and_actual_length() {
    let mut bytes = binary_stl(b"", &TWO_TRIANGLES);
    bytes.truncate(bytes.len() - 7); // 184 - 7 = 177
    let (error, message) = stl_err(&bytes);
    assert!(
        matches!(
            error,
            MeshError::BinaryStlLength {
                triangles: Some(2),
                expected_len: 184,
                actual_len: 177,
                ..
            }
        ),
        "{error:?}"
    );
    assert!(
        message.starts_with("gen.stl: truncated binary STL"),
        "{message}"
    );
    assert!(
        message.contains("184") && message.contains("177"),
        "{message}"
    );
}

#[test]
fn truncated_binary_stl_with_solid_header_is_still_reported_as_binary() {
    let mut bytes = binary_stl(b"solid looks like text", &TWO_TRIANGLES);
    bytes.truncate(150);
    let (error, message) = stl_err(&bytes);
    assert!(
        matches!(
            error,
            MeshError::BinaryStlLength {
                actual_len: 150,
                ..
            }
        ),
        "{error:?}"
    );
    assert!(message.contains("truncated"), "{message}");
}

#[test]
fn binary_stl_with_trailing_bytes_is_inconsistent() {
    let mut bytes = binary_stl(b"", &TWO_TRIANGLES);
    bytes.extend_from_slice(&[0; 10]);
    let (error, message) = stl_err(&bytes);
    assert!(
        matches!(
            error,
            MeshError::BinaryStlLength {
                expected_len: 184,
                actual_len: 194,
                ..
            }
        ),
        "{error:?}"
    );
    assert!(message.contains("inconsistent"), "{message}");
}

#[test]
fn stl_shorter_than_a_header_is_an_error() {
    let (error, message) = stl_err(b"not a mesh");
    assert!(
        matches!(
            error,
            MeshError::BinaryStlLength {
                triangles: None,
                ..
            }
        ),
        "{error:?}"
    );
    assert!(
        message.contains("gen.stl") && message.contains("84"),
        "{message}"
    );
}

#[test]
fn binary_stl_claiming_4g_triangles_fails_fast_without_allocating() {
    let mut bytes = vec![0u8; 100];
    bytes[80..84].copy_from_slice(&u32::MAX.to_le_bytes());
    LARGEST_ALLOCATION.with(|largest| largest.set(0));
    let start = std::time::Instant::now();
    let result = TriMesh::from_stl_bytes(&bytes, "liar.stl");
    let elapsed = start.elapsed();
    let largest = LARGEST_ALLOCATION.with(Cell::get);
    let error = result.expect_err("must fail");
    assert!(
        matches!(
            error,
            MeshError::BinaryStlLength {
                triangles: Some(u32::MAX),
                actual_len: 100,
                ..
            }
        ),
        "{error:?}"
    );
    assert!(
        error.to_string().contains("214748364834"),
        "expected length named: {error}"
    );
    assert!(largest < 4096, "allocated {largest} bytes");
    assert!(
        elapsed < std::time::Duration::from_secs(1),
        "took {elapsed:?}"
    );
}

#[test]
fn binary_stl_nan_names_its_byte_offset() {
    let mut triangles = TWO_TRIANGLES;
    triangles[1][2][1] = f32::NAN; // triangle 1, corner 2, y
    let (error, message) = stl_err(&binary_stl(b"", &triangles));
    // 84 + 50 (triangle 0) + 12 (normal) + 2 × 12 (corners 0, 1) + 4 (x) = 174
    assert!(
        matches!(&error, MeshError::NonFinite { place, .. } if place.at == Location::Byte(174)),
        "{error:?}"
    );
    assert!(message.starts_with("gen.stl: byte 174:"), "{message}");
}

#[test]
fn malformed_ascii_stl_fixture_names_line_and_token() {
    let (error, message) = load_err("bad_token.stl");
    assert!(matches!(error, MeshError::Syntax { .. }), "{error:?}");
    assert!(
        message.ends_with("bad_token.stl:5: expected 'vertex', found \"vertx\""),
        "{message}"
    );
}

#[test]
fn malformed_ascii_stl_variants() {
    let facet = "facet normal 0 0 1\nouter loop\nvertex 0 0 0\nvertex 1 0 0\nvertex 0 1 0\nendloop\nendfacet\n";
    let cases: [Case<String>; 6] = [
        // Missing endsolid: the error is at the last line.
        (
            format!("solid x\n{facet}"),
            |e| matches!(e, MeshError::Syntax { .. }),
            "gen.stl:9: expected 'facet' or 'endsolid', found end of file",
        ),
        (
            format!("solid x\n{}", facet.replace("1 0 0", "1 zero 0")),
            |e| matches!(e, MeshError::Syntax { .. }),
            "gen.stl:5: bad vertex coordinate \"zero\"",
        ),
        (
            format!("solid x\n{}", facet.replace("0 1 0", "0 inf 0")),
            |e| matches!(e, MeshError::NonFinite { .. }),
            "gen.stl:6: non-finite",
        ),
        (
            format!(
                "solid x\n{}",
                facet.replace("endloop", "vertex 1 1 1\nendloop")
            ),
            |e| matches!(e, MeshError::Syntax { .. }),
            "gen.stl:7: expected 'endloop', found \"vertex\"",
        ),
        (
            format!("solid x\n{facet}endsolid x\ngarbage\n"),
            |e| matches!(e, MeshError::Syntax { .. }),
            "gen.stl:10: expected 'solid' or end of file",
        ),
        (
            "solid x\nendsolid x\n".to_owned(),
            |e| matches!(e, MeshError::EmptyMesh { .. }),
            "gen.stl: empty mesh",
        ),
    ];
    for (text, is_expected, expected) in cases {
        let (error, message) = stl_err(text.as_bytes());
        assert!(is_expected(&error), "{text}: {error:?}");
        assert!(message.starts_with(expected), "{message}");
    }
}

#[test]
fn zero_area_stl_facets_are_kept_and_counted() {
    let triangles = [
        [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]],
        [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [2.0, 0.0, 0.0]], // collinear
        [[0.0, 1.0, 0.0], [0.0, 1.0, 0.0], [1.0, 0.0, 0.0]], // coincident corners
    ];
    let mesh = TriMesh::from_stl_bytes(&binary_stl(b"", &triangles), "flat.stl").expect("loads");
    assert_eq!(mesh.faces().len(), 3);
    assert_eq!(mesh.faces()[2], [2, 2, 1], "welded into a repeated index");
    assert_eq!(mesh.degenerate_triangle_count(), 2);
}

// ---------------------------------------------------------------------------
// TriMesh::new and degenerate triangles

fn square() -> Vec<[f64; 3]> {
    vec![
        [0.0, 0.0, 0.0],
        [1.0, 0.0, 0.0],
        [1.0, 1.0, 0.0],
        [0.0, 1.0, 0.0],
    ]
}

#[test]
fn new_accepts_a_valid_soup_unchanged() {
    let mesh = TriMesh::new(square(), vec![[0, 1, 2], [0, 2, 3]]).expect("valid");
    assert_eq!(mesh.vertices(), square().as_slice());
    assert_eq!(mesh.faces(), &[[0, 1, 2], [0, 2, 3]]);
}

#[test]
fn new_rejects_each_invalid_input() {
    let error = TriMesh::new(vec![], vec![[0, 1, 2]]).unwrap_err();
    assert!(matches!(error, MeshError::EmptyMesh { .. }), "{error:?}");

    let error = TriMesh::new(square(), vec![]).unwrap_err();
    assert!(
        matches!(
            error,
            MeshError::NoFaces {
                vertex_count: 4,
                ..
            }
        ),
        "{error:?}"
    );

    let error = TriMesh::new(square(), vec![[0, 1, 2], [0, 4, 3]]).unwrap_err();
    assert!(
        matches!(&error, MeshError::IndexOutOfRange { place, index, vertex_count: 4 } if place.at == Location::Face(1) && index == "4"),
        "{error:?}"
    );
    assert_eq!(
        error.to_string(),
        "<memory>: face 1: face index 4 out of range (4 vertices)"
    );

    for bad in [f64::NAN, f64::INFINITY, f64::NEG_INFINITY] {
        let mut vertices = square();
        vertices[2][1] = bad;
        let error = TriMesh::new(vertices, vec![[0, 1, 2]]).unwrap_err();
        assert!(
            matches!(&error, MeshError::NonFinite { place, .. } if place.at == Location::Vertex(2)),
            "{error:?}"
        );
    }
}

#[test]
fn degenerate_triangles_are_counted_by_exact_zero_cross_product() {
    let mut vertices = square();
    vertices.push([0.5, 0.5, 0.0]); // 4: on the diagonal 0-2
    vertices.push([1.0, 0.0, 0.0]); // 5: same position as 1
    vertices.push([0.5, 0.5, 1e-9]); // 6: just off the diagonal
    let faces = vec![
        [0, 1, 2], // fine
        [0, 0, 1], // repeated index
        [0, 4, 2], // collinear
        [1, 5, 3], // coincident positions
        [0, 6, 2], // sliver, not degenerate
    ];
    let mesh = TriMesh::new(vertices, faces).expect("valid");
    assert_eq!(mesh.degenerate_triangle_count(), 3);
}

// ---------------------------------------------------------------------------
// TriMesh::load: formats and file errors

#[test]
fn load_picks_the_format_by_extension_in_any_case() {
    let dir = scratch_dir("extension");
    let obj = std::fs::read(fixture("polygons.obj")).expect("fixture");
    let stl = binary_stl(b"", &TWO_TRIANGLES);
    std::fs::write(dir.join("upper.OBJ"), &obj).expect("write");
    std::fs::write(dir.join("mixed.Stl"), &stl).expect("write");
    assert_eq!(
        TriMesh::load(&dir.join("upper.OBJ"))
            .expect("obj")
            .faces()
            .len(),
        6
    );
    assert_eq!(
        TriMesh::load(&dir.join("mixed.Stl"))
            .expect("stl")
            .faces()
            .len(),
        2
    );
    std::fs::remove_dir_all(&dir).ok();
}

#[test]
fn a_misnamed_file_is_refused_with_what_its_content_is() {
    // The extension chooses the parser; when it fails on content that is
    // recognisably something else, the error says what to rename it to.
    let dir = scratch_dir("misnamed");
    let ascii_stl = std::fs::read(fixture("two_facets.stl")).expect("fixture");
    let obj = std::fs::read(fixture("polygons.obj")).expect("fixture");
    let mut png = b"\x89PNG\r\n\x1a\n\0\0\0\rIHDR".to_vec();
    png.extend([0u8; 40]);
    let cases: Vec<(&str, Vec<u8>, &str)> = vec![
        (
            "binary.obj",
            binary_stl(b"exported", &TWO_TRIANGLES),
            "binary.obj: not an OBJ file: the content is a binary STL; name it .stl",
        ),
        (
            "ascii.obj",
            ascii_stl,
            "ascii.obj: not an OBJ file: the content is an ASCII STL; name it .stl",
        ),
        (
            "text.stl",
            obj.clone(),
            "text.stl: not an STL file: the content is OBJ text; name it .obj",
        ),
        (
            "image.obj",
            png,
            "image.obj: not an OBJ file: the content is binary data, not text",
        ),
    ];
    for (name, bytes, message) in cases {
        let path = dir.join(name);
        std::fs::write(&path, bytes).expect("write");
        let error = TriMesh::load(&path).unwrap_err();
        assert!(
            matches!(error, MeshError::Misnamed { .. }),
            "{name}: {error:?}"
        );
        let shown = error.to_string();
        assert!(shown.ends_with(message), "{name}: {shown}");
    }
    // Content that could be the named format keeps the parse's own error.
    std::fs::write(dir.join("empty.obj"), b"# nothing\n").expect("write");
    assert!(matches!(
        TriMesh::load(&dir.join("empty.obj")),
        Err(MeshError::EmptyMesh { .. })
    ));
    std::fs::remove_dir_all(&dir).ok();
}

#[test]
fn load_sniffs_unknown_extensions() {
    let dir = scratch_dir("sniff");
    let cases: [(&str, Vec<u8>, Option<usize>); 5] = [
        (
            "binary.dat",
            binary_stl(b"solid but binary", &TWO_TRIANGLES),
            Some(2),
        ),
        (
            "ascii.mesh",
            std::fs::read(fixture("two_facets.stl")).expect("fixture"),
            Some(3),
        ),
        (
            "wavefront.txt",
            std::fs::read(fixture("polygons.obj")).expect("fixture"),
            Some(6),
        ),
        (
            "noextension",
            std::fs::read(fixture("groups.obj")).expect("fixture"),
            Some(3),
        ),
        (
            "model.ply",
            b"ply\nformat ascii 1.0\nelement vertex 3\n".to_vec(),
            None,
        ),
    ];
    for (name, bytes, faces) in cases {
        let path = dir.join(name);
        std::fs::write(&path, bytes).expect("write");
        match (TriMesh::load(&path), faces) {
            (Ok(mesh), Some(faces)) => assert_eq!(mesh.faces().len(), faces, "{name}"),
            (Err(MeshError::UnknownFormat { .. }), None) => {}
            (other, _) => panic!("{name}: unexpected {other:?}"),
        }
    }
    let error = TriMesh::load(&dir.join("model.ply")).unwrap_err();
    assert!(
        error.to_string().contains("model.ply: unknown mesh format"),
        "{error}"
    );
    std::fs::remove_dir_all(&dir).ok();
}

#[test]
fn load_missing_file_names_it_with_the_os_error() {
    let path = fixture("does_not_exist.obj");
    let error = TriMesh::load(&path).unwrap_err();
    let MeshError::Io { source, .. } = &error else {
        panic!("{error:?}");
    };
    assert_eq!(source.kind(), std::io::ErrorKind::NotFound);
    let message = error.to_string();
    assert!(
        message.contains("does_not_exist.obj: cannot read: "),
        "{message}"
    );
    assert!(message.contains(&source.to_string()), "{message}");
}

#[test]
fn mesh_error_is_a_thread_safe_static_error() {
    fn assert_error<E: std::error::Error + Send + Sync + 'static>() {}
    assert_error::<MeshError>();
    let boxed: Box<dyn std::error::Error + Send + Sync> =
        Box::new(TriMesh::new(vec![], vec![]).unwrap_err());
    assert!(boxed.to_string().contains("empty mesh"));
}

// ---------------------------------------------------------------------------
// Properties

/// Fixture texts that load, as material for mutation.
fn valid_texts() -> Vec<Vec<u8>> {
    [
        "polygons.obj",
        "groups.obj",
        "negative.obj",
        "corner_forms.obj",
        "two_facets.stl",
    ]
    .iter()
    .map(|name| std::fs::read(fixture(name)).expect("fixture"))
    .collect()
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(256))]

    /// Arbitrary bytes give a mesh or an error, never a panic.
    #[test]
    fn parsers_never_panic_on_arbitrary_bytes(bytes in prop::collection::vec(any::<u8>(), 0..600)) {
        let _ = TriMesh::from_obj_bytes(&bytes, "fuzz.obj");
        let _ = TriMesh::from_stl_bytes(&bytes, "fuzz.stl");
    }

    /// Valid files with a few bytes overwritten by OBJ/STL-ish characters
    /// (digits, signs, slashes, letters of keywords) never panic, and whatever
    /// loads satisfies the TriMesh invariants.
    #[test]
    fn parsers_never_panic_on_mutated_files(
        which in 0usize..5,
        edits in prop::collection::vec(
            (any::<prop::sample::Index>(), prop::sample::select(b"0123456789-+/ .\nefvnail".to_vec())),
            1..8,
        ),
    ) {
        let mut bytes = valid_texts().swap_remove(which);
        for (at, byte) in edits {
            let i = at.index(bytes.len());
            bytes[i] = byte;
        }
        let loaded = [
            TriMesh::from_obj_bytes(&bytes, "m.obj"),
            TriMesh::from_stl_bytes(&bytes, "m.stl"),
        ];
        for mesh in loaded.iter().flatten() {
            let n = mesh.vertices().len();
            prop_assert!(mesh.faces().iter().flatten().all(|&i| (i as usize) < n));
            prop_assert!(mesh.vertices().iter().flatten().all(|c| c.is_finite()));
        }
    }

    /// Binary STL: face k has exactly the corners of record k, and no two
    /// vertices have the same position.
    #[test]
    fn binary_stl_keeps_every_triangle(
        triangles in prop::collection::vec(
            prop::array::uniform3(prop::array::uniform3(
                prop::sample::select(vec![-1.0f32, -0.0, 0.0, 0.5, 1.0, 1e-30]),
            )),
            1..40,
        ),
    ) {
        let mesh = TriMesh::from_stl_bytes(&binary_stl(b"", &triangles), "p.stl").expect("valid");
        let expected: Vec<[[f64; 3]; 3]> =
            triangles.iter().map(|t| t.map(|c| c.map(|x| f64::from(x) + 0.0))).collect();
        prop_assert_eq!(corners(&mesh), expected);
        let mut bits: Vec<[u64; 3]> = mesh.vertices().iter().map(|v| v.map(f64::to_bits)).collect();
        bits.sort_unstable();
        bits.dedup();
        prop_assert_eq!(bits.len(), mesh.vertices().len());
    }

    /// OBJ with random polygons: triangle ids follow the fan order of each face.
    #[test]
    fn obj_polygons_fan_in_order(
        faces in prop::collection::vec(prop::collection::vec(1u32..=6, 3..7), 1..10),
    ) {
        let mut text = String::from("v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\nv 1 1 0\nv 1 1 1\n");
        let mut expected = Vec::new();
        for face in &faces {
            text.push('f');
            for i in face {
                text.push_str(&format!(" {i}"));
            }
            text.push('\n');
            for k in 1..face.len() - 1 {
                expected.push([face[0] - 1, face[k] - 1, face[k + 1] - 1]);
            }
        }
        let mesh = TriMesh::from_obj_bytes(text.as_bytes(), "p.obj").expect("valid");
        prop_assert_eq!(mesh.faces(), expected.as_slice());
        prop_assert_eq!(mesh.vertices().len(), 6);
    }
}
