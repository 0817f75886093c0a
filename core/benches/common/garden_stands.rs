//! The gardens of `benches/garden.rs` and `examples/garden_timing.rs`: random stands of the six
//! presets in turn, planted as seedlings; and the edits of one tree that `garden_edit_timing`
//! and the bench time.
#![allow(dead_code)] // each includer uses a part

use sylva_core::garden::{Garden, Layout, Planting, PlantingFile};
use sylva_core::species::Species;

/// The mixed presets, taken in turn.
pub const PRESETS: [&str; 6] = [
    "birch",
    "maple",
    "oak",
    "norway_spruce",
    "weeping_willow",
    "lombardy_poplar",
];

/// `count` seedlings of the presets at random on a `side_m` × `side_m` plot.
pub fn stand(count: usize, side_m: f32, seed: u64) -> Garden {
    let file = PlantingFile {
        plantings: vec![Planting::Stand {
            species: PRESETS.iter().map(|s| s.to_string()).collect(),
            width_m: side_m,
            depth_m: side_m,
            count,
            layout: Layout::Random,
            age_years: 0.0,
            seed,
        }],
    };
    let by_name = |name: &str| Species::by_name(name).map_err(|e| e.to_string());
    Garden::plant(file.trees(&by_name).expect("a valid stand")).expect("plants")
}

/// An edit of one tree.
pub type Edit = fn(&mut sylva_core::Tree);

/// The edits of one tree timed against its garden (issue #24, Done when 5), each as a plain
/// function of the tree so the same edit can be applied in the garden and to the tree alone.
pub const EDITS: [(&str, Edit); 4] = [
    ("brush", brush_edit),
    ("prune", prune_edit),
    ("parameters", parameter_edit),
    ("regrow", regrow_edit),
];

/// A brush dab of 300 points in a 0.5 m sphere beside the crown's top, grown towards in three
/// brush-guided iterations.
fn brush_edit(tree: &mut sylva_core::Tree) {
    let m = tree.metrics();
    let centre = glam::Vec3::new(0.5 * m.crown_width_m.max(0.5), m.height_m * 0.8, 0.0);
    let mut rng = sylva_core::Rng::new(11);
    for _ in 0..300 {
        let p = centre + rng.in_unit_ball() * 0.5;
        tree.environment.attraction.add_persistent(p);
    }
    for _ in 0..3 {
        tree.step(sylva_core::growth::StepOptions {
            autonomous: false,
            scene: None,
        });
    }
}

/// The first branch cut off, then a year of growth.
fn prune_edit(tree: &mut sylva_core::Tree) {
    let branch = (1..tree.skeleton.len())
        .find(|&i| tree.skeleton.internodes[i].order == 1)
        .map(|i| sylva_core::NodeId(i as u32));
    tree.remove_subtrees(&branch.into_iter().collect::<Vec<_>>());
    tree.grow_years(1.0);
}

/// Apical dominance lowered by a tenth, then a year of growth.
fn parameter_edit(tree: &mut sylva_core::Tree) {
    tree.species.apical_dominance *= 0.9;
    tree.grow_years(1.0);
}

/// Apical dominance lowered by a tenth and the tree regrown from a seedling to its age, as a
/// design regrows after a slider moves.
fn regrow_edit(tree: &mut sylva_core::Tree) {
    let mut species = tree.species.clone();
    species.apical_dominance *= 0.9;
    let age_years = tree.age_years();
    *tree = sylva_core::Tree::new(species, 7);
    tree.grow_years(age_years);
}

/// The tree `index` of `garden` as if it stood alone: its own shade only, no neighbours.
pub fn alone(garden: &Garden, index: usize) -> sylva_core::Tree {
    let mut tree = garden.trees[index].tree.clone();
    tree.rebuild_shadow();
    tree.environment.neighbour_nodes.clear();
    tree.environment.neighbour_tropism = glam::Vec3::ZERO;
    tree
}
