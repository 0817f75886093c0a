//! Shi–Tomasi corners ("good features to track", Shi and Tomasi 1994): the smaller eigenvalue
//! of the structure tensor (3 × 3 Sobel gradients summed over a 3 × 3 block), local maxima above
//! 1% of the strongest, taken strongest first at least a minimum distance apart.

use crate::frame::GrayImage;
use glam::Vec2;

/// Smaller eigenvalue of each pixel's structure tensor, row-major (borders reflected, as
/// OpenCV's `BORDER_REFLECT_101`). Gradients are unscaled Sobel sums.
pub fn min_eigenvalues(image: &GrayImage) -> Vec<f32> {
    let (w, h) = (image.width as usize, image.height as usize);
    if w < 2 || h < 2 {
        return vec![0.0; w * h];
    }
    let reflect = |i: isize, n: usize| -> usize {
        let n = n as isize;
        let r = if i < 0 {
            -i
        } else if i >= n {
            2 * n - 2 - i
        } else {
            i
        };
        r.clamp(0, n - 1) as usize
    };
    let px = |x: usize, y: usize| f32::from(image.pixels[y * w + x]);
    // Gradient products per pixel.
    let mut xx = vec![0.0f32; w * h];
    let mut xy = vec![0.0f32; w * h];
    let mut yy = vec![0.0f32; w * h];
    let cols: Vec<(usize, usize)> = (0..w)
        .map(|x| (reflect(x as isize - 1, w), reflect(x as isize + 1, w)))
        .collect();
    for y in 0..h {
        let (ya, yb) = (reflect(y as isize - 1, h), reflect(y as isize + 1, h));
        for (x, &(xa, xb)) in cols.iter().enumerate() {
            let dx = (px(xb, ya) - px(xa, ya))
                + 2.0 * (px(xb, y) - px(xa, y))
                + (px(xb, yb) - px(xa, yb));
            let dy = (px(xa, yb) - px(xa, ya))
                + 2.0 * (px(x, yb) - px(x, ya))
                + (px(xb, yb) - px(xb, ya));
            let i = y * w + x;
            xx[i] = dx * dx;
            xy[i] = dx * dy;
            yy[i] = dy * dy;
        }
    }
    // 3 × 3 box sums: horizontal then vertical.
    let box3 = |v: &[f32]| -> Vec<f32> {
        let mut horizontal = vec![0.0f32; w * h];
        for y in 0..h {
            let row = &v[y * w..(y + 1) * w];
            for (x, &(xa, xb)) in cols.iter().enumerate() {
                horizontal[y * w + x] = row[xa] + row[x] + row[xb];
            }
        }
        let mut out = vec![0.0f32; w * h];
        for y in 0..h {
            let (ya, yb) = (reflect(y as isize - 1, h), reflect(y as isize + 1, h));
            for x in 0..w {
                out[y * w + x] =
                    horizontal[ya * w + x] + horizontal[y * w + x] + horizontal[yb * w + x];
            }
        }
        out
    };
    let (a, b, c) = (box3(&xx), box3(&xy), box3(&yy));
    a.iter()
        .zip(&b)
        .zip(&c)
        .map(|((&a, &b), &c)| {
            let half_a = 0.5 * a;
            let half_c = 0.5 * c;
            (half_a + half_c) - ((half_a - half_c) * (half_a - half_c) + b * b).sqrt()
        })
        .collect()
}

/// Shi–Tomasi corners at least `min_distance_px` away from each other and from `existing`
/// (a disc of that radius around each existing point is excluded), strongest first, at most
/// `max_corners`. Quality level 0.01 of the strongest response, 3 × 3 non-maximum suppression,
/// the one-pixel border excluded: OpenCV's `goodFeaturesToTrack` with the tracker's settings.
pub fn detect_corners(
    image: &GrayImage,
    max_corners: usize,
    min_distance_px: f32,
    existing: &[Vec2],
) -> Vec<Vec2> {
    let (w, h) = (image.width as usize, image.height as usize);
    if max_corners == 0 || w < 3 || h < 3 || image.pixels.len() != w * h {
        return Vec::new();
    }
    let eig = min_eigenvalues(image);
    let max = eig.iter().copied().fold(0.0f32, f32::max);
    if max <= 0.0 {
        return Vec::new();
    }
    let threshold = 0.01 * max;
    let mut allowed = vec![true; w * h];
    let r = min_distance_px.round() as i64;
    for p in existing {
        let (cx, cy) = (p.x.round() as i64, p.y.round() as i64);
        for y in (cy - r).max(0)..=(cy + r).min(h as i64 - 1) {
            for x in (cx - r).max(0)..=(cx + r).min(w as i64 - 1) {
                if (x - cx) * (x - cx) + (y - cy) * (y - cy) <= r * r {
                    allowed[y as usize * w + x as usize] = false;
                }
            }
        }
    }
    let mut candidates: Vec<(f32, usize)> = Vec::new();
    for y in 1..h - 1 {
        for x in 1..w - 1 {
            let i = y * w + x;
            let v = eig[i];
            if v <= threshold || !allowed[i] {
                continue;
            }
            let is_max = (y - 1..=y + 1).all(|yy| (x - 1..=x + 1).all(|xx| eig[yy * w + xx] <= v));
            if is_max {
                candidates.push((v, i));
            }
        }
    }
    candidates.sort_unstable_by(|a, b| b.0.total_cmp(&a.0).then(a.1.cmp(&b.1)));
    let min_d = min_distance_px.max(0.0);
    let mut corners: Vec<Vec2> = Vec::new();
    if min_d < 1.0 {
        corners.extend(
            candidates
                .iter()
                .take(max_corners)
                .map(|&(_, i)| Vec2::new((i % w) as f32, (i / w) as f32)),
        );
        return corners;
    }
    // Accepted corners bucketed on a grid of cells `min_d` wide: only the 3 × 3 cells around a
    // candidate can hold one that is too near.
    let cell = min_d;
    let gw = (w as f32 / cell).ceil() as usize + 1;
    let gh = (h as f32 / cell).ceil() as usize + 1;
    let mut grid: Vec<Vec<Vec2>> = vec![Vec::new(); gw * gh];
    let min_d2 = min_d * min_d;
    for &(_, i) in &candidates {
        let p = Vec2::new((i % w) as f32, (i / w) as f32);
        let (gx, gy) = ((p.x / cell) as usize, (p.y / cell) as usize);
        let near = (gy.saturating_sub(1)..=(gy + 1).min(gh - 1)).any(|cy| {
            (gx.saturating_sub(1)..=(gx + 1).min(gw - 1)).any(|cx| {
                grid[cy * gw + cx]
                    .iter()
                    .any(|q| (*q - p).length_squared() < min_d2)
            })
        });
        if near {
            continue;
        }
        grid[gy * gw + gx].push(p);
        corners.push(p);
        if corners.len() == max_corners {
            break;
        }
    }
    corners
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A grey image with dark squares on a light background.
    fn checker(w: u32, h: u32, squares: &[(u32, u32, u32)]) -> GrayImage {
        let mut img = GrayImage::filled(w, h, 200);
        for &(x0, y0, s) in squares {
            for y in y0..y0 + s {
                for x in x0..x0 + s {
                    img.pixels[(y * w + x) as usize] = 40;
                }
            }
        }
        img
    }

    #[test]
    fn finds_the_four_corners_of_a_square() {
        let img = checker(80, 60, &[(20, 15, 30)]);
        let corners = detect_corners(&img, 10, 5.0, &[]);
        assert_eq!(corners.len(), 4, "{corners:?}");
        for truth in [(20.0, 15.0), (50.0, 15.0), (20.0, 45.0), (50.0, 45.0)] {
            let t = Vec2::new(truth.0, truth.1);
            let nearest = corners
                .iter()
                .map(|c| (*c - t).length())
                .fold(f32::MAX, f32::min);
            assert!(nearest <= 1.5, "corner near {t} missing in {corners:?}");
        }
    }

    #[test]
    fn respects_distance_existing_points_and_the_cap() {
        let squares: Vec<(u32, u32, u32)> = (0..5)
            .flat_map(|i| (0..4).map(move |j| (10 + 30 * i, 10 + 30 * j, 12)))
            .collect();
        let img = checker(170, 130, &squares);
        let all = detect_corners(&img, 1000, 10.0, &[]);
        assert_eq!(all.len(), 80, "four corners per square");
        for (k, a) in all.iter().enumerate() {
            for b in &all[k + 1..] {
                assert!((*a - *b).length() >= 10.0);
            }
        }
        let existing = [Vec2::new(10.0, 10.0)];
        let without = detect_corners(&img, 1000, 10.0, &existing);
        assert_eq!(without.len(), 79);
        assert!(without.iter().all(|c| (*c - existing[0]).length() > 10.0));
        assert_eq!(detect_corners(&img, 7, 10.0, &[]).len(), 7);
        assert!(detect_corners(&GrayImage::filled(50, 50, 9), 10, 5.0, &[]).is_empty());
        assert!(detect_corners(&GrayImage::filled(2, 2, 9), 10, 5.0, &[]).is_empty());
    }
}
