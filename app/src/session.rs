//! Recorded sessions: the footage reference, per-frame tracking output, every input event with
//! its frame and time, the parameters and seeds. Replaying one headlessly gives the same tree and
//! the same frames on every run.

use std::path::{Path, PathBuf};
use std::time::Instant;

use anyhow::{Context, bail};
use glam::Mat4;
use serde::{Deserialize, Serialize};

use crate::footage::Footage;
use crate::planting::{camera_in_tree, ground_in_tree, occluder_in_tree};
use crate::render::offscreen::OFFSCREEN_FORMAT;
use crate::render::{FrameView, Gpu, GroundPlane, Offscreen, Renderer, ViewCamera};
use crate::scene_tracking::{SceneFrame, SceneMesher};
use crate::state::{DesignState, InputEvent, Parameters};
use sylva_tracking::depth_mesh::Observation;

pub const SESSION_FORMAT: &str = "sylva-session";
/// The largest side of replayed frames, pixels.
const MAX_FRAME_SIDE: u32 = 8192;
/// 2: frames record their tracked points (v1 sessions, made with ground-truth poses, are refused).
/// 3: the tree is planted where the user taps the ground (a version 2 session replays as it was
/// made: the tree planted at the world origin from the start), parameters carry the scene mode.
pub const SESSION_VERSION: u32 = 3;
/// The oldest version this build replays.
pub const OLDEST_SESSION_VERSION: u32 = 2;

/// Tracking output for one frame.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct FrameRecord {
    pub index: usize,
    pub time_s: f64,
    /// Column-major `world_from_camera`, absent while tracking is lost.
    pub world_from_camera: Option<[f32; 16]>,
    /// Ground plane (point, normal) once found.
    pub ground: Option<[f32; 6]>,
    /// Tracked points: map-point id, ideal pixel (x, y) and depth along the optical axis (m).
    pub points: Vec<PointRecord>,
}

/// One tracked point of a frame, written as `[id, x, y, depth_m]`.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct PointRecord(pub u64, pub f32, pub f32, pub f32);

impl FrameRecord {
    /// The recorded ground plane.
    pub fn ground_plane(&self) -> Option<GroundPlane> {
        self.ground.map(|g| GroundPlane {
            point: glam::Vec3::new(g[0], g[1], g[2]),
            normal: glam::Vec3::new(g[3], g[4], g[5]),
        })
    }

    /// The recorded tracked points as depth-mesh observations.
    pub fn observations(&self) -> Vec<Observation> {
        self.points
            .iter()
            .map(|p| Observation {
                id: p.0,
                pixel: glam::Vec2::new(p.1, p.2),
                depth_m: p.3,
            })
            .collect()
    }
}

/// An input event and when it happened.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct TimedEvent {
    pub frame: usize,
    pub time_s: f64,
    pub event: InputEvent,
}

/// A session file.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Session {
    pub format: String,
    pub version: u32,
    /// Footage folder, relative to the session file's folder (or absolute).
    pub footage: PathBuf,
    pub seed: u64,
    pub parameters: Parameters,
    /// Size of replayed frames, pixels.
    pub frame_size: [u32; 2],
    pub frames: Vec<FrameRecord>,
    pub events: Vec<TimedEvent>,
}

impl Session {
    /// An empty session on the footage at `footage_ref`.
    pub fn new(footage_ref: PathBuf, seed: u64, parameters: Parameters) -> Session {
        Session {
            format: SESSION_FORMAT.into(),
            version: SESSION_VERSION,
            footage: footage_ref,
            seed,
            parameters,
            frame_size: [320, 240],
            frames: Vec::new(),
            events: Vec::new(),
        }
    }

    /// Records that footage frame `index` was shown next, with its tracking output.
    pub fn push_frame(&mut self, footage: &Footage, index: usize, scene: &SceneFrame) {
        let Some(frame) = footage.frames.get(index) else {
            return;
        };
        self.frames.push(FrameRecord {
            index,
            time_s: frame.time_s,
            world_from_camera: scene.world_from_camera.map(|m| m.to_cols_array()),
            ground: scene.ground.map(|g| {
                [
                    g.point.x, g.point.y, g.point.z, g.normal.x, g.normal.y, g.normal.z,
                ]
            }),
            points: scene
                .observations
                .iter()
                .map(|o| PointRecord(o.id, o.pixel.x, o.pixel.y, o.depth_m))
                .collect(),
        });
    }

    /// Records an event that happened after the last recorded frame: a replay applies it just
    /// before the next one, as the live app did.
    pub fn record(&mut self, event: InputEvent) {
        let time_s = self.frames.last().map_or(0.0, |f| f.time_s);
        self.events.push(TimedEvent {
            frame: self.frames.len(),
            time_s,
            event,
        });
    }

    pub fn load(path: &Path) -> anyhow::Result<Session> {
        let text = std::fs::read_to_string(path)
            .with_context(|| format!("cannot read session {}", path.display()))?;
        let session: Session = serde_json::from_str(&text)
            .with_context(|| format!("{} is not a valid session file", path.display()))?;
        if session.format != SESSION_FORMAT
            || !(OLDEST_SESSION_VERSION..=SESSION_VERSION).contains(&session.version)
        {
            bail!(
                "{}: format `{}` version {} (this build reads `{SESSION_FORMAT}` versions {OLDEST_SESSION_VERSION} to {SESSION_VERSION})",
                path.display(),
                session.format,
                session.version
            );
        }
        session
            .check()
            .map_err(|why| anyhow::anyhow!("{} is a damaged session: {why}", path.display()))?;
        Ok(session)
    }

    /// Why this session cannot be replayed, if it cannot: parameters, frame size, poses, tracked
    /// points and events must all be values the app could have recorded.
    pub fn check(&self) -> Result<(), String> {
        self.parameters
            .check()
            .map_err(|why| format!("parameters: {why}"))?;
        if !self
            .frame_size
            .iter()
            .all(|&n| (1..=MAX_FRAME_SIDE).contains(&n))
        {
            return Err(format!(
                "frame size {:?} (each side 1 to {MAX_FRAME_SIDE} pixels)",
                self.frame_size
            ));
        }
        for (i, frame) in self.frames.iter().enumerate() {
            let pose = frame.world_from_camera.iter().flatten();
            let ground = frame.ground.iter().flatten();
            let points = frame.points.iter().flat_map(|p| [p.1, p.2, p.3]);
            if !pose
                .chain(ground)
                .copied()
                .chain(points)
                .all(f32::is_finite)
                || !frame.time_s.is_finite()
            {
                return Err(format!(
                    "frame {i}: a non-finite pose, ground, point or time"
                ));
            }
        }
        for (i, timed) in self.events.iter().enumerate() {
            let why = match &timed.event {
                InputEvent::Parameters { parameters } => parameters.check().err(),
                InputEvent::RestoreTree {
                    tree_file,
                    world_from_tree,
                } => crate::autosave::parse_restored_tree(tree_file)
                    .err()
                    .or_else(|| {
                        world_from_tree
                            .is_some_and(|m| !m.iter().all(|v| v.is_finite()))
                            .then(|| "a restored tree placed at a non-finite pose".into())
                    }),
                InputEvent::Grow { iterations }
                    if iterations.unsigned_abs() > crate::state::MAX_ITERATIONS_PER_REQUEST =>
                {
                    Some(format!(
                        "grows {iterations} iterations at once (at most {})",
                        crate::state::MAX_ITERATIONS_PER_REQUEST
                    ))
                }
                InputEvent::Touch { x, y, .. } if !(x.is_finite() && y.is_finite()) => {
                    Some(format!("touch at ({x}, {y})"))
                }
                InputEvent::HoldingHeight { holding_height_m }
                    if sylva_tracking::scale::validate_holding_height_m(*holding_height_m)
                        .is_err() =>
                {
                    Some(format!(
                        "a camera height of {holding_height_m} m (0.3 to 3 m)"
                    ))
                }
                InputEvent::ScaleTool {
                    tool: Some(crate::scale::ScaleTool::KnownLength { length_m }),
                } if !(length_m.is_finite() && (0.01..=1000.0).contains(length_m)) => {
                    Some(format!("a known length of {length_m} m"))
                }
                InputEvent::Tool { tool } if tool.check().is_err() => tool.check().err(),
                InputEvent::Recreate {
                    action: crate::state::RecreateAction::Overlay { opacity, .. },
                } if !opacity.is_finite() => Some(format!("an overlay opacity of {opacity}")),
                InputEvent::PlantAnother { species }
                    if sylva_core::species::Species::by_name(species).is_err() =>
                {
                    Some(format!("plants an unknown species {species:?}"))
                }
                InputEvent::SelectTree { index }
                    if *index >= sylva_core::garden::MAX_GARDEN_TREES =>
                {
                    Some(format!(
                        "selects tree {index} (a garden holds at most {})",
                        sylva_core::garden::MAX_GARDEN_TREES
                    ))
                }
                _ if !timed.time_s.is_finite() => Some("a non-finite time".into()),
                _ => None,
            };
            if let Some(why) = why {
                return Err(format!("event {i}: {why}"));
            }
        }
        Ok(())
    }

    /// The design state a replay starts from: version 2 sessions had the tree planted at the
    /// world origin from the start; later ones wait for a tap on the ground.
    pub fn initial_design(&self) -> DesignState {
        if self.version <= 2 {
            DesignState::new(self.seed, self.parameters.clone())
        } else {
            DesignState::unplanted(self.seed, self.parameters.clone())
        }
    }

    pub fn save(&self, path: &Path) -> anyhow::Result<()> {
        // Compact: a few hundred tracked points per frame make pretty-printing several times
        // larger.
        let json = serde_json::to_string(self)?;
        // Atomic and durable: a crash mid-write leaves the previous session whole.
        crate::outputs::write_file(path, json.as_bytes())
    }
}

/// What a replay produced.
#[derive(Clone, Debug, PartialEq)]
pub struct ReplayReport {
    pub tree_sha256: String,
    /// Where the tree stands (column-major `world_from_tree`), None if never planted.
    pub world_from_tree: Option<[f32; 12]>,
    /// SHA-256 of each frame's RGBA pixels (empty when frames are not rendered).
    pub frame_sha256: Vec<String>,
    /// Each frame's [`frame_thumbnail`]: what a check across machines compares (software
    /// rasterisers on different CPUs differ in a few edge pixels, so the exact checksums match
    /// only on the machine that recorded them).
    pub frame_thumbnails: Vec<Vec<u8>>,
    pub num_frames: usize,
    pub ms_per_frame: f64,
    /// SHA-256 of the garden's file when the design holds several trees (None for one).
    pub garden_sha256: Option<String>,
}

impl ReplayReport {
    pub fn summary_line(&self) -> String {
        let base = match self.world_from_tree {
            Some(m) => format!("{:.3},{:.3},{:.3}", m[9], m[10], m[11]),
            None => "unplanted".into(),
        };
        format!(
            "tree_sha256={} tree_base={base} frames={} ms_per_frame={:.1}",
            self.tree_sha256, self.num_frames, self.ms_per_frame
        )
    }
}

/// The camera of a recorded frame.
pub fn frame_camera(record: &FrameRecord, footage: &Footage) -> Option<ViewCamera> {
    let m = record.world_from_camera?;
    Some(ViewCamera::new(
        footage.intrinsics,
        Mat4::from_cols_array(&m),
    ))
}

/// The occluder of every recorded frame that has a camera, as the replay builds it: the depth
/// mesh of the tracked points fed with every frame's observations in order. Yields the frame's
/// step, its camera (world) and the occluder (world).
pub fn frame_occluders<'a>(
    session: &'a Session,
    footage: &'a Footage,
) -> impl Iterator<Item = (usize, ViewCamera, crate::render::OccluderMesh)> + 'a {
    let mut mesher = SceneMesher::new(&footage.intrinsics);
    session
        .frames
        .iter()
        .enumerate()
        .filter_map(move |(step, record)| {
            let camera = frame_camera(record, footage)?;
            let occluder = mesher.update(
                &record.observations(),
                camera.world_from_camera,
                record.ground_plane(),
            );
            Some((step, camera, occluder))
        })
}

/// Replays `session` (located at `session_path`); writes PNG frames and the tree (`tree.json`, `tree.glb`) into `out` when
/// given, and renders frames when `render` is set.
pub fn replay(
    session_path: &Path,
    out: Option<&Path>,
    render: bool,
    mut on_frame: impl FnMut(usize, &DesignState),
) -> anyhow::Result<ReplayReport> {
    let session = Session::load(session_path)?;
    let base = session_path.parent().unwrap_or(Path::new("."));
    let footage = Footage::open(&base.join(&session.footage))?;
    if let Some(out) = out {
        std::fs::create_dir_all(out).with_context(|| format!("cannot create {}", out.display()))?;
    }
    let mut gpu_parts = if render {
        let gpu = Gpu::headless()?;
        let renderer = Renderer::new(&gpu, OFFSCREEN_FORMAT);
        let target = Offscreen::new(&gpu.device, session.frame_size[0], session.frame_size[1]);
        Some((gpu, renderer, target))
    } else {
        None
    };
    // Everything comes from the recording (poses, ground, tracked points): a replay needs no
    // tracker and gives the same frames on every machine.
    let mut mesher = SceneMesher::new(&footage.intrinsics);
    let mut tree_mesher = crate::tree_model::TreeMesher::default();
    let mut garden_mesher = crate::garden_view::GardenMesher::default();
    let mut state = session.initial_design();
    let mut meshed_revision = None;
    let mut frame_sha256 = Vec::new();
    let mut frame_thumbnails = Vec::new();
    let mut events = session.events.iter().peekable();
    let started = Instant::now();
    let mut previous_time = session.frames.first().map_or(0.0, |f| f.time_s);
    for (step, record) in session.frames.iter().enumerate() {
        let camera = frame_camera(record, &footage);
        let index = record.index;
        while let Some(e) = events.next_if(|e| e.frame <= step) {
            state.apply(&e.event);
        }
        let dt = frame_dt(record.time_s - previous_time);
        previous_time = record.time_s;
        state.observe_scene(
            &footage.intrinsics,
            camera.map(|c| c.world_from_camera),
            record.ground_plane(),
            &record.observations(),
        );
        state.scale.set_frame_index(index);
        state.advance_frame(camera, record.time_s, dt);
        on_frame(step, &state);
        let Some((gpu, renderer, target)) = gpu_parts.as_mut() else {
            continue;
        };
        let Some(camera) = camera else {
            // Tracking not (yet) there: the frame is the footage alone, as the app shows it.
            let rgba = footage.load_rgba(index)?;
            let image = image::imageops::resize(
                &rgba,
                session.frame_size[0],
                session.frame_size[1],
                image::imageops::FilterType::Triangle,
            );
            write_frame(&image, step, out, &mut frame_sha256, &mut frame_thumbnails)?;
            continue;
        };
        if meshed_revision != Some(state.revision) {
            // Nothing is shown before the tree is planted.
            match state.is_planted() {
                true => {
                    renderer.set_tree(gpu, tree_mesher.mesh_in(&state.tree, state.params.season))
                }
                false => renderer.set_tree(gpu, &Default::default()),
            }
            meshed_revision = Some(state.revision);
        }
        garden_mesher.upload(gpu, renderer, &state, state.is_planted());
        let rgba = footage.load_rgba(index)?;
        renderer.set_camera_image(gpu, rgba.as_raw(), footage.intrinsics);
        // The frame is drawn in tree space (the tree's mesh is): camera, occluder and ground
        // moved by tree_from_world.
        let tree_from_world = state.tree_from_world();
        let occluder = mesher.update(
            &record.observations(),
            camera.world_from_camera,
            record.ground_plane(),
        );
        renderer.set_occluder(gpu, &occluder_in_tree(&occluder, &tree_from_world));
        let ground = record
            .ground_plane()
            .map(|g| ground_in_tree(&g, &tree_from_world));
        let camera = camera_in_tree(&camera, &tree_from_world);
        let image = target.render(gpu, renderer, &FrameView::augmented(camera, ground))?;
        write_frame(&image, step, out, &mut frame_sha256, &mut frame_thumbnails)?;
    }
    let num_frames = session.frames.len();
    let ms_per_frame = started.elapsed().as_secs_f64() * 1000.0 / num_frames.max(1) as f64;
    if let Some(out) = out {
        crate::player::export_tree(&state, out)?;
    }
    Ok(ReplayReport {
        tree_sha256: state.tree_sha256(),
        world_from_tree: state.world_from_tree.map(|m| m.to_cols_array()),
        frame_sha256,
        frame_thumbnails,
        num_frames,
        ms_per_frame,
        garden_sha256: state.garden_sha256(),
    })
}

/// Hashes a replayed frame and writes it as `frame_NNNN.png` into `out` when given.
fn write_frame(
    image: &image::RgbaImage,
    step: usize,
    out: Option<&Path>,
    frame_sha256: &mut Vec<String>,
    frame_thumbnails: &mut Vec<Vec<u8>>,
) -> anyhow::Result<()> {
    use sha2::Digest;
    frame_sha256.push(format!("{:x}", sha2::Sha256::digest(image.as_raw())));
    frame_thumbnails.push(frame_thumbnail(image));
    if let Some(out) = out {
        let path = out.join(format!("frame_{step:04}.png"));
        crate::outputs::write_png(image, &path)?;
    }
    Ok(())
}

/// Cells across and down of a [`frame_thumbnail`].
pub const THUMBNAIL_CELLS: (u32, u32) = (12, 9);

/// A frame's mean colour in each of [`THUMBNAIL_CELLS`] equal cells, row by row, RGB (bytes,
/// rounded): a summary that a moved, missing, hidden or recoloured tree changes by far more
/// than a rasteriser's edge pixels do.
pub fn frame_thumbnail(image: &image::RgbaImage) -> Vec<u8> {
    let (cols, rows) = THUMBNAIL_CELLS;
    let (width, height) = image.dimensions();
    let mut thumbnail = Vec::with_capacity((cols * rows * 3) as usize);
    for row in 0..rows {
        let (y0, y1) = (row * height / rows, (row + 1) * height / rows);
        for col in 0..cols {
            let (x0, x1) = (col * width / cols, (col + 1) * width / cols);
            let mut sum = [0u64; 3];
            for y in y0..y1 {
                for x in x0..x1 {
                    let p = image.get_pixel(x, y).0;
                    for (s, &c) in sum.iter_mut().zip(&p[..3]) {
                        *s += u64::from(c);
                    }
                }
            }
            let count = (u64::from(x1 - x0) * u64::from(y1 - y0)).max(1);
            thumbnail.extend(sum.iter().map(|&s| ((s + count / 2) / count) as u8));
        }
    }
    thumbnail
}

/// Time step between two shown frames: the footage's, or one 30 Hz frame when playback looped
/// or jumped.
pub fn frame_dt(dt_s: f64) -> f32 {
    if dt_s > 0.0 && dt_s < 0.5 {
        dt_s as f32
    } else {
        1.0 / 30.0
    }
}
