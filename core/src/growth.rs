//! Self-organizing growth (Pałubicki et al. 2009; Longay 2014 ch. 4), one iteration (one season)
//! at a time, step by step in the thesis' order:
//!
//! 1. light: bud exposure L = max(C − s + a, 0) from the shadow grid (module `light`);
//! 2. competition for space: attraction points, occupancy spheres, perception cones (module `space`);
//! 3. bud input Q = b·L^κ with gravimorphism b (module `light`);
//! 4. vigor: extended Borchert–Honda, basipetal then acropetal (module `vigor`);
//! 5. and 6. shoots of n = ⌊v/v_max·n_max⌋ internodes heading H' = αH + βT + γE (module `shoots`);
//! 7. shedding of branches whose vigor per internode falls below Th (module `vigor`);
//! 8. widths by the pipe model, exponents re-solved below width constraints (module `widths`).
//!
//! Space: world metres, Y up, base at the origin. The ground is the plane y = 0 through the base:
//! attraction points below it are dropped and no shoot grows into it. All randomness comes from
//! `Tree::rng`, so the same species, seed and calls give a byte-identical saved tree.

mod buds;
mod io;
mod light;
mod parallel;
mod shoots;
pub(crate) mod snapshot;
mod space;
pub mod timing;
mod vigor;
mod widths;

pub use io::{TREE_FORMAT_VERSION, TreeFileError, TreeFileFormat};
pub use widths::solve_pipe_exponent;

use glam::Vec3;
use serde::{Deserialize, Serialize};

use crate::environment::{Environment, Scene, SceneMode, ShadowGrid};
use crate::rng::Rng;
use crate::species::Species;
use crate::tree::{Bud, Children, Internode, LateralBuds, NodeId, Skeleton, TreeInvariantError};

/// A growing tree: skeleton, species, environment and the generator that drives it.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct Tree {
    pub species: Species,
    /// Growth iterations done so far (0 = the seedling).
    pub iteration: u32,
    pub skeleton: Skeleton,
    pub environment: Environment,
    /// Selective growth: when set, only buds in the subtree rooted here may grow (all buds still
    /// consume attraction points in their occupancy spheres).
    pub growth_mask: Option<NodeId>,
    pub rng: Rng,
    /// Pipe-model exponent of each internode's subtree (derived, see [`Tree::update_widths`]).
    #[serde(skip)]
    pipe_exponents: Vec<f32>,
    #[serde(skip)]
    scratch: Box<Scratch>,
}

/// How one iteration runs.
#[derive(Clone, Copy, Default)]
pub struct StepOptions<'a> {
    /// Every bud generates attraction points in its perception volume (autonomous growth), and
    /// shedding runs. Off for brush-guided iterations: only the persistent points feed buds.
    pub autonomous: bool,
    pub scene: Option<(&'a dyn Scene, SceneMode)>,
}

/// What one iteration did.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct IterationStats {
    pub num_buds: usize,
    pub num_enabled_buds: usize,
    pub num_points: usize,
    pub num_shoots: usize,
    pub num_new_internodes: usize,
    pub num_shed_internodes: usize,
    pub num_pruned_internodes: usize,
}

impl IterationStats {
    /// Adds one more iteration's figures to these totals: counts add up, and `num_buds` is the
    /// latest iteration's (the buds standing now).
    pub fn accumulate(&mut self, s: IterationStats) {
        self.num_buds = s.num_buds;
        self.num_enabled_buds += s.num_enabled_buds;
        self.num_points += s.num_points;
        self.num_shoots += s.num_shoots;
        self.num_new_internodes += s.num_new_internodes;
        self.num_shed_internodes += s.num_shed_internodes;
        self.num_pruned_internodes += s.num_pruned_internodes;
    }
}

/// Summary figures of a tree.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct TreeMetrics {
    pub num_internodes: usize,
    pub height_m: f32,
    /// Mean of the crown's extents along X and Z (the horticultural spread).
    pub crown_width_m: f32,
    /// Diameter at the base of the trunk.
    pub trunk_diameter_m: f32,
    pub age_years: f32,
    /// How far the tree leans: the horizontal distance from the base to the centre of the wood
    /// (internode midpoints weighted by length), over the height (0 for an upright tree).
    pub lean: f32,
}

/// Per-iteration working memory, kept between iterations so the hot loops do not allocate.
/// Cloning a tree (undo history, what-if previews) does not copy it: a clone starts empty.
#[derive(Debug, Default)]
pub(crate) struct Scratch {
    pub buds: Vec<buds::BudState>,
    /// The attraction points each bud won, by bud.
    pub won: Vec<buds::WonPoints>,
    /// Buds of node i are `buds[node_bud_start[i]..node_bud_start[i + 1]]`, terminal first.
    pub node_bud_start: Vec<u32>,
    pub positions: Vec<Vec3>,
    /// The end of every internode, in arena order, taken by [`buds::collect`] (the arena does
    /// not change until the shoots grow).
    pub node_end: Vec<Vec3>,
    pub bud_grid: crate::environment::SpatialGrid,
    pub node_grid: crate::environment::SpatialGrid,
    pub point_grid: crate::environment::SpatialGrid,
    pub point_alive: Vec<bool>,
    /// Runs of `point_grid`'s cells, the blocks of the parallel passes ([`parallel`]).
    pub point_runs: Vec<std::ops::Range<usize>>,
    /// Whether each point survived occupancy, and its winner, by slot of `point_grid` (the
    /// parallel passes' results before they go to `point_alive` and `point_winner`).
    pub slot_alive: Vec<bool>,
    pub slot_winner: Vec<(u32, Vec3)>,
    /// Competing nodes near one cell of attraction points (colonization).
    pub candidates: crate::environment::Candidates,
    /// The bud each attraction point feeds and the unit vector from it to the point
    /// (colonization).
    pub point_winner: Vec<(u32, Vec3)>,
    /// The competing buds of entry i of `bud_grid` (a node; entries are numbered by slot, see
    /// [`crate::environment::SpatialGrid::number_entries_by_slot`]) are
    /// `competing_buds[competing_start[i]..competing_start[i + 1]]`, as (index in `buds`,
    /// direction), in bud order: compact, for the hot perception loop.
    pub competing_start: Vec<u32>,
    pub competing_buds: Vec<(u32, Vec3)>,
    /// The same in `bud_grid`'s slot order, built from them (then swapped in).
    pub sorted_start: Vec<u32>,
    pub sorted_buds: Vec<(u32, Vec3)>,
    pub q_main: Vec<f32>,
    pub q_lateral: Vec<f32>,
    pub vigor: Vec<f32>,
    pub size: Vec<u32>,
    pub in_mask: Vec<bool>,
    pub acc: Vec<f64>,
    /// What `acc` holds the sums of, when they describe the arena ([`widths`]).
    pub widths_of: Option<widths::WidthsOf>,
    pub subtree_root: Vec<u32>,
    /// The arena's links as bud collection reads them, compact for the passes that follow
    /// before the arena changes (both vigor passes, shedding): main child of node i
    /// ([`NO_NODE`] for none) and its lateral children
    /// `lateral[lateral_range[i].0..lateral_range[i].1]` in order.
    pub main_child: Vec<u32>,
    pub lateral_range: Vec<(u32, u32)>,
    pub lateral: Vec<u32>,
    /// Nodes on the paths from the enabled buds to the base, and a flag per node ([`vigor`]'s
    /// pass along those paths).
    pub on_path: Vec<bool>,
    pub path_nodes: Vec<u32>,
    /// Every node born before this iteration had all its lateral buds dead at the start of
    /// iteration `expired_at` ([`buds::collect`] kills them once they outlive the bud lifetime).
    pub expired_below: u32,
    pub expired_at: Option<u32>,
    /// What the last bud collection computed the nodes' light exposures from
    /// ([`buds::collect`] keeps those whose shadow cannot have changed since).
    pub light_seen: Option<buds::LightSeen>,
    /// The autonomous points of each block of buds, and the generator's draws before each
    /// block (the parallel point generation, [`space`]).
    pub point_blocks: Vec<Vec<crate::environment::AttractionPoint>>,
    pub point_block_draws: Vec<u64>,
    /// Living buds and lateral children of each block of nodes ([`buds::collect`]).
    pub bud_blocks: Vec<buds::BudBlock>,
}

/// No part of a tree lies further than this from its base (metres): beyond any real tree, a
/// file that says otherwise is damaged.
pub const MAX_TREE_EXTENT_M: f32 = 1000.0;

/// The widest diameter a width constraint may ask for, metres (wider than any trunk).
pub const MAX_WIDTH_CONSTRAINT_M: f32 = 10.0;

/// Whether `diameter_m` is a diameter a width constraint may ask for: in (0,
/// [`MAX_WIDTH_CONSTRAINT_M`]] metres.
pub fn is_width_constraint(diameter_m: f32) -> bool {
    diameter_m.is_finite() && diameter_m > 0.0 && diameter_m <= MAX_WIDTH_CONSTRAINT_M
}

/// Growth iterations a tree may have done (a thousand years at the shortest season a species
/// may have): more means a damaged file.
pub const MAX_ITERATIONS: u32 = 100_000;

/// No node, in [`Scratch`]'s compact links.
pub(crate) const NO_NODE: u32 = u32::MAX;

impl Clone for Scratch {
    fn clone(&self) -> Self {
        Scratch::default()
    }
}

impl Tree {
    /// A seedling of `species`: one upright internode with its buds; randomness from `seed`.
    pub fn new(species: Species, seed: u64) -> Tree {
        let mut tree = Tree {
            environment: Environment::default(),
            skeleton: Skeleton {
                internodes: Vec::new(),
            },
            iteration: 0,
            growth_mask: None,
            rng: Rng::new(seed),
            pipe_exponents: Vec::new(),
            scratch: Box::default(),
            species,
        };
        tree.environment.shadow = tree.empty_shadow_grid();
        let l = tree.species.internode_length_m;
        let mut seedling = Internode {
            parent: None,
            main_child: None,
            lateral_children: Children::new(),
            start: Vec3::ZERO,
            end: Vec3::Y * l,
            left: Vec3::X,
            diameter: tree.species.tip_diameter_m,
            order: 0,
            born_iteration: 0,
            terminal_bud: Some(Bud::new(Vec3::Y)),
            lateral_buds: LateralBuds::new(),
            width_constraint: None,
            light_exposure: tree.species.full_exposure,
        };
        let azimuth = tree.rng.range_f32(0.0, std::f32::consts::TAU);
        buds::LateralBudPlacement::of(&tree.species).add_to(&mut seedling, azimuth);
        tree.environment.shadow.apply_node(seedling.end, 1);
        tree.skeleton.internodes.push(seedling);
        tree.update_widths();
        tree
    }

    fn empty_shadow_grid(&self) -> ShadowGrid {
        let s = &self.species;
        ShadowGrid::new(
            s.internode_length_m * s.shadow_voxel_internodes,
            s.shadow_strength,
            s.shadow_decay_base,
            s.shadow_depth_voxels,
        )
    }

    /// Recomputes the shadow grid from the skeleton (after loading or editing positions).
    pub fn rebuild_shadow(&mut self) {
        let mut grid = self.empty_shadow_grid();
        for node in &self.skeleton.internodes {
            grid.apply_node(node.end, 1);
        }
        self.environment.shadow = grid;
    }

    /// Grows `iterations` autonomous iterations, optionally against a scene.
    pub fn grow(
        &mut self,
        iterations: u32,
        scene: Option<(&dyn Scene, SceneMode)>,
    ) -> IterationStats {
        let mut total = IterationStats::default();
        for _ in 0..iterations {
            total.accumulate(self.step(StepOptions {
                autonomous: true,
                scene,
            }));
        }
        total
    }

    /// Grows autonomously for `years` more years (rounded to whole iterations).
    pub fn grow_years(&mut self, years: f32) -> IterationStats {
        let iterations = self.species.iterations_for_years(years);
        self.grow(iterations, None)
    }

    /// The metrics of a tree of `species` grown from `seed`, at each age of `ages_years` (in
    /// increasing order; one tree grows through all of them).
    pub fn metrics_at_ages(species: &Species, seed: u64, ages_years: &[f32]) -> Vec<TreeMetrics> {
        let mut tree = Tree::new(species.clone(), seed);
        ages_years
            .iter()
            .map(|&age| {
                tree.grow_years((age - tree.age_years()).max(0.0));
                tree.metrics()
            })
            .collect()
    }

    /// Height of the ground the tree stands on (see [`Skeleton::ground_y`]).
    pub fn ground_y(&self) -> f32 {
        self.skeleton.ground_y()
    }

    /// Age in years.
    pub fn age_years(&self) -> f32 {
        self.iteration as f32 * self.species.years_per_iteration
    }

    /// One growth iteration (steps 1–8 of the module doc).
    pub fn step(&mut self, options: StepOptions) -> IterationStats {
        self.iteration += 1;
        let mut stats = IterationStats::default();
        let mut scratch = std::mem::take(&mut self.scratch);
        let mut clock = timing::PhaseClock::start();
        buds::collect(self, &mut scratch);
        clock.lap(timing::Phase::Collect);
        stats.num_points = space::colonize(self, &mut scratch, options, &mut clock);
        clock.lap(timing::Phase::Space);
        stats.num_enabled_buds = light::bud_input(self, &mut scratch);
        clock.lap(timing::Phase::BudInput);
        let v_max = vigor::distribute(self, &mut scratch, options.autonomous);
        stats.num_buds = scratch.buds.len();
        let shed = if options.autonomous && v_max > 0.0 {
            vigor::select_shed(self, &mut scratch, v_max)
        } else {
            Vec::new()
        };
        let removed = subtree_flags(&scratch, &shed);
        clock.lap(timing::Phase::Vigor);
        let num_before = self.skeleton.len();
        let grown = shoots::grow_all(self, &mut scratch, v_max, &removed, options.scene);
        stats.num_shoots = grown.0;
        stats.num_new_internodes = grown.1;
        clock.lap(timing::Phase::Shoots);
        if !shed.is_empty() {
            // The shoots grew only from kept nodes: the new ones stay.
            let mut removed = removed;
            removed.resize(self.skeleton.len(), false);
            stats.num_shed_internodes = self.remove_flagged_subtrees(&removed);
        }
        if let Some((scene, SceneMode::PruneToScene)) = options.scene {
            stats.num_pruned_internodes = self.prune_to_scene(scene);
        }
        clock.lap(timing::Phase::Shed);
        space::finish_iteration(self, &scratch);
        clock.lap(timing::Phase::Finish);
        // When internodes were only added, the widths change along their paths to the base.
        let only_added = stats.num_shed_internodes == 0 && stats.num_pruned_internodes == 0;
        if !(only_added
            && widths::update_after_growth(
                &mut self.skeleton,
                self.species.tip_diameter_m,
                self.species.pipe_exponent,
                &mut self.pipe_exponents,
                &mut scratch,
                num_before,
            ))
        {
            self.scratch = scratch;
            self.update_widths();
        } else {
            self.scratch = scratch;
        }
        clock.lap(timing::Phase::Widths);
        stats
    }

    /// Removes the subtrees rooted at `roots` (with their shadow), keeping the arena topological.
    /// The growth mask follows the renumbering (and is cleared if its root is removed).
    /// Returns how many internodes were removed.
    pub fn remove_subtrees(&mut self, roots: &[NodeId]) -> usize {
        let flags = self.skeleton.subtree_flags(roots);
        self.remove_flagged_subtrees(&flags)
    }

    /// [`Tree::remove_subtrees`] given the flags of every internode to remove (closed under
    /// descendants, one per internode). The compaction of the arena hands over the removed
    /// internodes, whose shadow is then taken away (integer sums: the order does not matter).
    fn remove_flagged_subtrees(&mut self, flags: &[bool]) -> usize {
        if !flags.iter().any(|&gone| gone) {
            return 0;
        }
        let mut gone_ends = Vec::new();
        let remap = self
            .skeleton
            .remove_closed_flags(flags, |node| gone_ends.push(node.end));
        self.environment
            .shadow
            .apply_nodes(gone_ends.iter().copied(), -1);
        self.growth_mask = self
            .growth_mask
            .and_then(|m| remap.get(m.index()).copied().flatten());
        gone_ends.len()
    }

    /// Cuts every internode that entered occupied space, with its subtree. Returns the count.
    pub fn prune_to_scene(&mut self, scene: &dyn Scene) -> usize {
        let cut: Vec<NodeId> = (0..self.skeleton.len())
            .filter(|&i| {
                let n = &self.skeleton.internodes[i];
                !scene.is_free(n.start) || !scene.is_segment_free(n.start, n.end)
            })
            .map(|i| NodeId(i as u32))
            .collect();
        let count = self.remove_subtrees(&cut);
        if count > 0 {
            self.update_widths();
        }
        count
    }

    /// Sets every internode's `light_exposure` from the current shadow grid. Growth keeps it
    /// current only for internodes with living buds (and new ones); call this before reading it
    /// on a whole tree.
    pub fn update_light_exposure(&mut self) {
        let s = &self.species;
        let shadow = &self.environment.shadow;
        for node in &mut self.skeleton.internodes {
            node.light_exposure =
                (s.full_exposure - shadow.shadow_at(node.end) + s.shadow_strength).max(0.0);
        }
    }

    /// Ambient light at a point in [0, 1] from the shadow grid: 1 unshaded, 0 in full shade.
    pub fn ambient_at(&self, point_in_world: Vec3) -> f32 {
        let s = &self.species;
        let exposure =
            s.full_exposure - self.environment.shadow.shadow_at(point_in_world) + s.shadow_strength;
        (exposure / s.full_exposure).clamp(0.0, 1.0)
    }

    /// Recomputes every diameter by the pipe model (module `widths`); call after edits. Growth
    /// keeps the pipe-model sums of this update and, after an iteration that only added
    /// internodes, recomputes only their paths: an edit that changes links or width
    /// constraints outside growth must call this (the `edit` module's do).
    pub fn update_widths(&mut self) {
        let mut scratch = std::mem::take(&mut self.scratch);
        widths::update(
            &mut self.skeleton,
            self.species.tip_diameter_m,
            self.species.pipe_exponent,
            &mut self.pipe_exponents,
            &mut scratch,
        );
        self.scratch = scratch;
    }

    /// Pipe-model exponent n used at internode `id` (d^n = Σ children d_i^n).
    pub fn pipe_exponent(&self, id: NodeId) -> f32 {
        self.pipe_exponents
            .get(id.index())
            .copied()
            .unwrap_or(self.species.pipe_exponent)
    }

    /// Arena invariants plus the growth state's own (finite values, mask in range).
    pub fn sanity_check(&self) -> Result<(), TreeInvariantError> {
        self.skeleton.sanity_check()?;
        if self.iteration > MAX_ITERATIONS {
            return Err(TreeInvariantError::Broken {
                index: 0,
                what: format!(
                    "the tree is at iteration {} (at most {MAX_ITERATIONS})",
                    self.iteration
                ),
            });
        }
        if let Some(m) = self.growth_mask
            && m.index() >= self.skeleton.len()
        {
            return Err(TreeInvariantError::Broken {
                index: m.index(),
                what: "growth mask points past the arena".into(),
            });
        }
        let base = self
            .skeleton
            .internodes
            .first()
            .map_or(Vec3::ZERO, |n| n.start);
        for (index, node) in self.skeleton.internodes.iter().enumerate() {
            let reach = node.start.distance(base).max(node.end.distance(base));
            if reach > MAX_TREE_EXTENT_M {
                return Err(TreeInvariantError::Broken {
                    index,
                    what: format!("lies {reach} m from the base (at most {MAX_TREE_EXTENT_M} m)"),
                });
            }
            let buds = node.terminal_bud.iter().chain(&node.lateral_buds);
            let unit = |v: Vec3| v.is_finite() && (v.length() - 1.0).abs() <= 1e-3;
            let bad_bud =
                |b: &Bud| !unit(b.direction) || b.tropism_override.is_some_and(|t| !unit(t));
            if buds.clone().any(bad_bud) || !node.light_exposure.is_finite() {
                return Err(TreeInvariantError::Broken {
                    index,
                    what: "a bud direction or tropism that is not a unit vector, or a non-finite light exposure".into(),
                });
            }
            if !unit(node.left) {
                return Err(TreeInvariantError::Broken {
                    index,
                    what: format!("L axis {} is not a unit vector", node.left),
                });
            }
            if let Some(d) = node.width_constraint
                && !is_width_constraint(d)
            {
                return Err(TreeInvariantError::Broken {
                    index,
                    what: format!(
                        "width constraint {d} is not a diameter in (0, {MAX_WIDTH_CONSTRAINT_M}] m"
                    ),
                });
            }
            if node.born_iteration > self.iteration {
                return Err(TreeInvariantError::Broken {
                    index,
                    what: format!(
                        "born at {} after iteration {}",
                        node.born_iteration, self.iteration
                    ),
                });
            }
        }
        Ok(())
    }

    /// The diameter of the trunk at `height_m` above its base: of the internode of the main axis
    /// (the root and its main children) that spans that height; `None` when the trunk does
    /// not reach it.
    pub fn trunk_diameter_at(&self, height_m: f32) -> Option<f32> {
        let skeleton = &self.skeleton;
        let mut node = skeleton.internodes.first()?;
        let top = node.start.y + height_m;
        loop {
            if node.end.y >= top {
                return Some(node.diameter);
            }
            node = skeleton.get(node.main_child?);
        }
    }

    /// Height, crown spread, trunk diameter, size and lean.
    pub fn metrics(&self) -> TreeMetrics {
        let nodes = &self.skeleton.internodes;
        let base = nodes.first().map_or(Vec3::ZERO, |n| n.start);
        let (mut lo, mut hi) = (base, base);
        let (mut centre, mut length) = (Vec3::ZERO, 0.0);
        for n in nodes {
            lo = lo.min(n.end);
            hi = hi.max(n.end);
            let l = n.start.distance(n.end);
            centre += (n.start + n.end) * 0.5 * l;
            length += l;
        }
        let offset = centre / length.max(1e-9) - base;
        let height = hi.y - base.y;
        TreeMetrics {
            num_internodes: nodes.len(),
            height_m: height,
            crown_width_m: 0.5 * ((hi.x - lo.x) + (hi.z - lo.z)),
            trunk_diameter_m: nodes.first().map_or(0.0, |n| n.diameter),
            age_years: self.age_years(),
            lean: if height > 0.0 {
                offset.x.hypot(offset.z) / height
            } else {
                0.0
            },
        }
    }
}

/// [`crate::tree::Skeleton::subtree_flags`] from the compact links of the arena: children come
/// after their parent, so one forward pass hands the flags down.
fn subtree_flags(scratch: &Scratch, roots: &[NodeId]) -> Vec<bool> {
    let n = scratch.main_child.len();
    let mut flags = vec![false; n];
    if roots.is_empty() {
        return flags;
    }
    for r in roots {
        if let Some(f) = flags.get_mut(r.index()) {
            *f = true;
        }
    }
    for i in 0..n {
        if !flags[i] {
            continue;
        }
        let (start, end) = scratch.lateral_range[i];
        let laterals = &scratch.lateral[start as usize..end as usize];
        for &c in std::iter::once(&scratch.main_child[i]).chain(laterals) {
            if let Some(f) = flags.get_mut(c as usize) {
                *f = true;
            }
        }
    }
    flags
}

impl PartialEq for Tree {
    /// Trees are equal when their saved state is (derived caches are ignored).
    fn eq(&self, other: &Self) -> bool {
        self.species == other.species
            && self.iteration == other.iteration
            && self.skeleton == other.skeleton
            && self.environment.attraction == other.environment.attraction
            && self.growth_mask == other.growth_mask
            && self.rng == other.rng
    }
}

#[cfg(test)]
mod tests {
    use glam::Vec3;

    use super::*;

    /// Steps `tree` (keeping its working memory) and a clone of it made before every step
    /// (empty working memory: every pass over the whole tree) and checks they stay equal,
    /// widths and light exposures included.
    fn step_both(kept: &mut Tree, options: StepOptions, what: &str) {
        let mut fresh = kept.clone();
        kept.step(options);
        fresh.step(options);
        assert!(*kept == fresh, "{what}");
        for (i, (a, b)) in kept
            .skeleton
            .internodes
            .iter()
            .zip(&fresh.skeleton.internodes)
            .enumerate()
        {
            assert_eq!(
                a.diameter.to_bits(),
                b.diameter.to_bits(),
                "{what}: node {i}"
            );
            assert_eq!(
                a.light_exposure.to_bits(),
                b.light_exposure.to_bits(),
                "{what}: node {i}"
            );
        }
    }

    #[test]
    fn kept_sums_and_exposures_grow_the_same_tree_as_passes_over_the_whole_tree() {
        let species = Species::by_name("maple").expect("maple preset");
        let mut tree = Tree::new(species, 9);
        let autonomous = StepOptions {
            autonomous: true,
            scene: None,
        };
        let brushed = StepOptions {
            autonomous: false,
            scene: None,
        };
        for i in 0..6 {
            step_both(&mut tree, autonomous, &format!("autonomous {i}"));
        }
        let mut rng = crate::rng::Rng::new(3);
        let brushed_from = tree.skeleton.len();
        for i in 0..8 {
            // Points in the perception reach of the highest tip.
            let perception = space::radii(&tree).1;
            let top = tree
                .skeleton
                .internodes
                .iter()
                .map(|n| n.end)
                .max_by(|a, b| a.y.total_cmp(&b.y))
                .expect("a tree has internodes");
            for _ in 0..80 {
                tree.environment
                    .attraction
                    .add_persistent(top + rng.in_unit_ball() * perception);
            }
            if i == 3 {
                // Other light parameters: every exposure is computed again.
                tree.species.shadow_strength *= 1.5;
            }
            if i == 5 {
                // Shade from outside growth (a garden's neighbours).
                tree.environment
                    .shadow
                    .apply_nodes([top - Vec3::Y * 0.5, top + Vec3::X * 0.2], 1);
            }
            step_both(&mut tree, brushed, &format!("brushed {i}"));
        }
        assert!(
            tree.skeleton.len() > brushed_from && brushed_from > 300,
            "{brushed_from} → {}",
            tree.skeleton.len()
        );
        step_both(&mut tree, autonomous, "autonomous after brushing");
    }
}
