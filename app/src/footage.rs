//! Recorded footage in the TUM RGB-D layout (`rgb.txt`, `depth.txt`, `groundtruth.txt`,
//! `camera.txt`) as the app plays it.
//!
//! TEMPORARY STAND-IN: until `sylva_tracking`'s tracker is wired in, each frame's
//! `world_from_camera` is the ground-truth pose nearest in time (world: metres, Y up, origin at the
//! planting spot, as the synthetic demo writes it).

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

/// TEMPORARY STAND-IN for `sylva_tracking::depth_mesh`: the scene surface from one depth map, a
/// grid of back-projected samples every `step` pixels, with triangles across depth jumps dropped.
pub fn occluder_from_depth(
    depth: &(u32, u32, Vec<f32>),
    intrinsics: &Intrinsics,
    world_from_camera: Mat4,
    step: u32,
) -> crate::render::OccluderMesh {
    let (w, h, values) = depth;
    let k = intrinsics.scaled_to(*w, *h);
    let (nx, ny) = (w / step + 1, h / step + 1);
    let mut mesh = crate::render::OccluderMesh::default();
    let mut depths = Vec::with_capacity((nx * ny) as usize);
    for j in 0..ny {
        for i in 0..nx {
            let (x, y) = ((i * step).min(w - 1), (j * step).min(h - 1));
            let z = values[(y * w + x) as usize];
            let ray = k.ray_from_pixel(glam::Vec2::new(x as f32, y as f32));
            mesh.positions
                .push(world_from_camera.transform_point3(ray * z.max(1e-3)));
            depths.push(z);
        }
    }
    for j in 0..ny - 1 {
        for i in 0..nx - 1 {
            let q = [
                j * nx + i,
                j * nx + i + 1,
                (j + 1) * nx + i + 1,
                (j + 1) * nx + i,
            ];
            for tri in [[q[0], q[1], q[2]], [q[0], q[2], q[3]]] {
                let z = tri.map(|v| depths[v as usize]);
                let (lo, hi) = (
                    z.iter().copied().fold(f32::MAX, f32::min),
                    z.iter().copied().fold(0.0, f32::max),
                );
                if lo > 0.0 && hi < lo * 1.08 {
                    mesh.indices.extend(tri);
                }
            }
        }
    }
    mesh
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
