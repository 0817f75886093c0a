//! Scene depth mesh: an incremental 2D Delaunay triangulation (spade) of the visible tracked
//! points in image space, each vertex carrying its depth and map-point id.
//!
//! Used for occlusion (a virtual tree behind a real fence disappears), for pruning a tree to
//! the scene and for growing in front of it (Longay 2014, §5.4.1 and §5.4.3; TreeSketch
//! triangulated the feature points in screen space every frame). Here the triangulation is
//! updated incrementally: newly visible points are inserted, lost ones removed, tracked ones
//! moved; nothing is rebuilt per frame.
//!
//! **Two layers.** Every valid observation goes into the *all* triangulation; a vertex whose
//! inverse depth is predicted by no triangle of its neighbours (a wrong triangulation, a
//! mismatched track) is kept out of the *surface* triangulation, which answers queries.
//!
//! **Unknown.** A surface triangle does not occlude when an edge is longer than
//! [`DepthMeshConfig::max_edge_px`], when it spans a depth discontinuity (in 3D it is seen
//! almost edge-on: a silhouette or a thin structure), or where there is no triangle (outside
//! the points' hull, e.g. sky). Unknown never counts as near. Edge-on is measured by the
//! distance of the triangle's plane from the camera centre: grazing ground far away still lies
//! a camera height from it, while a triangle bridging a pole and the wall behind it passes
//! within centimetres.
//!
//! **Solids on the ground.** [`GroundSolids`] keeps every tracked point in the world over the
//! frames and raises the groups of points above the ground into prisms standing on it, carved
//! by the free space seen along the rays to the other points: the faces of plain objects, where
//! one frame tracks too few points, still occlude.
//!
//! **Spaces.** Pixels: the tracker's undistorted pixel coordinates (`u` right, `v` down).
//! Camera space: OpenCV (X right, Y down, Z forward), metres;
//! depth is camera Z. `world_from_camera` maps camera space into the world (metres, Y up).

mod consistency;
mod export;
mod ground_solids;
mod layer;
mod mesh;
mod plan;
mod query;
mod validity;

#[cfg(test)]
mod proptests;
#[cfg(test)]
mod tests;

pub use export::OcclusionMesh;
pub use ground_solids::{GroundSolid, GroundSolids, GroundSolidsConfig};
pub use mesh::{DepthMesh, MeshVertex, UpdateStats};
pub use query::{DepthSample, UnknownReason};

use glam::{Vec2, Vec3};

/// Pinhole intrinsics of undistorted pixel coordinates (the tracker undistorts points).
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct PinholeIntrinsics {
    pub width: u32,
    pub height: u32,
    pub fx: f32,
    pub fy: f32,
    pub cx: f32,
    pub cy: f32,
}

impl PinholeIntrinsics {
    /// Pixel of a camera-space point, `None` behind the camera.
    pub fn pixel_from_camera(&self, point_in_camera: Vec3) -> Option<Vec2> {
        if point_in_camera.z.is_nan() || point_in_camera.z <= 1e-6 {
            return None;
        }
        Some(Vec2::new(
            self.fx * point_in_camera.x / point_in_camera.z + self.cx,
            self.fy * point_in_camera.y / point_in_camera.z + self.cy,
        ))
    }

    /// Camera-space point at `pixel` with camera Z = `depth_m`.
    pub fn camera_from_pixel(&self, pixel: Vec2, depth_m: f32) -> Vec3 {
        Vec3::new(
            (pixel.x - self.cx) / self.fx * depth_m,
            (pixel.y - self.cy) / self.fy * depth_m,
            depth_m,
        )
    }

    /// Whether `pixel` lies in the image `[0, width) × [0, height)`.
    pub fn contains(&self, pixel: Vec2) -> bool {
        pixel.x >= 0.0
            && pixel.y >= 0.0
            && pixel.x < self.width as f32
            && pixel.y < self.height as f32
    }
}

impl From<&crate::camera::Camera> for PinholeIntrinsics {
    /// The pinhole part of the tracker's camera (the tracker hands over undistorted pixels).
    fn from(camera: &crate::camera::Camera) -> Self {
        Self {
            width: camera.width,
            height: camera.height,
            fx: camera.fx as f32,
            fy: camera.fy as f32,
            cx: camera.cx as f32,
            cy: camera.cy as f32,
        }
    }
}

/// One tracked point seen in the current frame.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Observation {
    /// Map-point id (unique per point).
    pub id: u64,
    pub pixel: Vec2,
    /// Camera Z of the point (m).
    pub depth_m: f32,
}

/// Tuning of the depth mesh; the defaults suit 640 × 480 footage of a garden.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct DepthMeshConfig {
    /// Triangles with a longer edge (pixels) are unknown: too little evidence in between.
    pub max_edge_px: f32,
    /// A triangle whose 3D plane passes closer than this to the camera centre is seen nearly
    /// edge-on: it bridges a depth discontinuity (a silhouette, a thin structure). A real
    /// surface that close (m) is rare; the ground lies a holding height away ...
    pub min_plane_distance_m: f32,
    /// ... provided its depths also differ by more than this fraction.
    pub min_discontinuity_ratio: f32,
    /// A vertex is consistent when some triangle of its neighbours predicts its inverse depth
    /// within this relative tolerance.
    pub consistency_tolerance: f32,
    /// A tracked point moving less than this (pixels) keeps its vertex where it is.
    pub move_tolerance_px: f32,
    /// Valid depths (m).
    pub min_depth_m: f32,
    pub max_depth_m: f32,
}

impl Default for DepthMeshConfig {
    fn default() -> Self {
        Self {
            max_edge_px: 80.0,
            min_plane_distance_m: 0.3,
            min_discontinuity_ratio: 0.03,
            consistency_tolerance: 0.02,
            move_tolerance_px: 0.25,
            min_depth_m: 0.05,
            max_depth_m: 100.0,
        }
    }
}

/// Why an observation was not taken into the mesh.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum DepthMeshError {
    #[error(
        "point {id}: pixel ({u}, {v}) is not a finite position inside the {width}x{height} image"
    )]
    PixelOutside {
        id: u64,
        u: f32,
        v: f32,
        width: u32,
        height: u32,
    },
    #[error("point {id}: depth {depth_m} m is not finite or outside the valid range")]
    InvalidDepth { id: u64, depth_m: f32 },
    #[error("point {id}: pixel ({u}, {v}) is already taken by point {other}")]
    DuplicatePosition { id: u64, other: u64, u: f32, v: f32 },
    #[error("point {id}: not in the mesh")]
    UnknownPoint { id: u64 },
    #[error("spade rejected point {id}: {reason}")]
    Triangulation { id: u64, reason: String },
}
