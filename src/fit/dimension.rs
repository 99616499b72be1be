//! Intrinsic dimension of a point set (dissertation §3.3.5), and the simplex that proves it.
//!
//! The classification grows a simplex greedily: the farthest pair among the six
//! axis-extreme points, then the point farthest from their line, then the point farthest
//! from their plane. Each step compares the new extent with the set's diameter, so the
//! tolerance is relative and the test is invariant to scale. The same simplex seeds the
//! 3-D convex hull, which is why it is kept.

use crate::arr3::{cross, dot, norm2, normalize, sub, V3};

/// Extents below this fraction of the diameter count as zero when deciding dimension.
pub(crate) const DIMENSION_TOLERANCE: f64 = 1e-12;

/// A set whose diameter is below this fraction of its largest absolute coordinate is a
/// single point: differences that small are at the level of coordinate rounding.
pub(crate) const POINT_TOLERANCE: f64 = 64.0 * f64::EPSILON;

/// What [`classify`] found.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Shape {
    /// Intrinsic dimension, 0..=3.
    pub dim: u8,
    /// Length of the bounding-box diagonal (≥ the true diameter, ≤ √3 times it).
    pub diameter: f64,
    /// Indices of the simplex vertices; entries past `dim` repeat earlier ones.
    pub simplex: [usize; 4],
    /// Unit direction from `simplex[0]` to `simplex[1]` (meaningful when `dim ≥ 1`).
    pub direction: V3,
    /// Unit normal of the plane through `simplex[0..3]` (meaningful when `dim ≥ 2`).
    pub normal: V3,
    /// Largest distance of any point from that plane (meaningful when `dim ≥ 2`).
    pub thickness: f64,
}

impl Shape {
    fn point(diameter: f64) -> Shape {
        Shape {
            dim: 0,
            diameter,
            simplex: [0; 4],
            direction: [1.0, 0.0, 0.0],
            normal: [0.0, 0.0, 1.0],
            thickness: 0.0,
        }
    }
}

/// Classifies `points` (centred near the origin) by intrinsic dimension.
///
/// `magnitude` is the largest absolute coordinate of the points before centring; it sets
/// the floor below which the whole set is one point. Never panics; an empty or non-finite
/// set is reported as a point.
pub(crate) fn classify(points: &[V3], magnitude: f64) -> Shape {
    // Pass 1: bounding box and the points attaining it.
    let mut extremes = Extremes::new(points.first().copied().unwrap_or_default());
    for (i, &p) in points.iter().enumerate() {
        extremes.add(i, p);
    }
    classify_with(points, magnitude, &extremes, false)
}

/// The bounding box of a point set and, for each side, the first point on it (in order
/// of [`Extremes::add`]).
#[derive(Clone, Copy, Debug, Default)]
pub(crate) struct Extremes {
    lo: V3,
    hi: V3,
    /// Index of the first point attaining `lo[k]` (at `[k][0]`) and `hi[k]` (at `[k][1]`).
    ext: [[usize; 2]; 3],
}

impl Extremes {
    /// The indices of the six points attaining the bounding box (some may repeat).
    pub(crate) fn indices(&self) -> [usize; 6] {
        let [[a, b], [c, d], [e, f]] = self.ext;
        [a, b, c, d, e, f]
    }

    /// The extremes of the set `{first}` (point 0).
    pub(crate) fn new(first: V3) -> Extremes {
        Extremes {
            lo: first,
            hi: first,
            ext: [[0; 2]; 3],
        }
    }

    /// Takes point `i` into account; points must be added in index order.
    #[inline(always)]
    pub(crate) fn add(&mut self, i: usize, p: V3) {
        // One call per axis, spelled out: this runs once per point of every node.
        let [lx, ly, lz] = &mut self.lo;
        let [hx, hy, hz] = &mut self.hi;
        let [ex, ey, ez] = &mut self.ext;
        let [x, y, z] = p;
        extend(x, lx, hx, ex, i);
        extend(y, ly, hy, ey, i);
        extend(z, lz, hz, ez, i);
    }
}

/// One axis of [`Extremes::add`]: `x` of point `i` against the side values `lo`, `hi` and
/// the points `at` that first attained them.
#[inline(always)]
fn extend(x: f64, lo: &mut f64, hi: &mut f64, at: &mut [usize; 2], i: usize) {
    let [at_lo, at_hi] = at;
    if x < *lo {
        *lo = x;
        *at_lo = i;
    }
    if x > *hi {
        *hi = x;
        *at_hi = i;
    }
}

/// [`classify`], given the [`Extremes`] of `points` (added in order). With
/// `any_solid_point`, the last pass stops at the first point farther than the tolerance
/// from the plane: the dimension, line and plane are the same, but `thickness` and
/// `simplex[3]` are then those of that point rather than the farthest (only the convex
/// hull, which grows from the simplex, needs the farthest).
pub(crate) fn classify_with(
    points: &[V3],
    magnitude: f64,
    extremes: &Extremes,
    any_solid_point: bool,
) -> Shape {
    let Some(&first) = points.first() else {
        return Shape::point(0.0);
    };
    let Extremes { lo, hi, ext } = *extremes;
    let diameter = norm2(sub(hi, lo)).sqrt();
    if !diameter.is_finite() || diameter <= POINT_TOLERANCE * magnitude || diameter == 0.0 {
        return Shape::point(if diameter.is_finite() { diameter } else { 0.0 });
    }
    let at = |i: usize| points.get(i).copied().unwrap_or(first);

    // The farthest pair among the extremes spans the set well (it is within √3 of the
    // diameter), which keeps the line and plane below well conditioned.
    let (mut i0, mut i1, mut best) = (0usize, 0usize, -1.0);
    let ext = ext.as_flattened();
    for (a, &ea) in ext.iter().enumerate() {
        for &eb in ext.iter().skip(a + 1) {
            let d = norm2(sub(at(ea), at(eb)));
            if d > best {
                (i0, i1, best) = (ea, eb, d);
            }
        }
    }
    let p0 = at(i0);
    let Some(direction) = normalize(sub(at(i1), p0)) else {
        return Shape::point(diameter);
    };
    let tol = DIMENSION_TOLERANCE * diameter;

    // Pass 2: the point farthest from the line.
    let (mut i2, mut far2) = (i0, 0.0);
    for (i, &p) in points.iter().enumerate() {
        let d = norm2(cross(sub(p, p0), direction));
        if d > far2 {
            (i2, far2) = (i, d);
        }
    }
    let mut shape = Shape {
        dim: 1,
        diameter,
        simplex: [i0, i1, i1, i1],
        direction,
        normal: [0.0; 3],
        thickness: 0.0,
    };
    let normal = normalize(cross(direction, sub(at(i2), p0)));
    let (true, Some(normal)) = (far2 > tol * tol, normal) else {
        return shape;
    };

    // Pass 3: the point farthest from the plane.
    let (mut i3, mut far3) = (i2, 0.0);
    for (i, &p) in points.iter().enumerate() {
        let d = dot(sub(p, p0), normal).abs();
        if d > far3 {
            (i3, far3) = (i, d);
            if any_solid_point && d > tol {
                break;
            }
        }
    }
    shape.normal = normal;
    shape.thickness = far3;
    shape.simplex = [i0, i1, i2, i2];
    shape.dim = 2;
    if far3 > tol {
        shape.simplex[3] = i3;
        shape.dim = 3;
    }
    shape
}
