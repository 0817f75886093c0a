//! The gardens of `benches/garden.rs` and `examples/garden_timing.rs`: random stands of the six
//! presets in turn, planted as seedlings.

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
