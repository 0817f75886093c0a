//! Export for rendering: a depth-only occlusion pass and a debug wireframe.

use std::collections::HashMap;

use glam::{Affine3A, Vec3};
use spade::Triangulation;

use super::DepthMesh;
use super::query::classify_triangle;

/// Triangles of the known surface plus wireframe line lists.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct OcclusionMesh {
    /// Vertex positions (camera space, or world space after [`Self::to_world`]).
    pub positions: Vec<Vec3>,
    /// Triangle list over `positions`: only triangles that may occlude.
    pub indices: Vec<u32>,
    /// Line list (pairs of indices) of the edges of known triangles.
    pub wireframe: Vec<u32>,
    /// Line list of the edges of unknown triangles (debug view).
    pub unknown_wireframe: Vec<u32>,
}

impl OcclusionMesh {
    /// The same mesh with positions mapped into the world.
    pub fn to_world(&self, world_from_camera: &Affine3A) -> Self {
        Self {
            positions: self
                .positions
                .iter()
                .map(|&p| world_from_camera.transform_point3(p))
                .collect(),
            ..self.clone()
        }
    }
}

impl DepthMesh {
    /// The surface in camera space (metres): known triangles for a depth-only pass, and
    /// wireframes of known and unknown triangles.
    pub fn export_camera_space(&self) -> OcclusionMesh {
        let triangles = &self.surface.triangles;
        let mut index_of = HashMap::with_capacity(triangles.num_vertices());
        let mut mesh = OcclusionMesh::default();
        for vertex in triangles.vertices() {
            let data = vertex.data();
            index_of.insert(vertex.fix(), mesh.positions.len() as u32);
            mesh.positions
                .push(self.camera.camera_from_pixel(data.pixel, data.depth_m));
        }
        let c = &self.config;
        for face in triangles.inner_faces() {
            let handles = face.vertices();
            let vertices = handles.map(|v| *v.data());
            let ids = handles.map(|v| index_of[&v.fix()]);
            let known = classify_triangle(
                &vertices,
                &self.camera,
                c.max_edge_px,
                c.min_plane_distance_m,
                c.min_discontinuity_ratio,
            )
            .is_ok();
            let lines = if known {
                &mut mesh.wireframe
            } else {
                &mut mesh.unknown_wireframe
            };
            for i in 0..3 {
                lines.extend([ids[i], ids[(i + 1) % 3]]);
            }
            if known {
                // Camera space has Y down: (a, b, c) counter-clockwise on screen stays so.
                mesh.indices.extend(ids);
            }
        }
        mesh
    }
}
