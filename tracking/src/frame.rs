//! One image of the footage, and the per-frame output of the tracker.

use glam::{DAffine3, DVec3, Vec2, Vec3};

/// An 8-bit grey image, row-major, `width * height` bytes.
#[derive(Clone, Debug, PartialEq)]
pub struct GrayImage {
    pub width: u32,
    pub height: u32,
    pub pixels: Vec<u8>,
}

impl GrayImage {
    /// An image of one grey level.
    pub fn filled(width: u32, height: u32, level: u8) -> Self {
        Self {
            width,
            height,
            pixels: vec![level; width as usize * height as usize],
        }
    }

    /// Wraps row-major pixels; None when the length does not match the size.
    pub fn from_pixels(width: u32, height: u32, pixels: Vec<u8>) -> Option<Self> {
        (pixels.len() == width as usize * height as usize).then_some(Self {
            width,
            height,
            pixels,
        })
    }

    /// Standard deviation of the grey levels: a blank (or blanked) frame has almost none.
    pub fn contrast(&self) -> f64 {
        if self.pixels.is_empty() {
            return 0.0;
        }
        let n = self.pixels.len() as f64;
        let (sum, sum_sq) = self
            .pixels
            .iter()
            .step_by(7)
            .fold((0.0, 0.0), |(s, q), &p| {
                let p = p as f64;
                (s + p, q + p * p)
            });
        let m = n / 7.0;
        let mean = sum / m;
        (sum_sq / m - mean * mean).max(0.0).sqrt()
    }
}

/// A timestamped image from a footage source.
#[derive(Clone, Debug)]
pub struct Frame {
    /// Index in the source, counting skipped frames too.
    pub index: usize,
    pub timestamp_s: f64,
    pub image: GrayImage,
}

/// The tracker's state, as in ORB-SLAM.
#[derive(Clone, Copy, Debug, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
pub enum TrackingState {
    /// No reference frame yet.
    NotInitialized,
    /// A reference frame is set; waiting for enough parallax to build the first map.
    Initializing,
    /// The pose of this frame was estimated from the map.
    Ok,
    /// Tracking failed for a short while; the last pose is held and relocalisation is tried.
    RecentlyLost,
    /// Tracking failed for long; relocalisation against keyframes is tried on every frame.
    Lost,
}

/// A map point seen in a frame.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize)]
pub struct TrackedPoint {
    pub id: u64,
    /// Raw image pixel.
    pub pixel: Vec2,
    /// Position in the world (metres, Y up, origin on the ground plane).
    pub world: Vec3,
}

/// A plane `normal · p = offset` in the world.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct Plane {
    /// Unit normal.
    pub normal: DVec3,
    pub offset: f64,
}

impl Plane {
    /// Signed distance of a point to the plane (positive on the normal's side).
    pub fn signed_distance(&self, point: DVec3) -> f64 {
        self.normal.dot(point) - self.offset
    }
}

/// What the tracker says about one frame.
#[derive(Clone, Debug)]
pub struct FrameOutput {
    pub index: usize,
    pub timestamp_s: f64,
    pub state: TrackingState,
    /// Camera pose when `state` is `Ok` (world: metres, Y up, origin on the ground plane).
    pub world_from_camera: Option<DAffine3>,
    pub tracked_points: Vec<TrackedPoint>,
    /// The ground plane in the world, once the map exists.
    pub plane: Option<Plane>,
}
