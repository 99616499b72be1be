//! The smallest ball enclosing a set of points (Welzl's algorithm with the move-to-front
//! heuristic of Gärtner's "miniball"): expected linear time, exact up to rounding. The
//! sphere volume uses its centre and measures the radius itself, rounding outward, so
//! containment never depends on this computation's accuracy.

use crate::generate::Rng;
use nalgebra::Vector3;

/// A ball: centre and squared radius (negative for the empty ball).
#[derive(Clone, Copy, Debug)]
struct Ball {
    center: Vector3<f64>,
    radius2: f64,
}

impl Ball {
    const EMPTY: Ball = Ball {
        center: Vector3::new(0.0, 0.0, 0.0),
        radius2: -1.0,
    };

    /// Whether `p` is inside, with a relative margin of rounding size (a point on the
    /// sphere through its support counts as inside).
    fn contains(&self, p: &Vector3<f64>) -> bool {
        (p - self.center).norm_squared() <= self.radius2 * (1.0 + 1e-12) + 1e-300
    }

    /// The smallest ball with every point of `support` (at most 4) on its boundary, or
    /// `None` when they are degenerate (coincident, collinear or coplanar beyond what the
    /// support's size allows).
    fn through(support: &[Vector3<f64>]) -> Option<Ball> {
        match support {
            [] => Some(Ball::EMPTY),
            [a] => Some(Ball {
                center: *a,
                radius2: 0.0,
            }),
            [a, b] => {
                let center = (a + b) / 2.0;
                Some(Ball {
                    center,
                    radius2: (a - center).norm_squared(),
                })
            }
            [a, b, c] => {
                let (u, v) = (b - a, c - a);
                let w = u.cross(&v);
                let w2 = w.norm_squared();
                // Collinear: no circle through the three.
                if w2 <= 1e-24 * u.norm_squared() * v.norm_squared() {
                    return None;
                }
                let x =
                    (v.cross(&w) * u.norm_squared() + w.cross(&u) * v.norm_squared()) / (2.0 * w2);
                Some(Ball {
                    center: a + x,
                    radius2: x.norm_squared(),
                })
            }
            [a, b, c, d] => {
                let (u, v, w) = (b - a, c - a, d - a);
                let det = u.dot(&v.cross(&w));
                // Coplanar: no sphere through the four.
                if det.abs() <= 1e-12 * u.norm() * v.norm() * w.norm() {
                    return None;
                }
                let x = (v.cross(&w) * u.norm_squared()
                    + w.cross(&u) * v.norm_squared()
                    + u.cross(&v) * w.norm_squared())
                    / (2.0 * det);
                Some(Ball {
                    center: a + x,
                    radius2: x.norm_squared(),
                })
            }
            _ => None,
        }
    }
}

/// The smallest ball of `points[..end]` with `support` on its boundary (move-to-front:
/// a point found outside goes to the front, so later calls meet it early).
fn move_to_front(points: &mut [Vector3<f64>], end: usize, support: &mut Vec<Vector3<f64>>) -> Ball {
    let mut ball = match Ball::through(support) {
        Some(ball) => ball,
        // A degenerate support: the ball of all but its newest point, which then lies
        // within rounding of that ball's boundary.
        None => {
            let newest = support.pop();
            let ball = Ball::through(support).unwrap_or(Ball::EMPTY);
            support.extend(newest);
            ball
        }
    };
    if support.len() == 4 {
        return ball;
    }
    for i in 0..end {
        let Some(&p) = points.get(i) else {
            break;
        };
        if !ball.contains(&p) {
            support.push(p);
            ball = move_to_front(points, i, support);
            support.pop();
            if let Some(prefix) = points.get_mut(..=i) {
                prefix.rotate_right(1);
            }
        }
    }
    ball
}

/// The centre of the smallest ball containing `points` (the origin for none). Exact up to
/// rounding: callers measure the radius from it.
pub(crate) fn minimal_ball_center<'a>(points: impl Iterator<Item = &'a [f64; 3]>) -> [f64; 3] {
    let mut points: Vec<Vector3<f64>> = points.map(|p| Vector3::from(*p)).collect();
    // Move-to-front is expected linear on points in random order, and input order (often
    // sorted along the surface) is its worst case. A shuffle of fixed seed keeps the
    // result a function of the points alone.
    let mut rng = Rng::new(points.len() as u64);
    for i in (1..points.len()).rev() {
        points.swap(i, rng.below(i + 1));
    }
    let mut support = Vec::with_capacity(4);
    let end = points.len();
    move_to_front(&mut points, end, &mut support).center.into()
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The largest distance from `c` to the points.
    fn reach(c: [f64; 3], points: &[[f64; 3]]) -> f64 {
        points
            .iter()
            .map(|p| (Vector3::from(*p) - Vector3::from(c)).norm())
            .fold(0.0, f64::max)
    }

    #[test]
    fn known_balls_are_found() {
        // A regular tetrahedron's circumcentre is its centroid.
        let tetra = [
            [1.0, 1.0, 1.0],
            [1.0, -1.0, -1.0],
            [-1.0, 1.0, -1.0],
            [-1.0, -1.0, 1.0],
        ];
        let c = minimal_ball_center(tetra.iter());
        assert!(Vector3::from(c).norm() < 1e-12, "{c:?}");
        // Two far points and many between: the ball is their diameter's.
        let mut line: Vec<[f64; 3]> = (0..50)
            .map(|i| [f64::from(i) / 49.0 * 4.0 - 2.0, 0.1, 0.0])
            .collect();
        line.push([0.0, 0.0, 0.0]);
        let c = minimal_ball_center(line.iter());
        assert!((reach(c, &line) - 2.0).abs() < 1e-9, "{c:?}");
        // One point is its own centre, also listed many times; two their midpoint.
        let point = [0.25, -0.5, 0.125];
        assert_eq!(minimal_ball_center([point].iter()), point);
        assert_eq!(minimal_ball_center([point; 6].iter()), point);
        let pair = [point, [0.75, -0.5, 0.125]];
        assert_eq!(minimal_ball_center(pair.iter()), [0.5, -0.5, 0.125]);
        // An octahedron's corners about (3, 0, 0), each listed twice: all on the ball.
        let corners = [
            [4.0, 0.0, 0.0],
            [2.0, 0.0, 0.0],
            [3.0, 1.0, 0.0],
            [3.0, -1.0, 0.0],
            [3.0, 0.0, 1.0],
            [3.0, 0.0, -1.0],
        ];
        let octahedron: Vec<[f64; 3]> = corners.iter().flat_map(|&p| [p, p]).collect();
        let c = minimal_ball_center(octahedron.iter());
        assert!(
            (Vector3::from(c) - Vector3::new(3.0, 0.0, 0.0)).norm() < 1e-12,
            "{c:?}"
        );
    }

    /// The degeneracy tests compare a measure with the size of the support, so whether a
    /// support is degenerate does not depend on the units: nearly collinear triples and
    /// nearly coplanar quadruples just below and above the threshold, at three scales.
    #[test]
    fn degeneracy_does_not_depend_on_scale() {
        let v = |x: f64, y: f64, z: f64| Vector3::new(x, y, z);
        for (eps, degenerate) in [(1e-13, true), (1e-9, false)] {
            // Volume `eps` against a product of edge lengths about 0.7.
            let quad = [
                v(0.0, 0.0, 0.0),
                v(1.0, 0.0, 0.0),
                v(0.0, 1.0, 0.0),
                v(0.5, 0.5, eps),
            ];
            // Squared area `eps²/4` against a product of squared lengths about 1.
            let triple = [v(0.0, 0.0, 0.0), v(1.0, 0.0, 0.0), v(0.5, eps, 0.0)];
            for scale in [1e-3, 1.0, 1e3] {
                let quad = quad.map(|p| p * scale);
                let triple = triple.map(|p| p * scale);
                assert_eq!(
                    Ball::through(&quad).is_none(),
                    degenerate,
                    "{eps} at {scale}"
                );
                assert_eq!(
                    Ball::through(&triple).is_none(),
                    degenerate,
                    "{eps} at {scale}"
                );
                // A ball found passes through its support.
                for support in [&quad[..], &triple[..]] {
                    if let Some(ball) = Ball::through(support) {
                        for p in support {
                            let r2 = (p - ball.center).norm_squared();
                            assert!((r2 - ball.radius2).abs() <= 1e-4 * ball.radius2);
                        }
                    }
                }
            }
        }
    }

    #[test]
    fn random_clouds_get_a_ball_no_other_centre_improves() {
        let mut rng = crate::generate::Rng::new(5);
        // Clouds about the origin, and small ones away from it: the ball owes nothing to
        // where the points are or how far they reach.
        for (n, size, offset) in [
            (3, 1.0, 0.0),
            (10, 1.0, 0.0),
            (100, 1.0, 0.0),
            (1000, 1.0, 0.0),
            (2, 0.1, 0.3),
            (10, 0.1, 0.3),
            (100, 0.01, -0.2),
        ] {
            let points: Vec<[f64; 3]> = (0..n)
                .map(|_| {
                    [rng.signed() * 3.0, rng.signed(), rng.signed() * 0.2]
                        .map(|x| x * size + offset)
                })
                .collect();
            let c = minimal_ball_center(points.iter());
            let r = reach(c, &points);
            // Any move of the centre makes the ball larger (checked along many directions).
            for _ in 0..200 {
                let step = Vector3::new(rng.signed(), rng.signed(), rng.signed()) * 1e-3 * size;
                let moved = (Vector3::from(c) + step).into();
                assert!(reach(moved, &points) >= r - 1e-12 * size, "n = {n}");
            }
        }
    }
}
