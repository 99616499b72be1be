//! Contact geometry: where touching triangles meet (`triangle_intersection`) on closed
//! forms, against an independent computation on random crossing pairs, and through a
//! collision query and the CLI on the cow.
// Test code outside `#[test]` functions (helpers): a failure is a failed test.
#![allow(clippy::expect_used, clippy::indexing_slicing)]

use crate::closest::point_triangle_distance;
use crate::common;

use nalgebra::Vector3;
use obbtree::build::{build, BuildOptions};
use obbtree::generate::Rng;
use obbtree::query::triangle::{
    triangle_intersection, triangles_intersect, IntersectionKind, Triangle,
};
use obbtree::query::{CollideOptions, PairQuery, Pose};

fn v(x: f64, y: f64, z: f64) -> Vector3<f64> {
    Vector3::new(x, y, z)
}

#[test]
fn a_crossing_pair_meets_along_its_known_segment() {
    let a: Triangle = [v(0.0, 0.0, 0.0), v(2.0, 0.0, 0.0), v(0.0, 2.0, 0.0)];
    // In the plane x = 0.5, covering y from -1 to 4 at z = 0: the cut is A's chord there.
    let b: Triangle = [v(0.5, -1.0, -1.0), v(0.5, -1.0, 1.0), v(0.5, 4.0, 0.0)];
    let meet = triangle_intersection(&a, &b).expect("they cross");
    assert_eq!(meet.kind, IntersectionKind::Segment);
    let mut ends: Vec<Vector3<f64>> = meet.points().to_vec();
    ends.sort_by(|p, q| p.y.total_cmp(&q.y));
    assert_eq!(ends, vec![v(0.5, 0.0, 0.0), v(0.5, 1.5, 0.0)]);
    assert_eq!(meet.length(), 1.5);
    // Each cuts the other short: the cut is where their chords overlap (z from -5 to 0),
    // neither chord whole, also for corners placed about the origin, in either order.
    let [p, q, r] = [v(-1.0, 0.0, -10.0), v(1.0, 0.0, -10.0), v(1.0, 0.0, 10.0)];
    let upright: Triangle = [v(0.0, -5.0, -5.0), v(0.0, 5.0, -5.0), v(0.0, 0.0, 5.0)];
    let (long, turned): (Triangle, Triangle) = ([p, q, r], [p, r, q]);
    for (x, y) in [(&long, &upright), (&upright, &long), (&turned, &upright)] {
        let meet = triangle_intersection(x, y).expect("they cross");
        let mut ends: Vec<Vector3<f64>> = meet.points().to_vec();
        ends.sort_by(|p, q| p.z.total_cmp(&q.z));
        assert_eq!(ends, vec![v(0.0, 0.0, -5.0), v(0.0, 0.0, 0.0)]);
    }
    // Touching at one corner: a segment of length 0 at that corner.
    let c: Triangle = [v(2.0, 0.0, 0.0), v(3.0, 0.0, 1.0), v(3.0, 1.0, -1.0)];
    let corner = triangle_intersection(&a, &c).expect("they touch");
    assert_eq!(corner.points(), &[v(2.0, 0.0, 0.0), v(2.0, 0.0, 0.0)]);
    // Apart: nothing.
    let far: Triangle = [v(5.0, 0.0, 0.0), v(6.0, 0.0, 0.0), v(5.0, 1.0, 0.0)];
    assert!(triangle_intersection(&a, &far).is_none());
}

/// A corner exactly on the other triangle's plane, inside it, the triangle's other two
/// corners to one side: they meet at that corner, and the answer is it to the bit (the
/// module's promise), though the other triangle's section through it is computed and
/// rounded. Corners on a 1/1024 grid and a point at sixty-fourths of its edges, kept only
/// where the predicates find it on the plane exactly.
#[test]
fn a_corner_touching_a_face_is_where_they_meet_exactly() {
    let mut rng = Rng::new(5);
    let mut unit = || rng.unit();
    let mut touching = 0;
    for _ in 0..100_000 {
        let grid = |x: f64| ((2.0 * x - 1.0) * 1024.0).round() / 1024.0;
        let a: Triangle = [0, 1, 2].map(|_| v(grid(unit()), grid(unit()), grid(unit())));
        let (s, t) = (
            (16.0 * unit()).floor() / 64.0,
            (16.0 * unit()).floor() / 64.0,
        );
        let corner = a[0] + (a[1] - a[0]) * s + (a[2] - a[0]) * t;
        let normal = (a[1] - a[0]).cross(&(a[2] - a[0])).normalize();
        let off = v(unit() - 0.5, unit() - 0.5, unit() - 0.5);
        let b: Triangle = [
            corner,
            corner + normal * 0.5 + off,
            corner + normal * 0.7 - off,
        ];
        let side = |p: &Vector3<f64>| {
            let c = |p: &Vector3<f64>| robust::Coord3D {
                x: p.x,
                y: p.y,
                z: p.z,
            };
            robust::orient3d(c(&a[0]), c(&a[1]), c(&a[2]), c(p))
        };
        if side(&corner) != 0.0 || side(&b[1]) * side(&b[2]) <= 0.0 {
            continue;
        }
        touching += 1;
        for (x, y) in [(&a, &b), (&b, &a)] {
            let meet = triangle_intersection(x, y).expect("they touch");
            assert_eq!(meet.points(), &[corner, corner], "{a:?} {b:?}");
        }
    }
    assert!(touching > 1000, "{touching}");
}

/// Triangles that meet at one point where an edge of each crosses the other's plane, their
/// chords along the planes' common line meeting end to end: the cut is that point. Each
/// edge crosses a third of its way along, so each chord's end is rounded on its own; with
/// these translations (found by a search over translations of three decimals) the two ends
/// pass each other, and the answer must still be the point, wherever it lies.
#[test]
fn chords_meeting_end_to_end_give_their_one_common_point() {
    for (s, t, at) in [
        (3.0, 5.0, v(0.001, 15.372, -23.062)),
        (9.0, 6.0, v(1.421, 3.236, 39.354)),
        (8.0, 5.0, v(-7.871, 43.393, 7.044)),
        (4.0, 9.0, v(-0.722, -14.523, 16.173)),
    ] {
        // `a` in z = 0 meets the x axis from below 0 up to 0, `b` in y = 0 from 0 up.
        let a: Triangle = [v(s, -1.0, 0.0), v(-2.0 * s, 2.0, 0.0), v(-3.0, -1.0, 0.0)];
        let b: Triangle = [v(-t, 0.0, -1.0), v(2.0 * t, 0.0, 2.0), v(3.0, 0.0, -1.0)];
        let (a, b) = (a.map(|p| p + at), b.map(|p| p + at));
        for (x, y) in [(&a, &b), (&b, &a)] {
            let meet = triangle_intersection(x, y).expect("they touch");
            assert_eq!(meet.kind, IntersectionKind::Segment);
            for p in meet.points() {
                assert!((p - at).norm() <= 1e-13 * at.norm(), "{p:?} for {at:?}");
            }
        }
    }
}

#[test]
fn coplanar_pairs_share_their_overlap_polygon() {
    let a: Triangle = [v(0.0, 0.0, 0.0), v(2.0, 0.0, 0.0), v(0.0, 2.0, 0.0)];
    let b: Triangle = [v(1.0, 0.0, 0.0), v(3.0, 0.0, 0.0), v(1.0, 2.0, 0.0)];
    let meet = triangle_intersection(&a, &b).expect("they overlap");
    assert_eq!(meet.kind, IntersectionKind::Polygon);
    assert_eq!(meet.points().len(), 3, "{:?}", meet.points());
    assert!((meet.area() - 0.5).abs() <= 1e-15, "{}", meet.area());
    for p in [v(1.0, 0.0, 0.0), v(2.0, 0.0, 0.0), v(1.0, 1.0, 0.0)] {
        assert!(
            meet.points().iter().any(|q| (q - p).norm() <= 1e-15),
            "{p:?} missing"
        );
    }
    // A hexagon: a triangle and its point reflection through their common centroid.
    let c = (a[0] + a[1] + a[2]) / 3.0;
    let flipped: Triangle = a.map(|p| c * 2.0 - p);
    let hexagon = triangle_intersection(&a, &flipped).expect("they overlap");
    assert_eq!(hexagon.points().len(), 6);
    // (Two thirds of the triangle's area 2.)
    assert!(
        (hexagon.area() - 4.0 / 3.0).abs() <= 1e-14,
        "{}",
        hexagon.area()
    );
}

/// A corner of one coplanar triangle exactly on the line of the other's edge is a corner of
/// their polygon once: no crossing is made there, which would land near the corner, not on
/// it (`0.7 + (0.1 - 0.7)` is not `0.1`), and stay beside it as a corner of its own.
#[test]
fn a_corner_on_an_edge_line_is_one_corner_of_the_shared_polygon() {
    let b: Triangle = [v(-10.0, 0.0, 0.0), v(10.0, 0.0, 0.0), v(0.0, 10.0, 0.0)];
    // The corner before it inside `b`: the polygon is `a` itself.
    let inside: Triangle = [v(0.7, 1.0, 0.0), v(0.1, 0.0, 0.0), v(2.0, 1.5, 0.0)];
    let meet = triangle_intersection(&inside, &b).expect("they overlap");
    assert_eq!(meet.points(), &inside);
    // The corner before it outside: that edge is cut off, the corner stays.
    let across: Triangle = [v(0.7, -1.0, 0.0), v(0.1, 0.0, 0.0), v(2.0, 1.5, 0.0)];
    let meet = triangle_intersection(&across, &b).expect("they overlap");
    let points = meet.points();
    assert_eq!(points.len(), 3, "{points:?}");
    assert_eq!(points[..2], across[1..]);
}

/// Coplanar triangles that only touch share a segment or a point: their polygon is that
/// segment's two ends or that one point, each once, though clipping meets them twice.
#[test]
fn coplanar_triangles_touching_along_an_edge_or_at_a_corner_share_it_once() {
    let a: Triangle = [v(-0.5, 0.25, 0.0), v(0.75, 0.25, 0.0), v(0.75, 0.0, 0.0)];
    let b: Triangle = [v(0.5, 1.0, 0.0), v(0.5, 0.25, 0.0), v(-0.25, 0.25, 0.0)];
    let ends = [v(-0.25, 0.25, 0.0), v(0.5, 0.25, 0.0)];
    let corner: Triangle = [v(0.75, 0.0, 0.0), v(1.0, 0.0, 0.0), v(1.0, -1.0, 0.0)];
    for (x, y, shared) in [(&a, &b, &ends[..]), (&a, &corner, &[corner[0]][..])] {
        for (x, y) in [(x, y), (y, x)] {
            let meet = triangle_intersection(x, y).expect("they touch");
            assert_eq!(meet.kind, IntersectionKind::Polygon);
            let mut points = meet.points().to_vec();
            points.sort_by(|p, q| p.x.total_cmp(&q.x));
            assert_eq!(points, shared, "{x:?} {y:?}");
            assert_eq!(meet.area(), 0.0);
        }
    }
}

/// Where the edges of one triangle pierce the other, both ways: for a generic crossing
/// pair, the two ends of their intersection segment. Computed apart from the library, by
/// solving each edge against the other triangle's plane and testing barycentrics.
fn piercings(a: &Triangle, b: &Triangle) -> Vec<Vector3<f64>> {
    let mut out = Vec::new();
    for (s, t) in [(a, b), (b, a)] {
        let n = (t[1] - t[0]).cross(&(t[2] - t[0]));
        for i in 0..3 {
            let (p, q) = (s[i], s[(i + 1) % 3]);
            let (dp, dq) = (n.dot(&(p - t[0])), n.dot(&(q - t[0])));
            if dp * dq >= 0.0 {
                continue;
            }
            let x = p + (q - p) * (dp / (dp - dq));
            if point_triangle_distance(&x, &t.map(Into::into)) <= 1e-9 {
                out.push(x);
            }
        }
    }
    out
}

#[test]
fn random_crossing_segments_match_an_independent_computation() {
    let mut rng = Rng::new(17);
    let mut checked = 0;
    while checked < 500 {
        let mut corner = || v(rng.signed(), rng.signed(), rng.signed());
        let a: Triangle = [corner(), corner(), corner()];
        let b: Triangle = [corner(), corner(), corner()];
        if !triangles_intersect(&a, &b) {
            continue;
        }
        let meet = triangle_intersection(&a, &b).expect("they touch");
        assert_eq!(meet.kind, IntersectionKind::Segment);
        let brute = piercings(&a, &b);
        if brute.len() != 2 {
            continue;
        }
        for p in meet.points() {
            let nearest = brute
                .iter()
                .map(|q| (p - q).norm())
                .fold(f64::INFINITY, f64::min);
            assert!(nearest <= 1e-12, "{p:?} is {nearest} from {brute:?}");
        }
        let length = (brute[0] - brute[1]).norm();
        assert!(
            (meet.length() - length).abs() <= 1e-12,
            "{} vs {length}",
            meet.length()
        );
        assert!(meet.residual <= 1e-12, "{}", meet.residual);
        checked += 1;
    }
}

#[test]
fn a_collision_query_gives_every_contact_its_geometry() {
    let file = build(&common::cow(), &BuildOptions::default(), None).expect("builds");
    // Both posed, so that the geometry is placed in the world by A's pose too.
    let (pose_a, pose_b) = (common::sliding_pose(0.02, 7), common::turned_pose(5, 0.05));
    let mut pair = PairQuery::new(&file, &file).expect("a pair");
    let options = CollideOptions {
        geometry: true,
        ..CollideOptions::default()
    };
    let r = pair.collide(&pose_a, &pose_b, &options).expect("answers");
    assert!(r.pairs.len() > 50, "{} contacts", r.pairs.len());
    let ids: Vec<(u32, u32)> = r.contacts.iter().map(|c| (c.tri_a, c.tri_b)).collect();
    assert_eq!(ids, r.pairs);
    // Every point lies on both posed triangles.
    let tris: std::collections::HashMap<u32, [[f64; 3]; 3]> =
        common::file_triangles(&file).into_iter().collect();
    let world = |id: u32, pose: &Pose| tris[&id].map(|p| pose.apply(&Vector3::from(p)).into());
    for c in &r.contacts {
        let (ta, tb) = (world(c.tri_a, &pose_a), world(c.tri_b, &pose_b));
        for p in c.intersection.points() {
            let off = point_triangle_distance(p, &ta).max(point_triangle_distance(p, &tb));
            assert!(off <= 1e-12, "{c:?}: {off}");
        }
    }
    let total: f64 = r.contacts.iter().map(|c| c.intersection.length()).sum();
    assert!(total > 0.0 && r.curve_length() == total);
    let (lo, hi) = r.contact_bounds().expect("contacts");
    for p in r.contacts.iter().flat_map(|c| c.intersection.points()) {
        assert!((0..3).all(|k| lo[k] <= p[k] && p[k] <= hi[k]));
    }
    assert_eq!(r.overlap_area(), 0.0, "no coplanar pairs in a turned pose");
    // Without the option: the same pairs, no geometry.
    let plain = pair
        .collide(&pose_a, &pose_b, &CollideOptions::default())
        .expect("answers");
    assert_eq!(plain.pairs, r.pairs);
    assert!(plain.contacts.is_empty() && plain.contact_bounds().is_none());
}

#[test]
fn the_cli_prints_the_geometry() {
    use common::cli::{cow, obbtree, stderr};
    let file = build(&common::cow(), &BuildOptions::default(), None).expect("builds");
    let pose = "0,-1,0,1,0,0,0,0,1,0.05,0,0";
    let pose_b =
        Pose::from_row_major(&[0.0, -1.0, 0.0, 1.0, 0.0, 0.0, 0.0, 0.0, 1.0, 0.05, 0.0, 0.0])
            .expect("a pose");
    let options = CollideOptions {
        geometry: true,
        ..CollideOptions::default()
    };
    let r = PairQuery::new(&file, &file)
        .expect("a pair")
        .collide(&Pose::identity(), &pose_b, &options)
        .expect("answers");
    let cow = cow();
    let o = obbtree(&[
        "collide",
        &cow,
        &cow,
        "--pose-b",
        pose,
        "--geometry",
        "--json",
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    let line: serde_json::Value = serde_json::from_slice(&o.stdout).expect("JSON");
    let printed = line["curve_length"].as_f64().expect("a number");
    assert!(
        (printed - r.curve_length()).abs() <= 1e-12 * r.curve_length(),
        "{printed}"
    );
    assert_eq!(
        line["geometry"].as_array().expect("contacts").len(),
        r.pairs.len()
    );
    assert_eq!(line["geometry"][0]["kind"], "segment");
    let o = obbtree(&[
        "collide",
        &cow,
        &cow,
        "--pose-b",
        pose,
        "--geometry",
        "--csv",
    ]);
    let text = String::from_utf8_lossy(&o.stdout);
    let mut lines = text.lines();
    let header: Vec<&str> = lines.next().expect("a header").split(',').collect();
    let row: Vec<&str> = lines.next().expect("a row").split(',').collect();
    let column = header
        .iter()
        .position(|h| *h == "curve_length")
        .expect("the column");
    let value: f64 = row[column].parse().expect("a number");
    assert!((value - r.curve_length()).abs() <= 1e-12 * r.curve_length());
}

/// Two unit cubes, one moved by (0.5, 0.25, 0): their top faces lie in one plane and share
/// a 0.5 × 0.75 rectangle, as their bottom faces do; the side faces cross.
#[test]
fn coplanar_faces_count_in_the_overlap_area() {
    let file = build(&common::cube(0.5), &BuildOptions::default(), None).expect("builds");
    let mut pair = PairQuery::new(&file, &file).expect("a pair");
    let options = CollideOptions {
        geometry: true,
        ..CollideOptions::default()
    };
    let r = pair
        .collide(
            &Pose::identity(),
            &Pose::translation(0.5, 0.25, 0.0),
            &options,
        )
        .expect("answers");
    let area = r.overlap_area();
    assert!((area - 0.75).abs() <= 1e-12, "{area}");
    assert!(r.curve_length() > 0.0);
}
