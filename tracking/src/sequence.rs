//! Recorded footage: the TUM RGB-D layout and image folders, behind one [`FrameSource`] trait.
//!
//! A TUM sequence is a folder with `rgb.txt` (`timestamp path` per line), `camera.txt` (see
//! [`Camera::from_file`]) and optionally `groundtruth.txt` (`timestamp tx ty tz qx qy qz qw`,
//! `world_from_camera`), `depth.txt` and `accelerometer.txt` (`timestamp ax ay az`).
//! Unreadable frames are skipped and reported as [`SourceEvent::Skipped`], naming the file.
//!
//! Every reader opens only regular files and caps what it reads ([`crate::input_file`]); list
//! timestamps must increase strictly, line by line, and ground-truth quaternions must be unit
//! length, so a damaged list is an error naming its line rather than a figure computed from it.

use crate::camera::{Camera, CameraError};
use crate::frame::{Frame, GrayImage};
use crate::input_file::{
    self, MAX_IMAGE_FILE_BYTES, MAX_LIST_FILE_BYTES, decode_image, decode_limits,
    read_regular_file, read_regular_text,
};
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
        // A listed name that is there but is not a readable regular file is an error, not
        // footage without that part.
        let optional = |name: &str| {
            let path = root.join(name);
            input_file::exists(&path).then_some(path)
        };
        let groundtruth = match optional("groundtruth.txt") {
            Some(path) => read_poses(&path)?,
            None => Vec::new(),
        };
        let depth = match optional("depth.txt") {
            Some(path) => read_file_list(root, &path)?,
            None => Vec::new(),
        };
        let accelerometer = match optional("accelerometer.txt") {
            Some(path) => read_rows(&path, 4)?
                .into_iter()
                .map(|row| TimedVector {
                    timestamp_s: row.timestamp_s,
                    value: DVec3::new(row.values[0], row.values[1], row.values[2]),
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
    let bytes = read_image_file(path)?;
    let decoded = decode_image(&bytes, decode_limits(camera.width, camera.height))
        .map_err(|e| format!("{e} (the camera says {} x {})", camera.width, camera.height))?;
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

/// The bytes of an image file (a regular file of at most [`MAX_IMAGE_FILE_BYTES`]), checked
/// to be complete.
pub fn read_image_file(path: &Path) -> Result<Vec<u8>, String> {
    let bytes = read_regular_file(path, MAX_IMAGE_FILE_BYTES).map_err(|e| e.to_string())?;
    check_complete(&bytes)?;
    Ok(bytes)
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
    let bytes = read_image_file(path)?;
    let side = crate::camera::MAX_IMAGE_SIDE;
    let decoded = decode_image(&bytes, decode_limits(side, side))?;
    let depth = decoded.to_luma16();
    let (w, h) = depth.dimensions();
    let metres = depth
        .into_raw()
        .into_iter()
        .map(|d| (d as f64 / depth_scale) as f32);
    Ok((w, h, metres.collect()))
}

fn read_text(path: &Path) -> Result<String, SequenceError> {
    read_regular_text(path, MAX_LIST_FILE_BYTES).map_err(|source| SequenceError::Io {
        path: path.to_path_buf(),
        source,
    })
}

/// One row of a timestamped list: its timestamp, the other numbers, and its line (from 1).
#[derive(Clone, Debug, PartialEq)]
pub struct Row {
    pub timestamp_s: f64,
    pub values: Vec<f64>,
    pub line: usize,
}

/// Checks that each row's timestamp follows the previous row's.
struct Increasing<'a> {
    path: &'a Path,
    previous_s: Option<f64>,
}

impl Increasing<'_> {
    fn check(&mut self, timestamp_s: f64, line: usize) -> Result<(), SequenceError> {
        if let Some(previous_s) = self.previous_s
            && timestamp_s <= previous_s
        {
            let what = if timestamp_s == previous_s {
                "repeats"
            } else {
                "goes back from"
            };
            return Err(SequenceError::Parse {
                path: self.path.to_path_buf(),
                line,
                problem: format!(
                    "timestamp {timestamp_s} {what} the previous one ({previous_s}); \
                     timestamps must increase"
                ),
            });
        }
        self.previous_s = Some(timestamp_s);
        Ok(())
    }
}

/// Rows of `timestamp v1 .. v(n-1)` from `text` (the contents of `path`, which only names the
/// file in errors), skipping comments and blank lines. Every number must be finite and the
/// timestamps must increase.
pub fn parse_rows(text: &str, path: &Path, columns: usize) -> Result<Vec<Row>, SequenceError> {
    let mut rows = Vec::new();
    let mut increasing = Increasing {
        path,
        previous_s: None,
    };
    for (index, line) in text.lines().enumerate() {
        let line = line.trim();
        if line.is_empty() || line.starts_with('#') {
            continue;
        }
        let parsed: Result<Vec<f64>, _> = line.split_whitespace().map(str::parse::<f64>).collect();
        match parsed {
            Ok(values) if values.len() == columns && values.iter().all(|v| v.is_finite()) => {
                increasing.check(values[0], index + 1)?;
                rows.push(Row {
                    timestamp_s: values[0],
                    values: values[1..].to_vec(),
                    line: index + 1,
                });
            }
            _ => {
                return Err(SequenceError::Parse {
                    path: path.to_path_buf(),
                    line: index + 1,
                    problem: format!("expected {columns} finite numbers, found `{line}`"),
                });
            }
        }
    }
    Ok(rows)
}

fn read_rows(path: &Path, columns: usize) -> Result<Vec<Row>, SequenceError> {
    parse_rows(&read_text(path)?, path, columns)
}

/// Largest distance of a ground-truth quaternion's length from 1.
pub const QUATERNION_LENGTH_TOLERANCE: f64 = 0.1;

/// Poses of `groundtruth.txt` (`timestamp tx ty tz qx qy qz qw`) from `text`; a quaternion
/// that is not of unit length (zero, say) is an error naming its line.
pub fn parse_poses(text: &str, path: &Path) -> Result<Vec<TimedPose>, SequenceError> {
    parse_rows(text, path, 8)?
        .into_iter()
        .map(|row| {
            let v = &row.values;
            let rotation = DQuat::from_xyzw(v[3], v[4], v[5], v[6]);
            let length = rotation.length();
            // Written so that a NaN length fails too.
            let unit = (length - 1.0).abs() <= QUATERNION_LENGTH_TOLERANCE;
            if !unit {
                return Err(SequenceError::Parse {
                    path: path.to_path_buf(),
                    line: row.line,
                    problem: format!(
                        "quaternion ({}, {}, {}, {}) has length {length}, not 1",
                        v[3], v[4], v[5], v[6]
                    ),
                });
            }
            Ok(TimedPose {
                timestamp_s: row.timestamp_s,
                world_from_camera: DAffine3::from_rotation_translation(
                    rotation.normalize(),
                    DVec3::new(v[0], v[1], v[2]),
                ),
            })
        })
        .collect()
}

fn read_poses(path: &Path) -> Result<Vec<TimedPose>, SequenceError> {
    parse_poses(&read_text(path)?, path)
}

/// A `timestamp relative/path` list from `text` (the contents of `list`; paths are relative
/// to `root`); timestamps must be finite and increase.
pub fn parse_file_list(
    text: &str,
    root: &Path,
    list: &Path,
) -> Result<Vec<TimedFile>, SequenceError> {
    let mut files = Vec::new();
    let mut increasing = Increasing {
        path: list,
        previous_s: None,
    };
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
        increasing.check(timestamp_s, index + 1)?;
        files.push(TimedFile {
            timestamp_s,
            path: root.join(relative),
        });
    }
    Ok(files)
}

fn read_file_list(root: &Path, list: &Path) -> Result<Vec<TimedFile>, SequenceError> {
    parse_file_list(&read_text(list)?, root, list)
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::collection::vec;
    use proptest::prelude::*;

    use crate::fuzz_config as config;

    /// Words a damaged list could hold: numbers of every kind, names, comments.
    fn word() -> impl Strategy<Value = String> {
        prop_oneof![
            any::<f64>().prop_map(|x| x.to_string()),
            (0u32..100).prop_map(|x| format!("{}.{x:02}", x / 10)),
            prop::sample::select(vec![
                "nan",
                "NaN",
                "inf",
                "-inf",
                "1e400",
                "-0",
                "0",
                "1",
                "0.0",
                "#",
                "rgb/1.png",
                "..",
                "/dev/zero",
                "",
                "1.0.0",
                "+",
                "e5",
            ])
            .prop_map(str::to_owned),
            "\\PC{0,6}",
        ]
    }

    fn list_text() -> impl Strategy<Value = String> {
        let line = vec(word(), 0..10).prop_map(|words| words.join(" "));
        vec(line, 0..24).prop_map(|lines| lines.join("\n"))
    }

    /// What every accepted row must satisfy.
    fn check_rows(rows: &[Row], columns: usize) {
        for pair in rows.windows(2) {
            assert!(pair[0].timestamp_s < pair[1].timestamp_s, "{rows:?}");
        }
        for row in rows {
            assert_eq!(row.values.len(), columns - 1);
            assert!(row.timestamp_s.is_finite() && row.values.iter().all(|v| v.is_finite()));
        }
    }

    fn check_all(text: &str) {
        let path = Path::new("list.txt");
        if let Ok(rows) = parse_rows(text, path, 4) {
            check_rows(&rows, 4);
        }
        if let Ok(poses) = parse_poses(text, path) {
            for pose in &poses {
                let m = glam::DMat4::from(pose.world_from_camera);
                assert!(m.is_finite(), "{m}");
                let det = pose.world_from_camera.matrix3.determinant();
                assert!((det - 1.0).abs() < 1e-9, "rotation determinant {det}");
            }
        }
        if let Ok(files) = parse_file_list(text, Path::new("root"), path) {
            for pair in files.windows(2) {
                assert!(pair[0].timestamp_s < pair[1].timestamp_s);
            }
        }
    }

    proptest! {
        #![proptest_config(config())]

        #[test]
        fn list_readers_never_panic_on_arbitrary_bytes(bytes in vec(any::<u8>(), 0..600)) {
            check_all(&String::from_utf8_lossy(&bytes));
        }

        #[test]
        fn list_readers_never_panic_and_keep_their_invariants_on_number_like_lines(
            text in list_text()
        ) {
            check_all(&text);
        }
    }

    #[test]
    fn a_repeated_timestamp_is_an_error_naming_the_file_and_line() {
        let text = "# t x y z\n1.0 0 0 9.8\n1.5 0 0 9.8\n1.5 0 0 9.8\n";
        let err = parse_rows(text, Path::new("accelerometer.txt"), 4).expect_err("a repeat");
        let message = err.to_string();
        assert!(
            message.contains("accelerometer.txt, line 4") && message.contains("repeats"),
            "{message}"
        );
        let err = parse_file_list("2 a.png\n1 b.png\n", Path::new("."), Path::new("rgb.txt"))
            .expect_err("going back");
        assert!(err.to_string().contains("rgb.txt, line 2"), "{err}");
    }

    #[test]
    fn zero_and_non_unit_quaternions_are_errors_naming_the_line() {
        let path = Path::new("groundtruth.txt");
        let good = "1.0 0 0 0 0 0 0 1\n";
        assert_eq!(parse_poses(good, path).expect("a unit quaternion").len(), 1);
        for bad in [
            "2.0 0 0 0 0 0 0 0",
            "2.0 0 0 0 0.2 0 0 0.2",
            "2.0 0 0 0 0 0 0 nan",
        ] {
            let err = parse_poses(&format!("{good}{bad}\n"), path).expect_err(bad);
            assert!(err.to_string().contains("line 2"), "{bad}: {err}");
        }
    }

    #[test]
    fn a_frame_that_is_not_a_regular_file_is_skipped_naming_it() {
        let camera = Camera::pinhole(4, 4, 4.0, 4.0, 2.0, 2.0);
        let reason = decode_gray(Path::new("/dev/zero"), &camera).expect_err("a device");
        assert!(reason.contains("not a regular file"), "{reason}");
    }
}
