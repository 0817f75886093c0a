//! Recorded footage in the TUM RGB-D layout (`rgb.txt`, `depth.txt`, `groundtruth.txt`,
//! `camera.txt`) as the app plays it.
//!
//! Each frame also carries the ground-truth pose nearest in time when the footage has one
//! (`groundtruth.txt`): tests compare the app against it. The app itself places the camera with
//! the tracker ([`crate::scene_tracking`]), never with the ground truth.

use std::path::{Path, PathBuf};

use anyhow::{Context, bail};
use glam::{Mat4, Quat, Vec3};

use crate::render::Intrinsics;

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

fn read_lines(path: &Path) -> anyhow::Result<Vec<Vec<String>>> {
    let text =
        std::fs::read_to_string(path).with_context(|| format!("cannot read {}", path.display()))?;
    Ok(text
        .lines()
        .map(str::trim)
        .filter(|l| !l.is_empty() && !l.starts_with('#'))
        .map(|l| l.split_whitespace().map(str::to_owned).collect())
        .collect())
}

fn number<T: std::str::FromStr>(path: &Path, line: usize, field: &str) -> anyhow::Result<T> {
    field.parse().map_err(|_| {
        anyhow::anyhow!(
            "{}: entry {line}: `{field}` is not a number",
            path.display()
        )
    })
}

impl Footage {
    /// Opens a TUM-layout folder.
    pub fn open(root: &Path) -> anyhow::Result<Footage> {
        let camera_path = root.join("camera.txt");
        let mut values = std::collections::HashMap::new();
        for (i, fields) in read_lines(&camera_path)?.iter().enumerate() {
            if let [key, value, ..] = fields.as_slice() {
                values.insert(key.clone(), number::<f32>(&camera_path, i, value)?);
            }
        }
        let get = |key: &str| {
            values
                .get(key)
                .copied()
                .with_context(|| format!("{}: missing `{key}`", camera_path.display()))
        };
        let intrinsics = Intrinsics {
            width: get("width")? as u32,
            height: get("height")? as u32,
            fx: get("fx")?,
            fy: get("fy")?,
            cx: get("cx")?,
            cy: get("cy")?,
            distortion: ["k1", "k2", "p1", "p2", "k3"]
                .map(|k| values.get(k).copied().unwrap_or(0.0)),
        };
        let depth_scale = values.get("depth_scale").copied().unwrap_or(5000.0);
        let timed = |name: &str| -> anyhow::Result<Vec<(f64, PathBuf)>> {
            let path = root.join(name);
            if !path.exists() {
                return Ok(Vec::new());
            }
            read_lines(&path)?
                .iter()
                .enumerate()
                .map(|(i, f)| match f.as_slice() {
                    [t, file, ..] => Ok((number(&path, i, t)?, root.join(file))),
                    _ => bail!("{}: entry {i}: expected `timestamp file`", path.display()),
                })
                .collect()
        };
        let rgb = timed("rgb.txt")?;
        if rgb.is_empty() {
            bail!("{}: no frames listed in rgb.txt", root.display());
        }
        let depth = timed("depth.txt")?;
        let poses = read_poses(&root.join("groundtruth.txt"))?;
        let frames = rgb
            .into_iter()
            .map(|(time_s, rgb)| FootageFrame {
                time_s,
                depth: nearest(&depth, time_s, 0.02).map(|d| d.1.clone()),
                world_from_camera: nearest(&poses, time_s, 0.02).map(|p| p.1),
                rgb,
            })
            .collect();
        Ok(Footage {
            root: root.to_owned(),
            intrinsics,
            depth_scale,
            frames,
        })
    }

    pub fn len(&self) -> usize {
        self.frames.len()
    }

    pub fn is_empty(&self) -> bool {
        self.frames.is_empty()
    }

    /// The colour image of frame `index`, RGBA8.
    pub fn load_rgba(&self, index: usize) -> anyhow::Result<image::RgbaImage> {
        let frame = self
            .frames
            .get(index)
            .with_context(|| format!("{}: no frame {index}", self.root.display()))?;
        Ok(image::open(&frame.rgb)
            .with_context(|| format!("cannot decode {}", frame.rgb.display()))?
            .to_rgba8())
    }

    /// The depth map of frame `index` in metres (0 = no measurement), if the footage has one.
    pub fn load_depth_m(&self, index: usize) -> anyhow::Result<Option<(u32, u32, Vec<f32>)>> {
        let Some(path) = self.frames.get(index).and_then(|f| f.depth.as_ref()) else {
            return Ok(None);
        };
        let image = image::open(path)
            .with_context(|| format!("cannot decode {}", path.display()))?
            .to_luma16();
        let scale = 1.0 / self.depth_scale;
        let (w, h) = image.dimensions();
        Ok(Some((
            w,
            h,
            image.pixels().map(|p| p.0[0] as f32 * scale).collect(),
        )))
    }
}

fn read_poses(path: &Path) -> anyhow::Result<Vec<(f64, Mat4)>> {
    if !path.exists() {
        return Ok(Vec::new());
    }
    read_lines(path)?
        .iter()
        .enumerate()
        .map(|(i, f)| {
            if f.len() < 8 {
                bail!(
                    "{}: entry {i}: expected `t tx ty tz qx qy qz qw`",
                    path.display()
                );
            }
            let v: Vec<f64> = f[..8]
                .iter()
                .map(|x| number(path, i, x))
                .collect::<anyhow::Result<_>>()?;
            let rotation =
                Quat::from_xyzw(v[4] as f32, v[5] as f32, v[6] as f32, v[7] as f32).normalize();
            let translation = Vec3::new(v[1] as f32, v[2] as f32, v[3] as f32);
            Ok((v[0], Mat4::from_rotation_translation(rotation, translation)))
        })
        .collect()
}

fn nearest<T>(items: &[(f64, T)], t: f64, max_gap_s: f64) -> Option<&(f64, T)> {
    let i = items.partition_point(|(ti, _)| *ti < t);
    [i.checked_sub(1), Some(i)]
        .into_iter()
        .flatten()
        .filter_map(|j| items.get(j))
        .filter(|(ti, _)| (ti - t).abs() <= max_gap_s)
        .min_by(|a, b| (a.0 - t).abs().total_cmp(&(b.0 - t).abs()))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn nearest_pose_is_found_within_the_gap_only() {
        let items = vec![(1.0, 'a'), (2.0, 'b'), (3.0, 'c')];
        assert_eq!(nearest(&items, 2.01, 0.02).map(|x| x.1), Some('b'));
        assert_eq!(nearest(&items, 2.5, 0.02), None);
    }

    #[test]
    fn a_missing_folder_is_an_error_naming_the_file() {
        let err = Footage::open(Path::new("/nonexistent/seq")).expect_err("must fail");
        assert!(format!("{err:#}").contains("camera.txt"));
    }
}
