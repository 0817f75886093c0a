//! The design state: the tree, its parameters, the brush and the touch gestures that edit it.
//!
//! Every change comes in as an [`InputEvent`] stamped with its frame, so the window, headless
//! replay and UI tests drive exactly the same code (Longay 2014 §5.1–5.2: one finger brushes,
//! double tap prunes, press-and-hold selects a bud, three fingers bend).
//!
//! **The brush plane** faces the camera at the depth where the stroke started (a branch's depth
//! when the stroke starts on a branch, else the tree's) and keeps that camera distance while
//! painting: each new frame re-projects the finger through the *current* camera, so moving the
//! device moves the plane and lengthens the stroke.

use std::collections::BTreeMap;

use glam::{Quat, Vec2, Vec3};
use serde::{Deserialize, Serialize};
use sylva_core::{NodeId, Rng, Skeleton};

use crate::render::ViewCamera;
use crate::standin;

/// Growth and brush parameters the UI exposes.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Parameters {
    pub species: String,
    pub apical_dominance: f32,   /* λ */
    pub light_sensitivity: f32,  /* κ */
    pub shedding_threshold: f32, /* Th */
    pub max_shoot_length: u32,   /* n_max */
    /// Shoot direction blend: α default (heading), β environment (brush), γ tropism; sums to 1.
    pub direction_weights: [f32; 3], /* α β γ */
    /// Tropism direction angle from vertical, radians.
    pub tropism_angle: f32, /* θ */
    /// Gravimorphism ellipse: horizontal and vertical semi-axes.
    pub gravimorphism: [f32; 2],
    pub branching_angle: f32,
    pub deflection_angle: f32,
    pub years: f32,
    /// Brush radius, metres.
    pub brush_radius: f32,
    /// Growth iterations per second while brushing (negative: ungrow).
    pub grow_speed: f32,
}

impl Default for Parameters {
    fn default() -> Self {
        Parameters {
            species: "generic".into(),
            apical_dominance: 0.5,
            light_sensitivity: 0.5,
            shedding_threshold: 0.2,
            max_shoot_length: 3,
            direction_weights: [0.2, 0.7, 0.1],
            tropism_angle: 0.0,
            gravimorphism: [1.0, 1.0],
            branching_angle: 0.7,
            deflection_angle: 0.1,
            years: 5.0,
            brush_radius: 0.12,
            grow_speed: 10.0,
        }
    }
}

impl Parameters {
    /// The tropism direction (unit) from θ.
    pub fn tropism(&self) -> Vec3 {
        Vec3::new(self.tropism_angle.sin(), self.tropism_angle.cos(), 0.0)
    }
}

#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum TouchPhase {
    Start,
    Move,
    End,
}

/// One input, as recorded in sessions. Touch positions are pixels of the camera image.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(tag = "kind", rename_all = "snake_case")]
pub enum InputEvent {
    Touch {
        phase: TouchPhase,
        id: u64,
        x: f32,
        y: f32,
    },
    Parameters {
        parameters: Parameters,
    },
    Undo,
    /// Grows (positive) or ungrows (negative) the whole tree by this many iterations.
    Grow {
        iterations: i32,
    },
}

/// A brush stroke.
#[derive(Clone, Debug, PartialEq)]
pub struct Stroke {
    /// Camera distance (Z in camera space, metres) of the brush plane.
    pub depth: f32,
    /// Where the finger is, image pixels.
    pub pixel: Vec2,
    /// Stroke points in the world, one per move and per frame.
    pub points: Vec<Vec3>,
    /// Brush radius at each point.
    pub radii: Vec<f32>,
    /// Camera position when each point was made.
    pub eyes: Vec<Vec3>,
}

#[derive(Clone, Copy, Debug)]
struct Touch {
    start: Vec2,
    now: Vec2,
    start_time_s: f64,
    moved: bool,
}

const TAP_SLOP_PX: f32 = 8.0;
const DOUBLE_TAP_S: f64 = 0.35;
const HOLD_S: f64 = 0.5;
const PICK_RADIUS_PX: f32 = 25.0;

/// The tree being designed and everything that edits it.
pub struct DesignState {
    pub params: Parameters,
    pub tree: Skeleton,
    pub seed: u64,
    history: Vec<Skeleton>,
    pub stroke: Option<Stroke>,
    pub finished_strokes: Vec<Stroke>,
    attractors: Vec<Vec3>,
    rng: Rng,
    touches: BTreeMap<u64, Touch>,
    last_tap: Option<(f64, Vec2)>,
    pub selected: Option<NodeId>,
    bend: Option<(NodeId, Vec2)>,
    pub camera: Option<ViewCamera>,
    pub time_s: f64,
    /// Bumped whenever the tree changes (the renderer re-meshes on change).
    pub revision: u64,
    grow_debt: f32,
}

impl DesignState {
    /// A seedling at the ground origin.
    pub fn new(seed: u64, params: Parameters) -> DesignState {
        DesignState {
            params,
            tree: standin::standin_skeleton(seed, 0),
            seed,
            history: Vec::new(),
            stroke: None,
            finished_strokes: Vec::new(),
            attractors: Vec::new(),
            rng: Rng::new(seed ^ 0x5eed),
            touches: BTreeMap::new(),
            last_tap: None,
            selected: None,
            bend: None,
            camera: None,
            time_s: 0.0,
            revision: 0,
            grow_debt: 0.0,
        }
    }

    /// Number of undo steps available.
    pub fn undo_depth(&self) -> usize {
        self.history.len()
    }

    fn checkpoint(&mut self) {
        self.history.push(self.tree.clone());
        if self.history.len() > 64 {
            self.history.remove(0);
        }
    }

    fn changed(&mut self) {
        self.revision += 1;
    }

    /// SHA-256 of the tree's JSON.
    pub fn tree_sha256(&self) -> String {
        use sha2::Digest;
        let json = serde_json::to_vec(&self.tree).unwrap_or_default();
        format!("{:x}", sha2::Sha256::digest(json))
    }

    /// Advances to a new frame seen from `camera` at `time_s`: the brush plane follows the
    /// device, held touches become selections, and the tree grows towards the brush.
    pub fn advance_frame(&mut self, camera: Option<ViewCamera>, time_s: f64, dt_s: f32) {
        self.camera = camera;
        self.time_s = time_s;
        if self.stroke.is_some() {
            self.add_stroke_point();
        }
        self.detect_hold();
        self.grow_debt += self.params.grow_speed.max(0.0) * dt_s;
        while self.grow_debt >= 1.0 {
            self.grow_debt -= 1.0;
            if !self.attractors.is_empty() {
                self.grow_once();
            }
        }
    }

    fn grow_once(&mut self) -> usize {
        let grown = standin::standin_grow_towards(
            &mut self.tree,
            &mut self.attractors,
            (0.45, 0.05),
            self.params.direction_weights,
            self.params.tropism(),
        );
        if grown > 0 {
            self.changed();
        }
        grown
    }

    /// Applies one input event.
    pub fn apply(&mut self, event: &InputEvent) {
        match event {
            InputEvent::Touch { phase, id, x, y } => self.touch(*phase, *id, Vec2::new(*x, *y)),
            InputEvent::Parameters { parameters } => self.params = parameters.clone(),
            InputEvent::Undo => {
                if let Some(previous) = self.history.pop() {
                    self.tree = previous;
                    self.attractors.clear();
                    self.changed();
                }
            }
            InputEvent::Grow { iterations } => self.grow_whole_tree(*iterations),
        }
    }

    fn grow_whole_tree(&mut self, iterations: i32) {
        self.checkpoint();
        if iterations < 0 {
            for _ in 0..iterations.unsigned_abs() {
                let newest = self.tree.internodes.iter().map(|n| n.born_iteration).max();
                let Some(newest) = newest.filter(|n| *n > 0) else {
                    break;
                };
                while let Some(i) = self
                    .tree
                    .internodes
                    .iter()
                    .rposition(|n| n.born_iteration == newest && i_is_not_root(n))
                {
                    standin::standin_remove_subtree(&mut self.tree, NodeId(i as u32));
                }
            }
        } else {
            let top = self
                .tree
                .internodes
                .iter()
                .map(|n| n.end)
                .fold(Vec3::ZERO, |a, b| if b.y > a.y { b } else { a });
            for _ in 0..iterations {
                for _ in 0..24 {
                    let p =
                        top + Vec3::Y * 0.2 + self.rng.in_unit_ball() * Vec3::new(0.5, 0.35, 0.5);
                    self.attractors.push(p);
                }
                self.grow_once();
            }
            self.attractors.clear();
        }
        self.changed();
    }

    fn touch(&mut self, phase: TouchPhase, id: u64, pixel: Vec2) {
        match phase {
            TouchPhase::Start => {
                self.touches.insert(
                    id,
                    Touch {
                        start: pixel,
                        now: pixel,
                        start_time_s: self.time_s,
                        moved: false,
                    },
                );
                match self.touches.len() {
                    1 => self.begin_stroke(pixel),
                    3 => self.begin_bend(),
                    _ => self.end_stroke(false),
                }
            }
            TouchPhase::Move => {
                if let Some(t) = self.touches.get_mut(&id) {
                    t.now = pixel;
                    t.moved |= t.now.distance(t.start) > TAP_SLOP_PX;
                }
                if self.bend.is_some() {
                    self.update_bend();
                } else if let Some(stroke) = self.stroke.as_mut() {
                    stroke.pixel = pixel;
                    self.add_stroke_point();
                }
            }
            TouchPhase::End => {
                let touch = self.touches.remove(&id);
                if self.bend.is_some() {
                    if self.touches.is_empty() {
                        self.bend = None;
                    }
                    return;
                }
                let is_tap =
                    touch.is_some_and(|t| !t.moved && self.time_s - t.start_time_s < HOLD_S);
                self.end_stroke(!is_tap);
                if is_tap {
                    self.tap(pixel);
                }
            }
        }
    }

    fn begin_stroke(&mut self, pixel: Vec2) {
        let Some(camera) = self.camera else {
            return;
        };
        // A stroke starting on a branch takes that branch's depth, else the tree's.
        let depth = match self.pick(pixel) {
            Some(id) => camera.depth_of(self.tree.get(id).end),
            None => {
                let centre = self.tree_centre();
                camera.depth_of(centre)
            }
        };
        if depth <= camera.near {
            return;
        }
        self.stroke = Some(Stroke {
            depth,
            pixel,
            points: Vec::new(),
            radii: Vec::new(),
            eyes: Vec::new(),
        });
    }

    fn tree_centre(&self) -> Vec3 {
        let n = self.tree.len().max(1) as f32;
        self.tree.internodes.iter().map(|i| i.end).sum::<Vec3>() / n
    }

    /// Adds the finger's point on the brush plane seen from the current camera.
    fn add_stroke_point(&mut self) {
        let (Some(camera), Some(stroke)) = (self.camera, self.stroke.as_mut()) else {
            return;
        };
        let moved = self.touches.values().any(|t| t.moved);
        if !moved
            && stroke.points.is_empty()
            && self.time_s
                - self
                    .touches
                    .values()
                    .map(|t| t.start_time_s)
                    .fold(f64::MAX, f64::min)
                < HOLD_S
        {
            // Not yet a stroke: maybe a tap.
            return;
        }
        let ray = camera.intrinsics.ray_from_pixel(stroke.pixel);
        let point = camera
            .world_from_camera
            .transform_point3(ray * stroke.depth);
        if stroke.points.is_empty() {
            self.history.push(self.tree.clone());
        }
        let radius = self.params.brush_radius;
        stroke.points.push(point);
        stroke.radii.push(radius);
        stroke.eyes.push(camera.position());
        for _ in 0..6 {
            let p = point + self.rng.in_unit_ball() * radius;
            self.attractors.push(p);
        }
    }

    fn end_stroke(&mut self, keep: bool) {
        if let Some(stroke) = self.stroke.take()
            && keep
            && !stroke.points.is_empty()
        {
            self.finished_strokes.push(stroke);
        }
    }

    fn tap(&mut self, pixel: Vec2) {
        let double = self
            .last_tap
            .is_some_and(|(t, p)| self.time_s - t < DOUBLE_TAP_S && p.distance(pixel) < 20.0);
        if !double {
            self.last_tap = Some((self.time_s, pixel));
            return;
        }
        self.last_tap = None;
        if let Some(id) = self.pick(pixel).filter(|id| id.0 != 0) {
            self.checkpoint();
            standin::standin_remove_subtree(&mut self.tree, id);
            self.selected = None;
            self.changed();
        }
    }

    fn detect_hold(&mut self) {
        if self.touches.len() != 1 {
            return;
        }
        let Some(t) = self.touches.values().next().copied() else {
            return;
        };
        if !t.moved
            && self.time_s - t.start_time_s >= HOLD_S
            && self.stroke.as_ref().is_some_and(|s| s.points.is_empty())
        {
            self.stroke = None;
            self.selected = self.pick(t.now);
        }
    }

    fn begin_bend(&mut self) {
        self.end_stroke(false);
        let centroid = self.touch_centroid();
        if let Some(id) = self
            .pick_within(centroid, 4.0 * PICK_RADIUS_PX)
            .filter(|id| id.0 != 0)
        {
            self.checkpoint();
            self.bend = Some((id, centroid));
        }
    }

    fn update_bend(&mut self) {
        let (Some((root, last)), Some(camera)) = (self.bend, self.camera) else {
            return;
        };
        let centroid = self.touch_centroid();
        let angle = (centroid.x - last.x) / 200.0;
        let forward = camera.world_from_camera.z_axis.truncate();
        standin::standin_bend(&mut self.tree, root, Quat::from_axis_angle(forward, -angle));
        self.bend = Some((root, centroid));
        self.changed();
    }

    fn touch_centroid(&self) -> Vec2 {
        let n = self.touches.len().max(1) as f32;
        self.touches.values().map(|t| t.now).sum::<Vec2>() / n
    }

    fn pick(&self, pixel: Vec2) -> Option<NodeId> {
        self.pick_within(pixel, PICK_RADIUS_PX)
    }

    /// The internode whose midpoint projects nearest to `pixel`, within `radius_px`.
    fn pick_within(&self, pixel: Vec2, radius_px: f32) -> Option<NodeId> {
        let camera = self.camera?;
        self.tree
            .internodes
            .iter()
            .enumerate()
            .filter_map(|(i, n)| {
                let p = camera.pixel_from_world(0.5 * (n.start + n.end))?;
                Some((i, p.distance(pixel)))
            })
            .filter(|(_, d)| *d <= radius_px)
            .min_by(|a, b| a.1.total_cmp(&b.1))
            .map(|(i, _)| NodeId(i as u32))
    }
}

fn i_is_not_root(n: &sylva_core::Internode) -> bool {
    n.parent.is_some()
}
