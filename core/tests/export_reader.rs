//! Every preset's `.glb` read by a real glTF reader that honours the extensions it uses
//! (glTF Transform with its extensions, `tools/gltf-reader`: quantized attributes come back
//! dequantized, instanced leaf cards with their instance transforms): one tree in one scene,
//! the finest level's triangles (the bark's and fruit's plus the leaf card mesh's triangles
//! times its instances), one instance per leaf card, the bounds of everything drawn, and no
//! leaf below the ground (issue #25).

mod support;

use sylva_core::Tree;
use sylva_core::export::write_glb;
use sylva_core::geometry::build_tree_meshes;
use sylva_core::species::Species;

const SEED: u64 = 11;
const AGE_YEARS: f32 = 15.0;

/// Every primitive of `node` and its children, with the instances drawing it.
fn primitives(node: &serde_json::Value, out: &mut Vec<(serde_json::Value, u64)>) {
    let instances = node["instances"].as_u64().expect("instances");
    for primitive in node["primitives"].as_array().expect("primitives") {
        out.push((primitive.clone(), instances));
    }
    for child in node["children"].as_array().expect("children") {
        primitives(child, out);
    }
}

#[test]
fn a_real_reader_finds_one_tree_per_scene_with_the_finest_levels_triangles_instances_and_bounds() {
    let dir = tempfile::tempdir().expect("temp dir");
    for species in Species::presets() {
        let name = species.name.clone();
        let mut tree = Tree::new(species, SEED);
        tree.grow_years(AGE_YEARS);
        let meshes = build_tree_meshes(&tree);
        let path = dir.path().join(format!("{name}.glb"));
        write_glb(&meshes, &path).expect("glb written");
        let report = support::read_glb_with_gltf_transform(&path);
        let required = report["extensions_required"].as_array().expect("required");
        for extension in ["KHR_mesh_quantization", "EXT_mesh_gpu_instancing"] {
            assert!(
                required.iter().any(|e| e == extension),
                "{name}: {extension} not required: {required:?}"
            );
        }
        let scenes = report["scenes"].as_array().expect("scenes");
        assert_eq!(scenes.len(), 1, "{name}: one scene");
        assert_eq!(report["default_scene"], 0, "{name}: the default scene");
        let nodes = scenes[0]["nodes"].as_array().expect("nodes");
        assert_eq!(nodes.len(), 1, "{name}: one tree in the scene");
        let tree_node = &nodes[0];
        assert_eq!(
            tree_node["instances"], 1,
            "{name}: one instance of the tree"
        );
        // Triangles drawn: each mesh's triangles times its instances (the leaf cards').
        assert_eq!(
            tree_node["drawn_triangles"].as_u64(),
            Some(meshes.num_triangles(0) as u64),
            "{name}: the finest level's triangles"
        );
        let mut parts = Vec::new();
        primitives(tree_node, &mut parts);
        let leaf_instances: u64 = parts
            .iter()
            .filter(|(p, _)| p["material"] == "leaf")
            .map(|(_, instances)| instances)
            .sum();
        assert_eq!(
            leaf_instances,
            (meshes.lods[0].num_leaf_indices / 6) as u64,
            "{name}: one instance per leaf card"
        );
        let (lo, hi) = meshes.bounds(0).expect("bounds");
        let step = (hi - lo).max_element() / 32_767.0;
        let corner = |key: &str| -> [f32; 3] {
            let v = tree_node[key].as_array().expect("a bound");
            [0, 1, 2].map(|i| v[i].as_f64().expect("a number") as f32)
        };
        let (min, max) = (corner("min"), corner("max"));
        for axis in 0..3 {
            assert!(
                (min[axis] - lo[axis]).abs() <= 2.0 * step + 1e-5
                    && (max[axis] - hi[axis]).abs() <= 2.0 * step + 1e-5,
                "{name}: bounds {min:?}..{max:?} against {lo}..{hi}"
            );
        }
        let lowest = parts
            .iter()
            .filter(|(p, _)| p["material"] == "leaf")
            .map(|(p, _)| p["lowest_y"].as_f64().expect("a height") as f32)
            .fold(f32::INFINITY, f32::min);
        // Card heights are quantized upwards; their rotations to 1/32767, which moves a
        // corner of a card of some centimetres by well under 0.02 mm.
        assert!(
            lowest >= tree.ground_y() - 2e-5,
            "{name}: leaves reach {lowest} m, below the ground at {} m",
            tree.ground_y()
        );
        for (primitive, _) in &parts {
            assert_eq!(
                primitive["texcoord0"],
                primitive["material"] != "fruit",
                "{name}: {} texture coordinates",
                primitive["material"]
            );
        }
    }
}
