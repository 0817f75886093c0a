//! Bundle adjustment: Levenberg–Marquardt on reprojection errors with a Huber loss, the point
//! blocks eliminated by the Schur complement (Triggs et al., "Bundle adjustment: a modern
//! synthesis"). Poses are `camera_from_world`, updated on the left by a twist (ω, v); points
//! additively. Residuals are in pixels: `f · (π(R X + t) − x)` with `x` normalised coordinates.

use crate::linalg::cholesky_solve;
use crate::pose::{Se3, skew};
use glam::{DMat3, DVec2, DVec3};

/// One reprojection term.
#[derive(Clone, Copy, Debug)]
pub struct BaObservation {
    pub camera: usize,
    pub point: usize,
    pub normalized: DVec2,
}

/// Settings of the solver.
#[derive(Clone, Copy, Debug)]
pub struct BaConfig {
    /// Focal length (pixels) turning normalised errors into pixels.
    pub focal: f64,
    /// Huber threshold δ in pixels.
    pub huber_px: f64,
    pub max_iterations: usize,
}

/// Residual (pixels) and its Jacobians w.r.t. the camera twist (2×6, as two rows) and the
/// point (2×3). None when the point is behind the camera.
fn project_with_jacobians(
    pose: &Se3,
    point: DVec3,
    observed: DVec2,
    focal: f64,
) -> Option<(DVec2, [[f64; 6]; 2], [DVec3; 2])> {
    let pc = pose.transform_point(point);
    if pc.z < 1e-6 {
        return None;
    }
    let iz = 1.0 / pc.z;
    let residual = (DVec2::new(pc.x * iz, pc.y * iz) - observed) * focal;
    // d(u)/d(pc) rows, scaled by f.
    let du = DVec3::new(iz, 0.0, -pc.x * iz * iz) * focal;
    let dv = DVec3::new(0.0, iz, -pc.y * iz * iz) * focal;
    // d(pc)/dω = −[pc]×, d(pc)/dv = I, d(pc)/dX = R.
    let minus_skew = -skew(pc);
    let rot = pose.rotation_matrix();
    let row = |d: DVec3| -> [f64; 6] {
        let w = minus_skew.transpose() * d;
        [w.x, w.y, w.z, d.x, d.y, d.z]
    };
    let point_row = |d: DVec3| rot.transpose() * d;
    Some((residual, [row(du), row(dv)], [point_row(du), point_row(dv)]))
}

fn huber_weight(error: f64, delta: f64) -> f64 {
    if error <= delta { 1.0 } else { delta / error }
}

fn total_cost(
    poses: &[Se3],
    points: &[DVec3],
    observations: &[BaObservation],
    config: &BaConfig,
) -> f64 {
    observations
        .iter()
        .map(|o| {
            let pc = poses[o.camera].transform_point(points[o.point]);
            if pc.z < 1e-6 {
                return config.huber_px * 100.0;
            }
            let e = ((pc.truncate() / pc.z - o.normalized) * config.focal).length();
            if e <= config.huber_px {
                0.5 * e * e
            } else {
                config.huber_px * (e - 0.5 * config.huber_px)
            }
        })
        .sum()
}

/// Reprojection error in pixels of one observation (infinite behind the camera).
pub fn reprojection_error_px(pose: &Se3, point: DVec3, normalized: DVec2, focal: f64) -> f64 {
    let pc = pose.transform_point(point);
    if pc.z < 1e-6 {
        return f64::INFINITY;
    }
    ((pc.truncate() / pc.z - normalized) * focal).length()
}

/// Local bundle adjustment in place. `fixed[c]` keeps camera `c` still. Returns the final cost.
pub fn bundle_adjust(
    poses: &mut [Se3],
    fixed: &[bool],
    points: &mut [DVec3],
    observations: &[BaObservation],
    config: &BaConfig,
) -> f64 {
    // Free cameras get consecutive slots in the reduced system.
    let mut slot = vec![usize::MAX; poses.len()];
    let mut num_free = 0;
    for (c, s) in slot.iter_mut().enumerate() {
        if !fixed[c] {
            *s = num_free;
            num_free += 1;
        }
    }
    let n = 6 * num_free;
    let mut lambda = 1e-3;
    let mut cost = total_cost(poses, points, observations, config);
    let mut by_point: Vec<Vec<usize>> = vec![Vec::new(); points.len()];
    for (i, o) in observations.iter().enumerate() {
        by_point[o.point].push(i);
    }
    for _ in 0..config.max_iterations {
        // Normal equations: U (cameras), V (points), W (camera × point), gradients.
        let mut u = vec![0.0; n * n];
        let mut gc = vec![0.0; n];
        let mut v = vec![DMat3::ZERO; points.len()];
        let mut gp = vec![DVec3::ZERO; points.len()];
        let mut w: Vec<(usize, usize, [DVec3; 6])> = Vec::with_capacity(observations.len());
        for o in observations {
            let Some((r, jc, jp)) = project_with_jacobians(
                &poses[o.camera],
                points[o.point],
                o.normalized,
                config.focal,
            ) else {
                continue;
            };
            let weight = huber_weight(r.length(), config.huber_px);
            let res = [r.x, r.y];
            for k in 0..2 {
                v[o.point] +=
                    DMat3::from_cols(jp[k] * jp[k].x, jp[k] * jp[k].y, jp[k] * jp[k].z) * weight;
                gp[o.point] += jp[k] * (res[k] * weight);
            }
            let s = slot[o.camera];
            if s == usize::MAX {
                continue;
            }
            let mut wblock = [DVec3::ZERO; 6];
            for k in 0..2 {
                for a in 0..6 {
                    gc[6 * s + a] += jc[k][a] * res[k] * weight;
                    // Upper triangle of the camera's block only (see below).
                    for b in a..6 {
                        u[(6 * s + a) * n + 6 * s + b] += jc[k][a] * jc[k][b] * weight;
                    }
                    wblock[a] += jp[k] * (jc[k][a] * weight);
                }
            }
            w.push((s, o.point, wblock));
        }
        // U is block diagonal and each block symmetric: its lower triangles are the same
        // products as the upper ones.
        for s in 0..num_free {
            for a in 0..6 {
                for b in 0..a {
                    u[(6 * s + a) * n + 6 * s + b] = u[(6 * s + b) * n + 6 * s + a];
                }
            }
        }
        let accepted = lm_step(
            poses,
            &slot,
            points,
            observations,
            config,
            &mut lambda,
            &mut cost,
            &by_point,
            (u, gc, v, gp, w),
            n,
        );
        if !accepted {
            break;
        }
    }
    cost
}

type Normal = (
    Vec<f64>,
    Vec<f64>,
    Vec<DMat3>,
    Vec<DVec3>,
    Vec<(usize, usize, [DVec3; 6])>,
);

/// Tries damped steps until one lowers the cost (true) or the damping explodes (false).
#[allow(clippy::too_many_arguments)]
fn lm_step(
    poses: &mut [Se3],
    slot: &[usize],
    points: &mut [DVec3],
    observations: &[BaObservation],
    config: &BaConfig,
    lambda: &mut f64,
    cost: &mut f64,
    by_point: &[Vec<usize>],
    normal: Normal,
    n: usize,
) -> bool {
    let (u, gc, v, gp, w) = normal;
    // W blocks per point, for the Schur complement.
    let mut w_of_point: Vec<Vec<(usize, [DVec3; 6])>> = vec![Vec::new(); points.len()];
    for (s, p, block) in w {
        w_of_point[p].push((s, block));
    }
    for _attempt in 0..6 {
        let damp = 1.0 + *lambda;
        let v_inv: Vec<Option<DMat3>> = v
            .iter()
            .map(|m| {
                let mut d = *m;
                for k in 0..3 {
                    d.col_mut(k)[k] = m.col(k)[k] * damp + 1e-9;
                }
                (d.determinant().abs() > 1e-18).then(|| d.inverse())
            })
            .collect();
        // S = U − Σ W V⁻¹ Wᵀ, rhs = −g_c + Σ W V⁻¹ g_p.
        let mut s_mat = u.clone();
        for i in 0..n {
            s_mat[i * n + i] = u[i * n + i] * damp + 1e-9;
        }
        let mut rhs: Vec<f64> = gc.iter().map(|g| -g).collect();
        for (p, blocks) in w_of_point.iter().enumerate() {
            let Some(vi) = v_inv[p] else { continue };
            let vg = vi * gp[p];
            for &(sa, wa) in blocks {
                for a in 0..6 {
                    let wv = vi.transpose() * wa[a];
                    rhs[6 * sa + a] += wa[a].dot(vg);
                    for &(sb, wb) in blocks {
                        for b in 0..6 {
                            s_mat[(6 * sa + a) * n + 6 * sb + b] -= wv.dot(wb[b]);
                        }
                    }
                }
            }
        }
        let dc = if n > 0 {
            cholesky_solve(&s_mat, &rhs, n)
        } else {
            Some(Vec::new())
        };
        let Some(dc) = dc else {
            *lambda *= 10.0;
            continue;
        };
        let new_poses: Vec<Se3> = poses
            .iter()
            .enumerate()
            .map(|(c, pose)| match slot[c] {
                usize::MAX => *pose,
                s => pose.updated(
                    DVec3::new(dc[6 * s], dc[6 * s + 1], dc[6 * s + 2]),
                    DVec3::new(dc[6 * s + 3], dc[6 * s + 4], dc[6 * s + 5]),
                ),
            })
            .collect();
        let new_points: Vec<DVec3> = points
            .iter()
            .enumerate()
            .map(|(p, x)| {
                let Some(vi) = v_inv[p] else { return *x };
                // dp = V⁻¹ (−g_p − Wᵀ dc)
                let mut b = -gp[p];
                for &(s, wb) in &w_of_point[p] {
                    for (a, col) in wb.iter().enumerate() {
                        b -= *col * dc[6 * s + a];
                    }
                }
                *x + vi * b
            })
            .collect();
        let new_cost = total_cost(&new_poses, &new_points, observations, config);
        let _ = by_point;
        if new_cost < *cost {
            let improvement = (*cost - new_cost) / cost.max(1e-12);
            poses.copy_from_slice(&new_poses);
            points.copy_from_slice(&new_points);
            *cost = new_cost;
            *lambda = (*lambda * 0.3).max(1e-7);
            return improvement > 1e-6;
        }
        *lambda *= 10.0;
    }
    false
}

/// Motion-only refinement: Gauss–Newton on one `camera_from_world` with the points fixed and a
/// Huber loss. Returns the refined pose.
pub fn refine_pose(pose: Se3, points: &[DVec3], normalized: &[DVec2], config: &BaConfig) -> Se3 {
    let mut pose = pose;
    for _ in 0..config.max_iterations {
        let mut h = [0.0; 36];
        let mut g = [0.0; 6];
        for (x, obs) in points.iter().zip(normalized) {
            let Some((r, jc, _)) = project_with_jacobians(&pose, *x, *obs, config.focal) else {
                continue;
            };
            let weight = huber_weight(r.length(), config.huber_px);
            let res = [r.x, r.y];
            for k in 0..2 {
                for a in 0..6 {
                    g[a] += jc[k][a] * res[k] * weight;
                    // Upper triangle only: the lower one holds the same products.
                    for b in a..6 {
                        h[a * 6 + b] += jc[k][a] * jc[k][b] * weight;
                    }
                }
            }
        }
        for a in 0..6 {
            for b in 0..a {
                h[a * 6 + b] = h[b * 6 + a];
            }
            h[a * 6 + a] += 1e-6;
        }
        let minus_g: Vec<f64> = g.iter().map(|v| -v).collect();
        let Some(d) = cholesky_solve(&h, &minus_g, 6) else {
            break;
        };
        pose = pose.updated(DVec3::new(d[0], d[1], d[2]), DVec3::new(d[3], d[4], d[5]));
        if d.iter().map(|x| x * x).sum::<f64>() < 1e-16 {
            break;
        }
    }
    pose
}
