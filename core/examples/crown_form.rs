//! The form of a preset's crown at 10, 15, 30 and 40 years on seeds 11, 2014 and 7: height,
//! spread, trunk diameter at breast height, internodes, and where the trunk divides: the first
//! node of the main axis with a lateral at least 0.6 times as thick as the continuation (a
//! co-dominant limb), as a share of the height, and how many limbs (the continuation counted)
//! leave the trunk there and within 1.5 m above. An excurrent tree (a leader to the top) divides
//! high or never; a decurrent one low.
//!
//! `cargo run --release -p sylva-core --example crown_form -- oak [field=json ...]`
//! (`SYLVA_SEEDS=1,2,3` tries other seeds).

#[path = "common/overrides.rs"]
mod overrides;
#[path = "common/seeds.rs"]
mod seeds;

use sylva_core::Tree;
use sylva_core::species::BREAST_HEIGHT_M;

const SEEDS: [u64; 3] = [11, 2014, 7];
const AGES: [f32; 4] = [10.0, 15.0, 30.0, 40.0];
const CO_DOMINANT: f32 = 0.6;

/// (height of the division, limbs there and within 1.5 m above) or None for a leader to the top.
fn division(tree: &Tree) -> Option<(f32, usize)> {
    let nodes = &tree.skeleton.internodes;
    let mut i = 0;
    let mut fork: Option<f32> = None;
    let mut limbs = 0;
    while let Some(m) = nodes.get(i)?.main_child {
        let d_main = nodes[m.index()].diameter;
        let thick = nodes[i]
            .lateral_children
            .iter()
            .filter(|c| nodes[c.index()].diameter >= CO_DOMINANT * d_main)
            .count();
        let y = nodes[i].end.y;
        match fork {
            None if thick > 0 => {
                fork = Some(y);
                limbs = thick;
            }
            Some(f) if y - f <= 1.5 => limbs += thick,
            Some(_) => break,
            None => {}
        }
        i = m.index();
    }
    fork.map(|f| (f, limbs + 1))
}

fn main() {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let name = args.first().map_or("oak", String::as_str);
    let species = overrides::species_with_overrides(name, args.get(1..).unwrap_or_default());
    for seed in seeds::seeds_from_env(&SEEDS) {
        let mut tree = Tree::new(species.clone(), seed);
        for age in AGES {
            tree.grow_years(age - tree.age_years());
            let m = tree.metrics();
            let dbh = tree.trunk_diameter_at(BREAST_HEIGHT_M).unwrap_or(0.0);
            let form = match division(&tree) {
                Some((y, limbs)) => format!(
                    "divides at {y:5.2} m ({:3.0}% of h) into {limbs} limbs",
                    y / m.height_m * 100.0
                ),
                None => "leader to the top".to_string(),
            };
            println!(
                "seed {seed:5} {age:>2}y: h {:5.2} m w {:5.2} m (w/h {:.2}) dbh {:5.1} cm n {:6}, {form}",
                m.height_m,
                m.crown_width_m,
                m.crown_width_m / m.height_m,
                dbh * 100.0,
                m.num_internodes
            );
        }
    }
}
