//! Meshes generated in code, shared by the integration tests.
#![allow(dead_code)]
// Fixtures are made from known-good inputs: one that fails is a failed test, not an input.
#![allow(
    clippy::unwrap_used,
    clippy::expect_used,
    clippy::panic,
    clippy::indexing_slicing
)]

// Integration tests only: the binary's path is known to them at compile time.
#[cfg(test)]
pub mod cli;
pub mod mutate;
pub mod oracle;
pub mod rng;
pub mod seal;

use obbtree::mesh::TriMesh;

/// The build options of the query profilers (`examples/profile_*`): the library's defaults
/// (f32), in f64 where the environment says `OBBTREE_PRECISION=f64`.
pub fn profiling_options() -> obbtree::build::BuildOptions {
    match std::env::var("OBBTREE_PRECISION").as_deref() {
        Ok("f64") => obbtree::build::BuildOptions {
            precision: obbtree::real::Precision::F64,
            ..Default::default()
        },
        _ => Default::default(),
    }
}

/// A latitude/longitude sphere of `2 * slices * (stacks - 1)` triangles, like the spheres of
/// the dissertation's §5.3.1 scene.
pub fn uv_sphere(radius: f64, stacks: u32, slices: u32) -> TriMesh {
    obbtree::generate::lat_long_sphere(radius, stacks, slices).expect("valid sphere")
}

/// The axis-aligned cube `[-h, h]^3`, 12 triangles.
pub fn cube(h: f64) -> TriMesh {
    cuboid([h, h, h], [0.0; 3])
}

/// The axis-aligned box with half-widths `half` centred at `center`, 12 triangles, outward
/// normals. Corner `i` has the upper coordinate on axis `k` when bit `k` of `i` is set.
pub fn cuboid(half: [f64; 3], center: [f64; 3]) -> TriMesh {
    obbtree::generate::cuboid(half, center).expect("valid cuboid")
}

/// A copy of `mesh` with every vertex coordinate moved by up to `r` (seeded): a noisy
/// scan of it.
pub fn noisy(mesh: &TriMesh, r: f64, seed: u64) -> TriMesh {
    let mut rng = obbtree::generate::Rng::new(seed);
    let v = mesh
        .vertices()
        .iter()
        .map(|p| p.map(|x| x + r * rng.signed()))
        .collect();
    TriMesh::new(v, mesh.faces().to_vec()).expect("a mesh")
}

/// A flat `n x n` grid of unit squares in the plane z = 0, `2 n^2` triangles.
pub fn grid(n: u32) -> TriMesh {
    // The library's plate of unit cells, moved from centred to a corner at the origin.
    let plate = obbtree::generate::plate([f64::from(n); 2], [n, n]).expect("valid grid");
    let half = f64::from(n) / 2.0;
    let vertices = plate
        .vertices()
        .iter()
        .map(|&[x, y, z]| [x + half, y + half, z]);
    TriMesh::new(vertices.collect(), plate.faces().to_vec()).expect("valid grid")
}

/// `mesh` as OBJ text: `v` lines (shortest decimals that read back exactly) and 1-based
/// `f` lines, in order.
pub fn obj_text(mesh: &TriMesh) -> String {
    mesh.to_obj()
}

/// The bundled cow (5,804 triangles), loaded from `assets/`.
pub fn cow() -> TriMesh {
    TriMesh::load(std::path::Path::new(concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/assets/cow.obj"
    )))
    .expect("assets/cow.obj loads")
}

/// A mesh of `../shared/meshes` (outside the repository, for benchmarks), or `None` with a
/// message on stderr when it is missing.
pub fn shared_mesh(name: &str) -> Option<TriMesh> {
    let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../shared/meshes")
        .join(name);
    if !path.exists() {
        eprintln!(
            "skipping benchmarks on {name}: {} not found",
            path.display()
        );
        return None;
    }
    Some(TriMesh::load(&path).expect("shared mesh loads"))
}

/// Every option combination the format supports, at leaf sizes 1 and 4.
pub fn all_options() -> Vec<obbtree::build::BuildOptions> {
    use obbtree::build::BuildOptions;
    use obbtree::bv::BvKind;
    use obbtree::real::Precision;
    let mut out = Vec::new();
    for bv in BvKind::ALL {
        for precision in Precision::ALL {
            for leaf_size in [1, 4] {
                out.push(BuildOptions {
                    bv,
                    precision,
                    leaf_size,
                    ..BuildOptions::default()
                });
            }
        }
    }
    // Quantised boxes, at the compact layout's own leaf size and at 1.
    for leaf_size in [1, obbtree::bv::Layout::Compact.default_leaf_size()] {
        out.push(BuildOptions {
            layout: obbtree::bv::Layout::Compact,
            leaf_size,
            ..BuildOptions::default()
        });
    }
    // Spheres centred on their smallest ball: another centre, the same guarantees.
    for precision in Precision::ALL {
        out.push(BuildOptions {
            bv: BvKind::Sphere,
            precision,
            sphere_fit: obbtree::build::SphereFit::Minimal,
            ..BuildOptions::default()
        });
    }
    out
}

/// Checks `file` with the library's validator (`verify`), then that every node's volume
/// contains every corner of every face below it within `tolerance` model units. `verify`
/// allows a slack relative to the model's size; an absolute `tolerance` holds volumes of
/// models far from unit size to a tighter bound.
pub fn assert_tight_enough(file: &obbtree::format::ObbtFile, tolerance: f64) {
    if let Err(error) = file.verify() {
        panic!("the file does not verify: {error}");
    }
    struct Tight(f64);
    impl obbtree::format::TreeVisitor for Tight {
        type Output = ();
        fn visit<B: obbtree::bv::BoundingVolume>(self, tree: obbtree::tree::TreeView<'_, B>) {
            contains_below(&tree, 0, &mut Vec::new(), self.0);
        }
    }
    file.visit(Tight(tolerance))
        .expect("a view of the file's own type");
}

/// Descends a verified tree from node `index`, below the nodes of `path`, checking every
/// leaf face against the volumes of all its ancestors.
fn contains_below<B: obbtree::bv::BoundingVolume>(
    tree: &obbtree::tree::TreeView<'_, B>,
    index: u32,
    path: &mut Vec<u32>,
    tolerance: f64,
) {
    use obbtree::tree::NodeKind;
    path.push(index);
    match tree.node_kind(index).expect("a verified tree") {
        NodeKind::Children(children) => {
            for child in children {
                contains_below(tree, child, path, tolerance);
            }
        }
        NodeKind::Faces(faces) => {
            for f in faces {
                let corners = tree.triangle(f).expect("a verified tree");
                for &node in path.iter() {
                    let bv = &tree.nodes()[node as usize].bv;
                    for (k, p) in corners.iter().enumerate() {
                        assert!(
                            bv.contains(*p, tolerance),
                            "node {node} ({bv:?}) misses corner {k} {p:?} of face {f}"
                        );
                    }
                }
            }
        }
    }
    path.pop();
}

/// The sliding-sphere scene of the dissertation's §5.3.1: B (radius 0.8) at `x` along the
/// x axis with a seeded random rotation, A (radius 1) at the origin.
pub fn sliding_pose(x: f64, seed: u64) -> obbtree::query::Pose {
    obbtree::query::Pose::new(
        rng::seeded_rotation(seed),
        nalgebra::Vector3::new(x, 0.0, 0.0),
    )
    .expect("rotation")
}

/// A model's copy turned by the seeded rotation `seed` and moved by `scale` along the x
/// axis turned by the rotation `seed + 100`: the poses of the pinned-work tests.
pub fn turned_pose(seed: u64, scale: f64) -> obbtree::query::Pose {
    let direction = rng::seeded_rotation(seed + 100) * nalgebra::Vector3::x();
    obbtree::query::Pose::new(rng::seeded_rotation(seed), direction * scale).expect("rotation")
}

/// The default tree of `mesh` in f64 (the scenes compare against f64 brute force).
pub fn tree_f64(mesh: &TriMesh) -> obbtree::format::ObbtFile {
    let options = obbtree::build::BuildOptions {
        precision: obbtree::real::Precision::F64,
        ..Default::default()
    };
    obbtree::build::build(mesh, &options, None).expect("builds")
}

/// The input-mesh id and model-frame corners of every face of a file, in face order; faces
/// whose corners or id a damaged file does not hold are left out.
pub fn file_triangles(file: &obbtree::format::ObbtFile) -> Vec<(u32, [[f64; 3]; 3])> {
    struct Faces;
    impl obbtree::format::TreeVisitor for Faces {
        type Output = Vec<(u32, [[f64; 3]; 3])>;
        fn visit<B: obbtree::bv::BoundingVolume>(
            self,
            tree: obbtree::tree::TreeView<'_, B>,
        ) -> Self::Output {
            (0..tree.faces().len() as u32)
                .filter_map(|f| Some((tree.source_id(f)?, tree.triangle(f)?)))
                .collect()
        }
    }
    file.visit(Faces).expect("a view of the file's own type")
}

/// Generic code on the typed views of two files of one volume type and precision: how the
/// tests reach [`obbtree::query::details`], the queries over typed views.
pub trait ViewsVisitor {
    /// What the visit returns.
    type Output;
    /// Called once, with both files viewed as their stored volume type `B`.
    fn visit<B: obbtree::bv::BoundingVolume>(
        self,
        a: &obbtree::tree::TreeView<'_, B>,
        b: &obbtree::tree::TreeView<'_, B>,
    ) -> Self::Output;
}

/// Runs `visitor` on the typed views of `a` and `b`, which must store the same volume type
/// and precision and be viewable.
pub fn with_views<V: ViewsVisitor>(
    a: &obbtree::format::ObbtFile,
    b: &obbtree::format::ObbtFile,
    visitor: V,
) -> V::Output {
    struct Typed<'f, V> {
        a: &'f obbtree::format::ObbtFile,
        b: &'f obbtree::format::ObbtFile,
        visitor: V,
    }
    impl<V: ViewsVisitor> obbtree::bv::VolumeVisitor for Typed<'_, V> {
        type Output = V::Output;
        fn visit<B: obbtree::bv::BoundingVolume>(self) -> V::Output {
            let a = self.a.view::<B>().expect("a view of A's own type");
            let b = self.b.view::<B>().expect("B stores A's type");
            self.visitor.visit(&a, &b)
        }
    }
    obbtree::bv::dispatch(a.node_type(), Typed { a, b, visitor })
}
