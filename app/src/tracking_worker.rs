//! Recorded footage's tracking, on the calling thread or on a worker thread (the window).
//!
//! The tracker is causal and each frame is tracked once, in order ([`SceneTracker`]). On a
//! worker, the window asks for frames ahead of the one shown and picks each result up when it is
//! there ([`TrackedFootage::ready`]), so a redraw never waits for the tracker: playback and
//! seeking show the next frame once it is tracked and draw the current one until then. Both
//! ways track the same frames in the same order, so they give the same scenes.

use std::path::{Path, PathBuf};
use std::sync::mpsc::{Receiver, Sender, TryRecvError};

use anyhow::Context;

use crate::render::Intrinsics;
use crate::scene_tracking::{SceneFrame, SceneTracker};

/// Frames the worker tracks ahead of the one asked for, so that playback finds the next frame
/// ready.
pub const TRACK_AHEAD_FRAMES: usize = 2;

/// The tracked scenes of a recorded footage folder, every frame kept once tracked.
pub struct TrackedFootage {
    num_frames: usize,
    source: Source,
}

enum Source {
    Inline(Box<SceneTracker>),
    Worker(Worker),
}

/// The thread that owns the tracker: it is sent the number of frames wanted and sends back each
/// frame's scene, in order.
struct Worker {
    /// The scenes picked up so far (frames 0..len).
    frames: Vec<SceneFrame>,
    wanted: Sender<usize>,
    tracked: Receiver<Result<SceneFrame, String>>,
    /// Frames asked for so far.
    asked: usize,
}

impl TrackedFootage {
    /// Tracking on the calling thread: [`Self::frame`] tracks up to the frame asked for.
    pub fn inline(
        root: &Path,
        intrinsics: Intrinsics,
        num_frames: usize,
    ) -> anyhow::Result<TrackedFootage> {
        Ok(TrackedFootage {
            num_frames,
            source: Source::Inline(Box::new(SceneTracker::open(root, intrinsics)?)),
        })
    }

    /// Tracking on a worker thread (the tracker is opened there; an error opening it is
    /// returned here).
    pub fn on_worker(
        root: &Path,
        intrinsics: Intrinsics,
        num_frames: usize,
    ) -> anyhow::Result<TrackedFootage> {
        let (wanted, wanted_rx) = std::sync::mpsc::channel::<usize>();
        let (tracked_tx, tracked) = std::sync::mpsc::channel();
        let (opened_tx, opened) = std::sync::mpsc::channel::<Result<(), String>>();
        let root_owned: PathBuf = root.to_path_buf();
        std::thread::Builder::new()
            .name("sylva-tracker".into())
            .spawn(move || {
                let mut tracker = match SceneTracker::open(&root_owned, intrinsics) {
                    Ok(tracker) => {
                        let _ = opened_tx.send(Ok(()));
                        tracker
                    }
                    Err(e) => {
                        let _ = opened_tx.send(Err(format!("{e:#}")));
                        return;
                    }
                };
                track_as_asked(&mut tracker, num_frames, &wanted_rx, &tracked_tx);
            })
            .context("cannot start the tracking thread")?;
        opened
            .recv()
            .context("the tracking thread ended before opening the footage")?
            .map_err(anyhow::Error::msg)?;
        Ok(TrackedFootage {
            num_frames,
            source: Source::Worker(Worker {
                frames: Vec::with_capacity(num_frames),
                wanted,
                tracked,
                asked: 0,
            }),
        })
    }

    /// The scene at frame `index` if it has been tracked (and picked up) already.
    pub fn get(&self, index: usize) -> Option<&SceneFrame> {
        match &self.source {
            Source::Inline(tracker) => tracker.get(index),
            Source::Worker(worker) => worker.frames.get(index),
        }
    }

    /// The scene at frame `index`, tracking (or waiting for the worker to track) the frames up
    /// to it first.
    pub fn frame(&mut self, index: usize) -> anyhow::Result<&SceneFrame> {
        let index = self.clamp(index);
        let worker = match &mut self.source {
            Source::Inline(tracker) => return tracker.frame(index),
            Source::Worker(worker) => worker,
        };
        worker.ask(index + 1 + TRACK_AHEAD_FRAMES, self.num_frames);
        while worker.frames.len() <= index {
            let scene = worker
                .tracked
                .recv()
                .context("the tracking thread has stopped")?;
            worker.take(scene)?;
        }
        Ok(&worker.frames[index])
    }

    /// The scene at frame `index` if it is tracked, without waiting: the worker is asked to
    /// track up to it (and [`TRACK_AHEAD_FRAMES`] beyond) and what it has sent is picked up.
    /// Inline tracking tracks it here.
    pub fn ready(&mut self, index: usize) -> anyhow::Result<Option<&SceneFrame>> {
        let index = self.clamp(index);
        let worker = match &mut self.source {
            Source::Inline(tracker) => return tracker.frame(index).map(Some),
            Source::Worker(worker) => worker,
        };
        worker.ask(index + 1 + TRACK_AHEAD_FRAMES, self.num_frames);
        while worker.frames.len() <= index {
            match worker.tracked.try_recv() {
                Ok(scene) => worker.take(scene)?,
                Err(TryRecvError::Empty) => return Ok(None),
                Err(TryRecvError::Disconnected) => {
                    anyhow::bail!("the tracking thread has stopped")
                }
            }
        }
        Ok(Some(&worker.frames[index]))
    }

    /// Asks the worker to track up to frame `index` without waiting (nothing to do inline).
    pub fn ask(&mut self, index: usize) {
        let count = self.clamp(index) + 1;
        if let Source::Worker(worker) = &mut self.source {
            worker.ask(count, self.num_frames);
        }
    }

    fn clamp(&self, index: usize) -> usize {
        index.min(self.num_frames.saturating_sub(1))
    }
}

impl Worker {
    /// Keeps the next frame's scene, or returns the error the worker stopped with.
    fn take(&mut self, scene: Result<SceneFrame, String>) -> anyhow::Result<()> {
        let scene = scene
            .map_err(anyhow::Error::msg)
            .with_context(|| format!("tracking frame {}", self.frames.len()))?;
        self.frames.push(scene);
        Ok(())
    }

    /// Asks for the first `count` frames (of `num_frames`) to be tracked.
    fn ask(&mut self, count: usize, num_frames: usize) {
        let count = count.min(num_frames.max(1));
        if count > self.asked {
            self.asked = count;
            // A stopped worker is reported when its result is waited for.
            let _ = self.wanted.send(count);
        }
    }
}

/// The worker's loop: tracks frames in order up to the count last asked for, sending each
/// scene (or the error that stopped it), until the footage's owner is gone.
fn track_as_asked(
    tracker: &mut SceneTracker,
    num_frames: usize,
    wanted: &Receiver<usize>,
    tracked: &Sender<Result<SceneFrame, String>>,
) {
    let mut target = 0;
    let mut next = 0;
    loop {
        if next >= target {
            match wanted.recv() {
                Ok(count) => target = target.max(count),
                Err(_) => return,
            }
        }
        while let Ok(count) = wanted.try_recv() {
            target = target.max(count);
        }
        target = target.min(num_frames);
        if next >= target {
            continue;
        }
        let scene = tracker.frame(next).cloned().map_err(|e| format!("{e:#}"));
        let failed = scene.is_err();
        if tracked.send(scene).is_err() || failed {
            return;
        }
        next += 1;
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn demo() -> Option<crate::footage::Footage> {
        let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("../test-data/demo_garden");
        crate::footage::Footage::open(&root).ok()
    }

    #[test]
    fn the_worker_tracks_the_same_scenes_as_inline_tracking_without_blocking_ready() {
        let Some(footage) = demo() else {
            panic!("the demo footage (test-data/demo_garden) is missing");
        };
        let n = 12;
        let mut inline = TrackedFootage::inline(&footage.root, footage.intrinsics, n).unwrap();
        let mut worker = TrackedFootage::on_worker(&footage.root, footage.intrinsics, n).unwrap();
        // Asking without waiting returns at once; the frames arrive in order.
        let mut polls = 0;
        while worker.ready(5).unwrap().is_none() {
            polls += 1;
            std::thread::sleep(std::time::Duration::from_millis(5));
        }
        assert!(
            polls > 0,
            "six frames cannot be tracked before the first poll"
        );
        // The same scenes (the time each took aside).
        let untimed = |scene: &SceneFrame| SceneFrame {
            tracking_ms: 0.0,
            ..scene.clone()
        };
        for i in 0..n {
            let (a, b) = (inline.frame(i).unwrap(), worker.frame(i).unwrap());
            assert_eq!(untimed(a), untimed(b), "frame {i}");
        }
        assert!(worker.get(n - 1).is_some() && worker.get(n).is_none());
        // Past the end: the last frame.
        let last = untimed(worker.frame(n + 5).unwrap());
        assert_eq!(last, untimed(inline.frame(n - 1).unwrap()));
    }
}
