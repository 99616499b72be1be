//! Reading fuzz input as small geometry: meshes on a grid, poses, build options. Shared by
//! the differential targets (`differential.rs`, `scene.rs`); past the end of the input every
//! byte reads as 0, so every input means something.

// The indexing is into constant arrays, modulo their length.
#![allow(clippy::indexing_slicing)]

use nalgebra::{Rotation3, Vector3};
use obbtree::build::BuildOptions;
use obbtree::bv::{BvKind, Layout};
use obbtree::fit::FitMethod;
use obbtree::mesh::TriMesh;
use obbtree::query::Pose;
use obbtree::real::Precision;

/// Reads the input a byte at a time; past the end, zeros.
pub struct Bytes<'a> {
    data: &'a [u8],
    at: usize,
}

impl<'a> Bytes<'a> {
    /// Reads `data` from its start.
    pub fn new(data: &'a [u8]) -> Bytes<'a> {
        Bytes { data, at: 0 }
    }

    /// The next byte.
    pub fn byte(&mut self) -> u8 {
        let b = self.data.get(self.at).copied().unwrap_or(0);
        self.at += 1;
        b
    }

    /// A coordinate on the grid of eighths in [-16, 16).
    pub fn coordinate(&mut self) -> f64 {
        f64::from(self.byte() as i8) / 8.0
    }

    /// A point on the grid of eighths.
    pub fn point(&mut self) -> [f64; 3] {
        [self.coordinate(), self.coordinate(), self.coordinate()]
    }

    /// A model of up to 12 vertices and 24 triangles (repeated corners allowed).
    pub fn mesh(&mut self) -> Option<TriMesh> {
        let vertices: Vec<[f64; 3]> = (0..3 + self.byte() % 10).map(|_| self.point()).collect();
        let n = vertices.len() as u8;
        let faces = (0..1 + self.byte() % 24)
            .map(|_| [0; 3].map(|_: u32| u32::from(self.byte() % n)))
            .collect();
        TriMesh::new(vertices, faces).ok()
    }

    /// A rotation by Euler angles in steps of π/32 (0: the identity, exactly) and a
    /// translation on the grid.
    pub fn pose(&mut self) -> Pose {
        let step = std::f64::consts::PI / 32.0;
        let mut angle = || f64::from(self.byte() % 64) * step;
        let r = Rotation3::from_euler_angles(angle(), angle(), angle());
        let t = Vector3::from(self.point()) / 2.0;
        Pose::new(r.into_inner(), t).unwrap_or_default()
    }

    /// Build options: any volume type, precision, layout, fit and leaf size.
    pub fn options(&mut self) -> BuildOptions {
        let (x, y) = (usize::from(self.byte()), usize::from(self.byte()));
        let bv = [BvKind::Obb, BvKind::Aabb, BvKind::Sphere][x % 3];
        let precision = [Precision::F32, Precision::F64][(x / 3) % 2];
        BuildOptions {
            bv,
            precision,
            // The compact layout exists for f32 boxes only.
            layout: if (bv, precision) == (BvKind::Obb, Precision::F32) && (x / 6) % 2 == 1 {
                Layout::Compact
            } else {
                Layout::Fast
            },
            fit: [FitMethod::Hull, FitMethod::Triangles, FitMethod::Vertices][(x / 12) % 3],
            leaf_size: [1, 2, 3, 8][y % 4],
            // Small meshes: the hull fit would never run with the default threshold.
            hull_min_faces: 1,
            ..BuildOptions::default()
        }
    }
}
