//! Meshes generated in code, shared by the integration tests.
#![allow(dead_code)]

use obbtree::mesh::TriMesh;

/// A latitude/longitude sphere of `2 * slices * (stacks - 1)` triangles, like the spheres of
/// the dissertation's §5.3.1 scene.
pub fn uv_sphere(radius: f64, stacks: u32, slices: u32) -> TriMesh {
    let mut vertices = vec![[0.0, 0.0, radius]];
    for i in 1..stacks {
        let theta = std::f64::consts::PI * f64::from(i) / f64::from(stacks);
        for j in 0..slices {
            let phi = 2.0 * std::f64::consts::PI * f64::from(j) / f64::from(slices);
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
    TriMesh::new(vertices, faces).expect("valid sphere")
}

/// The axis-aligned cube `[-h, h]^3`, 12 triangles.
pub fn cube(h: f64) -> TriMesh {
    let v: Vec<[f64; 3]> = (0..8)
        .map(|i| {
            [
                if i & 1 == 0 { -h } else { h },
                if i & 2 == 0 { -h } else { h },
                if i & 4 == 0 { -h } else { h },
            ]
        })
        .collect();
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
    TriMesh::new(v, faces).expect("valid cube")
}

/// A flat `n x n` grid of unit squares in the plane z = 0, `2 n^2` triangles.
pub fn grid(n: u32) -> TriMesh {
    let mut vertices = Vec::new();
    for y in 0..=n {
        for x in 0..=n {
            vertices.push([f64::from(x), f64::from(y), 0.0]);
        }
    }
    let id = |x: u32, y: u32| y * (n + 1) + x;
    let mut faces = Vec::new();
    for y in 0..n {
        for x in 0..n {
            faces.push([id(x, y), id(x + 1, y), id(x + 1, y + 1)]);
            faces.push([id(x, y), id(x + 1, y + 1), id(x, y + 1)]);
        }
    }
    TriMesh::new(vertices, faces).expect("valid grid")
}

/// The bundled cow (5,804 triangles), loaded from `assets/`.
#[cfg(any())]
pub fn cow() -> TriMesh {
    TriMesh::load(std::path::Path::new(concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/assets/cow.obj"
    )))
    .expect("assets/cow.obj loads")
}
