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
    /// The Sim(3) alignment's scale against 1 (true over estimated size, minus one): 0.03 is a
    /// world 3% too small, −0.37 one 1.59 times too large. Absolute scale, which the ATE hides.
    pub scale_error: f64,
    /// RMSE of positions after an SE(3) alignment (rotation and translation, no scale), metres:
    /// the error with the world's own scale.
    pub ate_se3_m: f64,
    /// Median over consecutive windows of the ATE RMSE, each window aligned on its own, metres.
    pub window_ate_m: f64,
    /// Max / min of the per-window alignment scales (1 = no scale drift).
    pub scale_spread: f64,
    /// Median angle between aligned estimated and true orientations, degrees.
    pub rot_err_deg: f64,
    /// Median screen distance between anchors seen through the aligned and the true pose, pixels.
    pub anchor_px: f64,
    /// The global alignment of camera centres (estimated → true), used for the ATE.
    #[serde(skip)]
    pub alignment: Similarity,
    /// The alignment of whole frames (see [`align_frames`]), used for orientations and anchors.
    #[serde(skip)]
    pub frame_alignment: Similarity,
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

/// The similarity that best aligns the estimated *frames* (orientations, then centres) onto the
/// true ones: the rotation is the quaternion mean of R_true·R_estᵀ (principal eigenvector of
/// Σ q qᵀ), then scale and translation are the least-squares fit of the centres with that
/// rotation fixed. A position-only alignment leaves the rotation about the axes of a flat or
/// straight path poorly determined (1 cm of noise on a 0.7 m-deep arc tilts it by ~1°), which
/// would be charged to the tracker's orientation and anchors; this one is not.
pub fn align_frames(pairs: &[PosePair]) -> Option<Similarity> {
    if pairs.len() < 3 {
        return None;
    }
    let mut m = [0.0f64; 16];
    let reference = rotation(&pairs[0].truth) * rotation(&pairs[0].estimated).inverse();
    for p in pairs {
        let mut q = rotation(&p.truth) * rotation(&p.estimated).inverse();
        if q.dot(reference) < 0.0 {
            q = -q;
        }
        let v = [q.x, q.y, q.z, q.w];
        for r in 0..4 {
            for c in 0..4 {
                m[r * 4 + c] += v[r] * v[c];
            }
        }
    }
    let (values, vectors) = crate::linalg::symmetric_eigen(&m, 4);
    let best = (0..4).max_by(|&a, &b| values[a].total_cmp(&values[b]))?;
    let q = DQuat::from_xyzw(
        vectors[best],
        vectors[4 + best],
        vectors[8 + best],
        vectors[12 + best],
    );
    if q.length().is_nan() || q.length() <= 1e-9 {
        return None;
    }
    let rotation = q.normalize();
    let n = pairs.len() as f64;
    let mean_e = pairs.iter().map(|p| p.estimated.translation).sum::<DVec3>() / n;
    let mean_t = pairs.iter().map(|p| p.truth.translation).sum::<DVec3>() / n;
    let (mut num, mut den) = (0.0, 0.0);
    for p in pairs {
        let e = rotation * (p.estimated.translation - mean_e);
        num += e.dot(p.truth.translation - mean_t);
        den += e.length_squared();
    }
    let scale = if den > 1e-12 { num / den } else { 1.0 };
    Some(Similarity {
        scale,
        rotation,
        translation: mean_t - scale * (rotation * mean_e),
    })
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
    let source: Vec<DVec3> = pairs.iter().map(|p| p.estimated.translation).collect();
    let target: Vec<DVec3> = pairs.iter().map(|p| p.truth.translation).collect();
    let ate_se3_m = align_similarity(&source, &target, false).map_or(f64::NAN, |a| rmse(&a, pairs));
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
    // Orientation and anchors are measured after the frame alignment (see [`align_frames`]).
    let frames = align_frames(pairs).unwrap_or(alignment);
    let rot_err_deg = median(
        pairs
            .iter()
            .map(|p| {
                aligned(&frames, &p.estimated)
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
                let (r, t) = aligned(&frames, &p.estimated);
                let estimated = DAffine3::from_rotation_translation(r, t);
                anchor_shift_px(camera, &anchors, &estimated, &p.truth)
            })
            .collect(),
    );
    Some(TrajectoryErrors {
        ate_rmse_m,
        scale_error: alignment.scale - 1.0,
        ate_se3_m,
        window_ate_m: median(window_errors),
        scale_spread,
        rot_err_deg,
        anchor_px,
        alignment,
        frame_alignment: frames,
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

/// Mean screen distance between the anchors seen through two `world_from_camera` poses, over
/// the anchors the true camera sees inside its image: an anchor out of view is not seen sliding,
/// and the distortion polynomial diverges far outside the image. None when no anchor is in view.
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
            camera.contains(t, 0.0).then(|| e.distance(t))
        })
        .collect();
    (!shifts.is_empty()).then(|| shifts.iter().sum::<f64>() / shifts.len() as f64)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// `num` frames of a wavy path and its estimate by `estimate(index, truth)`.
    fn pairs_of(num: usize, estimate: impl Fn(usize, &DAffine3) -> DAffine3) -> Vec<PosePair> {
        (0..num)
            .map(|i| {
                let f = i as f64 * 0.05;
                let truth = DAffine3::from_rotation_translation(
                    DQuat::from_rotation_y(f.sin() * 0.3),
                    DVec3::new(f.sin(), 0.2 * f.cos(), 0.1 * f),
                );
                PosePair {
                    index: i,
                    estimated: estimate(i, &truth),
                    truth,
                }
            })
            .collect()
    }

    #[test]
    fn a_metric_copy_with_noise_has_no_scale_error_and_its_noise_as_se3_error() {
        let camera = Camera::pinhole(640, 480, 500.0, 500.0, 320.0, 240.0);
        let pairs = pairs_of(200, |i, truth| {
            let noise = 0.01 * if i % 2 == 0 { 1.0 } else { -1.0 };
            let mut estimated = *truth;
            estimated.translation += DVec3::new(noise, 0.0, 0.0);
            estimated
        });
        let errors = trajectory_errors(&pairs, &camera, &pairs[0].truth, 2.0).expect("errors");
        assert!(errors.scale_error.abs() < 0.01, "{}", errors.scale_error);
        assert!(
            (errors.ate_se3_m - 0.01).abs() < 1e-3,
            "{}",
            errors.ate_se3_m
        );
    }

    #[test]
    fn a_scaled_rotated_copy_of_the_truth_has_no_error() {
        let camera = Camera::pinhole(640, 480, 500.0, 500.0, 320.0, 240.0);
        let mapping = DAffine3::from_scale_rotation_translation(
            DVec3::splat(0.3),
            DQuat::from_rotation_z(0.7),
            DVec3::new(1.0, 2.0, 3.0),
        );
        // Estimated = mapping⁻¹ applied to the truth (a similarity of the whole path).
        let inv = mapping.inverse();
        let pairs = pairs_of(300, |_, truth| {
            let r = DQuat::from_rotation_z(-0.7) * DQuat::from_mat3(&truth.matrix3);
            DAffine3::from_rotation_translation(r, inv.transform_point3(truth.translation))
        });
        let errors = trajectory_errors(&pairs, &camera, &pairs[0].truth, 2.0).expect("errors");
        assert!(errors.ate_rmse_m < 1e-9, "ate {}", errors.ate_rmse_m);
        // The copy is 1 / 0.3 times the size: the alignment scales it by 0.3.
        assert!(
            (errors.scale_error - (0.3 - 1.0)).abs() < 1e-6,
            "scale error {}",
            errors.scale_error
        );
        assert!(errors.ate_se3_m > 0.1, "se3 {}", errors.ate_se3_m);
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
