//! A small pure-Rust corner detector for data-driven tests (no OpenCV here).

use glam::Vec2;

/// Shi–Tomasi corners: minimum eigenvalue of the 5×5 structure tensor of Sobel gradients,
/// local maxima in 7×7 above 0.05 % of the strongest, at least `min_distance_px` apart, strongest first.
pub fn shi_tomasi(
    grey: &[f32],
    width: usize,
    height: usize,
    max_corners: usize,
    min_distance_px: usize,
) -> Vec<Vec2> {
    let at = |x: usize, y: usize| grey[y * width + x];
    let (mut xx, mut yy, mut xy) = (
        vec![0f32; width * height],
        vec![0f32; width * height],
        vec![0f32; width * height],
    );
    for y in 1..height - 1 {
        for x in 1..width - 1 {
            let gx = at(x + 1, y - 1) + 2.0 * at(x + 1, y) + at(x + 1, y + 1)
                - at(x - 1, y - 1)
                - 2.0 * at(x - 1, y)
                - at(x - 1, y + 1);
            let gy = at(x - 1, y + 1) + 2.0 * at(x, y + 1) + at(x + 1, y + 1)
                - at(x - 1, y - 1)
                - 2.0 * at(x, y - 1)
                - at(x + 1, y - 1);
            let i = y * width + x;
            (xx[i], yy[i], xy[i]) = (gx * gx, gy * gy, gx * gy);
        }
    }
    let mut score = vec![0f32; width * height];
    for y in 3..height - 3 {
        for x in 3..width - 3 {
            let (mut a, mut b, mut c) = (0.0, 0.0, 0.0);
            for dy in 0..5 {
                for dx in 0..5 {
                    let i = (y + dy - 2) * width + x + dx - 2;
                    (a, b, c) = (a + xx[i], b + yy[i], c + xy[i]);
                }
            }
            score[y * width + x] = 0.5 * (a + b) - (0.25 * (a - b) * (a - b) + c * c).sqrt();
        }
    }
    let max_score = score.iter().copied().fold(0.0, f32::max);
    let mut candidates: Vec<(f32, usize, usize)> = Vec::new();
    for y in 6..height - 6 {
        for x in 6..width - 6 {
            let s = score[y * width + x];
            if s < 0.0005 * max_score {
                continue;
            }
            let is_max =
                (y - 3..=y + 3).all(|ny| (x - 3..=x + 3).all(|nx| score[ny * width + nx] <= s));
            if is_max {
                candidates.push((s, x, y));
            }
        }
    }
    candidates.sort_by(|a, b| b.0.total_cmp(&a.0));
    let cell = min_distance_px.max(1);
    let (grid_w, grid_h) = (width / cell + 1, height / cell + 1);
    let mut taken = vec![false; grid_w * grid_h];
    let mut corners = Vec::new();
    for (_, x, y) in candidates {
        let (gx, gy) = (x / cell, y / cell);
        let near = (gy.saturating_sub(1)..=(gy + 1).min(grid_h - 1)).any(|ny| {
            (gx.saturating_sub(1)..=(gx + 1).min(grid_w - 1)).any(|nx| taken[ny * grid_w + nx])
        });
        if near {
            continue;
        }
        taken[gy * grid_w + gx] = true;
        corners.push(Vec2::new(x as f32, y as f32));
        if corners.len() >= max_corners {
            break;
        }
    }
    corners
}
