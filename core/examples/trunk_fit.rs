//! Trunk diameters at breast height (1.3 m) of every preset at 15, 30 and 40 years: the median
//! of seeds 2014 and 1–4 against the range the species file states, and what the median would
//! be with other pipe-model exponents n (widths are solved after growth, so the same trees
//! serve every n: the growth does not change), and how close each n puts the medians to the
//! middles of the stated ranges.
//!
//! `cargo run --release -p sylva-core --example trunk_fit [n n ...]`

use sylva_core::Tree;
use sylva_core::species::{BREAST_HEIGHT_M, Species};

const SEEDS: [u64; 5] = [2014, 1, 2, 3, 4];
const AGES: [f32; 3] = [15.0, 30.0, 40.0];

fn median(mut values: Vec<f32>) -> f32 {
    values.sort_by(f32::total_cmp);
    values[values.len() / 2]
}

/// The breast-height diameter of `tree` with exponent `n` (0 when the trunk is shorter).
fn diameter_with(tree: &mut Tree, n: f32) -> f32 {
    let kept = tree.species.pipe_exponent;
    tree.species.pipe_exponent = n;
    tree.update_widths();
    let d = tree.trunk_diameter_at(BREAST_HEIGHT_M).unwrap_or(0.0);
    if std::env::var_os("SYLVA_LEAFY").is_some() {
        let limit = tree.species.tip_diameter_m * tree.species.looks().leafy_diameters;
        let leafy = tree
            .skeleton
            .internodes
            .iter()
            .filter(|i| i.diameter < limit)
            .count();
        println!(
            "  {} n={n}: {leafy} of {} internodes leafy",
            tree.species.name,
            tree.skeleton.len()
        );
    }
    tree.species.pipe_exponent = kept;
    tree.update_widths();
    d
}

fn main() {
    let exponents: Vec<f32> = std::env::args()
        .skip(1)
        .filter_map(|a| a.parse().ok())
        .collect();
    for species in Species::presets() {
        let n0 = species.pipe_exponent;
        let candidates: Vec<f32> = std::iter::once(n0)
            .chain(exponents.iter().copied())
            .collect();
        // diameters[age][candidate][seed]
        let mut diameters = vec![vec![Vec::new(); candidates.len()]; AGES.len()];
        for seed in SEEDS {
            let mut tree = Tree::new(species.clone(), seed);
            for (a, &age) in AGES.iter().enumerate() {
                tree.grow_years(age - tree.age_years());
                for (c, &n) in candidates.iter().enumerate() {
                    diameters[a][c].push(diameter_with(&mut tree, n));
                }
            }
        }
        let stated = species.expected.trunk_diameter.as_ref();
        // The fit: the exponent whose medians lie closest to the middles of the stated ranges
        // (sum of squared log ratios over the three ages).
        if let Some(trunk) = stated {
            let scores: Vec<String> = candidates
                .iter()
                .enumerate()
                .map(|(c, n)| {
                    let score: f32 = (0..AGES.len())
                        .map(|a| {
                            let [lo, hi] = trunk.ranges()[a].1;
                            (median(diameters[a][c].clone()) / (0.5 * (lo + hi)))
                                .ln()
                                .powi(2)
                        })
                        .sum();
                    format!("n={n:.2}: {score:.3}")
                })
                .collect();
            println!(
                "{:16} fit (lower is better): {}",
                species.name,
                scores.join(", ")
            );
        }
        for (a, &age) in AGES.iter().enumerate() {
            let range = stated
                .map(|t| t.ranges()[a].1)
                .map_or("none stated".to_string(), |[lo, hi]| {
                    format!("{:.1}–{:.1} cm", lo * 100.0, hi * 100.0)
                });
            let figures: Vec<String> = candidates
                .iter()
                .zip(&diameters[a])
                .map(|(n, ds)| format!("n={n:.2}: {:.1} cm", median(ds.clone()) * 100.0))
                .collect();
            println!(
                "{:16} {age:>2} y: {} (seeds {:?} at n={n0}: {:?} cm); stated {range}",
                species.name,
                figures.join(", "),
                SEEDS,
                diameters[a][0]
                    .iter()
                    .map(|d| (d * 1000.0).round() / 10.0)
                    .collect::<Vec<_>>()
            );
        }
    }
}
