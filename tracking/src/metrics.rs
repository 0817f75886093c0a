//! Trajectory accuracy as the TUM RGB-D benchmark defines it (Sturm et al. 2012): absolute
//! trajectory error after a Sim(3) Umeyama alignment, plus the measures Sylva cares about: error
//! and scale per 100-frame window, orientation error and how far virtual anchors slide on screen.

use crate::camera::Camera;
use crate::linalg::{Similarity, align_similarity};
use glam::{DAffine3, DQuat, DVec2, DVec3};

/// An estimated pose and the true one for the same frame.
#[derive(Clone, Copy, Debug)]
pub struct PosePair {
    pub index: usize,
    pub estimated: DAffine3,
    pub truth: DAffine3,
}

/// Frames per window for `window_ate_m` and `scale_spread`.
pub const WINDOW_FRAMES: usize = 100;

/// The report's error fields.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize)]
pub struct TrajectoryErrors {
    /// RMSE of positions after one Sim(3) alignment over all tracked frames, metres.
    pub ate_rmse_m: f64,
    /// Median over consecutive windows of the ATE RMSE, each window aligned on its own, metres.
    pub window_ate_m: f64,
    /// Max / min of the per-window alignment scales (1 = no scale drift).
    pub scale_spread: f64,
    /// Median angle between aligned estimated and true orientations, degrees.
    pub rot_err_deg: f64,
    /// Median screen distance between anchors seen through the aligned and the true pose, pixels.
    pub anchor_px: f64,
    /// The global alignment (estimated → true).
    #[serde(skip)]
    pub alignment: Similarity,
}

fn rotation(a: &DAffine3) -> DQuat {
    DQuat::from_mat3(&a.matrix3).normalize()
}

fn aligned(alignment: &Similarity, estimated: &DAffine3) -> (DQuat, DVec3) {
    (
        (alignment.rotation * rotation(estimated)).normalize(),
        alignment.transform_point(estimated.translation),
    )
}

fn median(mut v: Vec<f64>) -> f64 {
    if v.is_empty() {
        return f64::NAN;
    }
    v.sort_by(f64::total_cmp);
    v[v.len() / 2]
}

fn rmse(alignment: &Similarity, pairs: &[PosePair]) -> f64 {
    let sum: f64 = pairs
        .iter()
        .map(|p| {
            let (_, position) = aligned(alignment, &p.estimated);
            position.distance_squared(p.truth.translation)
        })
        .sum();
    (sum / pairs.len().max(1) as f64).sqrt()
}

/// Sim(3) alignment of estimated camera centres onto the true ones.
pub fn align(pairs: &[PosePair]) -> Option<Similarity> {
    let source: Vec<DVec3> = pairs.iter().map(|p| p.estimated.translation).collect();
    let target: Vec<DVec3> = pairs.iter().map(|p| p.truth.translation).collect();
    align_similarity(&source, &target, true)
}

/// The error fields for the tracked frames. `first_truth` is the true pose of the first frame
/// and `anchor_depth_m` the depth the anchors sit at in it. None with fewer than 3 pairs.
pub fn trajectory_errors(
    pairs: &[PosePair],
    camera: &Camera,
    first_truth: &DAffine3,
    anchor_depth_m: f64,
) -> Option<TrajectoryErrors> {
    let alignment = align(pairs)?;
    let ate_rmse_m = rmse(&alignment, pairs);
    let mut window_errors = Vec::new();
    let mut window_scales = Vec::new();
    let last = pairs.iter().map(|p| p.index).max().unwrap_or(0);
    for start in (0..=last).step_by(WINDOW_FRAMES) {
        let window: Vec<PosePair> = pairs
            .iter()
            .copied()
            .filter(|p| p.index >= start && p.index < start + WINDOW_FRAMES)
            .collect();
        if window.len() < WINDOW_FRAMES / 2 {
            continue;
        }
        if let Some(a) = align(&window) {
            window_errors.push(rmse(&a, &window));
            window_scales.push(a.scale);
        }
    }
    let scale_spread = match (
        window_scales.iter().copied().reduce(f64::max),
        window_scales.iter().copied().reduce(f64::min),
    ) {
        (Some(max), Some(min)) if min > 0.0 => max / min,
        _ => f64::NAN,
    };
    let rot_err_deg = median(
        pairs
            .iter()
            .map(|p| {
                aligned(&alignment, &p.estimated)
                    .0
                    .angle_between(rotation(&p.truth))
                    .to_degrees()
            })
            .collect(),
    );
    let anchors = anchor_points(camera, first_truth, anchor_depth_m);
    let anchor_px = median(
        pairs
            .iter()
            .filter_map(|p| {
                let (r, t) = aligned(&alignment, &p.estimated);
                let estimated = DAffine3::from_rotation_translation(r, t);
                anchor_shift_px(camera, &anchors, &estimated, &p.truth)
            })
            .collect(),
    );
    Some(TrajectoryErrors {
        ate_rmse_m,
        window_ate_m: median(window_errors),
        scale_spread,
        rot_err_deg,
        anchor_px,
        alignment,
    })
}

/// A 3×3 grid of world points at `depth_m` in front of the first true camera.
pub fn anchor_points(camera: &Camera, first_truth: &DAffine3, depth_m: f64) -> Vec<DVec3> {
    let mut points = Vec::new();
    for j in 1..=3 {
        for i in 1..=3 {
            let pixel = DVec2::new(
                camera.width as f64 * i as f64 / 4.0,
                camera.height as f64 * j as f64 / 4.0,
            );
            let n = camera.normalized_from_pixel(pixel);
            points.push(first_truth.transform_point3(n.extend(1.0) * depth_m));
        }
    }
    points
}

/// Mean screen distance between the anchors seen through two `world_from_camera` poses.
fn anchor_shift_px(
    camera: &Camera,
    anchors: &[DVec3],
    estimated: &DAffine3,
    truth: &DAffine3,
) -> Option<f64> {
    let (est_inv, truth_inv) = (estimated.inverse(), truth.inverse());
    let shifts: Vec<f64> = anchors
        .iter()
        .filter_map(|a| {
            let e = camera.pixel_from_camera(est_inv.transform_point3(*a))?;
            let t = camera.pixel_from_camera(truth_inv.transform_point3(*a))?;
            Some(e.distance(t))
        })
        .collect();
    (!shifts.is_empty()).then(|| shifts.iter().sum::<f64>() / shifts.len() as f64)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_scaled_rotated_copy_of_the_truth_has_no_error() {
        let camera = Camera::pinhole(640, 480, 500.0, 500.0, 320.0, 240.0);
        let mapping = DAffine3::from_scale_rotation_translation(
            DVec3::splat(0.3),
            DQuat::from_rotation_z(0.7),
            DVec3::new(1.0, 2.0, 3.0),
        );
        let pairs: Vec<PosePair> = (0..300)
            .map(|i| {
                let f = i as f64 * 0.05;
                let truth = DAffine3::from_rotation_translation(
                    DQuat::from_rotation_y(f.sin() * 0.3),
                    DVec3::new(f.sin(), 0.2 * f.cos(), 0.1 * f),
                );
                // Estimated = mapping⁻¹ applied to the truth (a similarity of the whole path).
                let inv = mapping.inverse();
                let r = DQuat::from_rotation_z(-0.7) * DQuat::from_mat3(&truth.matrix3);
                let estimated =
                    DAffine3::from_rotation_translation(r, inv.transform_point3(truth.translation));
                PosePair {
                    index: i,
                    estimated,
                    truth,
                }
            })
            .collect();
        let errors = trajectory_errors(&pairs, &camera, &pairs[0].truth, 2.0).expect("errors");
        assert!(errors.ate_rmse_m < 1e-9, "ate {}", errors.ate_rmse_m);
        assert!(
            (errors.scale_spread - 1.0).abs() < 1e-6,
            "spread {}",
            errors.scale_spread
        );
        assert!(
            errors.rot_err_deg < 1e-4 && errors.anchor_px < 1e-6,
            "{errors:?}"
        );
    }
}
