//! Build -> write -> open: identical arrays and bytes, determinism, and volumes that contain
//! what is below them, for every volume type, both precisions and two leaf sizes.
// Test code outside `#[test]` functions (helpers, property bodies): a failure is a failed test.
#![allow(clippy::unwrap_used, clippy::indexing_slicing)]

use crate::common;

use obbtree::build::{build, BuildOptions};
use obbtree::bv::{Aabb, BoundingVolume, Obb, Sphere};
use obbtree::fit::FitMethod;
use obbtree::format::{ObbtFile, TreeVisitor};
use obbtree::mesh::TriMesh;
use obbtree::real::{point_to_f64, Real};
use obbtree::tree::{Encoding, TreeView};

/// Checks a tree against the mesh it was built from.
struct MatchesMesh<'m> {
    mesh: &'m TriMesh,
    options: BuildOptions,
}

impl TreeVisitor for MatchesMesh<'_> {
    type Output = ();
    fn visit<B: BoundingVolume>(self, tree: TreeView<'_, B>) {
        let mesh = self.mesh;
        assert_eq!(tree.vertices().len(), mesh.vertices().len());
        for (stored, input) in tree.vertices().iter().zip(mesh.vertices()) {
            let expected = input.map(<B::Real as Real>::from_f64_nearest);
            assert_eq!(point_to_f64(stored), point_to_f64(&expected));
        }
        for (face, &id) in tree.faces().iter().zip(tree.source_ids()) {
            assert_eq!(
                *face,
                mesh.faces()[id as usize],
                "face order must follow the source ids"
            );
        }
        // The encoding follows the tree's shape: binary exactly when every leaf has one face
        // (always with leaf size 1; also for tiny meshes at larger leaf sizes).
        let single_face_leaves =
            (0..tree.nodes().len() as u32).all(|i| tree.leaf_faces(i).is_none_or(|f| f.len() == 1));
        let expected_encoding = if single_face_leaves {
            Encoding::Binary
        } else {
            Encoding::Variable
        };
        assert_eq!(tree.encoding(), expected_encoding);
        assert!(self.options.leaf_size > 1 || expected_encoding == Encoding::Binary);
    }
}

fn check_mesh(mesh: &TriMesh) {
    static CALLS: std::sync::atomic::AtomicUsize = std::sync::atomic::AtomicUsize::new(0);
    let call = CALLS.fetch_add(1, std::sync::atomic::Ordering::Relaxed);
    let dir = std::env::temp_dir().join(format!("obbtree-roundtrip-{}-{call}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    for options in common::all_options() {
        let built = build(mesh, &options, None).unwrap();
        built.verify().unwrap();
        let path = dir.join("tree.obbt");
        built.write_atomic(&path).unwrap();
        let opened = ObbtFile::open(&path).unwrap();
        assert!(
            opened.bytes() == built.bytes(),
            "{options:?}: the file differs from the image"
        );
        assert_eq!(opened.info(), built.info());
        // The volumes are rounded outward, so only the f64 arithmetic of the check itself
        // needs slack.
        common::assert_tight_enough(&opened, 1e-12);
        opened.visit(MatchesMesh { mesh, options }).unwrap();
    }
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn sphere_round_trips_for_every_option() {
    check_mesh(&common::uv_sphere(1.0, 24, 48));
}

#[test]
fn cow_round_trips_for_every_option() {
    check_mesh(&common::cow());
}

#[test]
fn flat_and_tiny_meshes_round_trip() {
    check_mesh(&common::grid(7));
    check_mesh(&common::cube(0.5));
    check_mesh(
        &TriMesh::new(
            vec![[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]],
            vec![[0, 1, 2]],
        )
        .unwrap(),
    );
}

#[test]
fn degenerate_and_duplicated_triangles_round_trip() {
    // Collinear, coincident and duplicated triangles: kept, counted, and still enclosed.
    let vertices = vec![
        [0.0, 0.0, 0.0],
        [1.0, 0.0, 0.0],
        [2.0, 0.0, 0.0],
        [0.0, 1.0, 0.0],
        [5.0, 5.0, 5.0],
    ];
    let faces = vec![
        [0, 1, 2],
        [4, 4, 4],
        [0, 1, 3],
        [0, 1, 3],
        [0, 1, 3],
        [1, 2, 3],
    ];
    let mesh = TriMesh::new(vertices, faces).unwrap();
    check_mesh(&mesh);
    let info = build(&mesh, &BuildOptions::default(), None).unwrap().info();
    assert_eq!(info.stats.degenerate_triangles, 2);
}

#[test]
fn builds_are_byte_identical_whatever_the_thread_count() {
    let mesh = common::uv_sphere(1.0, 60, 120); // 14k triangles: the parallel levels run
    for options in [
        BuildOptions::default(),
        BuildOptions {
            leaf_size: 4,
            ..BuildOptions::default()
        },
    ] {
        let one = rayon::ThreadPoolBuilder::new()
            .num_threads(1)
            .build()
            .unwrap();
        let four = rayon::ThreadPoolBuilder::new()
            .num_threads(4)
            .build()
            .unwrap();
        let a = one.install(|| build(&mesh, &options, None).unwrap());
        let b = four.install(|| build(&mesh, &options, None).unwrap());
        let c = build(&mesh, &options, None).unwrap();
        assert!(a.bytes() == b.bytes(), "1 thread and 4 threads differ");
        assert!(
            a.bytes() == c.bytes(),
            "1 thread and the global pool differ"
        );
    }
}

#[test]
fn view_of_the_wrong_type_is_refused() {
    let file = build(&common::cube(1.0), &BuildOptions::default(), None).unwrap();
    assert!(file.view::<Obb<f32>>().is_ok());
    assert!(file.view::<Obb<f64>>().is_err());
    assert!(file.view::<Aabb<f32>>().is_err());
    assert!(file.view::<Sphere<f32>>().is_err());
}

#[test]
fn leaf_size_out_of_range_is_refused() {
    for leaf_size in [0, 129] {
        let options = BuildOptions {
            leaf_size,
            ..BuildOptions::default()
        };
        let err = build(&common::cube(1.0), &options, None).unwrap_err();
        assert!(err.to_string().contains("leaf size"), "{err}");
    }
}

#[test]
fn statistics_match_the_tree() {
    let mesh = common::uv_sphere(2.0, 16, 32);
    let file = build(&mesh, &BuildOptions::default(), None).unwrap();
    let info = file.info();
    let n = mesh.faces().len() as u32;
    assert_eq!(
        (
            info.triangles,
            info.nodes,
            info.stats.shape.leaves,
            info.stats.shape.max_leaf_faces
        ),
        (n, 2 * n - 1, n, 1)
    );
    assert!(
        info.stats.shape.depth > (f64::from(n).log2().ceil() as u32),
        "depth {}",
        info.stats.shape.depth
    );
    for k in 0..3 {
        assert!(
            (info.stats.bounds_min[k] + 2.0).abs() < 1e-6
                && (info.stats.bounds_max[k] - 2.0).abs() < 1e-6
        );
    }
    let file4 = build(
        &mesh,
        &BuildOptions {
            leaf_size: 4,
            ..BuildOptions::default()
        },
        None,
    )
    .unwrap();
    let info4 = file4.info();
    assert!(
        info4.stats.shape.max_leaf_faces <= 4
            && info4.stats.shape.leaves < n
            && info4.nodes == 2 * info4.stats.shape.leaves - 1
    );
}

#[test]
fn smallest_file_matches_the_spec_test_vector() {
    // formats/obbt.md § 12: one triangle, OBB f32.
    let mesh = TriMesh::new(
        vec![[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]],
        vec![[0, 1, 2]],
    )
    .unwrap();
    let file = build(&mesh, &BuildOptions::default(), None).unwrap();
    let offsets: Vec<(String, u64, u64)> = file
        .sections()
        .iter()
        .map(|s| (s.name(), s.offset, s.length))
        .collect();
    assert_eq!(
        offsets,
        [
            ("vertices".into(), 320, 36),
            ("faces".into(), 384, 12),
            ("source_ids".into(), 448, 4),
            ("nodes".into(), 512, 64)
        ]
    );
    assert_eq!(file.bytes().len(), 576);
    assert_eq!(file.info().encoding, Encoding::Binary);
    let tree = file.view::<Obb<f32>>().unwrap();
    assert_eq!(tree.nodes()[0].packed, 0);
    assert_eq!(&file.bytes()[..8], b"\x89OBT\r\n\x1a\n");
}

#[test]
fn files_and_views_can_be_shared_between_threads() {
    fn shared<T: Send + Sync>() {}
    shared::<ObbtFile>();
    shared::<TreeView<'static, Obb<f32>>>();
    shared::<TreeView<'static, Sphere<f64>>>();
    shared::<obbtree::query::QueryContext>();
}

/// Regression (found by fuzzing): a coordinate beyond the f32 range rounded to infinity and
/// gave an f32 file that its own verify refused. It is now a build error that names the
/// vertex and the way out; the f64 file is fine.
#[test]
fn coordinates_beyond_f32_are_a_build_error_for_f32_files() {
    let mesh = obbtree::mesh::TriMesh::new(
        vec![[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1e39, 0.0]],
        vec![[0, 1, 2]],
    )
    .expect("a valid mesh");
    let err = build(&mesh, &BuildOptions::default(), None)
        .expect_err("f32 cannot hold 1e39")
        .to_string();
    assert!(
        err.contains("vertex 2") && err.contains("--precision f64"),
        "{err}"
    );
    let options = BuildOptions {
        precision: obbtree::real::Precision::F64,
        ..BuildOptions::default()
    };
    build(&mesh, &options, None)
        .expect("f64 holds it")
        .verify()
        .expect("verifies");
}

/// The hull fit's size threshold: below it a node is fitted exactly as the triangle fit
/// fits it, so a threshold above the mesh gives the triangle fit's tree, and the default
/// gives a tree unlike both (its large nodes still fitted to their hulls).
#[test]
fn hull_fit_below_its_threshold_is_the_triangle_fit() {
    let cow = common::cow();
    let nodes = |options: BuildOptions| -> Vec<Obb<f32>> {
        let file = build(&cow, &options, None).expect("builds");
        let tree = file.view::<Obb<f32>>().expect("OBB f32");
        tree.nodes().iter().map(|n| n.bv).collect()
    };
    let with = |fit, hull_min_faces| BuildOptions {
        fit,
        hull_min_faces,
        ..BuildOptions::default()
    };
    let triangles = nodes(with(FitMethod::Triangles, 1));
    assert_eq!(nodes(with(FitMethod::Hull, u32::MAX)), triangles);
    let default = nodes(BuildOptions::default());
    let everywhere = nodes(with(FitMethod::Hull, 1));
    assert_ne!(default, triangles);
    assert_ne!(default, everywhere);
    // The hull fits the root in both.
    assert_eq!(default.first(), everywhere.first());
}

/// The hull's vertex sample: a small one changes the tree (the frames of the nodes it
/// samples) but never what the boxes contain, and a sample of every vertex is the hull of
/// every vertex.
#[test]
fn sampled_hulls_change_frames_only() {
    let cow = common::cow();
    // (Fitted frames only: the model's axes, which a sample does not change, would win at
    // the root.)
    let with = |hull_max_points| BuildOptions {
        hull_min_faces: 1,
        hull_max_points,
        model_axes: false,
        ..BuildOptions::default()
    };
    let nodes = |options: BuildOptions| -> Vec<Obb<f32>> {
        let file = build(&cow, &options, None).expect("builds");
        file.verify().expect("every box contains its triangles");
        let tree = file.view::<Obb<f32>>().expect("OBB f32");
        tree.nodes().iter().map(|n| n.bv).collect()
    };
    let every_vertex = nodes(with(u32::MAX));
    // The cow has 2,904 vertices: a sample of as many is every vertex.
    assert_eq!(nodes(with(2904)), every_vertex);
    let sampled = nodes(with(64));
    assert_ne!(sampled.first(), every_vertex.first());
    assert_eq!(sampled.len(), every_vertex.len());
    // The smallest sample allowed still builds boxes that contain their triangles.
    nodes(with(obbtree::build::MIN_HULL_POINTS));
    assert!(build(&cow, &with(obbtree::build::MIN_HULL_POINTS - 1), None).is_err());
}

/// The model's axes as a candidate frame: a node keeps the box on them only where it is
/// smaller, so the root's box is never larger than the fitted one, some nodes of the cow
/// lie on the model's axes, and every box still contains its triangles.
#[test]
fn model_axes_replace_a_fitted_box_only_where_theirs_is_smaller() {
    let cow = common::cow();
    let fitted_only = BuildOptions {
        model_axes: false,
        ..BuildOptions::default()
    };
    let (either, fitted) = (
        build(&cow, &BuildOptions::default(), None).expect("builds"),
        build(&cow, &fitted_only, None).expect("builds"),
    );
    for file in [&either, &fitted] {
        file.verify().expect("every box contains its triangles");
    }
    assert_ne!(either.bytes(), fitted.bytes());
    let nodes = |file: &obbtree::format::ObbtFile| -> Vec<Obb<f32>> {
        let tree = file.view::<Obb<f32>>().expect("OBB f32");
        tree.nodes().iter().map(|n| n.bv).collect()
    };
    let (with, without) = (nodes(&either), nodes(&fitted));
    assert!(with[0].volume() <= without[0].volume());
    let on_model_axes = |b: &Obb<f32>| {
        b.axes
            .iter()
            .all(|row| row.iter().filter(|v| v.abs() == 1.0).count() == 1)
    };
    let aligned = with.iter().filter(|b| on_model_axes(b)).count();
    let aligned_without = without.iter().filter(|b| on_model_axes(b)).count();
    assert!(
        aligned > aligned_without,
        "{aligned} nodes on the model's axes with the candidate, {aligned_without} without"
    );
}

/// The builder measures a node along its fitted frame and along the model's axes in one
/// scan; each box must be exactly the one the two separate enclosures give, the second
/// along `model_axes_frame` of the vertices' bounds. The cow's vertices, split into node-
/// like runs, along the identity, a turned frame and the cow's own principal axes, for every
/// volume type and precision.
#[test]
fn one_scan_encloses_along_the_fit_and_the_model_axes_as_two_enclosures_do() {
    use obbtree::bv::model_axes_frame;
    use obbtree::fit::principal_axes;
    fn check<B: BoundingVolume + PartialEq>(
        positions: &[[f64; 3]],
        frames: &[nalgebra::Matrix3<f64>],
    ) {
        let all: Vec<u32> = (0..positions.len() as u32).collect();
        for run in all.chunks(97).chain([all.as_slice(), &all[..3], &all[..1]]) {
            let (mut lo, mut hi) = ([f64::INFINITY; 3], [f64::NEG_INFINITY; 3]);
            for &v in run {
                for k in 0..3 {
                    lo[k] = lo[k].min(positions[v as usize][k]);
                    hi[k] = hi[k].max(positions[v as usize][k]);
                }
            }
            let model = model_axes_frame(lo, hi);
            for frame in frames {
                let [(f_axes, fitted), (m_axes, aligned)] =
                    B::enclose_vertices_fitted_and_aligned(frame, positions, run);
                assert_eq!(f_axes, *frame);
                assert_eq!(m_axes, model);
                assert_eq!(fitted, B::enclose_vertices(frame, positions, run));
                assert_eq!(aligned, B::enclose_vertices(&model, positions, run));
            }
        }
    }
    let cow = common::cow();
    let positions = cow.vertices();
    let frames = [
        nalgebra::Matrix3::identity(),
        common::rng::seeded_rotation(5),
        principal_axes(FitMethod::Hull, positions, cow.faces()),
    ];
    check::<Obb<f32>>(positions, &frames);
    check::<Obb<f64>>(positions, &frames);
    check::<Aabb<f32>>(positions, &frames);
    check::<Aabb<f64>>(positions, &frames);
    check::<Sphere<f32>>(positions, &frames);
    check::<Sphere<f64>>(positions, &frames);
}
