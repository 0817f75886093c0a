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

/// The nodes of the levels of detail of a glTF document, finest first: the one node of its one
/// scene, then the nodes its `MSFT_lod` extension lists (read from the JSON chunk of `glb`).
pub fn lod_nodes<'a>(document: &'a gltf::Document, glb: &[u8]) -> Vec<gltf::Node<'a>> {
    assert_eq!(document.scenes().count(), 1, "one scene");
    let scene = document.scenes().next().expect("a scene");
    let roots: Vec<gltf::Node> = scene.nodes().collect();
    assert_eq!(roots.len(), 1, "one tree in the scene");
    let json_length = u32::from_le_bytes(glb[12..16].try_into().expect("GLB header")) as usize;
    let json: serde_json::Value =
        serde_json::from_slice(&glb[20..20 + json_length]).expect("the JSON chunk parses");
    let finest = roots[0].index();
    let ids: Vec<usize> = json["nodes"][finest]["extensions"]["MSFT_lod"]["ids"]
        .as_array()
        .map(|ids| {
            ids.iter()
                .map(|i| i.as_u64().expect("a node id") as usize)
                .collect()
        })
        .unwrap_or_default();
    let mut nodes = vec![roots[0].clone()];
    nodes.extend(
        ids.into_iter()
            .map(|i| document.nodes().nth(i).expect("an LOD node")),
    );
    nodes
}

/// Re-imports `path` with the `gltf` crate and checks, per level of detail (the scene's one
/// node and its `MSFT_lod` levels), the triangle count and bounds against `meshes`, plus
/// textured bark and leaf materials.
pub fn assert_reimport_matches(path: &Path, meshes: &TreeMeshes) {
    let (document, buffers, images) = gltf::import(path).expect("the glb imports");
    let glb = std::fs::read(path).expect("the glb reads");
    let levels = lod_nodes(&document, &glb);
    assert_eq!(
        levels.len(),
        meshes.lods.len(),
        "a node per level of detail"
    );
    assert_eq!(document.default_scene().map(|s| s.index()), Some(0));
    for (level, node) in levels.iter().enumerate() {
        let mut triangles = 0;
        let mut lo = glam::Vec3::splat(f32::INFINITY);
        let mut hi = glam::Vec3::splat(f32::NEG_INFINITY);
        let mesh = node.mesh().expect("a mesh per level");
        for primitive in mesh.primitives() {
            let reader = primitive.reader(|b| Some(&buffers[b.index()]));
            triangles += reader.read_indices().expect("indexed").into_u32().count() / 3;
            let positions: Vec<[f32; 3]> = reader.read_positions().expect("positions").collect();
            assert!(reader.read_normals().is_some());
            // Only textured parts carry texture coordinates (the fruit has none).
            let textured = primitive
                .material()
                .pbr_metallic_roughness()
                .base_color_texture()
                .is_some();
            assert_eq!(reader.read_tex_coords(0).is_some(), textured);
            for p in positions {
                lo = lo.min(p.into());
                hi = hi.max(p.into());
            }
        }
        assert_eq!(
            triangles,
            meshes.num_triangles(level),
            "LOD{level} triangles"
        );
        let (expected_lo, expected_hi) = meshes.bounds(level).expect("bounds");
        assert!(
            lo.abs_diff_eq(expected_lo, 1e-6) && hi.abs_diff_eq(expected_hi, 1e-6),
            "LOD{level} bounds"
        );
    }
    let material = |name: &str| {
        document
            .materials()
            .find(|m| m.name() == Some(name))
            .unwrap_or_else(|| panic!("no {name} material"))
    };
    let leaf = material("leaf");
    assert!(
        leaf.pbr_metallic_roughness().base_color_texture().is_some(),
        "leaf texture"
    );
    assert_eq!(leaf.alpha_mode(), gltf::material::AlphaMode::Mask);
    assert!(
        material("bark")
            .pbr_metallic_roughness()
            .base_color_texture()
            .is_some(),
        "bark texture"
    );
    assert!(meshes.leaves.num_triangles() > 0, "the tree has leaves");
    assert_eq!(images.len(), 2, "bark and leaf images");
    assert!(images.iter().all(|i| i.width >= 64 && i.height >= 64));
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
    let package = workspace_root().join("tools/gltf-reader/node_modules/@gltf-transform/core");
    assert!(
        package.is_dir(),
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
