//! Growing the model into the measured tree: the species grows from the trunk base with the
//! visual hull as its envelope (TreeSketch's lasso envelope, Longay 2014 §5.2.2: attraction
//! points fill it, and no shoot leaves it: core's grow-in-front scene mode) and the tree's own
//! points as extra attraction points, until it fills the hull or stops gaining, never above the
//! measured height. The trunk's narrow column below the crown is free space too, so the trunk
//! can reach the crown, and branches it grows below the crown base are removed (crown lifting).
//! With the crown's own volume (the hull carved by segmented silhouettes) the attraction points
//! fill that instead, growth runs while a coverage score of the crown's views rises, shoots that
//! stick out of the crown are cut, and the foliage is fitted to the views ([`super::fit`]). The
//! result is an ordinary tree in its own space; `world_from_tree` places it.

use glam::{Affine3A, DVec3, Quat, Vec3};
use sylva_core::Tree;
use sylva_core::environment::{Scene, SceneMode};
use sylva_core::growth::StepOptions;
use sylva_core::species::Species;

use super::fit::{FoliageFit, fit_foliage, fit_foliage_from};
use super::hull::Hull;
use super::measure::Recreation;

/// The hull as core's scene, in tree space.
struct HullScene<'a> {
    hull: &'a Hull,
    world_from_tree: Affine3A,
    height_m: f32,
    /// The trunk's free column around the axis (m), from the ground up (the crown's narrow
    /// bottom, eroded away, must not stop the trunk; crown lifting keeps all else below the
    /// crown base out of it).
    trunk_column_m: f32,
}

impl Scene for HullScene<'_> {
    fn is_free(&self, point_in_tree: Vec3) -> bool {
        if point_in_tree.y > self.height_m {
            return false;
        }
        let horizontal = Vec3::new(point_in_tree.x, 0.0, point_in_tree.z).length();
        if horizontal <= self.trunk_column_m {
            return true;
        }
        let world = self.world_from_tree.transform_point3(point_in_tree);
        self.hull.contains(world.as_dvec3(), 0)
    }
}

/// How the growth went.
#[derive(Clone, Debug, serde::Serialize)]
pub struct GrowthReport {
    pub species: String,
    /// How the species was chosen.
    pub species_choice: String,
    pub iterations: u32,
    pub age_years: f32,
    /// Fraction of the hull's coarse cells reached by the tree.
    pub hull_filled: f32,
    pub attraction_points: usize,
    /// Frames the crown was segmented in (0 without the footage's images).
    pub segmented_views: usize,
    /// Voxels of the hull carved again by those silhouettes (None without them).
    pub crown_voxels: Option<usize>,
    /// The foliage fitted to the crown's silhouettes ([`super::fit`]).
    pub foliage: Option<super::fit::FoliageFit>,
    /// The real trunk as the footage shows it ([`super::trunk`]), and the factor the model's
    /// widths were scaled by to match its diameter.
    pub trunk: Option<super::trunk::TrunkFound>,
    pub trunk_width_ratio: Option<f32>,
}

/// Leaf cards reach about this far beyond the twigs that carry them (m): the envelope growth
/// fills is the hull shrunk by it, so the foliage ends near the hull's surface.
const LEAF_REACH_M: f64 = 0.1;
/// Attraction points sampled in the hull (at most).
const HULL_POINTS: usize = 6000;
/// A hull cell counts as filled when an internode ends within this many internode lengths.
const FILL_REACH_INTERNODES: f32 = 3.0;
/// Growth stops once this fraction of the hull is filled ...
const FILLED: f32 = 0.9;
/// ... or it gained less than this over the last few iterations.
const MIN_GAIN: f32 = 0.005;
const GAIN_WINDOW: usize = 5;
/// With a coverage score, growth stops after this many iterations without a better one.
const COVER_WINDOW: usize = 4;
/// The leafy threshold is this fraction of the trunk's diameter at the crown base.
const BARE_MARGIN: f32 = 0.99;
/// Shoots are trimmed to end at most this many voxels inside the crown's surface.
const TRIM_VOXELS: usize = 3;
/// The shallowest trim whose views' mean IoU is within this of the best trim's is kept: a deeper
/// one must gain more than this (half a percent of IoU, the size of the differences the views'
/// pixel sampling and the leaves' random placement make between like trees) to cut more.
const TRIM_TOLERANCE: f64 = 0.005;

/// Scores a grown tree (its widths updated, the trunk bare) against the crown's views.
pub type Coverage<'a> = &'a (dyn Fn(&Tree) -> f64 + Sync);

/// What the crown's views add to [`grow_into_hull`]: the crown's own volume and a coverage score.
#[derive(Clone, Copy, Default)]
pub struct Guide<'a> {
    pub crown: Option<&'a Hull>,
    pub coverage: Option<Coverage<'a>>,
}

/// The tree (grown in metres) placed at the trunk base, upright on the ground, in a world of
/// `metres_per_unit` metres per unit: `T(base) * R(up) * S(1 / metres_per_unit)`, as the design
/// places its trees.
pub fn world_from_tree(base: DVec3, up: DVec3, metres_per_unit: f64) -> Affine3A {
    let up = up.as_vec3().try_normalize().unwrap_or(Vec3::Y);
    let units_per_metre = if metres_per_unit.is_finite() && metres_per_unit > 0.0 {
        (1.0 / metres_per_unit) as f32
    } else {
        1.0
    };
    Affine3A::from_scale_rotation_translation(
        Vec3::splat(units_per_metre),
        Quat::from_rotation_arc(Vec3::Y, up),
        base.as_vec3(),
    )
}

/// The preset whose proportions (height over spread at 10 years) are closest to the measured ones.
pub fn closest_species(height_m: f64, crown_width_m: f64) -> (Species, String) {
    let measured = (height_m / crown_width_m.max(0.1)).ln();
    let mut best: Option<(f64, Species)> = None;
    for s in Species::presets() {
        let e = &s.expected;
        let ratio = (e.height_10y_m as f64 / e.spread_10y_m.max(0.1) as f64).ln();
        let d = (ratio - measured).abs();
        if best.as_ref().is_none_or(|(b, _)| d < *b) {
            best = Some((d, s));
        }
    }
    let species = best.map(|(_, s)| s).unwrap_or_else(|| {
        Species::presets()
            .into_iter()
            .next()
            .expect("the species presets are built in")
    });
    let e = &species.expected;
    let why = format!(
        "closest preset by proportions: measured height/width {:.2}, {} {:.2} at 10 years",
        height_m / crown_width_m.max(0.1),
        species.name,
        e.height_10y_m / e.spread_10y_m
    );
    (species, why)
}

/// Coarse occupancy of the hull, to measure how much of it the tree fills.
struct FillGrid {
    min: Vec3,
    cell_m: f32,
    dims: [usize; 3],
    in_hull: Vec<bool>,
    num_in_hull: usize,
}

impl FillGrid {
    fn new(hull_in_tree: &[Vec3], cell_m: f32) -> Self {
        let (min, max) = hull_in_tree.iter().fold(
            (Vec3::splat(f32::INFINITY), Vec3::splat(f32::NEG_INFINITY)),
            |(lo, hi), p| (lo.min(*p), hi.max(*p)),
        );
        let dims = [0, 1, 2].map(|a| (((max[a] - min[a]) / cell_m).floor() as usize + 1).min(512));
        let mut in_hull = vec![false; dims[0] * dims[1] * dims[2]];
        let mut grid = Self {
            min,
            cell_m,
            dims,
            in_hull: Vec::new(),
            num_in_hull: 0,
        };
        for p in hull_in_tree {
            if let Some(i) = grid.cell(*p) {
                in_hull[i] = true;
            }
        }
        grid.num_in_hull = in_hull.iter().filter(|&&v| v).count();
        grid.in_hull = in_hull;
        grid
    }

    fn cell(&self, p: Vec3) -> Option<usize> {
        let c = (p - self.min) / self.cell_m;
        let ijk = [c.x, c.y, c.z];
        let mut index = 0;
        for a in (0..3).rev() {
            let v = ijk[a].floor();
            if v < 0.0 || v as usize >= self.dims[a] {
                return None;
            }
            index = index * self.dims[a] + v as usize;
        }
        Some(index)
    }

    /// Fraction of hull cells within `reach_m` of some internode end.
    fn filled(&self, tree: &Tree, reach_m: f32) -> f32 {
        if self.num_in_hull == 0 {
            return 1.0;
        }
        let mut reached = vec![false; self.in_hull.len()];
        let r = (reach_m / self.cell_m).ceil() as i32;
        for node in &tree.skeleton.internodes {
            for dz in -r..=r {
                for dy in -r..=r {
                    for dx in -r..=r {
                        let offset = Vec3::new(dx as f32, dy as f32, dz as f32) * self.cell_m;
                        if offset.length() > reach_m {
                            continue;
                        }
                        if let Some(i) = self.cell(node.end + offset) {
                            reached[i] = true;
                        }
                    }
                }
            }
        }
        let hit = reached
            .iter()
            .zip(&self.in_hull)
            .filter(|(r, h)| **r && **h)
            .count();
        hit as f32 / self.num_in_hull as f32
    }
}

/// Crown lifting, as the real tree has it: below the crown base the trunk keeps one axis, bare.
/// From the base up, the trunk continues into the child carrying the most internodes (a lateral
/// that took over the lead is the trunk then); every other internode that ends below
/// `crown_base_m + leaf_reach_m` is cut with what it carries: the trunk's low branches, and
/// shoots of the crown that hang below its base (the leaves they would carry sit below the
/// lowest foliage). Returns how many internodes went.
pub fn lift_crown(tree: &mut Tree, crown_base_m: f32, leaf_reach_m: f32) -> usize {
    let nodes = &tree.skeleton.internodes;
    if nodes.is_empty() {
        return 0;
    }
    // The arena is topological (parents first): subtree sizes in one backward pass.
    let mut size = vec![1usize; nodes.len()];
    for i in (0..nodes.len()).rev() {
        if let Some(parent) = nodes[i].parent {
            size[parent.index()] += size[i];
        }
    }
    let lowest_foliage_m = crown_base_m + leaf_reach_m;
    let mut trunk = vec![false; nodes.len()];
    let mut node = sylva_core::NodeId(0);
    trunk[0] = true;
    while nodes[node.index()].end.y < lowest_foliage_m {
        let Some(next) = nodes[node.index()]
            .children()
            .max_by_key(|c| size[c.index()])
        else {
            break;
        };
        trunk[next.index()] = true;
        node = next;
    }
    let mut cut = vec![false; nodes.len()];
    let mut roots = Vec::new();
    for (i, n) in nodes.iter().enumerate() {
        let parent_cut = n.parent.is_some_and(|p| cut[p.index()]);
        if parent_cut {
            cut[i] = true;
        } else if !trunk[i] && n.end.y < lowest_foliage_m {
            cut[i] = true;
            roots.push(sylva_core::NodeId(i as u32));
        }
    }
    if roots.is_empty() {
        0
    } else {
        tree.remove_subtrees(&roots)
    }
}

/// Prunes what sticks out of the crown: every shoot that ends outside `inside` (tree space) and
/// carries nothing that ends inside goes, with what it carries; branches crossing a gap between
/// the crown's lobes stay (what they carry is inside). Returns how many internodes went.
pub fn trim_outside(tree: &mut Tree, inside: impl Fn(Vec3) -> bool) -> usize {
    let nodes = &tree.skeleton.internodes;
    let mut keep: Vec<bool> = nodes.iter().map(|n| inside(n.end)).collect();
    // Parents come first in the arena: one backward pass carries "something inside" up.
    for i in (0..nodes.len()).rev() {
        if keep[i]
            && let Some(parent) = nodes[i].parent
        {
            keep[parent.index()] = true;
        }
    }
    if !keep.first().copied().unwrap_or(false) {
        return 0;
    }
    let roots: Vec<sylva_core::NodeId> = (0..nodes.len())
        .filter(|&i| !keep[i] && nodes[i].parent.is_none_or(|p| keep[p.index()]))
        .map(|i| sylva_core::NodeId(i as u32))
        .collect();
    if roots.is_empty() {
        0
    } else {
        tree.remove_subtrees(&roots)
    }
}

/// The trunk below the crown base is bare, as measured: leaves grow only on branches thinner
/// than the trunk where it meets the crown base (the tree's leafy threshold, in tip diameters,
/// lowered to that from the species' `leafy_diameters` when the trunk is thinner than it).
pub fn bare_trunk(tree: &mut Tree, crown_base_m: f32, leafy_diameters: f32) {
    let nodes = &tree.skeleton.internodes;
    let mut node = 0;
    // Up the leader (the main child) to the internode that reaches the crown base.
    while nodes[node].end.y < crown_base_m {
        let Some(next) = nodes[node].main_child else {
            break;
        };
        node = next.index();
    }
    let Some(at_base) = nodes.get(node).map(|n| n.diameter) else {
        return;
    };
    let tip = tree.species.tip_diameter_m.max(1e-4);
    let mut looks = tree.species.looks().clone();
    // A little under the trunk's own: the trunk below the crown base is as thick as there (no
    // branch joins it), and rounding must not put it under the threshold when the widths are
    // scaled later ([`super::trunk::fit_trunk_diameter`]).
    looks.leafy_diameters = (at_base / tip * BARE_MARGIN).clamp(1.0, leafy_diameters.max(1.0));
    tree.species.looks = Some(looks);
}

/// The first of `scores` (shallowest trim first) within `tolerance` of the best; None when empty
/// or none is a number.
fn shallowest_near_best(scores: &[f64], tolerance: f64) -> Option<usize> {
    let top = scores
        .iter()
        .copied()
        .filter(|s| !s.is_nan())
        .fold(f64::NEG_INFINITY, f64::max);
    scores.iter().position(|&s| s >= top - tolerance)
}

/// Grows `species` into the recreation's hull; `max_years` bounds the growth. `guide.crown`, when
/// given, is the crown's own volume inside the hull (the hull carved again by the segmented
/// silhouettes, [`super::segment`]): the attraction points fill it, and the fill is measured
/// in it, while shoots may still cross the hull's gaps between its lobes. `guide.coverage`, when
/// given, scores a grown tree against the crown's views (its foliage's agreement with them):
/// growth then goes on while that rises and the best-scoring tree is kept.
///
/// The tree grows in metres whatever the world's unit: the hull, the points and the measures
/// (in the world's units, `metres_per_unit` metres each) are mapped into tree space with the
/// scale by `world_from_tree` (from [`world_from_tree`]: it carries `S(1 / metres_per_unit)`),
/// which is returned with the tree.
pub fn grow_into_hull(
    species: Species,
    species_choice: String,
    seed: u64,
    recreation: &Recreation,
    guide: Guide,
    world_from_tree: Affine3A,
    max_years: f32,
) -> (Tree, Affine3A, GrowthReport) {
    let Guide { crown, coverage } = guide;
    let tree_from_world = world_from_tree.inverse();
    // Metres per world unit as the placement has it (1 where the scale was not usable).
    let metres = 1.0 / f64::from(world_from_tree.matrix3.x_axis.length());
    let m = &recreation.measurements;
    let envelope = recreation.hull.eroded(LEAF_REACH_M / metres);
    let envelope = if envelope.num_voxels() > 0 {
        envelope
    } else {
        recreation.hull.clone()
    };
    let scene = HullScene {
        hull: &envelope,
        world_from_tree,
        height_m: (m.height_m * metres) as f32,
        trunk_column_m: 0.0,
    };
    let mut tree = Tree::new(species, seed);
    let scene = HullScene {
        trunk_column_m: (2.0 * tree.species.internode_length_m).max(0.1),
        ..scene
    };
    let crown_base_m = (m.crown_base_m * metres) as f32;
    // The volume the attraction points fill: the crown's own (shrunk by half the leaves' reach,
    // its lobes are small), else the envelope.
    let target = crown.map(|c| {
        let shrunk = c.eroded(0.5 * LEAF_REACH_M / metres);
        if shrunk.num_voxels() * 4 >= c.num_voxels() {
            shrunk
        } else {
            c.clone()
        }
    });
    let hull_in_tree: Vec<Vec3> = target
        .as_ref()
        .unwrap_or(&envelope)
        .voxels()
        .into_iter()
        .map(|p| tree_from_world.transform_point3(p.as_vec3()))
        .collect();
    // Attraction points: voxel centres of the hull (an even subset, jittered within the voxel),
    // and the tree's own points.
    let stride = hull_in_tree.len().div_ceil(HULL_POINTS).max(1);
    let voxel_m = (envelope.voxel_m * metres) as f32;
    let mut num_points = 0;
    for p in hull_in_tree.iter().step_by(stride) {
        let jitter = Vec3::new(
            tree.rng.range_f32(-0.5, 0.5),
            tree.rng.range_f32(-0.5, 0.5),
            tree.rng.range_f32(-0.5, 0.5),
        ) * voxel_m;
        tree.environment.attraction.add_persistent(*p + jitter);
        num_points += 1;
    }
    for p in &recreation.own_points {
        tree.environment
            .attraction
            .add_persistent(tree_from_world.transform_point3(p.as_vec3()));
        num_points += 1;
    }
    let reach_m = FILL_REACH_INTERNODES * tree.species.internode_length_m;
    let grid = FillGrid::new(&hull_in_tree, (reach_m * 0.5).max(voxel_m));
    let max_iterations = tree.species.iterations_for_years(max_years).max(1);
    let leafy_diameters = tree.species.looks().leafy_diameters;
    let mut history: Vec<f32> = Vec::new();
    let mut filled = 0.0;
    // Shedding may take back what a few iterations filled: the fullest tree is kept (by the
    // coverage of the crown's views when given, else by the hull's fill).
    let mut best: Option<(f64, f32, Tree)> = None;
    let mut since_best = 0;
    // The crown's own volume, in tree space (everything without it).
    let in_crown = |p: Vec3| {
        crown.is_none_or(|c| c.contains(world_from_tree.transform_point3(p).as_dvec3(), 0))
    };
    for _ in 0..max_iterations {
        tree.step(StepOptions {
            autonomous: true,
            scene: Some((&scene, SceneMode::GrowInFront)),
        });
        lift_crown(&mut tree, crown_base_m, LEAF_REACH_M as f32);
        filled = grid.filled(&tree, reach_m);
        history.push(filled);
        let score = match coverage {
            Some(coverage) => {
                let mut finished = tree.clone();
                trim_outside(&mut finished, in_crown);
                finished.update_widths();
                bare_trunk(&mut finished, crown_base_m, leafy_diameters);
                coverage(&finished)
            }
            None => f64::from(filled),
        };
        since_best += 1;
        if best.as_ref().is_none_or(|(b, _, _)| score > *b) {
            best = Some((score, filled, tree.clone()));
            since_best = 0;
        }
        let stalled = if coverage.is_some() {
            // The views' coverage has not risen for a while: the crown is as full as it gets.
            since_best >= COVER_WINDOW
        } else {
            // Early on the seedling is still climbing the trunk's column: no stall before half.
            filled > 0.5
                && history.len() > GAIN_WINDOW
                && filled - history[history.len() - 1 - GAIN_WINDOW] < MIN_GAIN
        };
        if (coverage.is_none() && filled >= FILLED) || stalled {
            break;
        }
    }
    if let Some((_, best_filled, best_tree)) = best {
        (filled, tree) = (best_filled, best_tree);
    }
    let finish = |tree: &Tree, inside: &dyn Fn(Vec3) -> bool| {
        let mut finished = tree.clone();
        trim_outside(&mut finished, inside);
        finished.update_widths();
        bare_trunk(&mut finished, crown_base_m, leafy_diameters);
        finished
    };
    // What sticks out of the crown goes. How far inside the crown's surface its shoots must end
    // (0 to TRIM_VOXELS: their leaves reach on past them) and the leaves' size and density are
    // chosen together by the views' coverage.
    let mut foliage = None;
    tree = match (crown, coverage) {
        (Some(crown), Some(coverage)) => {
            // Each trim's foliage is fitted from the untrimmed one's choice (a few scores when
            // it barely moves). Among trims scoring about the same, the one that cuts least is
            // kept: a deeper trim takes living shoots (and the buds that would regrow the
            // crown after a cut), so it must earn that by a clearly better agreement.
            let mut tried: Vec<(Tree, FoliageFit)> = Vec::new();
            for k in 0..=TRIM_VOXELS {
                let shrunk = crown.eroded(k as f64 * crown.voxel_m);
                let inside =
                    |p: Vec3| shrunk.contains(world_from_tree.transform_point3(p).as_dvec3(), 0);
                let start = tried.first().map(|(_, f)| f);
                let (candidate, mut fit) =
                    fit_foliage_from(&finish(&tree, &inside), coverage, start);
                fit.trim_voxels = k;
                tried.push((candidate, fit));
            }
            let trim_iou: Vec<f64> = tried.iter().map(|(_, f)| f.iou_after).collect();
            let fitted = shallowest_near_best(&trim_iou, TRIM_TOLERANCE).map(|k| {
                let (t, mut f) = tried.swap_remove(k);
                f.trim_iou = trim_iou;
                (t, f)
            });
            match fitted {
                Some((fitted, fit)) => {
                    foliage = Some(fit);
                    fitted
                }
                None => finish(&tree, &in_crown),
            }
        }
        (None, Some(coverage)) => {
            let (fitted, fit) = fit_foliage(&finish(&tree, &in_crown), coverage);
            foliage = Some(fit);
            fitted
        }
        _ => finish(&tree, &in_crown),
    };
    let report = GrowthReport {
        species: tree.species.name.clone(),
        species_choice,
        iterations: tree.iteration,
        age_years: tree.age_years(),
        hull_filled: filled,
        attraction_points: num_points,
        segmented_views: 0,
        crown_voxels: None,
        foliage,
        trunk: None,
        trunk_width_ratio: None,
    };
    (tree, world_from_tree, report)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_deeper_trim_is_kept_only_when_it_scores_clearly_better() {
        assert_eq!(shallowest_near_best(&[0.70, 0.703, 0.704], 0.005), Some(0));
        assert_eq!(
            shallowest_near_best(&[0.69, 0.70, 0.715, 0.711], 0.005),
            Some(2)
        );
        assert_eq!(shallowest_near_best(&[0.69, 0.712, 0.715], 0.005), Some(1));
        assert_eq!(shallowest_near_best(&[f64::NAN, 0.6], 0.005), Some(1));
        assert_eq!(shallowest_near_best(&[], 0.005), None);
    }

    #[test]
    fn crown_lifting_leaves_one_axis_below_the_crown_base() {
        let species = Species::by_name("oak").expect("oak preset");
        let mut tree = Tree::new(species, 3);
        tree.grow_years(6.0);
        let before = tree.skeleton.len();
        let removed = lift_crown(&mut tree, 1.0, 0.1);
        assert!(removed > 0 && tree.skeleton.len() == before - removed);
        let low: Vec<_> = tree
            .skeleton
            .internodes
            .iter()
            .filter(|n| n.end.y < 1.1)
            .collect();
        // Only the trunk's single axis ends below the crown base and the leaves' reach.
        let chain_ok = low
            .iter()
            .all(|n| n.parent.is_none_or(|p| tree.skeleton.get(p).end.y < 1.1));
        assert!(chain_ok, "a shoot hangs below the crown base");
        let branching = low
            .iter()
            .filter(|n| {
                n.children()
                    .filter(|c| tree.skeleton.get(*c).end.y < 1.1)
                    .count()
                    > 1
            })
            .count();
        assert_eq!(branching, 0, "a branching point below the crown base");
        assert!(tree.sanity_check().is_ok());
    }

    #[test]
    fn below_the_crown_base_the_trunk_is_too_thick_for_leaves() {
        let species = Species::by_name("birch").expect("birch preset");
        let mut tree = Tree::new(species, 5);
        tree.grow_years(8.0);
        lift_crown(&mut tree, 1.0, 0.1);
        let leafy = tree.species.looks().leafy_diameters;
        bare_trunk(&mut tree, 1.0, leafy);
        let threshold = tree.species.tip_diameter_m * tree.species.looks().leafy_diameters;
        let low: Vec<_> = (tree.skeleton.internodes.iter())
            .filter(|n| n.end.y < 1.0)
            .collect();
        assert!(!low.is_empty());
        for n in low {
            assert!(
                n.diameter >= threshold,
                "a trunk internode of {} m below the crown base, leaves below {threshold} m",
                n.diameter
            );
        }
    }
}
