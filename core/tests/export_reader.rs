//! Every preset's `.glb` read by a real glTF reader that honours the extensions it knows
//! (glTF Transform, `tools/gltf-reader`): one tree in one scene, one instance of it, the
//! finest level's triangles and bounds, and no leaf below the ground (issue #25).

mod support;

use sylva_core::Tree;
use sylva_core::export::write_glb;
use sylva_core::geometry::build_tree_meshes;
use sylva_core::species::Species;

const SEED: u64 = 11;
const AGE_YEARS: f32 = 15.0;

#[test]
fn a_real_reader_finds_one_tree_per_scene_with_the_finest_levels_triangles_and_bounds() {
    let dir = tempfile::tempdir().expect("temp dir");
    for species in Species::presets() {
        let name = species.name.clone();
        let mut tree = Tree::new(species, SEED);
        tree.grow_years(AGE_YEARS);
        let meshes = build_tree_meshes(&tree);
        let path = dir.path().join(format!("{name}.glb"));
        write_glb(&meshes, &path).expect("glb written");
        let report = support::read_glb_with_gltf_transform(&path);
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
        assert_eq!(
            tree_node["triangles"].as_u64(),
            Some(meshes.num_triangles(0) as u64),
            "{name}: the finest level's triangles"
        );
        let (lo, hi) = meshes.bounds(0).expect("bounds");
        let corner = |key: &str| -> [f32; 3] {
            let v = tree_node[key].as_array().expect("a bound");
            [0, 1, 2].map(|i| v[i].as_f64().expect("a number") as f32)
        };
        let (min, max) = (corner("min"), corner("max"));
        for axis in 0..3 {
            assert!(
                (min[axis] - lo[axis]).abs() < 1e-4 && (max[axis] - hi[axis]).abs() < 1e-4,
                "{name}: bounds {min:?}..{max:?} against {lo}..{hi}"
            );
        }
        let primitives = tree_node["primitives"].as_array().expect("primitives");
        let leaves = primitives
            .iter()
            .find(|p| p["material"] == "leaf")
            .unwrap_or_else(|| panic!("{name}: no leaf primitive"));
        let lowest = leaves["lowest_y"].as_f64().expect("a height") as f32;
        assert!(
            lowest >= tree.ground_y() - 1e-5,
            "{name}: leaves reach {lowest} m, below the ground at {} m",
            tree.ground_y()
        );
        for primitive in primitives {
            assert_eq!(
                primitive["texcoord0"],
                primitive["material"] != "fruit",
                "{name}: {} texture coordinates",
                primitive["material"]
            );
        }
    }
}
