//! Handheld-like camera paths: a walking arc around the planting spot with step bob, sway and
//! hand shake, all smooth closed-form functions of time (so accelerations are exact enough
//! for a synthetic accelerometer).
//!
//! Camera space is OpenCV's (X right, Y down, Z forward); `world_from_camera` maps it into the
//! garden's world (metres, Y up).

use glam::{Affine3A, Mat3, Quat, Vec3};
use serde::Serialize;

use super::rng::SplitMix64;
use super::scene::Ground;

/// A sum of sinusoids: `Σ aᵢ sin(2π fᵢ t + φᵢ)`.
#[derive(Clone, Debug, Serialize)]
struct Wobble {
    terms: Vec<(f32, f32, f32)>,
}

impl Wobble {
    fn random(
        rng: &mut SplitMix64,
        amplitude: f32,
        min_hz: f32,
        max_hz: f32,
        count: usize,
    ) -> Self {
        let terms = (0..count)
            .map(|_| {
                let hz = min_hz + (max_hz - min_hz) * rng.next_f32();
                let phase = std::f32::consts::TAU * rng.next_f32();
                let share = amplitude * (0.5 + rng.next_f32()) / count as f32;
                (share, hz, phase)
            })
            .collect();
        Self { terms }
    }

    fn at(&self, t: f32) -> f32 {
        self.terms
            .iter()
            .map(|&(a, hz, phase)| a * (std::f32::consts::TAU * hz * t + phase).sin())
            .sum()
    }
}

/// Parameters of the walk; the defaults are the demo's.
#[derive(Clone, Debug, Serialize)]
pub struct WalkParams {
    /// Horizontal distance from the camera to the planting spot (m).
    pub radius_m: f32,
    /// Camera height above the ground below it (m).
    pub height_m: f32,
    /// Downward tilt of the optical axis below the horizon (degrees).
    pub pitch_deg: f32,
    /// Bearing of the first and last camera position around the spot (degrees, 0 = +Z).
    pub start_bearing_deg: f32,
    pub end_bearing_deg: f32,
    /// Peak rotational hand shake (degrees) and positional shake (m).
    pub shake_deg: f32,
    pub shake_m: f32,
    /// Vertical bob of the walk (m) at the step frequency (Hz).
    pub bob_m: f32,
    pub step_hz: f32,
}

impl Default for WalkParams {
    fn default() -> Self {
        Self {
            radius_m: 3.0,
            height_m: 1.5,
            pitch_deg: 34.0,
            start_bearing_deg: -40.0,
            end_bearing_deg: 40.0,
            shake_deg: 0.5,
            shake_m: 0.004,
            bob_m: 0.012,
            step_hz: 1.8,
        }
    }
}

/// A concrete, seeded trajectory over `duration_s`.
#[derive(Clone, Debug)]
pub struct Walk {
    params: WalkParams,
    ground: Ground,
    duration_s: f32,
    shake_angles: [Wobble; 3],
    shake_position: [Wobble; 3],
    radius_drift: Wobble,
}

impl Walk {
    pub fn new(params: WalkParams, ground: Ground, duration_s: f32, seed: u64) -> Self {
        let mut rng = SplitMix64::new(seed ^ 0x7a11_c0de);
        let shake = params.shake_deg.to_radians();
        let shake_angles = [(); 3].map(|_| Wobble::random(&mut rng, shake, 1.0, 7.0, 4));
        let shake_position = [(); 3].map(|_| Wobble::random(&mut rng, params.shake_m, 0.8, 5.0, 3));
        let radius_drift = Wobble::random(&mut rng, 0.25, 0.05, 0.15, 2);
        Self {
            params,
            ground,
            duration_s: duration_s.max(1e-3),
            shake_angles,
            shake_position,
            radius_drift,
        }
    }

    /// The camera pose at time `t` (seconds from the first frame).
    pub fn world_from_camera(&self, t: f32) -> Affine3A {
        let p = &self.params;
        let s = (t / self.duration_s).clamp(-0.5, 1.5);
        let bearing =
            (p.start_bearing_deg + (p.end_bearing_deg - p.start_bearing_deg) * s).to_radians();
        let radius = p.radius_m + self.radius_drift.at(t);
        let (x, z) = (radius * bearing.sin(), radius * bearing.cos());
        let step_phase = std::f32::consts::TAU * p.step_hz * t;
        let bob = p.bob_m * step_phase.sin();
        let sway = 0.6 * p.bob_m * (0.5 * step_phase).sin();
        let tangent = Vec3::new(bearing.cos(), 0.0, -bearing.sin());
        let shake = Vec3::new(
            self.shake_position[0].at(t),
            self.shake_position[1].at(t),
            self.shake_position[2].at(t),
        );
        let position = Vec3::new(x, self.ground.height_at(x, z) + p.height_m + bob, z)
            + tangent * sway
            + shake;
        let yaw_to_spot = (-x).atan2(-z);
        let pitch = -p.pitch_deg.to_radians();
        let forward = Vec3::new(
            pitch.cos() * yaw_to_spot.sin(),
            pitch.sin(),
            pitch.cos() * yaw_to_spot.cos(),
        );
        let right = forward.cross(Vec3::Y).normalize();
        let down = forward.cross(right);
        let base = Mat3::from_cols(right, down, forward);
        let jitter = Quat::from_euler(
            glam::EulerRot::XYZ,
            self.shake_angles[0].at(t),
            self.shake_angles[1].at(t),
            self.shake_angles[2].at(t),
        );
        let rotation = Quat::from_mat3(&base) * jitter;
        Affine3A::from_rotation_translation(rotation.normalize(), position)
    }

    /// Specific force (what an accelerometer at rest reads: +g upwards) in camera space,
    /// by central differences of the position.
    pub fn specific_force_in_camera(&self, t: f32) -> Vec3 {
        const H: f32 = 1.0 / 240.0;
        let position = |t: f32| Vec3::from(self.world_from_camera(t).translation);
        let acceleration = (position(t + H) - 2.0 * position(t) + position(t - H)) / (H * H);
        let specific_force_in_world = acceleration + Vec3::new(0.0, 9.81, 0.0);
        let camera_from_world = Quat::from_mat3a(&self.world_from_camera(t).matrix3).inverse();
        camera_from_world * specific_force_in_world
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_camera_looks_down_at_the_spot_from_the_holding_height() {
        let params = WalkParams {
            shake_deg: 0.0,
            shake_m: 0.0,
            bob_m: 0.0,
            ..Default::default()
        };
        let walk = Walk::new(params, Ground::sloped(0.0), 8.0, 3);
        let pose = walk.world_from_camera(4.0);
        let position = Vec3::from(pose.translation);
        assert!((position.y - 1.5).abs() < 1e-4, "height {}", position.y);
        let forward = pose.transform_vector3(Vec3::Z);
        let pitch_deg = (-forward.y).asin().to_degrees();
        assert!((pitch_deg - 34.0).abs() < 0.01, "pitch {pitch_deg}");
        // The spot (origin) projects in front of the camera, near the middle column.
        let spot_in_camera = pose.inverse().transform_point3(Vec3::ZERO);
        assert!(spot_in_camera.z > 2.5 && spot_in_camera.x.abs() < 1e-3);
    }

    #[test]
    fn a_camera_at_rest_reads_gravity_upwards() {
        let params = WalkParams {
            shake_deg: 0.0,
            shake_m: 0.0,
            bob_m: 0.0,
            start_bearing_deg: 0.0,
            end_bearing_deg: 0.0,
            ..Default::default()
        };
        let mut walk = Walk::new(params, Ground::sloped(0.0), 8.0, 3);
        walk.radius_drift = Wobble { terms: Vec::new() };
        let force = walk.specific_force_in_camera(1.0);
        let up_in_camera = walk
            .world_from_camera(1.0)
            .inverse()
            .transform_vector3(Vec3::Y);
        assert!(
            (force - up_in_camera * 9.81).length() < 0.05,
            "force {force}"
        );
    }
}
