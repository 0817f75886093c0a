//! `sylva grow --glb --glb-compat`: the `.glb` for readers without `EXT_mesh_gpu_instancing`
//! and `MSFT_lod` (Blender 3.4 refuses the first and stacks the levels of the second): one
//! node, the finest level's triangles as plain primitives, only the extensions Blender 3.4's
//! importer reads.

use std::process::Command;

/// The JSON chunk of a binary glTF file.
fn glb_json(path: &std::path::Path) -> serde_json::Value {
    let bytes = std::fs::read(path).expect("glb written");
    let length = u32::from_le_bytes(bytes[12..16].try_into().expect("chunk header")) as usize;
    serde_json::from_slice(&bytes[20..20 + length]).expect("json")
}

#[test]
fn a_compat_glb_is_one_plain_node_of_the_finest_level_needing_only_quantization() {
    let dir = tempfile::tempdir().expect("temp dir");
    let (json, glb) = (dir.path().join("oak.json"), dir.path().join("oak.glb"));
    let output = Command::new(env!("CARGO_BIN_EXE_sylva"))
        .args([
            "grow",
            "--species",
            "oak",
            "--years",
            "8",
            "--seed",
            "3",
            "--out",
        ])
        .arg(&json)
        .arg("--glb")
        .arg(&glb)
        .arg("--glb-compat")
        .output()
        .expect("sylva runs");
    let text = String::from_utf8_lossy(&output.stdout);
    assert!(output.status.success(), "{output:?}");
    // lod_triangles=[a, b, c]: the finest level's triangles come first.
    let finest: usize = text
        .lines()
        .find_map(|l| l.split("lod_triangles=[").nth(1))
        .and_then(|rest| rest.split(',').next())
        .and_then(|n| n.trim().parse().ok())
        .unwrap_or_else(|| panic!("no lod_triangles in {text}"));
    let doc = glb_json(&glb);
    let required: Vec<&str> = doc["extensionsRequired"]
        .as_array()
        .expect("required extensions")
        .iter()
        .filter_map(|e| e.as_str())
        .collect();
    assert_eq!(required, ["KHR_mesh_quantization", "KHR_texture_transform"]);
    let used = doc["extensionsUsed"].to_string();
    assert!(
        !used.contains("EXT_mesh_gpu_instancing") && !used.contains("MSFT_lod"),
        "{used}"
    );
    assert_eq!(doc["nodes"].as_array().map(Vec::len), Some(1));
    let accessors = doc["accessors"].as_array().expect("accessors");
    let triangles: u64 = doc["meshes"][0]["primitives"]
        .as_array()
        .expect("primitives")
        .iter()
        .map(|p| {
            accessors[p["indices"].as_u64().expect("indexed") as usize]["count"]
                .as_u64()
                .unwrap_or(0)
                / 3
        })
        .sum();
    assert_eq!(triangles, finest as u64, "{text}");
    let materials = doc["materials"].to_string();
    assert!(
        materials.contains("\"leaf\""),
        "no leaf material: {materials}"
    );
}

#[test]
fn glb_compat_without_glb_is_refused() {
    let dir = tempfile::tempdir().expect("temp dir");
    let output = Command::new(env!("CARGO_BIN_EXE_sylva"))
        .args(["grow", "--species", "oak", "--years", "2", "--out"])
        .arg(dir.path().join("oak.json"))
        .arg("--glb-compat")
        .output()
        .expect("sylva runs");
    assert!(!output.status.success());
    let err = String::from_utf8_lossy(&output.stderr);
    assert!(err.contains("--glb"), "{err}");
}
