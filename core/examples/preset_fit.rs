//! Tries a species preset with some of its values replaced, on three seeds: height, spread and
//! internodes at 10, 15 and 30 years against the preset's stated figures, the lean at 15 and 30
//! years, and the worst deviation and lean. The tool the presets were refitted with.
//!
//! `cargo run --release -p sylva-core --example preset_fit -- birch apical_dominance=0.56 ...`
//! (values as JSON: numbers, `true`, `"spiral"`). `SYLVA_SEEDS=1,2,3` tries other seeds.

#[path = "common/overrides.rs"]
mod overrides;
#[path = "common/seeds.rs"]
mod seeds;

use sylva_core::Tree;

/// Seeds tried: the suite's, the README pictures', the benchmark's.
const SEEDS: [u64; 3] = [2014, 11, 7];

fn main() {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let Some(name) = args.first() else {
        eprintln!("usage: preset_fit PRESET [field=json ...]");
        std::process::exit(2);
    };
    let species = overrides::species_with_overrides(name, &args[1..]);
    let e = species.expected.clone();
    let seeds = seeds::seeds_from_env(&SEEDS);
    let (mut worst, mut worst_lean) = (0.0f32, 0.0f32);
    for seed in seeds {
        let [at10, at15, at30] = Tree::metrics_at_ages(&species, seed, &[10.0, 15.0, 30.0])[..]
        else {
            unreachable!("three ages, three metrics")
        };
        println!(
            "seed {seed:5}: 10y h {:5.2}/{:5.2} w {:5.2}/{:5.2} n {:6} | 15y n {:6} | \
             30y h {:5.2}/{:5.2} w {:5.2}/{:5.2} n {:6} trunk {:.3} m lean {:.2}/{:.2}",
            at10.height_m,
            e.height_10y_m,
            at10.crown_width_m,
            e.spread_10y_m,
            at10.num_internodes,
            at15.num_internodes,
            at30.height_m,
            e.height_30y_m,
            at30.crown_width_m,
            e.spread_30y_m,
            at30.num_internodes,
            at30.trunk_diameter_m,
            at15.lean,
            at30.lean
        );
        worst_lean = worst_lean.max(at15.lean).max(at30.lean);
        for (_, measured, expected) in e.against(&at10, &at30) {
            worst = worst.max((measured / expected - 1.0).abs());
        }
    }
    println!(
        "worst deviation {:.0}%, worst lean {worst_lean:.2} (at 15 and 30 years)",
        worst * 100.0
    );
}
