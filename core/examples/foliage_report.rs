//! Foliage of every species preset: leaf area index (one-sided blade area over the crown's
//! projection on the ground), the side view's crown porosity (with the sky in the middle 60% of
//! each row of the crown's hull and in the rim outside it, which tells a thin crown from a
//! conical or lobed outline), the triangles at LOD0 and the size of the `.glb`, at 15, 30 and
//! 40 years. Measured by rasterising the meshes (`geometry::crown`).
//!
//! `cargo run --release -p sylva-core --example foliage_report [seed]`

use sylva_core::Tree;
use sylva_core::export::glb_bytes;
use sylva_core::geometry::build_tree_meshes;
use sylva_core::geometry::crown::{
    AlphaMask, CARD_TEXTURE_SIZE, LEAF, MEASURE_PIXEL_M, View, crown_measures, rasterise,
};
use sylva_core::geometry::leaf_card::card_texture;
use sylva_core::species::Species;

const AGES_YEARS: [f32; 3] = [15.0, 30.0, 40.0];
/// Share of each row of the side view's hull counted as its middle.
const MIDDLE: f32 = 0.6;

fn main() {
    let seed: u64 = std::env::args()
        .nth(1)
        .and_then(|a| a.parse().ok())
        .unwrap_or(11);
    println!("seed {seed}; sky = background share of the side view's crown hull");
    println!(
        "{:<16} {:>5} {:>9} {:>7} {:>9} {:>8} {:>5} {:>9} {:>7} {:>7} {:>9} {:>9} {:>7}",
        "preset",
        "years",
        "internodes",
        "cards",
        "leaf m²",
        "crown m²",
        "LAI",
        "porosity",
        "middle",
        "rim",
        "leaf tris",
        "LOD0 tris",
        "glb MB"
    );
    for species in Species::presets() {
        let name = species.name.clone();
        let mut tree = Tree::new(species, seed);
        for age in AGES_YEARS {
            tree.grow_years(age - tree.age_years());
            let meshes = build_tree_meshes(&tree);
            let mask = AlphaMask::from_texture(&card_texture(&meshes, CARD_TEXTURE_SIZE));
            let Some(m) = crown_measures(&meshes, 0, &mask, MEASURE_PIXEL_M) else {
                println!("{name:<16} {age:>5} no leaves");
                continue;
            };
            let (middle, rim) = rasterise(&meshes, 0, &mask, View::Side, MEASURE_PIXEL_M)
                .map_or((f32::NAN, f32::NAN), |side| {
                    side.hull_sky_middle_and_rim(LEAF, MIDDLE)
                });
            println!(
                "{:<16} {:>5} {:>9} {:>7} {:>9.1} {:>8.1} {:>5.2} {:>8.1}% {:>6.1}% {:>6.1}% {:>9} {:>9} {:>7.1}",
                name,
                age,
                tree.skeleton.len(),
                m.num_leaf_cards,
                m.leaf_area_m2,
                m.crown_projection_m2,
                m.leaf_area_index,
                100.0 * m.side_porosity,
                100.0 * middle,
                100.0 * rim,
                meshes.lods[0].num_leaf_indices / 3,
                meshes.num_triangles(0),
                glb_bytes(&meshes).map_or(f64::NAN, |b| b.len() as f64 * 1e-6),
            );
        }
    }
}
