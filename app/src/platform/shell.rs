//! [`ShellApp`]: the entry points a shell calls. A phone shell (or a host test) pushes camera
//! frames in, passes touches on, draws into its surface, pauses and resumes with the app's
//! lifecycle and polls the autosave; the design, the UI and the recorded session are the same
//! as on desktop.

use std::path::{Path, PathBuf};
use std::time::Instant;

use super::{
    DisplayTransform, DrawSurface, PlatformFeed, PlatformFrame, PlatformIntrinsics, PlatformStream,
    StorageLocation, TrackerChoice, ViewDrawer,
};
use crate::autosave::{AUTOSAVE_INTERVAL, Autosaver};
use crate::player::Player;
use crate::render::Gpu;
use crate::state::TouchPhase;

/// A finger on the surface, physical pixels.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct TouchInput {
    pub phase: TouchPhase,
    /// Stable while the finger is down.
    pub id: u64,
    pub x_px: f32,
    pub y_px: f32,
}

/// The app as a shell drives it.
pub struct ShellApp {
    player: Player,
    feed: PlatformFeed,
    session_dir: PathBuf,
    autosaver: Autosaver,
    drawer: Option<ViewDrawer>,
    /// How the camera image is shown ([`ShellApp::set_display`]).
    display: DisplayTransform,
    /// UI input since the last draw.
    events: Vec<egui::Event>,
    /// Fingers down, and the one that moves egui's pointer (buttons, sliders).
    touches_down: Vec<(u64, egui::Pos2)>,
    pointer_touch: Option<u64>,
    /// Scale factor of the last surface drawn into (touches arrive in its pixels).
    pixels_per_point: f32,
    started: Instant,
    paused: bool,
}

impl ShellApp {
    /// Starts a design on a camera of `intrinsics` at `frame_rate_hz`, tracked by `choice`;
    /// the frames shown and the session are recorded into a new session folder in `storage`
    /// (replayable with `sylva replay <dir>/session.json`), the tree autosaved beside it.
    pub fn start(
        storage: &StorageLocation,
        intrinsics: PlatformIntrinsics,
        frame_rate_hz: f64,
        choice: TrackerChoice,
        describe: &str,
    ) -> anyhow::Result<ShellApp> {
        let session_dir = storage.new_session_dir()?;
        let (stream, feed) = PlatformStream::new(intrinsics, frame_rate_hz, choice, describe)?;
        let player = Player::live(Box::new(stream), Some(&session_dir))?;
        // A stream's session is written when it ends (its recording must be complete first);
        // the tree is autosaved meanwhile.
        let autosaver = Autosaver::new(
            &StorageLocation::session_path(&session_dir),
            false,
            AUTOSAVE_INTERVAL,
        );
        Ok(ShellApp {
            player,
            feed,
            session_dir,
            autosaver,
            drawer: None,
            display: DisplayTransform::default(),
            events: Vec::new(),
            touches_down: Vec::new(),
            pointer_touch: None,
            pixels_per_point: 1.0,
            started: Instant::now(),
            paused: false,
        })
    }

    pub fn player(&self) -> &Player {
        &self.player
    }

    /// The session folder (recorded frames, `session.json`, the autosaved tree).
    pub fn session_dir(&self) -> &Path {
        &self.session_dir
    }

    /// Where the tree is autosaved.
    pub fn autosave_path(&self) -> &Path {
        self.autosaver.tree_path()
    }

    /// The next camera frame: tracked and shown, unless the app is paused or the user froze
    /// the view (then it is dropped, as a live camera's frames are). Returns whether it was
    /// shown.
    pub fn frame(&mut self, frame: PlatformFrame) -> anyhow::Result<bool> {
        if self.paused || !self.player.ui.playing {
            return Ok(false);
        }
        if !self.feed.push(frame) {
            anyhow::bail!("the camera stream has closed");
        }
        self.player.next_live_frame()
    }

    /// A finger on the surface: goes to the UI (controls, then the AR view's gestures) at the
    /// next draw.
    pub fn touch(&mut self, touch: TouchInput) {
        let ppp = self.pixels_per_point;
        let pos = egui::pos2(touch.x_px / ppp, touch.y_px / ppp);
        let phase = match touch.phase {
            TouchPhase::Start => egui::TouchPhase::Start,
            TouchPhase::Move => egui::TouchPhase::Move,
            TouchPhase::End => egui::TouchPhase::End,
        };
        self.events.push(egui::Event::Touch {
            device_id: egui::TouchDeviceId(0),
            id: egui::TouchId(touch.id),
            phase,
            pos,
            force: None,
        });
        self.touches_down.retain(|(id, _)| *id != touch.id);
        if touch.phase != TouchPhase::End {
            self.touches_down.push((touch.id, pos));
        }
        // The first finger also moves egui's pointer, so buttons and sliders follow it.
        if self.pointer_touch.is_none_or(|id| id == touch.id) {
            let button = |pressed| egui::Event::PointerButton {
                pos,
                button: egui::PointerButton::Primary,
                pressed,
                modifiers: Default::default(),
            };
            match touch.phase {
                TouchPhase::Start => {
                    self.pointer_touch = Some(touch.id);
                    self.events.push(egui::Event::PointerMoved(pos));
                    self.events.push(button(true));
                }
                TouchPhase::Move => self.events.push(egui::Event::PointerMoved(pos)),
                TouchPhase::End => {
                    self.pointer_touch = None;
                    self.events.push(button(false));
                    self.events.push(egui::Event::PointerGone);
                }
            }
        }
    }

    /// Shows the camera image through `display` from the next draw on: a phone turns it upright
    /// and crops it to fill the screen ([`DisplayTransform::phone`]); touches on it still reach
    /// the design in the camera image's pixels. The default shows the image whole.
    pub fn set_display(&mut self, display: DisplayTransform) {
        self.display = display;
    }

    /// Draws the shown frame and the UI into `surface` with `gpu` (the shell's, kept across
    /// pauses: only the surface goes with the window), applying the touches since the last
    /// draw; false when the surface could not draw now.
    pub fn draw(&mut self, gpu: &Gpu, surface: &mut dyn DrawSurface) -> anyhow::Result<bool> {
        if self
            .drawer
            .as_ref()
            .is_none_or(|d| d.format() != surface.format())
        {
            self.drawer = Some(ViewDrawer::new(gpu, surface.format()));
        }
        let Some(drawer) = self.drawer.as_mut() else {
            return Ok(false);
        };
        let Some(target) = surface.begin_frame(gpu)? else {
            return Ok(false);
        };
        let size = surface.size_px();
        let ppp = surface.scale_factor().max(0.1);
        self.pixels_per_point = ppp;
        let mut raw = egui::RawInput {
            screen_rect: Some(egui::Rect::from_min_size(
                egui::Pos2::ZERO,
                egui::vec2(size.0 as f32 / ppp, size.1 as f32 / ppp),
            )),
            time: Some(self.started.elapsed().as_secs_f64()),
            max_texture_side: Some(gpu.device.limits().max_texture_dimension_2d as usize),
            events: std::mem::take(&mut self.events),
            focused: true,
            ..Default::default()
        };
        raw.viewports
            .entry(egui::ViewportId::ROOT)
            .or_default()
            .native_pixels_per_point = Some(ppp);
        drawer.set_display(self.display);
        drawer.draw(gpu, &mut self.player, &target, size, raw);
        surface.end_frame(gpu)?;
        if self.player.ui.export_requested {
            self.player.ui.export_requested = false;
            crate::player::export_tree(&self.player.design, &self.session_dir.join("export"))?;
        }
        Ok(true)
    }

    /// Autosaves the tree when it changed and the interval passed; returns whether it saved.
    pub fn poll_autosave(&mut self, now: Instant) -> anyhow::Result<bool> {
        self.autosaver
            .poll(now, &self.player.design, &self.player.session)
    }

    /// The app goes to the background (its window may be destroyed): fingers still down are
    /// lifted, the tree and the session so far are saved now, and frames are dropped until
    /// [`Self::resume`]. The design stays in memory.
    pub fn pause(&mut self) -> anyhow::Result<()> {
        for (id, pos) in std::mem::take(&mut self.touches_down) {
            self.events.push(egui::Event::Touch {
                device_id: egui::TouchDeviceId(0),
                id: egui::TouchId(id),
                phase: egui::TouchPhase::Cancel,
                pos,
                force: None,
            });
        }
        if self.pointer_touch.take().is_some() {
            self.events.push(egui::Event::PointerGone);
        }
        self.paused = true;
        self.autosaver
            .flush(&self.player.design, &self.player.session)?;
        // A phone may end a paused app without warning (and iOS's event loop never returns):
        // the session so far is written too. Frames still being encoded complete in the
        // background; a process killed before that leaves the last ones unreadable.
        self.player
            .session
            .save(&StorageLocation::session_path(&self.session_dir))
    }

    /// The app is back in the foreground (draw into the new surface).
    pub fn resume(&mut self) {
        self.paused = false;
    }

    pub fn is_paused(&self) -> bool {
        self.paused
    }

    /// Ends the design: saves the tree, completes the recording and writes the session;
    /// returns the session file.
    pub fn finish(mut self) -> anyhow::Result<PathBuf> {
        self.autosaver
            .flush(&self.player.design, &self.player.session)?;
        self.player.finish_recording()?;
        let path = StorageLocation::session_path(&self.session_dir);
        self.player.session.save(&path)?;
        Ok(path)
    }
}
