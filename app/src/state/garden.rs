//! A design of several trees: a garden (issue #24's app part).
//!
//! The design starts as one tree, exactly as before gardens. "Plant another tree"
//! ([`InputEvent::PlantAnother`](super::InputEvent::PlantAnother)) arms the next tap on the
//! ground: it plants a sapling of the chosen species there, grown at once to the garden's age
//! against the trees already standing, and selects it; the design then holds a
//! [`sylva_core::garden::Garden`] (garden space: the first tree's space, so its trunk stands at
//! the origin). The **selected** tree is `DesignState::tree`, so every tool, slider and gesture
//! edits it as they edit a single tree; its environment was readied by
//! [`Garden::prepare_edit`] (its neighbours' nodes as occupied space, their tropism and shade),
//! so it grows against its neighbours as they stand, and the others do not change. On the next
//! garden step (selecting another tree, planting, deleting, the years slider) it is put back
//! ([`Garden::replace_tree`]), which hands its change on to its neighbours' shade.
//!
//! **The years slider** moves the whole garden: every tree grows together to its planting age
//! plus the slider (trees are planted at age 0 of the garden's clock, so at the slider's age),
//! each against its own view of the tracked scene. Moving it back restores the garden as it was
//! kept at or before that age (kept each time the slider grew it; planting or deleting a tree
//! starts the keeping anew, as edits do for a single tree's timeline).
//!
//! **Undo** is one line: the selected tree's own edits since the last garden step first, then
//! the garden step itself (which brings back the trees, the selection and the undo steps of the
//! tree selected before it).

use std::sync::Arc;

use glam::{Affine3A, Vec2, Vec3};
use sylva_core::Tree;
use sylva_core::edit::{History, Timeline};
use sylva_core::environment::{Scene, SceneMode};
use sylva_core::garden::Garden;

use super::{
    DesignState, HOLD_S, MAX_UNDO, PICK_RADIUS_PX, Parameters, TAP_SLOP_PX, TIMELINE_BUDGET_TREES,
    TouchPhase, UNDO_BUDGET_TREES, planted, species_named,
};
use crate::planting::{
    SceneChoice, TreeScene, ground_point_at_pixel, growth_scene, tree_scene, world_from_tree_at,
};

/// Garden steps undo keeps (each holds every tree; the oldest dropped).
const MAX_GARDEN_UNDO: usize = 16;
/// Garden states the years slider can go back to (the oldest dropped).
const MAX_KEPT_AGES: usize = 8;

/// What the design knows of one garden tree besides the tree itself.
#[derive(Clone, Debug, PartialEq)]
pub struct GardenMember {
    /// Unique within the design, never reused: what drawn meshes are cached by.
    pub id: u64,
    /// A new number (from one counter) whenever this tree changes: the same id and revision
    /// always mean the same tree.
    pub revision: u64,
    pub world_from_tree: Affine3A,
}

/// The trees of a garden, with the selected one as it was last put back.
#[derive(Clone)]
struct Stand {
    garden: Garden,
    members: Vec<GardenMember>,
}

/// Everything a garden step changes, as it was before it.
struct GardenStep {
    stand: Option<Stand>,
    selected: usize,
    tree: Tree,
    seed: u64,
    world_from_tree: Option<Affine3A>,
    params: Parameters,
    history: History,
    timeline: Timeline,
    kept: Vec<Arc<Stand>>,
}

/// The design's garden: none until a second tree is planted.
#[derive(Default)]
pub struct GardenDesign {
    stand: Option<Stand>,
    /// Index of the selected tree in the garden.
    selected: usize,
    garden_from_world: Affine3A,
    /// The species "Plant another tree" armed: the next tap on the ground plants one there.
    pub planting: Option<String>,
    planting_touch: Option<(u64, Vec2, f64)>,
    undo: Vec<GardenStep>,
    kept: Vec<Arc<Stand>>,
    next_id: u64,
    next_revision: u64,
}

impl GardenDesign {
    fn revision(&mut self) -> u64 {
        self.next_revision += 1;
        self.next_revision
    }
}

/// A tree of the garden other than the selected one, as drawn.
pub struct OtherTree<'a> {
    pub id: u64,
    pub revision: u64,
    pub world_from_tree: Affine3A,
    pub tree: &'a Tree,
}

/// Each tree's scene (its own space) and mode, owned: borrowed by [`scene_refs`].
fn scenes_of<'a>(
    choice: SceneChoice,
    occupancy: &'a Option<crate::scene_tracking::SceneOccupancy>,
    members: &[GardenMember],
) -> Vec<Option<(TreeScene<'a>, SceneMode)>> {
    members
        .iter()
        .map(|m| growth_scene(choice, occupancy, Some(m.world_from_tree)))
        .collect()
}

fn scene_refs<'a>(
    scenes: &'a [Option<(TreeScene<'_>, SceneMode)>],
) -> Vec<Option<(&'a dyn Scene, SceneMode)>> {
    scenes
        .iter()
        .map(|s| s.as_ref().map(|(s, m)| (s as &dyn Scene, *m)))
        .collect()
}

impl DesignState {
    /// Number of trees in the design (0 before the first is planted).
    pub fn num_trees(&self) -> usize {
        match &self.garden.stand {
            Some(stand) => stand.members.len(),
            None => usize::from(self.is_planted()),
        }
    }

    /// Index of the selected tree (the one `tree` is).
    pub fn selected_tree(&self) -> usize {
        self.garden.selected
    }

    /// Whether the design holds a garden (a second tree was planted).
    pub fn has_garden(&self) -> bool {
        self.garden.stand.is_some()
    }

    /// The species of each tree, in garden order (the garden panel's list).
    pub fn tree_species(&self) -> Vec<String> {
        match &self.garden.stand {
            Some(stand) => (0..stand.members.len())
                .map(|i| match i == self.garden.selected {
                    true => self.tree.species.name.clone(),
                    false => stand.garden.trees[i].tree.species.name.clone(),
                })
                .collect(),
            None => vec![self.tree.species.name.clone(); self.num_trees()],
        }
    }

    /// The trees besides the selected one, where they stand.
    pub fn other_trees(&self) -> Vec<OtherTree<'_>> {
        let Some(stand) = &self.garden.stand else {
            return Vec::new();
        };
        stand
            .members
            .iter()
            .zip(&stand.garden.trees)
            .enumerate()
            .filter(|(i, _)| *i != self.garden.selected)
            .map(|(_, (m, t))| OtherTree {
                id: m.id,
                revision: m.revision,
                world_from_tree: m.world_from_tree,
                tree: &t.tree,
            })
            .collect()
    }

    /// The garden as it stands, the selected tree as it is now (None for a single tree), and
    /// where each tree stands in the world.
    pub fn garden_now(&self) -> Option<(Garden, Vec<Affine3A>)> {
        let stand = self.garden.stand.as_ref()?;
        let mut garden = stand.garden.clone();
        garden.trees[self.garden.selected].tree = self.tree.clone();
        let mut placed: Vec<Affine3A> = stand.members.iter().map(|m| m.world_from_tree).collect();
        if let Some(m) = self.world_from_tree {
            placed[self.garden.selected] = m;
        }
        Some((garden, placed))
    }

    /// SHA-256 of the garden's file (the selected tree as it is now); None for a single tree.
    pub fn garden_sha256(&self) -> Option<String> {
        use sha2::Digest;
        let (garden, _) = self.garden_now()?;
        Some(format!(
            "{:x}",
            sha2::Sha256::digest(garden.to_json_bytes())
        ))
    }

    /// "Plant another tree": the next tap on the ground plants a tree of `species` (an unknown
    /// name: the default species).
    pub(super) fn arm_planting(&mut self, species: &str) {
        self.garden.planting = Some(species_named(species).name);
        self.garden.planting_touch = None;
    }

    /// While planting is armed (and the first tree stands), a tap plants another tree; every
    /// touch is taken. False when the touch goes on to the tree as usual.
    pub(super) fn planting_touch(&mut self, phase: TouchPhase, id: u64, pixel: Vec2) -> bool {
        if self.garden.planting.is_none() || !self.is_planted() {
            return false;
        }
        match phase {
            TouchPhase::Start => {
                if self.garden.planting_touch.is_none() {
                    self.garden.planting_touch = Some((id, pixel, self.time_s));
                }
            }
            TouchPhase::Move => {}
            TouchPhase::End => {
                if let Some((start_id, start, t)) = self.garden.planting_touch.take()
                    && start_id == id
                    && start.distance(pixel) <= TAP_SLOP_PX
                    && self.time_s - t < HOLD_S
                {
                    self.plant_another_at(pixel);
                }
            }
        }
        true
    }

    /// Plants a sapling of the armed species where the ray through `pixel` meets the ground,
    /// grown to the garden's age against the trees standing, and selects it (undoable).
    fn plant_another_at(&mut self, pixel: Vec2) -> bool {
        let (Some(camera), Some(ground), Some(species)) =
            (self.world_camera, self.ground, self.garden.planting.clone())
        else {
            return false;
        };
        let Some(point) = ground_point_at_pixel(&camera, &ground, pixel) else {
            return false;
        };
        let Some(first_placed) = self.world_from_tree else {
            return false;
        };
        self.push_garden_step();
        if self.garden.stand.is_none() {
            let mut garden = Garden::empty();
            garden.years = self.params.years;
            let added = garden.add_tree(0.0, 0.0, 0.0, self.seed, self.tree.clone());
            if added.is_err() {
                self.drop_garden_step();
                return false;
            }
            let (id, revision) = (self.garden.next_id, self.garden.revision());
            self.garden.next_id += 1;
            self.garden.garden_from_world = first_placed.inverse();
            self.garden.selected = 0;
            self.garden.stand = Some(Stand {
                garden,
                members: vec![GardenMember {
                    id,
                    revision,
                    world_from_tree: first_placed,
                }],
            });
        } else {
            self.check_in();
        }
        let world_from_new =
            world_from_tree_at(point, &ground, self.tree_scale.metres_per_unit() as f32);
        let in_garden = self
            .garden
            .garden_from_world
            .transform_point3(world_from_new.transform_point3(Vec3::ZERO));
        let id = self.garden.next_id;
        let seed = self.seed.wrapping_add(id);
        let species = species_named(&species);
        let target = species.iterations_for_years(self.params.years.max(0.0));
        let tree = planted(species, seed);
        let revision = self.garden.revision();
        let scene_mode = self.params.scene_mode;
        let Some(stand) = self.garden.stand.as_mut() else {
            return false;
        };
        let Ok(index) = stand
            .garden
            .add_tree(in_garden.x, in_garden.z, 0.0, seed, tree)
        else {
            // On another trunk: nothing planted.
            self.undo_garden_step();
            return false;
        };
        let scene = growth_scene(scene_mode, &self.occupancy, Some(world_from_new));
        let scene = scene.as_ref().map(|(s, m)| (s as &dyn Scene, *m));
        stand.garden.edit_tree(index, |t| {
            while t.iteration < target {
                t.grow(1, scene);
            }
        });
        stand.members.push(GardenMember {
            id,
            revision,
            world_from_tree: world_from_new,
        });
        self.garden.next_id += 1;
        self.garden.kept.clear();
        self.garden.planting = None;
        self.check_out(index);
        true
    }

    /// Selects tree `index` (undoable): the tree selected before is put back into the garden.
    pub(super) fn select_tree(&mut self, index: usize) {
        let Some(stand) = &self.garden.stand else {
            return;
        };
        if index >= stand.members.len() || index == self.garden.selected {
            return;
        }
        self.push_garden_step();
        self.check_in();
        self.check_out(index);
    }

    /// Deletes the selected tree (undoable) when the garden holds another; the next one (or
    /// the last) is selected.
    pub(super) fn delete_selected_tree(&mut self) {
        if self
            .garden
            .stand
            .as_ref()
            .is_none_or(|s| s.members.len() < 2)
        {
            return;
        }
        self.push_garden_step();
        let selected = self.garden.selected;
        let Some(stand) = self.garden.stand.as_mut() else {
            return;
        };
        // The garden holds the tree as last put back, and its neighbours' shade that one's.
        stand.garden.remove_tree(selected);
        stand.members.remove(selected);
        let next = selected.min(stand.members.len() - 1);
        self.garden.kept.clear();
        self.check_out(next);
    }

    /// A tap on another tree selects it (the nearest node within the pick radius, when no node
    /// of the selected tree is nearer). True when it did.
    pub(super) fn garden_tap(&mut self, pixel: Vec2) -> bool {
        let (Some(stand), Some(camera)) = (&self.garden.stand, self.world_camera) else {
            return false;
        };
        let nearest = |tree: &Tree, world_from_tree: &Affine3A| {
            tree.skeleton
                .internodes
                .iter()
                .filter_map(|n| {
                    let mid = world_from_tree.transform_point3(0.5 * (n.start + n.end));
                    camera.pixel_from_world(mid).map(|p| p.distance(pixel))
                })
                .fold(f32::INFINITY, f32::min)
        };
        let own = self
            .world_from_tree
            .map_or(f32::INFINITY, |m| nearest(&self.tree, &m));
        let best = stand
            .members
            .iter()
            .zip(&stand.garden.trees)
            .enumerate()
            .filter(|(i, _)| *i != self.garden.selected)
            .map(|(i, (m, t))| (i, nearest(&t.tree, &m.world_from_tree)))
            .filter(|(_, d)| *d <= PICK_RADIUS_PX && *d < own)
            .min_by(|a, b| a.1.total_cmp(&b.1));
        match best {
            Some((i, _)) => {
                self.select_tree(i);
                true
            }
            None => false,
        }
    }

    /// New parameters for the whole garden, when that is what they are: the years slider alone
    /// (the garden grows or goes back), or choosing "prune to the scene" alone (every tree is
    /// cut back to the scene). False (nothing done) for a single tree or any other change.
    pub(super) fn garden_parameters(&mut self, parameters: &Parameters) -> bool {
        if self.garden.stand.is_none() {
            return false;
        }
        let mut same = parameters.clone();
        same.years = self.params.years;
        if same == self.params && parameters.years != self.params.years {
            if parameters.years.is_finite() {
                self.garden_to_age(parameters.years.max(0.0));
            }
            return true;
        }
        let mut same = parameters.clone();
        same.scene_mode = self.params.scene_mode;
        if same == self.params
            && parameters.scene_mode == SceneChoice::PruneToScene
            && self.params.scene_mode != SceneChoice::PruneToScene
        {
            self.prune_garden_to_scene(parameters);
            return true;
        }
        false
    }

    /// The years slider on a garden: every tree grows together to `years`, or the garden goes
    /// back to the state kept at or before it.
    fn garden_to_age(&mut self, years: f32) {
        self.push_garden_step();
        self.check_in();
        let Some(stand) = self.garden.stand.as_mut() else {
            return;
        };
        if years < stand.garden.years {
            let kept = self
                .garden
                .kept
                .iter()
                .rposition(|k| k.garden.years <= years);
            if let Some(k) = kept {
                *stand = (*self.garden.kept[k]).clone();
                self.garden.kept.truncate(k + 1);
            }
        } else {
            self.garden.kept.push(Arc::new(stand.clone()));
            let excess = self.garden.kept.len().saturating_sub(MAX_KEPT_AGES);
            self.garden.kept.drain(..excess);
        }
        let Some(stand) = self.garden.stand.as_mut() else {
            return;
        };
        if years > stand.garden.years {
            let scenes = scenes_of(self.params.scene_mode, &self.occupancy, &stand.members);
            stand
                .garden
                .grow_years_in(years - stand.garden.years, &scene_refs(&scenes));
            for m in &mut stand.members {
                self.garden.next_revision += 1;
                m.revision = self.garden.next_revision;
            }
        }
        self.params.years = years;
        self.check_out(self.garden.selected);
    }

    /// "Prune to the scene" on a garden: every tree cut back to the scene (undoable).
    fn prune_garden_to_scene(&mut self, parameters: &Parameters) {
        self.push_garden_step();
        self.check_in();
        self.params = parameters.clone();
        let Some(stand) = self.garden.stand.as_mut() else {
            return;
        };
        for (i, m) in stand.members.iter_mut().enumerate() {
            let Some(scene) = tree_scene(&self.occupancy, Some(m.world_from_tree)) else {
                continue;
            };
            let mut cut = 0;
            stand
                .garden
                .edit_tree(i, |t| cut = t.prune_to_scene(&scene));
            if cut > 0 {
                self.garden.next_revision += 1;
                m.revision = self.garden.next_revision;
            }
        }
        self.garden.kept.clear();
        self.check_out(self.garden.selected);
    }

    /// Where the garden's origin (its first tree's trunk base) stands in the world (None for a
    /// single tree).
    pub(crate) fn garden_origin_in_world(&self) -> Option<Vec3> {
        self.garden.stand.as_ref()?;
        Some(
            self.garden
                .garden_from_world
                .inverse()
                .transform_point3(Vec3::ZERO),
        )
    }

    /// A new design scale moved the world under the garden by `world_from_old` (a uniform scale
    /// about the garden's origin): every tree's placement follows, in the garden, its undo steps
    /// and its kept ages, so the garden keeps its layout in metres.
    pub(crate) fn rescale_garden(&mut self, world_from_old: &Affine3A) {
        let map = *world_from_old;
        let garden = &mut self.garden;
        if garden.stand.is_some() {
            garden.garden_from_world *= map.inverse();
        }
        let place = |stand: &mut Stand| {
            for m in &mut stand.members {
                m.world_from_tree = map * m.world_from_tree;
            }
        };
        // Kept stands are shared between the garden and its undo steps: moved once each.
        let mut moved: Vec<(*const Stand, Arc<Stand>)> = Vec::new();
        let mut place_kept = |kept: &mut Vec<Arc<Stand>>| {
            for k in kept.iter_mut() {
                let key = Arc::as_ptr(k);
                let new = match moved.iter().find(|(p, _)| *p == key) {
                    Some((_, new)) => new.clone(),
                    None => {
                        let mut stand = (**k).clone();
                        place(&mut stand);
                        let new = Arc::new(stand);
                        moved.push((key, new.clone()));
                        new
                    }
                };
                *k = new;
            }
        };
        if let Some(stand) = garden.stand.as_mut() {
            place(stand);
        }
        place_kept(&mut garden.kept);
        for step in &mut garden.undo {
            if let Some(stand) = step.stand.as_mut() {
                place(stand);
            }
            step.world_from_tree = step.world_from_tree.map(|m| map * m);
            place_kept(&mut step.kept);
        }
    }

    /// Garden steps undo can take back.
    pub(super) fn garden_undo_depth(&self) -> usize {
        self.garden.undo.len()
    }

    /// Undoes the last garden step when the selected tree has no edits of its own left to undo.
    pub(super) fn undo_garden_step_first(&mut self) -> bool {
        if self.history.num_undoable() > 0 || self.garden.undo.is_empty() {
            return false;
        }
        self.undo_garden_step()
    }

    fn undo_garden_step(&mut self) -> bool {
        let Some(step) = self.garden.undo.pop() else {
            return false;
        };
        self.garden.stand = step.stand;
        self.garden.selected = step.selected;
        self.garden.kept = step.kept;
        self.tree = step.tree;
        self.seed = step.seed;
        self.world_from_tree = step.world_from_tree;
        self.params = step.params;
        self.history = step.history;
        self.timeline = step.timeline;
        self.forget_gestures();
        self.update_tree_camera();
        self.changed();
        true
    }

    /// Keeps everything a garden step changes; the selected tree's undo steps go with it.
    fn push_garden_step(&mut self) {
        let history = std::mem::replace(
            &mut self.history,
            History::new(MAX_UNDO).with_budget(UNDO_BUDGET_TREES),
        );
        let timeline = std::mem::replace(
            &mut self.timeline,
            Timeline::with_budget(TIMELINE_BUDGET_TREES),
        );
        self.garden.undo.push(GardenStep {
            stand: self.garden.stand.clone(),
            selected: self.garden.selected,
            tree: self.tree.clone(),
            seed: self.seed,
            world_from_tree: self.world_from_tree,
            params: self.params.clone(),
            history,
            timeline,
            kept: self.garden.kept.clone(),
        });
        let excess = self.garden.undo.len().saturating_sub(MAX_GARDEN_UNDO);
        self.garden.undo.drain(..excess);
    }

    /// Takes back a step just pushed (the step did nothing).
    fn drop_garden_step(&mut self) {
        if let Some(step) = self.garden.undo.pop() {
            self.history = step.history;
            self.timeline = step.timeline;
        }
    }

    /// Puts the selected tree back into the garden (moved there if its trunk was dragged).
    fn check_in(&mut self) {
        let selected = self.garden.selected;
        let revision = self.garden.revision();
        let garden_from_world = self.garden.garden_from_world;
        let Some(stand) = self.garden.stand.as_mut() else {
            return;
        };
        let placed = self
            .world_from_tree
            .unwrap_or(stand.members[selected].world_from_tree);
        let at = garden_from_world.transform_point3(placed.transform_point3(Vec3::ZERO));
        let t = &stand.garden.trees[selected];
        let moved = Vec2::new(at.x - t.x_m, at.z - t.z_m).length() > 1e-4;
        let (planting_age, seed) = (t.planting_age_years, t.seed);
        stand.garden.replace_tree(selected, self.tree.clone());
        stand.members[selected].revision = revision;
        if moved && let Some(gone) = stand.garden.remove_tree(selected) {
            let member = stand.members.remove(selected);
            match stand
                .garden
                .add_tree(at.x, at.z, planting_age, seed, gone.tree.clone())
            {
                Ok(_) => stand.members.push(GardenMember {
                    world_from_tree: placed,
                    ..member
                }),
                // Dragged onto another trunk: it stays where it stood.
                Err(_) => {
                    let _ =
                        stand
                            .garden
                            .add_tree(gone.x_m, gone.z_m, planting_age, seed, gone.tree);
                    stand.members.push(member);
                }
            }
            self.garden.selected = stand.members.len() - 1;
        }
    }

    /// Makes tree `index` the selected one: readied against its neighbours and handed to the
    /// tools, with fresh undo steps (those before are in the garden step).
    fn check_out(&mut self, index: usize) {
        let Some(stand) = self.garden.stand.as_mut() else {
            return;
        };
        if index >= stand.members.len() {
            return;
        }
        stand.garden.prepare_edit(index);
        let t = &stand.garden.trees[index];
        self.tree = t.tree.clone();
        self.seed = t.seed;
        self.world_from_tree = Some(stand.members[index].world_from_tree);
        self.params = Parameters {
            brush_radius: self.params.brush_radius,
            grow_speed: self.params.grow_speed,
            scene_mode: self.params.scene_mode,
            season: self.params.season,
            sketch_tropism: self.params.sketch_tropism,
            years: stand.garden.years,
            ..Parameters::for_species(&t.tree.species)
        };
        self.garden.selected = index;
        self.history = History::new(MAX_UNDO).with_budget(UNDO_BUDGET_TREES);
        self.timeline = Timeline::with_budget(TIMELINE_BUDGET_TREES);
        self.timeline.keep(&self.tree);
        self.forget_gestures();
        self.update_tree_camera();
        self.changed();
    }

    /// Drops the gestures and picks that belonged to the tree edited before.
    fn forget_gestures(&mut self) {
        self.brush = None;
        self.bend = None;
        self.stroke = None;
        self.selected = None;
        self.touches.clear();
        self.moving_base = None;
        self.last_tap = None;
    }
}
