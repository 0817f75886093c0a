//! `sylva species` and `sylva grow`: the growth model from the command line.

use std::path::{Path, PathBuf};
use std::time::Instant;

use anyhow::Context;
use sylva_core::Tree;
use sylva_core::species::Species;

/// Arguments of `sylva grow`.
#[derive(clap::Args, Debug)]
pub struct GrowArgs {
    /// A preset name (see `sylva species`) or a species JSON file.
    #[arg(long)]
    pub species: String,
    /// Years of autonomous growth.
    #[arg(long)]
    pub years: f32,
    /// Seed of the tree's random generator.
    #[arg(long, default_value_t = 1)]
    pub seed: u64,
    /// Where to save the grown tree (versioned JSON).
    #[arg(long)]
    pub out: PathBuf,
}

/// Prints one line per preset, starting with its name.
pub fn species() -> anyhow::Result<()> {
    for s in Species::presets() {
        let e = &s.expected;
        println!(
            "{:16} {} ({}): {:.1} m tall, {:.1} m wide at 10 years; {:.1} m tall, {:.1} m wide at 30 years",
            s.name,
            s.common_name,
            s.latin_name,
            e.height_10y_m,
            e.spread_10y_m,
            e.height_30y_m,
            e.spread_30y_m
        );
    }
    Ok(())
}

fn load_species(name_or_file: &str) -> anyhow::Result<Species> {
    match Species::by_name(name_or_file) {
        Ok(s) => Ok(s),
        Err(preset_error) => {
            let path = Path::new(name_or_file);
            if path.exists() {
                Ok(Species::from_file(path)?)
            } else {
                Err(preset_error)
                    .context(format!("{name_or_file:?} is neither a preset nor a file"))
            }
        }
    }
}

/// Grows a tree autonomously, saves it and prints a `key=value` summary line.
pub fn grow(args: GrowArgs) -> anyhow::Result<()> {
    if !(args.years.is_finite() && args.years >= 0.0) {
        anyhow::bail!("--years must be a non-negative number, got {}", args.years);
    }
    let species = load_species(&args.species)?;
    let started = Instant::now();
    let mut tree = Tree::new(species, args.seed);
    tree.grow_years(args.years);
    let elapsed_ms = started.elapsed().as_secs_f64() * 1000.0;
    tree.save(&args.out)?;
    let m = tree.metrics();
    println!(
        "internodes={} height_m={:.3} crown_width_m={:.3} trunk_diameter_m={:.4} elapsed_ms={:.1}",
        m.num_internodes, m.height_m, m.crown_width_m, m.trunk_diameter_m, elapsed_ms
    );
    Ok(())
}
