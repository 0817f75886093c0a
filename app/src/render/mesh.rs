//! What the renderer draws, as plain CPU data: the tree (branches and leaves, lit), the scene
//! occluder (depth-only), and line/point overlays. World space: metres, Y up.

use bytemuck::{Pod, Zeroable};
use glam::Vec3;

/// A vertex of a lit surface (branch or leaf).
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq, Pod, Zeroable)]
pub struct LitVertex {
    pub position: [f32; 3],
    pub normal: [f32; 3],
    /// Ambient (indirect) light at this vertex in [0, 1], from the growth shadow grid.
    pub ambient: f32,
    /// Leaf texture coordinates: x across the blade in [-0.5, 0.5], y from petiole (0) to tip (1).
    pub uv: [f32; 2],
}

/// Triangles of lit vertices.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct LitMesh {
    pub vertices: Vec<LitVertex>,
    pub indices: Vec<u32>,
}

impl LitMesh {
    pub fn is_empty(&self) -> bool {
        self.indices.is_empty()
    }

    /// Axis-aligned bounds, `None` when empty.
    pub fn bounds(&self) -> Option<(Vec3, Vec3)> {
        let mut it = self.vertices.iter().map(|v| Vec3::from(v.position));
        let first = it.next()?;
        Some(it.fold((first, first), |(lo, hi), p| (lo.min(p), hi.max(p))))
    }

    /// Appends another mesh.
    pub fn append(&mut self, other: &LitMesh) {
        let base = self.vertices.len() as u32;
        self.vertices.extend_from_slice(&other.vertices);
        self.indices.extend(other.indices.iter().map(|i| i + base));
    }
}

/// The tree as drawn: bark and leaves, and their linear RGB (the species' look in its season).
#[derive(Clone, Debug, PartialEq)]
pub struct TreeMesh {
    pub branches: LitMesh,
    pub leaves: LitMesh,
    pub bark_color: [f32; 3],
    pub leaf_color: [f32; 3],
}

impl Default for TreeMesh {
    /// No geometry, in the renderer's former fixed bark and leaf colours.
    fn default() -> Self {
        TreeMesh {
            branches: LitMesh::default(),
            leaves: LitMesh::default(),
            bark_color: [0.30, 0.21, 0.14],
            leaf_color: [0.16, 0.38, 0.09],
        }
    }
}

impl TreeMesh {
    /// Bounds of branches and leaves together.
    pub fn bounds(&self) -> Option<(Vec3, Vec3)> {
        match (self.branches.bounds(), self.leaves.bounds()) {
            (Some(a), Some(b)) => Some((a.0.min(b.0), a.1.max(b.1))),
            (a, b) => a.or(b),
        }
    }

    pub fn num_triangles(&self) -> usize {
        (self.branches.indices.len() + self.leaves.indices.len()) / 3
    }
}

/// The real scene as a triangle mesh in world space (the depth mesh): drawn into depth only.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct OccluderMesh {
    pub positions: Vec<Vec3>,
    pub indices: Vec<u32>,
}

impl OccluderMesh {
    /// Edges of every triangle as a line list (each shared edge once per triangle).
    pub fn wireframe(&self) -> Vec<[f32; 3]> {
        let mut lines = Vec::with_capacity(self.indices.len() * 2);
        for tri in self.indices.chunks_exact(3) {
            for (a, b) in [(0, 1), (1, 2), (2, 0)] {
                let (Some(pa), Some(pb)) = (
                    self.positions.get(tri[a] as usize),
                    self.positions.get(tri[b] as usize),
                ) else {
                    continue;
                };
                lines.push(pa.to_array());
                lines.push(pb.to_array());
            }
        }
        lines
    }

    /// An axis-aligned box (used for synthetic scenes: walls, fences, cabinets).
    pub fn add_box(&mut self, min: Vec3, max: Vec3) {
        let base = self.positions.len() as u32;
        for i in 0..8u32 {
            self.positions.push(Vec3::new(
                if i & 1 == 0 { min.x } else { max.x },
                if i & 2 == 0 { min.y } else { max.y },
                if i & 4 == 0 { min.z } else { max.z },
            ));
        }
        const FACES: [[u32; 4]; 6] = [
            [0, 2, 6, 4],
            [1, 5, 7, 3],
            [0, 4, 5, 1],
            [2, 3, 7, 6],
            [0, 1, 3, 2],
            [4, 6, 7, 5],
        ];
        for f in FACES {
            self.indices
                .extend([f[0], f[1], f[2], f[0], f[2], f[3]].map(|i| base + i));
        }
    }
}

/// The fitted ground plane, world space.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct GroundPlane {
    pub point: Vec3,
    /// Unit normal pointing up, out of the ground.
    pub normal: Vec3,
}

impl Default for GroundPlane {
    fn default() -> Self {
        GroundPlane {
            point: Vec3::ZERO,
            normal: Vec3::Y,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_box_has_twelve_triangles_and_a_wireframe_of_their_edges() {
        let mut m = OccluderMesh::default();
        m.add_box(Vec3::ZERO, Vec3::ONE);
        assert_eq!(m.indices.len(), 36);
        assert_eq!(m.wireframe().len(), 72);
    }

    #[test]
    fn appended_meshes_keep_their_triangles() {
        let v = LitVertex::default();
        let mut a = LitMesh {
            vertices: vec![v; 3],
            indices: vec![0, 1, 2],
        };
        let b = a.clone();
        a.append(&b);
        assert_eq!(a.indices, vec![0, 1, 2, 3, 4, 5]);
    }
}
