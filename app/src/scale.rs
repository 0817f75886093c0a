//! The window's metric scale, platform-neutral: where it comes from (the holding height with the
//! tracked camera's median height, or a known length tapped in one frame), its uncertainty, and
//! the measure tool (two taps: the distance in metres).
//!
//! The tracker's world is fixed once, in units of its first guess (the holding height at its
//! first map). [`ScaleState::metres_per_unit`] is one factor on that world about its origin (on
//! the ground); [`ScaleState::observe`] and the picks always take the tracker's own (unscaled)
//! frames. The design applies it to the trees, not to the world: tree space is metres and each
//! tree's `world_from_tree` carries S(1 / metres per unit) of the design's [`TreeScale`], taken
//! when the first tree is planted and changed only by an explicit event (a holding height, a
//! known length marked; never the camera height's frame-to-frame refinement), which rescales
//! every tree about its trunk base.
//!
//! The design's part is [`DesignScale`]: every shown frame goes to [`DesignScale::observe`]; the
//! camera-height field sends `InputEvent::HoldingHeight`; choosing the known-length or measure
//! tool sends `InputEvent::ScaleTool`, after which taps go to [`DesignScale::touch`] (not to the
//! tree) and each pair of taps in one frame ([`TwoTaps`]) is measured or marked in that frame's
//! view; the status line shows [`ScaleState::status`].

use std::collections::BTreeMap;

use glam::{DAffine3, DVec2, Mat4, Vec2, Vec3};
use serde::{Deserialize, Serialize};
use sylva_tracking::depth_mesh::Observation;
use sylva_tracking::measure::{FrameView, MeasureError, PixelPair, Surface};
use sylva_tracking::scale::{
    CameraHeights, DEFAULT_HOLDING_HEIGHT_M, MetricScale, ScaleError, scale_from_known_length,
    validate_holding_height_m,
};
use sylva_tracking::{Camera, Plane, TrackedPoint};

use crate::render::{GroundPlane, Intrinsics};
use crate::scene_tracking::SceneFrame;
use crate::state::TouchPhase;

/// The scale of the window's world.
#[derive(Clone, Debug, PartialEq)]
pub struct ScaleState {
    holding_height_m: f64,
    heights: CameraHeights,
    /// The scale of a known length the user marked (fixed when marked).
    known: Option<MetricScale>,
}

/// The scale the design's trees are placed with: `world_from_tree` carries
/// S(1 / [`TreeScale::metres_per_unit`]) (tree space is metres). It is taken when the first tree
/// is planted and changes only on an explicit scale event (a holding height entered, a known
/// length marked) or a restored placement, never with the camera height's frame-to-frame
/// refinement: a planted tree does not breathe.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum TreeScale {
    /// Planted before there was a scale: the tracker's unit is taken as a metre, and the first
    /// scale that comes is adopted.
    Awaiting,
    /// The tracker's unit taken as a metre until an explicit scale event (version 2 sessions and
    /// designs made with `DesignState::new`).
    TrackerUnit,
    /// A metric scale, as it was when taken.
    Metric(MetricScale),
    /// The scale a restored or recreated tree's placement carried (not the current scale).
    Restored { metres_per_unit: f64 },
}

impl TreeScale {
    /// Metres per unit of the tracker's world that the trees are placed with.
    pub fn metres_per_unit(&self) -> f64 {
        match self {
            TreeScale::Awaiting | TreeScale::TrackerUnit => 1.0,
            TreeScale::Metric(scale) => scale.metres_per_unit,
            TreeScale::Restored { metres_per_unit } => *metres_per_unit,
        }
    }

    /// The status line's words for the tree.
    pub fn status(&self) -> String {
        match self {
            TreeScale::Awaiting | TreeScale::TrackerUnit => {
                "Tree at the tracker's unit (no metric scale)".into()
            }
            TreeScale::Metric(scale) => format!("Tree at metric scale from {scale}"),
            TreeScale::Restored { metres_per_unit } => {
                format!("Tree at its restored placement's scale ({metres_per_unit:.3} m per unit)")
            }
        }
    }
}

/// A distance measured with the tool, metres.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Measured {
    pub distance_m: f64,
    /// One standard deviation: the taps' and the scale's.
    pub sigma_m: f64,
    pub surfaces: [Surface; 2],
}

impl ScaleState {
    /// A state for a holding height in [`sylva_tracking::scale::HOLDING_HEIGHT_RANGE_M`].
    pub fn new(holding_height_m: f64) -> Result<Self, ScaleError> {
        Ok(Self {
            holding_height_m: validate_holding_height_m(holding_height_m)?,
            heights: CameraHeights::default(),
            known: None,
        })
    }

    pub fn holding_height_m(&self) -> f64 {
        self.holding_height_m
    }

    /// A new holding height; a marked known length keeps the scale.
    pub fn set_holding_height_m(&mut self, holding_height_m: f64) -> Result<(), ScaleError> {
        self.holding_height_m = validate_holding_height_m(holding_height_m)?;
        Ok(())
    }

    /// One tracked frame: its camera's height above its plane, in the tracker's world.
    pub fn observe(&mut self, world_from_camera: &DAffine3, plane: &Plane) {
        self.heights.push(plane, world_from_camera.translation);
    }

    /// The scale now: the known length when marked, else the camera height (None until a few
    /// frames have a plane).
    pub fn current(&self) -> Option<MetricScale> {
        self.known
            .or_else(|| self.heights.scale(self.holding_height_m))
    }

    /// Metres per unit of the tracker's world (1 until there is a scale).
    pub fn metres_per_unit(&self) -> f64 {
        self.current().map_or(1.0, |s| s.metres_per_unit)
    }

    /// Sets the scale from two picks `length_m` apart in `view` (the tracker's frame).
    pub fn mark_known_length(
        &mut self,
        view: &FrameView,
        pair: &PixelPair,
        length_m: f64,
    ) -> Result<MetricScale, KnownLengthError> {
        let distance = view.measure(pair.a, pair.b)?;
        let scale =
            scale_from_known_length(distance.distance, distance.sigma, length_m, pair.frame)?
                .ok_or(MeasureError::SamePoint { frame: pair.frame })?;
        self.known = Some(scale);
        Ok(scale)
    }

    /// Back to the camera height.
    pub fn clear_known_length(&mut self) {
        self.known = None;
    }

    /// The distance in metres between two picks in `view` (the tracker's frame).
    pub fn measure(&self, view: &FrameView, pair: &PixelPair) -> Result<Measured, MeasureError> {
        let d = view.measure(pair.a, pair.b)?;
        let scale = self.metres_per_unit();
        let relative = self.current().map_or(0.0, |s| s.relative_sigma);
        let distance_m = d.distance * scale;
        Ok(Measured {
            distance_m,
            sigma_m: (d.sigma * scale).hypot(distance_m * relative),
            surfaces: [d.a.surface, d.b.surface],
        })
    }

    /// The status line's words: the source and its uncertainty.
    pub fn status(&self) -> String {
        match self.current() {
            Some(scale) => format!("Scale from {scale}"),
            None if self.heights.num_frames() > 0 => format!(
                "Scale: measuring the camera's height (held {} m up)",
                self.holding_height_m
            ),
            None => format!(
                "Scale: waiting for the ground (phone held {} m above it)",
                self.holding_height_m
            ),
        }
    }
}

/// Why a known length was not taken.
#[derive(Debug, thiserror::Error)]
pub enum KnownLengthError {
    #[error(transparent)]
    Pick(#[from] MeasureError),
    #[error(transparent)]
    Length(#[from] ScaleError),
}

/// Two taps in one frame make a pair; a tap in another frame starts again.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct TwoTaps {
    first: Option<(usize, DVec2)>,
}

impl TwoTaps {
    /// A tap at a raw pixel of `frame`: the pair on the second tap of a frame.
    pub fn tap(&mut self, frame: usize, pixel: DVec2) -> Option<PixelPair> {
        match self.first.take() {
            Some((first_frame, a)) if first_frame == frame => {
                Some(PixelPair { frame, a, b: pixel })
            }
            _ => {
                self.first = Some((frame, pixel));
                None
            }
        }
    }

    /// The first tap, while waiting for the second (to draw it).
    pub fn pending(&self) -> Option<(usize, DVec2)> {
        self.first
    }
}

/// The tracked points of a scene frame in its world (from the ideal pixels and depths it keeps).
pub fn scene_points(scene: &SceneFrame, camera: &Camera) -> Vec<TrackedPoint> {
    match scene.world_from_camera {
        Some(world_from_camera) => tracked_points(&scene.observations, world_from_camera, camera),
        None => Vec::new(),
    }
}

/// A scene frame's pose and plane as the picks want them (None without a pose).
pub fn scene_pose_and_plane(scene: &SceneFrame) -> Option<(DAffine3, Option<Plane>)> {
    let pose: Mat4 = scene.world_from_camera?;
    let pose = DAffine3::from_mat4(pose.as_dmat4());
    let plane = scene.ground.map(|g| Plane {
        normal: g.normal.as_dvec3(),
        offset: g.normal.dot(g.point) as f64,
    });
    Some((pose, plane))
}

/// The view of scene frame `frame` for picks: `points` from [`scene_points`].
pub fn scene_view<'a>(
    frame: usize,
    scene: &SceneFrame,
    camera: &'a Camera,
    points: &'a [TrackedPoint],
) -> Option<FrameView<'a>> {
    let (world_from_camera, plane) = scene_pose_and_plane(scene)?;
    Some(FrameView {
        frame,
        camera,
        world_from_camera,
        plane,
        points,
    })
}

/// The scale tools: while one is chosen, taps on the image go to it instead of the tree.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(tag = "tool", rename_all = "snake_case")]
pub enum ScaleTool {
    /// Two taps: the distance between their points, in metres.
    Measure,
    /// Two taps on the ends of something `length_m` long: the scale from it.
    KnownLength { length_m: f64 },
}

/// The frame shown, as the tools pick in it (the tracker's world).
#[derive(Clone, Debug)]
struct ShownFrame {
    world_from_camera: DAffine3,
    plane: Option<Plane>,
    points: Vec<TrackedPoint>,
}

/// The design's scale: the state fed by every shown frame, the chosen tool, its taps, and what
/// the last pair of taps gave.
#[derive(Clone, Debug)]
pub struct DesignScale {
    pub state: ScaleState,
    pub tool: Option<ScaleTool>,
    taps: TwoTaps,
    /// Where each touch started, to tell taps from drags.
    touch_starts: BTreeMap<u64, Vec2>,
    camera: Option<Camera>,
    shown: Option<ShownFrame>,
    /// Frames shown so far (both taps of a pair must be in one).
    num_shown: usize,
    /// The footage index of the frame shown, when the caller says it (messages name it).
    frame_index: Option<usize>,
    /// The last distance measured.
    pub measured: Option<Measured>,
    /// What the tool said last: a distance, a scale, or why it could not.
    pub message: Option<String>,
}

impl Default for DesignScale {
    fn default() -> Self {
        Self {
            state: ScaleState {
                holding_height_m: DEFAULT_HOLDING_HEIGHT_M,
                heights: CameraHeights::default(),
                known: None,
            },
            tool: None,
            taps: TwoTaps::default(),
            touch_starts: BTreeMap::new(),
            camera: None,
            shown: None,
            num_shown: 0,
            frame_index: None,
            measured: None,
            message: None,
        }
    }
}

/// A tap moves less than this, pixels.
const TAP_SLOP_PX: f32 = 8.0;

impl DesignScale {
    /// The frame about to be shown (the same inputs as the scene's occupancy).
    pub fn observe(
        &mut self,
        intrinsics: &Intrinsics,
        world_from_camera: Option<Mat4>,
        ground: Option<GroundPlane>,
        observations: &[Observation],
    ) {
        self.num_shown += 1;
        self.frame_index = None;
        let camera = *self.camera.get_or_insert_with(|| camera_of(intrinsics));
        let Some(pose) = world_from_camera else {
            self.shown = None;
            return;
        };
        let world_from_camera = DAffine3::from_mat4(pose.as_dmat4());
        let plane = ground.map(|g| Plane {
            normal: g.normal.as_dvec3(),
            offset: g.normal.dot(g.point) as f64,
        });
        if let Some(plane) = &plane {
            self.state.observe(&world_from_camera, plane);
        }
        self.shown = Some(ShownFrame {
            world_from_camera,
            plane,
            points: tracked_points(observations, pose, &camera),
        });
    }

    /// The footage index of the frame just observed (for the messages; call after
    /// [`Self::observe`]).
    pub fn set_frame_index(&mut self, index: usize) {
        self.frame_index = Some(index);
    }

    /// The camera-height field: refused (kept as it was) outside the range the field offers.
    pub fn set_holding_height_m(&mut self, holding_height_m: f64) {
        if let Err(e) = self.state.set_holding_height_m(holding_height_m) {
            self.message = Some(e.to_string());
        }
    }

    /// Chooses a tool (none: taps edit the tree again); a pending first tap is dropped.
    pub fn choose(&mut self, tool: Option<ScaleTool>) {
        self.tool = tool;
        self.taps = TwoTaps::default();
        self.touch_starts.clear();
        self.message = match tool {
            Some(ScaleTool::Measure) => Some("Measure: tap two points".into()),
            Some(ScaleTool::KnownLength { length_m }) => Some(format!(
                "Known length: tap the two ends of the {length_m:.2} m"
            )),
            None => None,
        };
    }

    /// A touch while a tool is chosen; a tap (a touch that did not move) is one of the pair.
    /// True when it marked a known length (the scale changed).
    pub fn touch(&mut self, phase: TouchPhase, id: u64, pixel: Vec2) -> bool {
        match phase {
            TouchPhase::Start => {
                self.touch_starts.insert(id, pixel);
                false
            }
            TouchPhase::Move => false,
            TouchPhase::End => match self.touch_starts.remove(&id) {
                Some(start) if start.distance(pixel) <= TAP_SLOP_PX => self.tap(pixel),
                _ => false,
            },
        }
    }

    /// The first tap waits for the second in the same frame; the second measures or marks (true
    /// when a known length was marked).
    fn tap(&mut self, pixel: Vec2) -> bool {
        let Some(tool) = self.tool else {
            return false;
        };
        let Some(pair) = self.taps.tap(self.num_shown, pixel.as_dvec2()) else {
            self.message = Some("First point marked: tap the second in this frame".into());
            return false;
        };
        let pair = PixelPair {
            frame: self.frame_index.unwrap_or(pair.frame),
            ..pair
        };
        let (Some(camera), Some(shown)) = (self.camera.as_ref(), self.shown.as_ref()) else {
            self.message = Some("No tracked frame to pick in yet".into());
            return false;
        };
        let view = FrameView {
            frame: pair.frame,
            camera,
            world_from_camera: shown.world_from_camera,
            plane: shown.plane,
            points: &shown.points,
        };
        let mut marked = false;
        self.message = Some(match tool {
            ScaleTool::Measure => match self.state.measure(&view, &pair) {
                Ok(measured) => {
                    self.measured = Some(measured);
                    format!(
                        "Distance: {:.2} m ± {:.2} m",
                        measured.distance_m, measured.sigma_m
                    )
                }
                Err(e) => format!("Cannot measure: {e}"),
            },
            ScaleTool::KnownLength { length_m } => {
                match self.state.mark_known_length(&view, &pair, length_m) {
                    Ok(_) => {
                        marked = true;
                        format!("Known length of {length_m:.2} m marked")
                    }
                    Err(e) => format!("Known length not taken: {e}"),
                }
            }
        });
        marked
    }
}

/// The tracking camera of the footage's intrinsics (the pixels the touches are in).
pub(crate) fn camera_of(k: &Intrinsics) -> Camera {
    Camera {
        distortion: k.distortion.map(f64::from),
        ..Camera::pinhole(
            k.width,
            k.height,
            k.fx as f64,
            k.fy as f64,
            k.cx as f64,
            k.cy as f64,
        )
    }
}

/// Tracked points in the world from their ideal pixels and depths seen from `world_from_camera`.
fn tracked_points(
    observations: &[Observation],
    world_from_camera: Mat4,
    camera: &Camera,
) -> Vec<TrackedPoint> {
    observations
        .iter()
        .map(|o| {
            let in_camera = Vec3::new(
                (o.pixel.x - camera.cx as f32) / camera.fx as f32 * o.depth_m,
                (o.pixel.y - camera.cy as f32) / camera.fy as f32 * o.depth_m,
                o.depth_m,
            );
            TrackedPoint {
                id: o.id,
                pixel: o.pixel,
                world: world_from_camera.transform_point3(in_camera),
            }
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::{DMat3, DQuat, DVec3};

    const FLOOR: Plane = Plane {
        normal: DVec3::Y,
        offset: 0.0,
    };

    /// A camera `height` units above the floor, looking down 34° towards −Z.
    fn pose(height: f64) -> DAffine3 {
        let pitch = 34f64.to_radians();
        let forward = DVec3::new(0.0, -pitch.sin(), -pitch.cos());
        let right = forward.cross(DVec3::Y).normalize();
        let down = forward.cross(right);
        DAffine3::from_rotation_translation(
            DQuat::from_mat3(&DMat3::from_cols(right, down, forward)),
            DVec3::new(0.0, height, 0.0),
        )
    }

    fn pixel(camera: &Camera, pose: &DAffine3, world: DVec3) -> DVec2 {
        camera
            .pixel_from_camera(pose.inverse().transform_point3(world))
            .expect("in front")
    }

    #[test]
    fn the_scale_moves_from_the_camera_height_to_a_known_length_and_back() {
        // The tracker's world is 2 units for a camera held at 1.5 m: 0.75 m per unit.
        let mut state = ScaleState::new(1.5).expect("valid");
        assert!(state.current().is_none() && state.status().contains("waiting"));
        for _ in 0..10 {
            state.observe(&pose(2.0), &FLOOR);
        }
        assert!((state.metres_per_unit() - 0.75).abs() < 1e-9);
        assert!(
            state.status().contains("camera's height"),
            "{}",
            state.status()
        );
        let camera = Camera::pinhole(640, 480, 525.0, 525.0, 319.5, 239.5);
        let view = FrameView {
            frame: 4,
            camera: &camera,
            world_from_camera: pose(2.0),
            plane: Some(FLOOR),
            points: &[],
        };
        // Taps on the ends of something 2 units long in this world, said to be 1.2 m: 0.6 m/unit.
        let mut taps = TwoTaps::default();
        let a = pixel(&camera, &pose(2.0), DVec3::new(-1.0, 0.0, -3.0));
        let b = pixel(&camera, &pose(2.0), DVec3::new(1.0, 0.0, -3.0));
        assert_eq!(taps.tap(4, a), None);
        let pair = taps.tap(4, b).expect("a pair");
        let scale = state.mark_known_length(&view, &pair, 1.2).expect("marked");
        assert!((scale.metres_per_unit - 0.6).abs() < 1e-6);
        assert!(
            state.status().contains("known length"),
            "{}",
            state.status()
        );
        let measured = state.measure(&view, &pair).expect("measured");
        assert!((measured.distance_m - 1.2).abs() < 1e-6);
        assert!(measured.sigma_m > 0.0 && measured.sigma_m < 0.02);
        state.clear_known_length();
        assert!((state.metres_per_unit() - 0.75).abs() < 1e-9);
    }

    #[test]
    fn taps_in_two_frames_start_again_and_bad_heights_are_refused() {
        let mut taps = TwoTaps::default();
        assert_eq!(taps.tap(1, DVec2::ONE), None);
        assert_eq!(taps.tap(2, DVec2::ONE), None);
        assert_eq!(taps.pending(), Some((2, DVec2::ONE)));
        assert!(ScaleState::new(f64::NAN).is_err());
        let mut state = ScaleState::new(1.5).expect("valid");
        assert!(state.set_holding_height_m(40.0).is_err());
        assert_eq!(state.holding_height_m(), 1.5);
    }

    #[test]
    fn a_tool_takes_taps_but_not_drags_and_measures_in_the_frame_shown() {
        let intrinsics = Intrinsics::from_fov(640, 480, 60f32.to_radians());
        let camera = camera_of(&intrinsics);
        let mut scale = DesignScale::default();
        let ground = GroundPlane {
            point: Vec3::ZERO,
            normal: Vec3::Y,
        };
        scale.observe(
            &intrinsics,
            Some(glam::DMat4::from(pose(1.5)).as_mat4()),
            Some(ground),
            &[],
        );
        // A seek shows one frame: the ground is there, its height not yet measured.
        assert!(
            scale
                .state
                .status()
                .contains("measuring the camera's height"),
            "{}",
            scale.state.status()
        );
        for _ in 0..10 {
            scale.observe(
                &intrinsics,
                Some(glam::DMat4::from(pose(1.5)).as_mat4()),
                Some(ground),
                &[],
            );
        }
        scale.set_frame_index(42);
        scale.choose(Some(ScaleTool::Measure));
        let a = pixel(&camera, &pose(1.5), DVec3::new(-1.0, 0.0, -3.0)).as_vec2();
        let b = pixel(&camera, &pose(1.5), DVec3::new(1.0, 0.0, -3.0)).as_vec2();
        // A drag is no tap.
        scale.touch(TouchPhase::Start, 1, a);
        scale.touch(TouchPhase::End, 1, a + Vec2::new(30.0, 0.0));
        assert_eq!(scale.taps.pending(), None);
        for p in [a, b] {
            scale.touch(TouchPhase::Start, 1, p);
            scale.touch(TouchPhase::End, 1, p);
        }
        let measured = scale.measured.expect("measured");
        assert!((measured.distance_m - 2.0).abs() < 1e-3, "{measured:?}");
        assert!(
            scale
                .message
                .as_deref()
                .is_some_and(|m| m.starts_with("Distance: 2.00 m")),
            "{:?}",
            scale.message
        );
        // The known length names the footage frame it was marked in.
        scale.choose(Some(ScaleTool::KnownLength { length_m: 1.0 }));
        for p in [a, b] {
            scale.touch(TouchPhase::Start, 2, p);
            scale.touch(TouchPhase::End, 2, p);
        }
        assert!((scale.state.metres_per_unit() - 0.5).abs() < 1e-3);
        assert!(
            scale.state.status().contains("frame 42"),
            "{}",
            scale.state.status()
        );
    }
}
