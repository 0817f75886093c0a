//! Helpers shared by the tests: the crack check, the Khronos validator and the re-import check
//! of the geometry and export tests, and measures of grown trees. Each test file uses some of
//! them.
#![allow(dead_code)]

use std::path::{Path, PathBuf};
use std::process::Command;

use glam::Vec3;
use sylva_core::geometry::{BranchStart, TreeMeshes};
use sylva_core::tree::{Internode, Skeleton};

pub struct ValidatorReport {
    pub num_errors: u64,
    pub num_warnings: u64,
    pub text: String,
}

fn workspace_root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("..")
}

/// Runs `node tools/gltf-validator/validate.js` on `path`. Panics, loudly, when node or the
/// validator package is missing: the check must never be skipped silently.
pub fn validate_glb(path: &Path) -> ValidatorReport {
    let script = workspace_root().join("tools/gltf-validator/validate.js");
    let package = workspace_root().join("tools/gltf-validator/node_modules/gltf-validator");
    assert!(
        package.is_dir(),
        "the Khronos glTF validator is not installed: run `bash scripts/setup.sh` \
         (npm install in tools/gltf-validator)"
    );
    let output = Command::new("node")
        .arg(&script)
        .arg(path)
        .output()
        .unwrap_or_else(|e| panic!("cannot run node (needed for the glTF validator): {e}"));
    let text = String::from_utf8_lossy(&output.stdout).into_owned();
    let report: serde_json::Value = serde_json::from_str(&text).unwrap_or_else(|e| {
        panic!(
            "validator gave no JSON report for {} ({e}); stderr: {}",
            path.display(),
            String::from_utf8_lossy(&output.stderr)
        )
    });
    let issues = &report["issues"];
    let count = |key: &str| {
        issues[key]
            .as_u64()
            .unwrap_or_else(|| panic!("report lacks issues.{key}"))
    };
    let num_errors = count("numErrors");
    assert_eq!(
        output.status.success(),
        num_errors == 0,
        "validator exit status disagrees with its report"
    );
    ValidatorReport {
        num_errors,
        num_warnings: count("numWarnings"),
        text,
    }
}

/// The JSON document and the BIN chunk of a binary glTF file.
pub fn glb_chunks(path: &Path) -> (serde_json::Value, Vec<u8>) {
    let glb = std::fs::read(path).expect("the glb reads");
    let word = |at: usize| u32::from_le_bytes(glb[at..at + 4].try_into().expect("a word")) as usize;
    assert_eq!(word(0), 0x4654_6C67, "GLB magic");
    let json_length = word(12);
    let json = serde_json::from_slice(&glb[20..20 + json_length]).expect("the JSON chunk parses");
    let bin_start = 20 + json_length;
    let bin_length = word(bin_start);
    (
        json,
        glb[bin_start + 8..bin_start + 8 + bin_length].to_vec(),
    )
}

/// The bytes of buffer view `view` of a GLB's BIN chunk.
pub fn view_bytes<'a>(json: &serde_json::Value, bin: &'a [u8], view: usize) -> &'a [u8] {
    let view = &json["bufferViews"][view];
    let offset = view["byteOffset"].as_u64().unwrap_or(0) as usize;
    let length = view["byteLength"].as_u64().expect("a view length") as usize;
    &bin[offset..offset + length]
}

/// Re-reads `path` with glTF Transform (a real reader that dequantizes attributes and expands
/// instances) and checks, per level of detail (the scene's one node and the nodes its
/// `MSFT_lod` lists), the triangles drawn (mesh triangles times instances, the leaf cards'
/// included) and the bounds of everything drawn against `meshes` (within the quantization's
/// step), plus textured bark and leaf materials and their two images.
pub fn assert_reimport_matches(path: &Path, meshes: &TreeMeshes) {
    let report = read_glb_with_gltf_transform(path);
    let levels = report["levels"].as_array().expect("levels");
    assert_eq!(
        levels.len(),
        meshes.lods.len(),
        "a node per level of detail"
    );
    assert_eq!(report["default_scene"], 0);
    for (level, node) in levels.iter().enumerate() {
        assert_eq!(
            node["drawn_triangles"].as_u64(),
            Some(meshes.num_triangles(level) as u64),
            "LOD{level} triangles"
        );
        let (expected_lo, expected_hi) = meshes.bounds(level).expect("bounds");
        let corner = |key: &str| -> Vec3 {
            let v = node[key].as_array().expect("a bound");
            Vec3::from([0, 1, 2].map(|i| v[i].as_f64().expect("a number") as f32))
        };
        let (lo, hi) = (corner("min"), corner("max"));
        // Positions are quantized to 1/32767 of the tree's half extent.
        let step = (expected_hi - expected_lo).max_element() / 32_767.0;
        assert!(
            lo.abs_diff_eq(expected_lo, 2.0 * step + 1e-5)
                && hi.abs_diff_eq(expected_hi, 2.0 * step + 1e-5),
            "LOD{level} bounds {lo}..{hi} against {expected_lo}..{expected_hi}"
        );
    }
    let (json, bin) = glb_chunks(path);
    let material = |name: &str| {
        json["materials"]
            .as_array()
            .expect("materials")
            .iter()
            .find(|m| m["name"] == name)
            .unwrap_or_else(|| panic!("no {name} material"))
            .clone()
    };
    let leaf = material("leaf");
    assert!(
        leaf["pbrMetallicRoughness"]["baseColorTexture"].is_object(),
        "leaf texture"
    );
    assert_eq!(leaf["alphaMode"], "MASK");
    assert!(
        material("bark")["pbrMetallicRoughness"]["baseColorTexture"].is_object(),
        "bark texture"
    );
    assert!(meshes.leaves.num_triangles() > 0, "the tree has leaves");
    let images = json["images"].as_array().expect("images");
    // A billboard-cloud level (the coarsest) carries its own leaf atlas.
    let atlases = meshes
        .lods
        .iter()
        .filter(|lod| lod.billboards.is_some() && lod.num_leaf_indices > 0)
        .count();
    assert_eq!(images.len(), 2 + atlases, "bark, leaf and atlas images");
    for image in images {
        let view = image["bufferView"].as_u64().expect("an embedded image") as usize;
        let decoded = image::load_from_memory(view_bytes(&json, &bin, view)).expect("a PNG");
        assert!(decoded.width() >= 64 && decoded.height() >= 64);
    }
}

/// The parent's tube around the branching point as the rings define it: closest point on the
/// parent internode or its continuation, radius interpolated between the rings at their ends.
fn parent_tube(
    skeleton: &Skeleton,
    start: &BranchStart,
    tip_taper: f32,
    point: Vec3,
) -> (f32, f32) {
    let (parent, continuation) = start.parent.expect("a lateral branch");
    let continuation_next = |node: &Internode| {
        node.children()
            .map(|c| skeleton.get(c).diameter)
            .fold(None, |best: Option<f32>, d| {
                Some(best.map_or(d, |b| b.max(d)))
            })
    };
    let mut best = (f32::INFINITY, 0.0);
    for id in [parent, continuation] {
        let node = skeleton.get(id);
        let end_radius = match continuation_next(node) {
            Some(d) => 0.5 * d,
            None => 0.5 * node.diameter * tip_taper,
        };
        let axis = node.end - node.start;
        let t = ((point - node.start).dot(axis) / axis.length_squared()).clamp(0.0, 1.0);
        let distance = point.distance(node.start + axis * t);
        if distance < best.0 {
            best = (
                distance,
                0.5 * node.diameter + (end_radius - 0.5 * node.diameter) * t,
            );
        }
    }
    best
}

pub fn assert_no_cracks(skeleton: &Skeleton, meshes: &TreeMeshes, tip_taper: f32) -> usize {
    let lod = &meshes.lods[0];
    let mut checked = 0;
    for start in lod.branch_starts.iter().filter(|s| s.parent.is_some()) {
        for k in 0..=start.sides {
            let p = Vec3::from(lod.branches.positions[(start.first_vertex + k) as usize]);
            let (distance, radius) = parent_tube(skeleton, start, tip_taper, p);
            assert!(
                (distance - radius).abs() <= 0.05 * radius,
                "branch at internode {}: ring vertex {k} is {distance} from the parent axis, radius {radius}",
                start.node.0
            );
            checked += 1;
        }
    }
    checked
}

/// Mean H·Y (signed: up > 0) of the internodes whose branch order lies in `orders`.
pub fn mean_rise(tree: &sylva_core::Tree, orders: std::ops::RangeInclusive<u32>) -> f32 {
    let rises: Vec<f32> = tree
        .skeleton
        .internodes
        .iter()
        .filter(|n| orders.contains(&n.order))
        .map(|n| n.heading().y)
        .collect();
    rises.iter().sum::<f32>() / rises.len().max(1) as f32
}

/// The median of `values` (the upper one of an even count), as the suite holds presets over
/// seeds.
pub fn median(mut values: Vec<f32>) -> f32 {
    values.sort_by(f32::total_cmp);
    values[values.len() / 2]
}

/// The lowest height of any vertex of `mesh` (+∞ for an empty mesh).
pub fn lowest_y(mesh: &sylva_core::geometry::TreeMesh) -> f32 {
    mesh.positions
        .iter()
        .fold(f32::INFINITY, |y, p| y.min(p[1]))
}

/// What glTF Transform (`node tools/gltf-reader/read.mjs`, a real reader) finds in `path`: its
/// JSON report. Panics, loudly, when node or the package is missing: the check must never be
/// skipped silently.
pub fn read_glb_with_gltf_transform(path: &Path) -> serde_json::Value {
    let script = workspace_root().join("tools/gltf-reader/read.mjs");
    let package = workspace_root().join("tools/gltf-reader/node_modules/@gltf-transform");
    assert!(
        package.join("core").is_dir() && package.join("extensions").is_dir(),
        "glTF Transform is not installed: run `bash scripts/setup.sh` (npm install in \
         tools/gltf-reader)"
    );
    let output = Command::new("node")
        .arg(&script)
        .arg(path)
        .output()
        .expect("node runs (install nodejs)");
    assert!(
        output.status.success(),
        "glTF Transform failed on {}: {}",
        path.display(),
        String::from_utf8_lossy(&output.stderr)
    );
    serde_json::from_slice(&output.stdout).expect("the reader prints JSON")
}
