//! The garden `.glb` (issue #24, Done when 7): the Khronos validator accepts it with no errors,
//! it opens as one node per tree at the tree's place, and the trees of a species share one leaf
//! texture, one bark texture and their materials, so ten trees cost their geometry, not ten
//! copies of the textures.

mod support;

use sylva_core::export::{
    SceneTree, garden_glb_bytes, glb_bytes, write_garden_glb, write_garden_obj,
};
use sylva_core::garden::{Garden, PlantedTree};
use sylva_core::species::Species;

fn species(name: &str) -> Species {
    Species::by_name(name).expect("preset")
}

/// Ten young trees, birches and maples in turn, in two rows 2.5 m apart.
fn ten_trees() -> Garden {
    let trees = (0..10)
        .map(|k| {
            let name = if k % 2 == 0 { "birch" } else { "maple" };
            let (x, z) = ((k / 2) as f32 * 2.5, (k % 2) as f32 * 2.5);
            PlantedTree::new(species(name), x, z, 2.0, k as u64)
        })
        .collect();
    let mut garden = Garden::plant(trees).expect("valid planting");
    garden.grow_years(2.0);
    garden
}

fn scene<'a>(
    garden: &Garden,
    meshes: &'a [sylva_core::geometry::TreeMeshes],
) -> Vec<SceneTree<'a>> {
    garden
        .trees
        .iter()
        .zip(meshes)
        .enumerate()
        .map(|(k, (t, m))| SceneTree {
            name: format!("tree {k} {}", t.tree.species.name),
            species: t.tree.species.name.clone(),
            translation: t.base(),
            meshes: m,
        })
        .collect()
}

fn json_chunk(glb: &[u8]) -> serde_json::Value {
    let length = u32::from_le_bytes(glb[12..16].try_into().expect("header")) as usize;
    serde_json::from_slice(&glb[20..20 + length]).expect("JSON chunk")
}

/// Whether an image is a tree's own coarsest-level leaf atlas (not shared by its species).
fn is_atlas(image: &serde_json::Value) -> bool {
    image["name"].as_str().is_some_and(|n| n.contains("atlas"))
}

/// Bytes of a document's species images (the bark and leaf PNG textures in its BIN chunk; a
/// tree's own leaf atlas counts as its geometry).
fn image_bytes(json: &serde_json::Value) -> u64 {
    let views = json["bufferViews"].as_array().expect("views");
    json["images"].as_array().map_or(0, |images| {
        images
            .iter()
            .filter(|i| !is_atlas(i))
            .map(|i| {
                views[i["bufferView"].as_u64().expect("view") as usize]["byteLength"]
                    .as_u64()
                    .expect("length")
            })
            .sum()
    })
}

#[test]
fn a_garden_glb_passes_the_validator_with_one_node_per_tree_and_shared_textures() {
    let garden = ten_trees();
    let meshes = garden.tree_meshes();
    let trees = scene(&garden, &meshes);
    let dir = tempfile::tempdir().expect("temp dir");
    let path = dir.path().join("garden.glb");
    write_garden_glb(&trees, &path).expect("garden glb written");
    let report = support::validate_glb(&path);
    assert_eq!(report.num_errors, 0, "validator errors: {}", report.text);

    let glb = std::fs::read(&path).expect("reads");
    // The `gltf` crate refuses required extensions (quantization, instancing): read the JSON.
    let json = json_chunk(&glb);
    let nodes = json["nodes"].as_array().expect("nodes");
    let scene = &json["scenes"][json["scene"].as_u64().unwrap_or(0) as usize];
    let roots: Vec<&serde_json::Value> = scene["nodes"]
        .as_array()
        .expect("a scene with nodes")
        .iter()
        .map(|i| &nodes[i.as_u64().expect("node index") as usize])
        .collect();
    assert_eq!(roots.len(), 10, "one node per tree");
    for (k, node) in roots.iter().enumerate() {
        assert_eq!(node["name"].as_str(), Some(trees[k].name.as_str()));
        let translation: Vec<f32> = node["translation"]
            .as_array()
            .expect("translated to its base")
            .iter()
            .map(|v| v.as_f64().expect("number") as f32)
            .collect();
        assert_eq!(translation, trees[k].translation.to_array().to_vec());
        let children = node["children"].as_array().map_or(0, Vec::len);
        assert!(children >= 1, "tree {k} holds its meshes");
    }
    // Two species: one bark and one leaf texture each, whatever the number of trees, and each
    // tree its own coarsest level's leaf atlas.
    let images = json["images"].as_array().expect("images");
    let atlases = images.iter().filter(|i| is_atlas(i)).count();
    let with_atlas = meshes
        .iter()
        .filter(|m| {
            m.lods
                .iter()
                .any(|l| l.billboards.is_some() && l.num_leaf_indices > 0)
        })
        .count();
    assert_eq!(atlases, with_atlas);
    assert_eq!(images.len(), 4 + atlases);
    assert_eq!(json["textures"].as_array().map(Vec::len), Some(4 + atlases));
    let materials = json["materials"].as_array().expect("materials");
    let names: Vec<&str> = materials
        .iter()
        .filter_map(|m| m["name"].as_str())
        .collect();
    assert_eq!(
        names.iter().filter(|n| n.ends_with("leaf")).count(),
        2,
        "{names:?}"
    );

    // Size: the trees' own files less their textures, plus one set of textures per species.
    let alone: Vec<Vec<u8>> = meshes
        .iter()
        .map(|m| glb_bytes(m).expect("tree glb"))
        .collect();
    let geometry: u64 = alone
        .iter()
        .map(|g| g.len() as u64 - image_bytes(&json_chunk(g)))
        .sum();
    let textures = image_bytes(&json_chunk(&alone[0])) + image_bytes(&json_chunk(&alone[1]));
    let expected = geometry + textures;
    let size = glb.len() as u64;
    println!(
        "garden of 10: {size} bytes; trees alone {} bytes in all, {geometry} without textures, textures of the two species {textures}",
        alone.iter().map(|g| g.len() as u64).sum::<u64>()
    );
    assert!(
        size.abs_diff(expected) * 50 < expected,
        "{size} bytes, expected about {expected}"
    );
    // One tree: its geometry and one set of textures, so nine more trees add only geometry.
    let one = garden_glb_bytes(&trees[..1]).expect("one tree");
    let one_expected = alone[0].len() as u64;
    assert!(
        (one.len() as u64).abs_diff(one_expected) * 50 < one_expected,
        "{} bytes for one tree, its own file {one_expected}",
        one.len()
    );
}

#[test]
fn a_garden_obj_has_one_group_per_tree_every_triangle_and_one_material_set_per_species() {
    let garden = ten_trees();
    let meshes = garden.tree_meshes();
    let trees = scene(&garden, &meshes);
    let dir = tempfile::tempdir().expect("temp dir");
    let path = dir.path().join("garden.obj");
    write_garden_obj(&trees, &path).expect("garden obj written");
    let obj = std::fs::read_to_string(&path).expect("reads");
    let groups: Vec<&str> = obj.lines().filter(|l| l.starts_with("g ")).collect();
    assert_eq!(groups.len(), 10);
    assert_eq!(groups[3], "g tree_3_maple");
    let num_vertices = obj.lines().filter(|l| l.starts_with("v ")).count();
    let faces: Vec<&str> = obj.lines().filter(|l| l.starts_with("f ")).collect();
    let triangles: usize = meshes
        .iter()
        .map(|m| {
            let lod = &m.lods[0];
            (lod.branches.indices.len() + lod.num_leaf_indices + lod.num_fruit_indices) / 3
        })
        .sum();
    assert_eq!(faces.len(), triangles);
    let largest = faces
        .iter()
        .flat_map(|f| f.split_whitespace().skip(1))
        .map(|c| {
            c.split('/')
                .next()
                .and_then(|v| v.parse::<usize>().ok())
                .expect("index")
        })
        .max()
        .expect("faces");
    assert_eq!(
        largest, num_vertices,
        "the last tree's indices reach the last vertex"
    );
    let mtl = std::fs::read_to_string(path.with_extension("mtl")).expect("mtl");
    let leafs: Vec<&str> = mtl
        .lines()
        .filter(|l| l.starts_with("newmtl") && l.ends_with("_leaf"))
        .collect();
    assert_eq!(leafs, ["newmtl birch_leaf", "newmtl maple_leaf"]);
    let pngs = std::fs::read_dir(dir.path())
        .expect("dir")
        .filter(|e| {
            e.as_ref()
                .is_ok_and(|e| e.path().extension().is_some_and(|x| x == "png"))
        })
        .count();
    assert_eq!(pngs, 4, "bark and leaf textures once per species");
    assert!(mtl.contains("map_Kd garden_maple_leaf.png"), "{mtl}");
}

#[test]
fn an_empty_garden_scene_is_an_error_naming_the_file() {
    let dir = tempfile::tempdir().expect("temp dir");
    let path = dir.path().join("empty.glb");
    let error = write_garden_glb(&[], &path).expect_err("nothing to write");
    assert!(error.to_string().contains("empty.glb"), "{error}");
}
