//! Plays footage into the design state and records the session: shared by the window and the
//! headless demo. Footage is a recorded TUM folder (seek, loop) or a stream — a live camera or a
//! video file ([`crate::live`]) — whose frames are shown once each, as they arrive.

use std::path::{Path, PathBuf};

use anyhow::Context;
use glam::Vec3;
use image::RgbaImage;

use crate::footage::{Footage, FootageFrame};
use crate::live::{FootageRecorder, LiveFrame, LiveNext, LiveStream, intrinsics_of};
use crate::render::{GroundPlane, ViewCamera};
use crate::scene_tracking::SceneFrame;
use crate::session::{Session, frame_dt};
use crate::state::{DesignState, InputEvent, Parameters, TouchPhase};
use crate::tracking_worker::TrackedFootage;
use crate::ui::UiState;

/// Seed of trees planted by the app.
pub const DEFAULT_SEED: u64 = 7;

/// Where the shown frames come from.
enum Scenes {
    /// A TUM folder: frames tracked once, in order, on a worker thread, and cached for seeking
    /// and looping.
    Recorded(Box<TrackedFootage>),
    /// A stream: each frame tracked as it arrives and shown once.
    Live(Box<LiveState>),
}

struct LiveState {
    stream: Box<dyn LiveStream>,
    /// Writes the shown frames as a TUM folder (the session's footage) when recording.
    recorder: Option<FootageRecorder>,
    /// The scene of the frame shown.
    shown: Option<SceneFrame>,
    ended: bool,
}

/// Footage playback, the design and the session being recorded.
pub struct Player {
    pub footage: Footage,
    pub design: DesignState,
    pub ui: UiState,
    pub session: Session,
    pub frame: usize,
    pub image: Option<RgbaImage>,
    scenes: Scenes,
    last_tick_s: Option<f64>,
    frame_clock_s: f64,
    /// Time of the last streamed frame shown.
    last_frame_time_s: f64,
    /// Plant at the world origin once the ground is found (`sylva view --plant-at-origin`).
    pub plant_at_origin: bool,
}

impl Player {
    /// A player over `footage` (recorded in sessions as `footage_ref`), tracking it as it plays
    /// on a worker thread ([`TrackedFootage::on_worker`]).
    pub fn new(footage: Footage, footage_ref: PathBuf) -> anyhow::Result<Player> {
        let params = Parameters::default();
        let ui = UiState {
            num_frames: footage.len(),
            ..UiState::default()
        };
        let tracker = TrackedFootage::on_worker(&footage.root, footage.intrinsics, footage.len())?;
        Ok(Player {
            session: Session::new(footage_ref, DEFAULT_SEED, params.clone()),
            design: DesignState::unplanted(DEFAULT_SEED, params)
                .with_scene_worker(&footage.intrinsics),
            footage,
            ui,
            frame: 0,
            image: None,
            scenes: Scenes::Recorded(Box::new(tracker)),
            last_tick_s: None,
            frame_clock_s: 0.0,
            last_frame_time_s: 0.0,
            plant_at_origin: false,
        })
    }

    /// A player over a stream (a live camera, a video file). With `record`, the shown frames are
    /// written there as a TUM folder, which the session references (absolute path): the live
    /// session then replays like recorded footage. Without it the session records the events
    /// only and cannot be replayed.
    pub fn live(stream: Box<dyn LiveStream>, record: Option<&Path>) -> anyhow::Result<Player> {
        let camera = *stream.camera();
        let recorder = record
            .map(|dir| FootageRecorder::create(dir, &camera))
            .transpose()?;
        let root = match &recorder {
            Some(r) => std::fs::canonicalize(r.root())
                .with_context(|| format!("cannot resolve {}", r.root().display()))?,
            None => PathBuf::from(stream.describe()),
        };
        let footage = Footage {
            root: root.clone(),
            intrinsics: intrinsics_of(&camera),
            depth_scale: camera.depth_scale.unwrap_or(5000.0) as f32,
            frames: Vec::new(),
        };
        let params = Parameters::default();
        Ok(Player {
            session: Session::new(root, DEFAULT_SEED, params.clone()),
            design: DesignState::unplanted(DEFAULT_SEED, params)
                .with_scene_worker(&intrinsics_of(&camera)),
            footage,
            ui: UiState {
                live: true,
                ..UiState::default()
            },
            frame: 0,
            image: None,
            scenes: Scenes::Live(Box::new(LiveState {
                stream,
                recorder,
                shown: None,
                ended: false,
            })),
            last_tick_s: None,
            frame_clock_s: 0.0,
            last_frame_time_s: 0.0,
            plant_at_origin: false,
        })
    }

    /// Whether frames come from a stream rather than a recorded folder.
    pub fn is_live(&self) -> bool {
        matches!(self.scenes, Scenes::Live(_))
    }

    /// Whether the session can be replayed: recorded footage, or a stream being recorded.
    pub fn session_replayable(&self) -> bool {
        match &self.scenes {
            Scenes::Recorded(_) => true,
            Scenes::Live(live) => live.recorder.is_some(),
        }
    }

    /// Completes the recording of a stream (frames still being written, `rgb.txt`); call before
    /// saving the session.
    pub fn finish_recording(&mut self) -> anyhow::Result<()> {
        match &mut self.scenes {
            Scenes::Live(live) => live.recorder.as_mut().map_or(Ok(()), |r| r.finish()),
            Scenes::Recorded(_) => Ok(()),
        }
    }

    /// The tracked camera of the current frame.
    pub fn camera(&self) -> Option<ViewCamera> {
        let m = self.scene()?.world_from_camera?;
        Some(ViewCamera::new(self.footage.intrinsics, m))
    }

    /// The ground plane once the tracker found it (the coaching overlay shows until then).
    pub fn ground(&self) -> Option<GroundPlane> {
        self.scene()?.ground
    }

    /// Tracking, ground plane and depth mesh of the frame shown (None before it is tracked).
    pub fn scene(&self) -> Option<&SceneFrame> {
        match &self.scenes {
            Scenes::Recorded(tracker) => tracker.get(self.frame),
            Scenes::Live(live) => live.shown.as_ref(),
        }
    }

    /// The brush sphere at the finger while painting.
    pub fn brush_sphere(&self) -> Option<(Vec3, f32)> {
        let stroke = self.design.stroke.as_ref()?;
        Some((*stroke.points.last()?, self.design.params.brush_radius))
    }

    /// Whether footage frame `index` is tracked, so that showing it does not wait for the
    /// tracker (asks the tracker for it when not); always true for a stream.
    pub fn frame_ready(&mut self, index: usize) -> anyhow::Result<bool> {
        match &mut self.scenes {
            Scenes::Recorded(tracker) => Ok(tracker.ready(index)?.is_some()),
            Scenes::Live(_) => Ok(true),
        }
    }

    /// Asks the tracker to track up to footage frame `index` (a seek's target) without waiting.
    pub fn track_ahead_to(&mut self, index: usize) {
        if let Scenes::Recorded(tracker) = &mut self.scenes {
            tracker.ask(index);
        }
    }

    /// Applies and records an input event.
    pub fn input(&mut self, event: InputEvent) {
        self.session.record(event.clone());
        self.design.apply(&event);
    }

    /// Shows footage frame `index` and advances the design to it (recorded footage; a stream
    /// shows its frames as they come: [`Self::next_live_frame`]).
    pub fn show_frame(&mut self, index: usize) -> anyhow::Result<()> {
        let Scenes::Recorded(tracker) = &mut self.scenes else {
            return Ok(());
        };
        let index = index.min(self.footage.len().saturating_sub(1));
        let previous_time = self
            .footage
            .frames
            .get(self.frame)
            .map_or(0.0, |f| f.time_s);
        self.frame = index;
        self.ui.frame = index;
        self.image = Some(self.footage.load_rgba(index)?);
        let scene = tracker.frame(index)?;
        // The frame's own tracking time (frames are tracked once; seeking ahead tracks the ones
        // in between first).
        self.ui.budget.tracking_ms = scene.tracking_ms;
        self.ui.ground_found = scene.ground.is_some();
        self.session.push_frame(&self.footage, index, scene);
        self.design.observe_scene(
            &self.footage.intrinsics,
            scene.world_from_camera,
            scene.ground,
            &scene.observations,
        );
        self.design.scale.set_frame_index(index);
        let time_s = self.footage.frames[index].time_s;
        self.advance_design(time_s, previous_time);
        Ok(())
    }

    fn advance_design(&mut self, time_s: f64, previous_time_s: f64) {
        let started = std::time::Instant::now();
        self.design
            .advance_frame(self.camera(), time_s, frame_dt(time_s - previous_time_s));
        self.ui.budget.growth_ms = started.elapsed().as_secs_f32() * 1000.0;
        if self.plant_at_origin
            && !self.design.is_planted()
            && self.design.ground.is_some()
            && let Some(p) = self
                .design
                .world_camera()
                .and_then(|c| c.pixel_from_world(Vec3::ZERO))
        {
            // A tap at the origin's pixel, as the user would make it (and recorded so).
            for phase in [TouchPhase::Start, TouchPhase::End] {
                self.input(InputEvent::Touch {
                    phase,
                    id: 0,
                    x: p.x,
                    y: p.y,
                });
            }
        }
        self.ui.planted = self.design.is_planted();
    }

    /// The tracked camera of the current frame in tree space (how the frame is drawn: the
    /// tree's mesh is in tree space).
    pub fn camera_in_tree(&self) -> Option<ViewCamera> {
        let camera = self.camera()?;
        Some(crate::planting::camera_in_tree(
            &camera,
            &self.design.tree_from_world(),
        ))
    }

    /// The ground plane in tree space.
    pub fn ground_in_tree(&self) -> Option<GroundPlane> {
        let ground = self.ground()?;
        Some(crate::planting::ground_in_tree(
            &ground,
            &self.design.tree_from_world(),
        ))
    }

    /// A stream: waits for its next frame and shows it. False once the stream has ended (and
    /// for recorded footage).
    pub fn next_live_frame(&mut self) -> anyhow::Result<bool> {
        self.pull_live(true)
    }

    /// Shows the stream's next frame if one is there (`wait`: waits for it).
    fn pull_live(&mut self, wait: bool) -> anyhow::Result<bool> {
        let Scenes::Live(live) = &mut self.scenes else {
            return Ok(false);
        };
        if live.ended {
            return Ok(false);
        }
        match live.stream.next(wait)? {
            LiveNext::Frame(frame) => {
                self.show_live(*frame)?;
                Ok(true)
            }
            LiveNext::Pending => Ok(false),
            LiveNext::Ended => {
                live.ended = true;
                eprintln!("{}: end of the stream", live.stream.describe());
                Ok(false)
            }
        }
    }

    /// Shows a streamed frame: records it (footage and session) when recording, then advances
    /// the design to it.
    fn show_live(&mut self, frame: LiveFrame) -> anyhow::Result<()> {
        let Scenes::Live(live) = &mut self.scenes else {
            return Ok(());
        };
        let previous_time = live
            .shown
            .as_ref()
            .map_or(frame.time_s, |_| self.last_frame_time_s);
        // Every shown frame gets the next index (the window re-uploads on a new index).
        let index = if live.shown.is_some() {
            self.frame + 1
        } else {
            0
        };
        if let Some(recorder) = live.recorder.as_mut() {
            let entry: FootageFrame = recorder.push(frame.time_s, &frame.rgba)?;
            self.footage.frames.push(entry);
            self.session
                .push_frame(&self.footage, self.footage.len() - 1, &frame.scene);
        }
        self.frame = index;
        self.ui.frame = index;
        self.ui.num_frames = index + 1;
        self.ui.budget.tracking_ms = frame.scene.tracking_ms;
        self.ui.ground_found = frame.scene.ground.is_some();
        self.design.observe_scene(
            &self.footage.intrinsics,
            frame.scene.world_from_camera,
            frame.scene.ground,
            &frame.scene.observations,
        );
        self.design.scale.set_frame_index(index);
        self.image = Some(frame.rgba);
        live.shown = Some(frame.scene);
        self.last_frame_time_s = frame.time_s;
        self.advance_design(frame.time_s, previous_time);
        Ok(())
    }

    /// Advances playback to wall-clock `now_s` (30 Hz footage, looping), honouring pause/seek.
    pub fn tick(&mut self, now_s: f64) -> anyhow::Result<()> {
        if let Scenes::Live(live) = &self.scenes {
            let (camera, frame_rate_hz) =
                (live.stream.is_live_camera(), live.stream.frame_rate_hz());
            return self.tick_live(now_s, camera, frame_rate_hz);
        }
        if let Some(target) = self.ui.seek_to.take() {
            return self.show_frame(target);
        }
        let last = self.last_tick_s.replace(now_s);
        // The frame is shown once the tracker has it; until then the window draws the last one.
        if self.image.is_none() {
            if self.frame_ready(self.frame)? {
                self.show_frame(self.frame)?;
            }
            return Ok(());
        }
        if !self.ui.playing {
            return Ok(());
        }
        self.frame_clock_s += now_s - last.unwrap_or(now_s);
        let next = (self.frame + 1) % self.footage.len().max(1);
        if self.frame_clock_s >= 1.0 / 30.0 && self.frame_ready(next)? {
            self.frame_clock_s = 0.0;
            self.show_frame(next)?;
        }
        Ok(())
    }

    /// A stream has no seeking or looping: a live camera shows each frame as it arrives, a file
    /// plays at its frame rate; pausing freezes the shown frame.
    fn tick_live(
        &mut self,
        now_s: f64,
        live_camera: bool,
        frame_rate_hz: f64,
    ) -> anyhow::Result<()> {
        self.ui.seek_to = None;
        let last = self.last_tick_s.replace(now_s);
        if self.image.is_none() {
            self.pull_live(!live_camera)?;
            return Ok(());
        }
        if !self.ui.playing {
            return Ok(());
        }
        if live_camera {
            self.pull_live(false)?;
            return Ok(());
        }
        self.frame_clock_s += now_s - last.unwrap_or(now_s);
        if self.frame_clock_s >= 1.0 / frame_rate_hz.max(1.0) {
            self.frame_clock_s = 0.0;
            self.pull_live(true)?;
        }
        Ok(())
    }
}

/// Where a design's tree stands, written next to its tree file.
#[derive(Clone, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct Placement {
    /// Column-major `world_from_tree` (tree space: metres, Y up, trunk base at the origin);
    /// None if the tree was never planted.
    pub world_from_tree: Option<[f32; 12]>,
}

/// Writes where the design's tree stands ([`Placement`]) to `path`.
pub fn write_placement(design: &DesignState, path: &Path) -> anyhow::Result<()> {
    let json = serde_json::to_string_pretty(&Placement {
        world_from_tree: design.world_from_tree.map(|m| m.to_cols_array()),
    })?;
    crate::outputs::write_file(path, json.as_bytes())
}

/// Writes the tree as `tree.json` (the growth state, in tree space), `tree.glb` (its meshes)
/// and `placement.json` (where it stands in the world) into `dir`; returns the path of the
/// `.glb`.
pub fn export_tree(design: &DesignState, dir: &Path) -> anyhow::Result<PathBuf> {
    std::fs::create_dir_all(dir).with_context(|| format!("cannot create {}", dir.display()))?;
    let json = dir.join("tree.json");
    design
        .tree
        .save(&json)
        .with_context(|| format!("cannot write {}", json.display()))?;
    write_placement(design, &dir.join("placement.json"))?;
    let glb = dir.join("tree.glb");
    let meshes = sylva_core::geometry::build_tree_meshes(&design.tree);
    sylva_core::export::write_glb(&meshes, &glb)
        .with_context(|| format!("cannot write {}", glb.display()))?;
    // A garden: every tree, and where each stands (the selected one is tree.json too).
    crate::garden_view::write_garden(design, &dir.join("garden.json"))?;
    Ok(glb)
}
