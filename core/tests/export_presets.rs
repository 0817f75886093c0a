//! Every species preset, grown for ten years, meshed with its own look and exported: the Khronos
//! validator reports no errors, the re-imported file matches the meshes, the branches have no
//! cracks and the levels of detail hit their triangle targets.

mod support;

use sylva_core::Tree;
use sylva_core::export::write_glb;
use sylva_core::geometry::{LOD_TRIANGLE_FRACTIONS, build_tree_meshes, mesh_params_for};
use sylva_core::species::Species;

const SEED: u64 = 11;
const AGE_YEARS: f32 = 10.0;

#[test]
fn every_preset_exports_a_valid_crack_free_glb_with_leaves_and_lods_on_target() {
    let presets = Species::presets();
    assert!(presets.len() >= 6, "only {} presets", presets.len());
    let dir = tempfile::tempdir().expect("temp dir");
    for species in presets {
        let name = species.name.clone();
        let params = mesh_params_for(&species);
        let mut tree = Tree::new(species, SEED);
        tree.grow_years(AGE_YEARS);
        let meshes = build_tree_meshes(&tree);
        assert!(meshes.leaves.num_triangles() > 0, "{name}: no leaves");

        let path = dir.path().join(format!("{name}.glb"));
        write_glb(&meshes, &path).unwrap_or_else(|e| panic!("{name}: {e}"));
        let report = support::validate_glb(&path);
        let full = meshes.num_triangles(0) as f32;
        let fractions: Vec<String> = (0..3)
            .map(|l| {
                format!(
                    "{} ({:.3})",
                    meshes.num_triangles(l),
                    meshes.num_triangles(l) as f32 / full
                )
            })
            .collect();
        println!(
            "{name}: {} internodes, LOD triangles {}, validator {} errors {} warnings",
            tree.skeleton.len(),
            fractions.join(" / "),
            report.num_errors,
            report.num_warnings
        );
        assert_eq!(
            report.num_errors, 0,
            "{name}: validator errors: {}",
            report.text
        );
        support::assert_reimport_matches(&path, &meshes);
        support::assert_no_cracks(&tree.skeleton, &meshes, params.tip_taper);
        for (level, target) in LOD_TRIANGLE_FRACTIONS.iter().enumerate() {
            let fraction = meshes.num_triangles(level) as f32 / full;
            assert!(
                (fraction - target).abs() <= 0.1 * target,
                "{name}: LOD{level} draws {fraction:.3} of the triangles, target {target}"
            );
        }
    }
}
