//! How far the coarsest level of detail's side view departs from the finest level's for every
//! species preset at 15 and 40 years (seed 11), measured as `core/tests/foliage_density.rs`
//! does (`geometry::silhouette`), with the coarsest level's quads and triangle share.
//!
//! `cargo run --release -p sylva-core --example lod_silhouette [cache_dir]`: with `cache_dir`,
//! the grown trees are kept there as tree files (`<preset>-<age>.sylva`) and read back on the
//! next run, so that a change to the meshing is measured without growing the trees again.

use std::path::{Path, PathBuf};

use sylva_core::Tree;
use sylva_core::geometry::build_tree_meshes;
use sylva_core::geometry::silhouette::side_silhouette_difference;
use sylva_core::species::Species;

const SEED: u64 = 11;
const AGES_YEARS: [f32; 2] = [15.0, 40.0];

fn main() {
    let cache = std::env::args().nth(1).map(PathBuf::from);
    println!(
        "{:<16} {:>5} {:>8} {:>9} {:>10}",
        "preset", "years", "quads", "coarsest", "silhouette"
    );
    let mut worst = 0.0f32;
    for species in Species::presets() {
        let name = species.name.clone();
        let mut tree = Tree::new(species, SEED);
        for age_years in AGES_YEARS {
            let tree = match grown(&mut tree, &name, age_years, cache.as_deref()) {
                Ok(tree) => tree,
                Err(e) => {
                    println!("{name:<16} {age_years:>5}: {e}");
                    continue;
                }
            };
            let meshes = build_tree_meshes(&tree);
            let coarsest = meshes.lods.len() - 1;
            let share =
                meshes.num_triangles(coarsest) as f32 / meshes.num_triangles(0).max(1) as f32;
            let quads = meshes.lods[coarsest]
                .billboards
                .as_ref()
                .map_or(0, |cloud| cloud.num_quads());
            let difference = side_silhouette_difference(&meshes, coarsest).unwrap_or(f32::NAN);
            worst = worst.max(difference);
            println!(
                "{name:<16} {age_years:>5} {quads:>8} {:>8.1}% {:>9.1}%",
                100.0 * share,
                100.0 * difference
            );
        }
    }
    println!("worst: {:.1}%", 100.0 * worst);
}

/// `tree` grown on to `age_years`, or the cached tree of that preset and age when there is one
/// (writing it there when there is not).
fn grown(
    tree: &mut Tree,
    name: &str,
    age_years: f32,
    cache: Option<&Path>,
) -> Result<Tree, String> {
    let path = cache.map(|dir| dir.join(format!("{name}-{age_years}.sylva")));
    if let Some(path) = path.as_ref().filter(|p| p.exists()) {
        let cached = Tree::load(path).map_err(|e| format!("{}: {e}", path.display()))?;
        *tree = cached.clone();
        return Ok(cached);
    }
    tree.grow_years(age_years - tree.age_years());
    if let Some(path) = &path {
        tree.save(path)
            .map_err(|e| format!("{}: {e}", path.display()))?;
    }
    Ok(tree.clone())
}
