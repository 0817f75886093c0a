//! Recorded footage: the TUM RGB-D layout and image folders, behind one [`FrameSource`] trait.
//!
//! A TUM sequence is a folder with `rgb.txt` (`timestamp path` per line), `camera.txt` (see
//! [`Camera::from_file`]) and optionally `groundtruth.txt` (`timestamp tx ty tz qx qy qz qw`,
//! `world_from_camera`), `depth.txt` and `accelerometer.txt` (`timestamp ax ay az`).
//! Unreadable frames are skipped and reported as [`SourceEvent::Skipped`], naming the file.

use crate::camera::{Camera, CameraError};
use crate::frame::{Frame, GrayImage};
use glam::{DAffine3, DQuat, DVec3};
use std::path::{Path, PathBuf};

/// A footage folder or file could not be opened.
#[derive(Debug, thiserror::Error)]
pub enum SequenceError {
    #[error("sequence {path} is not a folder or cannot be read")]
    NotFound { path: PathBuf },
    #[error("cannot read {path}: {source}")]
    Io {
        path: PathBuf,
        source: std::io::Error,
    },
    #[error("{path}, line {line}: {problem}")]
    Parse {
        path: PathBuf,
        line: usize,
        problem: String,
    },
    #[error("{path} lists no frames")]
    Empty { path: PathBuf },
    #[error(transparent)]
    Camera(#[from] CameraError),
    #[error("video source {what}: {problem}")]
    Video { what: String, problem: String },
}

/// What a footage source yields next.
#[derive(Debug)]
pub enum SourceEvent {
    Frame(Frame),
    /// A frame that could not be read; tracking goes on without it.
    Skipped {
        index: usize,
        path: PathBuf,
        reason: String,
    },
}

/// A source of timestamped grey frames.
pub trait FrameSource {
    /// The camera model of the footage.
    fn camera(&self) -> &Camera;
    /// The next frame, a skipped frame, or None at the end.
    fn next_event(&mut self) -> Option<SourceEvent>;
    /// Number of frames, when known in advance.
    fn len_hint(&self) -> Option<usize> {
        None
    }
}

/// A timestamped pose from `groundtruth.txt`.
#[derive(Clone, Copy, Debug)]
pub struct TimedPose {
    pub timestamp_s: f64,
    pub world_from_camera: DAffine3,
}

/// A timestamped accelerometer sample (m/s², sensor axes).
#[derive(Clone, Copy, Debug)]
pub struct TimedVector {
    pub timestamp_s: f64,
    pub value: DVec3,
}

/// A timestamped file (image or depth map).
#[derive(Clone, Debug)]
pub struct TimedFile {
    pub timestamp_s: f64,
    pub path: PathBuf,
}

/// A TUM RGB-D sequence folder.
#[derive(Clone, Debug)]
pub struct TumSequence {
    pub root: PathBuf,
    pub camera: Camera,
    pub frames: Vec<TimedFile>,
    pub groundtruth: Vec<TimedPose>,
    pub depth: Vec<TimedFile>,
    pub accelerometer: Vec<TimedVector>,
}

impl TumSequence {
    /// Opens a sequence folder: `rgb.txt` and `camera.txt` are required.
    pub fn open(root: &Path) -> Result<Self, SequenceError> {
        if !root.is_dir() {
            return Err(SequenceError::NotFound {
                path: root.to_path_buf(),
            });
        }
        let camera = Camera::from_file(&root.join("camera.txt"))?;
        let rgb_list = root.join("rgb.txt");
        let frames = read_file_list(root, &rgb_list)?;
        if frames.is_empty() {
            return Err(SequenceError::Empty { path: rgb_list });
        }
        let optional = |name: &str| {
            let path = root.join(name);
            path.is_file().then_some(path)
        };
        let groundtruth = match optional("groundtruth.txt") {
            Some(path) => read_rows(&path, 8)?
                .into_iter()
                .map(|(t, v)| TimedPose {
                    timestamp_s: t,
                    world_from_camera: DAffine3::from_rotation_translation(
                        DQuat::from_xyzw(v[3], v[4], v[5], v[6]).normalize(),
                        DVec3::new(v[0], v[1], v[2]),
                    ),
                })
                .collect(),
            None => Vec::new(),
        };
        let depth = match optional("depth.txt") {
            Some(path) => read_file_list(root, &path)?,
            None => Vec::new(),
        };
        let accelerometer = match optional("accelerometer.txt") {
            Some(path) => read_rows(&path, 4)?
                .into_iter()
                .map(|(t, v)| TimedVector {
                    timestamp_s: t,
                    value: DVec3::new(v[0], v[1], v[2]),
                })
                .collect(),
            None => Vec::new(),
        };
        Ok(Self {
            root: root.to_path_buf(),
            camera,
            frames,
            groundtruth,
            depth,
            accelerometer,
        })
    }

    /// The accelerometer sample nearest in time, within `max_gap_s`.
    pub fn accelerometer_at(&self, timestamp_s: f64, max_gap_s: f64) -> Option<DVec3> {
        nearest(&self.accelerometer, timestamp_s, |a| a.timestamp_s)
            .filter(|a| (a.timestamp_s - timestamp_s).abs() <= max_gap_s)
            .map(|a| a.value)
    }

    /// Gravity "up" in camera axes (X right, Y down, Z forward) from the accelerometer sample
    /// nearest in time. TUM's Kinect accelerometer has X left, Y up, Z forward, so X and Y flip
    /// (checked against the ground truth of fr1_rpy: agreement within about 10°).
    pub fn up_in_camera_at(&self, timestamp_s: f64) -> Option<DVec3> {
        let a = self.accelerometer_at(timestamp_s, 0.05)?;
        let up = DVec3::new(-a.x, -a.y, a.z);
        (up.length() > 1.0).then(|| up.normalize())
    }

    /// The ground-truth pose nearest in time, within `max_gap_s`.
    pub fn groundtruth_at(&self, timestamp_s: f64, max_gap_s: f64) -> Option<DAffine3> {
        nearest(&self.groundtruth, timestamp_s, |g| g.timestamp_s)
            .filter(|g| (g.timestamp_s - timestamp_s).abs() <= max_gap_s)
            .map(|g| g.world_from_camera)
    }

    /// A source that decodes the listed frames in order.
    pub fn source(&self) -> FileListSource {
        FileListSource {
            camera: self.camera,
            files: self.frames.clone(),
            next: 0,
        }
    }
}

/// The element of a time-sorted list nearest to `t`.
pub fn nearest<T>(items: &[T], t: f64, time: impl Fn(&T) -> f64) -> Option<&T> {
    let i = items.partition_point(|x| time(x) < t);
    let before = i.checked_sub(1).and_then(|j| items.get(j));
    match (before, items.get(i)) {
        (Some(a), Some(b)) => Some(if t - time(a) <= time(b) - t { a } else { b }),
        (a, b) => a.or(b),
    }
}

/// Decodes listed image files one by one (TUM `rgb.txt` or a sorted image folder).
#[derive(Clone, Debug)]
pub struct FileListSource {
    camera: Camera,
    files: Vec<TimedFile>,
    next: usize,
}

impl FileListSource {
    /// All PNG/JPEG files of a folder, sorted by name, at `frame_rate_hz` (default 30).
    pub fn image_folder(folder: &Path, camera: Camera) -> Result<Self, SequenceError> {
        let entries = std::fs::read_dir(folder).map_err(|source| SequenceError::Io {
            path: folder.to_path_buf(),
            source,
        })?;
        let mut paths: Vec<PathBuf> = entries
            .filter_map(|e| e.ok().map(|e| e.path()))
            .filter(|p| {
                let ext = p.extension().and_then(|e| e.to_str()).unwrap_or("");
                matches!(ext.to_ascii_lowercase().as_str(), "png" | "jpg" | "jpeg")
            })
            .collect();
        paths.sort();
        if paths.is_empty() {
            return Err(SequenceError::Empty {
                path: folder.to_path_buf(),
            });
        }
        let dt = 1.0 / camera.frame_rate_hz.unwrap_or(30.0);
        let files = paths
            .into_iter()
            .enumerate()
            .map(|(i, path)| TimedFile {
                timestamp_s: i as f64 * dt,
                path,
            })
            .collect();
        Ok(Self {
            camera,
            files,
            next: 0,
        })
    }
}

impl FrameSource for FileListSource {
    fn camera(&self) -> &Camera {
        &self.camera
    }

    fn next_event(&mut self) -> Option<SourceEvent> {
        let index = self.next;
        let file = self.files.get(index)?;
        self.next += 1;
        Some(match decode_gray(&file.path, &self.camera) {
            Ok(image) => SourceEvent::Frame(Frame {
                index,
                timestamp_s: file.timestamp_s,
                image,
            }),
            Err(reason) => SourceEvent::Skipped {
                index,
                path: file.path.clone(),
                reason,
            },
        })
    }

    fn len_hint(&self) -> Option<usize> {
        Some(self.files.len())
    }
}

/// Decodes an image file to grey, checking its size against the camera.
pub fn decode_gray(path: &Path, camera: &Camera) -> Result<GrayImage, String> {
    let bytes = std::fs::read(path).map_err(|e| e.to_string())?;
    check_complete(&bytes)?;
    let decoded = image::load_from_memory(&bytes).map_err(|e| e.to_string())?;
    let gray = decoded.to_luma8();
    if gray.width() != camera.width || gray.height() != camera.height {
        return Err(format!(
            "image is {} x {}, the camera says {} x {}",
            gray.width(),
            gray.height(),
            camera.width,
            camera.height
        ));
    }
    let (width, height) = gray.dimensions();
    GrayImage::from_pixels(width, height, gray.into_raw()).ok_or_else(|| "bad pixel buffer".into())
}

/// Decoders accept cut-off JPEGs (grey below the cut); a complete JPEG ends with the EOI
/// marker and a complete PNG with its IEND chunk.
fn check_complete(bytes: &[u8]) -> Result<(), String> {
    let is_jpeg = bytes.starts_with(&[0xFF, 0xD8]);
    let is_png = bytes.starts_with(b"\x89PNG");
    let tail = &bytes[bytes.len().saturating_sub(16)..];
    let jpeg_end = tail.windows(2).any(|w| w == [0xFF, 0xD9]);
    let png_end = tail.windows(4).any(|w| w == b"IEND");
    if (is_jpeg && !jpeg_end) || (is_png && !png_end) {
        return Err("truncated image file (no end marker)".into());
    }
    Ok(())
}

/// Decodes a 16-bit depth map to metres (0 where there is no measurement).
pub fn decode_depth_m(path: &Path, depth_scale: f64) -> Result<(u32, u32, Vec<f32>), String> {
    let bytes = std::fs::read(path).map_err(|e| e.to_string())?;
    let decoded = image::load_from_memory(&bytes).map_err(|e| e.to_string())?;
    let depth = decoded.to_luma16();
    let (w, h) = depth.dimensions();
    let metres = depth
        .into_raw()
        .into_iter()
        .map(|d| (d as f64 / depth_scale) as f32);
    Ok((w, h, metres.collect()))
}

fn read_text(path: &Path) -> Result<String, SequenceError> {
    std::fs::read_to_string(path).map_err(|source| SequenceError::Io {
        path: path.to_path_buf(),
        source,
    })
}

/// Rows of `timestamp v1 .. v(n-1)`, skipping comments and blank lines.
fn read_rows(path: &Path, columns: usize) -> Result<Vec<(f64, Vec<f64>)>, SequenceError> {
    let text = read_text(path)?;
    let mut rows = Vec::new();
    for (index, line) in text.lines().enumerate() {
        let line = line.trim();
        if line.is_empty() || line.starts_with('#') {
            continue;
        }
        let parsed: Result<Vec<f64>, _> = line.split_whitespace().map(str::parse::<f64>).collect();
        match parsed {
            Ok(values) if values.len() == columns && values.iter().all(|v| v.is_finite()) => {
                rows.push((values[0], values[1..].to_vec()))
            }
            _ => {
                return Err(SequenceError::Parse {
                    path: path.to_path_buf(),
                    line: index + 1,
                    problem: format!("expected {columns} numbers, found `{line}`"),
                });
            }
        }
    }
    rows.sort_by(|a, b| a.0.total_cmp(&b.0));
    Ok(rows)
}

/// A `timestamp relative/path` list.
fn read_file_list(root: &Path, list: &Path) -> Result<Vec<TimedFile>, SequenceError> {
    let text = read_text(list)?;
    let mut files = Vec::new();
    for (index, line) in text.lines().enumerate() {
        let line = line.trim();
        if line.is_empty() || line.starts_with('#') {
            continue;
        }
        let mut words = line.split_whitespace();
        let parsed = match (words.next(), words.next()) {
            (Some(t), Some(p)) => t
                .parse::<f64>()
                .ok()
                .filter(|t| t.is_finite())
                .map(|t| (t, p)),
            _ => None,
        };
        let Some((timestamp_s, relative)) = parsed else {
            return Err(SequenceError::Parse {
                path: list.to_path_buf(),
                line: index + 1,
                problem: format!("expected `timestamp path`, found `{line}`"),
            });
        };
        files.push(TimedFile {
            timestamp_s,
            path: root.join(relative),
        });
    }
    Ok(files)
}
