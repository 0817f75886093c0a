//! Writes the TUM RGB-D layout: frames, depth maps and the text files describing them.

use std::fmt::Write as _;
use std::fs;
use std::io::BufWriter;
use std::path::{Path, PathBuf};

use glam::{Affine3A, Quat, Vec3};
use image::ImageEncoder;
use image::codecs::jpeg::JpegEncoder;
use image::codecs::png::{CompressionType, FilterType, PngEncoder};

use super::{FrameFormat, Garden, Pinhole, SequenceOptions, SyntheticError};

/// Metres × this = the 16-bit value stored in depth PNGs (TUM's convention).
pub const DEPTH_SCALE: f64 = 5000.0;

pub struct TumWriter<'a> {
    root: PathBuf,
    options: &'a SequenceOptions,
    rgb_list: String,
    depth_list: String,
    groundtruth: String,
    mask_list: String,
    total_bytes: u64,
}

fn write_error(path: &Path, error: impl std::fmt::Display) -> SyntheticError {
    SyntheticError::Write {
        path: path.to_path_buf(),
        reason: error.to_string(),
    }
}

impl<'a> TumWriter<'a> {
    pub fn create(root: &Path, options: &'a SequenceOptions) -> Result<Self, SyntheticError> {
        for sub in ["rgb", "depth"] {
            let dir = root.join(sub);
            fs::create_dir_all(&dir).map_err(|e| write_error(&dir, e))?;
        }
        if options.tree.is_some() {
            let dir = root.join("masks");
            fs::create_dir_all(&dir).map_err(|e| write_error(&dir, e))?;
        }
        Ok(Self {
            root: root.to_path_buf(),
            options,
            rgb_list: "# color images\n# synthetic garden (sylva-tests make_synthetic)\n# timestamp filename\n".into(),
            depth_list: "# depth maps (uint16 PNG, metres = value / 5000)\n# timestamp filename\n".into(),
            groundtruth: "# ground truth trajectory (world_from_camera, world Y up, metres)\n# timestamp tx ty tz qx qy qz qw\n".into(),
            mask_list: "# tree silhouette masks (8-bit PNG: 255 foliage, 128 wood, 0 not the tree)\n# timestamp filename\n".into(),
            total_bytes: 0,
        })
    }

    fn save(
        &mut self,
        relative: &str,
        encode: impl FnOnce(&mut BufWriter<fs::File>) -> image::ImageResult<()>,
    ) -> Result<(), SyntheticError> {
        let path = self.root.join(relative);
        let file = fs::File::create(&path).map_err(|e| write_error(&path, e))?;
        let mut buffer = BufWriter::new(file);
        encode(&mut buffer).map_err(|e| write_error(&path, e))?;
        drop(buffer);
        self.total_bytes += fs::metadata(&path)
            .map_err(|e| write_error(&path, e))?
            .len();
        Ok(())
    }

    /// One colour frame and its ground-truth pose.
    pub fn frame(
        &mut self,
        timestamp_s: f64,
        rgb: &[u8],
        world_from_camera: &Affine3A,
    ) -> Result<(), SyntheticError> {
        let (width, height) = (self.options.width, self.options.height);
        let relative = match self.options.frame_format {
            FrameFormat::Jpeg { quality } => {
                let relative = format!("rgb/{timestamp_s:.6}.jpg");
                self.save(&relative, |w| {
                    JpegEncoder::new_with_quality(w, quality).write_image(
                        rgb,
                        width,
                        height,
                        image::ExtendedColorType::Rgb8,
                    )
                })?;
                relative
            }
            FrameFormat::Png => {
                let relative = format!("rgb/{timestamp_s:.6}.png");
                self.save(&relative, |w| {
                    PngEncoder::new(w).write_image(
                        rgb,
                        width,
                        height,
                        image::ExtendedColorType::Rgb8,
                    )
                })?;
                relative
            }
        };
        let _ = writeln!(self.rgb_list, "{timestamp_s:.6} {relative}");
        let t = Vec3::from(world_from_camera.translation);
        let q = Quat::from_mat3a(&world_from_camera.matrix3).normalize();
        let _ = writeln!(
            self.groundtruth,
            "{timestamp_s:.6} {:.6} {:.6} {:.6} {:.7} {:.7} {:.7} {:.7}",
            t.x, t.y, t.z, q.x, q.y, q.z, q.w
        );
        Ok(())
    }

    /// One frame's tree silhouette mask (8-bit grey, see `render::render_tree_mask`).
    pub fn mask(&mut self, timestamp_s: f64, mask: &[u8]) -> Result<(), SyntheticError> {
        let (width, height) = (self.options.width, self.options.height);
        let relative = format!("masks/{timestamp_s:.6}.png");
        self.save(&relative, |w| {
            PngEncoder::new_with_quality(w, CompressionType::Best, FilterType::Adaptive)
                .write_image(mask, width, height, image::ExtendedColorType::L8)
        })?;
        let _ = writeln!(self.mask_list, "{timestamp_s:.6} {relative}");
        Ok(())
    }

    /// One depth map (camera Z in metres, 0 = no measurement).
    pub fn depth(&mut self, timestamp_s: f64, depth_m: &[f32]) -> Result<(), SyntheticError> {
        let (width, height) = (self.options.width, self.options.height);
        let mut bytes = Vec::with_capacity(depth_m.len() * 2);
        for &z in depth_m {
            let value = (z as f64 * DEPTH_SCALE).round();
            let value = if value >= 1.0 && value <= u16::MAX as f64 {
                value as u16
            } else {
                0
            };
            // `write_image` takes 16-bit samples in native byte order.
            bytes.extend_from_slice(&value.to_ne_bytes());
        }
        let relative = format!("depth/{timestamp_s:.6}.png");
        self.save(&relative, |w| {
            PngEncoder::new_with_quality(w, CompressionType::Best, FilterType::Adaptive)
                .write_image(&bytes, width, height, image::ExtendedColorType::L16)
        })?;
        let _ = writeln!(self.depth_list, "{timestamp_s:.6} {relative}");
        Ok(())
    }

    fn text(&mut self, name: &str, content: &str) -> Result<(), SyntheticError> {
        let path = self.root.join(name);
        fs::write(&path, content).map_err(|e| write_error(&path, e))?;
        self.total_bytes += content.len() as u64;
        Ok(())
    }

    /// Writes the lists, the accelerometer, `camera.txt` and `scene.json`; returns total bytes.
    pub fn finish(
        mut self,
        accelerometer: &[(f64, Vec3)],
        camera: &Pinhole,
        garden: &Garden,
        path_length_m: f64,
    ) -> Result<u64, SyntheticError> {
        let rgb_list = std::mem::take(&mut self.rgb_list);
        let depth_list = std::mem::take(&mut self.depth_list);
        let groundtruth = std::mem::take(&mut self.groundtruth);
        self.text("rgb.txt", &rgb_list)?;
        self.text("depth.txt", &depth_list)?;
        self.text("groundtruth.txt", &groundtruth)?;
        if let Some(tree) = &garden.tree {
            let mask_list = std::mem::take(&mut self.mask_list);
            self.text("masks.txt", &mask_list)?;
            let truth = serde_json::json!({
                "generator": "sylva-tests make_synthetic (stochastic branching grammar, tests/src/synthetic/tree.rs)",
                "truth": tree.truth(),
                "params": tree.params,
            });
            let json = serde_json::to_string_pretty(&truth)
                .map_err(|e| write_error(&self.root.join("tree_truth.json"), e))?;
            self.text("tree_truth.json", &json)?;
        }
        let mut accel = String::from(
            "# accelerometer data (m/s^2, specific force: +g upwards at rest)\n\
             # axes as the Kinect of TUM fr1: x = -camera X, y = -camera Y (up), z = camera Z (forward)\n\
             # timestamp ax ay az\n",
        );
        for (t, a) in accelerometer {
            let _ = writeln!(accel, "{t:.6} {:.6} {:.6} {:.6}", a.x, a.y, a.z);
        }
        self.text("accelerometer.txt", &accel)?;
        let camera_txt = format!(
            "# Camera model: synthetic pinhole (sylva-tests make_synthetic), no distortion.\n\
             width   {}\nheight  {}\nfx      {}\nfy      {}\ncx      {}\ncy      {}\n\
             k1      0\nk2      0\np1      0\np2      0\nk3      0\n\
             # depth/*.png: uint16, metres = value / 5000 (0 = no measurement).\n\
             depth_scale 5000\nframe_rate_hz {}\n",
            camera.width,
            camera.height,
            camera.fx,
            camera.fy,
            camera.cx,
            camera.cy,
            self.options.frame_rate_hz
        );
        self.text("camera.txt", &camera_txt)?;
        let scene = serde_json::json!({
            "generator": "sylva-tests make_synthetic",
            "world": "metres, Y up, planting spot at the origin on the ground; groundtruth = world_from_camera, camera axes X right, Y down, Z forward",
            "ground_plane": { "normal": garden.ground.normal.to_array(), "offset_m": 0.0, "slope_deg": garden.ground.slope_deg },
            "blocks": garden.blocks,
            "planting_spot": [0.0, 0.0, 0.0],
            "camera_height_m": self.options.walk.height_m,
            "path_length_m": path_length_m,
            "options": self.options,
            "camera": camera,
        });
        let json = serde_json::to_string_pretty(&scene)
            .map_err(|e| write_error(&self.root.join("scene.json"), e))?;
        self.text("scene.json", &json)?;
        Ok(self.total_bytes)
    }
}
