//! The design state: the tree, its parameters, the brush and the touch gestures that edit it.
//!
//! Every change comes in as an [`InputEvent`] stamped with its frame, so the window, headless
//! replay and UI tests drive exactly the same code (Longay 2014 §5.1–5.2: one finger brushes,
//! double tap prunes, press-and-hold selects a bud, three fingers bend).
//!
//! **The brush plane** faces the camera at the depth where the stroke started (a branch's depth
//! when the stroke starts on a branch, else the tree's) and keeps that camera distance while
//! painting: each new frame re-projects the finger through the *current* camera, so moving the
//! device moves the plane and lengthens the stroke. The core stroke gets the same camera with
//! each point, so the attraction points (what the tree grows towards) move with it too.

use std::collections::BTreeMap;

use glam::{Affine3A, Quat, Vec2, Vec3};
use serde::{Deserialize, Serialize};
use sylva_core::edit::brush::{grow_with_point_lifetime, step_with_point_lifetime};
use sylva_core::edit::{
    Bend, BendSettings, BrushSettings, BrushStroke, History, OperationKind, PositionalConstraint,
    StrokeCamera, Timeline,
};
use sylva_core::environment::DepthConstraint;
use sylva_core::environment::{Scene, SceneMode};
use sylva_core::geometry::Season;
use sylva_core::species::Species;
use sylva_core::{NodeId, Tree};

use crate::planting::{SceneChoice, growth_scene, tree_scene};
use crate::render::{GroundPlane, ViewCamera};
use crate::scale::{DesignScale, ScaleTool, TreeScale};
use crate::scene_tracking::SceneOccupancy;

mod garden;
mod recreate;
mod tools;
pub use garden::{GardenMember, OtherTree};
pub use recreate::{RecreateAction, RecreateMode, RecreateResult};
pub use tools::{DEFAULT_BRANCH_DIAMETER_M, LASSO_MAX_ITERATIONS, Tool};

/// Growth and brush parameters the UI exposes.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Parameters {
    pub species: String,
    pub apical_dominance: f32,   /* λ */
    pub light_sensitivity: f32,  /* κ */
    pub shedding_threshold: f32, /* Th */
    pub max_shoot_length: f32,   /* n_max */
    /// Shoot direction blend: α default (heading), β environment (brush), γ tropism; sums to 1.
    pub direction_weights: [f32; 3], /* α β γ */
    /// Tropism direction angle from vertical, radians.
    pub tropism_angle: f32, /* θ */
    /// Gravimorphism ellipse: horizontal and vertical semi-axes.
    pub gravimorphism: [f32; 2],
    pub branching_angle: f32,
    pub deflection_angle: f32,
    /// Sketch-based tropism: new branches follow the direction of brush strokes.
    #[serde(default)]
    pub sketch_tropism: bool,
    pub years: f32,
    /// Brush radius, metres.
    pub brush_radius: f32,
    /// Growth iterations per second while brushing (negative: ungrow).
    pub grow_speed: f32,
    /// The depth tool (Longay 2014 appendix B): attraction points only within this many metres
    /// of the vertical plane through the tree's base that faced the camera when it was set
    /// (flat, espalier-like crowns); none: free.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub depth_constraint_m: Option<f32>,
    /// How the tracked scene shapes growth (absent in older sessions: free).
    #[serde(default)]
    pub scene_mode: SceneChoice,
    /// The season the tree is shown in; sessions from before seasons are summer (and a summer
    /// session records none, so it stays as it was).
    #[serde(default, skip_serializing_if = "is_summer")]
    pub season: Season,
}

fn is_summer(season: &Season) -> bool {
    *season == Season::Summer
}

impl Default for Parameters {
    fn default() -> Self {
        match Species::by_name(DEFAULT_SPECIES) {
            Ok(species) => Parameters::for_species(&species),
            Err(_) => Parameters::for_species(&Species::presets()[0]),
        }
    }
}

pub use crate::limits::{MAX_DESIGN_YEARS, MAX_ITERATIONS_PER_REQUEST};

/// The species a new design starts with.
pub const DEFAULT_SPECIES: &str = "maple";

impl Parameters {
    /// The parameters of a species preset, with the default brush.
    pub fn for_species(species: &Species) -> Parameters {
        Parameters {
            species: species.name.clone(),
            apical_dominance: species.apical_dominance,
            light_sensitivity: species.light_sensitivity,
            shedding_threshold: species.shedding_threshold,
            max_shoot_length: species.max_shoot_internodes,
            direction_weights: normalised_weights([
                species.straightness,
                species.environment_weight,
                species.tropism_weight,
            ]),
            tropism_angle: species.gravitropism_angle_deg.to_radians(),
            gravimorphism: [
                species.gravimorphism.parallel_semi_axis,
                species.gravimorphism.vertical_semi_axis,
            ],
            branching_angle: species.branching_angle_deg.to_radians(),
            deflection_angle: species.deflection_angle_deg.to_radians(),
            sketch_tropism: false,
            years: 5.0,
            brush_radius: 0.12,
            grow_speed: 10.0,
            depth_constraint_m: None,
            scene_mode: SceneChoice::Free,
            season: Season::Summer,
        }
    }

    /// Why these parameters cannot drive a design, if they cannot (a damaged session): an
    /// unknown species, growth values the species model refuses, or a years, brush or speed
    /// value outside what the controls offer many times over.
    pub fn check(&self) -> Result<(), String> {
        let mut species = Species::by_name(&self.species)
            .map_err(|_| format!("unknown species {:?}", self.species))?;
        self.apply_to(&mut species);
        species.validate()?;
        let within = |v: f32, lo: f32, hi: f32| v.is_finite() && (lo..=hi).contains(&v);
        if !within(self.years, 0.0, MAX_DESIGN_YEARS) {
            return Err(format!(
                "years must be from 0 to {MAX_DESIGN_YEARS}, got {}",
                self.years
            ));
        }
        if !within(self.brush_radius, 1e-3, 10.0) {
            return Err(format!(
                "brush radius must be from 0.001 to 10 m, got {}",
                self.brush_radius
            ));
        }
        if !within(self.grow_speed, -1e3, 1e3) {
            return Err(format!(
                "grow speed must be from -1000 to 1000 iterations/s, got {}",
                self.grow_speed
            ));
        }
        if let Some(depth) = self.depth_constraint_m
            && !within(depth, 0.0, 100.0)
        {
            return Err(format!(
                "the depth constraint must be from 0 to 100 m, got {depth}"
            ));
        }
        Ok(())
    }

    /// Writes the growth parameters into `species` (α, β, γ are the straightness, environment
    /// and tropism weights of the shoot direction).
    pub fn apply_to(&self, species: &mut Species) {
        species.apical_dominance = self.apical_dominance;
        species.light_sensitivity = self.light_sensitivity;
        species.shedding_threshold = self.shedding_threshold;
        species.max_shoot_internodes = self.max_shoot_length.max(1.0);
        let [alpha, beta, gamma] = self.direction_weights;
        species.straightness = alpha;
        species.environment_weight = beta;
        species.tropism_weight = gamma;
        species.gravitropism_angle_deg = self.tropism_angle.to_degrees();
        species.gravimorphism.parallel_semi_axis = self.gravimorphism[0];
        species.gravimorphism.vertical_semi_axis = self.gravimorphism[1];
        species.branching_angle_deg = self.branching_angle.to_degrees();
        species.deflection_angle_deg = self.deflection_angle.to_degrees();
    }
}

fn normalised_weights(w: [f32; 3]) -> [f32; 3] {
    let sum: f32 = w.iter().sum();
    if sum > 0.0 {
        w.map(|x| x / sum)
    } else {
        [1.0 / 3.0; 3]
    }
}

/// The species preset named `name`, or the default species for an unknown name.
pub fn species_named(name: &str) -> Species {
    Species::by_name(name)
        .or_else(|_| Species::by_name(DEFAULT_SPECIES))
        .unwrap_or_else(|_| Species::presets().swap_remove(0))
}

/// Names of the species presets, for the picker.
pub fn species_names() -> Vec<String> {
    Species::presets().into_iter().map(|s| s.name).collect()
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
    /// The camera-height field: how high the phone is held above the ground, metres.
    HoldingHeight {
        holding_height_m: f64,
    },
    /// Chooses a scale tool (none: taps edit the tree again).
    ScaleTool {
        tool: Option<ScaleTool>,
    },
    /// Chooses the editing tool one finger uses ([`Tool`]; sessions without one brush).
    Tool {
        tool: Tool,
    },
    /// Restores an autosaved design (undoable): the tree file's JSON and where it stood.
    RestoreTree {
        tree_file: String,
        world_from_tree: Option<[f32; 12]>,
    },
    /// The Recreate mode's controls ([`RecreateAction`]): start marking a real tree, pick the
    /// species, grow to fit, the overlay.
    Recreate {
        action: RecreateAction,
    },
    /// "Plant another tree": the next tap on the ground plants a tree of `species` there
    /// (module `garden`).
    PlantAnother {
        species: String,
    },
    /// Selects tree `index` of the garden (a tap on a tree selects it too).
    SelectTree {
        index: usize,
    },
    /// Deletes the selected tree of a garden (undoable).
    DeleteTree,
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
pub(crate) const PICK_RADIUS_PX: f32 = 25.0;

/// A three-finger bend in progress: the branch from `base` to its tip `end`, rotated about the
/// start of `base` by `angle` radians about the view direction.
struct BendGesture {
    bend: Bend,
    end: NodeId,
    pivot: Vec3,
    rest_end: Vec3,
    angle: f32,
    last: Vec2,
}

/// The tree being designed and everything that edits it.
pub struct DesignState {
    pub params: Parameters,
    pub tree: Tree,
    pub seed: u64,
    history: History,
    timeline: Timeline,
    pub stroke: Option<Stroke>,
    brush: Option<BrushStroke>,
    pub finished_strokes: Vec<Stroke>,
    touches: BTreeMap<u64, Touch>,
    last_tap: Option<(f64, Vec2)>,
    pub selected: Option<NodeId>,
    bend: Option<BendGesture>,
    /// The camera in tree space (None while tracking is lost or before planting): picking,
    /// the brush and gestures work in tree space.
    pub camera: Option<ViewCamera>,
    /// The camera in the world.
    pub(crate) world_camera: Option<ViewCamera>,
    /// The ground plane in the world, once found.
    pub ground: Option<GroundPlane>,
    /// Where the tree stands in the world; None until a tap on the ground plants it.
    pub world_from_tree: Option<Affine3A>,
    /// The touch dragging the trunk base (moving the tree).
    pub(crate) moving_base: Option<u64>,
    /// The occupancy of the tracked scene (from the first frame with tracked points).
    pub(crate) occupancy: Option<SceneOccupancy>,
    /// The metric scale, its tools and what they measured.
    pub scale: DesignScale,
    /// The scale every tree of the design is placed with (`world_from_tree` carries it).
    pub tree_scale: TreeScale,
    pub time_s: f64,
    /// Bumped whenever the tree changes (the renderer re-meshes on change).
    pub revision: u64,
    grow_debt: f32,
    /// The editing tool and its gesture in progress.
    tools: tools::ToolState,
    /// Recreating a real tree: its marks, what was observed for them, the last result.
    pub recreate: RecreateMode,
    /// The other trees of a garden, and planting them (module `garden`).
    pub garden: garden::GardenDesign,
    /// When freed working memory was last given back to the system.
    free_memory: crate::memory::FreeMemory,
}

/// Grows `tree` autonomously to iteration `target` (keeping each iteration in `timeline`) against
/// the scene when one is given, or ungrows it to the kept iteration `target`.
fn move_to_iteration(
    tree: &mut Tree,
    timeline: &mut Timeline,
    target: u32,
    scene: Option<(&dyn Scene, SceneMode)>,
) -> Result<(), sylva_core::edit::EditError> {
    if target < tree.iteration {
        // A thinned-out iteration: the latest kept one before it, regrown to it when only
        // autonomous growth happened in between (else the ungrow lands there).
        let kept = timeline.kept_at_or_before(target).unwrap_or(target);
        timeline.go_to(tree, kept)?;
        if timeline.regrows_autonomously(kept, target) {
            while tree.iteration < target {
                grow_with_point_lifetime(tree, 1, scene);
            }
        }
        return Ok(());
    }
    while tree.iteration < target {
        grow_with_point_lifetime(tree, 1, scene);
        timeline.keep_autonomous(tree);
    }
    Ok(())
}

/// Autonomous iterations of the sapling a design starts from: a trunk with a few laterals to
/// brush from.
pub const PLANTED_ITERATIONS: u32 = 1;

fn planted(species: Species, seed: u64) -> Tree {
    let mut tree = Tree::new(species, seed);
    tree.grow(PLANTED_ITERATIONS, None);
    tree
}

/// Undo steps kept.
const MAX_UNDO: usize = 64;
/// Memory of the undo steps and of the timeline, each in multiples of the tree's own size
/// (`Tree::own_bytes`; the oldest dropped, or thinned, beyond it), so the design stays within a
/// few times the tree's size however long it is edited (see `examples/soak.rs`). Undo steps are
/// differences (what each operation changed): a stroke or a grow costs a few percent of the
/// tree, a years change or a prune up to the internodes it adds or removes, about a tree; two
/// trees keep such a step with the dozens of edits around it (at one tree, a years change forth
/// and back dropped the step before it).
const UNDO_BUDGET_TREES: f32 = 2.0;
/// Finished strokes kept (oldest dropped).
const MAX_FINISHED_STROKES: usize = 16;
const TIMELINE_BUDGET_TREES: f32 = 0.75;

impl DesignState {
    /// A sapling of `params.species` (the default species for an unknown name) planted at the
    /// world origin: its seedling grown [`PLANTED_ITERATIONS`] autonomous iterations (version 2
    /// sessions, and tests that need no planting).
    pub fn new(seed: u64, params: Parameters) -> DesignState {
        DesignState {
            world_from_tree: Some(Affine3A::IDENTITY),
            tree_scale: TreeScale::TrackerUnit,
            ..DesignState::unplanted(seed, params)
        }
    }

    /// The same sapling waiting to be planted: nothing is shown or edited until a tap on the
    /// ground plane plants it (the app and version 3 sessions).
    pub fn unplanted(seed: u64, params: Parameters) -> DesignState {
        let mut species = species_named(&params.species);
        params.apply_to(&mut species);
        let tree = planted(species, seed);
        let mut timeline = Timeline::with_budget(TIMELINE_BUDGET_TREES);
        timeline.keep(&tree);
        DesignState {
            params,
            tree,
            seed,
            history: History::new(MAX_UNDO).with_budget(UNDO_BUDGET_TREES),
            timeline,
            stroke: None,
            brush: None,
            finished_strokes: Vec::new(),
            touches: BTreeMap::new(),
            last_tap: None,
            selected: None,
            bend: None,
            camera: None,
            world_camera: None,
            ground: None,
            world_from_tree: None,
            moving_base: None,
            occupancy: None,
            scale: DesignScale::default(),
            tree_scale: TreeScale::Awaiting,
            time_s: 0.0,
            revision: 0,
            grow_debt: 0.0,
            tools: Default::default(),
            recreate: RecreateMode::default(),
            garden: Default::default(),
            free_memory: Default::default(),
        }
    }

    /// Bytes held by the undo snapshots and by the timeline's kept states (the soak report).
    pub fn snapshot_bytes(&self) -> (usize, usize) {
        (self.history.snapshot_bytes(), self.timeline.kept_bytes())
    }

    /// Number of undo steps available.
    pub fn undo_depth(&self) -> usize {
        self.history.num_undoable() + self.garden_undo_depth()
    }

    pub(crate) fn changed(&mut self) {
        self.revision += 1;
    }

    /// SHA-256 of the tree's JSON file.
    pub fn tree_sha256(&self) -> String {
        use sha2::Digest;
        let json = self.tree.to_json_bytes().unwrap_or_default();
        format!("{:x}", sha2::Sha256::digest(json))
    }

    /// Advances to a new frame seen from `camera` at `time_s`: the brush plane follows the
    /// device, held touches become selections, and while a stroke is painted the tree grows
    /// towards it (brush-guided iterations, `grow_speed` per second).
    pub fn advance_frame(&mut self, camera: Option<ViewCamera>, time_s: f64, dt_s: f32) {
        self.world_camera = camera;
        self.update_tree_camera();
        self.time_s = time_s;
        if self.stroke.is_some() {
            self.add_stroke_point();
        }
        self.detect_hold();
        self.grow_debt += self.params.grow_speed.max(0.0) * dt_s;
        while self.grow_debt >= 1.0 {
            self.grow_debt -= 1.0;
            if self.brush.is_some() {
                self.grow_once();
            }
        }
        self.free_memory.after_frame(self.revision, time_s);
    }

    /// One brush-guided growth iteration towards the persistent points of the stroke.
    fn grow_once(&mut self) {
        let Some(brush) = self.brush.as_mut() else {
            return;
        };
        brush.emit_dab(&mut self.tree);
        let stats = match growth_scene(
            self.params.scene_mode,
            &self.occupancy,
            self.world_from_tree,
        ) {
            Some((scene, mode)) => {
                brush.emit(&mut self.tree);
                step_with_point_lifetime(
                    &mut self.tree,
                    sylva_core::growth::StepOptions {
                        autonomous: false,
                        scene: Some((&scene, mode)),
                    },
                )
            }
            None => brush.iterate(&mut self.tree),
        };
        self.timeline.keep(&self.tree);
        if stats.num_new_internodes > 0 {
            self.changed();
        }
    }

    /// Applies one input event.
    pub fn apply(&mut self, event: &InputEvent) {
        match event {
            InputEvent::Touch { phase, id, x, y } => self.touch(*phase, *id, Vec2::new(*x, *y)),
            InputEvent::Parameters { parameters } => self.set_parameters(parameters),
            InputEvent::Undo => {
                if !self.undo_garden_step_first() && self.history.undo(&mut self.tree).is_some() {
                    self.brush = None;
                    self.bend = None;
                    self.selected = None;
                    self.changed();
                }
            }
            InputEvent::Grow { iterations } => self.grow_whole_tree(*iterations),
            InputEvent::HoldingHeight { holding_height_m } => {
                self.scale.set_holding_height_m(*holding_height_m);
                self.adopt_current_scale();
            }
            InputEvent::ScaleTool { tool } => self.scale.choose(*tool),
            InputEvent::Tool { tool } => self.choose_tool(*tool),
            InputEvent::RestoreTree {
                tree_file,
                world_from_tree,
            } => {
                if let Ok(tree) = crate::autosave::parse_restored_tree(tree_file) {
                    self.restore_tree(tree, *world_from_tree);
                }
            }
            InputEvent::Recreate { action } => self.recreate_action(action),
            InputEvent::PlantAnother { species } => self.arm_planting(species),
            InputEvent::SelectTree { index } => self.select_tree(*index),
            InputEvent::DeleteTree => self.delete_selected_tree(),
        }
    }

    /// Replaces the design's tree by a restored one (undoable), standing where it stood.
    fn restore_tree(&mut self, tree: Tree, world_from_tree: Option<[f32; 12]>) {
        self.history.record(OperationKind::Parameters, &self.tree);
        self.params = Parameters {
            brush_radius: self.params.brush_radius,
            grow_speed: self.params.grow_speed,
            scene_mode: self.params.scene_mode,
            season: self.params.season,
            years: tree.age_years(),
            ..Parameters::for_species(&tree.species)
        };
        self.tree = tree;
        self.timeline = Timeline::with_budget(TIMELINE_BUDGET_TREES);
        self.timeline.keep(&self.tree);
        if let Some(m) = world_from_tree.map(|m| Affine3A::from_cols_array(&m))
            && let Some(scale) = self.restored_scale(&m)
        {
            self.set_tree_scale(scale);
            self.world_from_tree = Some(m);
        }
        self.brush = None;
        self.bend = None;
        self.selected = None;
        self.changed();
    }

    /// The design scale a restored placement carries (None for a placement that cannot be one:
    /// not finite, or no plausible scale): the current scale when it is that one, the design's
    /// own when unchanged.
    fn restored_scale(&self, world_from_tree: &Affine3A) -> Option<TreeScale> {
        let metres_per_unit = f64::from(crate::planting::metres_per_unit_of(world_from_tree));
        if !(world_from_tree.is_finite() && (1e-3..=1e3).contains(&metres_per_unit)) {
            return None;
        }
        let same = |a: f64| (a / metres_per_unit - 1.0).abs() < 1e-5;
        let current = self.scale.state.current();
        Some(if same(self.tree_scale.metres_per_unit()) {
            self.tree_scale
        } else if let Some(scale) = current.filter(|s| same(s.metres_per_unit)) {
            TreeScale::Metric(scale)
        } else {
            TreeScale::Restored { metres_per_unit }
        })
    }

    /// New parameters (undoable). Another species starts a seedling of it.
    fn set_parameters(&mut self, parameters: &Parameters) {
        // Controls cannot make parameters that fail the check; a damaged session can.
        if *parameters == self.params || parameters.check().is_err() {
            return;
        }
        if self.garden_parameters(parameters) {
            return;
        }
        self.history.record(OperationKind::Parameters, &self.tree);
        if parameters.species != self.tree.species.name {
            let species = species_named(&parameters.species);
            let brush = (parameters.brush_radius, parameters.grow_speed);
            self.params = Parameters {
                brush_radius: brush.0,
                grow_speed: brush.1,
                scene_mode: parameters.scene_mode,
                season: parameters.season,
                ..Parameters::for_species(&species)
            };
            self.tree = planted(species, self.seed);
            self.timeline = Timeline::with_budget(TIMELINE_BUDGET_TREES);
            self.timeline.keep(&self.tree);
            self.brush = None;
            self.changed();
            return;
        }
        let years_changed = parameters.years != self.params.years;
        let depth_changed = parameters.depth_constraint_m != self.params.depth_constraint_m;
        let prune_now = parameters.scene_mode == SceneChoice::PruneToScene
            && self.params.scene_mode != SceneChoice::PruneToScene;
        if parameters.season != self.params.season {
            self.changed(); // the tree is drawn anew in its season
        }
        self.params = parameters.clone();
        if depth_changed {
            self.set_depth_constraint(parameters.depth_constraint_m);
        }
        parameters.apply_to(&mut self.tree.species);
        if prune_now {
            // Choosing "prune to the scene" cuts what free growth pushed into it.
            if let Some(scene) = tree_scene(&self.occupancy, self.world_from_tree)
                && self.tree.prune_to_scene(&scene) > 0
            {
                self.timeline.keep(&self.tree);
                self.brush = None;
                self.bend = None;
                self.selected = None;
                self.changed();
            }
        }
        if years_changed {
            self.grow_to_age(parameters.years);
        }
    }

    /// The years slider: grows the tree autonomously to `years` of age, or ungrows it to the kept
    /// iteration of that age (part of the parameter change's undo step).
    fn grow_to_age(&mut self, years: f32) {
        if !years.is_finite() {
            return;
        }
        let target = self.tree.species.iterations_for_years(years.max(0.0));
        let earliest = self.timeline.range().map_or(target, |(first, _)| first);
        let target = target.max(earliest);
        let scene = growth_scene(
            self.params.scene_mode,
            &self.occupancy,
            self.world_from_tree,
        );
        let scene = scene.as_ref().map(|(s, m)| (s as &dyn Scene, *m));
        if target == self.tree.iteration
            || move_to_iteration(&mut self.tree, &mut self.timeline, target, scene).is_err()
        {
            return;
        }
        self.brush = None;
        self.bend = None;
        self.selected = None;
        self.changed();
    }

    /// Autonomous growth (positive) or ungrowing to an earlier kept iteration (negative).
    fn grow_whole_tree(&mut self, iterations: i32) {
        let target = if iterations >= 0 {
            self.tree
                .iteration
                .saturating_add(iterations as u32)
                .min(sylva_core::growth::MAX_ITERATIONS)
        } else {
            self.tree
                .iteration
                .saturating_sub(iterations.unsigned_abs())
        };
        let timeline = &mut self.timeline;
        let scene = growth_scene(
            self.params.scene_mode,
            &self.occupancy,
            self.world_from_tree,
        );
        let scene = scene.as_ref().map(|(s, m)| (s as &dyn Scene, *m));
        let result = self
            .history
            .perform(OperationKind::Grow, &mut self.tree, |tree| {
                move_to_iteration(tree, timeline, target, scene)
            });
        if result.is_ok() {
            self.changed();
        }
    }

    fn touch(&mut self, phase: TouchPhase, id: u64, pixel: Vec2) {
        if self.scale.tool.is_some() {
            // A scale tool takes the taps (its touches never reach the tree); a known length
            // marked rescales the design.
            if self.scale.touch(phase, id, pixel) {
                self.adopt_current_scale();
            }
            return;
        }
        if self.recreate_touch(phase, id, pixel) {
            return;
        }
        if self.planting_touch(phase, id, pixel) {
            return;
        }
        if self.tool_touch(phase, id, pixel) {
            return;
        }
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
                    1 if !self.is_planted() || self.begin_move(id, pixel) => {}
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
                if self.moving_base == Some(id) {
                    if self.touches.get(&id).is_some_and(|t| t.moved) {
                        self.plant_at(pixel);
                    }
                } else if self.bend.is_some() {
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
                if self.moving_base.take_if(|m| *m == id).is_some() && !is_tap {
                    return;
                }
                if !self.is_planted() {
                    // Before planting, a tap on the ground plants the tree there.
                    if is_tap && self.touches.is_empty() {
                        self.plant_at(pixel);
                    }
                    return;
                }
                self.end_stroke(!is_tap);
                if is_tap && !self.garden_tap(pixel) {
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
            Some(id) => camera.depth_of(self.tree.skeleton.get(id).end),
            None => camera.depth_of(self.tree_centre()),
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
        let nodes = &self.tree.skeleton.internodes;
        let n = nodes.len().max(1) as f32;
        nodes.iter().map(|i| i.end).sum::<Vec3>() / n
    }

    /// Adds the finger's point on the brush plane seen from the current camera; the first
    /// point starts an undoable `sylva_core` brush stroke at the stroke's camera depth, and
    /// every point goes to it with the camera it was drawn from, so the attraction points
    /// follow the device (Longay 2014 §5.4.2).
    fn add_stroke_point(&mut self) {
        let (Some(camera), Some(stroke)) = (self.camera, self.stroke.as_mut()) else {
            return;
        };
        let moved = self.touches.values().any(|t| t.moved);
        let first_touch_s = self
            .touches
            .values()
            .map(|t| t.start_time_s)
            .fold(f64::MAX, f64::min);
        if !moved && stroke.points.is_empty() && self.time_s - first_touch_s < HOLD_S {
            // Not yet a stroke: maybe a tap.
            return;
        }
        // A point on the ray through the finger (camera depth 1) and the camera's optical axis.
        let through = camera
            .world_from_camera
            .transform_point3(camera.intrinsics.ray_from_pixel(stroke.pixel));
        let view_direction = camera.world_from_camera.transform_vector3(Vec3::Z);
        let Ok(view) = StrokeCamera::new(camera.position(), view_direction) else {
            return;
        };
        let Some(point) = view.point_at_depth(through, stroke.depth) else {
            return;
        };
        let radius = self.params.brush_radius;
        stroke.points.push(point);
        stroke.radii.push(radius);
        stroke.eyes.push(camera.position());
        if self.brush.is_none() {
            let settings = BrushSettings {
                sketch_tropism: self.params.sketch_tropism,
                ..BrushSettings::default()
            };
            let Ok(brush) = BrushStroke::new(stroke.depth, settings) else {
                return;
            };
            self.history.record(OperationKind::Stroke, &self.tree);
            self.brush = Some(brush);
        }
        let time_s = self.time_s;
        if let Some(brush) = self.brush.as_mut() {
            let time_s = brush
                .points()
                .last()
                .map_or(time_s, |p| p.time_s.max(time_s));
            if brush.add_point(time_s, view, through, radius).is_ok() {
                brush.emit(&mut self.tree);
            }
        }
    }

    /// The depth tool: the tree's one depth constraint (`sylva_core::environment::DepthConstraint`),
    /// a slab `depth_m` either side of the vertical plane through the tree's base that faces the
    /// current camera (the world's Z axis without one); brushing, the lasso and growth keep to it.
    fn set_depth_constraint(&mut self, depth_m: Option<f32>) {
        let base = self
            .tree
            .skeleton
            .internodes
            .first()
            .map_or(Vec3::ZERO, |n| n.start);
        let view = self
            .camera
            .map_or(Vec3::Z, |c| c.world_from_camera.transform_vector3(Vec3::Z));
        let normal = Vec3::new(view.x, 0.0, view.z)
            .try_normalize()
            .unwrap_or(Vec3::Z);
        let constraint = depth_m.and_then(|d| DepthConstraint::through(base, normal, d));
        // The points the constraint drops leave their groups (which counts as activity).
        let iteration = self.tree.iteration;
        let tracked = self.tree.environment.attraction.track(iteration);
        self.tree.environment.set_depth_constraint(constraint);
        self.tree.environment.attraction.age(&tracked, iteration);
        self.changed();
    }

    fn end_stroke(&mut self, keep: bool) {
        if self.brush.take().is_some() {
            // The stroke's undo step is complete: kept as what it changed.
            self.history.finish(&self.tree);
        }
        if let Some(stroke) = self.stroke.take()
            && keep
            && !stroke.points.is_empty()
        {
            self.finished_strokes.push(stroke);
            // The latest strokes only: memory must not grow with the length of a session.
            let excess = self
                .finished_strokes
                .len()
                .saturating_sub(MAX_FINISHED_STROKES);
            self.finished_strokes.drain(..excess);
        }
    }

    /// A double tap prunes the branch under the finger (`sylva_core::edit::prune_at`).
    fn tap(&mut self, pixel: Vec2) {
        let double = self
            .last_tap
            .is_some_and(|(t, p)| self.time_s - t < DOUBLE_TAP_S && p.distance(pixel) < 20.0);
        if !double {
            self.last_tap = Some((self.time_s, pixel));
            return;
        }
        self.last_tap = None;
        self.prune_under(pixel);
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

    /// Three fingers on a branch start bending it (`sylva_core::edit::Bend`) from the picked
    /// internode up to the tip of its axis.
    fn begin_bend(&mut self) {
        self.end_stroke(false);
        let centroid = self.touch_centroid();
        let Some(base) = self
            .pick_within(centroid, 4.0 * PICK_RADIUS_PX)
            .filter(|id| id.0 != 0)
        else {
            return;
        };
        let skeleton = &self.tree.skeleton;
        let mut end = base;
        while let Some(next) = skeleton.get(end).main_child {
            end = next;
        }
        let Ok(bend) = Bend::new(skeleton, base, end, BendSettings::default()) else {
            return;
        };
        let pivot = skeleton.get(base).start;
        let rest_end = skeleton.get(end).end;
        self.history.record(OperationKind::Bend, &self.tree);
        self.bend = Some(BendGesture {
            bend,
            end,
            pivot,
            rest_end,
            angle: 0.0,
            last: centroid,
        });
    }

    /// Sideways finger motion turns the branch tip about the view direction.
    fn update_bend(&mut self) {
        let centroid = self.touch_centroid();
        let (Some(gesture), Some(camera)) = (self.bend.as_mut(), self.camera) else {
            return;
        };
        gesture.angle += (centroid.x - gesture.last.x) / 200.0;
        gesture.last = centroid;
        let forward = camera.world_from_camera.z_axis.truncate();
        let rotation = Quat::from_axis_angle(forward, -gesture.angle);
        let target = gesture.pivot + rotation * (gesture.rest_end - gesture.pivot);
        let constraint = PositionalConstraint {
            node: gesture.end,
            end_position: target,
        };
        if let Ok(pose) = gesture.bend.solve(&[constraint]) {
            gesture.bend.apply_to_tree(&pose, &mut self.tree);
            self.changed();
        }
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
            .skeleton
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
