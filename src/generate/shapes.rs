//! The test shapes of the dissertation's experiments (§5.3): latitude/longitude spheres,
//! tessellated plates, and boxes.

use super::GenerateError;
use crate::mesh::TriMesh;
use std::f64::consts::{PI, TAU};

/// A latitude/longitude sphere of `radius` about the origin: `stacks` bands from pole to
/// pole (at least 2) of `slices` sectors (at least 3), a fan of triangles at each pole and
/// two triangles per cell between, `2 · slices · (stacks − 1)` triangles in all, wound
/// outward. The poles lie on the z axis. §5.3.1's spheres of 40,000 triangles are 101
/// stacks of 200 slices.
///
/// # Errors
///
/// [`GenerateError::Parameter`] for a radius that is not finite and greater than 0,
/// [`GenerateError::Count`] for fewer than 2 stacks or 3 slices, and
/// [`GenerateError::TooManyTriangles`] beyond [`MAX_GENERATED_TRIANGLES`].
///
/// # Examples
///
/// See the [module example](super).
pub fn lat_long_sphere(radius: f64, stacks: u32, slices: u32) -> Result<TriMesh, GenerateError> {
    positive("radius", radius)?;
    at_least("stacks", stacks, 2)?;
    at_least("slices", slices, 3)?;
    triangle_count(pairs(slices, stacks - 1))?;
    let mut vertices = vec![[0.0, 0.0, radius]];
    for i in 1..stacks {
        let theta = PI * f64::from(i) / f64::from(stacks);
        for j in 0..slices {
            let phi = TAU * f64::from(j) / f64::from(slices);
            vertices.push([
                radius * theta.sin() * phi.cos(),
                radius * theta.sin() * phi.sin(),
                radius * theta.cos(),
            ]);
        }
    }
    vertices.push([0.0, 0.0, -radius]);
    let south = vertices.len() as u32 - 1;
    let ring = |i: u32, j: u32| 1 + (i - 1) * slices + (j % slices);
    let mut faces = Vec::new();
    for j in 0..slices {
        faces.push([0, ring(1, j), ring(1, j + 1)]);
    }
    for i in 1..stacks - 1 {
        for j in 0..slices {
            faces.push([ring(i, j), ring(i + 1, j), ring(i + 1, j + 1)]);
            faces.push([ring(i, j), ring(i + 1, j + 1), ring(i, j + 1)]);
        }
    }
    for j in 0..slices {
        faces.push([ring(stacks - 1, j), south, ring(stacks - 1, j + 1)]);
    }
    Ok(TriMesh::new(vertices, faces)?)
}

/// A flat plate in the z = 0 plane, `size[0]` by `size[1]` and centred on the origin, cut
/// into `cells[0]` by `cells[1]` squares of two triangles each (normals along +z).
///
/// # Errors
///
/// [`GenerateError::Parameter`] for a size that is not finite and greater than 0,
/// [`GenerateError::Count`] for no cells along an axis, and
/// [`GenerateError::TooManyTriangles`] beyond [`MAX_GENERATED_TRIANGLES`].
///
/// # Examples
///
/// ```
/// let plate = obbtree::generate::plate([2.0, 1.0], [4, 2])?;
/// assert_eq!(plate.faces().len(), 16);
/// # Ok::<(), obbtree::generate::GenerateError>(())
/// ```
pub fn plate(size: [f64; 2], cells: [u32; 2]) -> Result<TriMesh, GenerateError> {
    positive("width", size[0])?;
    positive("height", size[1])?;
    at_least("cells along x", cells[0], 1)?;
    at_least("cells along y", cells[1], 1)?;
    let [nx, ny] = cells;
    triangle_count(pairs(nx, ny))?;
    // Cell `k` of `n` starts at (k − n/2) cells from the centre: exact for whole-number
    // cell sizes, so a plate of n cells of size 1 has integer and half-integer corners.
    let coordinate =
        |k: u32, n: u32, size: f64| (f64::from(k) - f64::from(n) / 2.0) * (size / f64::from(n));
    let mut vertices = Vec::new();
    for y in 0..=ny {
        for x in 0..=nx {
            vertices.push([coordinate(x, nx, size[0]), coordinate(y, ny, size[1]), 0.0]);
        }
    }
    let id = |x: u32, y: u32| y * (nx + 1) + x;
    let mut faces = Vec::new();
    for y in 0..ny {
        for x in 0..nx {
            faces.push([id(x, y), id(x + 1, y), id(x + 1, y + 1)]);
            faces.push([id(x, y), id(x + 1, y + 1), id(x, y + 1)]);
        }
    }
    Ok(TriMesh::new(vertices, faces)?)
}

/// The axis-aligned box with half-widths `half` (each at least 0) centred at `center`: 8
/// corners, 12 triangles wound outward. Corner `i` has the upper coordinate on axis `k`
/// when bit `k` of `i` is set.
///
/// # Errors
///
/// [`GenerateError::Parameter`] for a half-width that is not finite and at least 0, or a
/// centre coordinate that is not finite (or whose corners would not be).
///
/// # Examples
///
/// ```
/// let cube = obbtree::generate::cuboid([0.5; 3], [0.0, 0.0, 1.0])?;
/// assert_eq!((cube.vertices().len(), cube.faces().len()), (8, 12));
/// assert_eq!(cube.vertices()[7], [0.5, 0.5, 1.5]);
/// # Ok::<(), obbtree::generate::GenerateError>(())
/// ```
pub fn cuboid(half: [f64; 3], center: [f64; 3]) -> Result<TriMesh, GenerateError> {
    for (name, h) in ["half-width x", "half-width y", "half-width z"]
        .into_iter()
        .zip(half)
    {
        if !(h.is_finite() && h >= 0.0) {
            return Err(GenerateError::Parameter {
                name,
                value: h,
                expected: "finite and at least 0",
            });
        }
    }
    for (name, (c, h)) in ["centre x", "centre y", "centre z"]
        .into_iter()
        .zip(center.into_iter().zip(half))
    {
        // Both faces of the box must be finite too.
        if !(c.is_finite() && (c - h).is_finite() && (c + h).is_finite()) {
            return Err(GenerateError::Parameter {
                name,
                value: c,
                expected: "finite, with the box's faces finite too",
            });
        }
    }
    let corners: Vec<[f64; 3]> = (0..8u32)
        .map(|i| {
            let mut p = center;
            for (k, (c, h)) in p.iter_mut().zip(half).enumerate() {
                *c += if i & (1 << k) == 0 { -h } else { h };
            }
            p
        })
        .collect();
    // Two triangles per side: z = lo, z = hi, y = lo, y = hi, x = lo, x = hi.
    let faces = vec![
        [0, 2, 1],
        [1, 2, 3],
        [4, 5, 6],
        [5, 7, 6],
        [0, 1, 4],
        [1, 5, 4],
        [2, 6, 3],
        [3, 6, 7],
        [0, 4, 2],
        [2, 4, 6],
        [1, 3, 5],
        [3, 7, 5],
    ];
    Ok(TriMesh::new(corners, faces)?)
}

fn positive(name: &'static str, value: f64) -> Result<(), GenerateError> {
    if value.is_finite() && value > 0.0 {
        Ok(())
    } else {
        Err(GenerateError::Parameter {
            name,
            value,
            expected: "finite and greater than 0",
        })
    }
}

fn at_least(name: &'static str, count: u32, least: u32) -> Result<(), GenerateError> {
    if count >= least {
        Ok(())
    } else {
        Err(GenerateError::Count { name, count, least })
    }
}

/// The most triangles a generated shape has: 2^24, an OBJ of about 1.5 GB, held in memory
/// while it is written (the loaders' cap, 2^28, would take some 25 GB).
pub const MAX_GENERATED_TRIANGLES: u64 = 1 << 24;

/// Two triangles for each of `a × b` quads, saturating: with both near `u32::MAX` the count
/// does not fit in a `u64`, and a wrapped one could pass the limit.
fn pairs(a: u32, b: u32) -> u64 {
    u64::from(a).saturating_mul(u64::from(b)).saturating_mul(2)
}

fn triangle_count(count: u64) -> Result<(), GenerateError> {
    if count <= MAX_GENERATED_TRIANGLES {
        Ok(())
    } else {
        Err(GenerateError::TooManyTriangles { count })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Twice the signed volume enclosed by a closed mesh, by the divergence theorem:
    /// positive when every face is wound outward.
    fn six_volume(mesh: &TriMesh) -> f64 {
        let v = mesh.vertices();
        mesh.faces()
            .iter()
            .map(|f| {
                let [a, b, c] = f.map(|i| nalgebra::Vector3::from(v[i as usize]));
                a.dot(&b.cross(&c))
            })
            .sum()
    }

    #[test]
    fn the_dissertation_sphere_has_40000_triangles_on_its_radius_wound_outward() {
        let s = lat_long_sphere(1.0, 101, 200).unwrap();
        assert_eq!(s.faces().len(), 40_000);
        assert!(s.vertices().iter().all(|p| {
            let r = nalgebra::Vector3::from(*p).norm();
            (r - 1.0).abs() < 1e-15
        }));
        // Inscribed polyhedron: just under the ball's 4π/3, positive (outward).
        let volume = six_volume(&s) / 6.0;
        assert!(volume > 4.15 && volume < 4.0 * PI / 3.0, "{volume}");
        assert_eq!(s.degenerate_triangle_count(), 0);
    }

    #[test]
    fn a_box_encloses_its_volume_outward_and_a_plate_covers_its_area() {
        let b = cuboid([1.0, 2.0, 3.0], [5.0, -1.0, 0.5]).unwrap();
        assert!((six_volume(&b) / 6.0 - 48.0).abs() < 1e-12);
        let p = plate([4.0, 2.0], [8, 3]).unwrap();
        assert_eq!(p.faces().len(), 48);
        let v = p.vertices();
        let area: f64 = p
            .faces()
            .iter()
            .map(|f| {
                let [a, b, c] = f.map(|i| nalgebra::Vector3::from(v[i as usize]));
                // Counter-clockwise seen from +z: positive z of the cross product.
                (b - a).cross(&(c - a)).z / 2.0
            })
            .sum();
        assert!((area - 8.0).abs() < 1e-12);
        assert_eq!(v.first(), Some(&[-2.0, -1.0, 0.0]));
        assert_eq!(v.last(), Some(&[2.0, 1.0, 0.0]));
    }

    #[test]
    fn shapes_refuse_parameters_they_cannot_make() {
        assert!(lat_long_sphere(0.0, 10, 10).is_err());
        assert!(lat_long_sphere(f64::NAN, 10, 10).is_err());
        assert!(lat_long_sphere(1.0, 1, 10).is_err());
        assert!(lat_long_sphere(1.0, 10, 2).is_err());
        assert!(matches!(
            lat_long_sphere(1.0, u32::MAX, u32::MAX),
            Err(GenerateError::TooManyTriangles { .. })
        ));
        assert!(plate([1.0, -1.0], [2, 2]).is_err());
        assert!(plate([1.0, 1.0], [0, 2]).is_err());
        assert!(cuboid([1.0, f64::INFINITY, 1.0], [0.0; 3]).is_err());
        assert!(cuboid([1.0; 3], [f64::NAN, 0.0, 0.0]).is_err());
        assert!(cuboid([1e308, 1.0, 1.0], [1e308, 0.0, 0.0]).is_err());
        assert!(matches!(
            plate([1.0, 1.0], [5000, 5000]),
            Err(GenerateError::TooManyTriangles { .. })
        ));
        assert!(matches!(
            plate([1.0, 1.0], [u32::MAX, u32::MAX]),
            Err(GenerateError::TooManyTriangles { count: u64::MAX })
        ));
    }
}
