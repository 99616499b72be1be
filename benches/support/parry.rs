//! Conversions from obbtree's meshes and poses to parry3d's (f32), shared by the benchmarks
//! that compare with parry3d 0.31.

use obbtree::mesh::TriMesh;
use obbtree::query::Pose;
use parry3d::math::{Pose as PPose, Vector as PVector};

/// The mesh as a parry3d triangle mesh (coordinates rounded to f32).
pub fn parry_mesh(mesh: &TriMesh) -> parry3d::shape::TriMesh {
    let v = mesh
        .vertices()
        .iter()
        .map(|p| PVector::new(p[0] as f32, p[1] as f32, p[2] as f32))
        .collect();
    parry3d::shape::TriMesh::new(v, mesh.faces().to_vec()).expect("parry accepts the mesh")
}

/// The pose as a parry3d pose (rounded to f32).
pub fn parry_pose(p: &Pose) -> PPose {
    let r = p.rotation();
    let m = glam::Mat3::from_cols_array(&[
        r[(0, 0)] as f32,
        r[(1, 0)] as f32,
        r[(2, 0)] as f32,
        r[(0, 1)] as f32,
        r[(1, 1)] as f32,
        r[(2, 1)] as f32,
        r[(0, 2)] as f32,
        r[(1, 2)] as f32,
        r[(2, 2)] as f32,
    ]);
    let t = p.translation_vector();
    PPose::from_parts(
        PVector::new(t.x as f32, t.y as f32, t.z as f32),
        glam::Quat::from_mat3(&m),
    )
}
