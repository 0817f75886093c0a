//! The real crown segmented in the footage, guided by the hull: in a frame, the hull's
//! projection (a little dilated) is where the crown can be; a colour model of the background (a
//! ring of pixels just outside the projection, in the same frame) against one of the crown (the
//! projection's inside, re-estimated from what it classifies, a few rounds) decides each pixel.
//! The crown's silhouettes from many frames then carve the hull again (a voxel stays where
//! nearly every view sees crown at it): the traced outlines are rough and convex, the
//! segmented silhouettes follow the real crown's lobes and gaps.

use glam::{DVec2, DVec3};

use super::footage::TrackedFootage;
use super::hull::Hull;

/// A frame's colour image, RGB8 at the camera's size (the CLI reads the footage's files).
pub type FrameSource<'a> = &'a (dyn Fn(usize) -> Option<image::RgbImage> + Sync);

/// The crown as segmented in one frame, row-major.
pub struct CrownMask {
    pub frame: usize,
    pub width: u32,
    pub height: u32,
    pub inside: Vec<bool>,
    /// Distance (pixels) from each pixel to the nearest crown pixel (0 on the crown).
    distance: Vec<f32>,
}

impl CrownMask {
    /// Whether raw pixel `pixel` lies within `slack_px` of the crown.
    pub fn near(&self, pixel: DVec2, slack_px: f32) -> bool {
        let (x, y) = (pixel.x.round(), pixel.y.round());
        if x < 0.0 || y < 0.0 || x >= self.width as f64 || y >= self.height as f64 {
            return false;
        }
        self.distance[y as usize * self.width as usize + x as usize] <= slack_px
    }

    /// 8-bit grey PNG: 255 on the crown.
    pub fn save_png(&self, path: &std::path::Path) -> anyhow::Result<()> {
        super::silhouette::save_mask_png(path, &self.inside, self.width, self.height)
    }

    pub fn area_px(&self) -> usize {
        self.inside.iter().filter(|&&v| v).count()
    }
}

/// Colour levels per channel of the colour models.
const LEVELS: usize = 16;
/// The models' histograms are smoothed by a Gaussian of this many levels (σ).
const SMOOTH_LEVELS: f32 = 1.0;
/// Pixels past the hull's projection that may still be crown (pose error, the voxels' size).
const REGION_PX: f32 = 3.0;
/// The background ring: this far from the hull's projection, pixels.
const RING_PX: (f32, f32) = (8.0, 25.0);
/// The crown's first colour model: pixels this deep inside the projection.
const CORE_PX: f32 = 4.0;
/// Rounds of re-estimating the crown's colours from its classified pixels.
const ROUNDS: usize = 3;

/// A smoothed colour histogram (a density over RGB at [`LEVELS`] per channel).
pub(super) struct ColourModel {
    density: Vec<f32>,
}

fn bin(p: &image::Rgb<u8>) -> usize {
    let level = |v: u8| v as usize * LEVELS / 256;
    (level(p[0]) * LEVELS + level(p[1])) * LEVELS + level(p[2])
}

impl ColourModel {
    fn of(image: &image::RgbImage, pick: impl Fn(usize) -> bool) -> Option<Self> {
        Self::of_samples(
            image
                .pixels()
                .enumerate()
                .filter(|(i, _)| pick(*i))
                .map(|(_, p)| *p),
        )
    }

    /// The model of the colours `samples`; None without any.
    pub(super) fn of_samples(samples: impl Iterator<Item = image::Rgb<u8>>) -> Option<Self> {
        let mut counts = vec![0.0f32; LEVELS * LEVELS * LEVELS];
        let mut total = 0usize;
        for p in samples {
            counts[bin(&p)] += 1.0;
            total += 1;
        }
        if total == 0 {
            return None;
        }
        let radius = (3.0 * SMOOTH_LEVELS).ceil() as i64;
        let kernel: Vec<f32> = (-radius..=radius)
            .map(|d| (-0.5 * (d as f32 / SMOOTH_LEVELS).powi(2)).exp())
            .collect();
        let n = LEVELS as i64;
        for axis in 0..3 {
            let stride = [LEVELS * LEVELS, LEVELS, 1][axis] as i64;
            let mut blurred = vec![0.0f32; counts.len()];
            for (i, out) in blurred.iter_mut().enumerate() {
                let coordinate = (i as i64 / stride) % n;
                let mut sum = 0.0;
                for (k, w) in kernel.iter().enumerate() {
                    let c = coordinate + k as i64 - radius;
                    if (0..n).contains(&c) {
                        sum += w * counts[(i as i64 + (c - coordinate) * stride) as usize];
                    }
                }
                *out = sum;
            }
            counts = blurred;
        }
        let sum: f32 = counts.iter().sum();
        let floor = 1e-3 * sum / counts.len() as f32;
        Some(Self {
            density: counts.iter().map(|c| (c + floor) / sum).collect(),
        })
    }

    /// The density at colour `p`.
    pub(super) fn at(&self, p: &image::Rgb<u8>) -> f32 {
        self.density[bin(p)]
    }
}

/// Chamfer (1, √2) distance from every pixel to the nearest `true` one: exact along the axes
/// and diagonals, at most 8.3% over the Euclidean between them.
fn distance_to(mask: &[bool], width: usize, height: usize) -> Vec<f32> {
    let mut d: Vec<f32> = mask
        .iter()
        .map(|&m| if m { 0.0 } else { f32::INFINITY })
        .collect();
    let diagonal = std::f32::consts::SQRT_2;
    for y in 0..height {
        for x in 0..width {
            let i = y * width + x;
            let mut v = d[i];
            if x > 0 {
                v = v.min(d[i - 1] + 1.0);
            }
            if y > 0 {
                v = v.min(d[i - width] + 1.0);
                if x > 0 {
                    v = v.min(d[i - width - 1] + diagonal);
                }
                if x + 1 < width {
                    v = v.min(d[i - width + 1] + diagonal);
                }
            }
            d[i] = v;
        }
    }
    for y in (0..height).rev() {
        for x in (0..width).rev() {
            let i = y * width + x;
            let mut v = d[i];
            if x + 1 < width {
                v = v.min(d[i + 1] + 1.0);
            }
            if y + 1 < height {
                v = v.min(d[i + width] + 1.0);
                if x + 1 < width {
                    v = v.min(d[i + width + 1] + diagonal);
                }
                if x > 0 {
                    v = v.min(d[i + width - 1] + diagonal);
                }
            }
            d[i] = v;
        }
    }
    d
}

/// The hull's voxels seen from `frame`: each voxel a disc of its projected size.
pub fn hull_projection(footage: &TrackedFootage, frame: usize, hull: &Hull) -> Vec<bool> {
    let (width, height) = (footage.camera.width as i64, footage.camera.height as i64);
    let mut inside = vec![false; (width * height) as usize];
    let Some(pose) = footage.world_from_camera.get(frame).copied().flatten() else {
        return inside;
    };
    let camera_from_world = pose.inverse();
    let focal = 0.5 * (footage.camera.fx + footage.camera.fy);
    for p in hull.voxels() {
        let Some((pixel, depth)) = footage.pixel_and_depth(&camera_from_world, p) else {
            continue;
        };
        // Half the voxel's diagonal, in pixels at its depth.
        let r = 0.87 * hull.voxel_m * focal / depth;
        let (x0, x1) = ((pixel.x - r).ceil() as i64, (pixel.x + r).floor() as i64);
        let (y0, y1) = ((pixel.y - r).ceil() as i64, (pixel.y + r).floor() as i64);
        for y in y0.max(0)..=y1.min(height - 1) {
            for x in x0.max(0)..=x1.min(width - 1) {
                if DVec2::new(x as f64, y as f64).distance_squared(pixel) <= r * r {
                    inside[(y * width + x) as usize] = true;
                }
            }
        }
    }
    inside
}

/// Segments the crown in `image` (the footage's frame `frame`) where the hull's projection
/// `projection` says it can be. `None` when the frame shows no background around the hull (no
/// colour model of it) or nothing of the hull.
pub fn segment(frame: usize, image: &image::RgbImage, projection: &[bool]) -> Option<CrownMask> {
    let (width, height) = (image.width() as usize, image.height() as usize);
    if projection.len() != width * height {
        return None;
    }
    let outside = distance_to(projection, width, height);
    let not_projected: Vec<bool> = projection.iter().map(|&p| !p).collect();
    let depth = distance_to(&not_projected, width, height);
    let background = ColourModel::of(image, |i| (RING_PX.0..=RING_PX.1).contains(&outside[i]))?;
    let mut crown = ColourModel::of(image, |i| depth[i] >= CORE_PX)
        .or_else(|| ColourModel::of(image, |i| projection[i]))?;
    let pixels: Vec<usize> = image.pixels().map(bin).collect();
    let mut inside = vec![false; width * height];
    for round in 0..ROUNDS {
        for (i, v) in inside.iter_mut().enumerate() {
            *v =
                outside[i] <= REGION_PX && crown.density[pixels[i]] > background.density[pixels[i]];
        }
        if round + 1 < ROUNDS {
            match ColourModel::of(image, |i| inside[i]) {
                Some(model) => crown = model,
                None => break,
            }
        }
    }
    let distance = distance_to(&inside, width, height);
    Some(CrownMask {
        frame,
        width: width as u32,
        height: height as u32,
        inside,
        distance,
    })
}

/// How many frames are segmented to carve the hull again (evenly over the tracked ones, the
/// marked ones always).
pub const CARVE_FRAMES: usize = 24;
/// A voxel stays when at least this fraction of the views that see it see crown there.
const AGREE: f64 = 0.9;
/// Slack for the tracker's pose error when testing a voxel against a silhouette, pixels.
const CARVE_SLACK_PX: f32 = 1.5;

/// The frames to segment: the marked ones and [`CARVE_FRAMES`] spread evenly over the tracked.
pub fn carve_frames(footage: &TrackedFootage, marked: &[usize]) -> Vec<usize> {
    let tracked: Vec<usize> = (footage.world_from_camera.iter().enumerate())
        .filter_map(|(i, p)| p.is_some().then_some(i))
        .collect();
    let mut frames: Vec<usize> = marked.to_vec();
    if !tracked.is_empty() {
        let n = CARVE_FRAMES.min(tracked.len());
        for k in 0..n {
            frames.push(tracked[(k * (tracked.len() - 1)) / (n - 1).max(1)]);
        }
    }
    frames.sort_unstable();
    frames.dedup();
    frames
}

/// The crown segmented in `frames` (those whose image loads and shows background around the
/// hull).
pub fn segment_frames(
    footage: &TrackedFootage,
    hull: &Hull,
    frames: &[usize],
    images: FrameSource,
) -> Vec<CrownMask> {
    use rayon::prelude::*;
    frames
        .par_iter()
        .filter_map(|&frame| {
            let image = images(frame)?;
            let (w, h) = (footage.camera.width, footage.camera.height);
            if (image.width(), image.height()) != (w, h) {
                return None;
            }
            let projection = hull_projection(footage, frame, hull);
            segment(frame, &image, &projection)
        })
        .collect()
}

/// The hull carved again by the segmented silhouettes: a voxel stays when it lies on the crown
/// (within the slack) in at least [`AGREE`] of the views it projects into. Falls back to `hull`
/// itself when that would leave too little (fewer than a tenth of its voxels: the segmentation
/// failed).
pub fn carve_by_silhouettes(footage: &TrackedFootage, hull: &Hull, masks: &[CrownMask]) -> Hull {
    if masks.is_empty() {
        return hull.clone();
    }
    let poses: Vec<_> = masks
        .iter()
        .map(|m| footage.world_from_camera[m.frame].map(|p| p.inverse()))
        .collect();
    let mut carved = hull.clone();
    let [nx, ny, nz] = hull.dims;
    for k in 0..nz {
        for j in 0..ny {
            for i in 0..nx {
                let index = (k * ny + j) * nx + i;
                if !hull.occupied[index] {
                    continue;
                }
                let p: DVec3 = hull.centre(i, j, k);
                let (mut seen, mut on_crown) = (0usize, 0usize);
                for (mask, pose) in masks.iter().zip(&poses) {
                    let Some(camera_from_world) = pose else {
                        continue;
                    };
                    let Some((pixel, _)) = footage.pixel_and_depth(camera_from_world, p) else {
                        continue;
                    };
                    let in_image = pixel.x >= 0.0
                        && pixel.y >= 0.0
                        && pixel.x < mask.width as f64
                        && pixel.y < mask.height as f64;
                    if in_image {
                        seen += 1;
                        on_crown += mask.near(pixel, CARVE_SLACK_PX) as usize;
                    }
                }
                carved.occupied[index] = seen == 0 || on_crown as f64 >= AGREE * seen as f64;
            }
        }
    }
    if carved.num_voxels() * 10 < hull.num_voxels() {
        hull.clone()
    } else {
        carved
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_dark_disc_on_a_bright_sky_is_segmented_inside_a_looser_projection() {
        let (w, h) = (120u32, 100u32);
        let centre = DVec2::new(60.0, 50.0);
        let on_disc = |x: u32, y: u32| DVec2::new(x as f64, y as f64).distance(centre) <= 20.0;
        // Foliage: dark greens, speckled; sky: light blue, a little noisy.
        let image = image::RgbImage::from_fn(w, h, |x, y| {
            let n = ((x * 7 + y * 13) % 11) as u8;
            if on_disc(x, y) {
                image::Rgb([30 + n, 70 + 2 * n, 25 + n])
            } else {
                image::Rgb([200 + n, 220 + n, 245])
            }
        });
        // The hull's projection: a square around the disc, 8 px larger on every side.
        let projection: Vec<bool> = (0..h)
            .flat_map(|y| (0..w).map(move |x| (32..=88).contains(&x) && (22..=78).contains(&y)))
            .collect();
        let mask = segment(0, &image, &projection).expect("a background ring");
        let (mut both, mut either) = (0, 0);
        for y in 0..h {
            for x in 0..w {
                let (a, b) = (mask.inside[(y * w + x) as usize], on_disc(x, y));
                both += (a && b) as usize;
                either += (a || b) as usize;
            }
        }
        let iou = both as f64 / either as f64;
        assert!(iou > 0.97, "IoU {iou:.3} with the disc");
        assert!(mask.near(centre, 0.0) && !mask.near(DVec2::new(35.0, 25.0), 1.5));
    }

    #[test]
    fn the_chamfer_distance_is_close_to_euclidean() {
        let (w, h) = (50, 50);
        let mut mask = vec![false; w * h];
        mask[25 * w + 25] = true;
        let d = distance_to(&mask, w, h);
        assert_eq!(d[25 * w + 25], 0.0);
        assert!((d[25 * w + 35] - 10.0).abs() < 1e-4);
        let diagonal = d[35 * w + 35];
        assert!((diagonal - 200f32.sqrt()).abs() < 0.1, "{diagonal}");
        // Off the axes and diagonals the (1, √2) chamfer overestimates, by 8.3% at most.
        let knight = d[45 * w + 35];
        let euclid = 500f32.sqrt();
        assert!(knight >= euclid && knight <= 1.083 * euclid, "{knight}");
    }
}
