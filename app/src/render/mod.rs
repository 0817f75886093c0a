//! The wgpu renderer: one code path for the window and for headless (offscreen) frames.
//!
//! A frame is: the sun's shadow map of the tree (drawn again only when the tree, the sun or the
//! drawn level of detail changes, not per camera frame), then one scene pass — 4× MSAA on a GPU
//! and in offscreen frames, one sample with alpha-tested leaf edges for an interactive view on a
//! CPU rasteriser ([`interactive_sample_count`]): camera image (undistorted
//! for display), the scene's depth mesh into depth only (so the real scene hides the tree), the
//! ground plane (a shadow catcher over the camera image, or a lawn outside AR), bark with the
//! species' bark texture, leaf cards, then debug views (depth-mesh wireframe, feature points,
//! brush sphere). The pass resolves into the caller's target, where the UI may draw on top.
//!
//! The tree is drawn in its species' look and season ([`TreeLook`], [`textures`]): leaf cards
//! are instances of one quad (a [`CardInstance`] each) sampling the species' card texture,
//! alpha to coverage, lit on both faces (the sun through a blade lights its shaded face); the
//! level of detail is picked by the cards' size on screen ([`lod`]).
//!
//! World space: metres, Y up, origin on the ground plane.

mod buffers;
pub mod camera;
pub mod gpu;
pub mod lod;
pub mod mesh;
pub mod offscreen;
mod pipelines;
pub mod resources;
pub mod shadow;
pub mod textures;
mod tree_gpu;
pub mod ui_painter;
pub mod upscale;

pub use camera::{Intrinsics, ViewCamera};
pub use gpu::Gpu;
pub use mesh::{
    CardInstance, GroundPlane, LitMesh, LitVertex, OccluderMesh, TreeLevel, TreeLook, TreeMesh,
};
pub use offscreen::Offscreen;
pub use pipelines::{SAMPLE_COUNT, interactive_sample_count};
pub use resources::Renderer;
pub use upscale::SceneResolution;

use glam::Vec3;

/// How the ground is drawn.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum GroundStyle {
    /// AR: only the tree's shadow darkens the camera image.
    ShadowCatcher,
    /// Outside AR: a lit lawn disc that receives the shadow.
    Lawn,
}

/// Sun and sky.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Lighting {
    /// Unit direction from the scene towards the sun, world space.
    pub sun_direction: Vec3,
    pub sun_strength: f32,
    /// Scale of the per-vertex ambient (sky) light.
    pub ambient_strength: f32,
    /// Darkening of the camera image in the tree's full shadow, 0..1.
    pub shadow_strength: f32,
}

impl Default for Lighting {
    fn default() -> Self {
        Lighting {
            sun_direction: Vec3::new(0.45, 0.8, 0.35).normalize(),
            sun_strength: 1.1,
            ambient_strength: 0.55,
            shadow_strength: 0.55,
        }
    }
}

/// Debug overlays.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct DebugViews {
    pub feature_points: bool,
    pub depth_wireframe: bool,
    /// Centre and radius (metres) of the brush sphere.
    pub brush: Option<(Vec3, f32)>,
}

/// Everything about one frame that is not a mesh or an image.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct FrameView {
    pub camera: ViewCamera,
    /// Draw the uploaded camera image behind the scene (AR); otherwise a sky gradient.
    pub show_camera_image: bool,
    /// Draw the uploaded scene depth mesh into depth (real objects hide the tree).
    pub occlude: bool,
    pub ground: Option<GroundPlane>,
    pub ground_style: GroundStyle,
    pub lighting: Lighting,
    pub debug: DebugViews,
}

impl FrameView {
    /// An AR frame: camera image, occlusion, shadow on the ground.
    pub fn augmented(camera: ViewCamera, ground: Option<GroundPlane>) -> Self {
        FrameView {
            camera,
            show_camera_image: true,
            occlude: true,
            ground,
            ground_style: GroundStyle::ShadowCatcher,
            lighting: Lighting::default(),
            debug: DebugViews::default(),
        }
    }

    /// A view of the tree alone, on a lawn under the sky.
    pub fn tree_only(camera: ViewCamera) -> Self {
        FrameView {
            camera,
            show_camera_image: false,
            occlude: false,
            ground: Some(GroundPlane::default()),
            ground_style: GroundStyle::Lawn,
            lighting: Lighting::default(),
            debug: DebugViews::default(),
        }
    }
}
