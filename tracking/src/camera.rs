//! Pinhole intrinsics with OpenCV's radial-tangential distortion (k1, k2, p1, p2, k3).
//!
//! Tracking undistorts *points*, never whole images: corners are found and followed in the raw
//! image, then mapped to normalised (undistorted) coordinates `x = (X/Z, Y/Z)` for geometry.

use crate::input_file::{MAX_CAMERA_FILE_BYTES, read_regular_text};
use glam::{DVec2, DVec3};
use std::path::{Path, PathBuf};

/// A camera description could not be read.
#[derive(Debug, thiserror::Error)]
pub enum CameraError {
    #[error("cannot read camera file {path}: {source}")]
    Io {
        path: PathBuf,
        source: std::io::Error,
    },
    #[error("camera file {path}, line {line}: {problem}")]
    Parse {
        path: PathBuf,
        line: usize,
        problem: String,
    },
    #[error("camera file {path}: missing required key `{key}`")]
    Missing { path: PathBuf, key: &'static str },
    #[error("camera file {path}: {problem}")]
    Invalid { path: PathBuf, problem: String },
}

/// The longest image side a camera file may give, pixels (beyond any phone or video camera).
pub const MAX_IMAGE_SIDE: u32 = 16384;

/// The highest frame rate a camera file may give, frames per second.
pub const MAX_FRAME_RATE_HZ: f64 = 10_000.0;

/// Intrinsics of a pinhole camera with radial-tangential distortion.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct Camera {
    pub width: u32,
    pub height: u32,
    pub fx: f64,
    pub fy: f64,
    pub cx: f64,
    pub cy: f64,
    /// Distortion in OpenCV order: k1, k2, p1, p2, k3.
    pub distortion: [f64; 5],
    /// Depth map units per metre (TUM: 5000), when the footage has depth.
    pub depth_scale: Option<f64>,
    /// Nominal frame rate, when known.
    pub frame_rate_hz: Option<f64>,
}

impl Camera {
    /// A camera without distortion.
    pub fn pinhole(width: u32, height: u32, fx: f64, fy: f64, cx: f64, cy: f64) -> Self {
        Self {
            width,
            height,
            fx,
            fy,
            cx,
            cy,
            distortion: [0.0; 5],
            depth_scale: None,
            frame_rate_hz: None,
        }
    }

    /// Reads a `camera.txt`: one `key value` per line, `#` comments; keys `width height fx fy cx
    /// cy` are required, `k1 k2 p1 p2 k3 depth_scale frame_rate_hz` optional. Only a regular
    /// file of at most [`MAX_CAMERA_FILE_BYTES`] is read.
    pub fn from_file(path: &Path) -> Result<Self, CameraError> {
        let text =
            read_regular_text(path, MAX_CAMERA_FILE_BYTES).map_err(|source| CameraError::Io {
                path: path.to_path_buf(),
                source,
            })?;
        Self::parse(&text, path)
    }

    /// Parses the text of a `camera.txt`; `path` only names the file in errors.
    pub fn parse(text: &str, path: &Path) -> Result<Self, CameraError> {
        let mut values: Vec<(&str, f64)> = Vec::new();
        for (index, raw) in text.lines().enumerate() {
            let line = raw.split('#').next().unwrap_or("").trim();
            if line.is_empty() {
                continue;
            }
            let mut words = line.split_whitespace();
            let (Some(key), Some(value), None) = (words.next(), words.next(), words.next()) else {
                return Err(CameraError::Parse {
                    path: path.to_path_buf(),
                    line: index + 1,
                    problem: format!("expected `key value`, found `{line}`"),
                });
            };
            let number: f64 = value.parse().map_err(|_| CameraError::Parse {
                path: path.to_path_buf(),
                line: index + 1,
                problem: format!("`{value}` is not a number (key `{key}`)"),
            })?;
            if !number.is_finite() {
                return Err(CameraError::Parse {
                    path: path.to_path_buf(),
                    line: index + 1,
                    problem: format!("`{key}` is not finite"),
                });
            }
            values.push((key, number));
        }
        let get = |key: &str| {
            values
                .iter()
                .rev()
                .find(|(k, _)| *k == key)
                .map(|(_, v)| *v)
        };
        let required = |key: &'static str| {
            get(key).ok_or(CameraError::Missing {
                path: path.to_path_buf(),
                key,
            })
        };
        let invalid = |problem: String| CameraError::Invalid {
            path: path.to_path_buf(),
            problem,
        };
        let (width, height) = (required("width")?, required("height")?);
        let side = 1.0..=MAX_IMAGE_SIDE as f64;
        if !side.contains(&width)
            || !side.contains(&height)
            || width.fract() != 0.0
            || height.fract() != 0.0
        {
            return Err(invalid(format!(
                "image size {width} x {height} is not a whole size of 1 to {MAX_IMAGE_SIDE} \
                 pixels a side"
            )));
        }
        let (fx, fy) = (required("fx")?, required("fy")?);
        if fx <= 0.0 || fy <= 0.0 {
            return Err(invalid(format!(
                "focal lengths must be positive (fx {fx}, fy {fy})"
            )));
        }
        let distortion = [
            get("k1").unwrap_or(0.0),
            get("k2").unwrap_or(0.0),
            get("p1").unwrap_or(0.0),
            get("p2").unwrap_or(0.0),
            get("k3").unwrap_or(0.0),
        ];
        let depth_scale = get("depth_scale");
        if depth_scale.is_some_and(|s| s <= 0.0) {
            return Err(invalid("depth_scale must be positive".into()));
        }
        let frame_rate_hz = get("frame_rate_hz");
        if frame_rate_hz.is_some_and(|r| !(r > 0.0 && r <= MAX_FRAME_RATE_HZ)) {
            return Err(invalid(format!(
                "frame_rate_hz must be above 0 and at most {MAX_FRAME_RATE_HZ}"
            )));
        }
        Ok(Self {
            width: width as u32,
            height: height as u32,
            fx,
            fy,
            cx: required("cx")?,
            cy: required("cy")?,
            distortion,
            depth_scale,
            frame_rate_hz,
        })
    }

    /// True when any distortion coefficient is non-zero.
    pub fn is_distorted(&self) -> bool {
        self.distortion.iter().any(|&k| k != 0.0)
    }

    /// Applies the distortion to normalised coordinates.
    pub fn distort(&self, normalized: DVec2) -> DVec2 {
        let [k1, k2, p1, p2, k3] = self.distortion;
        let (x, y) = (normalized.x, normalized.y);
        let r2 = x * x + y * y;
        let radial = 1.0 + r2 * (k1 + r2 * (k2 + r2 * k3));
        DVec2::new(
            x * radial + 2.0 * p1 * x * y + p2 * (r2 + 2.0 * x * x),
            y * radial + p1 * (r2 + 2.0 * y * y) + 2.0 * p2 * x * y,
        )
    }

    /// Raw image pixel of a point in camera space (None behind the camera).
    pub fn pixel_from_camera(&self, point_in_camera: DVec3) -> Option<DVec2> {
        if point_in_camera.z <= 1e-9 {
            return None;
        }
        let n = point_in_camera.truncate() / point_in_camera.z;
        Some(self.pixel_from_normalized(n))
    }

    /// Raw (distorted) pixel of a normalised undistorted coordinate.
    pub fn pixel_from_normalized(&self, normalized: DVec2) -> DVec2 {
        let d = self.distort(normalized);
        DVec2::new(self.fx * d.x + self.cx, self.fy * d.y + self.cy)
    }

    /// Normalised undistorted coordinates of a raw pixel (Gauss–Newton on the distortion model).
    pub fn normalized_from_pixel(&self, pixel: DVec2) -> DVec2 {
        let distorted = DVec2::new((pixel.x - self.cx) / self.fx, (pixel.y - self.cy) / self.fy);
        if !self.is_distorted() {
            return distorted;
        }
        let mut x = distorted;
        for _ in 0..8 {
            let residual = self.distort(x) - distorted;
            if residual.length_squared() < 1e-20 {
                break;
            }
            // Numerical Jacobian of the distortion (2 x 2).
            let h = 1e-7;
            let jx = (self.distort(x + DVec2::new(h, 0.0)) - self.distort(x)) / h;
            let jy = (self.distort(x + DVec2::new(0.0, h)) - self.distort(x)) / h;
            let det = jx.x * jy.y - jy.x * jx.y;
            if det.abs() < 1e-12 {
                break;
            }
            let step = DVec2::new(
                (jy.y * residual.x - jy.x * residual.y) / det,
                (-jx.y * residual.x + jx.x * residual.y) / det,
            );
            x -= step;
        }
        x
    }

    /// Mean focal length, to turn pixel thresholds into normalised ones.
    pub fn focal(&self) -> f64 {
        0.5 * (self.fx + self.fy)
    }

    /// True when a raw pixel lies inside the image with `margin` pixels to spare.
    pub fn contains(&self, pixel: DVec2, margin: f64) -> bool {
        pixel.x >= margin
            && pixel.y >= margin
            && pixel.x < self.width as f64 - margin
            && pixel.y < self.height as f64 - margin
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    fn fr1() -> Camera {
        let mut camera = Camera::pinhole(640, 480, 517.3, 516.5, 318.6, 255.3);
        camera.distortion = [0.2624, -0.9531, -0.0054, 0.0026, 1.1633];
        camera
    }

    #[test]
    fn undistorting_a_distorted_pixel_returns_the_original_point() {
        let camera = fr1();
        for &(x, y) in &[(0.0, 0.0), (0.5, -0.4), (-0.55, 0.45), (0.3, 0.1)] {
            let n = DVec2::new(x, y);
            let back = camera.normalized_from_pixel(camera.pixel_from_normalized(n));
            assert!((back - n).length() < 1e-9, "{n} came back as {back}");
        }
    }

    #[test]
    fn a_camera_file_with_a_bad_number_is_an_error_naming_file_and_line() {
        let err = Camera::parse("width 640\nheight 48O\n", Path::new("cam.txt")).unwrap_err();
        let text = err.to_string();
        assert!(
            text.contains("cam.txt") && text.contains("line 2"),
            "{text}"
        );
    }

    #[test]
    fn a_camera_file_without_focal_length_is_an_error() {
        let err =
            Camera::parse("width 640\nheight 480\ncx 1\ncy 1", Path::new("c.txt")).unwrap_err();
        assert!(err.to_string().contains("fx"), "{err}");
    }

    #[test]
    fn negative_focal_length_is_rejected() {
        let text = "width 640\nheight 480\nfx -1\nfy 500\ncx 1\ncy 1";
        assert!(Camera::parse(text, Path::new("c.txt")).is_err());
    }

    #[test]
    fn a_frame_rate_of_zero_is_rejected() {
        let text = "width 640\nheight 480\nfx 500\nfy 500\ncx 1\ncy 1\nframe_rate_hz 0";
        let err = Camera::parse(text, Path::new("c.txt")).expect_err("zero frame rate");
        assert!(err.to_string().contains("frame_rate_hz"), "{err}");
    }

    use crate::fuzz_config as config;

    /// What every accepted camera must satisfy.
    fn check(text: &str) {
        if let Ok(c) = Camera::parse(text, Path::new("camera.txt")) {
            assert!((1..=MAX_IMAGE_SIDE).contains(&c.width), "{c:?}");
            assert!((1..=MAX_IMAGE_SIDE).contains(&c.height), "{c:?}");
            assert!(c.fx.is_finite() && c.fx > 0.0 && c.fy.is_finite() && c.fy > 0.0);
            assert!(c.cx.is_finite() && c.cy.is_finite());
            assert!(c.distortion.iter().all(|k| k.is_finite()));
            assert!(c.depth_scale.is_none_or(|s| s.is_finite() && s > 0.0));
            assert!(
                c.frame_rate_hz
                    .is_none_or(|r| r > 0.0 && r <= MAX_FRAME_RATE_HZ)
            );
        }
    }

    proptest! {
        #![proptest_config(config())]

        #[test]
        fn the_camera_parser_never_panics_on_arbitrary_bytes(
            bytes in proptest::collection::vec(any::<u8>(), 0..600)
        ) {
            check(&String::from_utf8_lossy(&bytes));
        }

        #[test]
        fn every_camera_the_parser_accepts_is_valid(
            lines in proptest::collection::vec(
                (
                    proptest::sample::select(vec![
                        "width", "height", "fx", "fy", "cx", "cy", "k1", "k2", "p1", "p2",
                        "k3", "depth_scale", "frame_rate_hz", "#", "other",
                    ]),
                    prop_oneof![
                        any::<f64>().prop_map(|x| x.to_string()),
                        (0u32..20000).prop_map(|x| x.to_string()),
                        proptest::sample::select(vec![
                            "nan", "inf", "-inf", "1e400", "-0", "0", "0.5", "16384", "16385",
                            "640", "", "x",
                        ])
                        .prop_map(str::to_owned),
                    ],
                ),
                0..20,
            )
        ) {
            let text: Vec<String> = lines.iter().map(|(k, v)| format!("{k} {v}")).collect();
            check(&text.join("\n"));
        }
    }
}
