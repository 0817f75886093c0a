//! The platform boundary: what differs between the desktop window, Android and iOS sits behind
//! a few small types and traits, and everything else (design state, renderer, UI, sessions) is
//! the same app library.
//!
//! - **Frames with tracking** ([`PlatformFrame`], [`FrameProvider`]): a phone's AR session
//!   (ARCore, ARKit) hands over per frame its pose, intrinsics, feature points with ids, planes
//!   and a light estimate; without one the frame is the camera image alone and Sylva's own
//!   tracker runs on it. [`PlatformStream`] turns either into the app's [`LiveStream`] of
//!   [`crate::scene_tracking::SceneFrame`]s (pose, ground, tracked points, depth mesh), so a
//!   session recorded on a phone replays on desktop like one recorded there.
//! - **A surface to draw on** ([`DrawSurface`]): a window's swap chain ([`WindowSurface`]) or an
//!   offscreen texture ([`OffscreenSurface`], host tests); the camera image is shown through the
//!   platform's display transform ([`DisplayTransform`]: turned upright, cropped to fill).
//! - **Touch input** ([`TouchInput`]): fingers in surface pixels, fed to the UI as egui touches.
//! - **Storage** ([`StorageLocation`]): where sessions, recordings and autosaves go (app storage
//!   on a phone).
//!
//! [`ShellApp`] is what a shell drives: frames in, touches in, draw, pause/resume, autosave.
//! The Android and iOS shell crates (`android/`, `ios/`) and the host tests call exactly its
//! entry points; [`winit_shell`] is the event loop the phone shells run it in.
//!
//! Spaces: a platform world is the AR session's (metres, Y up against gravity, origin where the
//! session started); cameras look along +Z with +Y down in the image (the convention of
//! Sylva's tracker and renderer: shells convert from the platforms' OpenGL-style cameras,
//! [`camera_from_gl_camera`]).

mod display;
mod draw;
mod shell;
mod storage;
mod stream;
mod surface;
mod tracking;
pub mod winit_shell;
mod yuv;

use glam::{DVec3, Mat4, Vec3};
use image::RgbaImage;

pub use display::DisplayTransform;
pub use draw::ViewDrawer;
pub use shell::{ShellApp, TouchInput};
pub use storage::StorageLocation;
pub use stream::{PlatformFeed, PlatformStream, TrackerChoice};
pub use surface::{DrawSurface, OffscreenSurface, WindowSurface};
// Sylva's own tracker builds its scenes with it too.
pub(crate) use tracking::posed_scene;
pub use tracking::{GROUND_MAX_TILT_DEG, PlatformTracker, ground_from_points, observations_of};
pub use yuv::{YuvPlanes, rgba_from_yuv420};

/// Pinhole intrinsics of a camera image, pixels (platforms report them undistorted).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PlatformIntrinsics {
    pub width: u32,
    pub height: u32,
    pub fx: f64,
    pub fy: f64,
    pub cx: f64,
    pub cy: f64,
}

impl PlatformIntrinsics {
    /// The tracking camera model of these intrinsics (no distortion).
    pub fn camera(&self, frame_rate_hz: f64) -> sylva_tracking::Camera {
        let mut camera = sylva_tracking::Camera::pinhole(
            self.width,
            self.height,
            self.fx,
            self.fy,
            self.cx,
            self.cy,
        );
        camera.frame_rate_hz = Some(frame_rate_hz);
        camera
    }
}

/// A feature point of the platform's map: its id (stable across frames while the platform
/// tracks it) and position in the platform world.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct FeaturePoint {
    pub id: u64,
    pub point_in_world: Vec3,
}

/// A plane the platform detected.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PlatformPlane {
    /// The platform's id of the plane (stable while it is tracked).
    pub id: u64,
    /// The plane's centre in the world.
    pub center_in_world: Vec3,
    /// Unit normal in the world (up for a floor).
    pub normal_in_world: Vec3,
    /// Extent along the plane's two axes, metres.
    pub extent_m: [f32; 2],
}

/// The platform's estimate of the scene's light.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct LightEstimate {
    /// Ambient intensity relative to a neutrally lit scene (1.0; ARKit's 1000 lumen = 1.0,
    /// ARCore's pixel intensity 0.5 = 1.0).
    pub ambient_intensity: f32,
    /// Colour correction (linear RGB gains, 1 = neutral).
    pub color_correction: [f32; 3],
}

/// What a platform tracker knows at one frame.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct PlatformTracking {
    /// `world_from_camera` (Sylva's camera axes); None while the platform is not tracking.
    pub world_from_camera: Option<Mat4>,
    /// Feature points observed in this frame.
    pub feature_points: Vec<FeaturePoint>,
    /// Planes tracked so far.
    pub planes: Vec<PlatformPlane>,
    pub light: Option<LightEstimate>,
}

/// One camera frame from the platform.
#[derive(Clone, Debug, PartialEq)]
pub struct PlatformFrame {
    /// Seconds since the session started.
    pub time_s: f64,
    /// The camera image as shown (its size is the intrinsics' size).
    pub rgba: RgbaImage,
    pub intrinsics: PlatformIntrinsics,
    /// The platform's tracking; None when the platform has no tracker (Sylva's own tracker then
    /// runs on the image).
    pub tracking: Option<PlatformTracking>,
    /// Gravity "up" in camera axes from the accelerometer, when the platform has one (helps
    /// Sylva's own tracker find the ground).
    pub up_in_camera: Option<DVec3>,
}

/// A platform's source of camera frames: an AR session or a plain camera stream.
pub trait FrameProvider {
    /// The next frame if a new one is there (never blocks for long: called once per redraw).
    fn poll_frame(&mut self) -> anyhow::Result<Option<PlatformFrame>>;
    /// The app goes to the background: stop the camera.
    fn pause(&mut self) -> anyhow::Result<()>;
    /// The app comes back: restart the camera.
    fn resume(&mut self) -> anyhow::Result<()>;
    /// Clockwise quarter turns that show the camera image upright on the screen as the phone is
    /// held now (Android: `(sensor orientation − display rotation) / 90°`, as
    /// `ArFrame_transformCoordinates2d` applies it; iOS: the rotation of
    /// `ARFrame.displayTransform(for:viewportSize:)`). 0 for an image that is already upright.
    fn display_quarter_turns_cw(&self) -> u8 {
        0
    }
}

/// Sylva's camera axes (X right, Y down, looking along +Z) from an OpenGL-style camera's (X
/// right, Y up, looking along -Z), which ARCore's and ARKit's poses use:
/// `world_from_camera = world_from_gl_camera * camera_from_gl_camera().inverse()` (the matrix is
/// its own inverse).
pub fn camera_from_gl_camera() -> Mat4 {
    Mat4::from_scale(Vec3::new(1.0, -1.0, -1.0))
}

/// A platform pose of an OpenGL-style camera as Sylva's `world_from_camera`.
pub fn world_from_camera_of_gl(world_from_gl_camera: Mat4) -> Mat4 {
    world_from_gl_camera * camera_from_gl_camera()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_gl_camera_looking_down_minus_z_looks_down_plus_z_in_sylva_axes() {
        // A phone held upright at 1.5 m, looking north (-Z in the platform world).
        let world_from_gl = Mat4::from_translation(Vec3::new(0.0, 1.5, 0.0));
        let world_from_camera = world_from_camera_of_gl(world_from_gl);
        let ahead = world_from_camera.transform_point3(Vec3::new(0.0, 0.0, 2.0));
        assert!(
            (ahead - Vec3::new(0.0, 1.5, -2.0)).length() < 1e-6,
            "{ahead}"
        );
        let image_down = world_from_camera.transform_vector3(Vec3::Y);
        assert!((image_down - Vec3::NEG_Y).length() < 1e-6, "{image_down}");
    }
}
