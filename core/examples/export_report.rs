//! The 40-year export of every species preset (issue #25): the `.glb`'s bytes, LOD0's triangles
//! (its own, i.e. bark and fruit, plus the instanced leaf cards' triangles: the card mesh's
//! triangles times its instances), the coarsest level's share of them and how far its side
//! silhouette departs from LOD0's (`geometry::lod_silhouette`).
//!
//! The `compat MB` column is the same tree written for readers without
//! `EXT_mesh_gpu_instancing` and `MSFT_lod` (`GlbOptions::compat`: LOD0 only, cards as plain
//! triangles; Blender 3.4's importer).
//!
//! `cargo run --release -p sylva-core --example export_report [age_years] [seed] [dir]`: with
//! `dir`, the files are written there too (`<preset>.glb`, `<preset>.compat.glb`).

use sylva_core::Tree;
use sylva_core::export::{GlbOptions, glb_bytes, glb_bytes_with};
use sylva_core::geometry::build_tree_meshes;
use sylva_core::geometry::silhouette::side_silhouette_difference;
use sylva_core::species::Species;

fn main() {
    let mut args = std::env::args().skip(1);
    let age_years: f32 = args.next().and_then(|a| a.parse().ok()).unwrap_or(40.0);
    let seed: u64 = args.next().and_then(|a| a.parse().ok()).unwrap_or(11);
    let dir = args.next().map(std::path::PathBuf::from);
    println!("{age_years}-year trees, seed {seed}");
    println!(
        "{:<16} {:>8} {:>9} {:>10} {:>10} {:>10} {:>9} {:>9} {:>10}",
        "preset",
        "glb MB",
        "compat MB",
        "LOD0 tris",
        "own",
        "instanced",
        "cards",
        "coarsest",
        "silhouette"
    );
    for species in Species::presets() {
        let name = species.name.clone();
        let mut tree = Tree::new(species, seed);
        tree.grow_years(age_years);
        let meshes = build_tree_meshes(&tree);
        let finest = &meshes.lods[0];
        let instanced = finest.num_leaf_indices / 3;
        let total = meshes.num_triangles(0);
        let coarsest = meshes.lods.len() - 1;
        let ratio = meshes.num_triangles(coarsest) as f32 / total.max(1) as f32;
        let glb = match glb_bytes(&meshes) {
            Ok(glb) => glb,
            Err(e) => {
                println!("{name:<16} cannot export: {e}");
                continue;
            }
        };
        let compat = match glb_bytes_with(&meshes, GlbOptions::compat()) {
            Ok(compat) => compat,
            Err(e) => {
                println!("{name:<16} cannot export without instancing: {e}");
                continue;
            }
        };
        if let Some(dir) = &dir {
            for (file, bytes) in [
                (format!("{name}.glb"), &glb),
                (format!("{name}.compat.glb"), &compat),
            ] {
                let path = dir.join(file);
                if let Err(e) = std::fs::write(&path, bytes) {
                    println!("{name:<16} cannot write {}: {e}", path.display());
                }
            }
        }
        let bytes = glb.len() as f64 * 1e-6;
        let silhouette = side_silhouette_difference(&meshes, coarsest)
            .map_or("-".to_string(), |d| format!("{:.1}%", 100.0 * d));
        println!(
            "{:<16} {:>8.2} {:>9.2} {:>10} {:>10} {:>10} {:>9} {:>8.1}% {:>10}",
            name,
            bytes,
            compat.len() as f64 * 1e-6,
            total,
            total - instanced,
            instanced,
            finest.num_leaf_indices / 6,
            100.0 * ratio,
            silhouette,
        );
        for lod in &meshes.lods {
            println!(
                "    LOD{} bark {} tris ({} vertices), leaves {} tris, fruit {} tris",
                lod.level,
                lod.branches.num_triangles(),
                lod.branches.num_vertices(),
                lod.num_leaf_indices / 3,
                lod.num_fruit_indices / 3
            );
        }
    }
}
