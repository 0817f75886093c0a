//! Desktop streams: a live camera or a video file read by OpenCV's videoio
//! ([`sylva_tracking::cv::VideoSource`]) and tracked on a capture thread, frame after frame in
//! the order they arrive (the tracker is causal), so the window stays responsive while it tracks.
//!
//! A video file is read when the player asks for frames (none is lost, the session is the same
//! every run). A live camera runs at its own pace: frames that arrive while the player is still
//! busy with earlier ones (or paused) are tracked but not shown, so what is shown stays current.

use std::path::{Path, PathBuf};
use std::sync::mpsc::{self, Receiver, RecvTimeoutError, TryRecvError};
use std::thread::JoinHandle;
use std::time::Duration;

use anyhow::{Context, bail};
use sylva_tracking::cv::VideoSource;
use sylva_tracking::{Camera, SourceEvent};

use crate::live::{
    DEFAULT_HORIZONTAL_FOV_DEG, LiveFrame, LiveNext, LiveStream, default_camera, intrinsics_of,
};
use crate::scene_tracking::FrameTracker;

/// What to open.
#[derive(Clone, Debug, PartialEq)]
pub enum StreamInput {
    /// A live camera by index.
    Camera(u32),
    /// A video file (or an image pattern such as `frames/%04d.png`).
    File(PathBuf),
}

impl StreamInput {
    fn describe(&self) -> String {
        match self {
            StreamInput::Camera(index) => format!("camera {index}"),
            StreamInput::File(path) => path.display().to_string(),
        }
    }
}

/// Camera model, then frames or the reason the stream stopped.
enum Message {
    Opened(Camera, f64),
    Frame(Box<LiveFrame>),
    Failed(anyhow::Error),
}

/// A tracked stream from OpenCV's videoio.
pub struct VideoStream {
    camera: Camera,
    describe: String,
    frame_rate_hz: f64,
    live_camera: bool,
    frames: Option<Receiver<Message>>,
    worker: Option<JoinHandle<()>>,
    ended: bool,
}

impl VideoStream {
    /// Opens `input` with the intrinsics in `calibration` (a `camera.txt`), or without one a
    /// guess from the frame size (logged, with a warning: metric scale and occlusion are then
    /// approximate).
    pub fn open(input: StreamInput, calibration: Option<&Path>) -> anyhow::Result<VideoStream> {
        let calibration = calibration
            .map(|path| {
                Camera::from_file(path)
                    .with_context(|| format!("cannot read the calibration {}", path.display()))
            })
            .transpose()?;
        let describe = input.describe();
        let live_camera = matches!(input, StreamInput::Camera(_));
        // A file waits for the player (nothing lost); a camera keeps one frame in hand.
        let (sender, frames) = mpsc::sync_channel(if live_camera { 1 } else { 4 });
        let worker = std::thread::Builder::new()
            .name("sylva-capture".into())
            .spawn(move || capture(input, calibration, sender))
            .context("cannot start the capture thread")?;
        let mut stream = VideoStream {
            camera: Camera::pinhole(1, 1, 1.0, 1.0, 0.0, 0.0),
            describe,
            frame_rate_hz: 30.0,
            live_camera,
            frames: Some(frames),
            worker: Some(worker),
            ended: false,
        };
        match stream.receive(true) {
            Received::Message(Message::Opened(camera, frame_rate_hz)) => {
                stream.camera = camera;
                stream.frame_rate_hz = frame_rate_hz;
                Ok(stream)
            }
            Received::Message(Message::Failed(e)) => Err(e),
            _ => bail!(
                "{}: the capture stopped before the first frame",
                stream.describe
            ),
        }
    }

    fn receive(&self, wait: bool) -> Received {
        let Some(frames) = self.frames.as_ref() else {
            return Received::Closed;
        };
        if !wait {
            return match frames.try_recv() {
                Ok(message) => Received::Message(message),
                Err(TryRecvError::Empty) => Received::Empty,
                Err(TryRecvError::Disconnected) => Received::Closed,
            };
        }
        loop {
            match frames.recv_timeout(Duration::from_secs(10)) {
                Ok(message) => return Received::Message(message),
                Err(RecvTimeoutError::Disconnected) => return Received::Closed,
                Err(RecvTimeoutError::Timeout) => {
                    eprintln!("waiting for a frame from {}…", self.describe)
                }
            }
        }
    }
}

enum Received {
    Message(Message),
    /// Nothing yet.
    Empty,
    /// The capture thread has stopped and everything it sent was received.
    Closed,
}

impl LiveStream for VideoStream {
    fn camera(&self) -> &Camera {
        &self.camera
    }

    fn describe(&self) -> &str {
        &self.describe
    }

    fn frame_rate_hz(&self) -> f64 {
        self.frame_rate_hz
    }

    fn is_live_camera(&self) -> bool {
        self.live_camera
    }

    fn next(&mut self, wait: bool) -> anyhow::Result<LiveNext> {
        if self.ended {
            return Ok(LiveNext::Ended);
        }
        match self.receive(wait) {
            Received::Message(Message::Frame(frame)) => Ok(LiveNext::Frame(frame)),
            Received::Message(Message::Failed(e)) => {
                self.ended = true;
                Err(e)
            }
            Received::Message(Message::Opened(..)) => bail!("{}: opened twice", self.describe),
            Received::Empty => Ok(LiveNext::Pending),
            Received::Closed => {
                self.ended = true;
                Ok(LiveNext::Ended)
            }
        }
    }
}

impl Drop for VideoStream {
    fn drop(&mut self) {
        // Closing the channel stops the capture thread at its next frame.
        drop(self.frames.take());
        if let Some(worker) = self.worker.take() {
            let _ = worker.join();
        }
    }
}

/// The camera model of an opened stream: the calibration (its size must match the frames) or
/// the default guess.
fn resolve_camera(source: &VideoSource, calibration: Option<Camera>) -> anyhow::Result<Camera> {
    let what = source.what().to_owned();
    let Some((width, height)) = source.frame_size() else {
        bail!("{what}: the stream does not report its frame size");
    };
    let frame_rate_hz = source.frame_rate_hz();
    match calibration {
        Some(camera) if (camera.width, camera.height) != (width, height) => bail!(
            "{what} gives {width} x {height} frames, the calibration is for {} x {}",
            camera.width,
            camera.height
        ),
        Some(camera) => Ok(camera),
        None => {
            let camera = default_camera(width, height, frame_rate_hz);
            eprintln!(
                "warning: {what} has no calibration (--calibration camera.txt): assuming a {DEFAULT_HORIZONTAL_FOV_DEG}° horizontal field of view, fx = fy = {:.1} px, principal point at the centre, no distortion; metric scale and occlusion will be approximate",
                camera.fx
            );
            Ok(camera)
        }
    }
}

fn open_source(input: &StreamInput, calibration: Option<Camera>) -> anyhow::Result<VideoSource> {
    // The model is set once the frame size is known.
    let placeholder = Camera::pinhole(1, 1, 1.0, 1.0, 0.0, 0.0);
    let mut source = match input {
        StreamInput::Camera(index) => {
            let index = i32::try_from(*index).context("camera index too large")?;
            let mut source = VideoSource::open_camera(index, placeholder).with_context(|| {
                format!("cannot open live camera {index} (is a camera connected at that index?)")
            })?;
            if let Some(camera) = calibration {
                // The calibrated size, if the camera offers it (checked below).
                source.request_frame_size(camera.width, camera.height);
            }
            source
        }
        StreamInput::File(path) => VideoSource::open_file(path, placeholder)
            .with_context(|| format!("cannot open the video {}", path.display()))?,
    };
    let camera = resolve_camera(&source, calibration)?;
    source.set_camera(camera);
    Ok(source)
}

/// The capture thread: opens the stream, then reads and tracks frames until the stream ends or
/// the player drops its end of the channel.
fn capture(input: StreamInput, calibration: Option<Camera>, sender: mpsc::SyncSender<Message>) {
    // One OpenCV thread (deterministic tracking) and no videoio chatter: failures are reported
    // as errors.
    sylva_tracking::cv::configure_single_thread();
    let opened = open_source(&input, calibration).and_then(|source| {
        let camera = *sylva_tracking::FrameSource::camera(&source);
        let tracker = FrameTracker::new(camera, intrinsics_of(&camera))
            .with_context(|| format!("cannot start the tracker on {}", input.describe()))?;
        Ok((source, tracker))
    });
    let (mut source, mut tracker) = match opened {
        Ok(parts) => parts,
        Err(e) => {
            let _ = sender.send(Message::Failed(e));
            return;
        }
    };
    let camera = *sylva_tracking::FrameSource::camera(&source);
    if sender
        .send(Message::Opened(camera, source.frame_rate_hz()))
        .is_err()
    {
        return;
    }
    stream_frames(
        &mut source,
        &mut tracker,
        &sender,
        matches!(input, StreamInput::Camera(_)),
    );
}

/// Frames skipped in a row (unreadable, wrong size) after which the stream is given up.
const MAX_SKIPPED_IN_A_ROW: usize = 30;

/// Reads, tracks and sends frames in order until the stream ends, fails, or the player is gone.
fn stream_frames(
    source: &mut VideoSource,
    tracker: &mut FrameTracker,
    sender: &mpsc::SyncSender<Message>,
    live_camera: bool,
) {
    let mut skipped_in_a_row = 0;
    while let Some((event, rgb)) = source.next_color() {
        let message = match (event, rgb) {
            (SourceEvent::Frame(frame), Some(rgb)) => match tracker.track(&frame, None) {
                Ok(scene) => Message::Frame(Box::new(LiveFrame {
                    time_s: frame.timestamp_s,
                    rgba: image::DynamicImage::ImageRgb8(rgb).to_rgba8(),
                    scene,
                })),
                Err(e) => Message::Failed(e),
            },
            (SourceEvent::Skipped { index, reason, .. }, _) => {
                skipped_in_a_row += 1;
                if skipped_in_a_row < MAX_SKIPPED_IN_A_ROW {
                    eprintln!(
                        "warning: {}: skipped frame {index}: {reason}",
                        source.what()
                    );
                    continue;
                }
                Message::Failed(anyhow::anyhow!(
                    "{}: {skipped_in_a_row} frames in a row could not be read (last: {reason})",
                    source.what()
                ))
            }
            (SourceEvent::Frame(frame), None) => Message::Failed(anyhow::anyhow!(
                "{}: frame {} came without its colour image",
                source.what(),
                frame.index
            )),
        };
        let failed = matches!(message, Message::Failed(_));
        if !failed {
            skipped_in_a_row = 0;
        }
        let delivered = if live_camera && !failed {
            // The player still has the previous frame: this one is tracked, not shown.
            !matches!(
                sender.try_send(message),
                Err(mpsc::TrySendError::Disconnected(_))
            )
        } else {
            sender.send(message).is_ok()
        };
        if failed || !delivered {
            return;
        }
    }
}
