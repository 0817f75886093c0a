//! Every species preset grows to within ±30% of its stated height and crown spread at 10 and 30
//! years, and keeps its botanical character.

use sylva_core::Tree;
use sylva_core::species::Species;

const SEED: u64 = 2014;
const TOLERANCE: f32 = 0.30;

fn within(measured: f32, expected: f32) -> bool {
    (measured - expected).abs() <= TOLERANCE * expected
}

#[test]
fn every_preset_lands_within_30_percent_of_its_stated_height_and_spread_at_10_and_30_years() {
    let mut failures = Vec::new();
    for species in Species::presets() {
        let e = species.expected.clone();
        let name = species.name.clone();
        let mut tree = Tree::new(species, SEED);
        tree.grow_years(10.0);
        let at10 = tree.metrics();
        tree.grow_years(20.0);
        let at30 = tree.metrics();
        println!(
            "{name:16} 10y: h {:5.2}/{:5.2} w {:5.2}/{:5.2}  30y: h {:5.2}/{:5.2} w {:5.2}/{:5.2}  n={} d={:.3}",
            at10.height_m,
            e.height_10y_m,
            at10.crown_width_m,
            e.spread_10y_m,
            at30.height_m,
            e.height_30y_m,
            at30.crown_width_m,
            e.spread_30y_m,
            at30.num_internodes,
            at30.trunk_diameter_m
        );
        for (what, measured, expected) in e.against(&at10, &at30) {
            if !within(measured, expected) {
                failures.push(format!(
                    "{name}: {what} {measured:.2} m, expected {expected:.2} m ±30%"
                ));
            }
        }
    }
    assert!(failures.is_empty(), "{}", failures.join("\n"));
}

fn mean_vertical(tree: &Tree, orders: std::ops::RangeInclusive<u32>) -> f32 {
    let ys: Vec<f32> = tree
        .skeleton
        .internodes
        .iter()
        .filter(|n| orders.contains(&n.order))
        .map(|n| n.heading().y)
        .collect();
    ys.iter().sum::<f32>() / ys.len().max(1) as f32
}

#[test]
fn presets_keep_their_botanical_character() {
    let grown = |name: &str| {
        let mut tree = Tree::new(Species::by_name(name).expect("preset"), SEED);
        tree.grow_years(20.0);
        tree
    };
    let spruce = grown("norway_spruce");
    let (trunk, laterals) = (mean_vertical(&spruce, 0..=0), mean_vertical(&spruce, 1..=1));
    println!("spruce trunk H·Y {trunk:.3}, first-order laterals H·Y {laterals:.3}");
    assert!(
        trunk > 0.97,
        "spruce trunk not upright: mean H·Y {trunk:.3}"
    );
    assert!(
        laterals.abs() < 0.35,
        "spruce laterals not plagiotropic: mean H·Y {laterals:.3}"
    );
    let willow = grown("weeping_willow");
    let hanging = mean_vertical(&willow, 2..=u32::MAX);
    println!("willow higher-order H·Y {hanging:.3}");
    assert!(
        hanging < -0.2,
        "willow shoots do not hang: mean H·Y {hanging:.3}"
    );
    let poplar = grown("lombardy_poplar").metrics();
    let oak = grown("oak").metrics();
    let (p, o) = (
        poplar.height_m / poplar.crown_width_m,
        oak.height_m / oak.crown_width_m,
    );
    println!("height/spread: poplar {p:.2}, oak {o:.2}");
    assert!(p > 3.5, "poplar is not columnar: height/spread {p:.2}");
    assert!(
        o < 1.8 && p > 2.0 * o,
        "oak is not broad next to poplar: {o:.2} vs {p:.2}"
    );
}
