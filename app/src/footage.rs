//! Recorded footage in the TUM RGB-D layout (`rgb.txt`, `depth.txt`, `groundtruth.txt`,
//! `camera.txt`) as the app plays it.
//!
//! Each frame also carries the ground-truth pose nearest in time when the footage has one
//! (`groundtruth.txt`): tests compare the app against it. The app itself places the camera with
//! the tracker ([`crate::scene_tracking`]), never with the ground truth.

use std::path::{Path, PathBuf};

use anyhow::{Context, bail};
use glam::{DMat4, Mat4};
use sylva_tracking::TumSequence;
use sylva_tracking::input_file::{decode_image, decode_limits};
use sylva_tracking::sequence::{decode_depth_m, nearest, read_image_file};

use crate::live::intrinsics_of;
use crate::render::Intrinsics;

/// Largest time gap when pairing a frame with a depth map or a ground-truth pose, seconds.
const MAX_PAIRING_GAP_S: f64 = 0.02;
/// Depth units per metre when `camera.txt` gives none (TUM's 5000).
const DEFAULT_DEPTH_SCALE: f64 = 5000.0;

/// One frame of footage.
#[derive(Clone, Debug, PartialEq)]
pub struct FootageFrame {
    pub time_s: f64,
    pub rgb: PathBuf,
    pub depth: Option<PathBuf>,
    /// Ground-truth `world_from_camera` (for tests and comparisons; the app tracks its own).
    pub world_from_camera: Option<Mat4>,
}

/// A sequence of frames with its camera.
#[derive(Clone, Debug, PartialEq)]
pub struct Footage {
    pub root: PathBuf,
    pub intrinsics: Intrinsics,
    /// Depth PNG value per metre.
    pub depth_scale: f32,
    pub frames: Vec<FootageFrame>,
}

impl Footage {
    /// Opens a TUM-layout folder through the tracking crate's validated readers
    /// ([`TumSequence::open`]): the camera file, frame lists and ground truth are checked there
    /// (finite numbers, positive focal lengths, sizes a texture can hold, increasing timestamps,
    /// unit quaternions, regular files of bounded size), once for the whole app.
    pub fn open(root: &Path) -> anyhow::Result<Footage> {
        let sequence = TumSequence::open(root)
            .with_context(|| format!("cannot open footage {}", root.display()))?;
        let frames = sequence
            .frames
            .iter()
            .map(|f| FootageFrame {
                time_s: f.timestamp_s,
                rgb: f.path.clone(),
                depth: nearest(&sequence.depth, f.timestamp_s, |d| d.timestamp_s)
                    .filter(|d| (d.timestamp_s - f.timestamp_s).abs() <= MAX_PAIRING_GAP_S)
                    .map(|d| d.path.clone()),
                world_from_camera: sequence
                    .groundtruth_at(f.timestamp_s, MAX_PAIRING_GAP_S)
                    .map(|pose| DMat4::from(pose).as_mat4()),
            })
            .collect();
        Ok(Footage {
            root: root.to_owned(),
            intrinsics: intrinsics_of(&sequence.camera),
            depth_scale: sequence.camera.depth_scale.unwrap_or(DEFAULT_DEPTH_SCALE) as f32,
            frames,
        })
    }

    pub fn len(&self) -> usize {
        self.frames.len()
    }

    pub fn is_empty(&self) -> bool {
        self.frames.is_empty()
    }

    /// The colour image of frame `index`, RGBA8: a complete image file of bounded size, of
    /// the camera's size (anything else is an error naming the file, never a blank frame).
    pub fn load_rgba(&self, index: usize) -> anyhow::Result<image::RgbaImage> {
        let frame = self
            .frames
            .get(index)
            .with_context(|| format!("{}: no frame {index}", self.root.display()))?;
        let (width, height) = (self.intrinsics.width, self.intrinsics.height);
        let decoded = read_image_file(&frame.rgb)
            .and_then(|bytes| decode_image(&bytes, decode_limits(width, height)))
            .map_err(|reason| {
                anyhow::anyhow!(
                    "cannot decode frame {index}, {}: {reason} (the camera says {width} x {height})",
                    frame.rgb.display()
                )
            })?;
        if (decoded.width(), decoded.height()) != (width, height) {
            bail!(
                "frame {index}, {}: image is {} x {}, the camera says {width} x {height}",
                frame.rgb.display(),
                decoded.width(),
                decoded.height()
            );
        }
        Ok(decoded.to_rgba8())
    }

    /// The depth map of frame `index` in metres (0 = no measurement), if the footage has one.
    pub fn load_depth_m(&self, index: usize) -> anyhow::Result<Option<(u32, u32, Vec<f32>)>> {
        let Some(path) = self.frames.get(index).and_then(|f| f.depth.as_ref()) else {
            return Ok(None);
        };
        let depth = decode_depth_m(path, f64::from(self.depth_scale))
            .map_err(|reason| anyhow::anyhow!("cannot decode {}: {reason}", path.display()))?;
        Ok(Some(depth))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_missing_folder_is_an_error_naming_it() {
        let err = Footage::open(Path::new("/nonexistent/seq")).expect_err("must fail");
        assert!(format!("{err:#}").contains("/nonexistent/seq"), "{err:#}");
    }
}
