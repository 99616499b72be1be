//! The brute-force reference of the query suites: every triangle pair of two lists tested
//! with the library's leaf primitives. A query that prunes a pair it should have opened
//! then disagrees with it; the primitives themselves are checked against independent
//! references in `tests/it/triangle_primitives.rs`.
//!
//! Both lists must be in one frame. [`in_frame_of_a`] maps B's triangles as the queries
//! map them, so that the oracle and a query round alike and can be compared exactly.

use nalgebra::Vector3;
use obbtree::query::triangle::{triangle_distance, triangles_intersect, Triangle};
use obbtree::query::Pose;

/// What the brute force says about two triangle lists, for the suites that check every
/// query kind on the same pair.
#[derive(Clone, Debug)]
pub struct Answers {
    /// [`contact_pairs`].
    pub pairs: Vec<(u32, u32)>,
    /// [`min_distance`].
    pub min_distance: f64,
    /// [`max_distance`].
    pub max_distance: f64,
}

impl Answers {
    /// All three answers for `a` and `b`.
    pub fn of(a: &[Triangle], b: &[Triangle]) -> Answers {
        Answers {
            pairs: contact_pairs(a, b),
            min_distance: min_distance(a, b),
            max_distance: max_distance(a, b),
        }
    }
}

/// Every pair `(i, j)` with `a[i]` touching `b[j]`, sorted (as the collision queries
/// report them).
pub fn contact_pairs(a: &[Triangle], b: &[Triangle]) -> Vec<(u32, u32)> {
    let mut pairs = Vec::new();
    for (i, s) in a.iter().enumerate() {
        for (j, t) in b.iter().enumerate() {
            if triangles_intersect(s, t) {
                pairs.push((i as u32, j as u32));
            }
        }
    }
    pairs
}

/// The least distance between a triangle of `a` and one of `b` (infinite if either list
/// is empty).
pub fn min_distance(a: &[Triangle], b: &[Triangle]) -> f64 {
    a.iter()
        .flat_map(|s| b.iter().map(move |t| triangle_distance(s, t).distance))
        .fold(f64::INFINITY, f64::min)
}

/// The greatest distance between a point of `a` and one of `b` (0 if either list is
/// empty). Taken over corners alone: the distance to a point is convex, so over a
/// triangle it peaks at a corner.
pub fn max_distance(a: &[Triangle], b: &[Triangle]) -> f64 {
    let corners = |list: &[Triangle]| list.iter().flatten().copied().collect::<Vec<_>>();
    let (pa, pb) = (corners(a), corners(b));
    pa.iter()
        .flat_map(|p| pb.iter().map(move |q| (p - q).norm()))
        .fold(0.0, f64::max)
}

/// The triangles of B (model frame) in A's model frame, mapped by the relative pose as
/// the queries map them rather than through the world, so that both round alike.
pub fn in_frame_of_a(pose_a: &Pose, pose_b: &Pose, b: &[Triangle]) -> Vec<Triangle> {
    let xf = Pose::relative(pose_a, pose_b);
    b.iter().map(|t| t.map(|p| xf.apply(&p))).collect()
}

/// The faces of a vertex list, posed into the world.
pub fn posed(vertices: &[[f64; 3]], faces: &[[u32; 3]], pose: &Pose) -> Vec<Triangle> {
    faces
        .iter()
        .map(|f| f.map(|v| pose.apply(&Vector3::from(vertices[v as usize]))))
        .collect()
}
