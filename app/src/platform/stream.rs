//! A platform's camera frames as the app's [`LiveStream`]: the shell pushes each frame into a
//! [`PlatformFeed`]; the stream tracks it with the platform's tracking (ARCore, ARKit) or with
//! Sylva's own tracker on the image, and the player shows it like any streamed frame.

use std::sync::mpsc;

use anyhow::bail;
use sylva_tracking::Camera;

use super::{PlatformFrame, PlatformIntrinsics, PlatformTracker};
use crate::live::{LiveFrame, LiveNext, LiveStream, intrinsics_of};

/// Which tracker makes the scene of a frame.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum TrackerChoice {
    /// The platform's AR session: every frame carries its tracking.
    Platform,
    /// Sylva's own tracker on the camera images (phones without ARCore or ARKit, or when the
    /// user picks it).
    Own,
}

/// The shell's end of a [`PlatformStream`]: frames go in here.
#[derive(Clone)]
pub struct PlatformFeed {
    sender: mpsc::Sender<PlatformFrame>,
}

impl PlatformFeed {
    /// Hands over the next camera frame; false once the stream is gone.
    pub fn push(&self, frame: PlatformFrame) -> bool {
        self.sender.send(frame).is_ok()
    }
}

enum FrameTracking {
    Platform(Box<PlatformTracker>),
    Own(Box<crate::scene_tracking::FrameTracker>),
}

/// Frames from a platform camera, tracked as they come.
pub struct PlatformStream {
    camera: Camera,
    describe: String,
    frame_rate_hz: f64,
    frames: mpsc::Receiver<PlatformFrame>,
    tracking: FrameTracking,
    num_frames: usize,
}

impl PlatformStream {
    /// A stream of `intrinsics` frames at `frame_rate_hz`, tracked by `choice`, described as
    /// `describe` (e.g. `ARCore camera`); returns it with the feed the shell pushes frames into.
    pub fn new(
        intrinsics: PlatformIntrinsics,
        frame_rate_hz: f64,
        choice: TrackerChoice,
        describe: &str,
    ) -> anyhow::Result<(PlatformStream, PlatformFeed)> {
        if intrinsics.width == 0
            || intrinsics.height == 0
            || ![intrinsics.fx, intrinsics.fy]
                .iter()
                .all(|f| f.is_finite() && *f > 0.0)
            || ![intrinsics.cx, intrinsics.cy].iter().all(|c| c.is_finite())
        {
            bail!("{describe}: unusable camera intrinsics {intrinsics:?}");
        }
        let camera = intrinsics.camera(frame_rate_hz);
        let tracking = match choice {
            TrackerChoice::Platform => {
                FrameTracking::Platform(Box::new(PlatformTracker::new(intrinsics_of(&camera))))
            }
            TrackerChoice::Own => own_tracker(camera, describe)?,
        };
        let (sender, frames) = mpsc::channel();
        Ok((
            PlatformStream {
                camera,
                describe: describe.to_owned(),
                frame_rate_hz,
                frames,
                tracking,
                num_frames: 0,
            },
            PlatformFeed { sender },
        ))
    }

    fn track(&mut self, frame: PlatformFrame) -> anyhow::Result<LiveFrame> {
        let index = self.num_frames;
        self.num_frames += 1;
        if (frame.intrinsics.width, frame.intrinsics.height)
            != (self.camera.width, self.camera.height)
            || (frame.rgba.width(), frame.rgba.height()) != (self.camera.width, self.camera.height)
        {
            bail!(
                "{}: frame {index} is {} x {} (intrinsics {} x {}), the stream's camera is {} x {}",
                self.describe,
                frame.rgba.width(),
                frame.rgba.height(),
                frame.intrinsics.width,
                frame.intrinsics.height,
                self.camera.width,
                self.camera.height
            );
        }
        let scene = match &mut self.tracking {
            FrameTracking::Platform(tracker) => {
                let Some(tracking) = &frame.tracking else {
                    bail!(
                        "{}: frame {index} came without the platform's tracking",
                        self.describe
                    );
                };
                tracker.track(tracking)
            }
            FrameTracking::Own(tracker) => {
                let gray = image::DynamicImage::ImageRgba8(frame.rgba.clone()).to_luma8();
                let (width, height) = gray.dimensions();
                let image = sylva_tracking::GrayImage::from_pixels(width, height, gray.into_raw())
                    .ok_or_else(|| {
                        anyhow::anyhow!("{}: frame {index}: bad pixels", self.describe)
                    })?;
                let frame_in = sylva_tracking::Frame {
                    index,
                    timestamp_s: frame.time_s,
                    image,
                };
                tracker.track(&frame_in, frame.up_in_camera)?
            }
        };
        Ok(LiveFrame {
            time_s: frame.time_s,
            rgba: frame.rgba,
            scene,
        })
    }
}

fn own_tracker(camera: Camera, describe: &str) -> anyhow::Result<FrameTracking> {
    use anyhow::Context;
    let tracker = crate::scene_tracking::FrameTracker::new(camera, intrinsics_of(&camera))
        .with_context(|| format!("cannot start Sylva's tracker on {describe}"))?;
    Ok(FrameTracking::Own(Box::new(tracker)))
}

impl LiveStream for PlatformStream {
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
        true
    }

    fn next(&mut self, wait: bool) -> anyhow::Result<LiveNext> {
        let received = if wait {
            self.frames
                .recv()
                .map_err(|_| mpsc::TryRecvError::Disconnected)
        } else {
            self.frames.try_recv()
        };
        match received {
            Ok(frame) => Ok(LiveNext::Frame(Box::new(self.track(frame)?))),
            Err(mpsc::TryRecvError::Empty) => Ok(LiveNext::Pending),
            Err(mpsc::TryRecvError::Disconnected) => Ok(LiveNext::Ended),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::platform::PlatformTracking;
    use glam::{Mat4, Vec3};

    fn intrinsics() -> PlatformIntrinsics {
        PlatformIntrinsics {
            width: 8,
            height: 6,
            fx: 10.0,
            fy: 10.0,
            cx: 4.0,
            cy: 3.0,
        }
    }

    fn frame(width: u32, tracking: Option<PlatformTracking>) -> PlatformFrame {
        PlatformFrame {
            time_s: 0.5,
            rgba: image::RgbaImage::new(width, 6),
            intrinsics: PlatformIntrinsics {
                width,
                ..intrinsics()
            },
            tracking,
            up_in_camera: None,
        }
    }

    #[test]
    fn a_pushed_platform_frame_comes_out_tracked_and_a_wrong_one_is_refused_by_name() {
        let (mut stream, feed) =
            PlatformStream::new(intrinsics(), 30.0, TrackerChoice::Platform, "test camera")
                .expect("stream");
        assert!(matches!(stream.next(false), Ok(LiveNext::Pending)));
        let pose = Mat4::from_translation(Vec3::new(0.0, 1.0, 0.0));
        let tracking = PlatformTracking {
            world_from_camera: Some(pose),
            ..PlatformTracking::default()
        };
        assert!(feed.push(frame(8, Some(tracking))));
        let Ok(LiveNext::Frame(shown)) = stream.next(true) else {
            panic!("a frame");
        };
        assert_eq!(shown.scene.world_from_camera, Some(pose));
        assert_eq!(shown.time_s, 0.5);
        feed.push(frame(8, None));
        let Err(error) = stream.next(true) else {
            panic!("refused")
        };
        assert!(
            format!("{error}").contains("test camera: frame 1 came without"),
            "{error}"
        );
        feed.push(frame(9, None));
        let Err(error) = stream.next(true) else {
            panic!("refused")
        };
        assert!(format!("{error}").contains("frame 2 is 9 x 6"), "{error}");
        drop(feed);
        assert!(matches!(stream.next(true), Ok(LiveNext::Ended)));
        let bad = PlatformIntrinsics {
            fx: 0.0,
            ..intrinsics()
        };
        assert!(PlatformStream::new(bad, 30.0, TrackerChoice::Platform, "x").is_err());
    }
}
