//! The tree outside AR: a camera orbiting the tree, driven by the usual gestures — one finger (or
//! the primary mouse button) orbits, two fingers (or the secondary/middle button) pan, pinch (or
//! the wheel) zooms.

use egui::{Rect, Ui};
use glam::Vec3;

use crate::render::{Intrinsics, ViewCamera};

/// Radians of orbit per pixel dragged.
const ORBIT_RAD_PER_PX: f32 = 0.008;
/// Pitch limits (radians above the horizon): never under the ground, never straight down.
const MIN_PITCH: f32 = -0.05;
const MAX_PITCH: f32 = 1.45;
/// Distance limits, metres.
const MIN_DISTANCE_M: f32 = 0.3;
const MAX_DISTANCE_M: f32 = 200.0;

/// A camera looking at `target` from `distance` metres, at `yaw` around the vertical and `pitch`
/// above the horizon.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct OrbitCamera {
    pub target: Vec3,
    pub yaw: f32,
    pub pitch: f32,
    pub distance: f32,
}

impl Default for OrbitCamera {
    fn default() -> Self {
        OrbitCamera {
            target: Vec3::new(0.0, 1.0, 0.0),
            yaw: 0.6,
            pitch: 0.25,
            distance: 5.0,
        }
    }
}

impl OrbitCamera {
    /// Frames a tree whose internode ends span `min..max`: looks at the middle of the crown
    /// from far enough to see all of it.
    pub fn framing(min: Vec3, max: Vec3) -> OrbitCamera {
        let size = (max - min).max_element().max(0.5);
        OrbitCamera {
            target: 0.5 * (min + max),
            distance: (1.6 * size).clamp(MIN_DISTANCE_M, MAX_DISTANCE_M),
            ..OrbitCamera::default()
        }
    }

    /// The eye position.
    pub fn eye(&self) -> Vec3 {
        let (sy, cy) = self.yaw.sin_cos();
        let (sp, cp) = self.pitch.sin_cos();
        self.target + self.distance * Vec3::new(cp * sy, sp, cp * cy)
    }

    pub fn camera(&self, intrinsics: Intrinsics) -> ViewCamera {
        ViewCamera::looking_at(intrinsics, self.eye(), self.target)
    }

    /// Turns around the target by a drag of `dx, dy` pixels.
    pub fn orbit(&mut self, dx: f32, dy: f32) {
        self.yaw -= dx * ORBIT_RAD_PER_PX;
        self.pitch = (self.pitch + dy * ORBIT_RAD_PER_PX).clamp(MIN_PITCH, MAX_PITCH);
    }

    /// Moves the target in the view plane so the scene follows a drag of `dx, dy` pixels seen
    /// through a camera of focal length `focal_px`.
    pub fn pan(&mut self, dx: f32, dy: f32, focal_px: f32) {
        let forward = (self.target - self.eye()).normalize_or_zero();
        let right = forward.cross(Vec3::Y).try_normalize().unwrap_or(Vec3::X);
        let up = right.cross(forward);
        let metres_per_px = self.distance / focal_px.max(1.0);
        self.target += (-dx * right + dy * up) * metres_per_px;
    }

    /// Zooms by `factor` (> 1 comes closer).
    pub fn zoom(&mut self, factor: f32) {
        if factor.is_finite() && factor > 0.0 {
            self.distance = (self.distance / factor).clamp(MIN_DISTANCE_M, MAX_DISTANCE_M);
        }
    }
}

/// Gestures on the view rectangle move `orbit`; `focal_px` is the view camera's focal length in
/// window pixels.
pub fn orbit_view_ui(ui: &mut Ui, view: Rect, orbit: &mut OrbitCamera, focal_px: f32) {
    let response = ui.interact(view, ui.scope_id().with("orbit view"), egui::Sense::drag());
    let ppp = ui.ctx().pixels_per_point();
    if let Some(touch) = ui.input(|i| i.multi_touch()) {
        orbit.pan(
            touch.translation_delta.x * ppp,
            touch.translation_delta.y * ppp,
            focal_px,
        );
        orbit.zoom(touch.zoom_delta);
        return;
    }
    let delta = response.drag_delta() * ppp;
    if response.dragged_by(egui::PointerButton::Primary) {
        orbit.orbit(delta.x, delta.y);
    } else if response.dragged_by(egui::PointerButton::Secondary)
        || response.dragged_by(egui::PointerButton::Middle)
    {
        orbit.pan(delta.x, delta.y, focal_px);
    }
    if response.hovered() {
        let scroll = ui.input(|i| i.smooth_scroll_delta.y);
        if scroll != 0.0 {
            orbit.zoom((scroll * 0.002).exp());
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn intrinsics() -> Intrinsics {
        Intrinsics {
            width: 640,
            height: 480,
            fx: 500.0,
            fy: 500.0,
            cx: 320.0,
            cy: 240.0,
            distortion: [0.0; 5],
        }
    }

    #[test]
    fn orbiting_keeps_the_target_centred_at_the_same_distance() {
        let mut orbit = OrbitCamera::framing(Vec3::new(-1.0, 0.0, -1.0), Vec3::new(1.0, 4.0, 1.0));
        let d = orbit.distance;
        orbit.orbit(120.0, -40.0);
        assert!((orbit.eye().distance(orbit.target) - d).abs() < 1e-4);
        let centre = orbit.camera(intrinsics()).pixel_from_world(orbit.target);
        let centre = centre.expect("target in view");
        assert!(
            centre.distance(glam::Vec2::new(320.0, 240.0)) < 0.5,
            "{centre}"
        );
        // Pitch stays above the ground however far one drags.
        orbit.orbit(0.0, -1e6);
        assert!(orbit.eye().y >= orbit.target.y - orbit.distance * 0.06);
    }

    #[test]
    fn panning_moves_the_scene_with_the_finger_and_zoom_changes_the_distance() {
        let mut orbit = OrbitCamera::default();
        let point = orbit.target;
        let before = orbit
            .camera(intrinsics())
            .pixel_from_world(point)
            .expect("in view");
        orbit.pan(50.0, 0.0, 500.0);
        let after = orbit
            .camera(intrinsics())
            .pixel_from_world(point)
            .expect("in view");
        assert!(
            (after.x - before.x - 50.0).abs() < 1.0,
            "{before} -> {after}"
        );
        assert!((after.y - before.y).abs() < 1.0);
        let d = orbit.distance;
        orbit.zoom(2.0);
        assert!((orbit.distance - d / 2.0).abs() < 1e-5);
        orbit.zoom(0.0);
        orbit.zoom(f32::NAN);
        assert!((orbit.distance - d / 2.0).abs() < 1e-5);
    }
}
