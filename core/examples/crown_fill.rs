//! How full a preset's crown is, for trying species values: on each seed (11, 2014 and 7, or
//! `SYLVA_SEEDS`) at each age (15 and 30 years, or `SYLVA_AGES`), the height, spread, lean, trunk
//! diameter at breast height, internodes, leaf area index and the side view's porosity (sky in
//! the crown's convex hull, also split into the middle 60% of each row and the rim), LOD0's
//! triangles and the `.glb`'s size, as
//! `foliage_report` and `core/tests/foliage_density.rs` measure them; then the worst porosity
//! and the range of the leaf area index over all crowns. Seeds grow on threads of their own.
//! With `SYLVA_PICTURES=dir` each side view is written there as a PNG: leaves green, wood
//! brown, sky inside the hull blue, outside it white.
//!
//! `cargo run --release -p sylva-core --example crown_fill -- oak [field=json ...]`

#[path = "common/overrides.rs"]
mod overrides;
#[path = "common/seeds.rs"]
mod seeds;

use sylva_core::Tree;
use sylva_core::export::glb_bytes;
use sylva_core::geometry::build_tree_meshes;
use sylva_core::geometry::crown::{
    AlphaMask, CARD_TEXTURE_SIZE, Coverage, LEAF, MEASURE_PIXEL_M, View, WOOD, crown_measures,
    rasterise,
};
use sylva_core::geometry::leaf_card::card_texture;
use sylva_core::species::{BREAST_HEIGHT_M, Species};

const SEEDS: [u64; 3] = [11, 2014, 7];
const AGES_YEARS: [f32; 2] = [15.0, 30.0];
/// Share of each row of the side view's hull counted as its middle (as `foliage_report`).
const MIDDLE: f32 = 0.6;

/// One crown's figures.
struct Crown {
    seed: u64,
    age_years: f32,
    line: String,
    leaf_area_index: f32,
    porosity: f32,
}

fn ages_from_env() -> Vec<f32> {
    std::env::var("SYLVA_AGES").map_or(AGES_YEARS.to_vec(), |list| {
        list.split(',')
            .map(|s| {
                s.trim()
                    .parse()
                    .unwrap_or_else(|e| panic!("SYLVA_AGES {s}: {e}"))
            })
            .collect()
    })
}

fn crowns_of_seed(species: &Species, seed: u64, ages: &[f32]) -> Vec<Crown> {
    let mut tree = Tree::new(species.clone(), seed);
    let mut out = Vec::new();
    for &age_years in ages {
        tree.grow_years(age_years - tree.age_years());
        let m = tree.metrics();
        let dbh_cm = 100.0 * tree.trunk_diameter_at(BREAST_HEIGHT_M).unwrap_or(0.0);
        let meshes = build_tree_meshes(&tree);
        let mask = AlphaMask::from_texture(&card_texture(&meshes, CARD_TEXTURE_SIZE));
        let Some(c) = crown_measures(&meshes, 0, &mask, MEASURE_PIXEL_M) else {
            println!("seed {seed} at {age_years} years: no leaves");
            continue;
        };
        let (middle, rim) = rasterise(&meshes, 0, &mask, View::Side, MEASURE_PIXEL_M)
            .map_or((f32::NAN, f32::NAN), |side| {
                side.hull_sky_middle_and_rim(LEAF, MIDDLE)
            });
        if let Ok(dir) = std::env::var("SYLVA_PICTURES") {
            let side = rasterise(&meshes, 0, &mask, View::Side, MEASURE_PIXEL_M);
            let path = format!("{dir}/{}_{seed}_{age_years}.png", species.name);
            if let Some(side) = side
                && let Err(e) = side_picture(&side).save(&path)
            {
                eprintln!("{path}: {e}");
            }
        }
        let line = format!(
            "seed {seed:5} {age_years:>2}y: h {:5.2} w {:5.2} lean {:4.2} dbh {dbh_cm:5.1} cm n {:6} LAI {:4.2} \
             porosity {:4.1}% (middle {:4.1}%, rim {:4.1}%) LOD0 {}k tris, glb {:.1} MB",
            m.height_m,
            m.crown_width_m,
            m.lean,
            m.num_internodes,
            c.leaf_area_index,
            100.0 * c.side_porosity,
            100.0 * middle,
            100.0 * rim,
            meshes.num_triangles(0) / 1000,
            glb_bytes(&meshes).map_or(f64::NAN, |b| b.len() as f64 * 1e-6),
        );
        out.push(Crown {
            seed,
            age_years,
            line,
            leaf_area_index: c.leaf_area_index,
            porosity: c.side_porosity,
        });
    }
    out
}

/// The side view's coverage as a picture (see the module doc).
fn side_picture(side: &Coverage) -> image::RgbImage {
    let spans = side.hull_spans(LEAF);
    image::RgbImage::from_fn(side.width as u32, side.height as u32, |x, y| {
        let (x, y) = (x as usize, y as usize);
        let inside = spans
            .get(y)
            .copied()
            .flatten()
            .is_some_and(|(first, last)| (first..=last).contains(&x));
        let p = side.pixels[y * side.width + x];
        image::Rgb(if p & LEAF != 0 {
            [40, 120, 30]
        } else if p & WOOD != 0 {
            [90, 60, 30]
        } else if inside {
            [120, 170, 255]
        } else {
            [255, 255, 255]
        })
    })
}

fn main() {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let name = args.first().map_or("oak", String::as_str);
    let species = overrides::species_with_overrides(name, args.get(1..).unwrap_or_default());
    let ages = ages_from_env();
    let seeds = seeds::seeds_from_env(&SEEDS);
    let crowns: Vec<Crown> = std::thread::scope(|scope| {
        let handles: Vec<_> = seeds
            .iter()
            .map(|&seed| {
                let (species, ages) = (&species, &ages);
                scope.spawn(move || crowns_of_seed(species, seed, ages))
            })
            .collect();
        handles
            .into_iter()
            .flat_map(|h| h.join().unwrap_or_default())
            .collect()
    });
    for c in &crowns {
        println!("{}", c.line);
    }
    let worst = crowns
        .iter()
        .max_by(|a, b| a.porosity.total_cmp(&b.porosity));
    let (lo, hi) = crowns.iter().fold((f32::INFINITY, 0.0f32), |(lo, hi), c| {
        (lo.min(c.leaf_area_index), hi.max(c.leaf_area_index))
    });
    let over = crowns.iter().filter(|c| c.porosity > 0.35).count();
    if let Some(w) = worst {
        println!(
            "{name}: {over} of {} crowns over 35% sky; worst {:.1}% (seed {} at {} years); \
             LAI {lo:.2}-{hi:.2}",
            crowns.len(),
            100.0 * w.porosity,
            w.seed,
            w.age_years
        );
    }
}
