//! The appearance of each species preset: leaf size, shape and density, bark and leaf colours,
//! fruit. Growth parameters live in [`crate::species`]; these only affect the meshes.

use super::{FruitParams, LeafParams, MeshParams};
use crate::growth::Tree;
use crate::species::Species;

/// Blade length and width (m), leaves per metre, linear RGB of bark and leaf, fruit.
struct Look {
    leaf_length: f32,
    leaf_width: f32,
    leaves_per_metre: f32,
    /// Leaves on branches thinner than this many tip diameters.
    leafy_diameters: f32,
    /// Leaves drawn on one card (a spray of small leaves, a needle shoot).
    leaves_per_card: u32,
    bark: [f32; 3],
    leaf: [f32; 3],
    fruit: Option<([f32; 3], f32)>,
}

fn look_of(name: &str) -> Look {
    let broadleaf = Look {
        leaf_length: 0.09,
        leaf_width: 0.06,
        leaves_per_metre: 120.0,
        leafy_diameters: 10.0,
        leaves_per_card: 8,
        bark: [0.25, 0.2, 0.15],
        leaf: [0.14, 0.34, 0.06],
        fruit: None,
    };
    match name {
        "birch" => Look {
            leafy_diameters: 10.0,
            leaves_per_card: 8,
            leaf_length: 0.06,
            leaf_width: 0.04,
            leaves_per_metre: 110.0,
            bark: [0.72, 0.7, 0.66],
            leaf: [0.22, 0.44, 0.08],
            ..broadleaf
        },
        "lombardy_poplar" => Look {
            leafy_diameters: 4.0,
            leaves_per_card: 10,
            leaves_per_metre: 25.0,
            leaf_length: 0.07,
            leaf_width: 0.06,
            bark: [0.33, 0.29, 0.24],
            leaf: [0.16, 0.38, 0.07],
            ..broadleaf
        },
        "maple" => Look {
            leafy_diameters: 10.0,
            leaves_per_card: 6,
            leaf_length: 0.11,
            leaf_width: 0.1,
            leaves_per_metre: 45.0,
            bark: [0.28, 0.23, 0.18],
            leaf: [0.13, 0.36, 0.05],
            ..broadleaf
        },
        "norway_spruce" => Look {
            leaves_per_card: 24,
            leaf_length: 0.035,
            leaf_width: 0.012,
            leaves_per_metre: 900.0,
            leafy_diameters: 12.0,
            bark: [0.3, 0.17, 0.1],
            leaf: [0.04, 0.15, 0.05],
            ..broadleaf
        },
        "oak" => Look {
            leaves_per_card: 8,
            leaves_per_metre: 200.0,
            leaf_length: 0.1,
            leaf_width: 0.055,
            bark: [0.2, 0.17, 0.14],
            leaf: [0.11, 0.29, 0.05],
            fruit: Some(([0.36, 0.26, 0.09], 0.012)),
            ..broadleaf
        },
        "weeping_willow" => Look {
            leafy_diameters: 10.0,
            leaves_per_card: 16,
            leaf_length: 0.11,
            leaf_width: 0.018,
            leaves_per_metre: 150.0,
            bark: [0.3, 0.25, 0.17],
            leaf: [0.3, 0.5, 0.1],
            ..broadleaf
        },
        _ => broadleaf,
    }
}

/// Mesh parameters giving `species` its appearance (unknown names get a generic broadleaf).
pub fn mesh_params_for(species: &Species) -> MeshParams {
    let look = look_of(&species.name);
    let defaults = MeshParams::default();
    MeshParams {
        leaves: LeafParams {
            max_branch_diameter: species.tip_diameter_m * look.leafy_diameters,
            leaves_per_metre: look.leaves_per_metre,
            length: look.leaf_length,
            width: look.leaf_width,
            leaves_per_card: look.leaves_per_card,
            petiole_length: 0.3 * look.leaf_length,
            ..LeafParams::default()
        },
        fruit: look.fruit.map(|(_, radius)| FruitParams {
            radius,
            max_branch_diameter: species.tip_diameter_m * 2.5,
            ..FruitParams::default()
        }),
        bark_color: look.bark,
        leaf_color: look.leaf,
        fruit_color: look.fruit.map_or(defaults.fruit_color, |(color, _)| color),
        ..defaults
    }
}

/// Meshes of a grown tree with its species' look, ambient light from its shadow grid.
pub fn build_tree_meshes(tree: &Tree) -> super::TreeMeshes {
    build_tree_meshes_with(tree, &mesh_params_for(&tree.species))
}

/// Meshes of a grown tree with its species' look at level of detail `level` only (see
/// [`super::build_level`]): what a renderer draws.
pub fn build_tree_level(tree: &Tree, level: usize) -> super::TreeMeshes {
    let params = mesh_params_for(&tree.species);
    super::build_level(&tree.skeleton, &params, &|p| tree.ambient_at(p), level)
}

/// Meshes of a grown tree with explicit parameters, ambient light from its shadow grid.
pub fn build_tree_meshes_with(tree: &Tree, params: &MeshParams) -> super::TreeMeshes {
    super::build_meshes(&tree.skeleton, params, &|p| tree.ambient_at(p))
}
