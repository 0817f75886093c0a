//! Gardens: several trees, each with its own species, seed, planting position and planting age,
//! growing together so that they compete for light and space (Longay 2014 ch. 6; Pałubicki et
//! al. 2009, competition through a shared shadow).
//!
//! Each tree keeps its own space (its base at its origin) and its own [`Tree`]; the garden places
//! it at `(x_m, 0, z_m)` in garden space (world metres, Y up, the ground at y = 0). Trees grow in
//! rounds, one iteration per round for the trees due (a species' iteration may be more or less
//! than a year; each tree spreads its iterations evenly over the rounds). Before every round each
//! tree's environment is brought up to date with its neighbours (module `competition`):
//!
//! - **shared shade**: the nodes of a neighbour cast their shadow pyramids into the tree's
//!   shadow grid, so a tall neighbour shades the buds below and beside it (integer sums, so the
//!   grid is the same whatever the order the pyramids arrive in); only near the tree's own
//!   nodes, where the grid is read (module `shade`), so the grid reads there exactly the shade
//!   of all of them;
//! - **space**: the neighbours' nodes within reach occupy space as the tree's own do
//!   ([`crate::environment::Environment::neighbour_nodes`]): no bud takes the space a
//!   neighbour's internodes hold;
//! - **neighbourhood asymmetry**: the pressure of the trees around (Longay 2014 eq. 6.3–6.5)
//!   tilts the tree's shoots away from its neighbours while it is young
//!   ([`crate::environment::Environment::neighbour_tropism`]).
//!
//! [`Garden::edit_tree`] edits one tree against its neighbours as they stand; the others do not
//! change, only their environments take in the edited tree's new nodes.
//!
//! Within a round the trees grow in parallel (rayon); each reads only its own environment, made
//! before the round, so the garden is the same whatever the number of threads. A garden of one
//! tree grows exactly that tree.

mod cache;
mod cell_hash;
mod competition;
mod index;
mod io;
mod members;
mod planting;
mod shade;
mod stats;

pub use io::{GARDEN_FORMAT_VERSION, GardenFileError};
pub use planting::{
    Layout, MAX_GARDEN_TREES, MAX_PLANTING_EXTENT_M, MIN_TREE_SPACING_M, PlantedTree, Planting,
    PlantingFile, stand_positions,
};
pub use stats::{CrownStats, RIPLEY_RADIUS_M, ripley_excess};

use glam::Vec3;
use rayon::prelude::*;
use serde::{Deserialize, Serialize};

use crate::Tree;
use crate::environment::{Scene, SceneMode};
use crate::species::Species;

/// The oldest a tree may be planted or a garden grown, years (a damaged file or a typo beyond).
pub const MAX_GARDEN_YEARS: f32 = 500.0;

/// One tree of a garden: where it stands, how old it was planted, and the tree itself.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct GardenTree {
    /// Position of the trunk base on the ground, garden metres.
    pub x_m: f32,
    pub z_m: f32,
    /// Age when planted: the tree grew this long alone (in the nursery) before the garden.
    pub planting_age_years: f32,
    pub seed: u64,
    pub tree: Tree,
    /// The trees (indices) whose nodes reach this one's environment: once a neighbour's crown
    /// comes within reach it stays linked (see module `competition`).
    #[serde(default)]
    pub neighbours: Vec<u32>,
    /// Where its shadow grid holds the neighbours' shade (derived, never saved).
    #[serde(skip)]
    pub(crate) shade_cover: shade::ShadeCover,
    /// Its nodes by coarse cells of garden space (derived, never saved).
    #[serde(skip)]
    pub(crate) node_index: index::NodeIndex,
    /// Its version and what edits reuse (derived, never saved; module `cache`).
    #[serde(skip)]
    pub(crate) cache: cache::EditCache,
}

impl GardenTree {
    /// The trunk base in garden space.
    pub fn base(&self) -> Vec3 {
        Vec3::new(self.x_m, 0.0, self.z_m)
    }
}

/// Trees growing together in one environment.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Garden {
    pub trees: Vec<GardenTree>,
    /// Years grown together since planting.
    pub years: f32,
    /// Whether the trees compete (shade and space). Off, each grows as if alone: the reference
    /// the competition is measured against.
    pub competition: bool,
}

/// Why a garden could not be planted.
#[derive(Debug, thiserror::Error)]
pub enum GardenError {
    #[error("planting {entry}: {reason}")]
    Planting { entry: String, reason: String },
}

impl Garden {
    /// Plants `trees` (checked: see [`planting::check_trees`]): each grows alone to its planting
    /// age, in parallel.
    pub fn plant(trees: Vec<PlantedTree>) -> Result<Garden, GardenError> {
        planting::check_trees(&trees)?;
        let trees = trees
            .into_par_iter()
            .map(|p| {
                let mut tree = Tree::new(p.species, p.seed);
                tree.grow_years(p.age_years);
                GardenTree {
                    x_m: p.x_m,
                    z_m: p.z_m,
                    planting_age_years: p.age_years,
                    seed: p.seed,
                    tree,
                    neighbours: Vec::new(),
                    shade_cover: shade::ShadeCover::default(),
                    node_index: index::NodeIndex::default(),
                    cache: cache::EditCache::default(),
                }
            })
            .collect();
        Ok(Garden {
            trees,
            years: 0.0,
            competition: true,
        })
    }

    /// Grows every tree `years` more years together (each to its planting age plus the
    /// garden's years, rounded to whole iterations of its species).
    pub fn grow_years(&mut self, years: f32) {
        self.grow_years_in(years, &[]);
    }

    /// [`Garden::grow_years`], each tree growing against its scene (`scenes[i]`, in tree i's
    /// own space, with how it shapes growth; none past the slice's end): a design's trees
    /// standing in a tracked scene.
    pub fn grow_years_in(&mut self, years: f32, scenes: &[Option<(&dyn Scene, SceneMode)>]) {
        let years = years.clamp(0.0, MAX_GARDEN_YEARS);
        let steps: Vec<u32> = self
            .trees
            .iter()
            .map(|t| {
                let age = t.planting_age_years + self.years + years;
                t.tree
                    .species
                    .iterations_for_years(age)
                    .saturating_sub(t.tree.iteration)
            })
            .collect();
        let rounds = steps.iter().copied().max().unwrap_or(0);
        for round in 0..rounds {
            let due: Vec<bool> = steps
                .iter()
                .map(|&n| {
                    let (k, n, r) = (u64::from(round), u64::from(n), u64::from(rounds));
                    (k + 1) * n / r > k * n / r
                })
                .collect();
            self.grow_round(&due, scenes);
        }
        self.years += years;
    }

    /// One round: the neighbours brought into each tree's environment, then one iteration of
    /// every tree that is `due`, then the shade of what grew and what was shed handed on.
    fn grow_round(&mut self, due: &[bool], scenes: &[Option<(&dyn Scene, SceneMode)>]) {
        if !self.competition {
            self.step_due(due, scenes);
            return;
        }
        competition::link_neighbours(self);
        // The neighbours' nodes are found through their indexes (an edited tree's is made
        // anew here, not at every edit: edits never ask for it).
        competition::index_nodes(self, &vec![false; self.trees.len()]);
        competition::gather_neighbour_nodes(self, due);
        competition::set_neighbour_tropisms(self, due);
        let before: Vec<Option<(Vec<Vec3>, u32)>> = self
            .trees
            .par_iter()
            .zip(due)
            .map(|(t, &d)| d.then(|| (competition::node_ends(t), t.tree.iteration)))
            .collect();
        self.step_due(due, scenes);
        let changes: Vec<Option<competition::NodeChanges>> = self
            .trees
            .par_iter()
            .zip(before)
            .map(|(t, before)| before.map(|(b, k)| competition::NodeChanges::of(t, &b, k)))
            .collect();
        competition::index_nodes(self, due);
        competition::hand_on_shade(self, &changes);
    }

    /// One autonomous iteration of every tree that is `due`, in parallel.
    fn step_due(&mut self, due: &[bool], scenes: &[Option<(&dyn Scene, SceneMode)>]) {
        self.trees
            .par_iter_mut()
            .zip(due)
            .enumerate()
            .filter(|(_, (_, d))| **d)
            .for_each(|(i, (t, _))| {
                t.tree.grow(1, scenes.get(i).copied().flatten());
                t.cache.changed();
            });
    }

    /// Edits tree `index` (a brush stroke, a prune, a bend, new parameters, more years: whatever
    /// `edit` does to it) against its neighbours as they stand, then hands the change of its
    /// nodes on to the shade of the trees it reaches. No other tree grows or changes; only their
    /// environments follow. Returns false (and does nothing) for an index past the trees.
    pub fn edit_tree(&mut self, index: usize, edit: impl FnOnce(&mut Tree)) -> bool {
        if index >= self.trees.len() {
            return false;
        }
        if !self.competition {
            edit(&mut self.trees[index].tree);
            return true;
        }
        let mut due = vec![false; self.trees.len()];
        due[index] = true;
        competition::link_neighbours(self);
        competition::give_all_neighbour_nodes(self, index);
        competition::set_neighbour_tropisms(self, &due);
        // The edit may grow anywhere: from now on the tree's grid holds all its linked
        // neighbours' shade (cast once, at its first edit; see module `shade`).
        competition::set_shade_everywhere(self, index);
        let before = competition::node_ends(&self.trees[index]);
        let before_iteration = self.trees[index].tree.iteration;
        edit(&mut self.trees[index].tree);
        self.trees[index].cache.changed();
        let mut changes: Vec<Option<competition::NodeChanges>> =
            (0..self.trees.len()).map(|_| None).collect();
        changes[index] = Some(competition::NodeChanges::of(
            &self.trees[index],
            &before,
            before_iteration,
        ));
        // Its grid takes every neighbour's shade already, so handing on asks no index: its
        // own is made anew at the next round.
        self.trees[index].node_index = index::NodeIndex::default();
        competition::hand_on_shade(self, &changes);
        true
    }

    /// The trees' environments as they were grown: each tree's own shade (rebuilt on load)
    /// plus that of its linked neighbours. Call after loading or changing trees by hand.
    pub fn rebuild_environment(&mut self) {
        competition::rebuild_shade(self);
    }

    /// The meshes of every tree (its species' summer look, in its own space), built in
    /// parallel: what [`crate::export::write_garden_glb`] places.
    pub fn tree_meshes(&self) -> Vec<crate::geometry::TreeMeshes> {
        self.trees
            .par_iter()
            .map(|t| crate::geometry::build_tree_meshes(&t.tree))
            .collect()
    }

    /// Total internodes of all trees.
    pub fn num_internodes(&self) -> usize {
        self.trees.iter().map(|t| t.tree.skeleton.len()).sum()
    }

    /// The crown of each tree in garden space (see [`CrownStats`]).
    pub fn crowns(&self) -> Vec<CrownStats> {
        self.trees.iter().map(CrownStats::of).collect()
    }

    /// The mean horizontal distance from each trunk base to its crown's centroid, metres.
    pub fn mean_crown_offset_m(&self) -> f32 {
        let crowns = self.crowns();
        if crowns.is_empty() {
            return 0.0;
        }
        crowns.iter().map(|c| c.offset().length()).sum::<f32>() / crowns.len() as f32
    }
}

/// Threads the garden's trees grow on (rayon's pool: `RAYON_NUM_THREADS`, else one per core).
pub fn num_threads() -> usize {
    rayon::current_num_threads()
}

/// A tree to plant: species, position on the ground (garden metres), planting age and seed.
impl PlantedTree {
    pub fn new(species: Species, x_m: f32, z_m: f32, age_years: f32, seed: u64) -> PlantedTree {
        PlantedTree {
            species,
            x_m,
            z_m,
            age_years,
            seed,
            entry: String::new(),
        }
    }
}
