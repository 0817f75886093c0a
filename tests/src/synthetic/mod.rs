//! Synthetic footage: TUM RGB-D-layout sequences of a textured garden (ground, wall, box) seen
//! along handheld-like walks, rendered by a CPU ray caster, deterministic from a seed.
//!
//! Layout written (see `test-data/README.md`): `rgb/` frames + `rgb.txt`, `depth/` 16-bit PNG
//! (metres × 5000) + `depth.txt`, `groundtruth.txt` (`timestamp tx ty tz qx qy qz qw`,
//! `world_from_camera`, OpenCV camera axes), `accelerometer.txt`, `camera.txt` and
//! `scene.json` (the analytic scene and the options used). The tree presets (`tree-a`, `tree-b`)
//! add a grammar tree at the spot ([`tree`]), its silhouette masks (`masks/`, `masks.txt`) and its
//! true measures (`tree_truth.json`).
//!
//! World space: metres, Y up, the planting spot at the origin on the ground.

pub mod render;
mod rng;
pub mod scene;
pub mod texture;
pub mod trajectory;
pub mod tree;
pub mod tree_bvh;
mod writer;

use std::ops::Range;
use std::path::{Path, PathBuf};

use glam::Affine3A;
use serde::Serialize;

pub use render::{Exposure, Pinhole};
pub use scene::{Block, Garden, Ground};
pub use trajectory::{Walk, WalkParams};
pub use tree::{SynthTree, TreeParams, TreeTruth};

/// Errors while writing a sequence.
#[derive(Debug, thiserror::Error)]
pub enum SyntheticError {
    #[error("cannot write {path}: {reason}")]
    Write { path: PathBuf, reason: String },
    #[error("invalid synthetic sequence options: {0}")]
    Options(String),
}

/// How colour frames are stored.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum FrameFormat {
    Jpeg { quality: u8 },
    Png,
}

/// Everything that defines a sequence. Same options ⇒ byte-identical files.
#[derive(Clone, Debug, Serialize)]
pub struct SequenceOptions {
    pub seed: u64,
    pub width: u32,
    pub height: u32,
    pub num_frames: usize,
    pub frame_rate_hz: f64,
    /// Rise of the ground towards −Z, degrees (0 = flat).
    pub slope_deg: f32,
    pub walk: WalkParams,
    /// Shutter open for this fraction of the frame interval; blur from the motion in it.
    pub motion_blur: bool,
    pub shutter_fraction: f32,
    /// Slow auto-exposure drift plus one abrupt change.
    pub exposure_changes: bool,
    /// Frames replaced by a uniform dark image (a covered lens): a forced tracking loss.
    pub blank_frames: Option<Range<usize>>,
    pub noise_sigma: f32,
    pub frame_format: FrameFormat,
    /// Write a depth map every this many frames (0 = none, 1 = every frame).
    pub depth_every: usize,
    /// Accelerometer samples per second.
    pub accelerometer_hz: f64,
    /// A grammar tree at the planting spot (the tree presets): its garden, silhouette masks per
    /// frame (`masks/`) and its true measures (`tree_truth.json`).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub tree: Option<TreePreset>,
}

/// The tree presets' trees and their gardens.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum TreePreset {
    /// Tree A on an open lawn (the paved path beside it, no wall or box).
    OpenLawn,
    /// Tree B with a brick wall 3 m behind it.
    WallBehind,
}

impl TreePreset {
    pub fn params(self) -> TreeParams {
        match self {
            Self::OpenLawn => TreeParams::tree_a(),
            Self::WallBehind => TreeParams::tree_b(),
        }
    }

    fn blocks(self, ground: Ground) -> Vec<Block> {
        match self {
            Self::OpenLawn => Vec::new(),
            Self::WallBehind => {
                let base = ground.height_at(0.0, -3.0).max(ground.height_at(0.0, -3.2));
                vec![Block {
                    name: "wall",
                    min: glam::Vec3::new(-4.5, base - 3.0, -3.2),
                    max: glam::Vec3::new(4.5, base + 1.8, -3.0),
                    material: scene::BlockMaterial::Brick,
                }]
            }
        }
    }
}

impl SequenceOptions {
    /// The committed demo (`test-data/demo_garden`): 240 frames, 640 × 480, 30 Hz, flat ground,
    /// JPEG quality 75 (the encoder writes 4:4:4 chroma; this keeps the folder near 14 MB).
    pub fn demo_garden() -> Self {
        Self {
            seed: 2026,
            width: 640,
            height: 480,
            num_frames: 240,
            frame_rate_hz: 30.0,
            slope_deg: 0.0,
            walk: WalkParams::default(),
            motion_blur: true,
            shutter_fraction: 0.4,
            exposure_changes: true,
            blank_frames: None,
            noise_sigma: 1.0,
            frame_format: FrameFormat::Jpeg { quality: 75 },
            depth_every: 10,
            accelerometer_hz: 120.0,
            tree: None,
        }
    }

    /// Tree A (`test-data/tree_a`): the camera circles a 3 m grammar tree on an open lawn at
    /// 7 m, 80° of arc in 180 frames, pitched 4° down so the whole tree stays in view.
    pub fn tree_a() -> Self {
        Self {
            seed: 2031,
            num_frames: 180,
            walk: WalkParams {
                radius_m: 7.0,
                height_m: 1.5,
                pitch_deg: 4.0,
                start_bearing_deg: -40.0,
                end_bearing_deg: 40.0,
                ..WalkParams::default()
            },
            motion_blur: false,
            frame_format: FrameFormat::Jpeg { quality: 60 },
            depth_every: 0,
            tree: Some(TreePreset::OpenLawn),
            ..Self::demo_garden()
        }
    }

    /// Tree B (`test-data/tree_b`): a 3.3 m ovoid grammar tree with a wall behind it, circled the
    /// other way round.
    pub fn tree_b() -> Self {
        Self {
            seed: 2032,
            walk: WalkParams {
                start_bearing_deg: 40.0,
                end_bearing_deg: -40.0,
                ..Self::tree_a().walk
            },
            tree: Some(TreePreset::WallBehind),
            ..Self::tree_a()
        }
    }

    /// The demo walk on ground rising by 8°.
    pub fn slope() -> Self {
        Self {
            seed: 2027,
            slope_deg: 8.0,
            ..Self::demo_garden()
        }
    }

    /// The app's demo (`test-data/demo_yard`): the same garden walked at 9 m from the spot with
    /// the camera held nearly level (8° down), so a tree of 12–15 years (4–5 m) behind the box is
    /// in view from its foot (hidden by the box) to its crown.
    pub fn demo_yard() -> Self {
        Self {
            seed: 2029,
            walk: WalkParams {
                radius_m: 9.0,
                pitch_deg: 8.0,
                start_bearing_deg: -25.0,
                end_bearing_deg: 25.0,
                ..WalkParams::default()
            },
            ..Self::demo_garden()
        }
    }

    /// The demo walk with one second of blanked frames starting at frame 120.
    pub fn forced_loss() -> Self {
        Self {
            seed: 2028,
            blank_frames: Some(120..150),
            ..Self::demo_garden()
        }
    }

    fn validate(&self) -> Result<(), SyntheticError> {
        let bad = |reason: &str| Err(SyntheticError::Options(reason.to_owned()));
        if self.width < 8 || self.height < 8 || self.width > 8192 || self.height > 8192 {
            return bad("image size must be between 8 and 8192 pixels");
        }
        if self.num_frames == 0 {
            return bad("at least one frame is needed");
        }
        if !(self.frame_rate_hz.is_finite() && self.frame_rate_hz > 0.0) {
            return bad("frame rate must be positive");
        }
        if !(0.0..=1.0).contains(&self.shutter_fraction) {
            return bad("shutter fraction must be in [0, 1]");
        }
        if self.slope_deg.is_nan() || self.slope_deg.abs() >= 45.0 {
            return bad("slope must be within ±45 degrees");
        }
        if matches!(self.frame_format, FrameFormat::Jpeg { quality } if quality == 0 || quality > 100)
        {
            return bad("JPEG quality must be in 1..=100");
        }
        Ok(())
    }

    fn duration_s(&self) -> f32 {
        (self.num_frames as f64 / self.frame_rate_hz) as f32
    }
}

/// What [`render_sequence`] wrote.
#[derive(Clone, Debug, Serialize)]
pub struct SequenceSummary {
    pub root: PathBuf,
    pub num_frames: usize,
    pub num_depth_maps: usize,
    /// Length of the camera path (m), for "ATE ≤ 1 % of path length".
    pub path_length_m: f64,
    /// Ground-truth `world_from_camera` per frame.
    #[serde(skip)]
    pub world_from_camera: Vec<Affine3A>,
    pub total_bytes: u64,
}

/// Timestamp of frame `index` (seconds; an arbitrary epoch like TUM's).
pub fn frame_timestamp_s(options: &SequenceOptions, index: usize) -> f64 {
    1_700_000_000.0 + index as f64 / options.frame_rate_hz
}

/// Exposure gain at time `t`: a slow drift, and one abrupt step that auto-exposure brings back.
fn exposure_gain(options: &SequenceOptions, t: f32) -> f32 {
    if !options.exposure_changes {
        return 1.0;
    }
    let mut rng = rng::SplitMix64::new(options.seed ^ 0xe4905e);
    let phase = std::f32::consts::TAU * rng.next_f32();
    let step_at_s = options.duration_s() * (0.3 + 0.4 * rng.next_f32());
    let drift = 1.0 + 0.18 * (std::f32::consts::TAU * t / 6.0 + phase).sin();
    let step = if t >= step_at_s {
        0.45 * (-(t - step_at_s) / 0.6).exp()
    } else {
        0.0
    };
    drift * (1.0 + step)
}

/// Poses over the shutter interval centred on `t`, enough of them that consecutive ones
/// move the image by about one pixel or less.
fn shutter_poses(
    walk: &Walk,
    options: &SequenceOptions,
    camera: &Pinhole,
    t: f32,
) -> Vec<Affine3A> {
    let centre = walk.world_from_camera(t);
    if !options.motion_blur || options.shutter_fraction <= 0.0 {
        return vec![centre];
    }
    let open_s = options.shutter_fraction / options.frame_rate_hz as f32;
    let (start, end) = (
        walk.world_from_camera(t - 0.5 * open_s),
        walk.world_from_camera(t + 0.5 * open_s),
    );
    let rotation =
        glam::Quat::from_mat3a(&start.matrix3).angle_between(glam::Quat::from_mat3a(&end.matrix3));
    let shift_m =
        (glam::Vec3::from(end.translation) - glam::Vec3::from(start.translation)).length();
    let motion_px = camera.fx * (rotation + shift_m / 2.0);
    let count = (motion_px.ceil() as usize).clamp(1, 10);
    if count == 1 {
        return vec![centre];
    }
    (0..count)
        .map(|i| {
            walk.world_from_camera(t - 0.5 * open_s + open_s * (i as f32 + 0.5) / count as f32)
        })
        .collect()
}

/// Renders the sequence into `root` (created if needed) and returns what was written.
pub fn render_sequence(
    options: &SequenceOptions,
    root: &Path,
) -> Result<SequenceSummary, SyntheticError> {
    options.validate()?;
    let camera = Pinhole::tum_default(options.width, options.height);
    let ground = Ground::sloped(options.slope_deg);
    let mut garden = Garden::new(ground, (options.seed as u32) ^ 0x6a4d);
    if let Some(preset) = options.tree {
        garden = garden.with_tree(preset.blocks(ground), SynthTree::new(preset.params()));
    }
    let walk = Walk::new(
        options.walk.clone(),
        ground,
        options.duration_s(),
        options.seed,
    );
    let mut out = writer::TumWriter::create(root, options)?;
    let mut poses = Vec::with_capacity(options.num_frames);
    for index in 0..options.num_frames {
        let t = index as f32 / options.frame_rate_hz as f32;
        let timestamp_s = frame_timestamp_s(options, index);
        let world_from_camera = walk.world_from_camera(t);
        let blank = options
            .blank_frames
            .as_ref()
            .is_some_and(|r| r.contains(&index));
        let rgb = if blank {
            vec![12u8; (options.width * options.height * 3) as usize]
        } else {
            let exposure = Exposure {
                world_from_camera: shutter_poses(&walk, options, &camera, t),
                gain: exposure_gain(options, t),
                noise_sigma: options.noise_sigma,
                noise_seed: (options.seed as u32)
                    .wrapping_mul(31)
                    .wrapping_add(index as u32),
            };
            render::render_rgb(&garden, &camera, &exposure)
        };
        out.frame(timestamp_s, &rgb, &world_from_camera)?;
        if let Some(tree) = &garden.tree {
            let mask = render::render_tree_mask(tree, &camera, &world_from_camera);
            out.mask(timestamp_s, &mask)?;
        }
        if options.depth_every > 0 && index % options.depth_every == 0 {
            let depth_m = render::render_depth_m(&garden, &camera, &world_from_camera);
            out.depth(timestamp_s, &depth_m)?;
        }
        poses.push(world_from_camera);
    }
    let accelerometer = accelerometer_samples(&walk, options);
    let path_length_m = poses
        .windows(2)
        .map(|w| {
            (glam::Vec3::from(w[1].translation) - glam::Vec3::from(w[0].translation)).length()
                as f64
        })
        .sum();
    let total_bytes = out.finish(&accelerometer, &camera, &garden, path_length_m)?;
    Ok(SequenceSummary {
        root: root.to_path_buf(),
        num_frames: options.num_frames,
        num_depth_maps: if options.depth_every == 0 {
            0
        } else {
            options.num_frames.div_ceil(options.depth_every)
        },
        path_length_m,
        world_from_camera: poses,
        total_bytes,
    })
}

/// `(timestamp, reading)` in the Kinect accelerometer axes used by TUM's fr1 recordings.
fn accelerometer_samples(walk: &Walk, options: &SequenceOptions) -> Vec<(f64, glam::Vec3)> {
    let mut rng = rng::SplitMix64::new(options.seed ^ 0xacce1);
    let duration_s = options.num_frames as f64 / options.frame_rate_hz;
    let count = (duration_s * options.accelerometer_hz).floor() as usize;
    (0..count)
        .map(|i| {
            let t = i as f64 / options.accelerometer_hz;
            let f = walk.specific_force_in_camera(t as f32);
            let noise = glam::Vec3::new(
                rng.next_gaussian(),
                rng.next_gaussian(),
                rng.next_gaussian(),
            ) * 0.02;
            // Kinect axes = OpenCV camera axes with X and Y flipped (checked on fr1_rpy).
            (
                frame_timestamp_s(options, 0) + t,
                glam::Vec3::new(-f.x, -f.y, f.z) + noise,
            )
        })
        .collect()
}

/// Renders `options` into a fresh temporary folder (removed when the guard drops).
pub fn render_to_temp_dir(
    options: &SequenceOptions,
) -> Result<(tempfile::TempDir, SequenceSummary), SyntheticError> {
    let dir = tempfile::Builder::new()
        .prefix("sylva-synthetic-")
        .tempdir()
        .map_err(|e| SyntheticError::Write {
            path: std::env::temp_dir(),
            reason: e.to_string(),
        })?;
    let summary = render_sequence(options, dir.path())?;
    Ok((dir, summary))
}
