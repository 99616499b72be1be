//! The differential fuzz target: two small trees made from arbitrary bytes, posed, and
//! every query kind checked against brute force over their triangles. Crash fuzzing finds
//! panics; this finds wrong answers: a box test that prunes a pair it should open, a bound
//! that stops a search early, a tie broken two ways.
//!
//! Shared by `fuzz_targets/differential.rs` and by the stable test `tests/it/fuzz_corpus.rs`,
//! which replays the checked-in corpus and every fixed finding through it. It depends only
//! on `obbtree` and the brute-force oracle of `tests/common/oracle.rs`.
//!
//! Input layout (bytes past the end read as 0, so every input means something): the build
//! options, then each model (vertex count, coordinates on a grid of eighths so that
//! coincident, coplanar and degenerate triangles are common, triangle count, corner
//! indices), then the two poses (rotations in steps of π/32, translations in eighths), then
//! query points and rays. The queries run on the file's own stored triangles, so f32 trees
//! are compared with their rounded corners.

// The fuzz target uses one entry point, the corpus test another view of it.
#![allow(dead_code)]
// The panics and `expect`s are the assertions (a query refusing two trees it built is a bug
// in the library), and the indexing is into constant arrays, modulo their length.
#![allow(clippy::panic, clippy::expect_used, clippy::indexing_slicing)]

#[path = "../tests/common/oracle.rs"]
mod oracle;

use nalgebra::Vector3;
use obbtree::build::{build, BuildError};
use obbtree::bv::BoundingVolume;
use obbtree::format::{ObbtFile, TreeVisitor};
use obbtree::mesh::TriMesh;
use obbtree::query::triangle::{closest_point_on_triangle, RaySpace, Triangle};
use obbtree::query::{
    cast_rays, closest_points, hausdorff, winding_numbers, ClosestOptions, CollideOptions,
    DistanceOptions, HausdorffOptions, PairQuery, Pose, Ray, RayMode, RayOptions, SpanOptions,
    ToleranceOptions, WindingAccuracy, WindingOptions,
};
use obbtree::tree::TreeView;

#[path = "bytes.rs"]
mod bytes;
use bytes::Bytes;

/// A file's stored triangles indexed by input id (model frame, f64).
fn triangles(file: &ObbtFile) -> Vec<Triangle> {
    struct Faces;
    impl TreeVisitor for Faces {
        type Output = Vec<(u32, [[f64; 3]; 3])>;
        fn visit<B: BoundingVolume>(self, tree: TreeView<'_, B>) -> Self::Output {
            (0..tree.faces().len() as u32)
                .filter_map(|f| Some((tree.source_id(f)?, tree.triangle(f)?)))
                .collect()
        }
    }
    let mut faces = file
        .visit(Faces)
        .expect("a built file views as its own type");
    faces.sort_by_key(|(id, _)| *id);
    assert!(
        faces
            .iter()
            .enumerate()
            .all(|(i, (id, _))| *id as usize == i),
        "a built file's source ids are not its input's triangles"
    );
    faces
        .into_iter()
        .map(|(_, t)| t.map(Vector3::from))
        .collect()
}

/// Distance from `p` to the nearest of `list`.
fn point_distance(p: &Vector3<f64>, list: &[Triangle]) -> f64 {
    list.iter()
        .map(|t| (p - closest_point_on_triangle(p, t).0).norm())
        .fold(f64::INFINITY, f64::min)
}

/// The generalised winding number of `list` at `p`: each triangle's solid angle (Van
/// Oosterom and Strackee) over 4π.
fn winding(p: &Vector3<f64>, list: &[Triangle]) -> f64 {
    let total: f64 = list
        .iter()
        .map(|t| {
            let [a, b, c] = t.map(|q| q - p);
            let (la, lb, lc) = (a.norm(), b.norm(), c.norm());
            let det = a.dot(&b.cross(&c));
            let div = la * lb * lc + a.dot(&b) * lc + a.dot(&c) * lb + b.dot(&c) * la;
            2.0 * det.atan2(div)
        })
        .sum();
    total / (4.0 * std::f64::consts::PI)
}

/// Builds two trees from `data` and holds every query to brute force.
pub fn differential(data: &[u8]) {
    let mut bytes = Bytes::new(data);
    let options = bytes.options();
    let (Some(mesh_a), Some(mesh_b)) = (bytes.mesh(), bytes.mesh()) else {
        return;
    };
    let built = |mesh: &TriMesh| match build(mesh, &options, None) {
        Ok(file) => file,
        Err(error @ BuildError::CoordinateOverflow { .. }) => panic!("grid coordinates: {error}"),
        Err(error) => panic!("a small mesh does not build ({options:?}): {error}"),
    };
    let (a, b) = (built(&mesh_a), built(&mesh_b));
    let (pose_a, pose_b) = (bytes.pose(), bytes.pose());
    let (ta, tb) = (triangles(&a), triangles(&b));
    // World units: coordinates up to 16, translations up to 8.
    let eps = 1e-9 * 32.0;
    pair_queries(&a, &b, &pose_a, &pose_b, (&ta, &tb), eps);
    let world_a: Vec<Triangle> = ta.iter().map(|t| t.map(|p| pose_a.apply(&p))).collect();
    let world_b: Vec<Triangle> = tb.iter().map(|t| t.map(|p| pose_b.apply(&p))).collect();
    let points: Vec<[f64; 3]> = (0..4).map(|_| bytes.point()).collect();
    point_queries(&a, &pose_a, &ta, &world_a, &points, eps);
    let rays: Vec<Ray> = (0..4)
        .map(|_| Ray {
            origin: bytes.point(),
            direction: bytes.point(),
        })
        .filter(|r| r.direction != [0.0; 3])
        .collect();
    ray_queries(&a, &pose_a, &ta, &rays);
    hausdorff_query(&a, &pose_a, &b, &pose_b, (&world_a, &world_b), eps);
}

/// Collision, first contact, exact, approximate and limited distance, tolerance and span,
/// against the oracle in A's frame (B mapped as the queries map it).
fn pair_queries(
    a: &ObbtFile,
    b: &ObbtFile,
    pose_a: &Pose,
    pose_b: &Pose,
    (ta, tb): (&[Triangle], &[Triangle]),
    eps: f64,
) {
    let tb_in_a = oracle::in_frame_of_a(pose_a, pose_b, tb);
    let expected = oracle::Answers::of(ta, &tb_in_a);
    let mut pair = PairQuery::new(a, b).expect("two built trees of one type");
    let all = pair
        .collide(pose_a, pose_b, &CollideOptions::default())
        .expect("collides");
    assert_eq!(all.pairs, expected.pairs, "all-pairs collision");
    let first = CollideOptions {
        first_contact: true,
        ..CollideOptions::default()
    };
    let one = pair.collide(pose_a, pose_b, &first).expect("collides");
    assert_eq!(
        one.pairs.len(),
        expected.pairs.len().min(1),
        "first contact"
    );
    assert!(
        one.pairs.iter().all(|p| expected.pairs.contains(p)),
        "first contact {:?} is no contact",
        one.pairs
    );
    let d_star = expected.min_distance;
    let exact = pair
        .distance(pose_a, pose_b, &DistanceOptions::default())
        .expect("measures")
        .distance();
    assert!(
        (exact - d_star).abs() <= eps,
        "distance {exact} vs {d_star}"
    );
    if !expected.pairs.is_empty() {
        assert_eq!(exact, 0.0, "touching models at distance {exact}");
    }
    let rel_err = 0.25;
    let approximate = pair
        .distance(
            pose_a,
            pose_b,
            &DistanceOptions {
                rel_err,
                ..DistanceOptions::default()
            },
        )
        .expect("measures")
        .distance();
    assert!(
        approximate >= d_star - eps && approximate <= d_star * (1.0 + rel_err) + eps,
        "rel_err {rel_err}: {approximate} vs {d_star}"
    );
    for limit in [d_star * 0.5, d_star * 2.0, 1.0] {
        if (limit - d_star).abs() <= eps || limit <= 0.0 {
            continue;
        }
        let limited = pair
            .distance(
                pose_a,
                pose_b,
                &DistanceOptions {
                    max_distance: limit,
                    ..DistanceOptions::default()
                },
            )
            .expect("measures")
            .distance();
        if d_star < limit {
            assert!(
                (limited - d_star).abs() <= eps,
                "max_distance {limit}: {limited} vs {d_star}"
            );
        } else {
            assert_eq!(
                limited,
                f64::INFINITY,
                "max_distance {limit} below {d_star}"
            );
        }
    }
    for tolerance in [d_star * 0.9, d_star * 1.1, 0.5] {
        if (tolerance - d_star).abs() <= eps {
            continue;
        }
        let within = pair
            .within(pose_a, pose_b, &ToleranceOptions::new(tolerance))
            .expect("answers");
        assert_eq!(
            within.closer(),
            d_star < tolerance,
            "tolerance {tolerance}, distance {d_star}"
        );
        if let Some(w) = within.witness {
            assert!(
                w.distance < tolerance + eps,
                "witness at {} for {tolerance}",
                w.distance
            );
        }
    }
    let span = pair
        .span(pose_a, pose_b, &SpanOptions::default())
        .expect("spans")
        .span();
    assert!(
        (span - expected.max_distance).abs() <= eps,
        "span {span} vs {}",
        expected.max_distance
    );
}

/// Closest points and winding numbers (exact and bounded) at query points, against the
/// posed triangles.
fn point_queries(
    a: &ObbtFile,
    pose: &Pose,
    ta: &[Triangle],
    world: &[Triangle],
    points: &[[f64; 3]],
    eps: f64,
) {
    let closest = closest_points(a, pose, points, &ClosestOptions::default()).expect("answers");
    for (p, c) in points.iter().zip(&closest) {
        let expected = point_distance(&Vector3::from(*p), world);
        let found = c.distance();
        assert!(
            (found - expected).abs() <= eps,
            "closest point of {p:?}: {found} vs {expected}"
        );
    }
    // The winding number jumps across the surface: only points clear of it are compared.
    let model = Pose::relative(pose, &Pose::identity());
    let clear: Vec<[f64; 3]> = points
        .iter()
        .copied()
        .filter(|p| point_distance(&Vector3::from(*p), world) > 1e-6)
        .collect();
    for (accuracy, allowed) in [
        (WindingAccuracy::Exact, 1e-9_f64),
        (WindingAccuracy::Bounded { tolerance: 1e-3 }, 1e-3 + 1e-9),
    ] {
        let found =
            winding_numbers(a, pose, &clear, &WindingOptions { accuracy }).expect("answers");
        for (p, w) in clear.iter().zip(&found) {
            let expected = winding(&model.apply(&Vector3::from(*p)), ta);
            assert!(
                (w.value - expected).abs() <= allowed.max(w.error_bound + 1e-9),
                "winding number at {p:?} ({accuracy:?}): {} vs {expected}",
                w.value
            );
        }
    }
}

/// The closest hit of each ray, against every triangle tested alone in the frame the
/// library maps the ray into (ties to the smallest input id).
fn ray_queries(a: &ObbtFile, pose: &Pose, ta: &[Triangle], rays: &[Ray]) {
    let options = RayOptions {
        mode: RayMode::Closest,
        t_max: f64::INFINITY,
    };
    let found = cast_rays(a, pose, rays, &options).expect("casts");
    let model = Pose::relative(pose, &Pose::identity());
    for (ray, r) in rays.iter().zip(&found) {
        let origin = model.apply(&Vector3::from(ray.origin));
        let direction = model.rotation() * Vector3::from(ray.direction);
        let Some(space) = RaySpace::new(&origin, &direction) else {
            continue;
        };
        let expected = ta
            .iter()
            .enumerate()
            .filter_map(|(id, t)| Some((space.intersect(t, f64::INFINITY)?.t, id as u32)))
            // (-0 and 0 are one parameter: a ray starting on two triangles.)
            .min_by(|x, y| {
                x.0.partial_cmp(&y.0)
                    .unwrap_or(std::cmp::Ordering::Equal)
                    .then(x.1.cmp(&y.1))
            });
        let hit = r.hit.map(|h| (h.t, h.triangle));
        assert!(
            match (hit, expected) {
                (Some((t, id)), Some((u, jd))) => t == u && id == jd,
                (None, None) => true,
                _ => false,
            },
            "closest hit of {ray:?}: {hit:?} vs {expected:?}"
        );
    }
}

/// The Hausdorff error asked: exact answers on a ridge between two triangles' regions
/// cost seconds (pieces split to the floor all along it), which would starve the fuzzer;
/// `tests/it/hausdorff.rs` holds the exact ones to brute force.
const HAUSDORFF_REL_ERR: f64 = 1e-6;

/// The one-sided Hausdorff distance: at least every vertex's distance, at most its bound
/// over samples of A, the witness at the distance it claims, the bounds within the error.
fn hausdorff_query(
    a: &ObbtFile,
    pose_a: &Pose,
    b: &ObbtFile,
    pose_b: &Pose,
    (world_a, world_b): (&[Triangle], &[Triangle]),
    eps: f64,
) {
    let options = HausdorffOptions {
        rel_err: HAUSDORFF_REL_ERR,
        ..HausdorffOptions::default()
    };
    let h = hausdorff(a, pose_a, b, pose_b, &options).expect("measures");
    assert!(h.distance <= h.upper_bound, "{h:?}");
    let witness = point_distance(&Vector3::from(h.point_a), world_b);
    assert!(
        (witness - h.distance).abs() <= eps,
        "witness at {witness}, claimed {}",
        h.distance
    );
    for t in world_a {
        let [p, q, r] = *t;
        for s in [
            p,
            q,
            r,
            (p + q) / 2.0,
            (q + r) / 2.0,
            (r + p) / 2.0,
            (p + q + r) / 3.0,
        ] {
            let d = point_distance(&s, world_b);
            assert!(d <= h.upper_bound + eps, "a point of A at {d}, above {h:?}");
        }
    }
    let corners = world_a
        .iter()
        .flatten()
        .map(|p| point_distance(p, world_b))
        .fold(0.0, f64::max);
    assert!(
        h.distance >= corners - eps,
        "h {} below a corner at {corners}",
        h.distance
    );
    // Within the error asked; or, where that is below 2^-24 of A's diagonal (h about 0),
    // within what the floor of the splitting leaves (pieces of 2^-16 of A's diagonal, where
    // bounds close at least linearly). The query measures A's bounding box in B's frame,
    // whose diagonal is up to √3 times the world box's.
    let (lo, hi) = world_a.iter().flatten().fold(
        (
            Vector3::repeat(f64::INFINITY),
            Vector3::repeat(f64::NEG_INFINITY),
        ),
        |(lo, hi), p| (lo.inf(p), hi.sup(p)),
    );
    let floor_gap = 2.0 * (hi - lo).norm() / f64::from(1u32 << 16);
    assert!(
        h.upper_bound <= h.distance * (1.0 + HAUSDORFF_REL_ERR) + eps
            || (HAUSDORFF_REL_ERR * h.distance
                < 3f64.sqrt() * (hi - lo).norm() / f64::from(1u32 << 24)
                && h.upper_bound <= h.distance + floor_gap + eps),
        "bounds further apart than asked: {h:?}"
    );
}
