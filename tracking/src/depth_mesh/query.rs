//! Queries: depth at a pixel (barycentric in inverse depth) and occlusion of world points.

use glam::{Affine3A, Vec2, Vec3};
use std::sync::atomic::Ordering;

use spade::handles::{FixedFaceHandle, FixedVertexHandle, InnerTag};
use spade::{PositionInTriangulation, Triangulation};

use super::mesh::MeshVertex;
use super::{DepthMesh, PinholeIntrinsics};

/// Most faces a query walk crosses before handing over to spade's point location (a walk
/// from the hint grid usually crosses a few).
const MAX_WALK_STEPS: usize = 256;

/// A query walk starts from the last face found when that is this close (pixels).
const LAST_FACE_REACH_PX: f32 = 12.0;

/// Outcome of a query walk.
enum Walk {
    Found(FixedFaceHandle<InnerTag>),
    OutsideHull,
    GaveUp,
}

/// Why the mesh has no depth at a pixel.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum UnknownReason {
    /// Outside the image or behind the camera.
    OutsideImage,
    /// Outside the triangulated points (sky, an area with no tracked points).
    NoTriangle,
    /// The triangle has an edge longer than `max_edge_px`.
    LongEdge,
    /// The triangle spans a depth discontinuity (seen edge-on in 3D).
    Discontinuity,
}

/// The scene depth at a pixel.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum DepthSample {
    Known { depth_m: f32 },
    Unknown(UnknownReason),
}

impl DepthSample {
    pub fn depth_m(self) -> Option<f32> {
        match self {
            DepthSample::Known { depth_m } => Some(depth_m),
            DepthSample::Unknown(_) => None,
        }
    }
}

/// Whether a triangle may occlude, from its vertices.
pub(crate) fn classify_triangle(
    vertices: &[MeshVertex; 3],
    camera: &PinholeIntrinsics,
    max_edge_px: f32,
    min_plane_distance_m: f32,
    min_discontinuity_ratio: f32,
) -> Result<(), UnknownReason> {
    let max_edge2 = max_edge_px * max_edge_px;
    for i in 0..3 {
        if vertices[i]
            .pixel
            .distance_squared(vertices[(i + 1) % 3].pixel)
            > max_edge2
        {
            return Err(UnknownReason::LongEdge);
        }
    }
    let depths = vertices.map(|v| v.depth_m);
    let (near, far) = (
        depths.iter().copied().fold(f32::MAX, f32::min),
        depths.iter().copied().fold(0.0, f32::max),
    );
    if far <= near * (1.0 + min_discontinuity_ratio) {
        return Ok(());
    }
    let points = vertices.map(|v| camera.camera_from_pixel(v.pixel, v.depth_m));
    let normal = (points[1] - points[0]).cross(points[2] - points[0]);
    match normal.try_normalize() {
        Some(n) if n.dot(points[0]).abs() >= min_plane_distance_m => Ok(()),
        _ => Err(UnknownReason::Discontinuity),
    }
}

impl DepthMesh {
    fn face_vertices(&self, face: FixedFaceHandle<InnerTag>) -> [MeshVertex; 3] {
        self.surface
            .triangles
            .face(face)
            .vertices()
            .map(|v| *v.data())
    }

    /// A triangle containing `pixel`, if any: a walk from a face next to the hint grid's
    /// vertex, or spade's exact point location where the walk gives up.
    fn containing_face(&self, pixel: Vec2) -> Option<FixedFaceHandle<InnerTag>> {
        match self.walk_to_face(pixel) {
            Walk::Found(face) => Some(face),
            Walk::OutsideHull => None,
            Walk::GaveUp => self.locate_face(pixel),
        }
    }

    /// Visibility walk: from a face near `pixel`, cross an edge that has `pixel` strictly on
    /// its outer side until no edge does. On a Delaunay triangulation it ends; leaving the
    /// convex hull means no triangle holds the pixel. Floating-point orientation suffices
    /// here: a pixel within round-off of an edge belongs to either face, and a walk that
    /// round-off sends in circles gives up after a bounded number of steps.
    fn walk_to_face(&self, pixel: Vec2) -> Walk {
        let triangles = &self.surface.triangles;
        if triangles.num_inner_faces() == 0 {
            return Walk::OutsideHull;
        }
        let Some(start) = self.walk_start(pixel) else {
            return Walk::GaveUp;
        };
        let Some(mut face) = triangles
            .vertex(start)
            .out_edges()
            .find_map(|edge| edge.face().as_inner())
        else {
            return Walk::GaveUp;
        };
        let (px, py) = (pixel.x as f64, pixel.y as f64);
        for _ in 0..MAX_WALK_STEPS {
            let exit = face.adjacent_edges().into_iter().find(|edge| {
                let [a, b] = edge.positions();
                (b.x - a.x) * (py - a.y) - (b.y - a.y) * (px - a.x) < 0.0
            });
            let Some(exit) = exit else {
                let corner = face.vertices()[0].fix().index();
                self.last_query_vertex.store(corner, Ordering::Relaxed);
                return Walk::Found(face.fix());
            };
            match exit.rev().face().as_inner() {
                Some(next) => face = next,
                None => return Walk::OutsideHull,
            }
        }
        Walk::GaveUp
    }

    /// Where a query walk starts: a corner of the last face found when it is near `pixel`
    /// (queries in scan order), else the hint grid's vertex.
    fn walk_start(&self, pixel: Vec2) -> Option<FixedVertexHandle> {
        let last = self.last_query_vertex.load(Ordering::Relaxed);
        if last < self.surface.triangles.num_vertices() {
            let handle = FixedVertexHandle::from_index(last);
            let corner = self.surface.triangles.vertex(handle).data().pixel;
            if corner.distance_squared(pixel) <= LAST_FACE_REACH_PX * LAST_FACE_REACH_PX {
                return Some(handle);
            }
        }
        self.surface.hint(pixel)
    }

    /// Spade's exact point location (the fallback of [`Self::walk_to_face`]).
    fn locate_face(&self, pixel: Vec2) -> Option<FixedFaceHandle<InnerTag>> {
        let triangles = &self.surface.triangles;
        match self.surface.locate(pixel, None) {
            PositionInTriangulation::OnFace(face) => Some(face),
            PositionInTriangulation::OnEdge(edge) => {
                let edge = triangles.directed_edge(edge);
                edge.face()
                    .as_inner()
                    .or_else(|| edge.rev().face().as_inner())
                    .map(|f| f.fix())
            }
            PositionInTriangulation::OnVertex(vertex) => triangles
                .vertex(vertex)
                .out_edges()
                .find_map(|edge| edge.face().as_inner())
                .map(|f| f.fix()),
            PositionInTriangulation::OutsideOfConvexHull(_)
            | PositionInTriangulation::NoTriangulation => None,
        }
    }

    /// Scene depth (camera Z, m) at `pixel`: inverse depth interpolated barycentrically, exact
    /// for planar surfaces.
    pub fn depth_at(&self, pixel: Vec2) -> DepthSample {
        if !(pixel.is_finite() && self.camera.contains(pixel)) {
            return DepthSample::Unknown(UnknownReason::OutsideImage);
        }
        let Some(face) = self.containing_face(pixel) else {
            return DepthSample::Unknown(UnknownReason::NoTriangle);
        };
        let vertices = self.face_vertices(face);
        let c = &self.config;
        if let Err(reason) = classify_triangle(
            &vertices,
            &self.camera,
            c.max_edge_px,
            c.min_plane_distance_m,
            c.min_discontinuity_ratio,
        ) {
            return DepthSample::Unknown(reason);
        }
        let [a, b, cc] = vertices.map(|v| Vec2::new(v.pixel.x, v.pixel.y));
        let area2 = (b - a).perp_dot(cc - a);
        if area2.abs() < 1e-9 {
            return DepthSample::Unknown(UnknownReason::NoTriangle);
        }
        let beta = (pixel - a).perp_dot(cc - a) / area2;
        let gamma = (b - a).perp_dot(pixel - a) / area2;
        let alpha = 1.0 - beta - gamma;
        let inverse_depth =
            alpha / vertices[0].depth_m + beta / vertices[1].depth_m + gamma / vertices[2].depth_m;
        if inverse_depth > 0.0 {
            DepthSample::Known {
                depth_m: 1.0 / inverse_depth,
            }
        } else {
            DepthSample::Unknown(UnknownReason::NoTriangle)
        }
    }

    /// Whether `point_in_world` lies behind the scene surface seen from this mesh's camera
    /// at `world_from_camera`, by more than `margin_m`. Unknown surface never hides anything.
    pub fn is_hidden(
        &self,
        point_in_world: Vec3,
        world_from_camera: &Affine3A,
        margin_m: f32,
    ) -> bool {
        let point_in_camera = world_from_camera.inverse().transform_point3(point_in_world);
        self.is_hidden_in_camera(point_in_camera, margin_m)
    }

    /// [`Self::is_hidden`] for a point already in camera space.
    pub fn is_hidden_in_camera(&self, point_in_camera: Vec3, margin_m: f32) -> bool {
        let Some(pixel) = self.camera.pixel_from_camera(point_in_camera) else {
            return false;
        };
        match self.depth_at(pixel) {
            DepthSample::Known { depth_m } => point_in_camera.z > depth_m + margin_m,
            DepthSample::Unknown(_) => false,
        }
    }
}
