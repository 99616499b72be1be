//! The two ray sets the ray benchmarks and the ray profiler cast at a mesh: camera rays
//! (coherent) and random rays (incoherent), from one seed.

use obbtree::generate::Rng;
use obbtree::mesh::TriMesh;
use obbtree::query::Ray;

/// The mesh's bounding box, low and high corners.
fn bounds(mesh: &TriMesh) -> ([f64; 3], [f64; 3]) {
    let (mut lo, mut hi) = ([f64::INFINITY; 3], [f64::NEG_INFINITY; 3]);
    for v in mesh.vertices() {
        for ((l, h), x) in lo.iter_mut().zip(hi.iter_mut()).zip(v) {
            *l = l.min(*x);
            *h = h.max(*x);
        }
    }
    (lo, hi)
}

/// About `count` rays of a square image of the mesh's bounding sphere, seen from three
/// radii away along +z: neighbouring rays take neighbouring paths.
pub fn camera_rays(mesh: &TriMesh, count: usize) -> Vec<Ray> {
    let (lo, hi) = bounds(mesh);
    let centre: [f64; 3] = std::array::from_fn(|k| (lo[k] + hi[k]) / 2.0);
    let radius = (0..3).map(|k| (hi[k] - lo[k]).powi(2)).sum::<f64>().sqrt() / 2.0;
    let side = (count as f64).sqrt().ceil() as usize;
    let origin = [centre[0], centre[1], centre[2] + 3.0 * radius];
    (0..side * side)
        .map(|i| {
            let (u, v) = (
                (i % side) as f64 / side as f64,
                (i / side) as f64 / side as f64,
            );
            let target = [
                centre[0] + (2.0 * u - 1.0) * radius,
                centre[1] + (2.0 * v - 1.0) * radius,
                centre[2],
            ];
            Ray {
                origin,
                direction: std::array::from_fn(|k| target[k] - origin[k]),
            }
        })
        .collect()
}

/// `count` rays from uniform points of the sphere twice the bounding sphere to uniform
/// points of the bounding box: every ray takes its own path through the tree.
pub fn random_rays(mesh: &TriMesh, count: usize, seed: u64) -> Vec<Ray> {
    let (lo, hi) = bounds(mesh);
    let centre: [f64; 3] = std::array::from_fn(|k| (lo[k] + hi[k]) / 2.0);
    let radius = (0..3).map(|k| (hi[k] - lo[k]).powi(2)).sum::<f64>().sqrt() / 2.0;
    let mut rng = Rng::new(seed);
    (0..count)
        .map(|_| {
            let d = loop {
                let d = [rng.signed(), rng.signed(), rng.signed()];
                let n = (d[0] * d[0] + d[1] * d[1] + d[2] * d[2]).sqrt();
                if n > 0.1 && n <= 1.0 {
                    break d.map(|x| x / n);
                }
            };
            let origin: [f64; 3] = std::array::from_fn(|k| centre[k] + 2.0 * radius * d[k]);
            let target: [f64; 3] = std::array::from_fn(|k| lo[k] + (hi[k] - lo[k]) * rng.unit());
            Ray {
                origin,
                direction: std::array::from_fn(|k| target[k] - origin[k]),
            }
        })
        .collect()
}
