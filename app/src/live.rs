//! Streamed footage: frames that arrive one by one (a live camera, a video file), tracked in
//! order as they come and shown as they come, and the recorder that writes them as a TUM-layout
//! folder so a live session replays like recorded footage.
//!
//! A stream has no frame list to seek in or loop over: the player shows each frame once, in
//! order (pausing freezes the shown frame). On desktop OpenCV's videoio reads the stream and the
//! tracker runs on it ([`crate::live_capture`]); phone shells can implement [`LiveStream`] with
//! the platform's AR session.

use std::io::Write;
use std::path::{Path, PathBuf};
use std::sync::mpsc;
use std::thread::JoinHandle;

use anyhow::{Context, bail};
use image::RgbaImage;
use sylva_tracking::Camera;

use crate::footage::FootageFrame;
use crate::render::Intrinsics;
use crate::scene_tracking::SceneFrame;

/// Horizontal field of view assumed for a camera without calibration, degrees.
pub const DEFAULT_HORIZONTAL_FOV_DEG: f64 = 60.0;

/// One streamed frame, tracked.
pub struct LiveFrame {
    /// Seconds since the stream started.
    pub time_s: f64,
    /// The colour image as shown.
    pub rgba: RgbaImage,
    /// Tracking, ground plane and depth mesh of this frame.
    pub scene: SceneFrame,
}

/// What a stream has next.
pub enum LiveNext {
    Frame(Box<LiveFrame>),
    /// No new frame yet (a live camera between frames).
    Pending,
    /// The stream ended (end of the video file, camera disconnected).
    Ended,
}

/// A stream of tracked frames.
pub trait LiveStream {
    /// The camera model of the frames.
    fn camera(&self) -> &Camera;
    /// `camera N` or the video file, for messages and the session.
    fn describe(&self) -> &str;
    /// Frames per second of the stream.
    fn frame_rate_hz(&self) -> f64;
    /// Whether frames come at the capture's own pace (a live camera) rather than when asked
    /// (a file, played at its frame rate).
    fn is_live_camera(&self) -> bool;
    /// The next frame; with `wait`, blocks until it comes or the stream ends.
    fn next(&mut self, wait: bool) -> anyhow::Result<LiveNext>;
}

/// The renderer's intrinsics of a tracking camera model.
pub fn intrinsics_of(camera: &Camera) -> Intrinsics {
    Intrinsics {
        width: camera.width,
        height: camera.height,
        fx: camera.fx as f32,
        fy: camera.fy as f32,
        cx: camera.cx as f32,
        cy: camera.cy as f32,
        distortion: camera.distortion.map(|d| d as f32),
    }
}

/// A guess for an uncalibrated camera: no distortion, square pixels, principal point at the
/// centre and a horizontal field of view of [`DEFAULT_HORIZONTAL_FOV_DEG`].
pub fn default_camera(width: u32, height: u32, frame_rate_hz: f64) -> Camera {
    let fx = 0.5 * f64::from(width) / (0.5 * DEFAULT_HORIZONTAL_FOV_DEG.to_radians()).tan();
    let mut camera = Camera::pinhole(
        width,
        height,
        fx,
        fx,
        0.5 * (f64::from(width) - 1.0),
        0.5 * (f64::from(height) - 1.0),
    );
    camera.frame_rate_hz = Some(frame_rate_hz);
    camera
}

/// The text of a `camera.txt` that [`Camera::from_file`] reads back to `camera`.
pub fn camera_file_text(camera: &Camera) -> String {
    let mut text =
        String::from("# Camera model of a recorded live stream (sylva view --record).\n");
    let [k1, k2, p1, p2, k3] = camera.distortion;
    let rows: [(&str, f64); 11] = [
        ("width", f64::from(camera.width)),
        ("height", f64::from(camera.height)),
        ("fx", camera.fx),
        ("fy", camera.fy),
        ("cx", camera.cx),
        ("cy", camera.cy),
        ("k1", k1),
        ("k2", k2),
        ("p1", p1),
        ("p2", p2),
        ("k3", k3),
    ];
    for (key, value) in rows {
        text.push_str(&format!("{key} {value}\n"));
    }
    if let Some(hz) = camera.frame_rate_hz {
        text.push_str(&format!("frame_rate_hz {hz}\n"));
    }
    text
}

/// Writes streamed frames as a TUM-layout folder: `camera.txt`, `rgb/NNNNNN.png` (lossless, so
/// replays draw the pixels the app showed) and `rgb.txt`. Images are encoded on a writer thread.
pub struct FootageRecorder {
    root: PathBuf,
    sender: Option<mpsc::SyncSender<(f64, PathBuf, RgbaImage)>>,
    writer: Option<JoinHandle<anyhow::Result<()>>>,
    count: usize,
}

impl FootageRecorder {
    /// Starts a recording in `root` (created; refused if it already holds a recorded frame).
    pub fn create(root: &Path, camera: &Camera) -> anyhow::Result<FootageRecorder> {
        let rgb_list = root.join("rgb.txt");
        // A folder left by a start that failed before its first frame (no window) is reused.
        // Read bounded, and only a regular file: a FIFO or a device there is refused.
        let listed = sylva_tracking::input_file::read_regular_file(
            &rgb_list,
            sylva_tracking::input_file::MAX_LIST_FILE_BYTES,
        );
        let lists_frames = match listed {
            Ok(bytes) => String::from_utf8_lossy(&bytes)
                .lines()
                .any(|l| !l.trim().is_empty() && !l.trim_start().starts_with('#')),
            Err(e) if e.kind() == std::io::ErrorKind::NotFound => false,
            Err(e) => bail!("cannot record into {}: {e}", root.display()),
        };
        if lists_frames {
            bail!(
                "{} already holds a recording ({} exists); choose another folder",
                root.display(),
                rgb_list.display()
            );
        }
        let rgb = root.join("rgb");
        std::fs::create_dir_all(&rgb)
            .with_context(|| format!("cannot create {}", rgb.display()))?;
        let camera_path = root.join("camera.txt");
        crate::outputs::write_file(&camera_path, camera_file_text(camera).as_bytes())?;
        // rgb.txt is a log appended frame by frame (each line once its frame is on disk).
        sylva_core::safe_write::check_output(&rgb_list)?;
        let mut list = std::fs::File::create(&rgb_list)
            .with_context(|| format!("cannot create {}", rgb_list.display()))?;
        writeln!(list, "# timestamp filename (sylva view --record)")
            .with_context(|| format!("cannot write {}", rgb_list.display()))?;
        // A few frames in flight: a writer slower than the stream holds the app back instead of
        // filling the memory.
        let (sender, receiver) = mpsc::sync_channel::<(f64, PathBuf, RgbaImage)>(8);
        let root_owned = root.to_owned();
        let writer = std::thread::Builder::new()
            .name("sylva-recorder".into())
            .spawn(move || -> anyhow::Result<()> {
                for (time_s, relative, rgba) in receiver {
                    let path = root_owned.join(&relative);
                    crate::outputs::write_png(
                        &image::DynamicImage::ImageRgba8(rgba).to_rgb8(),
                        &path,
                    )?;
                    writeln!(list, "{time_s:.6} {}", relative.display())
                        .with_context(|| format!("cannot write {}", rgb_list.display()))?;
                }
                list.flush()
                    .and_then(|()| list.sync_all())
                    .with_context(|| format!("cannot write {}", rgb_list.display()))
            })
            .context("cannot start the recording thread")?;
        Ok(FootageRecorder {
            root: root.to_owned(),
            sender: Some(sender),
            writer: Some(writer),
            count: 0,
        })
    }

    /// The recording's folder.
    pub fn root(&self) -> &Path {
        &self.root
    }

    /// Frames recorded so far.
    pub fn len(&self) -> usize {
        self.count
    }

    pub fn is_empty(&self) -> bool {
        self.count == 0
    }

    /// Records the next frame; returns its footage entry.
    pub fn push(&mut self, time_s: f64, rgba: &RgbaImage) -> anyhow::Result<FootageFrame> {
        let relative = PathBuf::from(format!("rgb/{:06}.png", self.count));
        let sent = self
            .sender
            .as_ref()
            .is_some_and(|s| s.send((time_s, relative.clone(), rgba.clone())).is_ok());
        if !sent {
            // The writer stopped: its error says why.
            self.finish()?;
            bail!("the recording in {} has stopped", self.root.display());
        }
        self.count += 1;
        Ok(FootageFrame {
            time_s,
            rgb: self.root.join(relative),
            depth: None,
            world_from_camera: None,
        })
    }

    /// Writes the frames still queued and closes `rgb.txt`; the folder is then complete.
    pub fn finish(&mut self) -> anyhow::Result<()> {
        drop(self.sender.take());
        match self.writer.take().map(JoinHandle::join) {
            Some(Ok(result)) => result,
            Some(Err(_)) => bail!("the recording thread of {} failed", self.root.display()),
            None => Ok(()),
        }
    }
}

impl Drop for FootageRecorder {
    fn drop(&mut self) {
        if let Err(e) = self.finish() {
            eprintln!("warning: {e:#}");
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_default_camera_sees_sixty_degrees_across() {
        let camera = default_camera(640, 480, 30.0);
        let half_fov = (0.5 * f64::from(camera.width) / camera.fx)
            .atan()
            .to_degrees();
        assert!((2.0 * half_fov - 60.0).abs() < 1e-9);
        assert_eq!(camera.fx, camera.fy);
        assert_eq!((camera.cx, camera.cy), (319.5, 239.5));
    }

    #[test]
    fn a_written_camera_file_reads_back_to_the_same_camera() {
        let mut camera = Camera::pinhole(1280, 720, 911.25, 910.5, 640.1, 359.9);
        camera.distortion = [0.1, -0.25, 0.001, -0.002, 0.05];
        camera.frame_rate_hz = Some(29.97);
        let back = Camera::parse(&camera_file_text(&camera), Path::new("camera.txt"))
            .expect("the written file parses");
        assert_eq!(back, camera);
    }

    #[test]
    fn a_recording_is_a_tum_folder_the_footage_reader_opens() {
        let dir = tempfile::tempdir().expect("temp dir");
        let root = dir.path().join("rec");
        let camera = default_camera(8, 6, 30.0);
        let mut recorder = FootageRecorder::create(&root, &camera).expect("recorder");
        for i in 0..3u8 {
            let image = RgbaImage::from_pixel(8, 6, image::Rgba([i * 50, 10, 20, 255]));
            let entry = recorder.push(f64::from(i) / 30.0, &image).expect("push");
            assert_eq!(entry.rgb, root.join(format!("rgb/{i:06}.png")));
        }
        recorder.finish().expect("finish");
        let empty = dir.path().join("empty");
        drop(FootageRecorder::create(&empty, &camera).expect("an empty recording"));
        FootageRecorder::create(&empty, &camera).expect("a recording without frames is reused");
        let footage = crate::footage::Footage::open(&root).expect("reopens");
        assert_eq!(footage.len(), 3);
        assert_eq!(footage.intrinsics, intrinsics_of(&camera));
        let last = footage.load_rgba(2).expect("decodes");
        assert_eq!(last.get_pixel(3, 3).0, [100, 10, 20, 255]);
        let again = FootageRecorder::create(&root, &camera)
            .err()
            .expect("refused");
        assert!(format!("{again:#}").contains("already holds a recording"));
    }
}
