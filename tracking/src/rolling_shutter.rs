//! Rolling shutter: a CMOS sensor exposes its rows one after the other, so under rotation each
//! row sees the scene from a slightly different orientation (phones and the Kinect of the TUM
//! sequences alike). At 1 rad/s and a 25 ms readout the first and last rows are 1.4° apart, about
//! 13 px at 517 px focal length: a shear no rigid pose explains. The tracker states every
//! observation in the camera at the frame's middle row time, to first order in the rotation
//! rate (the translation during a readout is negligible at walking speed):
//! a ray seen at row `v` is rotated back by `exp(−ω · δt)`, `δt = (v − h/2) / h · readout`.
//!
//! The readout time is a property of the camera that calibration files seldom state, so unless
//! it is given the tracker estimates it from the footage: at frames with enough rotation (every
//! one until 40 have been sampled, then keyframes) it refines the pose once per candidate readout and keeps the robust reprojection cost; the
//! candidate with the least accumulated cost (above the least of each keyframe) is used.

use crate::ba::{BaConfig, refine_pose, reprojection_error_px};
use crate::camera::Camera;
use crate::pose::Se3;
use glam::{DQuat, DVec2, DVec3, Vec2};

/// The rows' time offsets applied to observations of one frame.
#[derive(Clone, Copy, Debug, Default)]
pub struct RollingShutter {
    /// Angular velocity of the camera, rad/s, as the rotation vector of
    /// `camera_now ← camera_before` per second.
    pub rate: DVec3,
    /// Time from the first row to the last, seconds (0: global shutter).
    pub readout_s: f64,
}

impl RollingShutter {
    /// The rotation vector from the middle row's camera to row `row`'s.
    fn rotation_at_row(&self, camera: &Camera, row: f64) -> DVec3 {
        let h = f64::from(camera.height);
        self.rate * ((row - 0.5 * h) / h * self.readout_s)
    }

    fn is_global(&self) -> bool {
        self.readout_s == 0.0 || self.rate == DVec3::ZERO
    }

    /// Normalised coordinates of the ray seen at `pixel`, in the camera at the middle row time.
    pub fn normalized(&self, camera: &Camera, pixel: Vec2) -> DVec2 {
        let n = camera.normalized_from_pixel(pixel.as_dvec2());
        if self.is_global() {
            return n;
        }
        let back = DQuat::from_scaled_axis(-self.rotation_at_row(camera, f64::from(pixel.y)));
        let ray = back * n.extend(1.0);
        if ray.z <= 1e-9 {
            return n;
        }
        ray.truncate() / ray.z
    }

    /// Where a point given in the middle-row camera appears (its row's time found from the
    /// global-shutter projection: first order, like [`Self::normalized`]).
    pub fn pixel(&self, camera: &Camera, point_in_camera: DVec3) -> Option<DVec2> {
        let global = camera.pixel_from_camera(point_in_camera)?;
        if self.is_global() {
            return Some(global);
        }
        let turn = DQuat::from_scaled_axis(self.rotation_at_row(camera, global.y));
        camera.pixel_from_camera(turn * point_in_camera)
    }
}

/// Candidate readout times, seconds: 0 to 40 ms by 5 ms.
const CANDIDATES_S: [f64; 9] = [0.0, 0.005, 0.01, 0.015, 0.02, 0.025, 0.03, 0.035, 0.04];
/// Samples (frames with enough rotation) needed before the estimate replaces the global shutter.
const MIN_SAMPLES: usize = 5;
/// Weight kept by the evidence so far at each new sample: the map and poses the evidence is
/// measured against were built with the readout in use, which pulls each sample's answer
/// towards it; forgetting lets the estimate climb to where the answer and the readout in use
/// agree (a fixed point) instead of staying near the first guess. Of 0.9, 0.8, 0.7 and 0.5,
/// 0.7 gave the least mean errors over ten starts of TUM fr1_rpy.
const DECAY: f64 = 0.7;
/// Frames with enough rotation sampled one after the other before only keyframes are.
const SETTLING_SAMPLES: usize = 40;
/// Slowest rotation that says something about the readout, rad/s.
pub const MIN_RATE_RAD_S: f64 = 0.3;
/// Fewest observations for a sample.
const MIN_OBSERVATIONS: usize = 30;

/// The readout time estimated from keyframes (see the module documentation).
#[derive(Clone, Debug, Default)]
pub struct ReadoutEstimate {
    excess_cost: [f64; CANDIDATES_S.len()],
    samples: usize,
}

impl ReadoutEstimate {
    /// Adds one keyframe's evidence: its observations (map points and pixels), pose, rotation
    /// rate and the solver settings. Keyframes rotating slower than [`MIN_RATE_RAD_S`] or
    /// with few observations are skipped.
    pub fn observe(
        &mut self,
        camera: &Camera,
        pose: &Se3,
        rate: DVec3,
        observations: &[(DVec3, Vec2)],
        config: &BaConfig,
    ) {
        if rate.length() < MIN_RATE_RAD_S || observations.len() < MIN_OBSERVATIONS {
            return;
        }
        let points: Vec<DVec3> = observations.iter().map(|o| o.0).collect();
        let costs = CANDIDATES_S.map(|readout_s| {
            let shutter = RollingShutter { rate, readout_s };
            let rays: Vec<DVec2> = observations
                .iter()
                .map(|o| shutter.normalized(camera, o.1))
                .collect();
            let refined = refine_pose(*pose, &points, &rays, config);
            let huber = |e: f64| {
                if e <= config.huber_px {
                    0.5 * e * e
                } else {
                    config.huber_px * (e - 0.5 * config.huber_px)
                }
            };
            points
                .iter()
                .zip(&rays)
                .map(|(p, n)| huber(reprojection_error_px(&refined, *p, *n, config.focal)))
                .sum::<f64>()
                / points.len() as f64
        });
        let least = costs.iter().copied().fold(f64::INFINITY, f64::min);
        if !least.is_finite() {
            return;
        }
        for (sum, cost) in self.excess_cost.iter_mut().zip(costs) {
            *sum = *sum * DECAY + (cost - least);
        }
        self.samples += 1;
    }

    /// Whether the estimate still wants evidence from every frame (then from keyframes only).
    pub fn is_settling(&self) -> bool {
        self.samples < SETTLING_SAMPLES
    }

    /// The readout time with the least accumulated cost, once enough keyframes rotated.
    pub fn readout_s(&self) -> Option<f64> {
        if self.samples < MIN_SAMPLES {
            return None;
        }
        let cost = &self.excess_cost;
        let best = (0..CANDIDATES_S.len()).min_by(|&a, &b| cost[a].total_cmp(&cost[b]))?;
        // The parabola through the least cost and its neighbours places the minimum between
        // candidates.
        if best == 0 || best + 1 == CANDIDATES_S.len() {
            return Some(CANDIDATES_S[best]);
        }
        let (before, at, after) = (cost[best - 1], cost[best], cost[best + 1]);
        let curvature = before - 2.0 * at + after;
        let step = CANDIDATES_S[1] - CANDIDATES_S[0];
        let shift = if curvature > 0.0 {
            (0.5 * (before - after) / curvature).clamp(-0.5, 0.5)
        } else {
            0.0
        };
        Some(CANDIDATES_S[best] + shift * step)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn camera() -> Camera {
        Camera::pinhole(640, 480, 525.0, 525.0, 319.5, 239.5)
    }

    #[test]
    fn correcting_what_the_shutter_did_gives_back_the_middle_row_ray() {
        let camera = camera();
        let shutter = RollingShutter {
            rate: DVec3::new(0.3, -1.2, 0.4),
            readout_s: 0.03,
        };
        for point in [
            DVec3::new(0.3, -0.4, 2.0),
            DVec3::new(-0.5, 0.35, 1.5),
            DVec3::new(0.0, 0.0, 3.0),
        ] {
            let pixel = shutter.pixel(&camera, point).expect("in front");
            let ray = shutter.normalized(&camera, pixel.as_vec2());
            let truth = point.truncate() / point.z;
            // First order both ways: agreement far below a pixel.
            assert!(
                (ray - truth).length() * 525.0 < 0.25,
                "{ray} vs {truth} for {point}"
            );
            let global = camera.pixel_from_camera(point).expect("in front");
            if (point.y / point.z).abs() > 0.1 {
                assert!(
                    global.distance(pixel) > 1.0,
                    "rows away from the middle move"
                );
            }
        }
    }

    #[test]
    fn the_readout_is_recovered_from_a_rotating_frame_and_zero_from_a_global_shutter() {
        let camera = camera();
        let pose = Se3::new(DQuat::from_rotation_y(0.2), DVec3::new(0.1, -0.2, 0.3));
        let world_from_camera = pose.inverse();
        // A grid of points 1.5–3 m in front of the camera.
        let mut points = Vec::new();
        for i in 0..10 {
            for j in 0..8 {
                let c = DVec3::new(
                    -0.8 + 0.18 * f64::from(i),
                    -0.6 + 0.17 * f64::from(j),
                    1.5 + 0.15 * f64::from((i * 3 + j) % 11),
                );
                points.push(world_from_camera.transform_point(c));
            }
        }
        let config = BaConfig {
            focal: camera.focal(),
            huber_px: 1.5,
            max_iterations: 10,
        };
        let rate = DVec3::new(0.2, 1.1, -0.3);
        for true_readout in [0.0, 0.025] {
            let shutter = RollingShutter {
                rate,
                readout_s: true_readout,
            };
            let observations: Vec<(DVec3, Vec2)> = points
                .iter()
                .map(|p| {
                    let pixel = shutter
                        .pixel(&camera, pose.transform_point(*p))
                        .expect("seen");
                    (*p, pixel.as_vec2())
                })
                .collect();
            let mut estimate = ReadoutEstimate::default();
            for _ in 0..MIN_SAMPLES {
                assert_eq!(estimate.readout_s(), None);
                estimate.observe(&camera, &pose, rate, &observations, &config);
            }
            let found = estimate.readout_s().expect("enough samples");
            assert!(
                (found - true_readout).abs() < 0.001,
                "readout {found} s for {true_readout} s"
            );
        }
    }
}
