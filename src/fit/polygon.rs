//! 2-D convex hull (Andrew's monotone chain) for coplanar point sets.
//!
//! Used when the points span a plane: the hull "surface" is then the convex polygon, whose
//! area distribution gives the in-plane covariance. The chain pops reflex turns and
//! boundary points within `eps` of the line through their neighbours, so collinear
//! boundary points (exactly, or up to the rounding of the projection into the plane) and
//! duplicates are dropped; it always terminates and, being 2-D, has no topology to get
//! wrong.

/// True when `o → a → b` turns left with `a` more than `eps` from the line `o b`.
#[inline]
fn convex_turn(o: [f64; 2], a: [f64; 2], b: [f64; 2], eps: f64) -> bool {
    let (ob0, ob1) = (b[0] - o[0], b[1] - o[1]);
    // Twice the signed area of (o, a, b): the distance of `a` from line `o b` times |ob|.
    let cross = (a[0] - o[0]) * ob1 - (a[1] - o[1]) * ob0;
    cross > 0.0 && cross * cross > eps * eps * (ob0 * ob0 + ob1 * ob1)
}

/// Writes into `out` the indices of the convex polygon of `pts`, counter-clockwise,
/// without repeating the first vertex; points within `eps` of the polygon's boundary may
/// be left out. `order` is scratch space.
///
/// Degenerate input gives a degenerate polygon of fewer than three vertices (coincident
/// or collinear points), or nothing for an empty set.
pub(crate) fn convex_polygon(pts: &[[f64; 2]], eps: f64, order: &mut Vec<u32>, out: &mut Vec<u32>) {
    out.clear();
    order.clear();
    order.extend(0..pts.len().min(u32::MAX as usize) as u32);
    let at = |i: u32| pts.get(i as usize).copied().unwrap_or([0.0; 2]);
    order.sort_unstable_by(|&i, &j| {
        let (a, b) = (at(i), at(j));
        a[0].total_cmp(&b[0])
            .then(a[1].total_cmp(&b[1]))
            .then(i.cmp(&j))
    });
    if order.len() < 2 {
        out.extend_from_slice(order);
        return;
    }
    // Lower chain left to right, then upper chain right to left.
    for &i in order.iter() {
        while let [.., o, a] = out[..] {
            if convex_turn(at(o), at(a), at(i), eps) {
                break;
            }
            out.pop();
        }
        out.push(i);
    }
    let lower = out.len() + 1;
    for &i in order.iter().rev().skip(1) {
        while out.len() >= lower {
            let [.., o, a] = out[..] else { break };
            if convex_turn(at(o), at(a), at(i), eps) {
                break;
            }
            out.pop();
        }
        out.push(i);
    }
    // The upper chain ends at the first point again.
    out.pop();
}
