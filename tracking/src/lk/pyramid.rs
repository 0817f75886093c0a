//! The image pyramid Lucas–Kanade searches: each level a 5-tap Gaussian then every other pixel
//! (as OpenCV's `pyrDown`), stored with a mirrored border so a window may hang over the edge.

use super::{LEVELS, PAD, SLACK};
use crate::frame::GrayImage;
use glam::Vec2;
use std::sync::Arc;

/// One level: the image padded by [`PAD`] pixels of mirrored border.
#[derive(Default)]
pub(super) struct Level {
    pub(super) width: usize,
    pub(super) height: usize,
    pub(super) stride: usize,
    pub(super) image: Vec<f32>,
}

/// An image pyramid, built once per frame and reused by every track call; clones share it.
#[derive(Clone)]
pub struct Pyramid {
    pub(super) levels: Arc<Vec<Level>>,
}

/// Memory reused from one pyramid build to the next (a frame's buffers are large enough that
/// fresh ones cost page faults and zeroing every frame).
#[derive(Default)]
pub struct PyramidScratch {
    base: Vec<f32>,
    rows: Vec<f32>,
    down: Vec<Vec<f32>>,
    pub(super) spare: Option<Vec<Level>>,
}

impl Pyramid {
    /// The pyramid of an 8-bit image: each level a 5-tap Gaussian (1 4 6 4 1)/16 then every
    /// other pixel, as OpenCV's `pyrDown`.
    pub fn build(image: &GrayImage) -> Self {
        Self::build_with(image, &mut PyramidScratch::default())
    }

    /// [`Pyramid::build`] in memory from `scratch` (same result).
    pub fn build_with(image: &GrayImage, scratch: &mut PyramidScratch) -> Self {
        let (width, height) = (image.width as usize, image.height as usize);
        scratch.base.clear();
        scratch.base.extend(image.pixels.iter().map(|&p| p as f32));
        scratch.down.resize_with(LEVELS, Vec::new);
        let mut levels = scratch.spare.take().unwrap_or_default();
        levels.resize_with(LEVELS + 1, Level::default);
        let (mut w, mut h) = (width, height);
        levels[0].fill(&scratch.base, w, h);
        for (k, level) in levels.iter_mut().enumerate().skip(1) {
            let (below, this) = scratch.down.split_at_mut(k - 1);
            let src = below.last().unwrap_or(&scratch.base);
            (w, h) = pyr_down(src, w, h, &mut scratch.rows, &mut this[0]);
            level.fill(&this[0], w, h);
        }
        Self {
            levels: Arc::new(levels),
        }
    }

    /// Hands the pyramid's memory to `scratch` for the next build, unless a clone (a
    /// keyframe's) still shares it.
    pub fn recycle(self, scratch: &mut PyramidScratch) {
        if let Ok(levels) = Arc::try_unwrap(self.levels) {
            scratch.spare = Some(levels);
        }
    }

    /// Image size of the base level.
    pub fn size(&self) -> (usize, usize) {
        (self.levels[0].width, self.levels[0].height)
    }
}

/// Mirror index (reflect-101: `-1 → 1`, `n → n − 2`).
fn reflect(i: isize, n: usize) -> usize {
    let n = n as isize;
    if n == 1 {
        return 0;
    }
    let period = 2 * (n - 1);
    let mut i = i.rem_euclid(period);
    if i >= n {
        i = period - i;
    }
    i as usize
}

/// One level down from `src` (`width` × `height`) into `dst`, through `rows`; returns the new
/// size.
fn pyr_down(
    src: &[f32],
    width: usize,
    height: usize,
    rows: &mut Vec<f32>,
    dst: &mut Vec<f32>,
) -> (usize, usize) {
    const K: [f32; 5] = [1.0 / 16.0, 4.0 / 16.0, 6.0 / 16.0, 4.0 / 16.0, 1.0 / 16.0];
    let (w, h) = (width.div_ceil(2), height.div_ceil(2));
    // Horizontal filter and decimation: height × w.
    rows.clear();
    rows.resize(height * w, 0.0);
    for y in 0..height {
        let src_row = &src[y * width..(y + 1) * width];
        let out = &mut rows[y * w..(y + 1) * w];
        for (x, o) in out.iter_mut().enumerate() {
            let c = 2 * x;
            *o = if c >= 2 && c + 2 < width {
                let t = &src_row[c - 2..c + 3];
                K[0] * t[0] + K[1] * t[1] + K[2] * t[2] + K[3] * t[3] + K[4] * t[4]
            } else {
                (0..5)
                    .map(|k| K[k] * src_row[reflect(c as isize + k as isize - 2, width)])
                    .sum()
            };
        }
    }
    // Vertical filter and decimation.
    dst.clear();
    dst.resize(w * h, 0.0);
    for y in 0..h {
        let c = 2 * y as isize;
        let taps: [usize; 5] = std::array::from_fn(|k| reflect(c + k as isize - 2, height));
        let out = &mut dst[y * w..(y + 1) * w];
        for (k, &t) in taps.iter().enumerate() {
            let row = &rows[t * w..(t + 1) * w];
            for (o, r) in out.iter_mut().zip(row) {
                *o += K[k] * r;
            }
        }
    }
    (w, h)
}

impl Level {
    /// This level made from `pixels` (`width` × `height`), reusing its memory.
    fn fill(&mut self, pixels: &[f32], width: usize, height: usize) {
        let stride = width + 2 * PAD + SLACK;
        let rows = height + 2 * PAD;
        self.image.resize(stride * rows, 0.0);
        for y in 0..rows {
            let sy = reflect(y as isize - PAD as isize, height);
            let src = &pixels[sy * width..(sy + 1) * width];
            let dst = &mut self.image[y * stride..(y + 1) * stride];
            dst[PAD..PAD + width].copy_from_slice(src);
            for x in (0..PAD).chain(PAD + width..stride) {
                dst[x] = src[reflect(x as isize - PAD as isize, width)];
            }
        }
        (self.width, self.height, self.stride) = (width, height, stride);
    }

    /// Top-left sample (in the padded plane) and bilinear weights of the `side`-pixel window
    /// centred on `centre` (level pixels); None when the window leaves the padded plane.
    pub(super) fn window(&self, centre: Vec2, side: usize) -> Option<(usize, [f32; 4])> {
        let corner = centre - Vec2::splat((side / 2) as f32);
        let (fx, fy) = (corner.x.floor(), corner.y.floor());
        if !(fx.is_finite() && fy.is_finite()) {
            return None;
        }
        let (ix, iy) = (fx as isize + PAD as isize, fy as isize + PAD as isize);
        let limit_x = (self.stride - SLACK - side - 1) as isize;
        let limit_y = (self.height + 2 * PAD - side - 1) as isize;
        if ix < 0 || iy < 0 || ix > limit_x || iy > limit_y {
            return None;
        }
        let (a, b) = (corner.x - fx, corner.y - fy);
        let weights = [(1.0 - a) * (1.0 - b), a * (1.0 - b), (1.0 - a) * b, a * b];
        Some((iy as usize * self.stride + ix as usize, weights))
    }
}
