//! Plays footage into the design state and records the session: shared by the window and the
//! headless demo.

use std::path::{Path, PathBuf};

use anyhow::Context;
use glam::Vec3;
use image::RgbaImage;

use crate::footage::Footage;
use crate::render::{GroundPlane, ViewCamera};
use crate::scene_tracking::{SceneFrame, SceneTracker};
use crate::session::{Session, frame_dt};
use crate::state::{DesignState, InputEvent, Parameters};
use crate::ui::UiState;

/// Seed of trees planted by the app.
pub const DEFAULT_SEED: u64 = 7;

/// Footage playback, the design and the session being recorded.
pub struct Player {
    pub footage: Footage,
    pub design: DesignState,
    pub ui: UiState,
    pub session: Session,
    pub frame: usize,
    pub image: Option<RgbaImage>,
    tracker: SceneTracker,
    last_tick_s: Option<f64>,
    frame_clock_s: f64,
}

impl Player {
    /// A player over `footage` (recorded in sessions as `footage_ref`), tracking it as it plays.
    pub fn new(footage: Footage, footage_ref: PathBuf) -> anyhow::Result<Player> {
        let params = Parameters::default();
        let ui = UiState {
            num_frames: footage.len(),
            ..UiState::default()
        };
        let tracker = SceneTracker::open(&footage.root, footage.intrinsics)?;
        Ok(Player {
            session: Session::new(footage_ref, DEFAULT_SEED, params.clone()),
            design: DesignState::new(DEFAULT_SEED, params),
            footage,
            ui,
            frame: 0,
            image: None,
            tracker,
            last_tick_s: None,
            frame_clock_s: 0.0,
        })
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
        self.tracker.get(self.frame)
    }

    /// The brush sphere at the finger while painting.
    pub fn brush_sphere(&self) -> Option<(Vec3, f32)> {
        let stroke = self.design.stroke.as_ref()?;
        Some((*stroke.points.last()?, self.design.params.brush_radius))
    }

    /// Applies and records an input event.
    pub fn input(&mut self, event: InputEvent) {
        self.session.record(event.clone());
        self.design.apply(&event);
    }

    /// Shows footage frame `index` and advances the design to it.
    pub fn show_frame(&mut self, index: usize) -> anyhow::Result<()> {
        let index = index.min(self.footage.len().saturating_sub(1));
        let previous_time = self
            .footage
            .frames
            .get(self.frame)
            .map_or(0.0, |f| f.time_s);
        self.frame = index;
        self.ui.frame = index;
        self.image = Some(self.footage.load_rgba(index)?);
        let scene = self.tracker.frame(index)?;
        // The frame's own tracking time (frames are tracked once; seeking ahead tracks the ones
        // in between first).
        self.ui.budget.tracking_ms = scene.tracking_ms;
        self.ui.ground_found = scene.ground.is_some();
        self.session.push_frame(&self.footage, index, scene);
        let time_s = self.footage.frames[index].time_s;
        let started = std::time::Instant::now();
        self.design
            .advance_frame(self.camera(), time_s, frame_dt(time_s - previous_time));
        self.ui.budget.growth_ms = started.elapsed().as_secs_f32() * 1000.0;
        Ok(())
    }

    /// Advances playback to wall-clock `now_s` (30 Hz footage, looping), honouring pause/seek.
    pub fn tick(&mut self, now_s: f64) -> anyhow::Result<()> {
        if let Some(target) = self.ui.seek_to.take() {
            return self.show_frame(target);
        }
        let last = self.last_tick_s.replace(now_s);
        if self.image.is_none() {
            return self.show_frame(self.frame);
        }
        if !self.ui.playing {
            return Ok(());
        }
        self.frame_clock_s += now_s - last.unwrap_or(now_s);
        if self.frame_clock_s >= 1.0 / 30.0 {
            self.frame_clock_s = 0.0;
            let next = (self.frame + 1) % self.footage.len().max(1);
            self.show_frame(next)?;
        }
        Ok(())
    }
}

/// Writes the tree as `tree.json` (the growth state) and `tree.glb` (its meshes) into `dir`;
/// returns the path of the `.glb`.
pub fn export_tree(design: &DesignState, dir: &Path) -> anyhow::Result<PathBuf> {
    std::fs::create_dir_all(dir).with_context(|| format!("cannot create {}", dir.display()))?;
    let json = dir.join("tree.json");
    design
        .tree
        .save(&json)
        .with_context(|| format!("cannot write {}", json.display()))?;
    let glb = dir.join("tree.glb");
    let meshes = sylva_core::geometry::build_tree_meshes(&design.tree);
    sylva_core::export::write_glb(&meshes, &glb)
        .with_context(|| format!("cannot write {}", glb.display()))?;
    Ok(glb)
}
