//! Every species preset, grown for ten years, meshed with its own look and exported: the Khronos
//! validator reports no errors, the re-imported file matches the meshes, the branches have no
//! cracks and the levels of detail hit their triangle targets.

mod support;

use sylva_core::Tree;
use sylva_core::export::{GlbOptions, write_glb, write_glb_with};
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
            (report.num_errors, report.num_warnings),
            (0, 0),
            "{name}: validator errors and warnings: {}",
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

/// The largest `.glb` and the most triangles at LOD0 a 40-year tree may have (issue #25).
const MAX_GLB_BYTES: usize = 15_000_000;
const MAX_LOD0_TRIANGLES: u64 = 600_000;

#[test]
fn every_preset_at_40_years_exports_a_valid_glb_within_15_mb_and_600k_triangles() {
    let dir = tempfile::tempdir().expect("temp dir");
    let mut failures = Vec::new();
    for species in Species::presets() {
        let name = species.name.clone();
        let mut tree = Tree::new(species, SEED);
        tree.grow_years(40.0);
        let meshes = build_tree_meshes(&tree);
        let path = dir.path().join(format!("{name}.glb"));
        write_glb(&meshes, &path).unwrap_or_else(|e| panic!("{name}: {e}"));
        let bytes = std::fs::metadata(&path).expect("written").len() as usize;
        let report = support::validate_glb(&path);
        // Triangles as a reader draws them: bark and fruit, plus the leaf card mesh's
        // triangles times its instances (glTF Transform expands EXT_mesh_gpu_instancing).
        let read = support::read_glb_with_gltf_transform(&path);
        let drawn = read["levels"][0]["drawn_triangles"]
            .as_u64()
            .expect("LOD0 triangles");
        let coarsest = meshes.lods.len() - 1;
        let ratio = meshes.num_triangles(coarsest) as f32 / meshes.num_triangles(0) as f32;
        println!(
            "{name}: {:.2} MB, LOD0 {drawn} triangles ({} own, {} in leaf instances), \
             LOD{coarsest} {:.1}% of them; validator {} errors {} warnings",
            bytes as f64 * 1e-6,
            meshes.num_triangles(0) - meshes.lods[0].num_leaf_indices / 3,
            meshes.lods[0].num_leaf_indices / 3,
            100.0 * ratio,
            report.num_errors,
            report.num_warnings
        );
        assert_eq!(
            drawn,
            meshes.num_triangles(0) as u64,
            "{name}: LOD0 read back"
        );
        if bytes > MAX_GLB_BYTES {
            failures.push(format!("{name}: {bytes} bytes"));
        }
        if drawn > MAX_LOD0_TRIANGLES {
            failures.push(format!("{name}: {drawn} triangles at LOD0"));
        }
        if ratio > 0.15 + 1e-3 {
            failures.push(format!("{name}: the coarsest level has {ratio:.3} of them"));
        }
        if report.num_errors + report.num_warnings > 0 {
            failures.push(format!("{name}: validator: {}", report.text));
        }
        failures.extend(compat_failures(&name, &meshes, dir.path()));
    }
    assert!(failures.is_empty(), "{}", failures.join("\n"));
}

/// What is wrong with the `--glb-compat` file of `meshes` (for Blender 3.4, which refuses
/// `EXT_mesh_gpu_instancing` and stacks `MSFT_lod` levels): it must pass the validator, need
/// neither extension, and draw LOD0's triangles as one tree with no other level.
fn compat_failures(
    name: &str,
    meshes: &sylva_core::geometry::TreeMeshes,
    dir: &std::path::Path,
) -> Vec<String> {
    let path = dir.join(format!("{name}.compat.glb"));
    write_glb_with(meshes, &path, GlbOptions::compat()).unwrap_or_else(|e| panic!("{name}: {e}"));
    let bytes = std::fs::metadata(&path).expect("written").len();
    let report = support::validate_glb(&path);
    let read = support::read_glb_with_gltf_transform(&path);
    let (json, _) = support::glb_chunks(&path);
    let used = json["extensionsUsed"].to_string();
    println!(
        "{name}: compat {:.2} MB, extensions {used}, validator {} errors {} warnings",
        bytes as f64 * 1e-6,
        report.num_errors,
        report.num_warnings
    );
    let mut failures = Vec::new();
    if report.num_errors + report.num_warnings > 0 {
        failures.push(format!("{name}: compat validator: {}", report.text));
    }
    for extension in ["EXT_mesh_gpu_instancing", "MSFT_lod"] {
        if used.contains(extension) {
            failures.push(format!("{name}: compat file uses {extension}"));
        }
    }
    let nodes = json["nodes"].as_array().map_or(0, Vec::len);
    let levels = read["levels"].as_array().map_or(0, Vec::len);
    let drawn = read["levels"][0]["drawn_triangles"].as_u64();
    if nodes != 1 || levels != 1 || drawn != Some(meshes.num_triangles(0) as u64) {
        failures.push(format!(
            "{name}: compat file has {nodes} nodes, {levels} levels, {drawn:?} triangles \
             for LOD0's {}",
            meshes.num_triangles(0)
        ));
    }
    failures
}
